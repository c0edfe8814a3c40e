#!/usr/bin/env bash
# glint against Blender's Cycles on Khronos' DamagedHelmet.glb under royal_esplanade_1k.hdr
# (both from ../shared/assets, never committed; GLINT_ASSETS names the folder): the same
# camera, environment map, bounces and sample count, linear EXRs, then a side-by-side PNG and
# the image means. Needs Debian's `blender` (3.4) and python3 with numpy, OpenEXR, imageio.
# Usage: bench/cycles/run.sh OUT_DIR [SIZE] [SPP]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
out=$(mkdir -p "$1" && cd "$1" && pwd)
size=${2:-256}
spp=${3:-256}
assets=${GLINT_ASSETS:-$here/../../../shared/assets}
model=$assets/DamagedHelmet.glb
sky=$assets/royal_esplanade_1k.hdr
cat > "$out/helmet.toml" <<TOML
[camera]
eye = [0.0, 0.0, 3.2]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
vfov = 40.0

[render]
width = $size
height = $size
spp = $spp
max_bounces = 8

[environment]
file = "$sky"

[[meshes]]
file = "$model"
TOML
glint=${GLINT:-$here/../../target/release/glint}
"$glint" render "$out/helmet.toml" --cpu -o "$out/helmet_glint.exr"
blender -b --python "$here/render.py" -- "$model" "$sky" "$out/helmet_cycles.exr" \
    "$size" "$spp" 3.2 40 > "$out/blender.log" 2>&1
python3 "$here/compare.py" "$out/helmet_glint.exr" "$out/helmet_cycles.exr" "$out/side.png" \
    0,0,40,40 216,0,256,60 100,100,156,140 110,200,150,240
