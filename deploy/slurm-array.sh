#!/bin/bash
# A render split over a Slurm job array: task i renders samples
# i*CHUNK..(i+1)*CHUNK (the last task up to SPP) into parts/part_i.exr, and a
# dependent job merges the parts. Submit the whole thing with
#
#     SPP=4096 TASKS=16 sbatch --array=0-15 deploy/slurm-array.sh render
#     sbatch --dependency=afterok:<array job id> deploy/slurm-array.sh merge
#
# or run `deploy/slurm-array.sh submit`, which does both. Every task runs the
# same `treelet` binary (build it once, on shared storage:
# `cargo build --release -p treelet`) with the same scene, size and seed.
#SBATCH --job-name=treelet
#SBATCH --gpus=1
#SBATCH --output=parts/treelet_%A_%a.log
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
PARTS=${PARTS:-parts}
mkdir -p "$PARTS"

case "${1:-render}" in
  submit)
    job=$(sbatch --parsable --array=0-$((TASKS - 1)) "$0" render)
    sbatch --dependency=afterok:"$job" --gpus=0 "$0" merge
    ;;
  render)
    i=${SLURM_ARRAY_TASK_ID:?run as a job array task, or use: $0 submit}
    chunk=$(((SPP + TASKS - 1) / TASKS))
    first=$((i * chunk))
    last=$(((i + 1) * chunk < SPP ? (i + 1) * chunk : SPP))
    if [ "$first" -ge "$last" ]; then exit 0; fi  # more tasks than samples
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
