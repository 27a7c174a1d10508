// Frequency-response files.
//
// FRF CSV (text_table.h rules: header line, comma-separated numbers, '#' comments), two
// headers, columns in any order, other columns ignored:
//   f_hz,re_ohm,im_ohm[,sigma_ohm]   an impedance Z (Quantity::kImpedanceOhm), ohm
//   f_hz,re,im[,sigma]               a mobility (Quantity::kMobility), e.g. the bench's
//                                    j w Theta / I in rad/s/A
// sigma is the standard deviation of the complex estimate (E|dZ|^2 = sigma^2, so Re and Im
// each have variance sigma^2 / 2); without the column the Frf has no sigma. An optional
// column sigma_dof (with sigma) gives the degrees of freedom of each line's sigma^2 when sigma
// was estimated (2 (P - 1) for P periods, times the lines pooled): one value for the whole
// file, above 4 (0 on every line: sigma exact).
//
// ZMA (loudspeaker-tool impedance text): per line "frequency |Z| phase" (Hz, ohm, degrees),
// separated by spaces, tabs or commas; lines starting with '*' and blank lines are ignored;
// extra columns are ignored. Z = |Z| exp(j phase). No sigma.
//
// Every reader checks the Frf invariants and throws FileError naming file, line and column:
// a field that is not a finite number, a missing column, frequencies not positive and strictly
// increasing, |Z| negative, sigma not positive, sigma_dof without sigma, in (0, 4] or not
// the same on every line, an empty file. Gzip-compressed input is read
// as well. Writers throw FileError when the file cannot be written.
#pragma once

#include <string>

#include "analysis/frf.h"

namespace eol::io {

// sigma_dof (may be null): the file's sigma_dof column, 0 without one.
analysis::Frf ReadFrfCsv(const std::string& path, double* sigma_dof = nullptr);
// Impedance header for kImpedanceOhm, the plain one otherwise; sigma column when present,
// sigma_dof column when sigma_dof > 0 (and the Frf has sigma).
void WriteFrfCsv(const std::string& path, const analysis::Frf& frf, double sigma_dof = 0.0);

analysis::Frf ReadZma(const std::string& path);
void WriteZma(const std::string& path, const analysis::Frf& z);

}  // namespace eol::io
