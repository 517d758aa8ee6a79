#!/usr/bin/env bash
# report_test.sh SHADESIM WORK [SCENE [tools-absent]]: `shadesim report` on SCENE (default builtin:sphere) in two
# lane modes, checked
# from outside (testbench/report_check.py): every number of report.md's tables is its
# report.json value formatted, report.csv holds report.json's rows, the plots are valid PNG files
# whose data is the CSV beside them and that CSV is report.json's, the images are equal across
# the modes (and `shadesim render` in the second mode writes the same PNG bytes), and two rows'
# error figures and cycles equal what `shadesim render --json` gives. The report runs with
# --no-hardware (the place and route of the units takes minutes; testbench/pnr_test.sh and the
# synth_ tests run the tools). With tools-absent, a second run without yosys and nextpnr on PATH
# must still write the report, name the absent figures and why, and exit 1.
set -euo pipefail
shadesim=$(realpath "$1")
work=$2
scene=${3:-builtin:sphere}
case "$scene" in builtin:*) ;; *) scene=$(realpath "$scene") ;; esac
here=$(cd "$(dirname "$0")" && pwd)
source "$here/fresh_work.sh"
fresh_work "$work"
cd "$work"
# SHD_REPORT_ARGS: more options for the reports (fewer units: the sanitizer build, other scenes).
# shellcheck disable=SC2086
"$shadesim" report --scene "$scene" --modes serial,evenodd --bench 1 --no-hardware ${SHD_REPORT_ARGS:-} -o r --quiet > report.out
cat report.out
if [ "${4:-}" = tools-absent ]; then
  mkdir -p nobin cache
  status=0
  # shellcheck disable=SC2086
  PATH=$work/nobin "$shadesim" report --scene "$scene" --modes serial --bench 1 --hardware-cache cache ${SHD_REPORT_ARGS:-} \
    -o r2 --quiet > r2.out 2> r2.err || status=$?
  [ "$status" -eq 1 ] || { cat r2.err; echo "report_test: without the tools: exit $status, expected 1" >&2; exit 1; }
  grep -q '^report: area absent: yosys' r2.err && grep -q '^report: fmax, time absent: place and route' r2.err \
    || { cat r2.err; echo "report_test: the absent figures are not named" >&2; exit 1; }
  grep -q '^- area (every row): yosys' r2/report.md && grep -q '^- fmax, time (every row): place and route' r2/report.md \
    || { echo "report_test: report.md does not say which figures are absent" >&2; exit 1; }
fi
# Two sample rows, by render in the second lane mode: a device lobe with the fixed-point
# datapath, an exact lobe with Gouraud.
"$shadesim" render --scene "$scene" --method phong-fixed --brdf quadratic --mode evenodd -o s1.png --json s1.json --quiet > /dev/null
"$shadesim" render --scene "$scene" --method gouraud --brdf blinn --mode evenodd -o s2.png --json s2.json --quiet > /dev/null
python3 "$here/report_check.py" r \
  "phong-fixed,quadratic,evenodd,s1.json,s1.png" "gouraud,blinn,evenodd,s2.json,s2.png"
