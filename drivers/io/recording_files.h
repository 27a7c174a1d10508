// Raw recordings: voltage and current sample streams (analysis::Recording).
//
// Recording CSV (text_table.h rules), header t_s,u_v,i_a (columns in any order, others
// ignored): time in s, voltage in V, current in A. The sampling must be uniform: with
// dt = (t_last - t_first) / (n - 1), every t_k must lie within 1 % of dt of t_first + k dt
// (times printed with a few decimals pass), else FileError names the first line off the grid.
// sample_rate_hz = 1 / dt, snapped to the nearest integer when within 1e-6 of it; FileError
// when dt or 1 / dt is not finite (times near the ends of double's range).
// Optional columns u_full_scale_v and i_full_scale_a state the converter's full scale of
// each channel (one positive value, the same in every row; FileError otherwise): samples at
// it count as clipped. Without them the full scales are 0 (unknown) and clipping is found
// from samples repeated at a rail (analysis/signal/clipping.h). period_samples is left 0
// (the caller knows the excitation).
//
// Two-channel WAV (libsndfile; any PCM or float encoding): channel 1 is the voltage, channel 2
// the current, as fractions of the converter's full scale (integer formats are normalised to
// [-1, 1) by libsndfile). Gains turn them into physical units: u = voltage_gain_v * ch1,
// i = current_gain_a * ch2; the full scales of the Recording are the gains, so samples at the
// converter's limit count as clipped. FileError (no line numbers) when the file cannot be
// opened, is not two-channel, is empty, or holds a sample that is not finite (frame named).
#pragma once

#include <string>

#include "analysis/signal/recording.h"

namespace eol::io {

analysis::Recording ReadRecordingCsv(const std::string& path);
void WriteRecordingCsv(const std::string& path, const analysis::Recording& recording);

analysis::Recording ReadWavRecording(const std::string& path, double voltage_gain_v,
                                     double current_gain_a);
// 32-bit float WAV at the recording's (integer) sample rate, ch1 = u / voltage_gain_v,
// ch2 = i / current_gain_a.
void WriteWavRecording(const std::string& path, const analysis::Recording& recording,
                       double voltage_gain_v, double current_gain_a);

// By extension: *.wav (any case) with the gains, anything else as a recording CSV (the gains
// unused). The replay acquisition driver reads its files through this.
analysis::Recording ReadRecordingFile(const std::string& path, double voltage_gain_v,
                                      double current_gain_a);

}  // namespace eol::io
