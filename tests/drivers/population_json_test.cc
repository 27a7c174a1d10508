// The population's one field list (analysis/sim/population.h kPopulationNumbers): complete,
// round-tripped by to_json/from_json, and the station's sim config reads what it writes.
#include <gtest/gtest.h>

#include "analysis/sim/population.h"
#include "drivers/factory/factory.h"
#include "drivers/io/json_config.h"

namespace eol::drivers {
namespace {

using analysis::MotorPopulation;

// A population with every listed field moved off its default to a distinct value.
MotorPopulation Distinct() {
  MotorPopulation p;
  double bump = 1.0;
  for (const analysis::PopulationNumber& f : analysis::kPopulationNumbers)
    p.*f.member *= 1.0 + 0.01 * bump++;
  p.seed = 42;
  return p;
}

void ExpectSame(const MotorPopulation& a, const MotorPopulation& b) {
  for (const analysis::PopulationNumber& f : analysis::kPopulationNumbers)
    EXPECT_EQ(a.*f.member, b.*f.member) << f.key;
  EXPECT_EQ(a.seed, b.seed);
}

TEST(PopulationJson, TheListHoldsEveryField) {
  // A member added to MotorPopulation but not to the list changes the size: this fails.
  EXPECT_EQ(sizeof(MotorPopulation),
            analysis::kPopulationNumbers.size() * sizeof(double) + sizeof(std::uint64_t));
  for (std::size_t i = 0; i < analysis::kPopulationNumbers.size(); ++i)
    for (std::size_t k = 0; k < i; ++k)
      EXPECT_NE(analysis::kPopulationNumbers[i].member, analysis::kPopulationNumbers[k].member)
          << analysis::kPopulationNumbers[i].key;
}

TEST(PopulationJson, RoundTripsAndTheSimConfigReadsWhatIsWritten) {
  const MotorPopulation p = Distinct();
  const nlohmann::json j = nlohmann::json::parse(nlohmann::json(p).dump());
  ExpectSame(j.get<MotorPopulation>(), p);
  ExpectSame(ParsePopulation(io::JsonObject(j, "/sim/population")), p);
}

TEST(PopulationJson, TheSimConfigRefusesAnUnknownKeyByPath) {
  nlohmann::json j = MotorPopulation{};
  j["q_god"] = 50.0;
  try {
    (void)ParsePopulation(io::JsonObject(j, "/sim/population"));
    FAIL() << "an unknown key was accepted";
  } catch (const io::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/sim/population/q_god"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace eol::drivers
