#!/usr/bin/env bash
# Primary rays of the default scene's picture, halo4d's tracer against Embree's, in one run:
# `cargo bench --bench rays` (criterion: halo4d's rays per second; it writes the rays and
# halo4d's hits to exports/rays/default-scene.bin), then benches/embree/rays.c built against
# Debian's Embree (libembree-dev, installed when missing) traces the same rays.
#
#   benches/embree/run.sh
set -euo pipefail
cd "$(dirname "$0")/../.."
if [ ! -e /usr/include/embree3/rtcore.h ]; then
  echo "-- installing Debian's libembree-dev"
  sudo=$([ "$(id -u)" = 0 ] || echo sudo)
  $sudo apt-get install -y libembree-dev
fi
cargo bench --bench rays
mkdir -p target/embree
gcc -O3 -march=native -fopenmp -Wall -Wextra -o target/embree/rays benches/embree/rays.c \
  -lembree3 -lm
target/embree/rays exports/rays/default-scene.bin
