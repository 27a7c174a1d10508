// The fixture contract (tests/support/fixture_contract.h) run against the sim fixture
// in-process and the Modbus TCP fixture against its emulator (ModbusFixtureServer) on
// 127.0.0.1, on a free port. The CAN fixture runs it in tests/can/, under the vcan stand-in.
#include "tests/support/fixture_contract.h"

#include <memory>
#include <stdexcept>
#include <string>

#include "drivers/emulators/modbus_fixture_server.h"
#include "drivers/fixture/modbus_fixture.h"
#include "drivers/sim/sim_fixture.h"

namespace eol::testing {
namespace {

using drivers::SimBench;

class SimUnderTest final : public FixtureUnderTest {
 public:
  explicit SimUnderTest(std::shared_ptr<SimBench> bench) : fixture_(std::move(bench)) {}
  drivers::Fixture& fixture() override { return fixture_; }
  std::string device() const override { return "no answer from the fixture controller"; }

 private:
  drivers::SimFixture fixture_;
};

class ModbusUnderTest final : public FixtureUnderTest {
 public:
  explicit ModbusUnderTest(std::shared_ptr<SimBench> bench) {
    drivers::ModbusFixtureServerSettings s;
    s.link.port = 0;  // a free port
    server_ = std::make_unique<drivers::ModbusFixtureServer>(std::move(bench), s);
    const drivers::Status started = server_->Start();
    if (!started.ok()) throw std::runtime_error(started.message());
    drivers::ModbusFixtureSettings c;
    c.link.host = "127.0.0.1";
    c.link.port = server_->port();
    c.response_timeout_ms = 100;
    c.attempts = 2;
    c.backoff_initial_ms = 10;
    c.backoff_max_ms = 40;
    fixture_ = std::make_unique<drivers::ModbusFixture>(c);
  }
  drivers::Fixture& fixture() override { return *fixture_; }
  std::string device() const override {
    return "at 127.0.0.1:" + std::to_string(server_->port()) + " unit 1: ";
  }

 private:
  std::unique_ptr<drivers::ModbusFixtureServer> server_;  // outlives the driver
  std::unique_ptr<drivers::ModbusFixture> fixture_;
};

INSTANTIATE_TEST_SUITE_P(
    Backends, FixtureContractTest,
    ::testing::Values(FixtureBackend{"Sim",
                                     [](std::shared_ptr<SimBench> bench) {
                                       return std::unique_ptr<FixtureUnderTest>(
                                           new SimUnderTest(std::move(bench)));
                                     }},
                      FixtureBackend{"ModbusTcp",
                                     [](std::shared_ptr<SimBench> bench) {
                                       return std::unique_ptr<FixtureUnderTest>(
                                           new ModbusUnderTest(std::move(bench)));
                                     }}),
    BackendName);

}  // namespace
}  // namespace eol::testing
