// The printable report of one tested unit, as PDF through cairo (A4, `eol report`, GET
// /api/units/{serial}/report.pdf):
//   page 1: the serial and the verdict (large, coloured), the test (id, retest of), recipe
//           (id, version, SHA-256), station, operator, shift and order, start and end times,
//           the software that tested it and the one that printed the report; the reasons;
//           every measurement with its value, unit, limits and outcome; the teardown findings
//           of the serial (each with who and when), when there are any;
//   page 2: the stored impedance curve with the fitted model, the resonance window and, when
//           the caller has the test's recipe (same hash), its masks
//           (station/reports/curve_chart.h); a test that stored no curve says so instead.
// Text is drawn as text (cairo's PDF surface embeds the font with its Unicode map), so
// `pdftotext` or a screen reader finds the serial and the verdict.
#pragma once

#include <string>
#include <vector>

#include "analysis/qc/curve_mask.h"
#include "db/store.h"

namespace eol::station {

struct UnitReport {
  db::TestRecord test;                       // with its curves
  std::vector<db::TeardownEntry> teardowns;  // the serial's findings, oldest first
  std::vector<analysis::CurveMask> masks;    // the test's recipe's masks; empty: not drawn
  std::string masks_note;                    // why masks are not drawn (empty when they are)
  std::string printed_at;                    // ISO 8601 UTC
  std::string printed_by_software;           // station/daemon/version.h SoftwareVersion()
};

// The PDF's bytes. Throws std::runtime_error when cairo fails.
std::string RenderUnitReportPdf(const UnitReport& report);

// The report of `serial`'s test `test_id` (0: its newest finished test) from `store`, its
// teardown findings, and masks when `recipe_masks_hash` is the test's recipe hash.
// Throws std::out_of_range naming the serial (and id) when there is no such test.
UnitReport LoadUnitReport(db::Store& store, const std::string& serial, std::int64_t test_id,
                          const std::string& recipe_masks_hash,
                          const std::vector<analysis::CurveMask>& recipe_masks);

}  // namespace eol::station
