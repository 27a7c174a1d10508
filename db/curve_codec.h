// Compact binary form of a stored curve (schema v6, curves.encoding = 'binary-v1').
//
// Why: the zlib-compressed JSON of schema v1 spends about 30 bytes per line (decimal text of
// doubles does not compress); a curve is a line grid and three numbers per line, and a float32
// keeps 7 digits, four orders below a measurement's sigma. For the shipped 5 s recipe's 601
// lines the impedance curve falls from 17.8 KB to 7.2 KB and the model from 11.8 KB to 4.8 KB.
//
// Layout (little-endian):
//   "EOLC"                    magic
//   u8  version (1)
//   u8  flags: bit 0 sigma present, bit 1 grid stored as (first, step), bit 2 values as float64
//   u16 unit length, unit bytes (UTF-8)
//   u32 n (lines, 1 .. kMaxCurveLines)
//   grid: f64 first, f64 step            (bit 1)   or   n x f64
//   re[n], im[n], then sigma[n] if bit 0: float32 each, or all float64 (bit 2)
//
// What is kept, by construction (EncodeCurve checks and falls back, never loses more):
//   - the grid as (first, step) only when every line's frequency is within 1e-9 of its own
//     value (relative); otherwise every frequency as float64, exactly;
//   - re and im as float32 only when each line's rounding error is at most 1e-3 of that
//     line's sigma (curves with a sigma) or 1e-6 of the value's magnitude (without); otherwise
//     all values as float64, exactly. sigma likewise to 1e-6 of itself (float32 keeps 6e-8 in
//     its range; a sigma beyond it, zero-crossing or not finite means float64 for all).
// So re-fitting or re-judging a stored curve differs from the original by at most a thousandth
// of a standard deviation.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "db/test_record.h"

namespace eol::db {

inline constexpr std::size_t kMaxCurveLines = 1000000;

// The encoded bytes; curve.name is not part of them (the curves table has its own column).
// Throws std::invalid_argument for a curve whose arrays disagree in length, that has no lines
// or more than kMaxCurveLines, or a unit longer than 65535 bytes.
std::string EncodeCurve(const Curve& curve);

// The curve (named `name`) from EncodeCurve's bytes. Throws std::invalid_argument naming what
// is wrong for bytes that are not such a curve (bad magic or version, truncated, trailing
// bytes, a line count beyond the limit).
Curve DecodeCurve(std::string_view bytes, const std::string& name);

}  // namespace eol::db
