#!/usr/bin/env bash
# The frames of a halo4d animation as a Slurm array job: task I of N makes the frames whose
# index modulo N is I, into one folder that every node sees (a shared file system).
#
#   jobid=$(sbatch --parsable --array=0-39 examples/batch/slurm.sh scene.json frames/)
#   sbatch --dependency=afterok:$jobid --wrap 'halo4d animate --assemble frames/'
#
# A task that fails or is preempted can simply run again (`scontrol requeue`, or the same
# sbatch line): it makes only the frames without a record. `halo4d animate --status frames/`
# says where the frames stand at any time. HALO4D names the binary when it is not on PATH.
#SBATCH --job-name=halo4d-animate
#SBATCH --cpus-per-task=2
#SBATCH --output=halo4d-animate-%A-%a.log
set -euo pipefail
scene=${1:?usage: sbatch --array=0-(N-1) slurm.sh SCENE FOLDER}
out=${2:?usage: sbatch --array=0-(N-1) slurm.sh SCENE FOLDER}
# One rayon thread per core Slurm gave the task.
export RAYON_NUM_THREADS=${SLURM_CPUS_PER_TASK:-1}
exec "${HALO4D:-halo4d}" animate "$scene" --out "$out" \
  --shard "$SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT"
