#!/usr/bin/env bash
# The frames of a halo4d animation on one machine (or several, with GNU parallel's
# --sshlogin and a shared folder): N shards side by side, then the assembly.
#
#   examples/batch/parallel.sh scene.json frames/ 4
#
# Each shard runs single-threaded, so N shards keep N cores busy on whole frames.
set -euo pipefail
scene=${1:?usage: parallel.sh SCENE FOLDER [SHARDS]}
out=${2:?usage: parallel.sh SCENE FOLDER [SHARDS]}
n=${3:-$(nproc)}
halo4d=${HALO4D:-halo4d}
RAYON_NUM_THREADS=1 parallel --halt now,fail=1 --jobs "$n" \
  "$halo4d" animate "$scene" --out "$out" --quiet --shard {}/"$n" ::: $(seq 0 $((n - 1)))
"$halo4d" animate --assemble "$out"
