// POST /api/pod.svg and POST /api/gap.svg against the real station over HTTP: the figure the
// API draws from uploaded files is byte for byte the one `eol pod --pod-svg` and `eol gap
// --plot` write from the same files (one drawing code, station/reports/pod_chart.h and
// station/reports/gap_diagnosis.h), with the expected series; malformed input is 400 naming the
// cause; with tokens only engineers may ask; bodies are bounded per route.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

#include "drivers/io/frf_files.h"
#include "tests/support/child_process.h"
#include "tests/support/eol_cli.h"
#include "tests/support/gap_units.h"
#include "tests/support/raw_client.h"
#include "tests/support/station_ready.h"
#include "tests/support/token_station.h"

// After Eigen: <resolv.h> (through httplib) defines _res, a parameter name in Eigen.
#include <httplib.h>

namespace eol {
namespace {

using namespace std::chrono_literals;
using eol::testing::ChildProcess;

// The station's two tokens (tests/support/token_station.h): an operator's and an engineer's.
constexpr char kOperator[] = "figures-operator-token-0123";
constexpr char kEngineer[] = "figures-engineer-token-0123";

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string ErrorCode(const httplib::Result& res) {
  return nlohmann::json::parse(res->body)["error"]["code"];
}
std::string ErrorMessage(const httplib::Result& res) {
  return nlohmann::json::parse(res->body)["error"]["message"];
}

// A hits table as population_rejects.py writes it: defective units whose chance of being
// rejected rises with the defect size, good units (size 0) with their fitted f0. `good` rows
// pad the file beyond the ordinary 64 KiB body limit.
std::string HitsCsv(int defective, int good) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> f0(390.0, 2.0);
  std::ostringstream out;
  out << "class,size,hit,f0_hz\n";
  for (int i = 0; i < defective; ++i) {
    const double a = 0.02 + 0.5 * u(rng);
    const double pod = 1.0 / (1.0 + std::exp(-(a - 0.2) / 0.03));
    out << "one_magnet," << a << "," << (u(rng) < pod ? 1 : 0) << "," << 390.0 - 60.0 * a << "\n";
  }
  for (int i = 0; i < good; ++i) out << "good,0,0," << f0(rng) << "\n";
  return out.str();
}

class FigureApi : public ::testing::Test {
 protected:
  void SetUp() override {
    std::filesystem::copy_file(std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json",
                               dir_ / "pmsm-10pole.json");
    std::ofstream(dir_ / "station.json")
        << testing::TokenStationConfig("figures", "pmsm-10pole.json", kOperator, kEngineer).dump();
    station_ = std::make_unique<ChildProcess>(
        std::vector<std::string>{EOL_BINARY, "station", "--config", dir_ / "station.json"});
    ASSERT_TRUE(station_->WaitFor(
        [](const std::string& o) { return testing::PortFromReadyLine(o) > 0; }, 30s))
        << station_->output();
    http_ = std::make_unique<httplib::Client>("127.0.0.1",
                                              testing::PortFromReadyLine(station_->output()));
    http_->set_read_timeout(300, 0);
  }

  httplib::Result Post(const std::string& path, const nlohmann::json& body,
                       const char* token = kEngineer) {
    return PostText(path, body.dump(), token);
  }
  httplib::Result PostText(const std::string& path, const std::string& body,
                           const char* token = kEngineer) {
    httplib::Headers headers;
    if (token) headers.emplace("Authorization", std::string("Bearer ") + token);
    return http_->Post(path, headers, body, "application/json");
  }

