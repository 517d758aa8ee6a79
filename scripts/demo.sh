#!/usr/bin/env bash
# The main job: installs what is missing, builds, then for the default configuration of the
# specular unit generates the PROM (every format), runs the exhaustive co-simulation of the
# verilated RTL against the golden model, prints the error table, and synthesises the unit;
# then measures the span unit's cycles per mode, checked against its RTL; renders the sphere with
# the main methods; and writes the report of every method and lobe on the sphere in lane mode serial
# (error, model time, cycles, area, plots). Results go to out/.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
out="$root/out"
"$root/scripts/install_deps.sh"
source "$root/scripts/direct_python.sh"
"$root/scripts/build.sh" "$root/build"
S="$root/build/sim/shadesim"
mkdir -p "$out/prom"

echo "== 1. PROM of the default configuration (out/prom/)"
for fmt in hex mem coe mif csv; do
  "$S" prom --config default --format "$fmt" -o "$out/prom/spec_default.$fmt"
done

echo "== 2. exhaustive co-simulation: verilated shd_spec_unit vs golden model"
mkdir -p "$out/fail"
"$S" cosim --unit spec --config default --exhaustive --prom "$out/prom/spec_default.hex" \
  --fail-dir "$out/fail" --json > "$out/cosim_spec_default.json.tmp"
mv "$out/cosim_spec_default.json.tmp" "$out/cosim_spec_default.json"
python3 - "$out/cosim_spec_default.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
print(f"   {j['vectors']:,} vectors, {j['cycles']:,} cycles, {j['mismatches']} mismatches, "
      f"{j['seconds']:.2f} s ({j['vectors_per_second'] / 1e6:.1f} M vectors/s)")
PY

echo "== 3. error report: the paper's fit beside the minimax fit"
"$S" spec-error --config default --json-out "$out/spec_error_default.json" > "$out/spec_error_default.txt.tmp"
mv "$out/spec_error_default.txt.tmp" "$out/spec_error_default.txt"
cat "$out/spec_error_default.txt"

echo "== 4. synthesis with yosys (out/synth/default/)"
"$root/scripts/synth.py" spec:default --prom "$out/prom/spec_default.hex" --out "$out/synth/default" --target both --check

echo "== 5. span unit: cycles per mode on the size classes and the idx3d sphere, checked against the RTL"
"$S" span-cycles --triangles 20000 --rtl --json-out "$out/span_cycles.json" > "$out/span_cycles.txt.tmp"
mv "$out/span_cycles.txt.tmp" "$out/span_cycles.txt"
cat "$out/span_cycles.txt"

echo "== 6. builtin:sphere rendered with the main methods, by the model and with the RTL in the loop (out/render/)"
mkdir -p "$out/render"
for method in flat gouraud gouraud-classical phong phong-incremental phong-fixed; do
  for brdf in blinn quadratic; do
    "$S" render --scene builtin:sphere --method "$method" --brdf "$brdf" --rtl --quiet \
      -o "$out/render/sphere_${method}_${brdf}.png" --json "$out/render/sphere_${method}_${brdf}.json" > /dev/null
  done
done
python3 - "$out/render" > "$out/render/summary.txt" <<'PY'
import glob, json, os, sys
rows = [json.load(open(f)) for f in sorted(glob.glob(os.path.join(sys.argv[1], "sphere_*.json")))]
print(f"{'method':<18} {'brdf':<10} {'max LSB':>8} {'PSNR dB':>8} {'>1 LSB':>7} {'hl max':>7} {'cycles':>8} {'spec cyc':>9} {'ms':>7} {'rtl ms':>7} {'mismatch':>8}")
for j in rows:
    psnr = j["psnr_db"] if j["psnr_db"] is not None else float("inf")
    print(f"{j['method']:<18} {j['brdf']:<10} {j['max_abs_lsb']:>8.2f} {psnr:>8.2f} {100*j['metrics']['share_over_1lsb']:>6.2f}% "
          f"{j['highlight']['max_abs_lsb']:>7.2f} {j['cycles']:>8} {j['spec_cycles']:>9} {j['ms']:>7.1f} {j['rtl']['ms']:>7.1f} {j['pixel_mismatches']:>8}")
PY
cat "$out/render/summary.txt"

echo "== 7. report of builtin:sphere: every method and lobe in lane mode serial, with area and place and route on the UP5K (out/report/, docs/report.md)"
# Area (yosys) and place and route (nextpnr) of each unit, kept in out/hardware-cache/. The UP5K
# only: the HX8K's run (every multiplier in logic cells) would double the step's time, and the
# span unit does not fit the HX8K (no time per frame there); `--pnr-devices up5k,hx8k` adds it.
"$S" report --scene builtin:sphere --modes serial --pnr-devices up5k --hardware-cache "$out/hardware-cache" --quiet -o "$out/report"
python3 - "$out/report/report.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
rows = [r for r in j["rows"] if r["mode"] == "serial" and r["lobe"] in ("blinn", "quadratic")]
us = lambda r: "-" if (r.get("time_us") or {}).get("up5k") is None else f"{r['time_us']['up5k']:.0f}"
print(f"   {'method':<18} {'lobe':<10} {'max LSB':>8} {'RMSE':>7} {'cycles':>8} {'spec cyc':>9} {'UP5K us':>8} {'model ms':>8}")
for r in rows:
    print(f"   {r['method']:<18} {r['lobe']:<10} {r['metrics']['max_abs_lsb']:>8.2f} {r['metrics']['rmse_lsb']:>7.3f} "
          f"{r['counts']['cycles']:>8} {r['counts']['spec_cycles']:>9} {us(r):>8} {r['ms']:>8.2f}")
PY

echo "== results in $out"
ls -1 "$out"
