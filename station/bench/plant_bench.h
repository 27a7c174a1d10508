// `eol plant-bench`: the plant-integration figures of station/README.md, measured against a real
// MQTT broker and a real PostgreSQL server (deploy/plant-bench.sh starts throwaway ones):
//   - end-to-end delay, record stored -> received by an MES subscriber (QoS 1) and -> its row
//     visible in the central `tests` table, with the station's own publisher and replicator
//     at their default settings (they look at the outbox every 50 ms when idle);
//   - outbox replay rate after an outage: a backlog written while the publisher was stopped,
//     then the time until the broker has acknowledged all of it (records/s), the subscriber
//     receiving every record;
//   - central insert rate: the same for the replicator (batches of CentralConfig::batch).
// Records are synthetic but station-sized (measurements, reasons, two 400-line curves); the
// station id is new per run, so runs never collide in the central table.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace eol::station {

struct PlantBenchOptions {
  std::string mqtt_host = "127.0.0.1";
  int mqtt_port = 1883;
  std::string central;   // postgresql:// URI
  std::string work_dir;  // the bench's SQLite file goes here
  int online = 50;       // records for the delay figures, one at a time
  int backlog = 2000;    // records for the replay and insert rates
  double gap_s = 0.1;    // pause between online records
};

struct Percentiles {
  double median_ms = 0, p95_ms = 0, max_ms = 0;
};

struct PlantBenchSummary {
  std::string station_id;
  int online = 0;
  Percentiles stored_to_mqtt;
  Percentiles stored_to_postgres;
  int backlog = 0;
  double mqtt_replay_s = 0;  // backlog acknowledged by the broker
  double mqtt_replay_per_s = 0;
  double mqtt_all_received_s = 0;  // ... and received by the subscriber
  double central_replay_s = 0;
  double central_per_s = 0;
  std::string record_json_bytes;  // size of one record's JSON without / with curves
};

// Throws std::runtime_error naming the server when the broker or the database cannot be
// reached or a figure cannot be measured within its time limit.
PlantBenchSummary RunPlantBench(const PlantBenchOptions& options);
nlohmann::json ToJson(const PlantBenchSummary& s);

}  // namespace eol::station
