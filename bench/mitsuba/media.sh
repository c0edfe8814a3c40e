#!/usr/bin/env bash
# glint's participating media against Mitsuba 3's volpath, per pixel: for each scene in
# bench/mitsuba/media/ (a fog box, two smoke spheres with g = 0.7 and -0.5, the camera in a
# sphere of fog, glass spheres over a medium of chromatic albedo and over one whose σt differs
# per channel; media/dense/ holds a denser one, run on its own), Mitsuba renders
# RUNS independent images of MSPP spp (compare.py --variance: their mean, and the variance of
# that mean from their spread), glint's CPU reference renders GSPP spp with its variance
# image, and `glint compare` runs the per-pixel Z-test on the two. Prints per scene the pass
# rate, the z of the image means, the variance ratio and the means, then the same per channel.
#
# Where a medium's σt differs per channel, Mitsuba's volpath samples free flights in one
# channel per path and weighs the others by their transmittance ratio, whose noise is heavy
# tailed; there the script also renders Mitsuba once per channel with grey media of that
# channel's coefficients (compare.py --medium-channel) and tests glint against those channels
# put together ("per-channel reference").
#
#   bench/mitsuba/media.sh [SCENE.toml ...]     (default: every scene in bench/mitsuba/media/)
#
# Environment: RUNS (16), MSPP (256), GSPP (4096), WIDTH/HEIGHT (the scenes' 32x32), SEED
# (1: Mitsuba uses seeds SEED.. SEED+RUNS-1, glint SEED), OUT (a new folder under /tmp),
# GLINT (target/release/glint), INTEGRATOR (Mitsuba's: volpath, or volpathmis),
# DRJIT_LIBLLVM_PATH (see README.md), REUSE (1: keep Mitsuba's images already in OUT, to
# test another glint build against the same references).
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
runs=${RUNS:-16}
mspp=${MSPP:-256}
gspp=${GSPP:-4096}
seed=${SEED:-1}
glint=${GLINT:-target/release/glint}
integrator=${INTEGRATOR:-volpath}
if [[ $# -gt 0 ]]; then scenes=("$@"); else scenes=("$here"/media/*.toml); fi

if [[ -z "${DRJIT_LIBLLVM_PATH:-}" ]]; then
    echo "media.sh: DRJIT_LIBLLVM_PATH is not set; Mitsuba's LLVM variant crashes with LLVM 15:" \
        "point it at libLLVM-19.so (see bench/mitsuba/README.md)" >&2
    exit 2
fi
if [[ ! -x "$glint" ]]; then
    echo "media.sh: $glint not found; run cargo build --release first" >&2
    exit 2
fi
size=()
[[ -n "${WIDTH:-}" ]] && size+=(--width "$WIDTH")
[[ -n "${HEIGHT:-}" ]] && size+=(--height "$HEIGHT")

# One line from glint compare's JSON: pass rate, z of the means, variance ratio, means.
summary() {
    python3 - "$1" "$2" <<'PY'
import json, sys
c = json.load(open(sys.argv[1]))
z = c["z_test"]
rgb = lambda m: " ".join(f"{x:.4f}" for x in m)
print(f"{sys.argv[2]:<22} {100 * z['pass_rate']:8.2f}% {z['z_of_means']:8.2f} "
      f"{z['variance_ratio']:8.3f}  {rgb(c['mean_a']):<26} {rgb(c['mean_b'])}")
PY
}

# Whether REUSE=1 and Mitsuba's image, variance and JSON named $1 are in OUT already.
reused() {
    [[ "${REUSE:-0}" == 1 && -s "$out/$1.exr" && -s "$out/$1-variance.exr" && -s "$out/$1.json" ]]
}

out=${OUT:-$(mktemp -d /tmp/glint-media-vs-mitsuba.XXXXXX)}
mkdir -p "$out"
echo "Mitsuba $integrator: $runs renders of $mspp spp; glint CPU reference: $gspp spp; files in $out" >&2
printf '%-22s %9s %8s %8s  %-26s %s\n' scene pass z_means var_ratio "glint mean RGB" "Mitsuba mean RGB"
for scene in "${scenes[@]}"; do
    name=$(basename "$scene" .toml)
    # compare.py renders once plus --runs more, each with its own seed.
    if ! reused "$name-mitsuba"; then
        python3 "$here/compare.py" "$scene" "${size[@]}" --spp "$mspp" --runs $((runs - 1)) \
            --seed "$seed" --integrator "$integrator" \
            -o "$out/$name-mitsuba.exr" --variance "$out/$name-mitsuba-variance.exr" \
            > "$out/$name-mitsuba.json"
    fi
    "$glint" render "$scene" "${size[@]}" --cpu --spp "$gspp" --seed "$seed" \
        -o "$out/$name-glint.exr" --variance "$out/$name-glint-variance.exr" \
        --json > "$out/$name-glint.json"
    "$glint" compare "$out/$name-glint.exr" "$out/$name-mitsuba.exr" \
        --variance-a "$out/$name-glint-variance.exr" \
        --variance-b "$out/$name-mitsuba-variance.exr" --json > "$out/$name-compare.json"
    summary "$out/$name-compare.json" "$name"
    python3 "$here/channels.py" test "against volpath" \
        "$out/$name-glint.exr" "$out/$name-glint-variance.exr" \
        "$out/$name-mitsuba.exr" "$out/$name-mitsuba-variance.exr"
    spectral=$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["spectral_extinction"])' \
        "$out/$name-mitsuba.json")
    if [[ $spectral == True ]]; then
        for channel in 0 1 2; do
            reused "$name-mitsuba-c$channel" && continue
            python3 "$here/compare.py" "$scene" "${size[@]}" --spp "$mspp" \
                --runs $((runs - 1)) --seed "$((seed + 1000 * (channel + 1)))" \
                --integrator "$integrator" --medium-channel "$channel" \
                -o "$out/$name-mitsuba-c$channel.exr" \
                --variance "$out/$name-mitsuba-c$channel-variance.exr" \
                > "$out/$name-mitsuba-c$channel.json"
        done
        python3 "$here/channels.py" compose "$out/$name-mitsuba-channels.exr" \
            "$out/$name"-mitsuba-c{0,1,2}.exr
        python3 "$here/channels.py" compose "$out/$name-mitsuba-channels-variance.exr" \
            "$out/$name"-mitsuba-c{0,1,2}-variance.exr
        "$glint" compare "$out/$name-glint.exr" "$out/$name-mitsuba-channels.exr" \
            --variance-a "$out/$name-glint-variance.exr" \
            --variance-b "$out/$name-mitsuba-channels-variance.exr" --json \
            > "$out/$name-channels-compare.json"
        summary "$out/$name-channels-compare.json" "  per-channel ref."
        python3 "$here/channels.py" test "per-channel ref." \
            "$out/$name-glint.exr" "$out/$name-glint-variance.exr" \
            "$out/$name-mitsuba-channels.exr" "$out/$name-mitsuba-channels-variance.exr"
        python3 "$here/channels.py" test "volpath vs that ref." \
            "$out/$name-mitsuba.exr" "$out/$name-mitsuba-variance.exr" \
            "$out/$name-mitsuba-channels.exr" "$out/$name-mitsuba-channels-variance.exr"
    fi
done
