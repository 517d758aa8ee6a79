#!/usr/bin/env bash
# pnr_test.sh WORK CONFIG [pnr.py options...]: scripts/pnr.py places and routes CONFIG (a
# registry configuration file) on both devices into WORK/pnr: the UP5K fits with an fmax above
# 0 (no more than nextpnr's own figure, which leaves out the paths through DSPs), and the HX8K,
# which has no DSP, reports the DSP non-fit before placement. First, pnr.py's errors on bad
# input: exit 2, one stderr line "pnr.py: error: ..." naming the problem, nothing on stdout, no
# output directory (an unknown configuration, --prom for a span configuration, a missing tool,
# a bad --seed or --freq, --device of neither part).
set -euo pipefail
work=$1
config=$(realpath "$2")
shift 2
pnr=$(realpath "$(dirname "$0")/../scripts/pnr.py")
py=$(python3 -c "import sys; print(sys.executable)")  # the interpreter itself, not a shim
source "$(dirname "$0")/fresh_work.sh"
fresh_work "$work"
cd "$work"

# expect_error NAME REGEX [PATH=...] -- ARGS...: pnr.py exits 2 with one matching stderr line.
expect_error() {
  local name=$1 regex=$2 path=$PATH
  shift 2
  if [ "$1" != "--" ]; then path=$1; shift; fi
  shift
  local rc=0
  env PATH="$path" "$py" "$pnr" "$@" --out "$work/$name" >"$name.stdout" 2>"$name.stderr" || rc=$?
  if [ "$rc" -ne 2 ] || [ -s "$name.stdout" ] || [ "$(wc -l <"$name.stderr")" -ne 1 ] \
      || ! grep -Eq "^pnr.py: error: $regex" "$name.stderr" || [ -e "$work/$name" ]; then
    echo "pnr_test: $name: expected exit 2 and one line 'pnr.py: error: $regex', no output;" \
         "got exit $rc, stdout $(wc -c <"$name.stdout") bytes, stderr:" >&2
    cat "$name.stderr" >&2
    exit 1
  fi
  echo "pnr_test: $name: $(cat "$name.stderr")"
}
mkdir -p bin-yosys bin-none
ln -sf "$(command -v yosys)" bin-yosys/yosys
expect_error unknown-config "no configuration spec:nosuch \(known spec configurations: .*default" \
  -- spec:nosuch
expect_error prom-for-span "--prom: span:serial is a span configuration, which has no PROM" \
  -- span:serial --prom "$config"
expect_error no-nextpnr "nextpnr-ice40 not found" "$work/bin-yosys" -- "$config" "$@"
expect_error no-yosys "yosys not found" "$work/bin-none" -- "$config" "$@"
expect_error bad-seed "--seed '-1' is not an integer" -- "$config" "$@" --seed=-1
expect_error bad-freq "--freq 'nan' is not a frequency in MHz" -- "$config" "$@" --freq nan
rc=0
"$py" "$pnr" "$config" "$@" --device hx4k --out "$work/bad-device" >/dev/null 2>bad-device.stderr \
  || rc=$?
if [ "$rc" -ne 2 ] || ! grep -q "invalid choice: 'hx4k'" bad-device.stderr \
    || [ -e bad-device ]; then
  echo "pnr_test: bad-device: expected argparse's exit 2 naming 'hx4k', got exit $rc" >&2
  exit 1
fi

# The run.
"$py" "$pnr" "$config" "$@" --device both --out "$work/pnr"
"$py" - "$work/pnr/summary.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
up, hx = s["devices"]["up5k"], s["devices"]["hx8k"]
name = f"{s['unit']}:{s['config']}"
assert up["fits"] is True, (name, up.get("why_not"))
assert up["fmax_mhz"] > 0, up
assert up["fmax_mhz"] <= up["fmax_nextpnr_mhz"] + 0.01, up  # more paths: no faster
assert 0 < up["unit_luts"] <= up["luts"] <= up["luts_total"] == 5280, up
assert up["critical_path"]["logic_levels"] >= 2, up["critical_path"]
assert up["seed"] == 1 and up["wall_s"] > 0, up
dsps = s["netlist_cells"].get("SB_MAC16", 0)
assert dsps > 0, s["netlist_cells"]  # both units use DSPs on iCE40 (synth_ice40 -dsp)
assert up["fmax_kind"].startswith("upper bound"), up["fmax_kind"]
assert [p["dsp_count"] for p in up["dsp_paths"]][0] == 0, up["dsp_paths"]
assert hx["fits"] is False and hx["fmax_mhz"] is None, hx
assert hx["why_not"] == f"does not fit: needs {dsps} SB_MAC16, the HX8K has none", hx["why_not"]
assert hx["dsps_total"] == 0 and hx["luts"] > 0, hx
print(f"pnr_test: {name}: UP5K fmax {up['fmax_mhz']} MHz ({up['fmax_kind']}; nextpnr "
      f"{up['fmax_nextpnr_mhz']}), {up['luts']}/{up['luts_total']} logic cells, "
      f"{up['wall_s']} s; HX8K: {hx['why_not']}")
PY
