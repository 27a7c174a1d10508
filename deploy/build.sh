#!/usr/bin/env bash
# Configures and builds into build/ (the CLI lands at build/eol). Extra arguments go to
# CMake's configure step, e.g. deploy/build.sh -DEOL_WERROR=ON.
set -euo pipefail
cd "$(dirname "$0")/.."
# ccache, when the machine has it, makes rebuilds of an unchanged file free.
launcher=()
if command -v ccache >/dev/null 2>&1; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo "${launcher[@]}" "$@" > build.log 2>&1 ||
  { cat build.log; exit 1; }
cmake --build build -j "$(nproc)"
