#!/usr/bin/env bash
# run_icarus.sh: replays a shadesim vector file (sim/vectors/vector_file.h) under Icarus Verilog.
# The file's header names the unit and the configuration ("# config <name> <json>"); the testbench
# is compiled with that configuration's parameters and the specular unit loads the PROM the header
# names (relative to the file). The parameters come from scripts/shd_config.py: when <name> is a
# configuration of the registry (`shd_config.py list`: vectors/config/<unit>_<name>.json, the same
# source CMake verilates from), from the registry file, so a stale vector file fails the
# testbench's comparison with its "# params" line; otherwise (a user's own configuration) from the
# JSON of the "# config" line itself. The script prints which source it used. The RTL files of the
# unit come from `shd_config.py unit`.
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
config_line=$(header config)
config=${config_line%% *}
[ "$unit" = spec ] || [ "$unit" = span ] || die "$vec: no '# unit spec|span' header line: not a shadesim vector file"
[ -n "$config" ] || die "$vec: no '# config' header line"
case "$config" in */*|.*) die "$vec: configuration name '$config'" ;; esac

shd_config() { python3 "$root/scripts/shd_config.py" "$@"; }
top=tb_${unit}_unit
# The registry's file of this configuration, if there is one.
registry=$(shd_config list --unit "$unit" 2>&1) || die "the configuration registry: $registry"
cfg_json=$(awk -v name="$config" '$2 == name { sub(/^[^ ]+ [^ ]+ /, ""); print; exit }' <<<"$registry")
# -P<top>.<Name>=<value> for every member of the configuration's "rtl" object (integers only).
if [ -n "$cfg_json" ]; then
  source_text="the registry's $unit:$config ($cfg_json)"
  params=$(shd_config args --tool icarus --top "$top" "$cfg_json" 2>&1) || die "$params"
else
  case "$config_line" in *" "*) cfg_rtl=${config_line#* } ;; *) cfg_rtl="" ;; esac
  [ -n "$cfg_rtl" ] || die "$vec: '$config' is not a $unit configuration of the registry, and its '# config' line has no parameters"
  source_text="the '# config $config' line of $(basename "$vec") ($unit:$config is not in the registry)"
  params=$(printf '{"name": "%s", "rtl": %s}\n' "$config" "$cfg_rtl" |
           shd_config args --tool icarus --top "$top" --unit "$unit" - 2>&1) ||
    die "$vec: the parameters of its '# config' line: $params"
fi
pargs=()
while IFS= read -r p; do [ -z "$p" ] || pargs+=("$p"); done <<<"$params"
[ ${#pargs[@]} -gt 0 ] || die "$source_text: no parameters"

# The unit's RTL files: `shd_config.py unit` prints its top module, then the files.
unit_info=$(shd_config unit "$unit") || die "shd_config.py unit $unit failed"
mapfile -t sources < <(sed -n '2,$p' <<<"$unit_info")
[ ${#sources[@]} -gt 0 ] || die "no RTL files for the $unit unit"
for f in "${sources[@]}"; do [ -f "$f" ] || die "RTL file $f not found"; done

if [ "$unit" = spec ]; then
  if [ -z "$prom" ]; then
    prom=$(header prom)
    [ -n "$prom" ] || die "$vec: no '# prom' header line"
    case "$prom" in /*) ;; *) prom=$(dirname "$vec")/$prom ;; esac
  fi
  [ -f "$prom" ] || die "PROM file $prom does not exist"
  prom=$(cd "$(dirname "$prom")" && pwd)/$(basename "$prom")
else
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
echo "run_icarus.sh: parameters from $source_text"
echo "run_icarus.sh: $unit/$config, $(basename "$vec") under $(iverilog -V 2>&1 | head -1 | cut -d' ' -f1-4)"
# vvp prints "VCD info: ..." when dumping; $fatal gives exit status 1.
vvp -n "$work/$top.vvp" "${plusargs[@]}" "${extended[@]}"
