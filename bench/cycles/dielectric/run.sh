#!/usr/bin/env bash
# glint against Cycles 4.5 on textured rough dielectrics (issue 31, item 3): builds the scenes
# in Blender, renders each with Cycles and glint's CPU reference under a constant white sky and
# under royal_esplanade_1k.hdr, and prints the means per object and their ratios.
# Needs Blender 4.5 as a Python module (python3.11 -m venv V && V/bin/pip install "bpy==4.5.*"
# numpy openexr) as $PY, and a release build of glint as $GLINT.
# Usage: bench/cycles/dielectric/run.sh OUT_DIR
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
out=$(mkdir -p "$1" && cd "$1" && pwd)
PY=${PY:-python3.11}
GLINT=${GLINT:-$here/../../../target/release/glint}
sky=${GLINT_ASSETS:-$here/../../../../shared/assets}/royal_esplanade_1k.hdr
# A constant sky of radiance 1 for glint (Cycles uses its world colour).
python3 -c "import sys; sys.stdout.buffer.write(b'#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 8 +X 16\n' + bytes([128, 128, 128, 129]) * 128)" > "$out/white.hdr"
render() { # NAME W H SPP_CONST SPP_SKY
    $GLINT render "$out/$1.glb" --cpu --width $2 --height $3 --spp $4 --environment "$out/white.hdr" -o "$out/g_$1_const.exr"
    $GLINT render "$out/$1.glb" --cpu --width $2 --height $3 --spp $5 --environment "$sky" -o "$out/g_$1_sky.exr"
    $PY "$here/cycles_render.py" "$out/$1.glb" "$out/c_$1_const.exr" $2 $3 $4 const:1 > "$out/c_$1_const.log"
    $PY "$here/cycles_render.py" "$out/$1.glb" "$out/c_$1_sky.exr" $2 $3 $5 "$sky" > "$out/c_$1_sky.log"
}
scene() { # NAME FLAGS...
    local name=$1; shift
    $PY "$here/make_scene.py" "$out/$name.glb" "$@" > "$out/make_$name.log"
}
scene spheres_plain
scene spheres_normal --normal
scene spheres_roughtex --roughtex
scene spheres_nospec --nospec
scene spheres_nospec_closest --nospec --closest
scene planes --plane
scene floor --floor
scene floor_normal --floor --normal
scene floor_roughtex --floor --roughtex
scene floor_all --floor --normal --roughtex
scene floor_all_closest --floor --normal --roughtex --closest
for s in spheres_plain spheres_normal spheres_roughtex spheres_nospec spheres_nospec_closest planes; do render $s 120 120 256 1024; done
for s in floor floor_normal floor_roughtex floor_all floor_all_closest; do render $s 120 60 256 2048; done
for v in card nomask; do
    $PY "$here/make_card.py" "$out/$v.glb" $([ $v = nomask ] && echo --nomask) > "$out/make_$v.log"
    render $v 144 48 256 1024
done
for s in spheres_plain spheres_normal spheres_roughtex spheres_nospec spheres_nospec_closest planes floor floor_normal floor_roughtex floor_all floor_all_closest; do
    for l in const sky; do echo "== $s, $l"; $PY "$here/means.py" "$out/c_${s}_$l.exr" "$out/g_${s}_$l.exr"; done
done
for v in card nomask; do
    for l in const sky; do echo "== $v, $l"; $PY "$here/means.py" --row "$out/c_${v}_$l.exr" "$out/g_${v}_$l.exr"; done
done
