// Writing and reading the plant's central record (station/daemon/central/central_schema.h) through
// one PgConnection. The record's fields come from db/test_record.h's one JSON field list:
// the `record` column is that JSON without curves (what MQTT publishes), and a plant-wide
// query reads records back through the same from_json, so `eol query --central` and
// GET /api/units/{serial}?scope=plant answer with the fields of their station-local forms.
// The table's other columns (identity, who, what, when) are the central entries of the one
// column list of a test (db/test_columns.h), which the INSERT is made from.
#pragma once

#include <string>
#include <vector>

#include "db/test_record.h"
#include "station/daemon/central/pg.h"

namespace eol::station::central {

// Creates the schema if it is missing (idempotent; safe from many stations at once).
void EnsureCentralSchema(PgConnection& pg);

// Inserts `record` (stored in the station's outbox at `stored_at`, ISO 8601) unless a row
// with its (station_id, test_id) is there already. Returns whether it inserted. The caller
// holds the transaction. Strings are stored as valid UTF-8 without NUL characters (a NUL
// becomes U+FFFD: jsonb refuses it).
bool InsertCentral(PgConnection& pg, const db::TestRecord& record, const std::string& stored_at);

// Every test of `serial` on every station, newest first (started_at, then station_id and
// test id), at most `limit`; curves when asked.
std::vector<db::TestRecord> CentralTestsOfSerial(PgConnection& pg, const std::string& serial,
                                                 bool with_curves, int limit = 1000);

}  // namespace eol::station::central
