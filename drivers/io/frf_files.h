// Frequency-response files.
//
// FRF CSV (text_table.h rules: header line, comma-separated numbers, '#' comments), two
// headers, columns in any order, other columns ignored:
//   f_hz,re_ohm,im_ohm[,sigma_ohm]   an impedance Z (Quantity::kImpedanceOhm), ohm
//   f_hz,re,im[,sigma]               a mobility (Quantity::kMobility), e.g. the bench's
//                                    j w Theta / I in rad/s/A
// sigma is the standard deviation of the complex estimate (E|dZ|^2 = sigma^2, so Re and Im
// each have variance sigma^2 / 2); without the column the Frf has no sigma.
//
// ZMA (loudspeaker-tool impedance text): per line "frequency |Z| phase" (Hz, ohm, degrees),
// separated by spaces, tabs or commas; lines starting with '*' and blank lines are ignored;
// extra columns are ignored. Z = |Z| exp(j phase). No sigma.
//
// Every reader checks the Frf invariants and throws FileError naming file, line and column:
// a field that is not a finite number, a missing column, frequencies not positive and strictly
// increasing, |Z| negative, sigma not positive, an empty file. Gzip-compressed input is read
// as well. Writers throw FileError when the file cannot be written.
#pragma once

#include <string>

#include "analysis/frf.h"

namespace eol::io {

analysis::Frf ReadFrfCsv(const std::string& path);
// Impedance header for kImpedanceOhm, the plain one otherwise; sigma column when present.
void WriteFrfCsv(const std::string& path, const analysis::Frf& frf);

analysis::Frf ReadZma(const std::string& path);
void WriteZma(const std::string& path, const analysis::Frf& z);

}  // namespace eol::io
