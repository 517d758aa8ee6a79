#!/usr/bin/env bash
# Runs the libFuzzer targets of testbench/fuzz/ (docs/verification.md, "Fuzzing"): builds them
# (clang, -DSHD_FUZZ=ON, in build-fuzz/), runs each for a while from its checked-in corpus,
# merges what it found into testbench/fuzz/corpus/<target>/, and prints per target the runs,
# execs/s, coverage, new corpus files and findings. Exit 1 if any target found something.
#
#   scripts/fuzz.sh [options] [TARGET...]      targets: scene config prom vectors mesh span (default all)
#     -t, --time SECONDS   per target (default 600; 0: no fuzzing, only the merge)
#     -p, --parallel N     targets run at once (default 1; each is one process on one core)
#     --build DIR          the build directory (default build-fuzz)
#     --seed               also feed the seeds of testbench/fuzz/make_seeds.py
#     --minimise           rebuild each corpus as a minimal set that keeps its edge coverage
#                          (libFuzzer -set_cover_merge=1 into an empty directory) instead of
#                          adding to it; the reproducers of findings (finding-*) stay
#     --no-merge           leave the checked-in corpus alone
#
# Artifacts (crash-*, leak-*, timeout-*, oom-* files) stay in <build>/fuzz-work/<target>/findings/;
# each is replayed alone afterwards, and a finding is one that fails again (triage.txt there).
# replay one with <build>/testbench/fuzz/fuzz_<target> FILE (SHD_FUZZ_VERBOSE=1 prints the
# reader's message), and keep it as a regression input testbench/fuzz/corpus/<target>/finding-<what>.
# Known findings (reported, not fixed: knownFinding in testbench/fuzz/fuzz_util.h) do not stop
# a run; the table names those it met. The log of each run is <build>/fuzz-work/<target>/fuzz.log.
# Everything runs under nice.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
all_targets=(scene config prom vectors mesh span)
time_s=600
parallel=1
build=$root/build-fuzz
seed=0
minimise=0
merge=1
targets=()
while [ $# -gt 0 ]; do
  case "$1" in
    -t|--time) time_s=$2; shift 2 ;;
    -p|--parallel) parallel=$2; shift 2 ;;
    --build) build=$(realpath -m "$2"); shift 2 ;;
    --seed) seed=1; shift ;;
    --minimise) minimise=1; shift ;;
    --no-merge) merge=0; shift ;;
    -h|--help) sed -n '2,23p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "fuzz.sh: unknown option $1" >&2; exit 2 ;;
    *) [[ " ${all_targets[*]} " == *" $1 "* ]] || { echo "fuzz.sh: unknown target $1 (${all_targets[*]})" >&2; exit 2; }
       targets+=("$1"); shift ;;
  esac
done
[ ${#targets[@]} -gt 0 ] || targets=("${all_targets[@]}")

# The libFuzzer options of a target: input size, a dictionary, and limits. -timeout 10: a unit
# of these targets takes milliseconds, so 10 s is a hang. mesh: assimp allocates what a file
# declares (see fuzz_mesh.cpp), so a tighter memory limit there.
flags_of() {
  local dict=$root/testbench/fuzz/dict
  case "$1" in
    scene)   echo "-max_len=4096 -dict=$dict/json.dict" ;;
    config)  echo "-max_len=2048 -dict=$dict/json.dict" ;;
    prom)    echo "-max_len=2048" ;;
    vectors) echo "-max_len=8192 -dict=$dict/vectors.dict" ;;
    mesh)    echo "-max_len=8192 -dict=$dict/mesh.dict -rss_limit_mb=1024 -malloc_limit_mb=256" ;;
    span)    echo "-max_len=512 -use_value_profile=1" ;;
  esac
}

