#!/usr/bin/env python3
"""Caustics: bidirectional against path tracing at equal CPU time (issue 34's check).

For each scene: a long bidirectional reference, then path tracing and bidirectional renders
of about the same CPU time (user + system seconds, so that a busy machine does not skew it),
several seeds each; relative MSE against the reference over the whole image and in boxes
around the caustic and the shadow, with the ratio path / bdpt.

    GLINT=target/release/glint python3 bench/bdpt/measure.py OUT_DIR
"""
import json, os, resource, subprocess, sys
import numpy as np
import OpenEXR, Imath

GLINT = os.environ.get("GLINT", "target/release/glint")
OUT = sys.argv[1] if len(sys.argv) > 1 else "bdpt-measure"
os.makedirs(OUT, exist_ok=True)
SEEDS = [1, 2, 3]

# (scene, width, height, reference spp, bdpt spp, path spp, {region: (x0, y0, x1, y1)})
CASES = [
    ("scenes/caustic.toml", 96, 72, 2048, 32, 160,
     {"caustic": (43, 42, 60, 50), "shadow": (28, 50, 75, 60)}),
    # Boxes in pixels (x0, y0, x1, y1): the caustic's bright spot, and the shadow (for the
    # glass Cornell box, the sphere's whole shadow, caustic included).
    ("scenes/cornell-glass.toml", 72, 72, 2048, 32, 160,
     {"caustic": (23, 58, 34, 63), "shadow": (14, 58, 42, 68)}),
]


def load(path):
    f = OpenEXR.InputFile(path)
    dw = f.header()["dataWindow"]
    w, h = dw.max.x - dw.min.x + 1, dw.max.y - dw.min.y + 1
    pt = Imath.PixelType(Imath.PixelType.FLOAT)
    return np.stack([np.frombuffer(f.channel(c, pt), np.float32).reshape(h, w) for c in "RGB"], -1)


def render(scene, w, h, spp, integrator, seed, out):
    """Renders once (the CPU seconds kept beside the image, so that regions can be changed
    and the errors measured again without rendering)."""
    if os.path.exists(out + ".seconds"):
        return float(open(out + ".seconds").read())
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run([GLINT, "render", scene, "--cpu", "--width", str(w), "--height", str(h),
                    "--spp", str(spp), "--seed", str(seed), "--integrator", integrator,
                    "-o", out], check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    seconds = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    open(out + ".seconds", "w").write(str(seconds))
    return seconds


def rel_mse(img, ref, box=None):
    if box:
        x0, y0, x1, y1 = box
        img, ref = img[y0:y1, x0:x1], ref[y0:y1, x0:x1]
    return float(np.mean((img - ref) ** 2 / (ref ** 2 + 1e-2)))


results = {}
for scene, w, h, ref_spp, bdpt_spp, path_spp, regions in CASES:
    name = os.path.splitext(os.path.basename(scene))[0]
    ref_path = f"{OUT}/{name}-reference.exr"
    if not os.path.exists(ref_path):
        render(scene, w, h, ref_spp, "bdpt", 99, ref_path)
    ref = load(ref_path)
    row = {}
    for integrator, spp in (("bdpt", bdpt_spp), ("path", path_spp)):
        seconds, errors = [], {k: [] for k in ["image", *regions]}
        for seed in SEEDS:
            out = f"{OUT}/{name}-{integrator}-{seed}.exr"
            seconds.append(render(scene, w, h, spp, integrator, seed, out))
            img = load(out)
            errors["image"].append(rel_mse(img, ref))
            for k, box in regions.items():
                errors[k].append(rel_mse(img, ref, box))
        # The median over seeds: one rare firefly (the lamp's sub-pixel reflection in the
        # glass, which only a camera path finds, in either integrator) decides a mean of three.
        row[integrator] = {"spp": spp, "cpu_seconds": float(np.median(seconds)),
                           **{k: float(np.median(v)) for k, v in errors.items()}}
    # Equal time: scale path's error by its time over bdpt's (MSE ∝ 1 / time).
    t = row["path"]["cpu_seconds"] / row["bdpt"]["cpu_seconds"]
    row["path_over_bdpt_at_equal_time"] = {
        k: row["path"][k] * t / row["bdpt"][k] for k in ["image", *regions]}
    results[name] = row
    print(name, json.dumps(row, indent=1))
json.dump(results, open(f"{OUT}/results.json", "w"), indent=1)
