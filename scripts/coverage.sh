#!/usr/bin/env bash
# Line and toggle coverage of the RTL by its tests (Verilator --coverage).
#   scripts/coverage.sh [--slow] [ctest arguments...]
# Builds build-cov/ with -DSHD_COVERAGE=ON (every verilated configuration with line and toggle
# points), runs the fast tests of the label rtl there with SHD_COVERAGE_DIR set (each model
# writes its points when it finishes) -- with --slow also the exhaustive specular co-simulation
# and the million-triangle span co-simulations (about 10 minutes more) --, merges the points
# and writes to out/coverage/:
#   coverage.dat   the merged points (verilator_coverage format)
#   coverage.info  lcov (genhtml coverage.info -o html)
#   annotated/     the RTL sources with a count on every line; '%' marks lines below the minimum
#   summary.txt    line and toggle coverage per RTL file, as printed below
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
slow=0
if [ "${1:-}" = "--slow" ]; then slow=1; shift; fi
build="$root/build-cov"
out="$root/out/coverage"
"$root/scripts/install_deps.sh"
"$root/scripts/build.sh" "$build" -DSHD_COVERAGE=ON
rm -rf "$out"
mkdir -p "$out/raw"
SHD_COVERAGE_DIR="$out/raw" ctest --test-dir "$build" -L rtl -LE slow -j "$(nproc)" --output-on-failure "$@"
if [ "$slow" = 1 ]; then
  SHD_COVERAGE_DIR="$out/raw" ctest --test-dir "$build" -R 'SpecCosim.Exhaustive|cosim_span_million' \
    -j "$(nproc)" --output-on-failure "$@"
fi
shopt -s nullglob
raw=("$out"/raw/*.dat)
[ ${#raw[@]} -gt 0 ] || { echo "coverage.sh: no coverage files written (is $build a coverage build?)" >&2; exit 1; }
verilator_coverage --write "$out/coverage.dat" "${raw[@]}"
verilator_coverage --write-info "$out/coverage.info" "$out/coverage.dat"
verilator_coverage --annotate "$out/annotated" "$out/coverage.dat" >/dev/null
rm -rf "$out/raw"
# Per file and kind: a point's record is C '<\001key\002value...>' count, with the kind in the
# page key (v_line/..., v_branch/... count as line coverage, v_toggle/... as toggle coverage).
awk -v root="$root/" '
  /^C / {
    rec = $0
    count = rec; sub(/.*\047 /, "", count)
    file = rec; sub(/.*\001f\002/, "", file); sub(/\001.*/, "", file); sub(root, "", file)
    page = rec; sub(/.*\001page\002/, "", page); sub(/\/.*/, "", page)
    kind = (page == "v_toggle") ? "toggle" : "line"
    key = file SUBSEP kind
    total[key]++
    if (count + 0 > 0) hit[key]++
    files[file] = 1
  }
  END {
    printf "%-28s %22s %22s\n", "RTL file", "line (incl. branch)", "toggle"
    for (f in files) {
      lt = total[f, "line"] + 0; lh = hit[f, "line"] + 0
      tt = total[f, "toggle"] + 0; th = hit[f, "toggle"] + 0
      printf "%-28s %8d/%-6d %5.1f%% %8d/%-6d %5.1f%%\n", f, lh, lt, lt ? 100 * lh / lt : 0, th, tt, tt ? 100 * th / tt : 0
      LT += lt; LH += lh; TT += tt; TH += th
    }
    printf "%-28s %8d/%-6d %5.1f%% %8d/%-6d %5.1f%%\n", "all", LH, LT, LT ? 100 * LH / LT : 0, TH, TT, TT ? 100 * TH / TT : 0
  }' "$out/coverage.dat" | tee "$out/summary.txt"
echo "coverage.sh: annotated sources in $out/annotated, lcov in $out/coverage.info"
