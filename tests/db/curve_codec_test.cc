// Compact curve storage (db/curve_codec.h, schema v6): what a stored curve keeps (grid to 1e-9,
// values to a thousandth of a sigma, exact where float32 cannot), how small it is, that corrupt
// bytes are refused with the reason, and that a version-5 file's zlib-JSON curves still read.
#include "db/curve_codec.h"

#include <gtest/gtest.h>
#include <sqlite3.h>
#include <zlib.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "../support/child_process.h"
#include "db/schema.h"
#include "db/store.h"

namespace eol::db {
namespace {

// A measured impedance as the station stores it: the 5 s recipe's 601 lines at 1 Hz, with a
// sigma of the order the station measures (5 mOhm; 2 mV / 1 mA noise, 2 V over 601 lines).
Curve Measured(std::size_t n = 601, double sigma = 5e-3) {
  Curve c;
  c.name = "impedance";
  c.unit = "ohm";
  for (std::size_t k = 0; k < n; ++k) {
    const double f = 200.0 + static_cast<double>(k);
    const double w = 2.0 * M_PI * f;
    c.freq_hz.push_back(f);
    c.re.push_back(0.5 + 0.51 / (1.0 + std::pow(50.0 * (f / 390.0 - 390.0 / f), 2)) +
                   1e-4 * std::sin(0.37 * static_cast<double>(k)));
    c.im.push_back(w * 2e-3 + 1e-4 * std::cos(0.91 * static_cast<double>(k)));
    c.sigma.push_back(sigma * (1.0 + 0.1 * std::sin(static_cast<double>(k))));
  }
  return c;
}

// The curve as schema versions 1-5 stored it: the zlib stream of its JSON.
std::string ZlibJson(const Curve& c) {
  const std::string j = nlohmann::json(c).dump();
  uLongf size = compressBound(static_cast<uLong>(j.size()));
  std::string packed(size, '\0');
  EXPECT_EQ(compress2(reinterpret_cast<Bytef*>(packed.data()), &size,
                      reinterpret_cast<const Bytef*>(j.data()), j.size(), Z_DEFAULT_COMPRESSION),
            Z_OK);
  packed.resize(size);
  return packed;
}

TEST(CurveCodec, MeasuredCurveKeepsItsLinesToAThousandthOfSigmaInAThirdOfTheBytes) {
  const Curve c = Measured();
  const std::string bytes = EncodeCurve(c);
  std::printf("601-line curve with sigma: %zu bytes (zlib JSON: %zu)\n", bytes.size(),
              ZlibJson(c).size());
  EXPECT_LE(bytes.size(), 12u * 601u + 40u);  // float32 re, im, sigma; the grid as first, step
  const Curve back = DecodeCurve(bytes, "impedance");
  EXPECT_EQ(back.name, "impedance");
  EXPECT_EQ(back.unit, "ohm");
  ASSERT_EQ(back.freq_hz.size(), c.freq_hz.size());
  ASSERT_EQ(back.sigma.size(), c.sigma.size());
  for (std::size_t k = 0; k < c.freq_hz.size(); ++k) {
    EXPECT_NEAR(back.freq_hz[k], c.freq_hz[k], 1e-9 * c.freq_hz[k]) << k;
    EXPECT_LE(std::abs(back.re[k] - c.re[k]), 1e-3 * c.sigma[k]) << k;
    EXPECT_LE(std::abs(back.im[k] - c.im[k]), 1e-3 * c.sigma[k]) << k;
    EXPECT_NEAR(back.sigma[k], c.sigma[k], 1e-7 * c.sigma[k]) << k;
  }
}

TEST(CurveCodec, WhatFloat32CannotKeepIsStoredExactly) {
  // A sigma so small that float32's rounding would be more than a thousandth of it.
  const Curve precise = Measured(50, 1e-12);
  const std::string bytes = EncodeCurve(precise);
  EXPECT_GE(bytes.size(), 16u * 50u);  // float64 values
  const Curve back = DecodeCurve(bytes, "impedance");
  EXPECT_EQ(back.re, precise.re);
  EXPECT_EQ(back.im, precise.im);

  // A grid that is not uniform (log-spaced lines) is kept line by line, exactly.
  Curve log = Measured(40);
  for (std::size_t k = 0; k < log.freq_hz.size(); ++k)
    log.freq_hz[k] = 100.0 * std::pow(1.05, static_cast<double>(k));
  EXPECT_EQ(DecodeCurve(EncodeCurve(log), "x").freq_hz, log.freq_hz);

  // Without a sigma: to 1e-6 of each value. Non-finite values are kept as they are.
  Curve model = Measured(30);
  model.name = "model";
  model.sigma.clear();
  Curve back_model = DecodeCurve(EncodeCurve(model), "model");
  EXPECT_TRUE(back_model.sigma.empty());
  for (std::size_t k = 0; k < model.re.size(); ++k)
    EXPECT_NEAR(back_model.re[k], model.re[k], 1e-6 * std::abs(model.re[k]));
  model.re[3] = std::nan("");
  back_model = DecodeCurve(EncodeCurve(model), "model");
  EXPECT_TRUE(std::isnan(back_model.re[3]));
  EXPECT_EQ(back_model.im, model.im);

  // One line: no step to store; the frequency is kept exactly.
  const Curve one = Measured(1);
  EXPECT_EQ(DecodeCurve(EncodeCurve(one), "x").freq_hz, one.freq_hz);
}

TEST(CurveCodec, CorruptBytesAreRefusedWithTheReason) {
  const std::string good = EncodeCurve(Measured(20));
  // Every truncation is refused, never read past the end.
  for (std::size_t len = 0; len < good.size(); ++len)
    EXPECT_THROW(DecodeCurve(std::string_view(good).substr(0, len), "x"), std::invalid_argument)
        << len;
  auto error = [](const std::string& bytes) {
    try {
      DecodeCurve(bytes, "x");
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(error(good + "x"),
            "encoded curve of 20 lines needs 256 bytes after its header, has 257");
  std::string bad = good;
  bad[0] = 'X';
  EXPECT_EQ(error(bad), "not an encoded curve (no EOLC magic)");
  bad = good;
  bad[4] = 2;
  EXPECT_EQ(error(bad), "encoded curve version 2 (this program reads 1)");
  bad = good;
  bad[5] = static_cast<char>(0x80);
  EXPECT_EQ(error(bad), "encoded curve has unknown flags 128");
  bad = good;  // line count (after magic, version, flags, unit length 3, "ohm") = 0xFFFFFFFF
  for (std::size_t i = 11; i < 15; ++i) bad[i] = static_cast<char>(0xFF);
  EXPECT_EQ(error(bad), "encoded curve has 4294967295 lines");

  Curve uneven = Measured(5);
  uneven.im.pop_back();
  EXPECT_THROW(EncodeCurve(uneven), std::invalid_argument);
  EXPECT_THROW(EncodeCurve(Curve{}), std::invalid_argument);
}

void Exec(sqlite3* db, const std::string& sql) {
  char* err = nullptr;
  ASSERT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &err), SQLITE_OK)
      << sql << ": " << (err ? err : "");
}

TEST(CurveStore, VersionFiveZlibJsonCurvesStillReadAndNewOnesAreBinary) {
  eol::testing::TempDir dir;
  const std::string path = dir / "v5.sqlite";
  const Curve old_curve = Measured(10);
  {
    sqlite3* raw = nullptr;
    ASSERT_EQ(sqlite3_open(path.c_str(), &raw), SQLITE_OK);
    for (const char* step : {schema::kSchemaV1, schema::kSchemaV2, schema::kSchemaV3,
                             schema::kSchemaV4, schema::kSchemaV5})
      Exec(raw, step);
    Exec(raw, "PRAGMA application_id = " + std::to_string(schema::kApplicationId) +
                  "; PRAGMA user_version = 5");
    Exec(raw,
         "INSERT INTO tests (id, serial, station_id, recipe_id, recipe_version, recipe_hash, "
         "software_version, started_at, finished_at, outcome, reasons) VALUES (1, "
         "'OLD-5', 's', 'r', 1, 'h', 'v', '2025-01-01T00:00:00.000Z', "
         "'2025-01-01T00:00:01.000Z', 'PASS', '[]')");
    const std::string j = nlohmann::json(old_curve).dump();
    const std::string packed = ZlibJson(old_curve);
    sqlite3_stmt* s = nullptr;
    ASSERT_EQ(sqlite3_prepare_v2(raw,
                                 "INSERT INTO curves (test_id, name, raw_size, data) VALUES "
                                 "(1, 'impedance', ?1, ?2)",
                                 -1, &s, nullptr),
              SQLITE_OK);
    sqlite3_bind_int64(s, 1, static_cast<sqlite3_int64>(j.size()));
    sqlite3_bind_blob(s, 2, packed.data(), static_cast<int>(packed.size()), SQLITE_TRANSIENT);
    ASSERT_EQ(sqlite3_step(s), SQLITE_DONE);
    sqlite3_finalize(s);
    sqlite3_close(raw);
  }
  auto store = Store::Open(path);
  const auto old = store->LatestOfSerial("OLD-5");
  ASSERT_TRUE(old.has_value());
  ASSERT_EQ(old->curves.size(), 1u);
  EXPECT_EQ(old->curves[0].re, old_curve.re);  // JSON kept every digit

  TestRecord r;
  r.serial = "NEW-6";
  r.station_id = "s";
  r.recipe_id = "r";
  r.recipe_version = 1;
  r.recipe_hash = std::string(64, 'a');
  r.software_version = "v";
  r.started_at = r.finished_at = "2026-01-01T00:00:00.000Z";
  r.outcome = analysis::Outcome::kPass;
  r.curves = {Measured(), Measured(601)};
  r.curves[1].name = "model";
  r.curves[1].sigma.clear();
  store->Insert(r);
  const auto back = store->LatestOfSerial("NEW-6");
  ASSERT_TRUE(back.has_value());
  ASSERT_EQ(back->curves.size(), 2u);
  EXPECT_EQ(back->curves[0].name, "impedance");
  EXPECT_EQ(back->curves[1].name, "model");
  EXPECT_LE(std::abs(back->curves[0].re[300] - r.curves[0].re[300]), 1e-3 * r.curves[0].sigma[300]);

  sqlite3* raw = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &raw), SQLITE_OK);
  sqlite3_stmt* s = nullptr;
  ASSERT_EQ(sqlite3_prepare_v2(raw,
                               "SELECT encoding, SUM(length(data)) FROM curves GROUP BY encoding "
                               "ORDER BY encoding",
                               -1, &s, nullptr),
            SQLITE_OK);
  ASSERT_EQ(sqlite3_step(s), SQLITE_ROW);
  EXPECT_STREQ(reinterpret_cast<const char*>(sqlite3_column_text(s, 0)), "binary-v1");
  EXPECT_LE(sqlite3_column_int64(s, 1), 601 * (12 + 8) + 100);  // impedance + model
  ASSERT_EQ(sqlite3_step(s), SQLITE_ROW);
  EXPECT_STREQ(reinterpret_cast<const char*>(sqlite3_column_text(s, 0)), "json-zlib");
  sqlite3_finalize(s);
  // A corrupt binary row names the test and curve.
  Exec(raw, "UPDATE curves SET data = x'00' WHERE encoding = 'binary-v1' AND name = 'model'");
  sqlite3_close(raw);
  try {
    store->LatestOfSerial("NEW-6");
    ADD_FAILURE() << "a corrupt curve was read";
  } catch (const StoreError& e) {
    EXPECT_NE(std::string(e.what()).find("read curve 'model' of test"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("corrupt curve data: truncated curve"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace eol::db
