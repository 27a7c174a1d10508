// The conditions of one test (the record's "conditions" object): what the station measured or
// decided about the test itself, beside the motor's measurements. One typed field per key; the
// only place that maps them to and from JSON is test_conditions.cc (to_json / from_json).
//
// Key (JSON)              field type     unit   written by
//   clamp_pressure_bar      double         bar    Sequencer::ClampAndConfirm, the pressure read
//                                                 at clamp confirmation (`eol analyze
//                                                 --clamp-pressure-bar` offline). The judge's
//                                                 resonance_f_ref_pressure_hz and the teach's
//                                                 golden units read it (analysis/qc/f0_pressure.h).
//   phase_pair              int            -      Sequencer::ClampAndConfirm: the first pair
//                                                 excited, 0 U-V, 1 V-W, 2 W-U (the page names it).
//   excitation_peak_v       double         V      Sequencer::ExciteAndRecord: the recipe's peak.
//   crest_factor            double         1      ExciteAndRecord: peak / rms of one period.
//   line_spacing_hz         double         Hz     ExciteAndRecord: the multisine's line spacing.
//   sample_rate_hz          double         Hz     ExciteAndRecord: the DAQ's sample rate.
//   clamp_pressure_min_bar  double         bar    Sequencer::RecordWatchdog: lowest / highest
//   clamp_pressure_max_bar  double         bar    pressure from right before the relay closed
//                                                 through the last excitation's watchdog reads.
//   watchdog_max_gap_ms     double         ms     RecordWatchdog: the watchdog loop's longest
//                                                 gap, the largest over the test's excitations.
//   analysis_overlapped_s   double         s      Sequencer::MeasurePairs, only with more than
//                                                 one phase pair: analysis hidden behind a later
//                                                 pair's excitation.
//   periods_used            unsigned int   -      MeasurePairs: periods the last pair's FRF
//                                                 averaged (analysis/signal/periodic_frf.h).
//   looks, looks@<pair>     int            -      Sequencer::ExtendWhileUndecided, only with a
//   undecided, undecided@<pair>  [string]         "sequential" recipe: see PairLooks.
//   excitation_v_rms        double         V rms  EvaluateConditions (station/daemon/conditions.h)
//   excitation_a_rms        double         A rms  whenever a recording is judged.
//   winding_temperature_c   double         degC   EvaluateConditions, with the recipe's r_ref_ohm
//                                                 and a finite fitted R.
//   conditions_in_window    bool           -      EvaluateConditions / JudgeUnit, only when the
//                                                 recipe has a "conditions" section: every
//                                                 pair's conditions inside their windows.
//   simulation              string         -      Sequencer::RunTest on simulators: why (the
//                                                 SIMULATION banner; the export's "simulated").
//   variant, variant_by     string         -      Sequencer::RunTest on a station of variants
//                                                 (station/daemon/variants.h): the variant's name
//                                                 and how it was picked ("operator", "plc code 2",
//                                                 "prefix 'P10-'"); absent with one recipe.
//
// Every field is optional: absent in the record's JSON when unset, as not every test writes
// every key (a test that ends in ERROR before its excitation has only the first few). A double
// that is not finite (an rms of nothing) is written as JSON null.
//
// Reading (from_json) never throws for an object: a key whose value has not the field's type
// (a null, a string where a number belongs, a negative periods_used) and every key this list
// does not know are kept verbatim in `extra`, so an old or foreign record survives a read and
// write unchanged and its readers see the field unset, as the JSON readers before this type
// did (they checked is_number() / is_string()). A typed field that is set wins over the same
// key in `extra` when written. A "conditions" that is not an object (nor null) is refused
// with nlohmann::json::type_error naming "conditions".
#pragma once

#include <cstddef>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace eol::db {

// One phase pair's sequential looks (recipe "sequential", station/daemon/recipe.h
// SequentialPolicy), written as "looks<suffix>" and "undecided<suffix>" where the suffix is the
// pair's, as in measurement names: "" for the recipe's first pair, "@V-W" for a further one.
struct PairLooks {
  std::optional<int> looks;  // recordings of the pair combined: 1, or 1 + extensions
  // The measurement names (with the pair's suffix) found undecided at each look, in order;
  // written only when some were (the sequencer never writes an empty list).
  std::optional<std::vector<std::string>> undecided;
  bool operator==(const PairLooks&) const = default;
};

struct TestConditions {
  std::optional<double> clamp_pressure_bar;
  std::optional<int> phase_pair;
  std::optional<double> excitation_peak_v;
  std::optional<double> crest_factor;
  std::optional<double> line_spacing_hz;
  std::optional<double> sample_rate_hz;
  std::optional<double> clamp_pressure_min_bar;
  std::optional<double> clamp_pressure_max_bar;
  std::optional<double> watchdog_max_gap_ms;
  std::optional<double> analysis_overlapped_s;
  std::optional<std::size_t> periods_used;
  std::map<std::string, PairLooks> looks;  // key: the pair's suffix ("", "@V-W", ...)
  std::optional<double> excitation_v_rms;
  std::optional<double> excitation_a_rms;
  std::optional<double> winding_temperature_c;
  std::optional<bool> conditions_in_window;
  std::optional<std::string> simulation;
  std::optional<std::string> variant;
  std::optional<std::string> variant_by;
  // Keys of a read record that no field above took (see the head of this file); an object.
  nlohmann::json extra = nlohmann::json::object();
  bool operator==(const TestConditions&) const = default;
};

void to_json(nlohmann::json& j, const TestConditions& c);
// Null reads as no conditions; any other non-object throws nlohmann::json::type_error.
void from_json(const nlohmann::json& j, TestConditions& c);

}  // namespace eol::db
