#!/usr/bin/env bash
# sweep_area_test.sh SHADESIM WORK: a sweep with --area synthesises each point once (yosys, by
# scripts/synth.py) and records its area; the same sweep in another directory takes every area
# from the cache (no new cache entry, no synthesis) and writes the same bytes; the DSP counts that
# the pruning compares (synth.py --dsps-of) equal the synthesised ones.
set -euo pipefail
shadesim=$(realpath "$1")
synth=$(realpath "$(dirname "$0")/../scripts/synth.py")
work=$2
source "$(dirname "$0")/fresh_work.sh"
fresh_work "$work"
mkdir -p "$work/a" "$work/b" "$work/cache"
cd "$work"
args=(--config narrow --n-list 1,8,64,500 --param CoefFracBits=5:6 --area ice40 --synth-cache cache --quiet)
"$shadesim" sweep "${args[@]}" -o a
[ "$(find cache -name 'spec-*.json' | wc -l)" -eq 2 ]
[ "$(find cache -mindepth 1 -type d | wc -l)" -eq 0 ]  # no temporary directory left
# LUT, FF and block-RAM counts recorded, and positive.
python3 - <<'PY'
import csv
rows = list(csv.DictReader(open("a/sweep.csv")))
assert len(rows) == 2, rows
for r in rows:
    for k in ("ice40_luts", "ice40_ffs", "ice40_brams"):
        assert int(r[k]) > 0, (k, r[k])
    assert "xc7_luts" not in r
print("sweep_area: LUTs", [r["ice40_luts"] for r in rows])
PY
# The DSP counts the pruning compares (synth.py --dsps-of, no yosys) are the synthesised ones.
python3 -c 'import json; json.dump([p["rtl"] for p in json.load(open("a/sweep.json"))["results"]], open("rtl.json", "w"))'
python3 "$synth" --dsps-of rtl.json --unit spec --target ice40 > dsps.json
python3 - <<'PY'
import json
points = json.load(open("a/sweep.json"))["results"]
predicted = [d["ice40"] for d in json.load(open("dsps.json"))]
assert predicted == [p["area"]["ice40"]["dsps"] for p in points], (predicted, [p["area"] for p in points])
print("sweep_area: predicted DSPs", predicted, "equal the synthesised ones")
PY

touch -d '2000-01-01' cache/*.json
"$shadesim" sweep "${args[@]}" -o b
for f in sweep.csv sweep.json pareto.csv; do cmp "a/$f" "b/$f"; done
[ "$(find cache -name 'spec-*.json' -newermt '2001-01-01' | wc -l)" -eq 0 ]  # nothing synthesised again
grep -q '^error-ice40_luts,' a/pareto.csv
echo "sweep_area: the second sweep took every area from the cache"
