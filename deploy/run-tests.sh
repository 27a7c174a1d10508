#!/usr/bin/env bash
# Quick start 2: install what is missing (with the test peers), build with warnings as
# errors, and run the whole test suite with CTest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash deploy/install-deps.sh --tests
bash deploy/check-format.sh
(cd tests/peers/browser && npm ci --no-audit --no-fund --loglevel=error)
bash deploy/build.sh -DEOL_WERROR=ON
# The fuzzers' clang tree is built here with the rest; the suite's fuzz_readers only fuzzes.
bash tests/fuzz/run_fuzzers.sh --build build/fuzz --build-only
cd build
ctest --output-on-failure -j "$(nproc)" --timeout 900
