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
cat > "$out/clearcoat.toml" <<TOML
[camera]
eye = [$eye_x, $eye_y, $eye_z]
target = [$eye_x, $eye_y, 0.0]
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
"$glint" render "$out/clearcoat.toml" --cpu -o "$out/clearcoat_glint.exr"
blender -b --python "$here/render.py" -- "$model" "$sky" "$out/clearcoat_cycles.exr" \
    "$size" "$spp" "$eye_z" 40 "$eye_x" "$eye_y" > "$out/blender.log" 2>&1
python3 "$here/compare.py" "$out/clearcoat_glint.exr" "$out/clearcoat_cycles.exr" "$out/side.png"
