// The Modbus fixture driver against the Modbus emulator (ModbusFixtureServer), both
// in-process, over real TCP on 127.0.0.1 on a free port: what is Modbus's own beyond the
// fixture contract (tests/support/fixture_contract.h, run in fixture_contract_test.cc):
// relocated maps, pressure scaling at the driver edge, the retry policy and its messages,
// and recovery when the controller stops answering or goes away. The bench runs on a
// ManualClock: the clamp's travel is stated by advancing it. The independent peers
// (pymodbus) are in tests/peers/.
#include "drivers/fixture/modbus_fixture.h"

#include <gtest/gtest.h>
#include <modbus/modbus.h>
#include <spdlog/sinks/ringbuffer_sink.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "drivers/emulators/modbus_fixture_server.h"
#include "drivers/factory/factory.h"
#include "drivers/fixture/modbus_map.h"
#include "drivers/sim/sim_bench.h"
#include "drivers/sim/sim_clock.h"
#include "tests/support/glitch_proxy.h"

namespace eol::drivers {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

#define EXPECT_CONTAINS(text, part) \
  EXPECT_NE(std::string(text).find(part), std::string::npos) << "in: " << (text)

double Seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

// Adds a ring buffer to what spdlog's default logger writes, for the life of the object.
// spdlog's default logger must not be swapped while another thread logs through it (the
// emulator's thread does: a swap mid-call freed the logger under it and corrupted the heap),
// so the fixture makes one before the emulator starts and drops it after the emulator stops.
class LogCapture {
 public:
  LogCapture()
      : ring_(std::make_shared<spdlog::sinks::ringbuffer_sink_mt>(256)),
        previous_(spdlog::default_logger()) {
    std::vector<spdlog::sink_ptr> sinks = previous_->sinks();
    sinks.push_back(ring_);
    auto capture = std::make_shared<spdlog::logger>("capture", sinks.begin(), sinks.end());
    capture->set_level(previous_->level());
    spdlog::set_default_logger(capture);
  }
  ~LogCapture() { spdlog::set_default_logger(previous_); }
  LogCapture(const LogCapture&) = delete;
  LogCapture& operator=(const LogCapture&) = delete;

  std::vector<std::string> LinesWith(const std::string& part) const {
    std::vector<std::string> out;
    for (const std::string& line : ring_->last_formatted())
      if (line.find(part) != std::string::npos) out.push_back(line);
    return out;
  }

 private:
  std::shared_ptr<spdlog::sinks::ringbuffer_sink_mt> ring_;
  std::shared_ptr<spdlog::logger> previous_;
};

class ModbusFixtureTest : public ::testing::Test {
 protected:
  void SetUp() override {
    log_ = std::make_unique<LogCapture>();  // before any thread logs; see LogCapture
    bench_ = std::make_shared<SimBench>(bench_settings_, ManualClock::Of(clock_));
    bench_->LoadPart("T-0001");
    StartServer(0);
  }
  void TearDown() override {
    if (fixture_) fixture_->Disconnect();
    if (server_) server_->Stop();
    server_.reset();
    log_.reset();  // no thread of the emulator is left to log
  }

  // (Re)starts the emulator; port 0 picks a free one.
  void StartServer(int port) {
    ModbusFixtureServerSettings s;
    s.link.port = port;
    s.map = server_map_;
    server_ = std::make_unique<ModbusFixtureServer>(bench_, s);
    const Status st = server_->Start();
    ASSERT_TRUE(st.ok()) << st.message();
    ASSERT_GT(server_->port(), 0);
  }

  ModbusFixtureSettings ClientSettings() const {
    ModbusFixtureSettings c;
    c.link.host = "127.0.0.1";
    c.link.port = server_->port();
    c.map = client_map_;
    c.response_timeout_ms = 100;
    c.attempts = 2;
    c.backoff_initial_ms = 10;
    c.backoff_max_ms = 40;
    return c;
  }

  ModbusFixture& Connected() {
    fixture_ = std::make_unique<ModbusFixture>(ClientSettings());
    const Status s = fixture_->Connect();
    EXPECT_TRUE(s.ok()) << s.message();
    return *fixture_;
  }

  FixtureInputs Read() {
    auto in = fixture_->ReadInputs();
    EXPECT_TRUE(in.ok()) << in.status().message();
    return in.ok() ? in.value() : FixtureInputs{};
  }

