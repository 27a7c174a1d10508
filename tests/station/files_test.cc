// Readers and writers of drivers/io: round trips, and garbage rejected with a FileError
// naming file, line and column.
#include <gtest/gtest.h>
#include <sndfile.h>
#include <zlib.h>

#include <cmath>
#include <fstream>
#include <numbers>

#include "drivers/io/file_error.h"
#include "drivers/io/frf_files.h"
#include "drivers/io/measured_input.h"
#include "drivers/io/recording_files.h"
#include "drivers/io/text_table.h"
#include "tests/support/child_process.h"

namespace eol::io {
namespace {

#define EXPECT_CONTAINS(haystack, needle) \
  EXPECT_PRED_FORMAT2(::testing::IsSubstring, needle, haystack)

void Write(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
}

// The message of the FileError that `f` throws ("" and a test failure when none).
template <typename F>
std::string ErrorOf(F f) {
  try {
    f();
  } catch (const FileError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no FileError thrown";
  return "";
}

analysis::Frf SomeFrf(analysis::Quantity q, bool sigma) {
  analysis::Frf h;
  h.quantity = q;
  for (int k = 0; k < 5; ++k) {
    h.freq_hz.push_back(100.0 + 0.5 * k);
    h.value.emplace_back(0.1 * k + 1.0 / 3.0, -2.0 * k - 1e-7);
    if (sigma) h.sigma.push_back(1e-3 * (k + 1));
  }
  return h;
}

TEST(FrfCsvTest, RoundTripImpedanceAndMobility) {
  testing::TempDir dir;
  for (auto q : {analysis::Quantity::kImpedanceOhm, analysis::Quantity::kMobility}) {
    for (bool sigma : {true, false}) {
      const analysis::Frf h = SomeFrf(q, sigma);
      WriteFrfCsv(dir / "h.csv", h);
      const analysis::Frf back = ReadFrfCsv(dir / "h.csv");
      EXPECT_EQ(back.quantity, q);
      EXPECT_EQ(back.freq_hz, h.freq_hz);
      EXPECT_EQ(back.value, h.value);  // 17 digits: exact
      EXPECT_EQ(back.sigma, h.sigma);
      EXPECT_EQ(back.method, "file");
    }
  }
  std::ifstream in(dir / "h.csv");
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header, "f_hz,re,im");
}

TEST(FrfCsvTest, GarbageNamesFileLineAndColumn) {
  testing::TempDir dir;
  const std::string p = dir / "z.csv";
  Write(p, "f_hz,re_ohm,im_ohm\n100,1,2\n101, abc,3\n");
  EXPECT_EQ(ErrorOf([&] { ReadFrfCsv(p); }), p + ":3:6: re_ohm: \"abc\" is not a number");
  Write(p, "# comment\nf_hz,re_ohm,im_ohm,sigma_ohm\n100,1,2,0.1\n101,1,nan,0.1\n");
  EXPECT_EQ(ErrorOf([&] { ReadFrfCsv(p); }), p + ":4:7: im_ohm: \"nan\" is not a finite number");
  Write(p, "f_hz,re_ohm,im_ohm\n100,1,2\n100,1,2\n");
  EXPECT_CONTAINS(ErrorOf([&] { ReadFrfCsv(p); }), p + ":3:1: f_hz: frequencies must increase");
  Write(p, "f_hz,re_ohm,im_ohm,sigma_ohm\n100,1,2,0\n");
  EXPECT_EQ(ErrorOf([&] { ReadFrfCsv(p); }), p + ":2:9: sigma_ohm: sigma must be positive");
  Write(p, "f_hz,re_ohm\n100,1\n");
  EXPECT_CONTAINS(ErrorOf([&] { ReadFrfCsv(p); }), p + ":1: not an FRF CSV: need the columns");
  Write(p, "f_hz,re_ohm,im_ohm\n100,1\n");
  EXPECT_EQ(ErrorOf([&] { ReadFrfCsv(p); }), p + ":2:6: expected 3 fields, found 2");
  Write(p, "f_hz,re_ohm,im_ohm\n100,1,2,5\n");
  EXPECT_EQ(ErrorOf([&] { ReadFrfCsv(p); }), p + ":2:9: expected 3 fields, found 4");
  Write(p, "");
  EXPECT_EQ(ErrorOf([&] { ReadFrfCsv(p); }), p + ": file is empty (no header line)");
  Write(p, "f_hz,re_ohm,im_ohm\n\n");
  EXPECT_EQ(ErrorOf([&] { ReadFrfCsv(p); }), p + ":2: no data rows after the header");
  EXPECT_CONTAINS(ErrorOf([&] { ReadFrfCsv(dir / "missing.csv"); }), "missing.csv: cannot open");
}

// sigma_dof: the degrees of freedom of an estimated sigma^2 travel with the file.
TEST(FrfCsvTest, SigmaDofRoundTripsAndIsChecked) {
  testing::TempDir dir;
  const std::string p = dir / "z.csv";
  WriteFrfCsv(p, SomeFrf(analysis::Quantity::kImpedanceOhm, true), 14.0);
  double dof = -1.0;
  EXPECT_EQ(ReadFrfCsv(p, &dof).sigma.size(), 5u);
  EXPECT_EQ(dof, 14.0);
  WriteFrfCsv(p, SomeFrf(analysis::Quantity::kImpedanceOhm, true));  // exact: no column
  ReadFrfCsv(p, &dof);
  EXPECT_EQ(dof, 0.0);
  WriteFrfCsv(p, SomeFrf(analysis::Quantity::kImpedanceOhm, false), 14.0);  // no sigma: none
  std::ifstream in(p);
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header, "f_hz,re_ohm,im_ohm");
  EXPECT_CONTAINS(
      ErrorOf([&] { WriteFrfCsv(p, SomeFrf(analysis::Quantity::kImpedanceOhm, true), 3.0); }),
      "a sigma_dof of 3.000000: it must be above 4");

