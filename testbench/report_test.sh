#!/usr/bin/env bash
# report_test.sh SHADESIM WORK [SCENE]: `shadesim report` on SCENE (default builtin:sphere) in two
# lane modes, checked
# from outside (testbench/report_check.py): every number of report.md's tables is its
# report.json value formatted, report.csv holds report.json's rows, the plots are valid PNG files
# whose data is the CSV beside them and that CSV is report.json's, the images are equal across
# the modes (and `shadesim render` in the second mode writes the same PNG bytes), and two rows'
# error figures and cycles equal what `shadesim render --json` gives.
set -euo pipefail
shadesim=$(realpath "$1")
work=$2
scene=${3:-builtin:sphere}
case "$scene" in builtin:*) ;; *) scene=$(realpath "$scene") ;; esac
here=$(cd "$(dirname "$0")" && pwd)
source "$here/fresh_work.sh"
fresh_work "$work"
cd "$work"
"$shadesim" report --scene "$scene" --modes serial,evenodd --bench 1 -o r --quiet > report.out
cat report.out
# Two sample rows, by render in the second lane mode: a device lobe with the fixed-point
# datapath, an exact lobe with Gouraud.
"$shadesim" render --scene "$scene" --method phong-fixed --brdf quadratic --mode evenodd -o s1.png --json s1.json --quiet > /dev/null
"$shadesim" render --scene "$scene" --method gouraud --brdf blinn --mode evenodd -o s2.png --json s2.json --quiet > /dev/null
python3 "$here/report_check.py" r \
  "phong-fixed,quadratic,evenodd,s1.json,s1.png" "gouraud,blinn,evenodd,s2.json,s2.png"