  std::string Endpoint() const { return "127.0.0.1:" + std::to_string(server_->port()); }

  SimBenchSettings bench_settings_;
  std::shared_ptr<ManualClock> clock_ = std::make_shared<ManualClock>();
  ModbusMap server_map_, client_map_;
  std::shared_ptr<SimBench> bench_;
  std::unique_ptr<ModbusFixtureServer> server_;
  std::unique_ptr<ModbusFixture> fixture_;
  std::unique_ptr<LogCapture> log_;
};

TEST_F(ModbusFixtureTest, PressureCountsBecomeBarWithTheClientsScale) {
  // The emulator publishes 0.01 bar counts (550 for 5.5 bar); a client whose map says
  // 0.02 bar per count must read twice the pressure: the conversion is the driver's.
  client_map_.pressure_bar_per_count = 0.02;
  ModbusFixture& f = Connected();
  ASSERT_TRUE(f.Activate().ok());
  ASSERT_TRUE(f.Write(FixtureOutput::kClampCmd, true).ok());
  clock_->AdvanceSeconds(bench_settings_.clamp_close_s + 0.05);
  EXPECT_NEAR(Read().clamp_pressure_bar, 2.0 * bench_settings_.clamp_pressure_bar,
              2.0 * (0.02 + 0.005));
}

TEST_F(ModbusFixtureTest, FinePressureScaleOnBothEnds) {
  server_->Stop();
  bench_settings_.clamp_pressure_bar = 3.21;
  bench_ = std::make_shared<SimBench>(bench_settings_, ManualClock::Of(clock_));
  bench_->LoadPart("T-0002");
  server_map_.pressure_bar_per_count = 0.001;
  client_map_.pressure_bar_per_count = 0.001;
  StartServer(0);
  ModbusFixture& f = Connected();
  ASSERT_TRUE(f.Activate().ok());
  ASSERT_TRUE(f.Write(FixtureOutput::kClampCmd, true).ok());
  clock_->AdvanceSeconds(bench_settings_.clamp_close_s + 0.05);
  EXPECT_NEAR(Read().clamp_pressure_bar, 3.21, 0.02 + 0.0005);
}

TEST_F(ModbusFixtureTest, StopsAnsweringGivesANamedErrorAndRecoversAfterClearFaults) {
  ModbusFixture& f = Connected();
  ASSERT_TRUE(f.Activate().ok());
  ASSERT_TRUE(f.WriteAlive(1).ok());
  ASSERT_TRUE(f.Write(FixtureOutput::kExcitationEnable, true).ok());
  bench_->InjectFault(SimFault::kStopsAnswering, 0ms, /*on_excitation=*/false);

  const auto t0 = Clock::now();
  const auto in = f.ReadInputs();
  const double took_s = Seconds(Clock::now() - t0);
  const std::vector<std::string> retries = log_->LinesWith("retrying");  // never silent
  ASSERT_FALSE(in.ok());
  const std::string& m = in.status().message();
  EXPECT_CONTAINS(m,
                  "fixture 'modbus-tcp': read inputs: read discrete inputs 0..4 "
                  "(clamped..estop_ok) at " +
                      Endpoint() + " unit 1: ");
  // In excitation a failed read is an interlock loss at once: never retried.
  EXPECT_CONTAINS(m, "(attempt 1, timeout 100 ms, in excitation: not retried)");
  EXPECT_GE(took_s, 0.1);  // one full response timeout: the server really kept quiet
  EXPECT_LT(took_s, 0.19);
  EXPECT_EQ(f.lifecycle(), Lifecycle::kError);
  EXPECT_TRUE(retries.empty()) << retries.front();

  // The dead controller's relay dropped out on its own (fail-safe wiring).
  const auto deadline = Clock::now() + 1s;
  while (bench_->excitation_connected() && Clock::now() < deadline)
    std::this_thread::sleep_for(10ms);
  EXPECT_FALSE(bench_->excitation_connected());

  bench_->ClearFaults();
  const Status reconnect = f.Connect();
  ASSERT_TRUE(reconnect.ok()) << reconnect.message();
  const FixtureInputs after = Read();
  EXPECT_TRUE(after.part_present);
  EXPECT_TRUE(after.estop_ok);
}

TEST_F(ModbusFixtureTest, WritesFailWithTheSignalTableAndAddressWhileNotAnswering) {
  ModbusFixture& f = Connected();
  ASSERT_TRUE(f.Activate().ok());
  bench_->InjectFault(SimFault::kStopsAnswering, 0ms, false);
  const Status s = f.SelectPhasePair(PhasePair::kWU);
  ASSERT_FALSE(s.ok());
  EXPECT_CONTAINS(s.message(),
                  "fixture 'modbus-tcp': select phase pair: write holding register "
                  "0 (phase_pair) = 2 at " +
                      Endpoint() + " unit 1: ");
  EXPECT_CONTAINS(s.message(), "(attempt 2, timeout 100 ms)");
  EXPECT_EQ(bench_->phase_pair(), PhasePair::kUV);
  bench_->ClearFaults();
}

TEST_F(ModbusFixtureTest, ServerGoneThenBackNeedsOnlyConnect) {
  ModbusFixture& f = Connected();
  Read();
  const int port = server_->port();
  server_->Stop();
  const auto gone = f.ReadInputs();
  ASSERT_FALSE(gone.ok());
  EXPECT_CONTAINS(gone.status().message(),
                  "read discrete inputs 0..4 (clamped..estop_ok) at " + Endpoint() + " unit 1: ");
  EXPECT_CONTAINS(gone.status().message(),
                  "reconnect failed: Connection refused (attempt 2, "
                  "timeout 100 ms)");
  const Status refused = f.Connect();
  ASSERT_FALSE(refused.ok());
  EXPECT_CONTAINS(refused.message(),
                  "fixture 'modbus-tcp': connect: TCP connection at " + Endpoint() + " unit 1: ");
  EXPECT_CONTAINS(refused.message(), "Connection refused (attempt 2, timeout 100 ms)");

  StartServer(port);
  const Status back = f.Connect();
  ASSERT_TRUE(back.ok()) << back.message();
  EXPECT_TRUE(Read().part_present);
}

TEST_F(ModbusFixtureTest, BacksOffExponentiallyAndLogsEveryRetry) {
  ModbusFixtureSettings c = ClientSettings();
  server_->Stop();  // nothing listens on the port now
  c.attempts = 4;
  c.backoff_initial_ms = 10;
  c.backoff_max_ms = 25;
  ModbusFixture f(c);
  const Status s = f.Connect();
  ASSERT_FALSE(s.ok());
  EXPECT_CONTAINS(s.message(), "fixture 'modbus-tcp': connect: TCP connection at 127.0.0.1:" +
                                   std::to_string(c.link.port) +
                                   " unit 1: reconnect failed: Connection refused (attempt 4, "
                                   "timeout 100 ms)");
  const auto retries = log_->LinesWith("retrying");
  ASSERT_EQ(retries.size(), 3u);
  EXPECT_CONTAINS(retries[0],
                  "Connection refused (attempt 1, timeout 100 ms); retrying in 10 ms "
                  "(attempt 2 of 4)");
  EXPECT_CONTAINS(retries[1], "(attempt 2, timeout 100 ms); retrying in 20 ms (attempt 3 of 4)");
  EXPECT_CONTAINS(retries[2], "(attempt 3, timeout 100 ms); retrying in 25 ms (attempt 4 of 4)");
}

TEST_F(ModbusFixtureTest, ServerRestartIsBridgedByAReconnectWithinOneCall) {
  ModbusFixture& f = Connected();
  Read();
  const int port = server_->port();
  server_->Stop();
  StartServer(port);
  // The old connection is dead: attempt 1 fails, attempt 2 reconnects and reads.
  const auto in = f.ReadInputs();
  ASSERT_TRUE(in.ok()) << in.status().message();
  EXPECT_TRUE(in.value().part_present);
  EXPECT_EQ(f.lifecycle(), Lifecycle::kInactive);
}

// A reply spoiled on the wire (another unit id, another function, half a frame) during
// excitation: the read fails at once with the cause named, the request is not repeated,
// and the relay can still be commanded off.
struct Spoiled {
  testing::GlitchProxy::Glitch glitch;
  std::string cause;
};

void PrintTo(const Spoiled& s, std::ostream* os) { *os << s.cause; }

class ModbusGlitchTest : public ModbusFixtureTest, public ::testing::WithParamInterface<Spoiled> {};

TEST_P(ModbusGlitchTest, SpoiledReplyInExcitationFailsWithoutRetryAndTheRelayGoesOff) {
  testing::GlitchProxy proxy(server_->port());
  ASSERT_GT(proxy.port(), 0);
  ModbusFixtureSettings c = ClientSettings();
  c.link.port = proxy.port();
  fixture_ = std::make_unique<ModbusFixture>(c);
  ModbusFixture& f = *fixture_;
  ASSERT_TRUE(f.Connect().ok());
  ASSERT_TRUE(f.Activate().ok());
  ASSERT_TRUE(f.WriteAlive(1).ok());
  ASSERT_TRUE(f.Write(FixtureOutput::kExcitationEnable, true).ok());
  ASSERT_TRUE(bench_->excitation_connected());

  proxy.Arm(GetParam().glitch);
  const int before = proxy.requests();
  const auto in = f.ReadInputs();
  ASSERT_FALSE(in.ok()) << "a spoiled reply was taken for inputs";
  EXPECT_CONTAINS(in.status().message(), GetParam().cause);
  EXPECT_CONTAINS(in.status().message(), "(attempt 1, timeout 100 ms, in excitation: not retried)");
  EXPECT_EQ(proxy.requests() - before, 1) << "the failed request was retried in excitation";
  EXPECT_FALSE(proxy.armed());

  const Status off = f.Write(FixtureOutput::kExcitationEnable, false);
  ASSERT_TRUE(off.ok()) << off.message();
  EXPECT_FALSE(bench_->excitation_connected());
}

INSTANTIATE_TEST_SUITE_P(Replies, ModbusGlitchTest,
                         ::testing::Values(Spoiled{testing::GlitchProxy::Glitch::kForeignUnit,
                                                   "reply from unit 7 to a request for unit 1"},
                                           Spoiled{testing::GlitchProxy::Glitch::kWrongFunction,
                                                   "malformed reply to function 2"},
                                           Spoiled{testing::GlitchProxy::Glitch::kTruncated,
                                                   "timed out"}),
                         [](const ::testing::TestParamInfo<Spoiled>& info) {
                           switch (info.param.glitch) {
                             case testing::GlitchProxy::Glitch::kForeignUnit:
                               return std::string("ForeignUnit");
                             case testing::GlitchProxy::Glitch::kWrongFunction:
                               return std::string("WrongFunction");
                             default:
                               return std::string("Truncated");
                           }
                         });

// Outside excitation the same spoiled reply is retried (on a fresh connection) and the read
// succeeds: the retry policy stays for idle reads.
TEST_F(ModbusFixtureTest, ForeignUnitReplyIsRetriedWhenIdle) {
  testing::GlitchProxy proxy(server_->port());
  ModbusFixtureSettings c = ClientSettings();
  c.link.port = proxy.port();
  fixture_ = std::make_unique<ModbusFixture>(c);
  ASSERT_TRUE(fixture_->Connect().ok());
  proxy.Arm(testing::GlitchProxy::Glitch::kForeignUnit);
  const int before = proxy.requests();
  const FixtureInputs in = Read();
  EXPECT_TRUE(in.part_present);
  EXPECT_EQ(proxy.requests() - before, 3) << "spoiled, retried, then the registers";
}

// The controller's alive rule in real time: a client that closes the relay and then just
// stops (as a killed station does) finds it open 250 ms after its last station_alive, seen
// by a third client reading the excitation coil; nothing else is sent meanwhile.
TEST(ModbusAliveTest, RelayDropsWithinAliveTimeoutAfterTheClientStops) {
  auto bench = std::make_shared<SimBench>(SimBenchSettings{});  // the steady clock
  bench->LoadPart("ALIVE-1");
  ModbusFixtureServerSettings s;
  s.link.port = 0;
  ModbusFixtureServer server(bench, s);
  ASSERT_TRUE(server.Start().ok());
  ModbusFixtureSettings c;
  c.link.host = "127.0.0.1";
  c.link.port = server.port();
  ModbusFixture f(c);
  ASSERT_TRUE(f.Connect().ok());
  ASSERT_TRUE(f.Activate().ok());
  ASSERT_TRUE(f.WriteAlive(1).ok());
  ASSERT_TRUE(f.Write(FixtureOutput::kExcitationEnable, true).ok());
  Clock::time_point last_alive = Clock::now();
  for (std::uint16_t v = 2; v < 8; ++v) {  // 300 ms of a live station
    std::this_thread::sleep_for(50ms);
    ASSERT_TRUE(f.WriteAlive(v).ok());
    last_alive = Clock::now();
  }
  ASSERT_TRUE(bench->output(FixtureOutput::kExcitationEnable)) << "dropped with alive changing";

  modbus_t* observer = modbus_new_tcp("127.0.0.1", server.port());
  ASSERT_NE(observer, nullptr);
  modbus_set_slave(observer, 1);
  ASSERT_EQ(modbus_connect(observer), 0);
  std::uint8_t coil = 1;
  while (coil != 0 && Clock::now() - last_alive < 2s) {
    ASSERT_EQ(modbus_read_bits(observer, 1, 1, &coil), 1);
    if (coil != 0) std::this_thread::sleep_for(2ms);
  }
  const double off_ms = Seconds(Clock::now() - last_alive) * 1000.0;
  modbus_close(observer);
  modbus_free(observer);
  EXPECT_EQ(coil, 0) << "the relay stayed closed 2 s after the station stopped";
  EXPECT_GE(off_ms, 240.0) << "dropped before the alive timeout";
  EXPECT_LE(off_ms, 350.0) << "dropped late";
  f.Disconnect();
  server.Stop();
}

TEST_F(ModbusFixtureTest, WrongUnitIdIsAnExceptionNotATimeout) {
  ModbusFixtureSettings c = ClientSettings();
  c.link.unit_id = 2;
  c.attempts = 1;
  c.response_timeout_ms = 2000;
  ModbusFixture f(c);
  const auto t0 = Clock::now();
  const Status s = f.Connect();  // connecting writes excitation off
  ASSERT_FALSE(s.ok());
  EXPECT_LT(Seconds(Clock::now() - t0), 1.0);  // an answer, well before the timeout
  EXPECT_CONTAINS(s.message(), "write coil 1 (excitation_enable) = 0 at " + Endpoint() +
                                   " unit 2: Target device failed to respond (attempt 1, "
                                   "timeout 2000 ms)");
}

TEST_F(ModbusFixtureTest, ServesAndReadsARelocatedMap) {
  ModbusMap m;
  m.clamped = {ModbusTable::kDiscreteInput, 10};
  m.released = {ModbusTable::kDiscreteInput, 11};
  m.estop_ok = {ModbusTable::kDiscreteInput, 12};
  m.part_present = {ModbusTable::kDiscreteInput, 20};
  m.door_closed = {ModbusTable::kCoil, 30};
  m.clamp_pressure = {ModbusTable::kHoldingRegister, 5};
  m.heartbeat = {ModbusTable::kInputRegister, 7};
  m.phase_pair = {ModbusTable::kHoldingRegister, 6};
  m.excitation_enable = {ModbusTable::kHoldingRegister, 9};
  m.clamp_cmd = {ModbusTable::kCoil, 100};
  std::string why;
  ASSERT_TRUE(m.IsValid(&why)) << why;

  std::vector<std::string> runs;
  for (const ModbusRun& r : InputRuns(m)) runs.push_back(r.Describe());
  EXPECT_EQ(runs, (std::vector<std::string>{
                      "coil 30 (door_closed)", "discrete inputs 10..12 (clamped..estop_ok)",
                      "discrete input 20 (part_present)", "input register 7 (heartbeat)",
                      "holding register 5 (clamp_pressure)"}));

  server_->Stop();
  server_map_ = m;
  client_map_ = m;
  StartServer(0);
  ModbusFixture& f = Connected();
  ASSERT_TRUE(f.Activate().ok());
  FixtureInputs in = Read();
  EXPECT_TRUE(in.released && in.part_present && in.door_closed && in.estop_ok);
  ASSERT_TRUE(f.Write(FixtureOutput::kClampCmd, true).ok());
  ASSERT_TRUE(f.WriteAlive(1).ok());  // holding register 1, as by default
  ASSERT_TRUE(f.Write(FixtureOutput::kExcitationEnable, true).ok());
  ASSERT_TRUE(f.SelectPhasePair(PhasePair::kWU).ok());
  EXPECT_TRUE(bench_->output(FixtureOutput::kClampCmd));
  EXPECT_TRUE(bench_->excitation_connected());
  EXPECT_EQ(bench_->phase_pair(), PhasePair::kWU);
  clock_->AdvanceSeconds(bench_settings_.clamp_close_s + 0.05);
  in = Read();
  EXPECT_TRUE(in.clamped);
  EXPECT_NEAR(in.clamp_pressure_bar, bench_settings_.clamp_pressure_bar, 0.025);
}

TEST_F(ModbusFixtureTest, LoadsAPartWhenTheClampClosesOnAnEmptyFixture) {
  server_->Stop();
  bench_->RemovePart();
  ModbusFixtureServerSettings s;
  s.link.port = 0;
  s.load_part_on_clamp = true;
  server_ = std::make_unique<ModbusFixtureServer>(bench_, s);
  ASSERT_TRUE(server_->Start().ok());
  ModbusFixture& f = Connected();
  ASSERT_TRUE(f.Activate().ok());
  EXPECT_FALSE(Read().part_present);
  ASSERT_TRUE(f.Write(FixtureOutput::kClampCmd, true).ok());
  ASSERT_TRUE(bench_->part().has_value());
  EXPECT_EQ(bench_->part()->serial, "SIM-1");
  EXPECT_TRUE(Read().part_present);
}

// The simulator's clamp_sticks fault reaches the station as a released sensor that stays off
// after the open command (the sequencer's release time-out, station/daemon/sequencer.h).
TEST_F(ModbusFixtureTest, StuckClampNeverReadsReleasedUntilTheFaultClears) {
  ModbusFixture& f = Connected();
  ASSERT_TRUE(f.Activate().ok());
  ASSERT_TRUE(f.Write(FixtureOutput::kClampCmd, true).ok());
  clock_->AdvanceSeconds(bench_settings_.clamp_close_s + 0.05);
  EXPECT_TRUE(Read().clamped);
  bench_->InjectFault(SimFault::kClampSticks, 0ms, /*on_excitation=*/false);
  ASSERT_TRUE(f.Write(FixtureOutput::kClampCmd, false).ok());
  clock_->AdvanceSeconds(10 * bench_settings_.clamp_open_s);
  const FixtureInputs stuck = Read();
  EXPECT_FALSE(stuck.released);
  EXPECT_FALSE(stuck.clamped);
  bench_->ClearFaults();
  EXPECT_TRUE(Read().released);
}

TEST(ModbusMapTest, DefaultMapReadsInTwoRequests) {
  const ModbusMap m;
  std::string why;
  EXPECT_TRUE(m.IsValid(&why)) << why;
  const auto runs = InputRuns(m);
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_EQ(runs[0].Describe(), "discrete inputs 0..4 (clamped..estop_ok)");
  EXPECT_EQ(runs[1].Describe(), "input registers 0..1 (clamp_pressure..heartbeat)");
  EXPECT_EQ(Describe(m, SpecOf("excitation_enable")), "coil 1 (excitation_enable)");
}

std::string ParseError(const nlohmann::json& j) {
  try {
    ParseModbusMap(j, "/fixture/map");
  } catch (const io::ConfigError& e) {
    return e.what();
  }
  return "no error";
}

TEST(ModbusMapTest, ParsesOverridesOverTheDefaults) {
  const ModbusMap m = ParseModbusMap(
      nlohmann::json::parse(R"({"clamped": 10, "heartbeat": {"table": "holding_register",
                                "address": 7}, "phase_pair": {"address": 3},
                                "pressure_bar_per_count": 0.001})"),
      "/fixture/map");
  EXPECT_EQ(m.clamped, (ModbusSignal{ModbusTable::kDiscreteInput, 10}));
  EXPECT_EQ(m.heartbeat, (ModbusSignal{ModbusTable::kHoldingRegister, 7}));
  EXPECT_EQ(m.phase_pair, (ModbusSignal{ModbusTable::kHoldingRegister, 3}));
  EXPECT_EQ(m.released, ModbusMap{}.released);
  EXPECT_EQ(m.pressure_bar_per_count, 0.001);
}

