#!/usr/bin/env python3
"""Time to a relative MSE with and without adaptive sampling (`glint render --adaptive`).

For one scene: a converged reference (plain render, its own seed), then, per repetition (a
seed each), a ladder of plain renders (--spp S) and a ladder of adaptive ones (--adaptive
--target-error E --spp CAP), run interleaved (plain, adaptive, plain, ...). Each run's render
time is the JSON summary's "seconds" (batches only: no start-up, scene load or file writes);
its error is `glint compare`'s relative MSE against the reference. The time at which each
ladder reaches the goal is interpolated linearly in log(time)-log(rel. MSE) between the two
runs that bracket it; the medians over the repetitions are printed as a Markdown table,
followed by every run.

    bench/adaptive/time_to_quality.py target/release/glint scenes/caustic.toml \
        --size 128x96 --ref-spp 16384 --plain 64,128,256,512,1024 \
        --targets 0.3,0.2,0.14,0.1,0.07 --cap 4096 --reps 3 --out /tmp/tq-caustic
"""

import argparse
import json
import math
import os
import statistics
import subprocess
import sys


def run(cmd):
    out = subprocess.run(cmd, check=True, capture_output=True, text=True)
    return out.stdout


def render(args, out, extra):
    w, h = args.size.split("x")
    cmd = [args.glint, "render", args.scene, "--cpu", "--width", w, "--height", h,
           "-o", out, "--json", "--checkpoint-interval", "1e6"] + extra
    return json.loads(run(cmd))


def rel_mse(args, image, reference):
    return json.loads(run([args.glint, "compare", image, reference, "--json"]))["relative_mse"]


def time_at(points, goal):
    """points: (seconds, rel_mse) sorted by seconds; the time where rel. MSE crosses goal."""
    for (t0, e0), (t1, e1) in zip(points, points[1:]):
        if e0 > goal >= e1:
            f = (math.log(goal) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(t0) + f * (math.log(t1) - math.log(t0)))
    return None


def main():
    p = argparse.ArgumentParser()
    p.add_argument("glint")
    p.add_argument("scene")
    p.add_argument("--size", default="128x128")
    p.add_argument("--ref-spp", type=int, default=16384)
    p.add_argument("--plain", default="32,64,128,256,512")
    p.add_argument("--targets", default="0.3,0.2,0.14,0.1,0.07")
    p.add_argument("--cap", type=int, default=4096)
    p.add_argument("--min-spp", type=int, default=16)
    p.add_argument("--reps", type=int, default=3)
    p.add_argument("--goals", default="1e-2")
    p.add_argument("--out", required=True)
    args = p.parse_args()
    os.makedirs(args.out, exist_ok=True)
    reference = os.path.join(args.out, "reference.exr")
    if not os.path.exists(reference):
        r = render(args, reference, ["--spp", str(args.ref_spp), "--seed", "1000"])
        print(f"reference: {args.ref_spp} spp in {r['seconds']:.1f} s", file=sys.stderr)
    plain = [int(s) for s in args.plain.split(",")]
    targets = [float(t) for t in args.targets.split(",")]
    runs = []
    for rep in range(args.reps):
        seed = str(rep + 1)
        for i in range(max(len(plain), len(targets))):
            jobs = []
            if i < len(plain):
                jobs.append(("plain", f"--spp {plain[i]}", ["--spp", str(plain[i])]))
            if i < len(targets):
                jobs.append(("adaptive", f"E {targets[i]}",
                             ["--spp", str(args.cap), "--adaptive", "--target-error",
                              str(targets[i]), "--adaptive-min-spp", str(args.min_spp)]))
            for method, setting, extra in jobs:
                out = os.path.join(args.out, f"{method}-{rep}-{i}.exr")
                r = render(args, out, extra + ["--seed", seed])
                e = rel_mse(args, out, reference)
                mean_spp = r["adaptive"]["mean_spp"] if r.get("adaptive") else r["spp"]
                runs.append(dict(rep=rep, method=method, setting=setting, seconds=r["seconds"],
                                 mean_spp=mean_spp, rel_mse=e))
                print(f"rep {rep} {method:8} {setting:10} {r['seconds']:8.2f} s "
                      f"{mean_spp:8.1f} spp  rel. MSE {e:.4g}", file=sys.stderr)
    print(f"| {args.scene} {args.size} | plain | adaptive | adaptive / plain |")
    print("|---|---|---|---|")
    for goal in [float(g) for g in args.goals.split(",")]:
        times = {"plain": [], "adaptive": []}
        for rep in range(args.reps):
            for method in times:
                pts = sorted((r["seconds"], r["rel_mse"]) for r in runs
                             if r["rep"] == rep and r["method"] == method)
                times[method].append(time_at(pts, goal))
        med = {m: statistics.median([t for t in ts if t is not None] or [float("nan")])
               for m, ts in times.items()}
        per_rep = [f"{a / b:.2f}" if a and b else "n/a"
                   for a, b in zip(times["adaptive"], times["plain"])]
        print(f"| seconds to rel. MSE {goal:g} (median of {args.reps}) | {med['plain']:.2f} | "
              f"{med['adaptive']:.2f} | {med['adaptive'] / med['plain']:.2f} (per repetition: "
              f"{', '.join(per_rep)}) |")
    print()
    print("| rep | method | setting | seconds | mean spp | rel. MSE |")
    print("|---|---|---|---|---|---|")
    for r in runs:
        print(f"| {r['rep']} | {r['method']} | {r['setting']} | {r['seconds']:.2f} | "
              f"{r['mean_spp']:.1f} | {r['rel_mse']:.4g} |")


if __name__ == "__main__":
    main()
