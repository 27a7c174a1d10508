#!/usr/bin/env python3
"""Lists the GoogleTest tests that ran longer than a threshold in the last ctest run.

    python3 tests/tools/slow_tests.py BUILD_DIR [--over SECONDS]

Reads BUILD_DIR/Testing/Temporary/CTestCostData.txt (ctest writes each test's mean time there)
and prints tests/slow_tests.txt: a comment head, then one gtest filter pattern per line, sorted. A parametrised
test (ctest name with '/') is printed as its suite with '*' so every instance goes together.
Tests that are not GoogleTest tests (no '.' in the name) are skipped: label those in
tests/CMakeLists.txt itself.
"""
import argparse
import pathlib
import sys

HEADER = """\
# Tests that are not in the quick label `fast`: each ran longer than {over:g} s in the last full
# run. One GoogleTest filter pattern per line ('#' starts a comment). Every test not listed here
# is labelled `fast` (ctest -L fast), these are labelled `slow`. Made by
#   python3 tests/tools/slow_tests.py build > tests/slow_tests.txt
# after a full ctest run in build/ (a new slow test is `fast` until then)."""


def slow_patterns(cost_file, over):
    patterns = set()
    for line in cost_file.read_text().splitlines():
        parts = line.split()
        if len(parts) != 3 or "." not in parts[0]:
            continue
        name, seconds = parts[0], float(parts[2])
        if seconds <= over:
            continue
        suite, _, test = name.partition(".")
        patterns.add(f"{suite}.*" if "/" in name else name)
    return sorted(patterns)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("build_dir", type=pathlib.Path)
    p.add_argument("--over", type=float, default=2.5, help="seconds (default 2.5)")
    a = p.parse_args()
    cost = a.build_dir / "Testing" / "Temporary" / "CTestCostData.txt"
    if not cost.is_file():
        sys.exit(f"slow_tests: {cost} not found: run ctest in {a.build_dir} first")
    print(HEADER.format(over=a.over))
    print("\n".join(slow_patterns(cost, a.over)))


if __name__ == "__main__":
    main()
