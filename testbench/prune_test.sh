#!/usr/bin/env bash
# prune_test.sh SHADESIM WORK: `shadesim prune` on builtin:materials (phong-fixed, a quadratic and
# a cubic device lobe) with E = 1, checked from outside: the pruned PROMs hold exactly the
# shininess values of the materials with those lobes; the chosen lane mode's and serial's cycles
# are what `shadesim render --json` measures, and no mode has fewer; the scene rendered here with
# the pruned configurations is within E of the full ones' image, as prune's proof says; each
# width one bit narrower breaks something; the material-to-address table is the address map's;
# and a shininess the pruned PROM does not hold is refused by name.
set -euo pipefail
shadesim=$(realpath "$1")
work=$2
here=$(cd "$(dirname "$0")" && pwd)
source "$here/fresh_work.sh"
fresh_work "$work"
cd "$work"
"$shadesim" prune --scene builtin:materials --target-lsb 1 --no-hardware -o p --quiet > prune.out
cat prune.out
for f in analysis.json prune.json spec_defaultpruned.json spec_cubicpruned.json spec_defaultpruned.vec \
         spec_defaultpruned.frame.vec spec_cubicpruned.frame.vec \
         prom/spec_defaultpruned.hex prom/spec_defaultpruned.mem prom/spec_defaultpruned.coe \
         prom/spec_defaultpruned.mif prom/spec_defaultpruned.csv prom/spec_cubicpruned.hex; do
  [ -s "p/$f" ] || { echo "prune_test: p/$f missing or empty" >&2; exit 1; }
done
mode=$(python3 -c "import json; print(json.load(open('p/prune.json'))['chosen_mode'])")
for m in "$mode" serial; do
  "$shadesim" render --scene builtin:materials --method phong-fixed --mode "$m" -o "r_$m.png" --json "r_$m.json" --quiet > /dev/null
done
"$shadesim" render --scene builtin:materials --method phong-fixed --mode "$mode" \
  --quadratic-config p/spec_defaultpruned.json --cubic-config p/spec_cubicpruned.json -o pruned.png --quiet > /dev/null
python3 - "$mode" "$here" <<'PY'
import json, sys
from glob import glob
mode = sys.argv[1]
sys.path.insert(0, sys.argv[2])
import report_check  # its PNG decoder (the standard library's zlib; the five row filters undone)
a, p = json.load(open("p/analysis.json")), json.load(open("p/prune.json"))
def fail(msg):
    sys.exit("prune_test: " + msg)
cycles = {m["mode"]: m["span_cycles"] for m in p["lane_modes"]}
for m in (mode, "serial"):
    got = json.load(open(f"r_{m}.json"))["cycles"]
    if cycles[m] != got:
        fail(f"mode {m}: prune says {cycles[m]} cycles, render --json {got}")
if min(cycles.values()) != cycles[mode]:
    fail(f"chosen mode {mode} ({cycles[mode]} cycles) is not the fewest: {cycles}")
# The pruned configurations' image, rendered here, within E = 1 of the full one's, as prune says.
full, pruned = report_check.png_pixels(f"r_{mode}.png"), report_check.png_pixels("pruned.png")
if report_check.failures or full[:3] != pruned[:3]:
    fail(f"the images: {report_check.failures or 'other sizes or formats'}")
diff = max(abs(a - b) for a, b in zip(full[3], pruned[3]))  # in LSB, over every channel
if diff > 1 or diff != p["proof"]["max_abs_lsb"] or not p["proof"]["within_target"]:
    fail(f"the pruned image is {diff} LSB from the full one; prune's proof says {p['proof']}")
# The work the frame skipped, against render --json's counts of the same frame; the requests at
# the zero also against the analysis's per-address counts (the recorder's histogram).
k, r = p["skipped"], json.load(open("r_serial.json"))
for key in ("triangles", "culled_back", "culled_outside", "culled_no_pixel", "fragments", "depth_rejected",
            "spec_at_zero"):
    if k[key] != r[key]:
        fail(f"skipped {key}: {k[key]}, render --json {r[key]}")
if k["culled_back"] + k["culled_outside"] + k["culled_no_pixel"] != r["culled"]:
    fail(f"the culled triangles by reason do not add up to {r['culled']}: {k}")
per_address = sum(u["at_or_below_zero"] for lobe in a["lobes"] for u in lobe["requests"])
if k["spec_evaluations"] != r["spec_evaluations"] or not 0 < k["spec_at_zero"] < k["spec_evaluations"] \
        or per_address != k["spec_at_zero"]:
    fail(f"specular requests: {k}, render --json {r['spec_evaluations']} evaluations, {per_address} at the zero by address")
# The RTL: the chosen mode's verilated span unit in the loop, each pruned unit under Icarus on
# every distinct request of the frame.
rtl = p["proof"]["rtl"]
if rtl["span"] != {"config": mode, "image_equal": True, "span_cycles": cycles[mode], "cycles_equal": True}:
    fail(f"the span unit in the loop: {rtl['span']}")
