#!/usr/bin/env bash
# bench_peer_test.sh SHADESIM WORK: scripts/bench_peer.py against a stand-in peer that prints a
# given time (no figure is checked, only the plumbing): the ratios are shadesim's times over the
# peer's, "{seg}" reaches the peer command with each sphere size of --segments, --cpu pins the
# one-thread runs, the JSON holds every round (a two-thread round also its one-thread frames on
# each of the first two CPUs and the bound they set, none with --no-bound), and bad input or a
# peer without a time exits 2 naming the cause.
set -euo pipefail
shadesim=$(realpath "$1")
work=$2
root=$(cd "$(dirname "$0")/.." && pwd)
source "$(dirname "$0")/fresh_work.sh"
fresh_work "$work"
cd "$work"
bench=("$root/scripts/bench_peer.py" --shadesim "$shadesim" --frames 2 --rounds 2)
# The peer's ms per frame is the sphere's segment count: each size's own command ran.
"${bench[@]}" --segments 6,9 --threads 1,2 --pair gouraud 'echo "frame {seg}.0 ms"' --json-out r.json > out.txt
cat out.txt
python3 - <<'PY'
import json, os
r = json.load(open("r.json"))
assert r["segments"] == [6, 9], r["segments"]
pairs = r["pairs"]
assert sorted((p["segments"], p["threads"]) for p in pairs) == [(6, 1), (6, 2), (9, 1), (9, 2)], pairs
for p in pairs:
    assert p["peer"] == f'echo "frame {p["segments"]}.0 ms"', p["peer"]
    assert len(p["rounds"]) == 2
    for t in p["rounds"]:
        assert t["peer"] == p["segments"] and t["shadesim"] > 0, t
        assert abs(t["ratio"] - t["shadesim"] / t["peer"]) < 1e-12, t
    fastest = min(t["shadesim"] for t in p["rounds"])
    assert p["shadesim_fastest"] == fastest and p["peer_fastest"] == p["segments"], p
    assert abs(p["ratio_fastest"] - fastest / p["segments"]) < 1e-12, p
    # Two threads: a one-thread frame pinned to each of the first two CPUs, and their bound.
    cpus = [str(c) for c in sorted(os.sched_getaffinity(0))[:2]]
    for t in p["rounds"]:
        if p["threads"] == 1:
            assert "bound" not in t and "cpu_ms" not in t, t
            continue
        assert sorted(t["cpu_ms"]) == sorted(cpus) and all(ms > 0 for ms in t["cpu_ms"].values()), t
        assert abs(t["bound"] - 1 / sum(1 / ms for ms in t["cpu_ms"].values())) < 1e-12, t
        assert abs(t["bound_ratio"] - t["bound"] / t["peer"]) < 1e-12, t
    assert ("bound_ratio_median" in p) == (p["threads"] == 2), p
print("bench_peer json: ok")
PY
grep -q "^gouraud (1 thread(s), 9 segments), against: echo \"frame 9.0 ms\"" out.txt
grep -q "^median ratio " out.txt
grep -q "^fastest rounds: shadesim [0-9.]* ms, peer 9.000 ms, ratio " out.txt
grep -q "^the CPUs' bound against the peer, median [0-9.]*; two threads reached [0-9.]* of the bound" out.txt
"${bench[@]}" --threads 2 --no-bound --pair gouraud 'echo "frame 1.0 ms"' --json-out nobound.json > /dev/null
python3 -c 'import json; r = json.load(open("nobound.json")); assert all("bound" not in t for p in r["pairs"] for t in p["rounds"])'

# --cpu: the one-thread rounds' peer runs on that CPU alone, the two-thread rounds' on all (the
# peer's time here: the count of CPUs it may run on).
first=$(python3 -c 'import os; print(min(os.sched_getaffinity(0)))')
all=$(python3 -c 'import os; print(len(os.sched_getaffinity(0)))')
"${bench[@]}" --cpu "$first" --threads 1,2 --json-out cpu.json \
  --pair flat 'echo "$(python3 -c "import os; print(len(os.sched_getaffinity(0)))").0 ms"' > cpu.txt
grep -q "one-thread runs on CPU $first" cpu.txt
python3 - "$first" "$all" <<'PY'
import json, sys
r = json.load(open("cpu.json"))
assert r["cpu"] == int(sys.argv[1]), r["cpu"]
for p in r["pairs"]:
    want = 1 if p["threads"] == 1 else int(sys.argv[2])
    assert all(t["peer"] == want for t in p["rounds"]), (p["threads"], p["rounds"])
print("bench_peer --cpu: ok")
PY
expect2() {  # expect2 WHAT ARGS...: exit 2 with WHAT in stderr
  local what=$1; shift
  set +e
  "${bench[@]}" "$@" > /dev/null 2> err.txt
  local rc=$?
  set -e
  [ "$rc" -eq 2 ] || { echo "expected exit 2 for $*, got $rc"; exit 1; }
  grep -q -- "$what" err.txt || { echo "expected '$what' for $*:"; cat err.txt; exit 1; }
}
expect2 "segment counts 4..1024" --segments 3 --pair flat 'echo 1 ms'
expect2 "segment counts 4..1024" --segments 64 --scene builtin:torus --pair flat 'echo 1 ms'
expect2 "distinct thread counts" --threads 1,3 --pair flat 'echo 1 ms'
expect2 "no time per frame" --pair flat 'echo none'
expect2 "exit 3" --pair flat 'exit 3'
expect2 "not one of this process's CPUs" --cpu 100000 --pair flat 'echo 1 ms'
echo "bench_peer: ok"