  // With tokens: 401 without one, 403 for an operator; an engineer gets image/svg+xml, byte
  // for byte the file the command wrote (`cli_svg`), holding every one of `words`. Returns it.
  std::string ExpectTheCommandsFigure(const std::string& path, const nlohmann::json& body,
                                      const std::string& cli_svg,
                                      const std::vector<std::string>& words) {
    auto res = Post(path, body, nullptr);
    EXPECT_TRUE(res && res->status == 401) << path;
    res = Post(path, body, kOperator);
    EXPECT_TRUE(res && res->status == 403) << path;
    res = Post(path, body);
    EXPECT_TRUE(res && res->status == 200) << path << ": " << (res ? res->body : "no answer");
    if (!res || res->status != 200) return "";
    EXPECT_EQ(res->get_header_value("Content-Type"), "image/svg+xml");
    const std::string cli = ReadText(cli_svg);
    const auto differ = std::mismatch(cli.begin(), cli.end(), res->body.begin(), res->body.end());
    EXPECT_TRUE(res->body == cli) << path << ": the API and the CLI draw differently ("
                                  << res->body.size() << " and " << cli.size()
                                  << " bytes; from byte " << (differ.first - cli.begin())
                                  << " the CLI has '"
                                  << std::string(differ.first,
                                                 std::min(differ.first + 80, cli.end()))
                                  << "')";
    for (const std::string& w : words)
      EXPECT_NE(res->body.find(w), std::string::npos) << path << ": '" << w << "' is not drawn";
    return res->body;
  }

  // A 400 with this error code whose message says `says`.
  void Expect400(const std::string& path, const nlohmann::json& body, const std::string& code,
                 const std::string& says) {
    const auto res = Post(path, body);
    ASSERT_TRUE(res);
    EXPECT_EQ(res->status, 400) << body.dump().substr(0, 200);
    EXPECT_EQ(ErrorCode(res), code) << res->body;
    EXPECT_NE(ErrorMessage(res).find(says), std::string::npos) << res->body;
  }

  eol::testing::TempDir dir_;
  std::unique_ptr<ChildProcess> station_;
  std::unique_ptr<httplib::Client> http_;
};

TEST_F(FigureApi, PodSvgIsTheFigureOfEolPod) {
  const std::string hits = dir_ / "hits.csv";
  const std::string csv = HitsCsv(120, 5000);
  ASSERT_GT(csv.size(), 64u * 1024) << "the body must exceed the ordinary 64 KiB limit";
  std::ofstream(hits) << csv;
  const testing::CliRun cli = testing::RunEol({"pod", "--hits", hits, "--pod-svg", dir_ / "cli.svg",
                                               "--f0-limit", "370", "--f0-limit", "420"},
                                              true, 120s);
  ASSERT_EQ(cli.code, 0) << cli.out;

  const nlohmann::json body = {{"hits_csv", csv}, {"name", hits}, {"f0_limits_hz", {370, 420}}};
  const std::string svg = ExpectTheCommandsFigure(
      "/api/pod.svg", body, dir_ / "cli.svg",
      {"one_magnet hit/miss", "one_magnet POD", "one_magnet lower bound", "one_magnet a90/95",
       "good (5000)", "f0 limit 370.00 Hz", "f0 limit 420.00 Hz"});
  EXPECT_NE(svg.find("<title>POD from " + hits + "</title>"), std::string::npos);
}

TEST_F(FigureApi, PodSvgRefusesMalformedInputNamingTheCause) {
  auto expect_400 = [&](const nlohmann::json& body, const std::string& code,
                        const std::string& says) { Expect400("/api/pod.svg", body, code, says); };
  expect_400({{"hits_csv", "size,hit\n0.5,1\n0.6,yes\n"}}, "bad_hits",
             "hits.csv:3: hit must be 0 or 1");
  expect_400({{"hits_csv", "size,result\n0.5,1\n"}, {"name", "mine.csv"}}, "bad_hits",
             "mine.csv: the header has no column 'hit'");
  expect_400({{"hits_csv", "size,hit\n0,0\n"}}, "bad_hits", "no defective unit (size > 0)");
  expect_400({{"hits_csv", "size,hit,f0_hz\n0.5,1,1e9\n"}}, "bad_hits",
             "hits.csv:2: f0_hz must be in (0, 100000] Hz");
  expect_400({{"hits", "size,hit\n0.5,1\n"}}, "bad_request", "unknown field 'hits'");
  expect_400({{"name", "x.csv"}}, "bad_request", "hits_csv: required");
  expect_400({{"hits_csv", "size,hit\n0.5,1\n"}, {"link", "cauchit"}}, "bad_request", "cauchit");
  expect_400({{"hits_csv", "size,hit\n0.5,1\n"}, {"f0_limits_hz", {"390"}}}, "bad_request",
             "f0_limits_hz: each must be a number");
  expect_400({{"hits_csv", "size,hit\n0.5,1\n"}, {"confidence", 2}}, "bad_request",
             "confidence: must be a number in [0.5, 0.999]");
  const auto res = PostText("/api/pod.svg", "{not json");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 400);
  EXPECT_EQ(ErrorCode(res), "bad_json");
}

