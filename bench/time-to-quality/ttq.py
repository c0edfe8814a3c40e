#!/usr/bin/env python3
"""Time to a relative MSE of 10^-2: glint (CPU reference, lavapipe), Cycles 4.5, Mitsuba 3.

For each scene and renderer: a reference from that same renderer (REF spp, seed 1000), then
ROUNDS rounds, interleaved (round r renders every scene with every renderer before round r+1
starts), each a ladder of renders at 1 and LADDER spp (seed r+1). Per render: wall seconds and
process CPU seconds (user + sys, all threads): for glint, of the whole process (getrusage of the
child); for Cycles and Mitsuba, of the render call inside one process per ladder (after scene
load; Mitsuba after an untimed warm-up render). The 1-spp render is subtracted from the largest
one, which leaves seconds per sample without start-up, scene upload, BVH builds, shader or JIT
compilation. Error: relative MSE = mean over pixels and RGB channels of (x - ref)^2 / (ref^2 +
0.01), as `glint compare` computes it. relMSE(n) = a/n + b is fitted to each round's ladder
(least squares on the relative residuals; b is the reference's own error, which is removed);
spp needed = a / GOAL; seconds to GOAL = spp needed x seconds per sample. The table is the
median over the rounds. Every run is kept in OUT/runs.jsonl; the report is Markdown on stdout.
A reference already in OUT (SCENE-RENDERER-ref-SPP.exr) is reused. Renderers: glint-cpu,
glint-lavapipe (glint --gpu), cycles, mitsuba, and glint-cpu-sobol (--sampler sobol).

    bench/time-to-quality/ttq.py --glint target/release/glint --out /tmp/ttq \
        --scenes scenes/cornell.toml,scenes/bunny.toml,scenes/helmet.toml
"""

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
from exr import read_rgb as read_exr, rel_mse  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
RENDERERS = ["glint-cpu", "glint-lavapipe", "cycles", "mitsuba"]


def children_cpu():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def glint_ladder(args, device, scene, prefix, seed, spps, extra=()):
    runs = []
    for spp in spps:
        out = f"{prefix}-{spp}.exr"
        cmd = [args.glint, "render", scene, f"--{device}", "--spp", str(spp), "--width",
               str(args.size), "--height", str(args.size), "--seed", str(seed), "-o", out,
               "--json", *extra]
        load = os.getloadavg()[0]
        t0, c0 = time.perf_counter(), children_cpu()
        p = subprocess.run(cmd, check=True, capture_output=True, text=True)
        wall, cpu = time.perf_counter() - t0, children_cpu() - c0
        summary = json.loads(p.stdout)
        runs.append(dict(spp=spp, wall=wall, cpu=cpu, load=load, exr=out,
                         render_seconds=summary["seconds"], backend=summary["device"]))
    return runs


def worker_ladder(args, worker, scene, prefix, seed, spps):
    python = args.bpy_python if worker == "cycles" else sys.executable
    script = os.path.join(HERE, f"{worker}_worker.py")
    cmd = [python, script, scene, prefix, str(args.size), str(seed), str(args.threads),
           ",".join(map(str, spps))]
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(p.stderr.strip().splitlines()[-1] if p.stderr.strip() else "failed")
    return [json.loads(line[4:]) for line in p.stdout.splitlines() if line.startswith("TTQ ")]


def ladder(args, renderer, scene, prefix, seed, spps):
    if renderer == "glint-cpu":
        return glint_ladder(args, "cpu", scene, prefix, seed, spps)
    if renderer == "glint-cpu-sobol":  # not in the default set: --sampler sobol
        return glint_ladder(args, "cpu", scene, prefix, seed, spps, ["--sampler", "sobol"])
    if renderer == "glint-lavapipe":
        return glint_ladder(args, "gpu", scene, prefix, seed, spps)
    return worker_ladder(args, renderer, scene, prefix, seed, spps)


