#!/usr/bin/env bash
# A replay of a corrupted vector file must fail exactly there: copies <file.vec> with one
# expected output wrong (testbench/icarus/corrupt_vectors.py, which prints the cycle, 1-based,
# and the port), replays the copy with shadesim_systemc and passes only if it exits 1 with one
# mismatching sample, at that cycle on that port, against the file, and saved the failing case
# (in <work dir>/fail) so that it fails alone at its last cycle.
#   detects_corruption.sh <shadesim_systemc> <corrupt_vectors.py> <unit> <config> <file.vec> <work dir>
set -uo pipefail
sc=$1 corrupt=$2 unit=$3 config=$4 vec=$5 work=$6
mkdir -p "$work"
where=$(python3 "$corrupt" "$vec" "$work/bad.vec") || { echo "detects_corruption: corrupt_vectors.py failed" >&2; exit 1; }
cycle=${where%% *}
port=${where#* }
port=${port%%[*}
rm -rf "$work/fail"
mkdir -p "$work/fail"  # --fail-dir names an existing directory
"$sc" --unit "$unit" --config "$config" --vector-file "$work/bad.vec" --quiet --fail-dir "$work/fail" 2>"$work/stderr"
rc=$?
cat "$work/stderr" >&2
want="^MISMATCH \(first of 1 samples\) at [0-9]+ ns \(cycle [0-9]+\), vector file cycle $cycle: $port.*: vector file "
if [ "$rc" -ne 1 ] || ! grep -Eq "$want" "$work/stderr"; then
  echo "detects_corruption: expected exit 1 and a line matching '$want' (corrupted: cycle $cycle, $port); got exit $rc" >&2
  exit 1
fi
saved="^replayed alone \(.*\): fails at its last cycle [0-9]+, as the run did: .*$port"
if ! grep -Eq "$saved" "$work/stderr" || [ ! -s "$work/fail/${unit}_${config}_fail.vec" ]; then
  echo "detects_corruption: the failing case was not saved in $work/fail so that it fails alone at its last cycle" >&2
  exit 1
fi
echo "detects_corruption: $unit/$config fails at file cycle $cycle on $port, as it must; the case saved alone fails too"