# How a target is run. mesh: assimp 5.2 (uninstrumented) corrupts its heap on some malformed
# files, unseen until a later input fails, and allocates what a file declares (loadMeshFile's
# child process and its limits contain both). So mesh fuzzes in libFuzzer's fork mode, going on
# after a crash or an out-of-memory; afterwards each artifact is replayed alone (triage below),
# and only those that fail alone are findings.
mode_of() {
  case "$1" in
    mesh) echo "-fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1" ;;
  esac
}

"$root/scripts/install_deps.sh" build tools fuzz
echo "fuzz.sh: building $build"
if [ ! -f "$build/CMakeCache.txt" ]; then
  nice cmake -S "$root" -B "$build" -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DSHD_FUZZ=ON -DSHD_BENCHMARKS=OFF >/dev/null
fi
nice cmake --build "$build" -j2 >/dev/null

seeds=""
if [ $seed = 1 ]; then
  seeds=$build/fuzz-work/seeds
  rm -rf "$seeds"
  python3 "$root/testbench/fuzz/make_seeds.py" "$seeds" --root "$root"
fi

# One target: fuzz a copy of its corpus for time_s seconds, then merge into the corpus.
run_target() {
  local t=$1 bin=$build/testbench/fuzz/fuzz_$1 corpus=$root/testbench/fuzz/corpus/$1
  local work=$build/fuzz-work/$1
  rm -rf "$work"
  mkdir -p "$work/corpus" "$work/findings" "$corpus"
  cp -r "$corpus/." "$work/corpus/"
  local extra=()
  [ -z "$seeds" ] || extra+=("$seeds/$t")
  # Known findings (reported, not fixed yet: fuzz_util.h knownFinding) count as rejections while
  # fuzzing, and as crashes in the merge, which so leaves their inputs out of the corpus.
  touch "$work/fuzz.log"
  if [ "$time_s" -gt 0 ]; then
    # shellcheck disable=SC2046  # flags_of's and mode_of's words are separate options
    SHD_FUZZ_SKIP_KNOWN=1 nice "$bin" $(flags_of "$t") $(mode_of "$t") -timeout=10 -max_total_time="$time_s" -print_final_stats=1 \
      -artifact_prefix="$work/findings/" "$work/corpus" "${extra[@]}" >"$work/fuzz.log" 2>&1 || true
  fi
  find "$corpus" -maxdepth 1 -type f | wc -l >"$work/corpus_before"
  [ $merge = 1 ] || return 0
  # The checked-in corpus keeps edge coverage only (-use_counters=0 -use_value_profile=0: not
  # every hit count and compared value the fuzzer tells apart), so that it stays small and its
  # replay fast; a run starts from it and finds the rest again quickly. Inputs that crash the
  # merge's child (known findings) stay out; libFuzzer writes them to the artifact prefix.
  local merge_flags=(-use_counters=0 -use_value_profile=0 -artifact_prefix="$work/merge-")
  if [ $minimise = 1 ]; then
    # The reproducers of findings (finding-*) stay whatever their coverage.
    mkdir -p "$work/minimal"
    # shellcheck disable=SC2046
    nice "$bin" $(flags_of "$t") "${merge_flags[@]}" -set_cover_merge=1 "$work/minimal" "$corpus" "$work/corpus" \
      "${extra[@]}" >>"$work/merge.log" 2>&1
    find "$corpus" -maxdepth 1 -name 'finding-*' -exec cp {} "$work/minimal/" \;
    rm -rf "$corpus" && mv "$work/minimal" "$corpus"
  else
    # shellcheck disable=SC2046
    nice "$bin" $(flags_of "$t") "${merge_flags[@]}" -merge=1 "$corpus" "$work/corpus" "${extra[@]}" \
      >>"$work/merge.log" 2>&1
  fi
}

# assimp's own leaks (testbench/fuzz/lsan.supp).
export LSAN_OPTIONS=suppressions=$root/testbench/fuzz/lsan.supp

