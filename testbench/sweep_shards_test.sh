#!/usr/bin/env bash
# sweep_shards_test.sh SHADESIM WORK: a sweep run whole, as 2 shards under GNU parallel, and as
# the Slurm job array of scripts/sweep_slurm.sh (its --dry-run commands run here by a stand-in
# for sbatch that runs each array task in turn); each merged result must equal the whole run byte
# for byte. Then the span and phong units, whole and as 2 shards.
set -euo pipefail
shadesim=$(realpath "$1")
work=$2
root=$(cd "$(dirname "$0")/.." && pwd)
source "$(dirname "$0")/fresh_work.sh"
fresh_work "$work"
mkdir -p "$work"
cd "$work"
args=(--config narrow --n-list 1,8,64,500 --param CoefFracBits=4:7 --param DiffFracBits=12,16)
files=(sweep-plan.json sweep.csv sweep.json pareto.csv)
same() {  # same DIR: DIR's results equal the whole run's
  for f in "${files[@]}"; do cmp "whole/$f" "$1/$f"; done
  echo "sweep_shards: $1 equals the whole run"
}

mkdir whole
"$shadesim" sweep "${args[@]}" --quiet -o whole
[ "$(wc -l <whole/sweep.csv)" -eq 9 ]  # a header and 8 points

# GNU parallel: two shards side by side, then the merge.
mkdir p1 p2 merged
parallel --halt now,fail=1 "$shadesim" sweep "${args[@]}" --quiet --shard {}/2 -o p{} ::: 1 2
[ ! -e p1/sweep.csv ] && [ ! -e p2/sweep.csv ]  # a shard alone is no result
"$shadesim" sweep-merge p1 p2 -o merged
same merged

# Slurm: the dry run's commands, with sbatch played by a function.
"$root/scripts/sweep_slurm.sh" --shards 3 --cpus 1 --dir slurm --shadesim "$shadesim" --dry-run -- "${args[@]}" \
  >slurm.sh
grep -q -- '--array=1-3' slurm.sh
grep -q -- '--dependency=afterok:' slurm.sh
sbatch() {
  local array="" wrap="" a
  while [ $# -gt 0 ]; do
    a=$1
    shift
    case "$a" in
      --array=*) array=${a#--array=} ;;
      --wrap) wrap=$1; shift ;;
    esac
  done
  if [ -n "$array" ]; then
    for i in $(seq "${array%-*}" "${array#*-}"); do SLURM_ARRAY_TASK_ID=$i bash -c "$wrap"; done
  else
    bash -c "$wrap"
  fi
}
# shellcheck disable=SC1091
source ./slurm.sh
same slurm/merged

# The other units: sweep-merge rebuilds each from the plan's base alone.
for unit in "--unit span --triangles 2000 --param ColourFracBits=8:12:2" "--unit phong --scene sphere --param LobeCosBits=8,12"; do
  rm -rf whole p1 p2 merged
  mkdir whole p1 p2 merged
  # shellcheck disable=SC2086
  "$shadesim" sweep $unit --quiet -o whole
  # shellcheck disable=SC2086
  parallel --halt now,fail=1 "$shadesim" sweep $unit --quiet --shard {}/2 -o p{} ::: 1 2
  "$shadesim" sweep-merge p1 p2 -o merged --quiet
  same merged
done
