#include "station/bench/safety_bench.h"

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <optional>
#include <random>
#include <thread>

#include "drivers/emulators/modbus_fixture_server.h"
#include "drivers/fixture/modbus_fixture.h"
#include "drivers/sim/sim_daq.h"
#include "drivers/sim/sim_fixture.h"
#include "station/daemon/safety.h"
#include "station/daemon/sequencer.h"

namespace eol::station {
namespace {

// The fixture under test: the in-process simulator, or the Modbus driver talking to the
// emulator that serves the same bench.
struct BenchFixture {
  std::unique_ptr<drivers::ModbusFixtureServer> server;
  std::unique_ptr<drivers::Fixture> fixture;
};

BenchFixture MakeFixture(const std::string& kind, const std::shared_ptr<drivers::SimBench>& bench) {
  BenchFixture f;
  if (kind == "sim") {
    f.fixture = std::make_unique<drivers::SimFixture>(bench);
    return f;
  }
  if (kind != "modbus") throw std::invalid_argument("safety-bench: fixture must be sim or modbus");
  drivers::ModbusFixtureServerSettings ss;
  ss.link.transport = drivers::ModbusLink::Transport::kTcp;
  ss.link.host = "127.0.0.1";
  ss.link.port = 0;
  f.server = std::make_unique<drivers::ModbusFixtureServer>(bench, ss);
  if (const drivers::Status s = f.server->Start(); !s.ok())
    throw std::runtime_error("fixture emulator: " + s.message());
  drivers::ModbusFixtureSettings cs;
  cs.link = ss.link;
  cs.link.port = f.server->port();
  f.fixture = std::make_unique<drivers::ModbusFixture>(cs);
  return f;
}

double Percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  const auto i = static_cast<std::size_t>(p * static_cast<double>(v.size() - 1) + 0.5);
  return v[std::min(i, v.size() - 1)];
}

void Summarise(std::vector<double> reactions, ReactionStats* st) {
  st->measured = static_cast<int>(reactions.size());
  if (reactions.empty()) return;
  st->min_ms = *std::min_element(reactions.begin(), reactions.end());
  st->median_ms = Percentile(reactions, 0.5);
  st->p95_ms = Percentile(reactions, 0.95);
  st->max_ms = *std::max_element(reactions.begin(), reactions.end());
}

// One trial of "station_stops": the station closes the relay, writes station_alive every
// alive period for 100..400 ms, then stops dead (as a SIGKILL leaves it: nothing more is
// sent). Returns the ms from its last alive write to the relay seen open by an observer
// polling the controller every millisecond; nullopt when it stayed closed for 2 s.
std::optional<double> StationStopsOnce(const SafetyBenchOptions& o, std::mt19937_64& rng) {
  using Clock = std::chrono::steady_clock;
  auto bench = std::make_shared<drivers::SimBench>(drivers::SimBenchSettings{});
  bench->LoadPart("SB-STOP");
  BenchFixture bench_fixture = MakeFixture(o.fixture, bench);
  drivers::Fixture& fixture = *bench_fixture.fixture;
  AliveSignal alive(fixture);
  if (!fixture.Connect().ok() || !fixture.Activate().ok() || !alive.Fresh().ok() ||
      !fixture.Write(drivers::FixtureOutput::kExcitationEnable, true).ok())
    return std::nullopt;
  const auto live_for =
      std::chrono::milliseconds(std::uniform_int_distribution<int>(100, 400)(rng));
  const auto start = Clock::now();
  auto last_alive = start;
  while (Clock::now() - start < live_for) {
    std::this_thread::sleep_for(
        std::chrono::milliseconds(static_cast<int>(SafetyOptions{}.alive_period_ms)));
    if (alive.Beat().ok()) last_alive = Clock::now();
  }
  while (bench->output(drivers::FixtureOutput::kExcitationEnable)) {
    if (Clock::now() - last_alive > std::chrono::seconds(2)) return std::nullopt;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return std::chrono::duration<double, std::milli>(Clock::now() - last_alive).count();
}

ReactionStats MeasureStationStops(const SafetyBenchOptions& o, std::mt19937_64& rng) {
  ReactionStats st;
  st.fault = "station_stops";
  std::vector<double> reactions;
  for (int t = 0; t < o.trials_per_fault; ++t) {
    ++st.trials;
    if (const auto ms = StationStopsOnce(o, rng)) {
      ++st.errors;  // here: the controller opened the relay by itself
      reactions.push_back(*ms);
    }
  }
  Summarise(std::move(reactions), &st);
  return st;
}

}  // namespace

std::vector<ReactionStats> RunSafetyBench(const SafetyBenchOptions& o) {
  const auto recipe = std::make_shared<const Recipe>(LoadRecipe(o.recipe_path));
  const std::string db_path = (std::filesystem::temp_directory_path() /
                               ("eol-safety-bench-" + std::to_string(::getpid()) + "-" + o.fixture +
                                "-" + std::to_string(o.seed) + ".sqlite"))
                                  .string();
  std::filesystem::remove(db_path);
  auto store = db::Store::Open(db_path);
  StatusBoard board("safety-bench");
  std::mt19937_64 rng(o.seed);
  std::uniform_int_distribution<int> delay_ms(20, 400);

  std::vector<ReactionStats> out;
  for (drivers::SimFault fault : {drivers::SimFault::kClampDrops, drivers::SimFault::kPressureLow,
                                  drivers::SimFault::kDoorOpens, drivers::SimFault::kEstop}) {
    ReactionStats st;
    st.fault = drivers::ToString(fault);
    std::vector<double> reactions;
    for (int t = 0; t < o.trials_per_fault; ++t) {
      drivers::SimBenchSettings bs;
      bs.clamp_close_s = 0.02;
      bs.clamp_open_s = 0.02;
      auto bench = std::make_shared<drivers::SimBench>(bs);
      BenchFixture bench_fixture = MakeFixture(o.fixture, bench);
      drivers::Fixture& fixture = *bench_fixture.fixture;
      drivers::SimDaqSettings ds;
      ds.time_scale = 1.0;  // real time: the fault lands mid-stream
      drivers::SimDaq daq(bench, ds);
      (void)fixture.Connect();
      (void)daq.Connect();
      SequencerOptions so;
      so.station_id = "safety-bench";
      so.safety.watchdog_period_ms = o.watchdog_period_ms;
      Sequencer seq(fixture, daq, *store, recipe, board, so);
      const std::string serial = "SB-" + st.fault + "-" + std::to_string(t);
      bench->LoadPart(serial);
      bench->InjectFault(fault, std::chrono::milliseconds(delay_ms(rng)));
      const db::TestRecord r = seq.RunTest(serial);
      ++st.trials;
      if (r.outcome == analysis::Outcome::kError) ++st.errors;
      if (bench->fault_visible_at() && bench->last_excitation_off())
        reactions.push_back(std::chrono::duration<double, std::milli>(
                                *bench->last_excitation_off() - *bench->fault_visible_at())
                                .count());
    }
    Summarise(std::move(reactions), &st);
    out.push_back(st);
  }
  out.push_back(MeasureStationStops(o, rng));
  store.reset();
  std::filesystem::remove(db_path);
  std::filesystem::remove(db_path + "-wal");
  std::filesystem::remove(db_path + "-shm");
  return out;
}

nlohmann::json ToJson(const std::vector<ReactionStats>& stats) {
  nlohmann::json j = nlohmann::json::array();
  for (const auto& s : stats)
    j.push_back({{"fault", s.fault},
                 {"trials", s.trials},
                 {"errors", s.errors},
                 {"measured", s.measured},
                 {"min_ms", s.min_ms},
                 {"median_ms", s.median_ms},
                 {"p95_ms", s.p95_ms},
                 {"max_ms", s.max_ms}});
  return j;
}

}  // namespace eol::station
