#!/usr/bin/env bash
# glint against Blender's Cycles on Khronos' ClearCoatTest (Debian's assimp-testmodels) under
# royal_esplanade_1k.hdr (../shared/assets; GLINT_ASSETS names the folder), as run.sh does for
# the helmet: the same camera, environment map, bounces and sample count, then a side-by-side
# PNG and the image means. Blender 3.4's importer reads KHR_materials_clearcoat into the
# Principled BSDF's Clearcoat, Clearcoat Roughness and Clearcoat Normal.
# Usage: bench/cycles/clearcoat.sh OUT_DIR [SIZE] [SPP]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
out=$(mkdir -p "$1" && cd "$1" && pwd)
size=${2:-256}
spp=${3:-256}
assets=${GLINT_ASSETS:-$here/../../../shared/assets}
model=/usr/share/assimp/models/glTF2/ClearCoat-glTF/ClearCoatTest.gltf
sky=$assets/royal_esplanade_1k.hdr
# The test's grid of spheres and labels spans x −7.4…3.2, y −6.3…7 (z 0): frame the spheres
# (x −3.1…3.1) and most of the labels.
eye_x=-1.0
eye_y=0.35
eye_z=19.5
"$here/side_by_side.sh" "$out" clearcoat "$model" "$sky" "$size" "$spp" $eye_x $eye_y $eye_z
python3 "$here/compare.py" "$out/clearcoat_glint.exr" "$out/clearcoat_cycles.exr" "$out/side.png"
