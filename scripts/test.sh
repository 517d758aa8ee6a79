#!/usr/bin/env bash
# The test command: installs what is missing, builds, runs every test with ctest.
#   scripts/test.sh [--sanitize] [ctest arguments...]
# --sanitize: then builds the tests again with AddressSanitizer + UndefinedBehaviorSanitizer
# (build-asan/) and runs the fast ones there. It doubles the run (about 9 more minutes on 2
# cores), which CI's 12 minutes cannot hold, so CI (.ci/run) runs without it; run it before
# merging a change to C++ code (docs/verification.md, "Tests").
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
sanitize=0
if [ "${1:-}" = "--sanitize" ]; then sanitize=1; shift; fi
start=$(date +%s)
"$root/scripts/install_deps.sh"
source "$root/scripts/direct_python.sh"
"$root/scripts/build.sh" "$root/build"
echo "test.sh: built after $(( $(date +%s) - start )) s"
ctest --test-dir "$root/build" --output-on-failure -j "$(nproc)" "$@"
echo "test.sh: release tests passed after $(( $(date +%s) - start )) s"
if [ "$sanitize" = 1 ]; then
  # -Og -g1: stack traces with files and lines (-g1: line tables only, a third less compile time
  # than -g). -Og compiles the largest model file (phong_fixed.cpp) in 0.51x the time of -O1
  # (3 interleaved runs each); at -O0 one run of these tests took 243 s (76 s at -Og, another run).
  # No benchmarks (figures, not tests).
  "$root/scripts/build.sh" "$root/build-asan" -DSHD_SANITIZE=ON -DSHD_BENCHMARKS=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-Og -g1 -DNDEBUG"
  # The icarus tests run no C++ of ours (Icarus Verilog alone), the proofs (label proof) do not
  # depend on the build, and the docs check (label docs) runs commands the other tests run: the
  # release run covers them.
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    ctest --test-dir "$root/build-asan" --output-on-failure -j "$(nproc)" -LE "slow|icarus|proof|docs" "$@"
  echo "test.sh: sanitizer tests passed after $(( $(date +%s) - start )) s"
fi
