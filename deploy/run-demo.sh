#!/usr/bin/env bash
# Quick start 1: install what is missing, build, and run the station on its simulators.
set -euo pipefail
cd "$(dirname "$0")/.."
bash deploy/install-deps.sh
bash deploy/build.sh
exec build/eol demo --units "${EOL_DEMO_UNITS:-50}" --db build/demo.sqlite --port "${EOL_DEMO_PORT:-8080}"
