#!/usr/bin/env bash
# The time-to-quality table of docs/src/performance/history/2026-12-04-time-to-quality.md:
# seconds to a relative MSE of 10^-2 against each renderer's own converged image, for glint's
# CPU reference, glint on the GPU (lavapipe here), Cycles 4.5 (bpy) and Mitsuba 3, on the
# Cornell box, the bunny and the helmet under the studio HDRI. See README.md.
#
#   GLINT_ASSETS=/path/to/assets bench/time-to-quality/run.sh [OUT]
#   (ROUNDS=3 SIZE=128 REF_SPP=512 LADDER=4,16,64 THREADS=2 SCENES="cornell bunny helmet";
#   SCENES=many-lights TTQ_SPHERE_SEGMENTS=32 for the light tree's scene, once main has it)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
out=${1:-/tmp/time-to-quality}
mkdir -p "$out"
: "${GLINT_ASSETS:?set GLINT_ASSETS to the folder holding DamagedHelmet.glb}"
export GLINT_ASSETS
if [ -z "${DRJIT_LIBLLVM_PATH:-}" ]; then
    DRJIT_LIBLLVM_PATH=$(dpkg -L libllvm19 | grep 'libLLVM-19.so$')
    export DRJIT_LIBLLVM_PATH
fi
glint=${GLINT:-$root/target/release/glint}
bpy_python=${BPY_PYTHON:-/tmp/bpyenv/bin/python}
scenes=()
for s in ${SCENES:-cornell bunny helmet}; do
    if [ "$s" = helmet ]; then
        # The helmet's mesh comes from GLINT_ASSETS: a copy of the scene with absolute paths.
        sed -e "s|\"models/DamagedHelmet.glb\"|\"$GLINT_ASSETS/DamagedHelmet.glb\"|" \
            -e "s|\"skies/studio.hdr\"|\"$root/scenes/skies/studio.hdr\"|" \
            "$root/scenes/helmet.toml" > "$out/helmet.toml"
        scenes+=("$out/helmet.toml")
    elif [ "$s" = many-lights ] && [ ! -e "$root/scenes/many-lights.toml" ]; then
        # Generated, not kept in the repository (scenes/tools/make_many_lights.py). Its 800
        # spheres are slow to build in Blender: run it on its own with TTQ_SPHERE_SEGMENTS=32.
        python3 "$root/scenes/tools/make_many_lights.py" --size "${SIZE:-128}" \
            --out "$out/many-lights.toml"
        scenes+=("$out/many-lights.toml")
    else
        scenes+=("$root/scenes/$s.toml")
    fi
done
uptime | tee "$out/uptime-start.txt"
python3 "$here/ttq.py" --glint "$glint" --bpy-python "$bpy_python" --out "$out" \
    --scenes "$(IFS=,; echo "${scenes[*]}")" --size "${SIZE:-128}" --ref-spp "${REF_SPP:-512}" \
    --ladder "${LADDER:-4,16,64}" --rounds "${ROUNDS:-3}" --threads "${THREADS:-2}" \
    2> "$out/progress.log" | tee "$out/report.md"
uptime | tee "$out/uptime-end.txt"
