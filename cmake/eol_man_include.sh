#!/usr/bin/env bash
# Writes the help2man include file for the manual page of `eol`: one subsection per
# subcommand, its text exactly what `eol SUB --help` prints (cmake/ManPage.cmake runs this,
# then help2man on `eol --help` with it). Usage: eol_man_include.sh EOL OUT
set -euo pipefail
eol=$1
out=$2
# The subcommands, as `eol --help` lists them (two-space indented names under "Subcommands:").
mapfile -t subs < <("$eol" --help | sed -n '/^Subcommands:/,/^$/p' | sed -n 's/^  \([a-z][a-z0-9-]*\).*/\1/p')
if ((${#subs[@]} == 0)); then
  echo "eol_man_include.sh: no subcommands in '$eol --help'" >&2
  exit 1
fi
{
  echo '[>DESCRIPTION]'
  echo 'Run one subcommand; each takes \fB\-\-help\fR. The text of every subcommand'"'"'s help follows.'
  echo
  echo '[COMMANDS]'
  for s in "${subs[@]}"; do
    echo ".SS \"eol $s\""
    echo '.nf'
    # roff: a backslash is \e; a line starting with . or ' would be a request.
    "$eol" "$s" --help | sed -e 's/\\/\\e/g' -e "s/^\\([.']\\)/\\\\\\&\\1/"
    echo '.fi'
  done
  echo
  echo '[EXIT STATUS]'
  echo '0 done; 1 the command'"'"'s negative answer (a serial with no tests, a drift alarm; see each'
  echo 'command'"'"'s help); 2 a usage error (unknown option, bad argument, missing file) or a failure'
  echo 'the command names; \fBeol station\fR exits 78 on a configuration error (systemd does not'
  echo 'restart it).'
  echo
  echo '[FILES]'
  echo '.TP'
  echo '.I /etc/eol/station.json'
  echo 'the station'"'"'s configuration (\fBeol station \-\-config\fR)'
  echo '.TP'
  echo '.I /var/lib/eol/'
  echo 'the records (eol.sqlite) and the recipes in use'
  echo '.TP'
  echo '.I /usr/share/eol/'
  echo 'the shipped recipes, the operator and engineer pages'
  echo
  echo '[SEE ALSO]'
  echo 'The project'"'"'s README.md and deploy/OPERATIONS.md (installing, wiring, plant integration).'
} > "$out"
