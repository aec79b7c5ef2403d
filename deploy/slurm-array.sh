#!/bin/bash
# A render split over a Slurm job array: task i renders samples
# i*CHUNK..(i+1)*CHUNK (the last task up to SPP) into parts/part_i.exr, and a
# dependent job merges the parts. Submit the whole thing with
#
#     SPP=4096 TASKS=16 deploy/slurm-array.sh submit
#
# which runs `sbatch --array=0-15 ... render`, then `sbatch
# --dependency=afterok:<array job> ... merge`, with the logs in parts/. Every
# task runs the same `treelet` binary (build it once, on shared storage:
# `cargo build --release -p treelet`) with the same scene, size and seed.
# GPUS is the GPUs a task asks for: 1 by default, 0 (none asked, as a
# cluster without GPU resources needs) with DEVICE=cpu. `deploy/slurm-local.sh`
# starts a one-node cluster to try it on.
#SBATCH --job-name=treelet
set -euo pipefail
TREELET=${TREELET:-target/release/treelet}
SCENE=${SCENE:-cornell}
WIDTH=${WIDTH:-1024}
HEIGHT=${HEIGHT:-768}
SPP=${SPP:-4096}
TASKS=${TASKS:-16}
SEED=${SEED:-0}
OUT=${OUT:-treelet.png}
DEVICE=${DEVICE:-auto}
if [ "$DEVICE" = cpu ]; then GPUS=${GPUS:-0}; else GPUS=${GPUS:-1}; fi
PARTS=${PARTS:-parts}

case "${1:-render}" in
  submit)
    # Slurm opens a task's log before the task runs: its folder must exist first.
    mkdir -p "$PARTS"
    gpus=()
    if [ "$GPUS" -gt 0 ]; then gpus=(--gpus="$GPUS"); fi
    job=$(sbatch --parsable --array=0-$((TASKS - 1)) "${gpus[@]}" --output="$PARTS/treelet_%A_%a.log" "$0" render)
    merge=$(sbatch --parsable --dependency=afterok:"$job" --output="$PARTS/treelet_merge_%j.log" "$0" merge)
    echo "array job $job ($TASKS tasks), then merge job $merge; logs in $PARTS/"
    ;;
  render)
    i=${SLURM_ARRAY_TASK_ID:?run as a job array task, or use: $0 submit}
    chunk=$(((SPP + TASKS - 1) / TASKS))
    first=$((i * chunk))
    last=$(((i + 1) * chunk < SPP ? (i + 1) * chunk : SPP))
    if [ "$first" -ge "$last" ]; then exit 0; fi  # more tasks than samples
    mkdir -p "$PARTS"
    "$TREELET" render --device "$DEVICE" --scene "$SCENE" --width "$WIDTH" --height "$HEIGHT" --seed "$SEED" \
      --samples "$first..$last" --out "$PARTS/part_$i.exr"
    ;;
  merge)
    "$TREELET" merge "$PARTS"/part_*.exr --out "$OUT"
    ;;
  *)
    echo "usage: $0 submit|render|merge" >&2
    exit 2
    ;;
esac
