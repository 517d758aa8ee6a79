#!/usr/bin/env bash
# lint.sh: the RTL portability gate (DESIGN.md: rtl/ must pass `verilator --lint-only -Wall` and
# compile under Icarus `iverilog -g2012`). Checks, one output line each:
#   verilator  <file>    every rtl/*.v on its own, top = the file's name, default parameters
#                        (submodules are found with -y rtl)
#   verilator  <top> [<config>]
#                        the unit with the "rtl" parameters of a configuration (-G<Name>=<value>):
#                        shd_spec_unit for every vectors/config/spec_<config>.json,
#                        shd_span_unit for every vectors/config/span_<config>.json
#   iverilog   <top> [<config>]
#                        iverilog -g2012 -Wall compile of the same (-P<top>.<Name>=<value>)
# Any warning or error fails the check: Icarus exits 0 on warnings (an unknown -P parameter, an
# out-of-range part select), so any output at all counts as a failure. Lint waivers, if the
# project adds them, are Verilator configuration files rtl/*.vlt and are passed to every
# Verilator run.
#
# Usage: scripts/lint.sh [-v]   (-v prints the tool output of passing checks too)
# Exit status: 0 all checks pass, 1 some check failed, 2 a tool or input is missing.
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
RTL=$ROOT/rtl
verbose=0
case ${1:-} in
  -v) verbose=1 ;;
  "") ;;
  *) echo "usage: scripts/lint.sh [-v]" >&2; exit 2 ;;
esac

for tool in verilator iverilog python3; do
  command -v "$tool" >/dev/null || { echo "lint.sh: error: $tool not found" >&2; exit 2; }
done

shopt -s nullglob
rtl_files=("$RTL"/*.v)
waivers=("$RTL"/*.vlt)
spec_configs=("$ROOT"/vectors/config/spec_*.json)
span_configs=("$ROOT"/vectors/config/span_*.json)
shopt -u nullglob
((${#rtl_files[@]} > 0)) || { echo "lint.sh: error: no rtl/*.v" >&2; exit 2; }
((${#spec_configs[@]} > 0)) || { echo "lint.sh: error: no vectors/config/spec_*.json" >&2; exit 2; }
((${#span_configs[@]} > 0)) || { echo "lint.sh: error: no vectors/config/span_*.json" >&2; exit 2; }
# "<top> <config file>" per configuration: the file name's prefix names the unit.
configs=()
for cfg in "${spec_configs[@]}"; do configs+=("shd_spec_unit $cfg"); done
for cfg in "${span_configs[@]}"; do configs+=("shd_span_unit $cfg"); done

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

failures=0
# run_check <label> <command...>: passes when the command exits 0 and prints nothing.
run_check() {
  local label=$1 rc=0
  shift
  "$@" >"$tmp/out" 2>&1 || rc=$?
  if ((rc == 0)) && [[ ! -s $tmp/out ]]; then
    printf 'PASS  %s\n' "$label"
    if ((verbose)); then sed 's/^/      /' "$tmp/out"; fi
  else
    printf 'FAIL  %s (exit %d)\n' "$label" "$rc"
    sed 's/^/      /' "$tmp/out"
    failures=$((failures + 1))
  fi
}

verilator_lint() {
  verilator --lint-only -Wall -y "$RTL" "${waivers[@]}" "$@"
}

for f in "${rtl_files[@]}"; do
  m=$(basename "$f" .v)
  run_check "verilator  $m.v" verilator_lint --top-module "$m" "$f"
done

for entry in "${configs[@]}"; do
  top=${entry%% *}
  cfg=${entry#* }
  name=$(basename "$cfg" .json)
  name=${name#*_}
  # One "Name=Value" per line from the configuration's "rtl" object, integers only.
  if ! params=$(python3 - "$cfg" 2>"$tmp/out" <<'EOF'
import json, re, sys
path = sys.argv[1]
try:
    rtl = json.load(open(path))["rtl"]
    assert isinstance(rtl, dict), "'rtl' is not an object"
except (OSError, ValueError, KeyError, AssertionError) as e:
    sys.exit(f"lint.sh: error: {path}: {e!r}")
for k, v in rtl.items():
    if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", k) or type(v) is not int:
        sys.exit(f"lint.sh: error: {path}: rtl.{k} = {v!r} is not an integer parameter")
    print(f"{k}={v}")
EOF
  ); then
    printf 'FAIL  config     %s\n' "$top [$name]"
    sed 's/^/      /' "$tmp/out"
    failures=$((failures + 1))
    continue
  fi
  gargs=()
  pargs=()
  while IFS= read -r kv; do
    gargs+=("-G$kv")
    pargs+=("-P$top.$kv")
  done <<<"$params"
  run_check "verilator  $top [$name]" verilator_lint --top-module "$top" "${gargs[@]}" "$RTL/$top.v"
  run_check "iverilog   $top [$name]" \
    iverilog -g2012 -Wall -s "$top" "${pargs[@]}" -o "$tmp/$top.$name.vvp" "${rtl_files[@]}"
done

if ((failures > 0)); then
  echo "lint.sh: $failures check(s) failed"
  exit 1
fi
echo "lint.sh: all checks passed"
