#!/bin/sh
# Interleaved renders of instanced.toml and flattened.toml in DIR ($1), ROUNDS ($2) rounds, on
# lavapipe (256², 8 spp) and the CPU reference (128², 4 spp): one JSON summary per render, with
# the scene and device. GLINT (default: target/release/glint) is the binary.
dir=$1
rounds=${2:-3}
glint=${GLINT:-target/release/glint}
for round in $(seq "$rounds"); do
  for scene in instanced flattened; do
    "$glint" render "$dir/$scene.toml" --gpu --width 256 --height 256 --spp 8 \
      -o "$dir/$scene-gpu.png" --json | sed "s/^{/{\"round\":$round,\"device_kind\":\"gpu\",/"
    "$glint" render "$dir/$scene.toml" --cpu --width 128 --height 128 --spp 4 \
      -o "$dir/$scene-cpu.png" --json | sed "s/^{/{\"round\":$round,\"device_kind\":\"cpu\",/"
  done
done
