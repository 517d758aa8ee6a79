#!/usr/bin/env bash
# sweep_target_test.sh SHADESIM WORK: --target-lsb on a small sweep of `narrow`: the least-latency
# point within 2 LSB is written as a configuration that shadesim loads, replayed under Icarus
# (the command fails on a mismatch), and each internal width one bit narrower is reported; a
# target no point meets exits 1 naming the least error; the pick runs again on the finished
# directory without evaluating anything.
set -euo pipefail
shadesim=$(realpath "$1")
work=$2
source "$(dirname "$0")/fresh_work.sh"
fresh_work "$work"
cd "$work"
mkdir d
args=(--config narrow --n-list 1,8,64,500 --param CoefFracBits=4:7 --param DiffFracBits=12,16 --quiet -o d)
"$shadesim" sweep "${args[@]}" --target-lsb 2 > out.txt
cat out.txt
grep -q "every output matches the model" out.txt
grep -q "one bit narrower:" out.txt
grep -q "CoefFracBits [0-9]*: " out.txt
[ -f d/spec_target.json ] && [ -f d/spec_target.vec ] && [ -f d/target.json ]
"$shadesim" spec-error --config d/spec_target.json --n-list 8 > /dev/null
# No point within 0.01 LSB (the output rounding alone is 0.5): exit 1, the least error named.
set +e
"$shadesim" sweep "${args[@]}" --target-lsb 0.01 > none.txt
rc=$?
set -e
[ "$rc" -eq 1 ] || { echo "expected exit 1, got $rc"; exit 1; }
grep -q "no point of sweep .* meets it; the least datapath_max_lsb is" none.txt
echo "sweep_target: ok"
