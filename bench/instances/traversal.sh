#!/bin/sh
# Interleaved renders of instanced.toml in DIR ($1), ROUNDS ($2) rounds, on the GPU (SIZE²,
# default 128², SPP samples, default 4) with the hardware traversal (ray queries: a TLAS
# instance per placement) and the software one (the two-level BVH): one JSON summary per
# render, with the traversal it ran. GLINT (default: target/release/glint) is the binary.
dir=$1
rounds=${2:-3}
glint=${GLINT:-target/release/glint}
size=${SIZE:-128}
spp=${SPP:-4}
for round in $(seq "$rounds"); do
  for traversal in hardware software; do
    "$glint" render "$dir/instanced.toml" --gpu --traversal "$traversal" --width "$size" \
      --height "$size" --spp "$spp" -o "$dir/instanced-$traversal.png" --json |
      sed "s/^{/{\"round\":$round,/"
  done
done
