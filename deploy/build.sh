#!/usr/bin/env bash
# Configures and builds into build/ (the CLI lands at build/eol). Extra arguments go to
# CMake's configure step, e.g. deploy/build.sh -DEOL_WERROR=ON.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo "$@" > build.log 2>&1 ||
  { cat build.log; exit 1; }
cmake --build build -j "$(nproc)"
