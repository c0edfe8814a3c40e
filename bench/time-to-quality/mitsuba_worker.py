#!/usr/bin/env python3
"""Render one glint scene with Mitsuba 3 (llvm_ad_rgb) at several sample counts in one process.

Maps the scene with ../mitsuba/compare.py's convert_scene, loads it once, renders once at 1 spp
untimed (JIT warm-up; Dr.Jit's kernel cache keeps later processes from compiling again), then
renders at each sample count and prints one JSON line per render: spp, wall seconds and process
CPU seconds (all threads) of mi.render up to the image being evaluated, and the EXR written.

    python3 mitsuba_worker.py SCENE.toml OUT_PREFIX SIZE SEED THREADS SPP[,SPP...]
"""

import json
import os
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "mitsuba"))
import compare  # noqa: E402  (bench/mitsuba/compare.py)


def main():
    scene_path, prefix, size, seed, threads, spps = sys.argv[1:7]
    size, seed, threads = int(size), int(seed), int(threads)
    spps = [int(s) for s in spps.split(",")]
    import drjit as dr
    import mitsuba as mi

    mi.set_variant("llvm_ad_rgb")
    dr.set_thread_count(threads)
    overrides = dict(width=size, height=size, spp=1, max_bounces=None, seed=seed,
                     integrator=None, medium_channel=None)
    try:
        scene_dict, _ = compare.convert_scene(scene_path, overrides)
    except compare.ConversionError as e:
        sys.exit(f"mitsuba_worker: {e}")
    scene = mi.load_dict(scene_dict)
    image = mi.render(scene, seed=seed + 7919, spp=1)  # warm-up, not timed
    dr.eval(image)
    dr.sync_thread()
    for spp in spps:
        load = os.getloadavg()[0]
        t0, c0 = time.perf_counter(), time.process_time()
        image = mi.render(scene, seed=seed, spp=spp)
        dr.eval(image)
        dr.sync_thread()
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        out = f"{prefix}-{spp}.exr"
        mi.Bitmap(image).write(out)
        print("TTQ " + json.dumps(dict(spp=spp, wall=wall, cpu=cpu, load=load, exr=out)),
              flush=True)


if __name__ == "__main__":
    main()