def fit(points):
    """a, b of relMSE = a/n + b, least squares on relative residuals."""
    n = np.array([p[0] for p in points], dtype=float)
    e = np.array([p[1] for p in points], dtype=float)
    A = np.stack([1 / (n * e), 1 / e], axis=1)
    (a, b), *_ = np.linalg.lstsq(A, np.ones_like(e), rcond=None)
    return float(a), float(b)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--glint", required=True)
    p.add_argument("--bpy-python", default="/tmp/bpyenv/bin/python")
    p.add_argument("--scenes", required=True, help="comma-separated glint scene files")
    p.add_argument("--renderers", default=",".join(RENDERERS))
    p.add_argument("--size", type=int, default=128)
    p.add_argument("--ref-spp", type=int, default=512)
    p.add_argument("--ladder", default="4,16,64")
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--threads", type=int, default=2, help="Cycles' and Mitsuba's threads")
    p.add_argument("--goal", type=float, default=1e-2)
    p.add_argument("--out", required=True)
    args = p.parse_args()
    os.makedirs(args.out, exist_ok=True)
    scenes = args.scenes.split(",")
    renderers = args.renderers.split(",")
    ladder_spp = [int(s) for s in args.ladder.split(",")]
    log = open(os.path.join(args.out, "runs.jsonl"), "a")

    def note(record):
        log.write(json.dumps(record) + "\n")
        log.flush()
        print(json.dumps(record), file=sys.stderr, flush=True)

    refs, skipped = {}, {}
    for scene in scenes:
        name = os.path.splitext(os.path.basename(scene))[0]
        for r in renderers:
            prefix = os.path.join(args.out, f"{name}-{r}-ref")
            kept = f"{prefix}-{args.ref_spp}.exr"
            if os.path.exists(kept):  # a reference from an earlier run into the same OUT
                refs[(name, r)] = read_exr(kept)
                note(dict(scene=name, renderer=r, reference=True, kept=kept))
                continue
            try:
                runs = ladder(args, r, scene, prefix, 1000, [args.ref_spp])
            except (RuntimeError, subprocess.CalledProcessError) as e:
                skipped[(name, r)] = str(e)
                note(dict(scene=name, renderer=r, skipped=str(e)))
                continue
            refs[(name, r)] = read_exr(runs[-1]["exr"])
            note(dict(scene=name, renderer=r, reference=True, **runs[-1],
                      mean=refs[(name, r)].mean(axis=(0, 1)).tolist()))
    results = []
    for rnd in range(args.rounds):
        for scene in scenes:
            name = os.path.splitext(os.path.basename(scene))[0]
            for r in renderers:
                if (name, r) not in refs:
                    continue
                prefix = os.path.join(args.out, f"{name}-{r}-r{rnd}")
                runs = ladder(args, r, scene, prefix, rnd + 1, [1] + ladder_spp)
                for run in runs:
                    run["rel_mse"] = rel_mse(read_exr(run["exr"]), refs[(name, r)])
                one, top = runs[0], runs[-1]
                a, b = fit([(x["spp"], x["rel_mse"]) for x in runs[1:]])
                per_spp_wall = (top["wall"] - one["wall"]) / (top["spp"] - 1)
                per_spp_cpu = (top["cpu"] - one["cpu"]) / (top["spp"] - 1)
                spp_needed = a / args.goal
                rec = dict(scene=name, renderer=r, round=rnd, runs=runs, a=a, b=b,
                           spp_needed=spp_needed, per_spp_wall=per_spp_wall,
                           per_spp_cpu=per_spp_cpu, wall_to_goal=spp_needed * per_spp_wall,
                           cpu_to_goal=spp_needed * per_spp_cpu,
                           load=statistics.mean(x["load"] for x in runs))
                results.append(rec)
                note(rec)
    report(args, scenes, renderers, results, skipped)


def report(args, scenes, renderers, results, skipped):
    med = statistics.median
    print(f"Seconds to relative MSE {args.goal:g}, {args.size}x{args.size}, median of "
          f"{args.rounds} rounds (wall / CPU seconds)\n")
    print("| scene | " + " | ".join(renderers) + " |")
    print("|---|" + "---|" * len(renderers))
    for scene in scenes:
        name = os.path.splitext(os.path.basename(scene))[0]
        cells = []
        for r in renderers:
            rs = [x for x in results if x["scene"] == name and x["renderer"] == r]
            if not rs:
                cells.append("skipped")
                continue
            cells.append(f"{med(x['wall_to_goal'] for x in rs):.2f} / "
                         f"{med(x['cpu_to_goal'] for x in rs):.2f}")
        print(f"| {name} | " + " | ".join(cells) + " |")
    print("\n| scene | renderer | spp to goal | ms per spp (wall / CPU) | reference rel. MSE "
          "(a/ref spp) | load (1 min) |")
    print("|---|---|---:|---|---:|---|")
    for scene in scenes:
        name = os.path.splitext(os.path.basename(scene))[0]
        for r in renderers:
            rs = [x for x in results if x["scene"] == name and x["renderer"] == r]
            if not rs:
                continue
            print(f"| {name} | {r} | {med(x['spp_needed'] for x in rs):.0f} | "
                  f"{1e3 * med(x['per_spp_wall'] for x in rs):.1f} / "
                  f"{1e3 * med(x['per_spp_cpu'] for x in rs):.1f} | "
                  f"{med(x['a'] for x in rs) / args.ref_spp:.2g} | "
                  f"{min(x['load'] for x in rs):.1f}–{max(x['load'] for x in rs):.1f} |")
    print("\nEvery run:\n")
    print("| scene | renderer | round | spp | wall s | CPU s | load | rel. MSE |")
    print("|---|---|---|---:|---:|---:|---:|---:|")
    for x in results:
        for run in x["runs"]:
            print(f"| {x['scene']} | {x['renderer']} | {x['round']} | {run['spp']} | "
                  f"{run['wall']:.2f} | {run['cpu']:.2f} | {run['load']:.1f} | "
                  f"{run['rel_mse']:.4g} |")
    for (name, r), why in skipped.items():
        print(f"\nSkipped: {name} with {r}: {why}")


if __name__ == "__main__":
    main()