for t in "${targets[@]}"; do
  echo "fuzz.sh: $t for ${time_s} s"
  run_target "$t" &
  # At most $parallel at once: wait for any one of them to end.
  [ "$(jobs -p -r | wc -l)" -lt "$parallel" ] || wait -n || true
done
wait

# An artifact is a finding if it fails again when replayed alone; one that does not (a heap
# corrupted by an earlier input, in uninstrumented code) is only counted. Out-of-memory
# artifacts of a target run with -ignore_ooms=1 are counted too (see mode_of), and so are
# crashes that are AddressSanitizer refusing an allocation larger than the memory there is.
triage() {
  local t=$1 bin=$build/testbench/fuzz/fuzz_$1 f kind
  find "$build/fuzz-work/$t/findings" -type f \( -name 'crash-*' -o -name 'leak-*' -o -name 'timeout-*' -o -name 'oom-*' \) |
    sort | while read -r f; do
      kind=$(basename "$f" | cut -d- -f1)
      # shellcheck disable=SC2046  # flags_of's words are separate options
      if [ "$kind" = oom ] && [[ "$(mode_of "$t")" == *-ignore_ooms=1* ]]; then
        echo "ignored $f"
      elif out=$(SHD_FUZZ_SKIP_KNOWN=1 nice "$bin" $(flags_of "$t") -timeout=10 "$f" 2>&1 >/dev/null); then
        echo "flaky $f"
      elif [[ "$(mode_of "$t")" == *-ignore_ooms=1* ]] &&
        grep -qE 'AddressSanitizer: (out-of-memory|allocation-size-too-big|requested allocation size)' <<<"$out"; then
        echo "ignored $f"  # AddressSanitizer's allocator refused a size read from the file: out of memory
      else
        echo "finding $f"
      fi
    done
}

# The figures: libFuzzer's final stats and its last status line (cov: edges, ft: features; in
# fork mode the parent's "#N: cov: ..." lines).
status=0
printf '\n%-8s %12s %9s %7s %7s %7s %9s %6s  %s\n' target runs execs/s cov ft corpus new_files other \
  'findings (known findings skipped)'
for t in "${targets[@]}"; do
  work=$build/fuzz-work/$t
  log=$work/fuzz.log
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  eps=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  last=$(grep -E '^#[0-9]+: cov:' "$log" | tail -1 || true)
  [ -n "$last" ] || last=$(grep -E '^#[0-9]+' "$log" | tail -1 || true)
  # Fork mode prints no final stats: the runs and the rate of its last status line.
  [ -n "$runs" ] || runs=$(sed -n 's/^#\([0-9]*\):.*/\1/p' <<<"$last")
  [ -n "$eps" ] || eps=$(sed -n 's/.* exec\/s \([0-9]*\).*/\1/p' <<<"$last")
  cov=$(sed -n 's/.* cov: \([0-9]*\).*/\1/p' <<<"$last")
  ft=$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<<"$last")
  after=$(find "$root/testbench/fuzz/corpus/$t" -maxdepth 1 -type f | wc -l)
  before=$(cat "$work/corpus_before" 2>/dev/null || echo "$after")
  triage "$t" >"$work/triage.txt"
  findings=$(sed -n 's/^finding //p' "$work/triage.txt")
  other=$(grep -c -E '^(flaky|ignored) ' "$work/triage.txt" || true)
  known=$(sed -n 's/^known finding \([^ ]*\) skipped:.*/\1/p' "$log" | sort -u | tr '\n' ' ')
  printf '%-8s %12s %9s %7s %7s %7s %+9d %6s  %s%s\n' "$t" "${runs:-?}" "${eps:-?}" "${cov:-?}" "${ft:-?}" "$after" \
    $((after - before)) "$other" "${findings:-none}" "${known:+ (${known% })}"
  [ -z "$findings" ] || status=1
done
echo "(other: artifacts that did not fail again alone, or ignored out-of-memory ones: <build>/fuzz-work/<target>/triage.txt)"
exit $status
