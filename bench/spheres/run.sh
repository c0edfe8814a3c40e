#!/bin/sh
# Interleaved renders of spheres-10, -1000 and -100000.toml in DIR ($1, from make_scenes.py),
# ROUNDS ($2) rounds, on lavapipe (256², 8 spp) and the CPU reference (128², 4 spp): one JSON
# summary per render, with the round and device. GLINT (default: target/release/glint) is the
# binary; TRAVERSAL (default: auto) is passed to the GPU renders' --traversal.
dir=$1
rounds=${2:-3}
glint=${GLINT:-target/release/glint}
traversal=${TRAVERSAL:-auto}
for round in $(seq "$rounds"); do
  for n in 10 1000 100000; do
    "$glint" render "$dir/spheres-$n.toml" --gpu --traversal "$traversal" --width 256 --height 256 \
      --spp 8 -o "$dir/spheres-$n-gpu.png" --json | sed "s/^{/{\"round\":$round,\"device_kind\":\"gpu\",/"
    "$glint" render "$dir/spheres-$n.toml" --cpu --width 128 --height 128 --spp 4 \
      -o "$dir/spheres-$n-cpu.png" --json | sed "s/^{/{\"round\":$round,\"device_kind\":\"cpu\",/"
  done
done
