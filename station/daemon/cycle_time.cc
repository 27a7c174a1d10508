#include "station/daemon/cycle_time.h"

#include <utility>

namespace eol::station {

std::string_view CycleStepOf(std::string_view state) {
  static constexpr std::pair<std::string_view, std::string_view> kSteps[] = {
      {"wait_serial", "start"},     {"check_interlocks", "interlocks"},
      {"clamp", "clamp"},           {"confirm_clamp", "clamp"},
      {"excite", "excitation"},     {"analyse", "analysis"},
      {"judge", "judge"},           {"unclamp", "unclamp"},
      {"safe_state", "safe_state"}, {"store", "store"},
      {"publish", "publish"}};
  for (const auto& [s, step] : kSteps)
    if (s == state) return step;
  return "";
}

std::map<std::string, double> CycleBreakdown(const std::vector<db::StateEntry>& trace,
                                             double end_ms) {
  std::map<std::string, double> out;
  for (std::size_t i = 0; i < trace.size(); ++i) {
    const double until = i + 1 < trace.size() ? trace[i + 1].t_ms : end_ms;
    const std::string_view step = CycleStepOf(trace[i].state);
    if (step.empty()) continue;
    const double from = i == 0 ? 0.0 : trace[i].t_ms;  // the clock starts before the entry
    out[std::string(step)] += std::max(0.0, until - from) / 1000.0;
  }
  out["total"] = end_ms / 1000.0;
  return out;
}

double CycleStepS(const std::map<std::string, double>& cycle_s, const char* step) {
  const auto it = cycle_s.find(step);
  return it == cycle_s.end() ? 0.0 : it->second;
}

double StationOverheadS(const std::map<std::string, double>& cycle_s) {
  return CycleStepS(cycle_s, "total") - CycleStepS(cycle_s, "clamp") -
         CycleStepS(cycle_s, "excitation") - CycleStepS(cycle_s, "unclamp");
}

}  // namespace eol::station
