#!/usr/bin/env bash
# Runs `trm sweep` on a Slurm cluster: an array of N tasks, each evaluating one shard of the points
# (sweep-shard.sbatch), then a merge job that starts once every task succeeded (sweep-merge.sbatch; cancelled if one
# failed). WORK must be on a file system every node sees.
#
# Usage: tools/slurm/sweep.sh [--shards N] [--trm PATH] [--wait] [--sbatch-option OPTION]... WORK [sweep options...]
#   --shards N          array tasks (default 8)
#   --trm PATH          the trm executable the nodes run (default: build/trm of this checkout, else trm on PATH)
#   --wait              return when the merge has finished; exit non-zero unless it wrote WORK/sweep
#   --sbatch-option O   passed to both sbatch calls (repeatable), e.g. --sbatch-option=--partition=batch
# Writes WORK/parts/part-K (one part per task), WORK/sweep (the merged outputs: sweep.csv, sweep.md, the plots,
# report.json) and WORK/logs/ (each job's output). Prints the two job ids.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"

usage() {
  sed -n '2,/^set -euo/p' "${BASH_SOURCE[0]}" | sed '$d; s/^# \{0,1\}//' >&2
  exit "${1:-2}"
}

shards=8
trm=""
wait_for_merge=0
sbatch_options=()
while (($#)); do
  case "$1" in
    --shards) shards=${2:?--shards needs N}; shift 2 ;;
    --shards=*) shards=${1#*=}; shift ;;
    --trm) trm=${2:?--trm needs a path}; shift 2 ;;
    --trm=*) trm=${1#*=}; shift ;;
    --wait) wait_for_merge=1; shift ;;
    --sbatch-option) sbatch_options+=("${2:?--sbatch-option needs an option}"); shift 2 ;;
    --sbatch-option=*) sbatch_options+=("${1#*=}"); shift ;;
    -h|--help) usage 0 ;;
    --) shift; break ;;
    -*) echo "sweep.sh: error: unknown option '$1'" >&2; usage ;;
    *) break ;;
  esac
done
(($# >= 1)) || { echo "sweep.sh: error: give the work directory" >&2; usage; }
if ! [[ "$shards" =~ ^[1-9][0-9]*$ ]]; then
  echo "sweep.sh: error: --shards must be a whole number >= 1, got '$shards'" >&2
  exit 2
fi
work=$(realpath -m "$1")
shift
if [[ -z "$trm" ]]; then
  if [[ -x "$here/../../build/trm" ]]; then trm="$here/../../build/trm"; else trm=$(command -v trm || true); fi
fi
[[ -n "$trm" && -x "$trm" ]] || { echo "sweep.sh: error: no trm executable (give --trm PATH)" >&2; exit 2; }
trm=$(realpath "$trm")
# The directories made here, deepest first, so that a refused submission can take them away again.
created=()
for dir in "$work/parts" "$work/logs"; do [[ -e "$dir" ]] || created+=("$dir"); done
dir=$work
while [[ ! -e "$dir" ]]; do created+=("$dir"); dir=$(dirname "$dir"); done
mkdir -p "$work/parts" "$work/logs"
if ! array=$(sbatch --parsable "${sbatch_options[@]}" --array="1-$shards" --output="$work/logs/shard-%a.out" \
               "$here/sweep-shard.sbatch" "$trm" "$work/parts" "$@"); then
  for dir in "${created[@]}"; do rmdir "$dir" 2>/dev/null || true; done  # nothing was queued: leave no trace
  echo "sweep.sh: error: sbatch refused the shard array (is Slurm set up here?)" >&2
  exit 1
fi
array=${array%%;*}
merge_options=(--parsable "${sbatch_options[@]}" --dependency="afterok:$array" --kill-on-invalid-dep=yes
               --output="$work/logs/merge.out")
((wait_for_merge)) && merge_options+=(--wait)
echo "sweep.sh: shard array job $array ($shards tasks), logs in $work/logs/"
set +e
merge=$(sbatch "${merge_options[@]}" "$here/sweep-merge.sbatch" "$trm" "$work/parts" "$shards" "$work/sweep")
status=$?
set -e
merge=${merge%%;*}
echo "sweep.sh: merge job $merge, into $work/sweep"
if ((wait_for_merge)); then
  # sbatch --wait reports a merge cancelled for a failed shard as success: the output is what tells.
  if ((status != 0)) || [[ ! -f "$work/sweep/sweep.csv" ]]; then
    echo "sweep.sh: error: the sweep did not complete (see $work/logs/)" >&2
    exit 1
  fi
fi