TEST(ModbusMapTest, ErrorsNameTheJsonPath) {
  EXPECT_EQ(ParseError(R"({"clampd": 3})"_json)
                .rfind("/fixture/map/clampd: unknown fixture signal (known: clamp_cmd, ", 0),
            0u)
      << ParseError(R"({"clampd": 3})"_json);
  EXPECT_EQ(ParseError(R"({"clamped": 70000})"_json),
            "/fixture/map/clamped: must be in 0..65535 (got 70000)");
  EXPECT_EQ(ParseError(R"({"clamped": "7"})"_json),
            "/fixture/map/clamped: must be an address or an object {\"table\", \"address\"} "
            "(got \"7\")");
  EXPECT_EQ(ParseError(R"({"phase_pair": {"table": "coil"}})"_json),
            "/fixture/map/phase_pair/table: cannot hold phase_pair (accepted: "
            "\"holding_register\") (got \"coil\")");
  EXPECT_EQ(ParseError(R"({"clamped": {"table": "register"}})"_json),
            "/fixture/map/clamped/table: unknown table 'register' (known: coil, discrete_input, "
            "input_register, holding_register)");
  EXPECT_EQ(ParseError(R"({"clamped": {"adress": 3}})"_json)
                .rfind("/fixture/map/clamped/adress: unknown field", 0),
            0u);
  EXPECT_EQ(ParseError(R"({"clamped": 1})"_json),
            "/fixture/map: released: discrete input 1 is already used by clamped");
  EXPECT_EQ(ParseError(R"({"pressure_bar_per_count": 0})"_json),
            "/fixture/map/pressure_bar_per_count: must be positive (got 0)");
}

