#!/usr/bin/env python3
"""bench_sweep.py: the benchmark of a specular sweep with area (docs/sweeps.md, "Cost").

  scripts/bench_sweep.py --shadesim BUILD/sim/shadesim --work DIR [--jobs J] [--skip-large]

1. The large sweep: 504 points of the default configuration (CosFracBits 12:15, CoefFracBits
   10:16, DiffFracBits 14:24:2, SpecFracBits 15:17) with --area both and an empty synthesis
   cache, timed wall clock; prints how many points were synthesised and each front's size.
2. The pruning check: a smaller grid (32 points: CoefFracBits 10:13, DiffFracBits 20:26:2,
   SpecFracBits 15:16) synthesised at every point (--area-all), then swept again with the pruning
   (the same cache: nothing is synthesised twice); prints whether each error-area front is the
   same, how many pairs of points q <= p (no wider on any axis) have more LUTs at q, and how many
   of those have the same DSP counts on both targets (the pairs the pruning compares: where the
   rule it assumes would not hold).
DIR must not exist (it is created). Exit 0 when the fronts agree and no pair of the same DSP
counts has more LUTs at the narrower point, 1 otherwise.
"""
import argparse
import csv
import os
import subprocess
import sys
import time

LARGE = ["CosFracBits=12:15", "CoefFracBits=10:16", "DiffFracBits=14:24:2", "SpecFracBits=15:17"]
SMALL = ["CoefFracBits=10:13", "DiffFracBits=20:26:2", "SpecFracBits=15:16"]
TARGETS = ["ice40", "xc7"]


def sweep(shadesim, params, out, cache, jobs, extra=()):
    os.makedirs(out)
    cmd = [shadesim, "sweep", "--config", "default", "--area", "both", "--synth-cache", cache, "-o", out, "--quiet"]
    cmd += [f"--param={p}" for p in params] + list(extra)
    if jobs:
        cmd += ["--jobs", str(jobs)]
    t0 = time.monotonic()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return time.monotonic() - t0


def rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def fronts(out):
    by = {}
    for r in rows(os.path.join(out, "pareto.csv")):
        by.setdefault(r["front"], set()).add(r["index"])
    return by


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--shadesim", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--jobs", type=int, default=0)
    ap.add_argument("--skip-large", action="store_true")
    a = ap.parse_args()
    os.makedirs(a.work)  # refuses an existing directory: nothing of the user's is touched
    if not a.skip_large:
        cache = os.path.join(a.work, "cache-large")
        os.makedirs(cache)
        out = os.path.join(a.work, "large")
        secs = sweep(a.shadesim, LARGE, out, cache, a.jobs)
        res = rows(os.path.join(out, "sweep.csv"))
        synthesised = sum(1 for r in res if r["area_pruned_by"] == "")
        sizes = ", ".join(f"{k} {len(v)}" for k, v in sorted(fronts(out).items()))
        print(f"large sweep: {len(res)} points, {synthesised} synthesised, {secs:.1f} s wall; fronts: {sizes}", flush=True)

    cache = os.path.join(a.work, "cache-small")
    os.makedirs(cache)
    full, pruned = os.path.join(a.work, "small-all"), os.path.join(a.work, "small-pruned")
    t_all = sweep(a.shadesim, SMALL, full, cache, a.jobs, ["--area-all"])
    sweep(a.shadesim, SMALL, pruned, cache, a.jobs)
    res = rows(os.path.join(full, "sweep.csv"))
    kept = sum(1 for r in rows(os.path.join(pruned, "sweep.csv")) if r["area_pruned_by"] == "")
    print(f"small sweep: {len(res)} points; every point synthesised in {t_all:.1f} s; the pruned run keeps {kept}")
    fa, fp = fronts(full), fronts(pruned)
    same = True
    for t in TARGETS:
        name = f"error-{t}_luts"
        ok = fa.get(name) == fp.get(name)
        same &= ok
        print(f"  {name}: every point {sorted(fa.get(name, []), key=int)}, pruned {sorted(fp.get(name, []), key=int)}: "
              f"{'the same' if ok else 'DIFFERENT'}")
    axes = [p.split("=")[0] for p in SMALL]
    dsps = lambda r: tuple(r[f"{t}_dsps"] for t in TARGETS)
    for t in TARGETS:
        bad = [(q, p) for q in res for p in res
               if q is not p and all(int(q[x]) <= int(p[x]) for x in axes)
               and int(q[f"{t}_luts"]) > int(p[f"{t}_luts"])]
        alike = [(q, p) for q, p in bad if dsps(q) == dsps(p)]
        same &= not alike
        print(f"  {t}: {len(bad)} pairs q <= p with more LUTs at q, {len(alike)} of them with the same DSP counts"
              + "".join(f"; {q['index']}->{p['index']} ({q[f'{t}_luts']} > {p[f'{t}_luts']} LUTs, "
                        f"DSPs {'/'.join(dsps(q))} and {'/'.join(dsps(p))})" for q, p in (alike or bad)[:4]))
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
