#!/usr/bin/env bash
# config_extension_test.sh SOURCE_DIR WORK_DIR BUILD_DIR: adding a configuration is adding one
# JSON file.
# Writes a new specular configuration (spec_trial.json) and a new lane mode (span_sierpinski2.json:
# the 4-way split with two lanes per sub-triangle) into a directory of their own, configures a
# scratch build with that directory added to the registry (SHD_CONFIG_DIRS), and checks that
#   - they are listed: the configure summary, `shadesim configs`, the CLI help;
#   - they are verilated: `shadesim configs` finds their models, and cosim and render --rtl run
#     them against the golden model with 0 mismatches (the new mode's image equals the serial
#     mode's, byte for byte); the SystemC testbench's build has their SystemC models (its
#     default list is every configuration: build.ninja has Vsc_spec_trial, Vsc_span_sierpinski2);
#   - they are tested: ctest holds their replay, Icarus, SystemC, synthesis and vector-freshness
#     tests, and all but the SystemC ones pass once scripts/regen_vectors.sh has made their PROM
#     and vector files.
# The scratch build compiles only what depends on the registry: its embedded files and the
# verilated models of the two new configurations (SHD_VERILATE); the model, vector, co-simulation
# and CLI libraries and Verilator's runtime are BUILD_DIR's, the build running this test
# (SHD_PREBUILT, of the same source tree and build type). The registry's other configurations
# are there for the golden model, marked "no verilated model". shadesim_systemc is not compiled
# here: the main build runs the SystemC testbench on every configuration of the registry,
# through the same per-configuration CMake code that this build generates for the new ones.
set -euo pipefail
src=$(cd "$1" && pwd)
work=$2
source "$(dirname "$0")/fresh_work.sh"
fresh_work "$work"
mkdir -p "$work/ext/config" "$work/run"
ext=$work/ext/config
step() { echo "config_extension: $*"; "$@"; }
# contains PATTERN COMMAND...: the command's whole output holds PATTERN. (Not "COMMAND | grep -q":
# grep leaves at the first match, the command dies of SIGPIPE and pipefail fails the test.)
contains() { local out; out=$("${@:2}"); grep -q -- "$1" <<<"$out"; }

cat >"$ext/spec_trial.json" <<'JSON'
{
  "name": "trial",
  "description": "A configuration added by the extension test: uQ1.12 cosine, uQ10.10 coefficient, 512 codes, two pipeline registers.",
  "rtl": {
    "Degree": 2, "CosFracBits": 12, "ShinBits": 9, "CoefIntBits": 10, "CoefFracBits": 10, "DiffFracBits": 20,
    "HornerFracBits": 10, "SpecFracBits": 13, "LightBits": 8, "PipeStages": 2
  },
  "prom": { "fit": "level", "level": 0.5, "n": "1:500" }
}
JSON
cat >"$ext/span_sierpinski2.json" <<'JSON'
{
  "name": "sierpinski2",
  "description": "A lane mode added by the extension test: the 4-way split, each sub-triangle in segments of two lanes.",
  "rtl": {
    "NumTri": 4, "LanesPerTri": 2, "AlignLanes": 0, "NumAttr": 4, "AttrBits": 32, "CoordBits": 16, "RemBits": 27,
    "PixBits": 12, "TagBits": 32
  }
}
JSON

build=$work/build
generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
main=$(cd "$3" && pwd)
type=$(sed -n 's/^CMAKE_BUILD_TYPE:[A-Z]*=//p' "$main/CMakeCache.txt")
sanitize=$(sed -n 's/^SHD_SANITIZE:[A-Z]*=//p' "$main/CMakeCache.txt")
step cmake -S "$src" -B "$build" "${generator[@]}" "-DCMAKE_BUILD_TYPE=$type" "-DSHD_SANITIZE=${sanitize:-OFF}" \
  "-DSHD_PREBUILT=$main" -DSHD_BENCHMARKS=OFF "-DSHD_CONFIG_DIRS=$src/vectors/config;$ext" "-DSHD_VERILATE=spec_trial;span_sierpinski2" \
  >"$work/configure.log"
grep -E '^-- shadesim configurations: spec .*trial.*; span .*sierpinski2' "$work/configure.log"
grep -q 'Vsc_spec_trial' "$build/build.ninja"
grep -q 'Vsc_span_sierpinski2' "$build/build.ninja"
step cmake --build "$build" --target shadesim -j "$(nproc)" >"$work/build.log"
S=$build/sim/shadesim

# Listed, with a verilated model, and named by the CLI's help.
step "$S" configs | tee "$work/configs.txt"
grep -qx 'spec trial .*spec_trial.json' "$work/configs.txt"
grep -qx 'span sierpinski2 .*span_sierpinski2.json' "$work/configs.txt"
grep -qx 'span serial .*span_serial.json  (no verilated model)' "$work/configs.txt"
if [ "$(grep -c 'no verilated model' "$work/configs.txt")" -ne "$(( $(grep -c '^sp' "$work/configs.txt") - 2 ))" ]; then
  echo "config_extension: the new configurations must have a model, the others none" >&2; exit 1
fi
contains trial "$S" cosim --help
contains sierpinski2 "$S" render --help

# Against the golden model.
cd "$work/run"
step "$S" cosim --unit spec --config trial --vectors 200000 --seed 3 --quiet
step "$S" cosim --unit span --mode sierpinski2 --triangles 3000 --seed 3 --quiet
step "$S" render --scene builtin:sphere --method gouraud --mode sierpinski2 --rtl --quiet -o s2.png --json s2.json
grep -q '"pixel_mismatches": 0' s2.json
step "$S" render --scene builtin:sphere --method gouraud --mode serial --quiet -o serial.png
cmp s2.png serial.png

# Their generated files, then the tests ctest registered for them.
step "$src/scripts/regen_vectors.sh" --shadesim "$S" --config-dir "$ext"
ls "$work/ext/prom/spec_trial.hex" "$work/ext/cycles/spec_trial.vec" "$work/ext/cycles/span_sierpinski2.vec"
want='^(replay|icarus|systemc)_(spec_trial|span_sierpinski2)(_file)?$|^synth_spec_trial$|^vectors_fresh_1$'
listed=$(ctest --test-dir "$build" -N -R "$want" | grep -c 'Test *#')
echo "config_extension: ctest lists $listed tests for the new configurations"
# 4 systemc, 2 replay, 2 icarus, synth_spec_trial, vectors_fresh_1
[ "$listed" -eq 10 ] || { ctest --test-dir "$build" -N -R "$want"; exit 1; }
contains cosim_span_million_sierpinski2 ctest --test-dir "$build" -N
step ctest --test-dir "$build" -R "$want" -E '^systemc_' -j "$(nproc)" --output-on-failure
echo "config_extension: the new configurations are listed, verilated and tested"
