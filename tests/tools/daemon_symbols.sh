#!/usr/bin/env bash
# The daemon's program holds the daemon and nothing of the tools: no bench, no emulator, no
# offline command. Fails naming each forbidden name found in `nm -C` of the program, and
# fails too when the program has no symbols to look at (a stripped file proves nothing).
#   tests/tools/daemon_symbols.sh build/eol-station
set -euo pipefail
program=${1:?usage: daemon_symbols.sh PROGRAM}
symbols=$(nm -C "$program")
# Something the daemon must hold, so an empty or stripped listing cannot pass.
grep -q 'eol::station::Station::Serve' <<<"$symbols" || {
  echo "$program: no eol::station::Station::Serve in its symbols (stripped, or not the daemon)"
  exit 1
}
status=0
# Benches (station/bench/, analysis/bench/), emulators (drivers/emulators/), the tool's
# commands (station/cli/ other than the station command) and the simulated bench
# (drivers/sim/, analysis/sim/).
for name in 'SafetyBench' 'CycleBench' 'PlantBench' 'HttpBench' 'DbBench' 'FitBench' \
            'GapIndependent' 'ProductionBench' 'ModbusFixtureServer' 'CanFixtureNode' \
            'AddDemoCommand' 'AddFixtureSimCommand' 'SimBench' 'SimFixture' 'SimDaq' \
            'TimeDomainSimulator' 'GapBench'; do
  count=$(grep -c -- "$name" <<<"$symbols" || true)
  if [ "$count" -ne 0 ]; then
    echo "$program: $count symbol(s) with '$name', e.g.: $(grep -m1 -- "$name" <<<"$symbols")"
    status=1
  fi
done
[ "$status" -eq 0 ] && echo "$program: no bench, emulator, simulator or tool symbols"
exit "$status"
