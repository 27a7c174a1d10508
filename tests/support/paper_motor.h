// The paper's ten-pole motor in the regime of analysis/README.md 2 (f0 = 390 Hz, Q = 50), shared by
// the tests of the paper's network and of its identification route.
#pragma once

#include <numbers>

#include "analysis/model/pmsm_network.h"

namespace eol::analysis::testing {

inline PmsmParams PaperMotor() {
  PmsmParams p;
  p.r_ohm = 0.5;
  p.l_h = 2e-3;
  p.transmission_nm_per_a = 0.05;
  p.inertia_kg_m2 = 1e-4;
  const double w0 = 2 * std::numbers::pi * 390.0;
  p.compliance_rad_per_nm = 1.0 / (p.inertia_kg_m2 * w0 * w0);
  p.damping_nms_per_rad = p.inertia_kg_m2 * w0 / 50.0;
  return p;
}

}  // namespace eol::analysis::testing
