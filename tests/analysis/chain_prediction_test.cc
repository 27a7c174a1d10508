// analysis/model/chain_prediction.h on the ten-pole chain (rotor_chain.h's calibration).
#include "analysis/model/chain_prediction.h"

#include <gtest/gtest.h>

#include <iostream>

namespace eol::analysis {
namespace {

TEST(ChainPrediction, TenPoleChainGivesItsModesAndDefectDirection) {
  const ChainPrediction p = PredictChain(0.5, 2e-3, 0.05 * std::sin(5 * 18 * M_PI / 180), {});
  std::cout << "good " << p.good.f0_hz << " Hz Q " << p.good.q << " Rp " << p.good.rp_ohm
            << "; half soft " << p.half_soft.f0_hz << "; all soft " << p.all_soft.f0_hz
            << "; residue_to_f0 " << p.residue_to_f0 << " at loss " << p.direction_loss << "\n";
  EXPECT_NEAR(p.good.f0_hz, 390.0, 1.0);
  EXPECT_NEAR(p.all_soft.f0_hz, 366.0, 2.0);
  EXPECT_LT(p.half_soft.f0_hz, p.good.f0_hz);
  EXPECT_GT(p.half_soft.f0_hz, p.all_soft.f0_hz);
  // bond_index.h: A rises about twelve times faster than f0 falls on this motor.
  EXPECT_GT(p.residue_to_f0, 8.0);
  EXPECT_LT(p.residue_to_f0, 16.0);
  EXPECT_NEAR(p.total_inertia_kg_m2, 1.0e-4, 1e-9);
}

TEST(ChainPrediction, RefusesAMotorWhoseTorqueExcitesNoMode) {
  try {
    PredictChain(0.5, 2e-3, 0.0, {});  // no torque constant: no motional impedance
    FAIL() << "no throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("no mode the torque excites"), std::string::npos)
        << e.what();
  }
  RotorChainParams rotor;
  rotor.magnets = 0;
  EXPECT_THROW(PredictChain(0.5, 2e-3, 0.05, rotor), std::invalid_argument);
}

}  // namespace
}  // namespace eol::analysis
