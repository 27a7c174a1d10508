#!/usr/bin/env bash
# Builds the libFuzzer targets (clang++-14, EOL_FUZZ=ON) and runs each on a copy of its seed
# corpus (tests/fuzz/corpus/<target>). Exits 1 on any finding (crash, leak, undefined
# behaviour, timeout, out-of-memory, broken contract), naming the input that reproduces it.
#
#   tests/fuzz/run_fuzzers.sh [--build DIR] [--seconds N] [--fork N] [--build-only] [TARGET...]
#
#   --build DIR   the fuzz build tree (default build/fuzz); configured when it is not yet
#   --seconds N   fuzzing time per target (default 20: the CI-sized run of the test suite)
#   --build-only  configure and build the tree, fuzz nothing (deploy/run-tests.sh builds it
#                 with the rest, so the suite's fuzz_readers test only fuzzes)
#   --fork N      N fuzzing processes per target that go on after a finding, so a long run
#                 collects every finding instead of stopping at the first (libFuzzer -fork)
#   TARGET        recipe config frf_csv zma recording_csv wav http_body curve_codec (default: all)
#
# Each run's new inputs, findings and log stay in DIR/runs/<target>/ until the next run.
set -euo pipefail
src="$(cd "$(dirname "$0")/../.." && pwd)"
build="$src/build/fuzz"
seconds=20
fork=0
build_only=0
targets=()
while (($#)); do
  case "$1" in
    --build) build="$2"; shift 2 ;;
    --seconds) seconds="$2"; shift 2 ;;
    --fork) fork="$2"; shift 2 ;;
    --build-only) build_only=1; shift ;;
    -*) echo "run_fuzzers: unknown option $1" >&2; exit 2 ;;
    *) targets+=("$1"); shift ;;
  esac
done
((${#targets[@]})) || targets=(recipe config frf_csv zma recording_csv wav http_body curve_codec)

if ! command -v clang++-14 >/dev/null 2>&1; then
  echo "run_fuzzers: clang++-14 not found (install clang-14 and libclang-rt-14-dev:" \
       "deploy/install-deps.sh --tests)" >&2
  exit 1
fi
mkdir -p "$build"
build="$(cd "$build" && pwd)"
if [[ ! -f "$build/build.ninja" ]]; then
  launcher=()
  if command -v ccache >/dev/null 2>&1; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
  cmake -S "$src" -B "$build" -G Ninja -DEOL_FUZZ=ON -DCMAKE_CXX_COMPILER=clang++-14 \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo "${launcher[@]}" > "$build/configure.log" 2>&1 ||
    { cat "$build/configure.log"; exit 1; }
fi
# The machine is shared with the rest of the suite: build and fuzz at a lower priority.
CCACHE_BASEDIR="${CCACHE_BASEDIR:-$src}" nice -n 10 cmake --build "$build" --target eol_fuzzers
if ((build_only)); then exit 0; fi

findings=0
for t in "${targets[@]}"; do
  bin="$build/${t}_fuzzer"
  seeds="$src/tests/fuzz/corpus/$t"
  [[ -x "$bin" && -d "$seeds" ]] || { echo "run_fuzzers: no target '$t'" >&2; exit 2; }
  run="$build/runs/$t"
  rm -rf "$run"
  mkdir -p "$run/corpus" "$run/findings"
  cp "$seeds"/* "$run/corpus/"
  opts=(-max_total_time="$seconds" -rss_limit_mb=512 -malloc_limit_mb=512 -timeout=10
        -artifact_prefix="$run/findings/" -print_final_stats=1)
  # The JSON readers get the schema's keys and edge values as a dictionary.
  case "$t" in recipe | config | http_body) opts+=(-dict="$src/tests/fuzz/json.dict") ;; esac
  if ((fork > 0)); then opts+=(-fork="$fork" -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1); fi
  echo "run_fuzzers: $t for ${seconds} s"
  status=0
  (cd "$run" && nice -n 10 "$bin" "${opts[@]}" "$run/corpus") > "$run/fuzz.log" 2>&1 || status=$?
  # One process prints stat:: lines; -fork prints "#<runs>: cov: ..." progress lines.
  { grep -E '^(stat::number_of_executed_units|stat::new_units_added)' "$run/fuzz.log" ||
    grep -E '^#[0-9]+: cov' "$run/fuzz.log" | tail -1 || true; } | sed "s/^/  $t: /"
  shopt -s nullglob
  found=("$run/findings"/*)
  shopt -u nullglob
  if ((status != 0 || ${#found[@]} > 0)); then
    findings=$((findings + 1))
    echo "run_fuzzers: FINDING in $t (exit $status); log $run/fuzz.log"
    { grep -E 'ERROR: |FINDING: |SUMMARY: |runtime error' "$run/fuzz.log" || true; } | head -20 |
      sed 's/^/  /'
    for f in "${found[@]}"; do echo "  reproduce: $bin $f"; done
  fi
done
if ((findings > 0)); then
  echo "run_fuzzers: $findings of ${#targets[@]} targets had findings"
  exit 1
fi
echo "run_fuzzers: no findings in ${#targets[@]} targets (${seconds} s each)"
