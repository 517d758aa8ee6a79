#!/usr/bin/env python3
"""bench_cosim.py: the span co-simulation's speed on one thread and on two, measured side by side.

  scripts/bench_cosim.py [--modes serial,seg4,...] [--rounds R] [--triangles N] [--seed S]
                         [--shadesim BIN]

Every round runs, for every mode, `shadesim cosim --unit span --mode MODE --triangles N --seed S
--threads T` with T = 1 and T = 2, one after the other (1 first on odd rounds, 2 first on even
ones), so that a machine drifting during the run weighs on both alike. The rate is the command's
own: lane fragments compared per wall-clock second. Both runs of a pair must report the same
fragments and cycles and no mismatch (two threads give one thread's result), else the script
fails.

Prints, per mode, the median rate of each thread count over the rounds with its range, and the
median of the rounds' ratios (two threads / one). Only figures taken in one run compare: never
with a figure from another run, day or machine. Exit status: 0, or 2 on bad input, a failing run
or two runs that disagree.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


class BenchError(Exception):
    pass


def cosim(a, mode, threads):
    cmd = [a.shadesim, "cosim", "--unit", "span", "--mode", mode, "--triangles", str(a.triangles), "--seed",
           str(a.seed), "--threads", str(threads), "--json", "--quiet"]
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if p.returncode != 0:
        tail = "\n".join((p.stdout + p.stderr).strip().splitlines()[-10:])
        raise BenchError(f"{' '.join(cmd)}: exit {p.returncode}\n{tail}")
    j = json.loads(p.stdout)
    return {"rate": j["fragments_per_second"] / 1e6, "fragments": j["fragments"], "cycles": j["cycles"]}


def measure(a):
    results = [{"mode": m, "rounds": []} for m in a.modes]
    for r in range(a.rounds):
        for res in results:
            t = {}
            for threads in ((1, 2) if r % 2 == 0 else (2, 1)):
                t[threads] = cosim(a, res["mode"], threads)
            if (t[1]["fragments"], t[1]["cycles"]) != (t[2]["fragments"], t[2]["cycles"]):
                raise BenchError(f"{res['mode']}: one thread {t[1]['fragments']} fragments in {t[1]['cycles']} "
                                 f"cycles, two threads {t[2]['fragments']} in {t[2]['cycles']}")
            res["rounds"].append({"one": t[1]["rate"], "two": t[2]["rate"], "ratio": t[2]["rate"] / t[1]["rate"]})
            print(f"bench_cosim: round {r + 1}/{a.rounds} {res['mode']}: one thread {t[1]['rate']:.1f}, "
                  f"two {t[2]['rate']:.1f} M fragments/s", file=sys.stderr, flush=True)
    for res in results:
        for k in ("one", "two", "ratio"):
            v = [t[k] for t in res["rounds"]]
            res[k] = {"median": statistics.median(v), "min": min(v), "max": max(v)}
    return results


def report(a, results):
    print(f"shadesim cosim --unit span --triangles {a.triangles} --seed {a.seed}, {a.rounds} interleaved rounds; "
          "M fragments per second (wall clock), median (range)")
    print(f"{'mode':<16} {'one thread':>18} {'two threads':>18} {'two / one':>8}")
    for res in results:
        def cell(k):
            return f"{res[k]['median']:.1f} ({res[k]['min']:.1f}-{res[k]['max']:.1f})"
        print(f"{res['mode']:<16} {cell('one'):>18} {cell('two'):>18} {res['ratio']['median']:>8.2f}")


def main(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--modes", help="span configurations, comma-separated (default: every verilated one)")
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--triangles", type=int, default=200000)
    p.add_argument("--seed", type=int, default=7)
    p.add_argument("--shadesim", default=os.path.join(ROOT, "build", "sim", "shadesim"))
    a = p.parse_args(argv)
    try:
        if a.rounds < 1 or a.triangles < 1 or a.seed < 0:
            raise BenchError("--rounds and --triangles must be at least 1, --seed at least 0")
        if not os.access(a.shadesim, os.X_OK):
            raise BenchError(f"{a.shadesim}: no shadesim binary (--shadesim)")
        if a.modes:
            a.modes = a.modes.split(",")
        else:
            out = subprocess.run([a.shadesim, "configs", "--unit", "span", "--json"], stdout=subprocess.PIPE,
                                 stderr=subprocess.PIPE, text=True)
            if out.returncode != 0:
                raise BenchError(f"shadesim configs: exit {out.returncode}: {out.stderr.strip()}")
            a.modes = [c["name"] for c in json.loads(out.stdout) if c["verilated"]]
        results = measure(a)
    except BenchError as e:
        print(f"bench_cosim: {e}", file=sys.stderr)
        return 2
    report(a, results)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
