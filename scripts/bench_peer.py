#!/usr/bin/env python3
"""bench_peer.py: the model's time per frame against a peer renderer's, measured side by side.

  scripts/bench_peer.py --pair METHOD 'PEER COMMAND' [--pair ...] [--rounds R] [--frames N]
                        [--threads 1,2] [--scene SCENE | --segments 32,64,...] [--shadesim BIN]
                        [--peer-pattern REGEX] [--cpu N] [--no-bound] [--json-out FILE]

Each --pair names a shadesim method (`shadesim render --method`) and a shell command that prints
the peer's time per frame in milliseconds. Every round runs, for every pair, shadesim
(`render --scene SCENE --method METHOD --bench N`, the median of N frames) and the peer, in the
order shadesim, peer on odd rounds and peer, shadesim on even ones, so that a machine drifting
during the run weighs on both alike. Only ratios taken this way mean anything: never compare with
a figure from another run, day or machine.

--threads: the thread counts of shadesim's frames (`render --threads`), comma-separated; each
pair runs once per count in every round, beside its own peer run (default 1).

--segments: instead of one scene, builtin:sphere's scene (vectors/scenes/sphere.json) with a
sphere of each of these segment counts (mesh "builtin:sphere(1,N)"); "{seg}" in a peer command
stands for N, so that the peer draws the same sphere (e.g. 'PEER_SEG={seg} PEER flat').

--peer-pattern: a regular expression whose first group is the peer's ms per frame, searched in
its output; the last match counts (default: a number followed by "ms").

--cpu N: the one-thread runs of both programs pinned to CPU N (its affinity, inherited by the
peer's threads); two-thread runs keep every CPU. On a VM whose CPUs do not run at the same
speed (one of this project's 2-core VMs had one 1.4-1.5 times slower than the other at times),
an unpinned run lands on either, and the ratio of two runs then mixes the CPUs' speeds.

Two-thread pairs (--threads 2) also time, in each round right after the two-thread frame, a
one-thread frame pinned to each of the two CPUs it runs on (the first two of this process's),
and print the bound those speeds set: 1 / (1 / t0 + 1 / t1), the frame shared between both CPUs
at their speeds with nothing spent on sharing it. On a VM whose two CPUs run at different
speeds, that bound over the peer's time is the lowest two-thread ratio the machine allows
then; bound / two-thread time is how much of it the frame reached. --no-bound: without these
runs.

Prints, per pair, every round's two times and their ratio, then the median of the rounds'
ratios (shadesim / peer: below 1, shadesim is faster) with its range, and the ratio of the two
sides' fastest rounds (each side's least disturbed frame time: on a machine whose load comes and
goes, the median of the ratios moves with the rounds a burst hit). The environment is
passed on (SHD_SCALAR=1 measures the scalar paths, SHD_NO_AVX512=1 the AVX2 ones; the report
names them). Exit status: 0, or 2 on bad input or a command that fails or prints no time.
"""
import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_PATTERN = r"([0-9]+(?:\.[0-9]+)?)\s*ms\b"


class BenchError(Exception):
    pass


def run(cmd, shell=False, cpu=None):
    pin = None if cpu is None else (lambda: os.sched_setaffinity(0, {cpu}))
    p = subprocess.run(cmd, shell=shell, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, preexec_fn=pin)
    if p.returncode != 0:
        tail = "\n".join((p.stdout + p.stderr).strip().splitlines()[-10:])
        raise BenchError(f"{cmd if shell else ' '.join(cmd)}: exit {p.returncode}\n{tail}")
    return p.stdout


def shadesim_ms(a, scene, method, threads, work, cpu=None):
    """The median frame time; on one thread pinned to cpu, else to --cpu (if given)."""
    js = os.path.join(work, "render.json")
    run([a.shadesim, "render", "--scene", scene, "--method", method, "--bench", str(a.frames), "--quiet",
         "--threads", str(threads), "-o", os.path.join(work, "render.png"), "--json", js],
        cpu=(a.cpu if cpu is None else cpu) if threads == 1 else None)
    with open(js, encoding="utf-8") as f:
        return float(json.load(f)["ms"])


