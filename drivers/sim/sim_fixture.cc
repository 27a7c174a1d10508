#include "drivers/sim/sim_fixture.h"

namespace eol::drivers {

SimFixture::SimFixture(std::shared_ptr<SimBench> bench)
    : Fixture("sim"), bench_(std::move(bench)) {}

}  // namespace eol::drivers