  Write(p, "f_hz,re_ohm,im_ohm,sigma_ohm,sigma_dof\n100,1,2,0.1,14\n101,1,2,0.1,22\n");
  EXPECT_EQ(ErrorOf([&] { ReadFrfCsv(p); }),
            p + ":3:13: sigma_dof: must be the same on every line (the first line has 14)");
  Write(p, "f_hz,re_ohm,im_ohm,sigma_ohm,sigma_dof\n100,1,2,0.1,3\n");
  EXPECT_EQ(ErrorOf([&] { ReadFrfCsv(p); }),
            p + ":2:13: sigma_dof: must be above 4 (or 0: sigma exact)");
  Write(p, "f_hz,re_ohm,im_ohm,sigma_dof\n100,1,2,14\n");
  EXPECT_EQ(ErrorOf([&] { ReadFrfCsv(p); }),
            p + ":1: a sigma_dof column needs the sigma_ohm column");
  Write(p, "f_hz,re_ohm,im_ohm,sigma_ohm,sigma_dof\n100,1,2,0.1,0\n101,1,2,0.1,0\n");
  ReadFrfCsv(p, &dof);
  EXPECT_EQ(dof, 0.0);
}

TEST(FrfCsvTest, ReadsGzip) {
  testing::TempDir dir;
  const std::string p = dir / "z.csv.gz";
  gzFile gz = gzopen(p.c_str(), "wb");
  ASSERT_NE(gz, nullptr);
  const std::string text = "f_hz,re_ohm,im_ohm\r\n100,1,2\r\n101,1.5,-2e-3\r\n";
  gzwrite(gz, text.data(), static_cast<unsigned>(text.size()));
  gzclose(gz);
  const analysis::Frf h = ReadFrfCsv(p);
  ASSERT_EQ(h.size(), 2u);
  EXPECT_EQ(h.value[1], std::complex<double>(1.5, -2e-3));
}

TEST(ZmaTest, ReadsMagnitudePhaseSkippingStars) {
  testing::TempDir dir;
  const std::string p = dir / "m.zma";
  Write(p, "* measured by something\n*\n10\t5.0\t0\n20 5.0 90\n\n30, 2.0, -45 extra\n");
  const analysis::Frf z = ReadZma(p);
  ASSERT_EQ(z.size(), 3u);
  EXPECT_FALSE(z.has_sigma());
  EXPECT_NEAR(std::abs(z.value[1] - std::complex<double>(0.0, 5.0)), 0.0, 1e-12);
  EXPECT_NEAR(std::arg(z.value[2]) * 180.0 / std::numbers::pi, -45.0, 1e-12);
  WriteZma(dir / "back.zma", z);
  const analysis::Frf back = ReadZma(dir / "back.zma");
  for (std::size_t k = 0; k < 3; ++k) EXPECT_NEAR(std::abs(back.value[k] - z.value[k]), 0.0, 1e-12);
  Write(p, "10 5 0\n20 x 0\n");
  EXPECT_EQ(ErrorOf([&] { ReadZma(p); }), p + ":2:4: |Z|: \"x\" is not a number");
  Write(p, "10 5 0\n5 5 0\n");
  EXPECT_EQ(ErrorOf([&] { ReadZma(p); }), p + ":2:1: frequencies must increase strictly");
  Write(p, "10 5\n");
  EXPECT_CONTAINS(ErrorOf([&] { ReadZma(p); }), p + ":1:5: expected 3 fields");
  Write(p, "* only comments\n");
  EXPECT_EQ(ErrorOf([&] { ReadZma(p); }), p + ": no data lines (an empty ZMA file)");
}

TEST(ZmaTest, AHugePhaseIsReducedToOneTurnNotANan) {
  // Found by the zma fuzzer: 1e308 degrees overflows when turned into radians.
  testing::TempDir dir;
  const std::string p = dir / "m.zma";
  Write(p, "300 2 1e308\n400 2 -720.5\n");
  const analysis::Frf z = ReadZma(p);
  std::string why;
  EXPECT_TRUE(z.Validate(&why)) << why;
  EXPECT_NEAR(std::abs(z.value[0]), 2.0, 1e-12);
  EXPECT_NEAR(std::arg(z.value[1]) * 180.0 / std::numbers::pi, -0.5, 1e-9);
}

analysis::Recording SomeRecording() {
  analysis::Recording r;
  r.sample_rate_hz = 8000.0;
  for (int t = 0; t < 1000; ++t) {
    r.voltage_v.push_back(std::sin(0.01 * t) * 1.7);
    r.current_a.push_back(std::cos(0.013 * t) * 0.3);
  }
  return r;
}

TEST(RecordingCsvTest, RoundTripInfersSampleRate) {
  testing::TempDir dir;
  const analysis::Recording r = SomeRecording();
  WriteRecordingCsv(dir / "r.csv", r);
  const analysis::Recording back = ReadRecordingCsv(dir / "r.csv");
  EXPECT_EQ(back.sample_rate_hz, 8000.0);
  EXPECT_EQ(back.voltage_v, r.voltage_v);
  EXPECT_EQ(back.current_a, r.current_a);
  EXPECT_EQ(back.period_samples, 0u);
  const std::string p = dir / "bad.csv";
  Write(p, "t_s,u_v,i_a\n0,1,2\n0.001,1,2\n0.0025,1,2\n0.003,1,2\n");
  EXPECT_CONTAINS(ErrorOf([&] { ReadRecordingCsv(p); }), p + ":4:1: t_s: sampling is not uniform");
  Write(p, "t_s,u_v\n0,1\n0.001,1\n");
  EXPECT_CONTAINS(ErrorOf([&] { ReadRecordingCsv(p); }), p + ":1: missing column \"i_a\"");
  Write(p, "t_s,u_v,i_a\n0,1,2\n");
  EXPECT_CONTAINS(ErrorOf([&] { ReadRecordingCsv(p); }), "need at least 2 samples");
}

TEST(WavTest, RoundTripWithGainsAndChannelCheck) {
  testing::TempDir dir;
  const analysis::Recording r = SomeRecording();
  WriteWavRecording(dir / "r.wav", r, 5.0, 0.5);
  const analysis::Recording back = ReadWavRecording(dir / "r.wav", 5.0, 0.5);
  EXPECT_EQ(back.sample_rate_hz, 8000.0);
  ASSERT_EQ(back.voltage_v.size(), r.voltage_v.size());
  for (std::size_t k = 0; k < r.voltage_v.size(); ++k) {
    EXPECT_NEAR(back.voltage_v[k], r.voltage_v[k], 5.0 * 1e-7);  // 32-bit float
    EXPECT_NEAR(back.current_a[k], r.current_a[k], 0.5 * 1e-7);
  }
  EXPECT_EQ(back.voltage_full_scale_v, 5.0);
  EXPECT_EQ(back.current_full_scale_a, 0.5);

  SF_INFO info{};
  info.samplerate = 8000;
  info.channels = 1;
  info.format = SF_FORMAT_WAV | SF_FORMAT_PCM_16;
  const std::string mono = dir / "mono.wav";
  SNDFILE* f = sf_open(mono.c_str(), SFM_WRITE, &info);
  ASSERT_NE(f, nullptr);
  const short samples[4] = {0, 100, -100, 0};
  sf_writef_short(f, samples, 4);
  sf_close(f);
  EXPECT_EQ(ErrorOf([&] { ReadWavRecording(mono, 1.0, 1.0); }),
            mono + ": need 2 channels (voltage, current), found 1");
  Write(dir / "text.wav", "not audio");
  EXPECT_CONTAINS(ErrorOf([&] { ReadWavRecording(dir / "text.wav", 1.0, 1.0); }),
                  "text.wav: cannot open as audio");
  EXPECT_CONTAINS(ErrorOf([&] { ReadMeasured(dir / "r.wav", {}); }),
                  "needs --voltage-gain and --current-gain");
}

TEST(MeasuredInputTest, TellsFilesApart) {
  testing::TempDir dir;
  WriteFrfCsv(dir / "z.csv", SomeFrf(analysis::Quantity::kImpedanceOhm, true));
  WriteRecordingCsv(dir / "r.csv", SomeRecording());
  EXPECT_EQ(ReadMeasured(dir / "z.csv", {}).format, "frf-csv");
  const MeasuredInput r = ReadMeasured(dir / "r.csv", {});
  EXPECT_EQ(r.kind, MeasuredKind::kRecording);
  EXPECT_EQ(r.format, "recording-csv");
  Write(dir / "other.csv", "a,b\n1,2\n");
  EXPECT_CONTAINS(ErrorOf([&] { ReadMeasured(dir / "other.csv", {}); }),
                  "other.csv:1: unknown file");
}

}  // namespace
}  // namespace eol::io
