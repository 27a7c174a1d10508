#!/usr/bin/env bash
# Fails, naming the files, when a C++ file differs from the repository's .clang-format
# (run by the README's test command; fix with `clang-format -i FILE`).
set -euo pipefail
cd "$(dirname "$0")/.."
# tests/support/vcan is a C tool with a style of its own.
mapfile -t files < <(git ls-files '*.cc' '*.h' ':!tests/support/vcan')
if ! clang-format --dry-run --Werror "${files[@]}" 2>/tmp/eol-format.$$; then
  grep -o '^[^:]*:[0-9]*' /tmp/eol-format.$$ | cut -d: -f1 | sort -u | sed 's/^/  not formatted: /' >&2
  rm -f /tmp/eol-format.$$
  echo "check-format: run clang-format -i on the files above" >&2
  exit 1
fi
rm -f /tmp/eol-format.$$
echo "check-format: ${#files[@]} files match .clang-format"
