#!/usr/bin/env bash
# Submit a `drumroll grid` to Slurm: a job array of TASKS shards (scripts/slurm/grid-array.sbatch,
# one shard per task), then a merge job that runs only if every shard succeeded
# (--dependency=afterok) and writes the map file, byte for byte the file that one
# `drumroll grid --output MAP` would write.
#
#   scripts/slurm/submit-grid.sh --tasks 16 --output map.jsonl [--parts-dir DIR] [--wait] \
#       [--sbatch-option OPT]... -- --case biolever-mica --vary a0 --from 5 --to 20 --steps 200 \
#       --z-from 21 --z-to 0.5 --z-steps 200 --retract
#
# --parts-dir: where the part files and Slurm logs go (default MAP.parts/); --wait: return when
# the merge has finished (sbatch --wait), with its exit status; --sbatch-option: passed to both
# sbatch calls (e.g. --partition=long). The binary is $DRUMROLL if set, else `drumroll` on the
# PATH; it must be reachable from the compute nodes at the same path. Prints the two job ids.
set -euo pipefail

usage() {
    sed -n '2,17p' "$0" >&2
    exit 2
}

tasks=
output=
parts_dir=
wait=()
sbatch_options=()
while [ $# -gt 0 ]; do
    case $1 in
        --tasks) tasks=${2:?--tasks needs a number}; shift 2 ;;
        --output) output=${2:?--output needs a file}; shift 2 ;;
        --parts-dir) parts_dir=${2:?--parts-dir needs a directory}; shift 2 ;;
        --wait) wait=(--wait); shift ;;
        --sbatch-option) sbatch_options+=("${2:?--sbatch-option needs a value}"); shift 2 ;;
        --) shift; break ;;
        *) echo "submit-grid.sh: unknown option $1" >&2; usage ;;
    esac
done
if ! [[ $tasks =~ ^[1-9][0-9]*$ ]]; then
    echo "submit-grid.sh: --tasks must be a positive integer (got '${tasks}')" >&2
    usage
fi
if [ -z "$output" ] || [ $# -eq 0 ]; then
    usage
fi
script_dir=$(cd "$(dirname "$0")" && pwd)
drumroll=${DRUMROLL:-$(command -v drumroll || true)}
if [ -z "$drumroll" ] || [ ! -x "$drumroll" ]; then
    echo "submit-grid.sh: no drumroll binary: set DRUMROLL or put drumroll on the PATH" >&2
    exit 2
fi
export DRUMROLL=$(cd "$(dirname "$drumroll")" && pwd)/$(basename "$drumroll")
output=$(cd "$(dirname "$output")" && pwd)/$(basename "$output")
parts_dir=${parts_dir:-${output}.parts}
mkdir -p "$parts_dir"
parts_dir=$(cd "$parts_dir" && pwd)

# The shards: the array's sbatch --wait returns when every task has ended.
array_job=$(sbatch --parsable "${wait[@]}" "${sbatch_options[@]}" \
    --array="0-$((tasks - 1))" \
    --output="${parts_dir}/slurm-%A_%a.out" \
    "${script_dir}/grid-array.sbatch" "$tasks" "$parts_dir" "$@")
array_job=${array_job%%;*}
echo "grid shards: job array ${array_job} (${tasks} tasks, parts in ${parts_dir})"

# The merge, once every shard has succeeded: the parts named one by one, so that a missing
# one is an error naming it.
merge_command=$(printf '%q ' "$DRUMROLL" grid merge)
for ((i = 0; i < tasks; i++)); do
    merge_command+=$(printf '%q ' "${parts_dir}/part-${i}.jsonl")
done
merge_command+=$(printf -- '--output %q' "$output")
merge_job=$(sbatch --parsable "${wait[@]}" "${sbatch_options[@]}" \
    --job-name=drumroll-grid-merge \
    --dependency="afterok:${array_job}" \
    --output="${parts_dir}/slurm-merge-%j.out" \
    --wrap="$merge_command")
merge_job=${merge_job%%;*}
echo "grid merge: job ${merge_job} (after ${array_job} succeeds) -> ${output}"
