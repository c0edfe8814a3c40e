#!/usr/bin/env bash
# One glTF file in glint (CPU reference) and in Blender's Cycles with the same camera (eye at
# (EYE_X, EYE_Y, EYE_Z) looking along −z, vertical field of view 40°), environment map,
# 8 bounces and sample count, as linear EXRs NAME_glint.exr and NAME_cycles.exr in OUT_DIR.
# Needs Debian's `blender` (3.4). Usage (from run.sh and clearcoat.sh):
# side_by_side.sh OUT_DIR NAME MODEL SKY SIZE SPP EYE_X EYE_Y EYE_Z
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
out=$1 name=$2 model=$3 sky=$4 size=$5 spp=$6 eye_x=$7 eye_y=$8 eye_z=$9
cat > "$out/$name.toml" <<TOML
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
"$glint" render "$out/$name.toml" --cpu -o "$out/${name}_glint.exr"
blender -b --python "$here/render.py" -- "$model" "$sky" "$out/${name}_cycles.exr" \
    "$size" "$spp" "$eye_z" 40 "$eye_x" "$eye_y" > "$out/blender.log" 2>&1
