#!/usr/bin/env python3
"""Caustics: bidirectional against path tracing at equal CPU time (issue 34's check).

For each scene: a long bidirectional reference, then path tracing and bidirectional renders
of about the same CPU time (user + system seconds, so that a busy machine does not skew it),
several seeds each; relative MSE against the reference over the whole image and in boxes
around the caustic and the shadow, with the ratio path / bdpt.

    GLINT=target/release/glint python3 bench/bdpt/measure.py OUT_DIR
"""
import json, os, sys
import numpy as np
from common import load, render, rel_mse

OUT = sys.argv[1] if len(sys.argv) > 1 else "bdpt-measure"
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


def main():
    os.makedirs(OUT, exist_ok=True)
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


if __name__ == "__main__":
    main()
