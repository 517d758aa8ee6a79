#!/usr/bin/env bash
# sweep_slurm.sh: a sweep as a Slurm job array, one shard per array task, then the merge.
#
#   scripts/sweep_slurm.sh --shards N --dir DIR [--cpus C] [--shadesim PATH] [--dry-run]
#                          [--sbatch-arg ARG]... -- SWEEP ARGUMENTS...
#
# Submits (or with --dry-run prints, submitting nothing)
#   1. sbatch --array=1-N: task i runs `shadesim sweep ARGS --shard i/N --jobs C -o DIR/shard-i`;
#   2. sbatch --dependency=afterok:<the array's job id>: `shadesim sweep-merge DIR/shard-1 ...
#      DIR/shard-N -o DIR/merged`, which refuses shards of different sweeps and names missing
#      points.
# It makes DIR and the shard directories first (shadesim itself never creates a directory). A
# task that is killed and resubmitted resumes: the shard's recorded points are skipped.
#   --shards N        the number of array tasks (1..10000)
#   --dir DIR         where the shards and the merged sweep go (on a file system every node sees)
#   --cpus C          --cpus-per-task of each task and the sweep's --jobs (default 1)
#   --shadesim PATH   the program the tasks run (default: shadesim on the nodes' PATH)
#   --sbatch-arg ARG  passed to both sbatch calls (repeat: --sbatch-arg=--partition=long ...)
# Example:
#   scripts/sweep_slurm.sh --shards 8 --cpus 4 --dir /scratch/sw -- \
#     --config default --param CoefFracBits=8:16 --param DiffFracBits=12:28
set -euo pipefail

usage() { sed -n '2,22p' "$0" | sed 's/^# \{0,1\}//'; exit "${1:-0}"; }
die() { echo "sweep_slurm: error: $*" >&2; exit 2; }

shards="" dir="" cpus=1 shadesim=shadesim dry=0
sbatch_args=()
while [ $# -gt 0 ]; do
  case "$1" in
    --shards) shards=${2-}; shift 2 ;;
    --dir) dir=${2-}; shift 2 ;;
    --cpus) cpus=${2-}; shift 2 ;;
    --shadesim) shadesim=${2-}; shift 2 ;;
    --sbatch-arg) sbatch_args+=("${2-}"); shift 2 ;;
    --sbatch-arg=*) sbatch_args+=("${1#--sbatch-arg=}"); shift ;;
    --dry-run) dry=1; shift ;;
    -h|--help) usage 0 ;;
    --) shift; break ;;
    *) die "unknown option '$1' (the sweep's own arguments go after --)" ;;
  esac
done
sweep_args=("$@")
[[ "$shards" =~ ^[0-9]+$ ]] && [ "$shards" -ge 1 ] && [ "$shards" -le 10000 ] ||
  die "--shards must be a whole number in [1, 10000], got '$shards'"
[[ "$cpus" =~ ^[0-9]+$ ]] && [ "$cpus" -ge 1 ] && [ "$cpus" -le 256 ] ||
  die "--cpus must be a whole number in [1, 256], got '$cpus'"
[ -n "$dir" ] || die "--dir is required"
[ ${#sweep_args[@]} -gt 0 ] || die "no sweep arguments after -- (at least one --param)"
for a in "${sweep_args[@]}"; do
  case "$a" in
    --shard|--shard=*|-o|--output|--output=*|--jobs|--jobs=*) die "'$a' is set by this script per task" ;;
  esac
done
command -v sbatch >/dev/null || [ "$dry" = 1 ] || die "sbatch not found (Slurm's client); --dry-run prints the commands"
dir=$(realpath -m -- "$dir")

# The task's command line, quoted for the shell sbatch --wrap runs.
task=$(printf '%q ' "$shadesim" sweep "${sweep_args[@]}")
task+="--shard \${SLURM_ARRAY_TASK_ID}/$shards --jobs $cpus --quiet -o $(printf '%q' "$dir")/shard-\${SLURM_ARRAY_TASK_ID}"
merge=$(printf '%q ' "$shadesim" sweep-merge)
for i in $(seq 1 "$shards"); do merge+="$(printf '%q' "$dir/shard-$i") "; done
merge+="-o $(printf '%q' "$dir/merged") --jobs $cpus --quiet"
# A sweep with --area: the shards evaluate the model only; the merge runs the area phase.
for ((i = 0; i < ${#sweep_args[@]}; i++)); do
  case "${sweep_args[$i]}" in
    --synth-cache) merge+=" --synth-cache $(printf '%q' "${sweep_args[$((i + 1))]:-}")" ;;
    --synth-cache=*) merge+=" --synth-cache $(printf '%q' "${sweep_args[$i]#--synth-cache=}")" ;;
  esac
done

array_cmd=(sbatch --parsable "--array=1-$shards" "--cpus-per-task=$cpus" --job-name=shadesim-sweep
  "${sbatch_args[@]}" "--output=$dir/shard-%a.log" --wrap "$task")
if [ "$dry" = 1 ]; then
  echo "mkdir -p $(printf '%q' "$dir")/shard-{1..$shards} $(printf '%q' "$dir/merged")"
  printf '%q ' "${array_cmd[@]}"; echo
  merge_cmd=(sbatch --parsable "--dependency=afterok:<the array's job id>" "--cpus-per-task=$cpus" --job-name=shadesim-sweep-merge
    "${sbatch_args[@]}" "--output=$dir/merge.log" --wrap "$merge")
  printf '%q ' "${merge_cmd[@]}"; echo
  exit 0
fi
for i in $(seq 1 "$shards"); do mkdir -p "$dir/shard-$i"; done
mkdir -p "$dir/merged"
job=$("${array_cmd[@]}")
job=${job%%;*}
merge_job=$(sbatch --parsable "--dependency=afterok:$job" "--cpus-per-task=$cpus" --job-name=shadesim-sweep-merge "${sbatch_args[@]}" \
  "--output=$dir/merge.log" --wrap "$merge")
echo "sweep_slurm: array job $job ($shards tasks), merge job ${merge_job%%;*}; the merged sweep: $dir/merged"
