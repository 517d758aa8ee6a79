#!/usr/bin/env bash
# install_test.sh SOURCE_DIR BUILD_DIR: installs the build into a scratch prefix and uses it as a
# user would, from another directory, with the source and build trees hidden (a private mount
# namespace with an empty tmpfs over each, where `unshare -m` is permitted, as for root): the
# programs must work from their embedded configurations, the installed scripts must find the
# installed RTL. The checks:
#   - shadesim configs, prom, spec-error, vectors and render (with the RTL in the loop), and a
#     replay of the written vector file on the installed verilated models;
#   - shadesim_systemc replaying a vector file of the default configuration;
#   - share/shadesim/testbench/icarus/run_icarus.sh replaying it under Icarus;
#   - share/shadesim/scripts/synth.py synthesising a configuration for iCE40 with its checks;
#   - shadesim report, its plots made by share/shadesim/scripts/plot_report.py.
set -euo pipefail

checks() {  # checks PREFIX RUN_DIR
  local prefix=$1 S=$1/bin/shadesim share=$1/share/shadesim
  cd "$2"
  step() { echo "install_test: $*"; "$@"; }
  step "$S" --version
  step "$S" configs | tee configs.txt
  grep -q '^spec default ' configs.txt
  grep -q '^span sierpinski ' configs.txt
  step "$S" prom --config default --format hex -o default.hex
  step "$S" prom --config "$share/vectors/config/spec_narrow.json" --format coe -o narrow.coe
  step "$S" spec-error --config narrow --n-list 8,32,200 --quiet >spec_error.txt
  grep -q 'datapath' spec_error.txt
  step "$S" vectors --unit spec --config narrow --cycles 400 --seed 5 -o narrow.vec
  test -s narrow.vec.hex  # the PROM written beside it
  step "$S" replay narrow.vec
  step "$S" render --scene builtin:sphere --method phong-fixed --brdf quadratic --rtl --quiet -o sphere.png --json sphere.json
  grep -q '"pixel_mismatches": 0' sphere.json
  test -s sphere.png && test -s sphere_reference.png && test -s sphere_error.png
  # The SystemC models of every build include default (the sanitizer build has few others).
  step "$S" vectors --unit spec --config default --cycles 400 --seed 5 -o default.vec
  step "$prefix/bin/shadesim_systemc" --unit spec --config default --vector-file default.vec --quiet
  step "$share/testbench/icarus/run_icarus.sh" narrow.vec
  step "$share/scripts/synth.py" spec:narrow --prom "$share/vectors/prom/spec_narrow.hex" --target ice40 --out synth --check
  test -s synth/summary.json
  # report: its plots by the installed scripts/plot_report.py
  step "$S" report --modes serial --bench 1 --no-hardware -o report --quiet
  grep -q '"made": true' report/report.json && test -s report/error_vs_cycles.png
  echo "install_test: the installed tree works from $2"
}

if [ "${1:-}" = --checks ]; then
  checks "$2" "$3"
  exit
fi
src=$(cd "$1" && pwd)
build=$(cd "$2" && pwd)
work=$(mktemp -d /tmp/shadesim-install-test.XXXXXX)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/run"
cmake --install "$build" --prefix "$work/prefix" >"$work/install.log"
cp "$0" "$work/install_test.sh"  # this script, outside the trees it hides
# shellcheck disable=SC2016
if unshare -m true 2>/dev/null; then
  echo "install_test: the source tree $src and the build tree $build are hidden for the checks"
  unshare -m bash -c 'mount -t tmpfs none "$2" && mount -t tmpfs none "$1" && exec bash "$3" --checks "$4" "$5"' \
    _ "$src" "$build" "$work/install_test.sh" "$work/prefix" "$work/run"
else
  echo "install_test: unshare -m is not permitted here: the checks run with the source tree present"
  bash "$work/install_test.sh" --checks "$work/prefix" "$work/run"
fi