TEST_F(FigureApi, BodiesAreBoundedPerRoute) {
  // The headers alone: a Content-Length over the route's limit is refused before the body is
  // read. 5 MiB is over the figures' 4 MiB; 100 KiB is over the 64 KiB of every other route
  // (here POST /api/tests) but within the figures' (PodSvgIsTheFigureOfEolPod sends more).
  auto answer = [&](const std::string& path, std::size_t length) {
    testing::RawClient c(testing::PortFromReadyLine(station_->output()));
    EXPECT_TRUE(c.connected());
    c.Send("POST " + path + " HTTP/1.1\r\nHost: 127.0.0.1\r\nAuthorization: Bearer " + kEngineer +
           "\r\nContent-Type: application/json\r\nContent-Length: " + std::to_string(length) +
           "\r\n\r\n");
    return c.ReadUntil("}}", 5s);
  };
  for (const auto& [path, length] : std::vector<std::pair<std::string, std::size_t>>{
           {"/api/pod.svg", 5u << 20}, {"/api/gap.svg", 5u << 20}, {"/api/tests", 100u << 10}}) {
    const std::string got = answer(path, length);
    EXPECT_EQ(got.rfind("HTTP/1.1 413", 0), 0u) << path << ": " << got;
    EXPECT_NE(got.find("the limit is " + std::to_string(path == "/api/tests" ? 65536 : 4194304)),
              std::string::npos)
        << path << ": " << got;
  }
}

TEST_F(FigureApi, GapSvgIsThePlotOfEolGapAndRefusesBadInputs) {
  const std::string sim = dir_ / "sim.csv", meas = dir_ / "meas.csv";
  io::WriteFrfCsv(sim, testing::GapSimulation());
  io::WriteFrfCsv(meas, testing::GapMeasured({{analysis::EffectKind::kChannelDelay, {6e-6}}}, 3));
  // The CLI runs from the checkout (its default --recipe is the shipped one, as the station's).
  const testing::CliRun cli = testing::RunEol(
      {"gap", "--sim", sim, "--measured", meas, "--plot", dir_ / "cli.svg"}, true, 300s);
  ASSERT_EQ(cli.code, 0) << cli.out;

  const nlohmann::json body = {{"simulation", {{"name", sim}, {"text", ReadText(sim)}}},
                               {"measured", {{{"name", meas}, {"text", ReadText(meas)}}}}};
  ExpectTheCommandsFigure(
      "/api/gap.svg", body, dir_ / "cli.svg",
      {"eol gap: channel_delay", "Re Z (ohm)", "Im Z - w L_nominal (ohm)", "|residual| / sigma",
       "measured", "simulated", "corrected", "where the gap is"});

  auto expect_400 = [&](const nlohmann::json& b, const std::string& code, const std::string& says) {
    Expect400("/api/gap.svg", b, code, says);
  };
  nlohmann::json bad = body;
  bad["measured"][0] = {{"name", "unit7.csv"},
                        {"text", "f_hz,re_ohm,im_ohm\n200,0.5,1\n201,x,1\n"}};
  expect_400(bad, "bad_input", "unit7.csv:3:");
  bad = body;
  bad["simulation"]["text"] = "freq,a,b\n1,2,3\n";
  bad["simulation"]["name"] = "sim-upload.csv";
  expect_400(bad, "bad_input", "sim-upload.csv");
  bad = body;
  bad.erase("measured");
  expect_400(bad, "bad_request", "measured: required");
  bad = body;
  bad["measured"] = nlohmann::json::array();
  expect_400(bad, "bad_request", "measured: must be an array of 1 to 8 entries");
  bad = body;
  bad["effects"] = {"gremlins"};
  expect_400(bad, "bad_request", "effects: unknown effect \"gremlins\"");
  bad = body;
  bad["quantity"] = "admittance";
  expect_400(bad, "bad_request", "quantity: must be impedance or mobility");
  bad = body;
  bad["simulation"] = "sim.csv";
  expect_400(bad, "bad_request", "simulation: must be {\"name\"");
}

}  // namespace
}  // namespace eol
