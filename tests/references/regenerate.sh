#!/usr/bin/env bash
# Regenerates the reference images the statistical tests compare GPU renders against: high-spp
# CPU-reference renders, each with the variance image of its pixel means. The seed (1000) is
# one no test uses, so tests and references are independent. The scenes have no specular
# surfaces, so no light arrives by caustic paths, whose rarity would make pixel means far from
# normal at the spp a test can afford (see the scene files).
set -euo pipefail
cd "$(dirname "$0")/../.."
cargo build --release
glint=target/release/glint
out=tests/references
"$glint" render "$out/cornell-diffuse.toml" --cpu --width 64 --height 64 --spp 16384 --seed 1000 \
    -o "$out/cornell-diffuse-64.exr" --variance "$out/cornell-diffuse-64.variance.exr" --json
"$glint" render "$out/sky-diffuse.toml" --cpu --width 64 --height 36 --spp 16384 --seed 1000 \
    -o "$out/sky-diffuse-64x36.exr" --variance "$out/sky-diffuse-64x36.variance.exr" --json
# The denoising test's reference (tests/denoise.rs): the shipped Cornell box, mirror sphere and
# all, at 256² on the GPU (about 20 minutes on 2 busy cores with lavapipe).
"$glint" render scenes/cornell.toml --gpu --width 256 --height 256 --spp 4096 --seed 1000 \
    -o "$out/cornell-256.exr" --json
