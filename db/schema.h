// The store's SQL schema, compiled into the binary (the station needs no files at run time).
//
// Each constant here is the SQL of one migration step; the ordered list of steps is
// kMigrations in store.cc. A shipped step is never edited: a schema change is a new step
// (and Store::kSchemaVersion + 1), so every station file, whatever version wrote it,
// migrates along the same path.
#pragma once

namespace eol::db::schema {

// Identifies a file as an EOL test store (PRAGMA application_id, "EOLS").
inline constexpr int kApplicationId = 0x454F4C53;

// Version 0 -> 1: the initial schema.
//
// tests: one row per test. The columns are authoritative for identity, outcome, times,
//   reasons and retest_of (reasons: a JSON array of {"code", "text"}; rows written before
//   reasons had codes hold plain strings, read as code "legacy"); `record` holds the rest of the
//   TestRecord as JSON (measurements with doc lines, conditions, calibration, fit, trace), without
//   the curves, and is NULL until the test is finished. A row is RUNNING from BeginTest until
//   FinishTest; a RUNNING row found when the store is opened was interrupted and becomes ABORTED.
//   Times are ISO 8601 UTC strings of one format (millisecond precision, 'Z'), so string
//   order is time order.
// measurements: a copy of the record's measurements for SQL queries (yield, trends, Cpk).
//   Values that were not finite are NULL; lo/hi are NULL where the limit is open.
// curves: each raw curve as the zlib (RFC 1950) stream of its UTF-8 JSON, with the JSON's
//   size in bytes; rows of one test are in the record's order (by id).
inline constexpr const char kSchemaV1[] = R"sql(
CREATE TABLE tests (
  id               INTEGER PRIMARY KEY,
  serial           TEXT    NOT NULL,
  station_id       TEXT    NOT NULL,
  recipe_id        TEXT    NOT NULL,
  recipe_version   INTEGER NOT NULL,
  recipe_hash      TEXT    NOT NULL,
  software_version TEXT    NOT NULL,
  started_at       TEXT    NOT NULL,
  finished_at      TEXT,
  outcome          TEXT    NOT NULL
                   CHECK (outcome IN ('RUNNING', 'PASS', 'FAIL', 'ERROR', 'ABORTED')),
  retest_of        INTEGER REFERENCES tests(id),
  reasons          TEXT    NOT NULL DEFAULT '[]',
  record           TEXT
);
CREATE INDEX tests_serial_started ON tests(serial, started_at);
CREATE INDEX tests_started ON tests(started_at);
-- Open() looks for RUNNING rows every time; this keeps that independent of the table size.
CREATE INDEX tests_running ON tests(id) WHERE outcome = 'RUNNING';

CREATE TABLE measurements (
  id       INTEGER PRIMARY KEY,
  test_id  INTEGER NOT NULL REFERENCES tests(id) ON DELETE CASCADE,
  name     TEXT    NOT NULL,
  value    REAL,
  sigma    REAL,
  unit     TEXT    NOT NULL,
  lo       REAL,
  hi       REAL,
  outcome  TEXT    NOT NULL CHECK (outcome IN ('PASS', 'FAIL', 'UNSET')),
  marginal INTEGER NOT NULL CHECK (marginal IN (0, 1))
);
CREATE INDEX measurements_name ON measurements(name);
CREATE INDEX measurements_test ON measurements(test_id);

CREATE TABLE curves (
  id       INTEGER PRIMARY KEY,
  test_id  INTEGER NOT NULL REFERENCES tests(id) ON DELETE CASCADE,
  name     TEXT    NOT NULL,
  raw_size INTEGER NOT NULL,
  data     BLOB    NOT NULL
);
CREATE INDEX curves_test ON curves(test_id);
)sql";

// Version 1 -> 2: the audit log of recipe changes (who, when, old and new hash).
inline constexpr const char kSchemaV2[] = R"sql(
CREATE TABLE recipe_audit (
  id           INTEGER PRIMARY KEY,
  at           TEXT    NOT NULL,
  who          TEXT    NOT NULL,
  role         TEXT    NOT NULL,
  recipe_id    TEXT    NOT NULL,
  old_version  INTEGER,
  new_version  INTEGER NOT NULL,
  old_hash     TEXT,
  new_hash     TEXT    NOT NULL,
  path         TEXT    NOT NULL
);
CREATE INDEX recipe_audit_at ON recipe_audit (at);
)sql";

// Version 2 -> 3: self-checks and the kind of each test.
//
// tests.kind: 'production' for a unit, 'self_check' for a master part tested to check the
//   station itself; production statistics read only 'production' rows. Rows written before
//   version 3 are production tests.
// self_checks: one row per master test, written in the same transaction as its test: which
//   master ('good' must PASS, 'limit' must FAIL on the resonance), whether the check passed,
//   and why. The station's lockout is derived from this table (station/daemon/self_check.h), so it
//   survives a restart.
inline constexpr const char kSchemaV3[] = R"sql(
ALTER TABLE tests ADD COLUMN kind TEXT NOT NULL DEFAULT 'production'
  CHECK (kind IN ('production', 'self_check'));
