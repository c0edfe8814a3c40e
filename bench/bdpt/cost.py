#!/usr/bin/env python3
"""Bidirectional's cost where path tracing has no trouble (issue 34's "Cost" check): time to the
same error as path tracing on scenes without caustics, on the CPU reference or, with
GLINT_DEVICE=gpu, on the GPU kernel (lavapipe here).

For each scene: a long path-traced reference, then seeds of each integrator at a fixed spp;
relative MSE against the reference times the render's CPU seconds is the work to reach a given
error (MSE ∝ 1 / time for an unbiased estimator), and bdpt's over path's is the cost ratio
(1 = equal, 2 = bidirectional needs twice the time).

    GLINT=target/release/glint GLINT_ASSETS=../shared/assets python3 bench/bdpt/cost.py OUT_DIR
    GLINT_DEVICE=gpu ... python3 bench/bdpt/cost.py OUT_DIR   # the kernel; more spp (below)

On the GPU each render's seconds are less those of the same render at 1 spp (the least of
three), which takes out start-up, the scene's loading and the kernel's compile (or its load
from Mesa's cache), as bench/mitsuba does; the references are the CPU's either way.
"""
import os, sys
import numpy as np
from common import DEVICE, load, render, rel_mse

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


# (name, scene, size, reference spp, path spp, bdpt spp); on the GPU 16× the samples, so that
# renders outlast their start-up by far.
GPU = DEVICE == "gpu"
MORE = 16 if GPU else 1
CASES = [("cornell", "scenes/cornell.toml", 64, 4096, 64 * MORE, 16 * MORE)]
if helmet_scene():
    CASES.append(("helmet", os.path.join(OUT, "helmet.toml"), 64, 2048, 32 * MORE, 8 * MORE))


def overhead(name, scene, size, integrator):
    """CPU seconds of a 1-spp render on the GPU: what every render pays besides its samples."""
    if not GPU:
        return 0.0
    runs = [render(scene, size, size, 1, integrator, 90 + k,
                   os.path.join(OUT, f"{name}-{integrator}-1spp-{k}.exr")) for k in range(3)]
    # The least: a run that compiled the kernel (or whose cache write had not landed yet for
    # the next) is slower, never faster.
    return float(min(runs))


print(f"device: {DEVICE}")
print("| scene, size | CPU s per render (bdpt / path) | rel. MSE, less the reference's (bdpt / path) | time to equal error, bdpt / path |")
print("|---|---|---|---|")
for name, scene, size, ref_spp, path_spp, bdpt_spp in CASES:
    ref_out = os.path.join(OUT, f"{name}-ref.exr")
    render(scene, size, size, ref_spp, "path", 999, ref_out, device="cpu")
    ref = load(ref_out)
    rows = {}
    for integrator, spp in (("path", path_spp), ("bdpt", bdpt_spp)):
        errors, seconds = [], []
        fixed = overhead(name, scene, size, integrator)
        for seed in SEEDS:
            out = os.path.join(OUT, f"{name}-{integrator}-{seed}.exr")
            seconds.append(render(scene, size, size, spp, integrator, seed, out) - fixed)
            errors.append(rel_mse(load(out), ref))
        rows[integrator] = (float(np.median(errors)), float(np.median(seconds)))
    (eb, tb), (ep, tp) = rows["bdpt"], rows["path"]
    # The reference's own noise adds to both measured errors: it is path tracing too, so at
    # ref_spp its error is path's at path_spp times path_spp / ref_spp. Measured path error =
    # E_path (1 + path_spp / ref_spp); take that share out of both (it matters on the GPU,
    # whose renders have 16× the samples; on the CPU it is under 2%).
    floor = ep * (path_spp / ref_spp) / (1 + path_spp / ref_spp)
    eb, ep = eb - floor, ep - floor
    print(f"| {name}, {size}² | {tb:.2f} / {tp:.2f} | {eb:.2e} / {ep:.2e} | **{eb * tb / (ep * tp):.2f}×** |")