TEST(ModbusFactoryTest, MakesModbusFixturesByName) {
  auto set = MakeDrivers(R"({"fixture": {"driver": "modbus-tcp", "host": "127.0.0.1",
                                         "port": 1502, "unit_id": 3, "map": {"clamped": 9}},
                             "daq": {"driver": "sim"}})"_json);
  ASSERT_NE(set.fixture, nullptr);
  EXPECT_EQ(set.fixture->name(), "modbus-tcp");
  const auto* mf = dynamic_cast<const ModbusFixture*>(set.fixture.get());
  ASSERT_NE(mf, nullptr);
  EXPECT_EQ(mf->settings().link.Describe(), "127.0.0.1:1502 unit 3");
  EXPECT_EQ(mf->settings().map.clamped.address, 9);

  set = MakeDrivers(R"({"fixture": {"driver": "modbus-rtu", "device": "/dev/ttyS9",
                                    "parity": "N", "stop_bits": 2},
                        "daq": {"driver": "sim"}})"_json);
  EXPECT_EQ(set.fixture->name(), "modbus-rtu");
  EXPECT_EQ(dynamic_cast<const ModbusFixture*>(set.fixture.get())->settings().link.Describe(),
            "/dev/ttyS9 (19200 8N2) unit 1");

  const auto error = [](const nlohmann::json& j) -> std::string {
    try {
      MakeDrivers(j);
    } catch (const io::ConfigError& e) {
      return e.what();
    }
    return "no error";
  };
  EXPECT_EQ(error(R"({"fixture": {"driver": "modbus"}, "daq": {"driver": "sim"}})"_json),
            "/fixture/driver: unknown fixture driver 'modbus' (known: sim, modbus-tcp, "
            "modbus-rtu, socketcan)");
  EXPECT_EQ(error(R"({"fixture": {"driver": "modbus-rtu"}, "daq": {"driver": "sim"}})"_json),
            "/fixture/device: missing (required)");
  EXPECT_EQ(error(R"({"fixture": {"driver": "modbus-tcp", "prot": 5},
                      "daq": {"driver": "sim"}})"_json)
                .rfind("/fixture/prot: unknown field", 0),
            0u);
  EXPECT_EQ(error(R"({"fixture": {"driver": "modbus-tcp", "map": {"lamp": 5}},
                      "daq": {"driver": "sim"}})"_json)
                .rfind("/fixture/map/lamp: unknown fixture signal", 0),
            0u);
  EXPECT_EQ(error(R"({"fixture": {"driver": "modbus-rtu", "device": "/dev/ttyS0",
                                  "parity": "X"}, "daq": {"driver": "sim"}})"_json),
            "/fixture/parity: must be \"N\", \"E\" or \"O\" (got \"X\")");
}

}  // namespace
}  // namespace eol::drivers