def peer_ms(a, cmd, threads):
    out = run(cmd, shell=True, cpu=a.cpu if threads == 1 else None)
    found = re.findall(a.peer_pattern, out)
    if not found:
        tail = "\n".join(out.strip().splitlines()[-5:])
        raise BenchError(f"{cmd}: no time per frame matching --peer-pattern '{a.peer_pattern}' in its output:\n{tail}")
    return float(found[-1] if isinstance(found[-1], str) else found[-1][0])


def sphere_scene(work, seg):
    """builtin:sphere's scene with a sphere of seg segments, as a scene file in work."""
    with open(os.path.join(ROOT, "vectors", "scenes", "sphere.json"), encoding="utf-8") as f:
        scene = json.load(f)
    scene["objects"][0]["mesh"] = f"builtin:sphere(1,{seg})"
    path = os.path.join(work, f"sphere{seg}.json")
    with open(path, "w", encoding="utf-8") as f:
        json.dump(scene, f)
    return path


def bound_ms(a, scene, method, work):
    """One-thread frames pinned to each of the two CPUs a two-thread frame runs on (the first two
    of this process's), and the time of a frame shared between both at those speeds with no
    cost of its own: 1 / (1 / t0 + 1 / t1)."""
    per_cpu = {c: shadesim_ms(a, scene, method, 1, work, cpu=c) for c in sorted(os.sched_getaffinity(0))[:2]}
    return per_cpu, 1.0 / sum(1.0 / ms for ms in per_cpu.values())


def measure(a):
    sizes = a.segments or [None]
    results = [{"method": m, "threads": n, "segments": g, "peer": c if g is None else c.replace("{seg}", str(g)),
                "rounds": []} for g in sizes for m, c in a.pair for n in a.threads]
    with tempfile.TemporaryDirectory(prefix="bench_peer_") as work:
        scenes = {g: a.scene if g is None else sphere_scene(work, g) for g in sizes}
        for r in range(a.rounds):
            for res in results:
                order = ("shadesim", "peer") if r % 2 == 0 else ("peer", "shadesim")
                t = {}
                per_cpu = None
                for who in order:
                    if who == "peer":
                        t["peer"] = peer_ms(a, res["peer"], res["threads"])
                        continue
                    t["shadesim"] = shadesim_ms(a, scenes[res["segments"]], res["method"], res["threads"], work)
                    if res["threads"] == 2 and a.bound:
                        per_cpu, t["bound"] = bound_ms(a, scenes[res["segments"]], res["method"], work)
                t["ratio"] = t["shadesim"] / t["peer"]
                bound = ""
                if per_cpu is not None:
                    t["cpu_ms"] = {str(c): ms for c, ms in per_cpu.items()}
                    t["bound_ratio"] = t["bound"] / t["peer"]
                    bound = ("; one thread: " + ", ".join(f"CPU {c} {ms:.3f} ms" for c, ms in per_cpu.items()) +
                             f", bound {t['bound']:.3f} ms")
                res["rounds"].append(t)
                print(f"bench_peer: round {r + 1}/{a.rounds} {label(res)}: "
                      f"shadesim {t['shadesim']:.3f} ms, "
                      f"peer {t['peer']:.3f} ms, ratio {t['ratio']:.3f}{bound}", file=sys.stderr, flush=True)
    for res in results:
        ratios = [t["ratio"] for t in res["rounds"]]
        res["ratio_median"] = statistics.median(ratios)
        res["ratio_min"], res["ratio_max"] = min(ratios), max(ratios)
        res["shadesim_fastest"] = min(t["shadesim"] for t in res["rounds"])
        res["peer_fastest"] = min(t["peer"] for t in res["rounds"])
        res["ratio_fastest"] = res["shadesim_fastest"] / res["peer_fastest"]
        if all("bound" in t for t in res["rounds"]):
            res["bound_ratio_median"] = statistics.median(t["bound_ratio"] for t in res["rounds"])
            res["efficiency_median"] = statistics.median(t["bound"] / t["shadesim"] for t in res["rounds"])
    return results


def label(res):
    seg = "" if res["segments"] is None else f", {res['segments']} segments"
    return f"{res['method']} ({res['threads']} thread(s){seg})"