CREATE INDEX tests_kind_started ON tests(kind, started_at);

CREATE TABLE self_checks (
  id         INTEGER PRIMARY KEY,
  test_id    INTEGER NOT NULL REFERENCES tests(id) ON DELETE CASCADE,
  at         TEXT    NOT NULL,
  station_id TEXT    NOT NULL,
  master     TEXT    NOT NULL CHECK (master IN ('good', 'limit')),
  serial     TEXT    NOT NULL,
  passed     INTEGER NOT NULL CHECK (passed IN (0, 1)),
  detail     TEXT    NOT NULL
);
CREATE INDEX self_checks_at ON self_checks(at);
)sql";

// Version 3 -> 4: who tested and for which order (db/test_record.h WorkContext).
//
// tests.operator_id, tests.shift, tests.order_number: as given with the serial; '' when not
//   given, and for every row written before version 4. Authoritative like the other columns
//   (the record JSON holds copies). The index serves "every unit of this order".
inline constexpr const char kSchemaV4[] = R"sql(
ALTER TABLE tests ADD COLUMN operator_id TEXT NOT NULL DEFAULT '';
ALTER TABLE tests ADD COLUMN shift TEXT NOT NULL DEFAULT '';
ALTER TABLE tests ADD COLUMN order_number TEXT NOT NULL DEFAULT '';
CREATE INDEX tests_order_started ON tests(order_number, started_at);
)sql";

// Version 4 -> 5: the outbox of finished records for the publishers (MQTT, ...).
//
// outbox: one row per finished record, written in the record's own transaction (and for a
//   test recovered as ABORTED, in the recovery's), so a record is never stored without its
//   row. AUTOINCREMENT: ids only grow, even if old rows are pruned, so a cursor stays valid.
//   Records stored before version 5 have no row and are not published.
// outbox_cursors: per consumer ('mqtt'), the id of the newest row it has delivered (acknowledged
//   by the broker); the consumer reads the rows after it, in id order.
inline constexpr const char kSchemaV5[] = R"sql(
CREATE TABLE outbox (
  id         INTEGER PRIMARY KEY AUTOINCREMENT,
  test_id    INTEGER NOT NULL REFERENCES tests(id) ON DELETE CASCADE,
  created_at TEXT    NOT NULL
);
CREATE TABLE outbox_cursors (
  consumer TEXT    PRIMARY KEY,
  last_id  INTEGER NOT NULL
);
)sql";

// Version 5 -> 6: curves in a compact binary form (db/curve_codec.h). encoding says how `data`
// is stored: 'json-zlib' (every row written before v6: the zlib stream of the curve's JSON,
// raw_size its size) or 'binary-v1' (EncodeCurve's bytes, raw_size their size). Old rows stay
// as they are; new rows are binary.
inline constexpr const char kSchemaV6[] = R"sql(
ALTER TABLE curves ADD COLUMN encoding TEXT NOT NULL DEFAULT 'json-zlib'
  CHECK (encoding IN ('json-zlib', 'binary-v1'));
)sql";

// Version 6 -> 7: what teardown of a unit found (db/store.h TeardownEntry).
//
// teardowns: one row per finding an engineer records for a serial: found ('defective': the
//   defect is confirmed; 'not_defective': nothing wrong was found), a note, who (the
//   engineer's name, never empty) and when (ISO 8601 UTC). Append-only: the triggers refuse
//   every UPDATE and DELETE, so a correction is a new row and the history stays; the newest
//   row of a serial (highest id) is its current finding, and `corrects` names the row it
//   replaced. test_id is the serial's newest finished test when the finding was recorded
//   (the verdict the teardown judges: a FAIL found not defective is a false reject).
inline constexpr const char kSchemaV7[] = R"sql(
CREATE TABLE teardowns (
  id       INTEGER PRIMARY KEY,
  serial   TEXT    NOT NULL CHECK (length(serial) > 0),
  found    TEXT    NOT NULL CHECK (found IN ('defective', 'not_defective')),
  note     TEXT    NOT NULL DEFAULT '',
  by       TEXT    NOT NULL CHECK (length(trim(by)) > 0),
  at       TEXT    NOT NULL CHECK (length(at) > 0),
  test_id  INTEGER REFERENCES tests(id),
  corrects INTEGER REFERENCES teardowns(id)
);
CREATE INDEX teardowns_serial ON teardowns(serial, id);
CREATE TRIGGER teardowns_append_only_update BEFORE UPDATE ON teardowns
BEGIN SELECT RAISE(ABORT, 'teardown findings are append-only: record a correction'); END;
CREATE TRIGGER teardowns_append_only_delete BEFORE DELETE ON teardowns
BEGIN SELECT RAISE(ABORT, 'teardown findings are append-only: record a correction'); END;
)sql";

}  // namespace eol::db::schema
