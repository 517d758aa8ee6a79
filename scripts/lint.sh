#!/usr/bin/env bash
# lint.sh: the RTL portability gate: the RTL must pass `verilator --lint-only -Wall` and compile
# under Icarus `iverilog -g2012`, on its own and with the parameters of every configuration of the
# registry (vectors/config/, read through scripts/shd_config.py). Checks, one output line each:
#   verilator  <file>    every rtl/*.v on its own, top = the file's name, default parameters
#                        (submodules are found with -y rtl)
#   verilator  <top> [<config>]
#                        the unit with the "rtl" parameters of a configuration (-G<Name>=<value>
#                        from `shd_config.py args --tool verilator`): shd_spec_unit for every
#                        spec configuration, shd_span_unit for every span configuration
#                        (`shd_config.py list`: vectors/config/<unit>_<config>.json)
#   iverilog   <top> [<config>]
#                        iverilog -g2012 -Wall compile of the same (-P<top>.<Name>=<value> from
#                        `shd_config.py args --tool icarus`)
#   config     registry  shown only when `shd_config.py list` rejects a configuration file
#                        (a FAIL: the configuration checks are skipped)
# Any warning or error fails the check: Icarus exits 0 on warnings (an unknown -P parameter, an
# out-of-range part select), so any output at all counts as a failure. Lint waivers would be
# Verilator configuration files (.vlt) in rtl/, passed to every Verilator run; there are none:
# the RTL is lint-clean without them.
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
shopt -u nullglob
((${#rtl_files[@]} > 0)) || { echo "lint.sh: error: no rtl/*.v" >&2; exit 2; }

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

failures=0
shd_config() { python3 "$ROOT/scripts/shd_config.py" "$@"; }
# "<top> <name> <file>" per configuration of the registry, the spec unit first.
configs=()
if ! listing=$(shd_config list 2>"$tmp/out"); then
  printf 'FAIL  config     registry\n'
  sed 's/^/      /' "$tmp/out"
  failures=$((failures + 1))
else
  for unit in spec span; do
    top=$(shd_config unit "$unit" | sed -n 1p)
    n=0
    while read -r u name file; do
      [[ $u == "$unit" ]] || continue
      configs+=("$top $name $file")
      n=$((n + 1))
    done <<<"$listing"
    ((n > 0)) || { echo "lint.sh: error: no $unit configuration in vectors/config" >&2; exit 2; }
  done
fi

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
  read -r top name cfg <<<"$entry"
  # The parameter options of each tool, one per line (shd_config.py validates the file).
  if ! gparams=$(shd_config args --tool verilator "$cfg" 2>"$tmp/out") ||
     ! pparams=$(shd_config args --tool icarus --top "$top" "$cfg" 2>"$tmp/out"); then
    printf 'FAIL  config     %s\n' "$top [$name]"
    sed 's/^/      /' "$tmp/out"
    failures=$((failures + 1))
    continue
  fi
  mapfile -t gargs <<<"$gparams"
  mapfile -t pargs <<<"$pparams"
  run_check "verilator  $top [$name]" verilator_lint --top-module "$top" "${gargs[@]}" "$RTL/$top.v"
  run_check "iverilog   $top [$name]" \
    iverilog -g2012 -Wall -s "$top" "${pargs[@]}" -o "$tmp/$top.$name.vvp" "${rtl_files[@]}"
done

if ((failures > 0)); then
  echo "lint.sh: $failures check(s) failed"
  exit 1
fi
echo "lint.sh: all checks passed"
