#include "analysis/fit/fit_json.h"

#include <string>

#include "analysis/enum_names.h"
#include "analysis/json_number.h"

namespace eol::analysis {

void to_json(nlohmann::json& j, const Termination& t) { j = ToString(t); }

void from_json(const nlohmann::json& j, Termination& t) {
  t = ParseEnumOrThrow("termination", j.get<std::string>(), kAllTerminations);
}

void to_json(nlohmann::json& j, const FitSummary& s) {
  nlohmann::json params = nlohmann::json::object();
  nlohmann::json names = nlohmann::json::array();
  for (const FittedParameter& p : s.params) {
    params[p.name] = {
        {"value", JsonNumber(p.value)}, {"sigma", JsonNumber(p.sigma)}, {"unit", p.unit}};
    names.push_back(p.name);
  }
  j = {{"model", s.model},
       {"usable", s.usable},
       {"termination", s.termination},
       {"message", s.message},
       {"params", params},
       {"chi2", JsonNumber(s.chi2)},
       {"dof", s.dof},
       {"chi2_per_dof", JsonNumber(s.chi2_per_dof)},
       {"iterations", s.iterations},
       {"sigma_estimated", s.sigma_estimated},
       {"estimated_sigma", JsonNumber(s.estimated_sigma)}};
  if (s.covariance.size() > 0) {
    nlohmann::json matrix = nlohmann::json::array();
    for (Eigen::Index r = 0; r < s.covariance.rows(); ++r) {
      nlohmann::json row = nlohmann::json::array();
      for (Eigen::Index c = 0; c < s.covariance.cols(); ++c)
        row.push_back(JsonNumber(s.covariance(r, c)));
      matrix.push_back(row);
    }
    j["covariance"] = {{"params", names}, {"matrix", matrix}};
  }
}

namespace {
FittedParameter ParamFrom(const std::string& name, const nlohmann::json& p) {
  return {name, p.value("unit", ""), NumberOrNaN(p, "value"), NumberOrNaN(p, "sigma")};
}
}  // namespace

void from_json(const nlohmann::json& j, FitSummary& s) {
  s = FitSummary{};
  s.model = j.value("model", s.model);
  s.usable = j.value("usable", false);
  s.termination = j.at("termination").get<Termination>();
  s.message = j.value("message", "");
  const nlohmann::json params = j.value("params", nlohmann::json::object());
  if (j.contains("covariance")) {
    // The covariance's order is the fit's order of params.
    const nlohmann::json& cov = j.at("covariance");
    const nlohmann::json& names = cov.at("params");
    const nlohmann::json& matrix = cov.at("matrix");
    const auto n = static_cast<Eigen::Index>(names.size());
    if (matrix.size() != names.size())
      throw std::invalid_argument("covariance: " + std::to_string(matrix.size()) + " rows for " +
                                  std::to_string(names.size()) + " params");
    s.covariance.resize(n, n);
    for (Eigen::Index r = 0; r < n; ++r) {
      const nlohmann::json& row = matrix.at(static_cast<std::size_t>(r));
      if (static_cast<Eigen::Index>(row.size()) != n)
        throw std::invalid_argument("covariance: row " + std::to_string(r) + " has " +
                                    std::to_string(row.size()) + " values, not " +
                                    std::to_string(n));
      for (Eigen::Index c = 0; c < n; ++c) {
        const nlohmann::json& v = row.at(static_cast<std::size_t>(c));
        s.covariance(r, c) = v.is_null() ? std::nan("") : v.get<double>();
      }
    }
    for (const nlohmann::json& name : names) {
      const std::string key = name.get<std::string>();
      if (!params.contains(key))
        throw std::invalid_argument("covariance: names parameter '" + key +
                                    "' that is not in params");
      s.params.push_back(ParamFrom(key, params.at(key)));
    }
  } else {
    for (const auto& [name, p] : params.items()) s.params.push_back(ParamFrom(name, p));
  }
  s.chi2 = NumberOrNaN(j, "chi2");
  s.dof = j.value("dof", 0);
  s.chi2_per_dof = NumberOrNaN(j, "chi2_per_dof");
  s.iterations = j.value("iterations", 0);
  s.sigma_estimated = j.value("sigma_estimated", false);
  s.estimated_sigma = j.value("estimated_sigma", 0.0);
}

}  // namespace eol::analysis
