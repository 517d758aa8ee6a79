#!/usr/bin/env bash
# run_icarus.sh: replays a shadesim vector file (sim/vector_file.h) under Icarus Verilog.
# The file's header names the unit and the configuration; the testbench is compiled with that
# configuration's parameters (vectors/config/<unit>_<config>.json, the same source CMake
# verilates from) and the specular unit loads the PROM the header names (relative to the file).
#
#   testbench/icarus/run_icarus.sh [--fst WAVE.fst] [--prom PROM.hex] [--work DIR] FILE.vec
#
#   --fst   also dump a waveform (vvp -fst; open it with gtkwave WAVE.fst)
#   --prom  spec: load this PROM instead of the header's
#   --work  where the compiled testbench goes (default: a temporary directory, removed after)
# Exit status: 0 every output matched; 1 a mismatch or malformed input (the testbench's $fatal);
# 2 a missing tool, file or configuration, or an iverilog warning (any compiler output fails,
# as in scripts/lint.sh: Icarus exits 0 on warnings).
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
usage() { echo "usage: testbench/icarus/run_icarus.sh [--fst WAVE.fst] [--prom PROM.hex] [--work DIR] FILE.vec" >&2; exit 2; }
die() { echo "run_icarus.sh: error: $*" >&2; exit 2; }

fst="" prom="" work="" vec=""
while [ $# -gt 0 ]; do
  case "$1" in
    --fst) [ $# -ge 2 ] || usage; fst=$2; shift ;;
    --prom) [ $# -ge 2 ] || usage; prom=$2; shift ;;
    --work) [ $# -ge 2 ] || usage; work=$2; shift ;;
    -h|--help) usage ;;
    -*) echo "run_icarus.sh: unknown option '$1'" >&2; usage ;;
    *) [ -z "$vec" ] || usage; vec=$1 ;;
  esac
  shift
done
[ -n "$vec" ] || usage
for tool in iverilog vvp python3; do
  command -v "$tool" >/dev/null || die "$tool not found (scripts/install_deps.sh installs it)"
done
[ -f "$vec" ] || die "no vector file $vec"
vec=$(cd "$(dirname "$vec")" && pwd)/$(basename "$vec")

# "# unit <u>" and "# config <name> <json>" from the header (before the first record).
header() { awk -v key="$1" '/^[^#]/ { exit } $1 == "#" && $2 == key { sub(/^# [^ ]+ /, ""); print; exit }' "$vec"; }
unit=$(header unit)
config=$(header config | cut -d' ' -f1)
[ "$unit" = spec ] || [ "$unit" = span ] || die "$vec: no '# unit spec|span' header line: not a shadesim vector file"
[ -n "$config" ] || die "$vec: no '# config' header line"
case "$config" in */*|.*) die "$vec: configuration name '$config'" ;; esac
cfg_json=$root/vectors/config/${unit}_${config}.json
[ -f "$cfg_json" ] || die "$vec: configuration '$config' has no $cfg_json"

top=tb_${unit}_unit
# -P<top>.<Name>=<value> for every member of the configuration's "rtl" object (integers only).
pargs=()
while IFS= read -r kv; do pargs+=("-P$top.$kv"); done < <(python3 - "$cfg_json" <<'EOF'
import json, re, sys
path = sys.argv[1]
try:
    rtl = json.load(open(path))["rtl"]
    assert isinstance(rtl, dict), "'rtl' is not an object"
except (OSError, ValueError, KeyError, AssertionError) as e:
    sys.exit(f"run_icarus.sh: error: {path}: {e!r}")
for k, v in rtl.items():
    if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", k) or type(v) is not int:
        sys.exit(f"run_icarus.sh: error: {path}: rtl.{k} = {v!r} is not an integer parameter")
    print(f"{k}={v}")
EOF
)
[ ${#pargs[@]} -gt 0 ] || die "$cfg_json: no parameters"

if [ "$unit" = spec ]; then
  sources=("$root/rtl/shd_spec_unit.v" "$root/rtl/shd_coef_rom.v" "$root/rtl/shd_pipe_reg.v")
  if [ -z "$prom" ]; then
    prom=$(header prom)
    [ -n "$prom" ] || die "$vec: no '# prom' header line"
    case "$prom" in /*) ;; *) prom=$(dirname "$vec")/$prom ;; esac
  fi
  [ -f "$prom" ] || die "PROM file $prom does not exist"
  prom=$(cd "$(dirname "$prom")" && pwd)/$(basename "$prom")
else
  sources=("$root/rtl/shd_span_unit.v")
  [ -z "$prom" ] || die "--prom: the span unit has no PROM"
fi

if [ -z "$work" ]; then
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
fi
mkdir -p "$work"
if ! iverilog -g2012 -Wall -I "$root/testbench/icarus" -s "$top" "${pargs[@]}" -o "$work/$top.vvp" \
       "$root/testbench/icarus/$top.v" "${sources[@]}" >"$work/iverilog.log" 2>&1 ||
   [ -s "$work/iverilog.log" ]; then
  cat "$work/iverilog.log" >&2
  die "iverilog failed or warned (above)"
fi

plusargs=("+vec=$vec")
[ "$unit" = spec ] && plusargs+=("+prom=$prom")
extended=()
if [ -n "$fst" ]; then
  fst=$(cd "$(dirname "$fst")" && pwd)/$(basename "$fst")
  plusargs+=("+dump=$fst")
  extended+=(-fst)
fi
echo "run_icarus.sh: $unit/$config, $(basename "$vec") under $(iverilog -V 2>&1 | head -1 | cut -d' ' -f1-4)"
# vvp prints "VCD info: ..." when dumping; $fatal gives exit status 1.
vvp -n "$work/$top.vvp" "${plusargs[@]}" "${extended[@]}"
