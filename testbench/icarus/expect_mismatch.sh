#!/usr/bin/env bash
# expect_mismatch.sh: a replay must fail when it should. Copies a vector file with exactly one
# expected output value wrong (corrupt_vectors.py), replays the copy, and passes only if the
# replay fails with a mismatch (exit status 1) that names that cycle and that signal, and no
# other mismatch.
#
#   testbench/icarus/expect_mismatch.sh --icarus FILE.vec WORKDIR
#   testbench/icarus/expect_mismatch.sh --replay SHADESIM FILE.vec WORKDIR
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
usage() { echo "usage: expect_mismatch.sh --icarus FILE.vec WORKDIR | --replay SHADESIM FILE.vec WORKDIR" >&2; exit 2; }

case "${1:-}" in
  --icarus) [ $# -eq 3 ] || usage; runner=icarus; vec=$2; work=$3 ;;
  --replay) [ $# -eq 4 ] || usage; runner=replay; shadesim=$2; vec=$3; work=$4 ;;
  *) usage ;;
esac
mkdir -p "$work"
bad=$work/$(basename "$vec" .vec)_corrupt.vec
read -r cycle signal < <(python3 "$here/corrupt_vectors.py" "$vec" "$bad")
echo "corrupted: $bad, cycle $cycle, $signal (one expected value, least significant bit flipped)"

rc=0
if [ "$runner" = icarus ]; then
  "$here/run_icarus.sh" --work "$work/icarus" "$bad" >"$work/out.txt" 2>&1 || rc=$?
  only_one="1 of [0-9]* output values differ, in 1 of"
else
  "$shadesim" replay "$bad" >"$work/out.txt" 2>&1 || rc=$?
  only_one="MISMATCH (first of 1, in 1 cycles)"
fi
cat "$work/out.txt"
if [ "$rc" -ne 1 ]; then
  echo "expect_mismatch.sh: FAIL: the replay of the corrupted file exited with $rc, 1 (a mismatch) expected" >&2
  exit 1
fi
if ! grep -qF "cycle $cycle: $signal: expected" "$work/out.txt"; then
  echo "expect_mismatch.sh: FAIL: no mismatch reported at cycle $cycle on $signal" >&2
  exit 1
fi
if ! grep -q "$only_one" "$work/out.txt"; then
  echo "expect_mismatch.sh: FAIL: other values differ too (only the corrupted one may)" >&2
  exit 1
fi
echo "expect_mismatch.sh: PASS: the $runner run failed at cycle $cycle on $signal, and only there"
