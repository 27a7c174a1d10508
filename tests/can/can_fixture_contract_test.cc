// The fixture contract (tests/support/fixture_contract.h) run against the CAN fixture driver
// and the CAN fixture node (the emulator behind `eol fixture-sim --can`), both in-process,
// over a real SocketCAN interface (EOL_CAN_INTERFACE; ctest runs this under
// tests/support/vcan/with-vcan).
#include <memory>
#include <stdexcept>
#include <string>

#include "drivers/emulators/can_fixture_node.h"
#include "drivers/fixture/can_fixture.h"
#include "tests/support/fixture_contract.h"

namespace eol::testing {
namespace {

constexpr const char* kInterface = EOL_CAN_INTERFACE;

class CanUnderTest final : public FixtureUnderTest {
 public:
  explicit CanUnderTest(std::shared_ptr<drivers::SimBench> bench) {
    drivers::CanFixtureNodeSettings n;
    n.interface = kInterface;
    node_ = std::make_unique<drivers::CanFixtureNode>(std::move(bench), n);
    const drivers::Status started = node_->Start();
    if (!started.ok()) throw std::runtime_error(started.message());
    drivers::CanFixtureSettings c;
    c.interface = kInterface;
    // The status timeout is how long a silent node takes to be noticed; the others are
    // generous, so that a loaded machine never trips them.
    c.status_timeout_ms = 500;
    c.heartbeat_timeout_ms = 3000;
    c.confirm_timeout_ms = 1000;
    c.connect_timeout_ms = 5000;
    fixture_ = std::make_unique<drivers::CanFixture>(c);
  }
  drivers::Fixture& fixture() override { return *fixture_; }
  std::string device() const override { return "from node 1 on " + std::string(kInterface); }

 private:
  std::unique_ptr<drivers::CanFixtureNode> node_;  // outlives the driver
  std::unique_ptr<drivers::CanFixture> fixture_;
};

INSTANTIATE_TEST_SUITE_P(Backends, FixtureContractTest,
                         ::testing::Values(FixtureBackend{
                             "SocketCan",
                             [](std::shared_ptr<drivers::SimBench> bench) {
                               return std::unique_ptr<FixtureUnderTest>(
                                   new CanUnderTest(std::move(bench)));
                             }}),
                         BackendName);

}  // namespace
}  // namespace eol::testing