if sorted(e["config"] for e in rtl["spec"]) != ["cubicpruned", "defaultpruned"] or \
        any(e["icarus"] != "equal" or e["frame_requests"] < 100 for e in rtl["spec"]):
    fail(f"the pruned specular units under Icarus: {rtl['spec']}")
# The scene's materials (scene.cpp builtin:materials): cubic n = 8, quadratic n = 1000.
want = {"cubic": [8.0], "quadratic": [1000.0]}
for lobe in a["lobes"]:
    got = [e["n"] for e in lobe["pruned"]["address_map"]]
    if got != want[lobe["lobe"]]:
        fail(f"{lobe['lobe']} lobe: the pruned PROM holds {got}, the scene uses {want[lobe['lobe']]}")
    # Every width is minimal against one-bit steps: one bit fewer breaks E or a derivation.
    for w, why in lobe["pruned"]["one_bit_narrower"].items():
        if not why.get("breaks"):
            fail(f"{lobe['lobe']} lobe: {w} one bit narrower: {why}")
    if not lobe["pruned"]["narrowed"]:
        fail(f"{lobe['lobe']} lobe: no width narrowed")
    if lobe["pruned"]["prom_bits"] >= lobe["full"]["prom_bits"]:
        fail(f"{lobe['lobe']} lobe: {lobe['pruned']['prom_bits']} bits pruned, {lobe['full']['prom_bits']} full")
    cfg = json.load(open(f"p/{lobe['pruned']['config']}"))
    if cfg["prom"]["n_list"] != ",".join(f"{n:g}" for n in want[lobe["lobe"]]):
        fail(f"{lobe['pruned']['config']}: n_list {cfg['prom']['n_list']}")
    for m in a["materials"]:
        if m["lobe"] == lobe["lobe"]:
            hit = [e for e in lobe["pruned"]["address_map"] if e["address"] == m["address"]]
            if not hit or hit[0]["n"] != round(m["shininess"]):
                fail(f"material {m['material']}: address {m['address']} does not hold n = {m['shininess']}")
print(f"prune_test: lane mode {mode} {cycles[mode]} cycles (serial {cycles['serial']}), PROMs "
      + ", ".join(f"{l['lobe']} {l['full']['prom_bits']} -> {l['pruned']['prom_bits']} bits" for l in a["lobes"]))
PY
# A shininess the pruned PROM does not hold: refused, naming it.
python3 - <<'PY'
import json
s = {"camera": {"eye": [0, 0, -3], "target": [0, 0, 0], "px_per_unit": 128, "width": 128, "height": 128, "z_near": 0.1},
     "ambient": [0, 0, 0], "lights": [{"type": "directional", "direction": [-1, 1, -1], "colour": [1, 1, 1]}],
     "materials": [{"name": "m", "colour": "#3070C0", "kd": 1, "ks": 1, "shininess": 77, "brdf": "quadratic"}],
     "objects": [{"name": "s", "mesh": "builtin:sphere(1,16)", "material": "m"}]}
json.dump(s, open("n77.json", "w"))
PY
status=0
"$shadesim" render --scene n77.json --method phong-fixed --quadratic-config p/spec_defaultpruned.json -o n77.png --quiet \
  > /dev/null 2> n77.err || status=$?
[ "$status" -eq 2 ] && grep -q "shininess 77 is not in the specular unit's PROM" n77.err \
  || { cat n77.err; echo "prune_test: a shininess outside the pruned PROM: exit $status, not refused by name" >&2; exit 1; }
# A cosine below the least the scene reached: the sphere lit from the side reaches N.H >= 0.34;
# its pruned configuration refuses builtin:sphere lit from the front (N.H down to 0.2), naming
# the code, and renders its own scene.
python3 - <<'PY'
import json
s = json.load(open("n77.json"))
s["lights"][0]["direction"] = [1, 0, 0]
s["materials"][0]["shininess"] = 32
json.dump(s, open("side.json", "w"))
PY
"$shadesim" prune --scene side.json --target-lsb 1 --no-hardware -o side --quiet > /dev/null
"$shadesim" render --scene side.json --method phong-fixed --quadratic-config side/spec_defaultpruned.json -o side.png --quiet > /dev/null
status=0
"$shadesim" render --scene builtin:sphere --brdf quadratic --method phong-fixed --quadratic-config side/spec_defaultpruned.json \
  -o front.png --quiet > /dev/null 2> front.err || status=$?
[ "$status" -eq 2 ] && grep -q "is below .*the least configuration side/spec_defaultpruned.json was sized for" front.err \
  || { cat front.err; echo "prune_test: a cosine below the analysed range: exit $status, not refused by name" >&2; exit 1; }
echo "prune_test: passed"
