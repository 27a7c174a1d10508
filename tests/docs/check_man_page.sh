#!/usr/bin/env bash
# The manual page eol(1) (cmake/ManPage.cmake) must hold the program's help: its NAME and
# SYNOPSIS from `eol --help`, and a subsection for every subcommand `eol --help` lists.
# Usage: check_man_page.sh EOL PAGE    (exit 0: complete; 1: names what is missing)
set -euo pipefail
eol=$1
page=$2
[[ -s $page ]] || { echo "check_man_page: $page is missing or empty" >&2; exit 1; }
missing=()
grep -q '^\.SH NAME' "$page" || missing+=("section NAME")
grep -q '^\.SH COMMANDS' "$page" || missing+=("section COMMANDS")
mapfile -t subs < <("$eol" --help | sed -n '/^Subcommands:/,/^$/p' | sed -n 's/^  \([a-z][a-z0-9-]*\).*/\1/p')
((${#subs[@]} > 0)) || missing+=("subcommands in '$eol --help'")
for s in "${subs[@]}"; do
  grep -q "^\.SS \"eol $s\"" "$page" || missing+=("subcommand $s")
  # Its own usage line must be in the page.
  # Whole help first: `eol ... | grep -m1` would let grep close the pipe early, and under
  # pipefail eol's SIGPIPE failed the check now and then.
  help=$("$eol" "$s" --help)
  usage=$(grep -m1 '^Usage:' <<<"$help")
  grep -qF -- "$usage" "$page" || missing+=("the help text of $s ('$usage')")
done
if ((${#missing[@]} > 0)); then
  printf 'check_man_page: %s lacks %s\n' "$page" "${missing[@]}" >&2
  exit 1
fi
echo "check_man_page: $page has the help of all ${#subs[@]} subcommands"
