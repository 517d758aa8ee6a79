#!/usr/bin/env python3
"""Renders a matrix of scenes x methods x lane modes x lobes with one shadesim binary, or
compares two such runs byte for byte: the check that a change of the renderer keeps its images.

  scripts/render_matrix.py render --shadesim build/sim/shadesim -o /tmp/before [--jobs 2]
  scripts/render_matrix.py compare /tmp/before /tmp/after

Each render writes its image, the reference, the error heat map (PNG) and its statistics (JSON).
compare requires every PNG to be byte-identical and every JSON to be equal except the timing
members (ms, frames, rtl.ms); it prints the first differences and exits 1 if there are any.
"""
import argparse
import concurrent.futures
import json
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TEAPOTS = "/usr/share/assimp/models/Collada/teapots.DAE"  # Debian assimp-testmodels
# Relative to the repository (the renders run there), so that the statistics' scene names of two
# checkouts are equal.
SCENES = ["builtin:sphere", "builtin:plane", "builtin:torus", "builtin:materials", "vectors/scenes/still_life.json",
          TEAPOTS]
# Every method and lobe the binary knows (its render --help); a subset of the lane modes.
MODES = ["serial", "evenodd", "seg4", "sierpinski"]
LOBE_METHODS = ["gouraud", "phong", "phong-incremental", "phong-fixed"]
TIMING = {"ms", "frames"}


def choices(shadesim, option):
    """The values render --help lists for an option ("--method TEXT:{flat,gouraud,...}")."""
    text = subprocess.run([shadesim, "render", "--help"], capture_output=True, text=True, check=True).stdout
    m = re.search(re.escape(option) + r" TEXT:\{([^}]*)\}", text)
    if m is None:
        sys.exit(f"render_matrix: {shadesim} render --help lists no choices for {option}")
    return m.group(1).split(",")


def jobs(shadesim):
    """(name, extra arguments) of every render of the matrix."""
    methods, lobes = choices(shadesim, "--method"), choices(shadesim, "--brdf")
    out = []
    for si, scene in enumerate(SCENES):
        for m in methods:
            for mode in MODES:
                out.append((f"s{si}_{m}_{mode}", ["--scene", scene, "--method", m, "--mode", mode]))
        for m in LOBE_METHODS:
            for lobe in lobes:
                out.append((f"s{si}_{m}_serial_{lobe}",
                            ["--scene", scene, "--method", m, "--mode", "serial", "--brdf", lobe]))
    return out


def render_one(shadesim, outdir, name, args):
    png = os.path.join(outdir, name + ".png")
    cmd = [shadesim, "render", *args, "--quiet", "-o", png, "--json", os.path.join(outdir, name + ".json")]
    r = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT)
    return name, r.returncode, r.stderr.strip()


def render(a):
    if not os.path.exists(TEAPOTS):
        sys.exit(f"render_matrix: {TEAPOTS} missing (Debian package assimp-testmodels)")
    a.out = os.path.abspath(a.out)
    a.shadesim = os.path.abspath(a.shadesim)
    os.makedirs(a.out, exist_ok=True)
    todo = jobs(a.shadesim)
    failed = 0
    with concurrent.futures.ThreadPoolExecutor(max_workers=a.jobs) as ex:
        futs = [ex.submit(render_one, a.shadesim, a.out, n, args) for n, args in todo]
        for i, f in enumerate(concurrent.futures.as_completed(futs), 1):
            name, rc, err = f.result()
            if rc != 0:
                failed += 1
                print(f"render_matrix: {name} failed (exit {rc}): {err}", file=sys.stderr)
            if i % 50 == 0 or i == len(todo):
                print(f"render_matrix: {i}/{len(todo)} renders", file=sys.stderr)
    print(f"render_matrix: {len(todo)} renders into {a.out}, {failed} failed")
    return 1 if failed else 0


def strip_timing(j):
    if isinstance(j, dict):
        return {k: strip_timing(v) for k, v in j.items() if k not in TIMING}
    return j


def compare(a):
    names_a = sorted(os.listdir(a.a))
    names_b = sorted(os.listdir(a.b))
    diffs = []
    if names_a != names_b:
        diffs.append(f"file lists differ: only in {a.a}: {sorted(set(names_a) - set(names_b))[:5]}, "
                     f"only in {a.b}: {sorted(set(names_b) - set(names_a))[:5]}")
    pngs = 0
    for n in sorted(set(names_a) & set(names_b)):
        pa, pb = os.path.join(a.a, n), os.path.join(a.b, n)
        if n.endswith(".json"):
            ja, jb = strip_timing(json.load(open(pa))), strip_timing(json.load(open(pb)))
            if ja != jb:
                keys = [k for k in set(ja) | set(jb) if ja.get(k) != jb.get(k)]
                diffs.append(f"{n}: statistics differ in {sorted(keys)}")
        else:
            pngs += 1
            if open(pa, "rb").read() != open(pb, "rb").read():
                diffs.append(f"{n}: bytes differ")
    for d in diffs[:20]:
        print("DIFF " + d)
    print(f"render_matrix: {pngs} PNGs and {len(names_a) - pngs} JSON compared, {len(diffs)} differences")
    return 1 if diffs else 0


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("render")
    r.add_argument("--shadesim", default=os.path.join(ROOT, "build/sim/shadesim"))
    r.add_argument("-o", "--out", required=True)
    r.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    c = sub.add_parser("compare")
    c.add_argument("a")
    c.add_argument("b")
    a = p.parse_args()
    return render(a) if a.cmd == "render" else compare(a)


if __name__ == "__main__":
    sys.exit(main())
