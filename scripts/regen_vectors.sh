#!/usr/bin/env bash
# Regenerates the files generated from the configurations of a configuration directory (default
# vectors/config/, the registry) with shadesim: each specular configuration's PROM table in
# <dir>/../prom/ and each configuration's vector file in <dir>/../cycles/ (scripts/shd_config.py
# names the places), or (--check) regenerates them into a temporary directory and fails if any
# differs from the checked-in copy or is missing, or a checked-in one is no longer generated
# (CI runs this as the ctest vectors_fresh). shadesim must have the directory's configurations
# built in (a build with that directory in SHD_CONFIG_DIRS).
#   scripts/regen_vectors.sh [--check] [--shadesim build/sim/shadesim] [--config-dir DIR]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
shadesim="$root/build/sim/shadesim"
config_dir="$root/vectors/config"
check=0
while [ $# -gt 0 ]; do
  case "$1" in
    --check) check=1 ;;
    --shadesim) shadesim="$2"; shift ;;
    --config-dir) config_dir="$2"; shift ;;
    *) echo "regen_vectors.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
  shift
done
[ -x "$shadesim" ] || { echo "regen_vectors.sh: $shadesim is not built" >&2; exit 2; }
[ -d "$config_dir" ] || { echo "regen_vectors.sh: no configuration directory $config_dir" >&2; exit 2; }
config_dir=$(cd "$config_dir" && pwd)
base=$(dirname "$config_dir")  # <base>/prom and <base>/cycles

if [ "$check" = 1 ]; then
  dest=$(mktemp -d)
  trap 'rm -rf "$dest"' EXIT
else
  dest="$base"
fi
mkdir -p "$dest/prom"

# The configurations of the directory (scripts/shd_config.py: "<unit> <name> <file>" per line).
configs=$(python3 "$root/scripts/shd_config.py" list --dir "$config_dir")
spec_configs=$(awk '$1 == "spec" { print $2 }' <<<"$configs")
span_configs=$(awk '$1 == "span" { print $2 }' <<<"$configs")

# The PROM of every unit configuration, as the simulators load it.
for cfg in $spec_configs; do
  "$shadesim" prom --config "$config_dir/spec_$cfg.json" --format hex -o "$dest/prom/spec_$cfg.hex" 2>/dev/null
done
# The registry's default PROM in every FPGA vendor's format.
if [ "$config_dir" = "$root/vectors/config" ]; then
  for fmt in mem coe mif csv; do
    "$shadesim" prom --config "$config_dir/spec_default.json" --format "$fmt" \
      -o "$dest/prom/spec_default.$fmt" 2>/dev/null
  done
fi

# Cycle-by-cycle vector files (sim/vectors/vector_file.h) of every unit configuration, replayed under
# Icarus and Verilator by ctest. The span files are long enough for the generator's directed
# phases (every size class x shape, the wide viewport) to finish in every mode; each file's
# "# coverage" lines say by which cycle (test_vectors checks it).
mkdir -p "$dest/cycles"
for cfg in $spec_configs; do
  "$shadesim" vectors --unit spec --config "$cfg" --cycles 3000 --seed 1 --prom "$dest/prom/spec_$cfg.hex" \
    -o "$dest/cycles/spec_$cfg.vec" 2>/dev/null
done
for mode in $span_configs; do
  "$shadesim" vectors --unit span --config "$mode" --cycles 4000 --seed 1 -o "$dest/cycles/span_$mode.vec" 2>/dev/null
done

if [ "$check" = 1 ]; then
  status=0
  while IFS= read -r f; do
    rel=${f#"$dest"/}
    if ! cmp -s "$f" "$base/$rel"; then
      echo "$base/$rel differs from a fresh regeneration or is missing (run scripts/regen_vectors.sh and commit)" >&2
      status=1
    fi
  done < <(find "$dest" -type f | sort)
  # A checked-in generated file that the generator no longer makes is stale too.
  while IFS= read -r f; do
    rel=${f#"$base"/}
    [ -e "$dest/$rel" ] || { echo "$base/$rel is not produced by the generator any more" >&2; status=1; }
  done < <(find "$base/prom" "$base/cycles" -type f 2>/dev/null | sort)
  [ "$status" = 0 ] && echo "$base: $(find "$dest" -type f | wc -l) generated files equal a fresh regeneration"
  exit "$status"
fi
echo "regenerated $(find "$dest/prom" -type f | wc -l) files under $base/prom, $(find "$dest/cycles" -type f | wc -l) under $base/cycles"
