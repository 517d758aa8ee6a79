#!/usr/bin/env bash
# A run that must fail (expect_failure.sh: exit <status>, a stderr line matching <regex>) and save
# its failing case in the current directory (the default --fail-dir): runs the command in an
# emptied <dir> and passes only if
#   - <unit>_<config>_fail.vec and <unit>_<config>_fail.fst exist and are not empty (spec: and
#     the PROM copy <unit>_<config>_fail.hex);
#   - the run's report names them and says that the case, replayed alone in a child process,
#     fails at its last cycle;
#   - `shadesim replay <fail.vec>` (the C++ harness, another simulator build) exits 1, with its
#     first mismatch at the file's last cycle and no other cycle mismatching.
#   fail_case.sh <shadesim> <dir> <unit> <config> <status> <regex> <command> [arguments...]
set -uo pipefail
shadesim=$1 dir=$2 unit=$3 config=$4 status=$5 regex=$6
shift 6
here=$(cd "$(dirname "$0")" && pwd)
fail() { echo "fail_case: $*" >&2; exit 1; }
rm -rf "$dir" && mkdir -p "$dir" && cd "$dir" || fail "cannot make $dir"
"$here/expect_failure.sh" "$status" "$regex" "$@" 2>run.stderr
rc=$?
cat run.stderr >&2
[ "$rc" -eq 0 ] || fail "the run did not fail as required"
base=${unit}_${config}_fail
files="$base.vec $base.fst"
[ "$unit" = spec ] && files="$files $base.hex"
for f in $files; do
  [ -s "$f" ] || fail "$dir/$f missing or empty"
done
grep -q "^failing case: $base.vec (" run.stderr || fail "the report does not name $base.vec"
grep -q "^failing case waveform: $base.fst " run.stderr || fail "the report does not name $base.fst"
grep -Eq "^replayed alone \(.*\): fails at its last cycle [0-9]+, as the run did: " run.stderr ||
  fail "the report does not say that the case replayed alone fails at its last cycle"

# The saved case under the C++ harness (Verilator, no SystemC).
"$shadesim" replay "$base.vec" --json >replay.json 2>replay.stderr
rc=$?
cat replay.stderr >&2
[ "$rc" -eq 1 ] || fail "shadesim replay $base.vec: exit status $rc, expected 1"
read -r cycles mcycles first < <(python3 -c '
import json, sys
j = json.load(open(sys.argv[1]))
print(j["cycles"], j["mismatching_cycles"], j.get("first_mismatch", {}).get("cycle", 0))' replay.json) ||
  fail "shadesim replay --json: unreadable result"
lines=$(grep -c -E '^(C |[0-9a-f])' "$base.vec")
[ "$cycles" -eq "$lines" ] || fail "shadesim replay counted $cycles cycles, the file holds $lines"
[ "$first" -eq "$cycles" ] && [ "$mcycles" -eq 1 ] ||
  fail "shadesim replay: first mismatch at cycle $first, $mcycles cycles mismatching; expected only the last, $cycles"
ls -l "$PWD"
echo "fail_case: $unit/$config saved $base.vec ($cycles cycles) and $base.fst; shadesim replay fails at cycle $cycles only"
