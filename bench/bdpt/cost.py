#!/usr/bin/env python3
"""Bidirectional's cost where path tracing has no trouble (issue 34's "Cost" check): time to the
same error as path tracing on scenes without caustics, on the CPU reference.

For each scene: a long path-traced reference, then seeds of each integrator at a fixed spp;
relative MSE against the reference times the render's CPU seconds is the work to reach a given
error (MSE ∝ 1 / time for an unbiased estimator), and bdpt's over path's is the cost ratio
(1 = equal, 2 = bidirectional needs twice the time).

    GLINT=target/release/glint GLINT_ASSETS=../shared/assets python3 bench/bdpt/cost.py OUT_DIR
"""
import os, sys
import numpy as np
from common import load, render, rel_mse

OUT = sys.argv[1] if len(sys.argv) > 1 else "bdpt-cost"
os.makedirs(OUT, exist_ok=True)
SEEDS = [1, 2, 3]
SCENES_DIR = os.path.abspath("scenes")


def helmet_scene():
    """scenes/helmet.toml with the model from GLINT_ASSETS (never committed)."""
    assets = os.environ.get("GLINT_ASSETS")
    if not assets:
        return None
    text = open(os.path.join(SCENES_DIR, "helmet.toml")).read()
    text = text.replace('"models/DamagedHelmet.glb"',
                        '"%s"' % os.path.join(os.path.abspath(assets), "DamagedHelmet.glb"))
    text = text.replace('"skies/studio.hdr"', '"%s"' % os.path.join(SCENES_DIR, "skies/studio.hdr"))
    path = os.path.join(OUT, "helmet.toml")
    open(path, "w").write(text)
    return path


# (name, scene, size, reference spp, path spp, bdpt spp)
CASES = [("cornell", "scenes/cornell.toml", 64, 4096, 64, 16)]
if helmet_scene():
    CASES.append(("helmet", os.path.join(OUT, "helmet.toml"), 64, 2048, 32, 8))


print("| scene, size | CPU s per render (bdpt / path) | rel. MSE (bdpt / path) | time to equal error, bdpt / path |")
print("|---|---|---|---|")
for name, scene, size, ref_spp, path_spp, bdpt_spp in CASES:
    ref_out = os.path.join(OUT, f"{name}-ref.exr")
    render(scene, size, size, ref_spp, "path", 999, ref_out)
    ref = load(ref_out)
    rows = {}
    for integrator, spp in (("path", path_spp), ("bdpt", bdpt_spp)):
        errors, seconds = [], []
        for seed in SEEDS:
            out = os.path.join(OUT, f"{name}-{integrator}-{seed}.exr")
            seconds.append(render(scene, size, size, spp, integrator, seed, out))
            errors.append(rel_mse(load(out), ref))
        rows[integrator] = (float(np.median(errors)), float(np.median(seconds)))
    (eb, tb), (ep, tp) = rows["bdpt"], rows["path"]
    print(f"| {name}, {size}² | {tb:.2f} / {tp:.2f} | {eb:.2e} / {ep:.2e} | **{eb * tb / (ep * tp):.2f}×** |")
