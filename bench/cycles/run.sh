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
"$here/side_by_side.sh" "$out" helmet "$model" "$sky" "$size" "$spp" 0.0 0.0 3.2
python3 "$here/compare.py" "$out/helmet_glint.exr" "$out/helmet_cycles.exr" "$out/side.png" \
    0,0,40,40 216,0,256,60 100,100,156,140 110,200,150,240