def report(a, results):
    # Set at all, as the model reads them (fixed_simd's envSet).
    env = "".join(f" {v}={os.environ[v]}" for v in ("SHD_SCALAR", "SHD_NO_AVX512") if v in os.environ)
    scene = f"builtin:sphere of {a.segments} segments" if a.segments else a.scene
    pinned = "" if a.cpu is None else f", one-thread runs on CPU {a.cpu}"
    print(f"{scene}, shadesim render --bench {a.frames}{env}, {a.rounds} interleaved rounds{pinned}; "
          "ratio = shadesim / peer")
    for res in results:
        print(f"\n{label(res)}, against: {res['peer']}")
        bounded = "bound_ratio_median" in res
        cpus = list(res["rounds"][0]["cpu_ms"]) if bounded else []
        extra = "".join(f" {'CPU ' + c + ' ms':>9}" for c in cpus) + (f" {'bound ms':>9} {'bound/peer':>10}" if bounded else "")
        print(f"{'round':>5} {'shadesim ms':>12} {'peer ms':>10} {'ratio':>7}{extra}")
        for i, t in enumerate(res["rounds"]):
            extra = "".join(f" {t['cpu_ms'][c]:>9.3f}" for c in cpus) + (
                f" {t['bound']:>9.3f} {t['bound_ratio']:>10.3f}" if bounded else "")
            print(f"{i + 1:>5} {t['shadesim']:>12.3f} {t['peer']:>10.3f} {t['ratio']:>7.3f}{extra}")
        print(f"median ratio {res['ratio_median']:.3f} (rounds {res['ratio_min']:.3f} to {res['ratio_max']:.3f})")
        print(f"fastest rounds: shadesim {res['shadesim_fastest']:.3f} ms, peer {res['peer_fastest']:.3f} ms, "
              f"ratio {res['ratio_fastest']:.3f}")
        if bounded:
            print(f"the CPUs' bound against the peer, median {res['bound_ratio_median']:.3f}; "
                  f"two threads reached {res['efficiency_median']:.2f} of the bound (median)")


def main(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--pair", nargs=2, action="append", metavar=("METHOD", "PEER_COMMAND"), required=True)
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--frames", type=int, default=200)
    p.add_argument("--threads", default="1")
    p.add_argument("--scene", default="builtin:sphere")
    p.add_argument("--segments")
    p.add_argument("--shadesim", default=os.path.join(ROOT, "build", "sim", "shadesim"))
    p.add_argument("--peer-pattern", default=DEFAULT_PATTERN)
    p.add_argument("--cpu", type=int)
    p.add_argument("--no-bound", dest="bound", action="store_false")
    p.add_argument("--json-out")
    a = p.parse_args(argv)
    try:
        if a.rounds < 1 or a.frames < 1:
            raise BenchError("--rounds and --frames must be at least 1")
        given = a.threads
        try:
            a.threads = [int(n) for n in given.split(",")]
        except ValueError:
            a.threads = []
        if not a.threads or any(n not in (1, 2) for n in a.threads) or len(set(a.threads)) != len(a.threads):
            raise BenchError(f"--threads '{given}': distinct thread counts, 1 or 2, comma-separated")
        if a.segments is not None:
            given = a.segments
            try:
                a.segments = [int(n) for n in given.split(",")]
            except ValueError:
                a.segments = []
            if not a.segments or any(n < 4 or n > 1024 for n in a.segments) or a.scene != "builtin:sphere":
                raise BenchError(f"--segments '{given}': segment counts 4..1024 (builtin:sphere(1,N)), comma-separated, without --scene")
        if a.cpu is not None and a.cpu not in os.sched_getaffinity(0):
            raise BenchError(f"--cpu {a.cpu}: not one of this process's CPUs {sorted(os.sched_getaffinity(0))}")
        if not os.access(a.shadesim, os.X_OK):
            raise BenchError(f"{a.shadesim}: no shadesim binary (--shadesim)")
        try:
            if re.compile(a.peer_pattern).groups < 1:
                raise BenchError(f"--peer-pattern '{a.peer_pattern}' has no group for the time")
        except re.error as e:
            raise BenchError(f"--peer-pattern '{a.peer_pattern}': {e}")
        results = measure(a)
    except BenchError as e:
        print(f"bench_peer: {e}", file=sys.stderr)
        return 2
    report(a, results)
    if a.json_out:
        with open(a.json_out + ".tmp", "w", encoding="utf-8") as f:
            json.dump({"scene": a.scene, "segments": a.segments, "frames": a.frames, "rounds": a.rounds, "cpu": a.cpu,
                       "pairs": results}, f, indent=1)
        os.replace(a.json_out + ".tmp", a.json_out)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
