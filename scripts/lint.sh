#!/usr/bin/env bash
# lint.sh: the RTL portability gate (DESIGN.md: rtl/ must pass `verilator --lint-only -Wall` and
# compile under Icarus `iverilog -g2012`). Checks, one output line each:
#   verilator  <file>    every rtl/*.v on its own, top = the file's name, default parameters
#                        (submodules are found with -y rtl)
#   verilator  <config>  shd_spec_unit with the "rtl" parameters of vectors/config/spec_<config>.json
#                        (-G<Name>=<value>)
#   iverilog   <config>  iverilog -g2012 -Wall compile of the same (-Pshd_spec_unit.<Name>=<value>)
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
TOP=shd_spec_unit
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
configs=("$ROOT"/vectors/config/spec_*.json)
shopt -u nullglob
((${#rtl_files[@]} > 0)) || { echo "lint.sh: error: no rtl/*.v" >&2; exit 2; }
((${#configs[@]} > 0)) || { echo "lint.sh: error: no vectors/config/spec_*.json" >&2; exit 2; }

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

for cfg in "${configs[@]}"; do
  name=$(basename "$cfg" .json)
  name=${name#spec_}
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
    printf 'FAIL  config     %s\n' "$name"
    sed 's/^/      /' "$tmp/out"
    failures=$((failures + 1))
    continue
  fi
  gargs=()
  pargs=()
  while IFS= read -r kv; do
    gargs+=("-G$kv")
    pargs+=("-P$TOP.$kv")
  done <<<"$params"
  run_check "verilator  $TOP [$name]" verilator_lint --top-module "$TOP" "${gargs[@]}" "$RTL/$TOP.v"
  run_check "iverilog   $TOP [$name]" \
    iverilog -g2012 -Wall -s "$TOP" "${pargs[@]}" -o "$tmp/$name.vvp" "${rtl_files[@]}"
done

if ((failures > 0)); then
  echo "lint.sh: $failures check(s) failed"
  exit 1
fi
echo "lint.sh: all checks passed"
