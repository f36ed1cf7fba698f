#!/usr/bin/env bash
# CI: the animation recipes of examples/batch/ run for real, each against one process's
# frames: a Slurm array job on a one-node cluster (.ci/slurm-up.sh), GNU parallel, and the
# Kubernetes Indexed Job's container command, run once per completion index. Each must
# make the same frames, byte for byte, and assemble.
# Usage: .ci/animate-batch.sh HALO4D OUT PYTHON
set -euo pipefail
halo4d=$(realpath "$1")
out=$(realpath "$2")
python=$3
scene=$PWD/fixtures/animations/flat-torus-turn.json
frames=$(grep -o '"frames": [0-9]*' "$scene" | grep -o '[0-9]*$')

same_frames() { # FOLDER: every frame's picture as one process's, and the folder assembles
  local k
  for ((k = 0; k < frames; k++)); do
    f=$(printf 'frame-%05d.png' "$k")
    cmp -s "$out/one/$f" "$1/$f" || { echo "$1/$f differs from one process's"; exit 1; }
  done
  "$halo4d" animate --status "$1"
  "$halo4d" animate --assemble "$1"
  test -s "$1/animation.png"
}

echo "-- one process"
"$halo4d" animate "$scene" --quiet --out "$out/one"

echo "-- a Slurm array of 4 tasks (examples/batch/slurm.sh)"
bash .ci/slurm-up.sh
sbatch --wait --array=0-3 --cpus-per-task=1 --chdir="$out" --export=ALL,HALO4D="$halo4d" \
  "$PWD/examples/batch/slurm.sh" "$scene" "$out/slurm"
cat "$out"/halo4d-animate-*.log
same_frames "$out/slurm"

echo "-- GNU parallel, 3 shards (examples/batch/parallel.sh)"
command -v parallel >/dev/null || {
  apt-get update -qq || echo 'apt-get update failed; installing from the lists there are'
  apt-get install -y -qq parallel
}
HALO4D=$halo4d examples/batch/parallel.sh "$scene" "$out/parallel" 3
same_frames "$out/parallel"

echo "-- the Kubernetes Indexed Job's command, once per index (examples/batch/k8s-indexed-job.yaml)"
"$python" .ci/k8s-indexed-job.py examples/batch/k8s-indexed-job.yaml "$halo4d" "$scene" "$out/k8s" 4
same_frames "$out/k8s"
