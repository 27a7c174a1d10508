// `eol plant-bench --central URL [--mqtt HOST:PORT] [--online N] [--backlog N] [--json]`:
// the plant-integration figures (station/bench/plant_bench.h) against a running broker and
// PostgreSQL server; deploy/plant-bench.sh starts throwaway ones and runs this.
#include <spdlog/spdlog.h>

#include <cstdio>
#include <filesystem>
#include <iostream>

#include "station/bench/plant_bench.h"
#include "station/cli/commands.h"
#include "station/cli/common.h"
#include "station/daemon/mqtt_publisher.h"

namespace eol::station::cli {

void AddPlantBenchCommand(CLI::App& app) {
  auto o = std::make_shared<PlantBenchOptions>();
  auto mqtt = std::make_shared<std::string>("mqtt://127.0.0.1:1883");
  auto json = std::make_shared<bool>(false);
  o->work_dir = std::filesystem::temp_directory_path().string();
  CLI::App* cmd = app.add_subcommand(
      "plant-bench",
      "Benchmark: delay from a stored record to an MQTT subscriber and to its central\n"
      "PostgreSQL row, outbox replay rate after an outage, central insert rate; against a\n"
      "running broker and database (deploy/plant-bench.sh starts throwaway ones).");
  cmd->add_option("--mqtt", *mqtt, "Broker URL mqtt://host:port")->capture_default_str();
  cmd->add_option("--central", o->central, "Central record postgresql://user@host:port/db")
      ->required();
  cmd->add_option("--online", o->online, "Records for the delay figures")
      ->capture_default_str()
      ->check(Between(1, 10000));
  cmd->add_option("--backlog", o->backlog, "Records for the replay and insert rates")
      ->capture_default_str()
      ->check(Between(1, 100000));
  cmd->add_option("--work-dir", o->work_dir, "Where the bench's SQLite file is made")
      ->capture_default_str();
  cmd->add_flag("--json", *json, "Print the figures as JSON");
  cmd->callback([o, mqtt, json] {
    RunGuarded("plant-bench", [&] {
      std::string why;
      bool tls = false;
      if (!ParseMqttUrl(*mqtt, &o->mqtt_host, &o->mqtt_port, &tls, &why) || tls)
        throw std::runtime_error("--mqtt: " + (tls ? "mqtts:// is not measured here" : why));
      spdlog::set_level(spdlog::level::warn);
      const PlantBenchSummary s = RunPlantBench(*o);
      if (*json) {
        std::cout << ToJson(s).dump(2) << std::endl;
        return 0;
      }
      std::printf("record JSON without / with curves: %s bytes\n", s.record_json_bytes.c_str());
      std::printf("%-34s %9s %9s %9s   (%d records, one at a time)\n", "delay from stored to",
                  "median ms", "p95 ms", "max ms", s.online);
      std::printf("%-34s %9.1f %9.1f %9.1f\n", "  MQTT subscriber (QoS 1)",
                  s.stored_to_mqtt.median_ms, s.stored_to_mqtt.p95_ms, s.stored_to_mqtt.max_ms);
      std::printf("%-34s %9.1f %9.1f %9.1f\n", "  central PostgreSQL row",
                  s.stored_to_postgres.median_ms, s.stored_to_postgres.p95_ms,
                  s.stored_to_postgres.max_ms);
      std::printf(
          "outbox replay to MQTT after an outage: %d records in %.2f s = %.0f records/s "
          "(all received by the subscriber after %.2f s)\n",
          s.backlog, s.mqtt_replay_s, s.mqtt_replay_per_s, s.mqtt_all_received_s);
      std::printf("central insert after an outage: %d records in %.2f s = %.0f records/s\n",
                  s.backlog, s.central_replay_s, s.central_per_s);
      return 0;
    });
  });
}

}  // namespace eol::station::cli
