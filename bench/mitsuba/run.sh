#!/usr/bin/env bash
# Interleaved side by side: glint on the GPU (lavapipe here), glint's CPU reference, and
# Mitsuba 3 (compare.py), on the same scene, resolution, spp and depth; prints the medians.
#
#   bench/mitsuba/run.sh [SCENE]            (default scenes/cornell.toml)
#
# Environment: ROUNDS (5), WIDTH and HEIGHT (256), SPP (64), BOUNCES (8), OUT (a new
# folder under /tmp), GLINT (target/release/glint), DEVICES ("gpu cpu mitsuba"),
# DRJIT_LIBLLVM_PATH (see README.md). Light sampling is glint's default (on); Mitsuba's path
# integrator always samples emitters.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
scene=${1:-scenes/cornell.toml}
rounds=${ROUNDS:-5}
width=${WIDTH:-256}
height=${HEIGHT:-256}
spp=${SPP:-64}
bounces=${BOUNCES:-8}
glint=${GLINT:-target/release/glint}
devices=${DEVICES:-gpu cpu mitsuba}

# lavapipe wants a private runtime folder and a writable shader cache (see
# docs/src/guide/install.md).
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp/xdg-$(id -un)}
mkdir -p -m 700 "$XDG_RUNTIME_DIR"
export MESA_SHADER_CACHE_DIR=${MESA_SHADER_CACHE_DIR:-$PWD/target/mesa-shader-cache}

if [[ " $devices " == *" mitsuba "* && -z "${DRJIT_LIBLLVM_PATH:-}" ]]; then
    echo "run.sh: DRJIT_LIBLLVM_PATH is not set; Mitsuba's LLVM variant crashes with LLVM 15:" \
        "point it at libLLVM-19.so (see bench/mitsuba/README.md)" >&2
    exit 2
fi
if [[ " $devices " == *" gpu "* || " $devices " == *" cpu "* ]] && [[ ! -x "$glint" ]]; then
    echo "run.sh: $glint not found; run cargo build --release first" >&2
    exit 2
fi

out=${OUT:-$(mktemp -d /tmp/glint-vs-mitsuba.XXXXXX)}
mkdir -p "$out"

common=(--width "$width" --height "$height" --spp "$spp" --max-bounces "$bounces")
results="$out/results.jsonl"
: > "$results"
echo "scene $scene, ${width}x${height}, $spp spp, max_bounces $bounces, $rounds rounds; files in $out" >&2
for round in $(seq 1 "$rounds"); do
    for device in $devices; do
        case $device in
        gpu | cpu)
            # Process CPU time (user + sys) at $spp and at 1 spp: their difference is the CPU
            # time of spp - 1 samples per pixel without start-up and shader compilation, a
            # measure that other processes on the shared cores disturb less than wall time.
            /usr/bin/time -f '%U %S' -o "$out/time-1spp" "$glint" render "$scene" \
                --width "$width" --height "$height" --spp 1 --max-bounces "$bounces" \
                --"$device" --seed "$round" -o "$out/glint-$device-1spp.exr" > /dev/null
            /usr/bin/time -f '%U %S' -o "$out/time" "$glint" render "$scene" "${common[@]}" \
                --"$device" --seed "$round" -o "$out/glint-$device.exr" --json > "$out/line"
            line=$(python3 -c 'import json, sys
line = json.load(open(sys.argv[1]))
cpu = lambda f: sum(map(float, open(f).read().split()))
line["cpu_seconds_per_path"] = (cpu(sys.argv[2]) - cpu(sys.argv[3])) / (line["paths"] * (1 - 1 / line["spp"]))
print(json.dumps(line))' "$out/line" "$out/time" "$out/time-1spp")
            ;;
        mitsuba)
            # One warm-up render (JIT compilation, not timed), then one timed render.
            line=$(python3 "$here/compare.py" "$scene" "${common[@]}" --seed "$round" --runs 1 \
                -o "$out/mitsuba.exr" --png "$out/mitsuba.png")
            ;;
        *)
            echo "run.sh: unknown device $device" >&2
            exit 2
            ;;
        esac
        # The load average tells how busy the shared machine was.
        load=$(cut -d' ' -f1 /proc/loadavg)
        echo "{\"round\": $round, \"device\": \"$device\", \"load\": $load, \"result\": $line}" >> "$results"
        echo "round $round $device (load $load): $(python3 -c 'import json,sys; print("%.3f M paths/s" % (json.loads(sys.argv[1])["paths_per_second"] / 1e6))' "$line")" >&2
    done
done

python3 - "$results" <<'EOF'
import json, statistics, sys
rows = [json.loads(l) for l in open(sys.argv[1])]
names = {"gpu": "glint GPU", "cpu": "glint CPU reference", "mitsuba": "Mitsuba 3"}
per, per_cpu = {}, {}
for r in rows:
    per.setdefault(r["device"], []).append(r["result"]["paths_per_second"])
    # Too small a render to measure CPU time by difference gives 0 or less: not a number.
    cost = r["result"]["cpu_seconds_per_path"]
    per_cpu.setdefault(r["device"], []).append(1 / cost if cost > 0 else float("nan"))
print("| renderer | median paths/s | runs (interleaved, M paths/s) | median paths per CPU second |")
print("|---|---|---|---|")
for device, values in per.items():
    label = names[device]
    if device == "gpu":
        label += f" ({rows[[r['device'] for r in rows].index('gpu')]['result']['device']})"
    if device == "mitsuba":
        first = next(r["result"] for r in rows if r["device"] == "mitsuba")
        label += f" {first['mitsuba']} {first['variant']}, {first['threads']} threads"
    runs = " / ".join(f"{v / 1e6:.2f}" for v in values)
    cpu = statistics.median(per_cpu[device])
    print(f"| {label} | {statistics.median(values) / 1e6:.2f} M | {runs} | {cpu / 1e6:.2f} M |")
loads = [r["load"] for r in rows]
print(f"1-minute load average during the runs: {min(loads):.1f} to {max(loads):.1f} (2 cores)")
if "mitsuba" in per:
    m = statistics.median(per["mitsuba"])
    for device in ("gpu", "cpu"):
        if device in per:
            print(f"{names[device]} / Mitsuba 3: {statistics.median(per[device]) / m:.2f}x "
                  f"(per CPU second: {statistics.median(per_cpu[device]) / statistics.median(per_cpu['mitsuba']):.2f}x)")
EOF

# The images should agree (same scene): means per channel, Mitsuba against glint.
if [[ " $devices " == *" mitsuba "* ]]; then
    for device in gpu cpu; do
        if [[ -f "$out/glint-$device.exr" ]]; then
            echo "Mitsuba (A) against glint $device (B), last round:"
            "$glint" compare "$out/mitsuba.exr" "$out/glint-$device.exr" | grep -E '^(mean|RMSE|rel)'
        fi
    done
fi
