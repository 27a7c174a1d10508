// The plant's central record in PostgreSQL, created by the stations themselves
// (CREATE ... IF NOT EXISTS, under an advisory lock so that eight stations starting at once
// do not race on the catalogue). deploy/OPERATIONS.md's "Central record" table documents these
// columns.
//
// tests: one row per stored record of every station, unique on (station_id, test_id): the
//   station's own test id (db/store.h) is the idempotency key, so a record replicated twice
//   (the station stopped between the central COMMIT and its cursor write) is inserted once
//   (INSERT ... ON CONFLICT DO NOTHING). The columns are for SQL (where, who, what, when);
//   `record` is the whole record as the station's API serves it (db/test_record.h, the MQTT
//   payload: measurements with limits, reasons, conditions, calibration, fit, trace, cycle),
//   `curves` its raw curves (JSON array of {name, unit, freq_hz, re, im, sigma}; PostgreSQL
//   compresses such large values itself, TOAST). Times are timestamptz (UTC in the record).
//   `retest_of` is a test id of the same station. Only stations write; nothing updates rows.
//   The columns but curves, stored_at and replicated_at are the central entries of
//   db/test_columns.h (names and types); tests/station/central_record_test.cc holds the two
//   together.
#pragma once

namespace eol::station::central {

// Version of this schema; a later version only adds columns (ALTER TABLE ... ADD COLUMN IF
// NOT EXISTS) and raises it. Stored as the table's comment.
inline constexpr int kCentralSchemaVersion = 1;

// Advisory lock key serialising the schema creation ("EOLS").
inline constexpr long long kSchemaLockKey = 0x454F4C53;

inline constexpr const char kCreateCentralSchema[] = R"sql(
CREATE TABLE IF NOT EXISTS tests (
  station_id       text        NOT NULL,
  test_id          bigint      NOT NULL,
  serial           text        NOT NULL,
  outcome          text        NOT NULL CHECK (outcome IN ('PASS', 'FAIL', 'ERROR', 'ABORTED')),
  started_at       timestamptz NOT NULL,
  finished_at      timestamptz,
  kind             text        NOT NULL,
  recipe_id        text        NOT NULL,
  recipe_version   integer     NOT NULL,
  recipe_sha256    text        NOT NULL,
  software_version text        NOT NULL,
  operator_id      text        NOT NULL DEFAULT '',
  shift            text        NOT NULL DEFAULT '',
  order_number     text        NOT NULL DEFAULT '',
  retest_of        bigint,
  reason_code      text,
  reasons          jsonb       NOT NULL,
  record           jsonb       NOT NULL,
  curves           jsonb       NOT NULL,
  stored_at        timestamptz NOT NULL,
  replicated_at    timestamptz NOT NULL DEFAULT now(),
  UNIQUE (station_id, test_id)
);
CREATE INDEX IF NOT EXISTS tests_serial_started ON tests (serial, started_at);
CREATE INDEX IF NOT EXISTS tests_order ON tests (order_number) WHERE order_number <> '';
CREATE INDEX IF NOT EXISTS tests_started ON tests (started_at);
COMMENT ON TABLE tests IS 'eol central record, schema 1 (station/daemon/central/central_schema.h)';
)sql";

}  // namespace eol::station::central
