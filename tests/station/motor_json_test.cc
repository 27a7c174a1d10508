// The motor file (drivers/io/motor_json.h): the shipped examples parse and build the
// calibrated chain, the canonical JSON round-trips, and errors name the JSON path.
#include "drivers/io/motor_json.h"

#include <gtest/gtest.h>

#include "drivers/io/json_config.h"

namespace eol::io {
namespace {

const std::string kMotors = std::string(EOL_SOURCE_DIR) + "/recipes/motors/";

std::string ErrorOf(const nlohmann::json& j) {
  try {
    ParseMotorJson(j, "m.json");
  } catch (const io::ConfigError& e) {
    return e.what();
  }
  return "no error";
}

nlohmann::json Minimal() {
  return {{"id", "m"},
          {"electrical", {{"r_ohm", 0.5}, {"l_h", 2e-3}}},
          {"transducer", {{"t_hat_nm_per_a", 0.05}, {"poles", 10}}}};
}

TEST(MotorJson, ShippedExamplesBuildTheCalibratedChain) {
  const MotorSpec fixture = LoadMotorJson(kMotors + "pmsm-10pole.json");
  EXPECT_NEAR(fixture.Motor().chain.Modes()[0].f_hz, 390.0, 0.4);
  EXPECT_NEAR(fixture.TransmissionNmPerA(), 0.05, 1e-12);
  const MotorSpec rigid = LoadMotorJson(kMotors + "pmsm-10pole-rigid.json");
  EXPECT_FALSE(rigid.rotor.fixture.has_value());
  EXPECT_NEAR(rigid.Motor().chain.Modes()[0].f_hz, 706.0, 0.7);
}

TEST(MotorJson, DefaultsAndRoundTrip) {
  const MotorSpec m = ParseMotorJson(Minimal(), "m.json");
  EXPECT_EQ(m.rotor.magnets, 10);
  EXPECT_NEAR(m.rotor_position_deg, 18.0, 1e-12);  // full coupling: 90 / p
  EXPECT_TRUE(m.rotor.fixture.has_value());
  const nlohmann::json canonical = ToJson(m);
  EXPECT_EQ(ToJson(ParseMotorJson(canonical, "canonical")), canonical);
  EXPECT_NEAR(m.TransmissionNmPerA(36.0), 0.0, 1e-15);
}

TEST(MotorJson, EffectsPassThroughRaw) {
  nlohmann::json j = Minimal();
  j["effects"] = nlohmann::json::array({{{"type", "eddy"}, {"l2_h", 1e-4}}});
  const MotorSpec m = ParseMotorJson(j, "m.json");
  ASSERT_EQ(m.effects.size(), 1u);
  EXPECT_EQ(m.effects[0]["type"], "eddy");
}

TEST(MotorJson, ErrorsNameThePath) {
  nlohmann::json j = Minimal();
  j["rotor"] = {{"bond", {{"stiffness_nm_per_rad", -3}}}};
  EXPECT_NE(ErrorOf(j).find("motor m.json: /rotor/bond/stiffness_nm_per_rad: must be positive"),
            std::string::npos)
      << ErrorOf(j);
  j = Minimal();
  j["rotor"] = {{"soft_magnets", {12}}};
  EXPECT_NE(ErrorOf(j).find("/rotor/soft_magnets/0: must be a magnet index"), std::string::npos)
      << ErrorOf(j);
  j = Minimal();
  j["transducer"]["transmission_nm_per_a"] = 0.05;
  EXPECT_NE(ErrorOf(j).find("/transducer: give either"), std::string::npos) << ErrorOf(j);
  j = Minimal();
  j["fixture"] = {{"stifness_nm_per_rad", 900}};
  EXPECT_NE(ErrorOf(j).find("/fixture/stifness_nm_per_rad: unknown field"), std::string::npos)
      << ErrorOf(j);
  j = Minimal();
  j["transducer"] = {{"transmission_nm_per_a", 0.05}};
  const MotorSpec direct = ParseMotorJson(j, "m.json");
  EXPECT_THROW(direct.TransmissionNmPerA(10.0), io::ConfigError);
}

}  // namespace
}  // namespace eol::io
