#!/usr/bin/env bash
# A Slurm job array rendering one sequence on N machines: task I renders the frames whose index
# (from the first) is I mod N, into one shared folder. Submit with
#   sbatch --array=0-15 examples/farm/slurm_array.sh scene.glb 0 9999 /shared/frames \
#       --panorama equirect --preset vr4k
# (arguments after the folder go to `twister render`).
# Assumptions: the scene file and the output folder are on storage every node mounts at the same
# path; each node has twister on PATH and a Vulkan driver (scripts/test.sh installs lavapipe
# where there is none). A task that is preempted or fails can simply run again: --resume skips
# the frames it finished, and every frame's files are written whole (temporary name, rename),
# so no node ever sees half a frame. The frames are the same bytes whichever node renders them.
#SBATCH --job-name=twister
#SBATCH --cpus-per-task=4
#SBATCH --gpus=1
set -euo pipefail
scene=$1 first=$2 last=$3 out=$4
shift 4
shards=${SLURM_ARRAY_TASK_COUNT:?run as a job array (sbatch --array=0-N)}
twister render "$scene" --frames "$first..$last" --shard "$SLURM_ARRAY_TASK_ID/$shards" --resume \
    --out "$out" --stats "$out/stats_$SLURM_ARRAY_TASK_ID.jsonl" "$@"
