#!/bin/bash
# Renders SCENE as SHARDS tasks of a Slurm job array, then merges them in a job that runs only
# if every shard succeeded. Prints the two job ids.
#
#   SCENE=scenes/cornell.toml OUT=/shared/render SHARDS=16 GLINT_ARGS="--spp 4096" \
#       deploy/slurm/submit.sh [extra sbatch flags, e.g. --partition=gpu --gres=gpu:1]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
: "${SCENE:?set SCENE to the scene file}"
SHARDS=${SHARDS:-4}
export OUT=${OUT:-$PWD}
mkdir -p "$OUT"
array=$(sbatch --parsable --array=0-$((SHARDS - 1)) --export=ALL \
    --output="$OUT/shard-%a.log" "$@" "$here/shard.sbatch")
array=${array%%;*}
merge=$(sbatch --parsable --dependency=afterok:"$array" --kill-on-invalid-dep=yes \
    --export=ALL --output="$OUT/merge.log" "$here/merge.sbatch")
echo "$array $merge"
