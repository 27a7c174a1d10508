// Production PASS records of one recipe, as `eol export --format records` writes them: the
// golden units the teach and approval tests feed to `eol teach`. Unit i carries every
// measurement the shipped recipe declares, spread a little from unit to unit (f0 388.6-391.4
// Hz, Q 50-52, R 0.500-0.506 ohm, L 2.00-2.02 mH, chi2/dof 1.00-1.04, residue 25.7-26.6 ohm/s,
// second-mode chi2 drop 9-15; the bond index is computed by teach from f0 and the residue).
#pragma once

#include <string>
#include <vector>

#include "db/test_record.h"

namespace eol::testing {

inline std::vector<db::TestRecord> PassRecords(const std::string& recipe_hash, int count) {
  const char* names[] = {"resonance_f_hz",       "resonance_q",      "winding_r_ohm",
                         "winding_l_h",          "fit_chi2_per_dof", "motional_residue_ohm_per_s",
                         "second_mode_chi2_drop"};
  std::vector<db::TestRecord> records;
  for (int i = 0; i < count; ++i) {
    db::TestRecord r;
    r.serial = "SN" + std::to_string(i);
    r.outcome = analysis::Outcome::kPass;
    r.recipe_hash = recipe_hash;
    const double values[] = {390.0 + 0.7 * (i % 5) - 1.4, 50.0 + (i % 3),
                             0.5 + 0.002 * (i % 4),       2e-3 * (1.0 + 0.01 * (i % 2)),
                             1.0 + 0.02 * (i % 3),        25.7 + 0.3 * (i % 4),
                             9.0 + 2.0 * (i % 4)};
    for (int k = 0; k < 7; ++k) {
      analysis::Measurement m;
      m.name = names[k];
      m.value = values[k];
      r.measurements.push_back(m);
    }
    records.push_back(r);
  }
  return records;
}

}  // namespace eol::testing
