"""The Python call against the CLI on the same render, and a scene's second render.

    python bench/python/overhead.py [--runs N] [--device cpu|gpu] [--glint target/release/glint]

A: `glint render SCENE --cpu|--gpu ... -o out.exr` as a process (wall time).
B: `python -c "import glint; glint.render(glint.load(SCENE), ...)"` as a process (wall time):
   the same render, the same output kept in memory instead of written.
Interleaved A, B, A, B, ... on a noisy shared machine; medians and their ratio.
Then, in this process: a scene's first render (device opened, kernel compiled) and its second
(kernel reused), each one's wall time and rendering time (stats["seconds"]), medians over
fresh scenes.
"""

import argparse
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

import glint

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCENE = ROOT / "scenes" / "cornell.toml"
SETTINGS = dict(width=128, height=128, spp=16, seed=1)


def timed(command):
    started = time.perf_counter()
    subprocess.run(command, check=True, capture_output=True)
    return time.perf_counter() - started


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--runs", type=int, default=7)
    parser.add_argument("--device", choices=("cpu", "gpu"), default="cpu")
    parser.add_argument("--glint", default=str(ROOT / "target" / "release" / "glint"))
    args = parser.parse_args()

    out = pathlib.Path(tempfile.mkdtemp()) / "out.exr"
    flags = [f"--{k.replace('_', '-')}={v}" for k, v in SETTINGS.items()]
    cli = [args.glint, "render", str(SCENE), f"--{args.device}", *flags, "-o", str(out)]
    py = [
        sys.executable,
        "-c",
        "import glint; glint.render(glint.load(%r), device=%r, **%r)"
        % (str(SCENE), args.device, SETTINGS),
    ]
    timed(cli), timed(py)  # warm-up: file caches, Mesa's shader cache
    a, b = [], []
    for _ in range(args.runs):
        a.append(timed(cli))
        b.append(timed(py))
    ma, mb = statistics.median(a), statistics.median(b)
    print(f"{args.device}: CLI process {ma:.3f} s, Python process {mb:.3f} s (medians of {args.runs}), "
          f"Python/CLI {mb / ma:.2f}, difference {mb - ma:+.3f} s")
    print("  CLI:   ", " ".join(f"{t:.3f}" for t in a))
    print("  Python:", " ".join(f"{t:.3f}" for t in b))
    # Where the difference goes: starting Python and importing NumPy and glint.
    starts = {"python -c pass": [], "import numpy": [], "import glint": []}
    for _ in range(args.runs):
        for name, code in zip(starts, ("pass", "import numpy", "import glint")):
            starts[name].append(timed([sys.executable, "-c", code]))
    print("  start-up medians:", ", ".join(f"{k} {statistics.median(v):.3f} s" for k, v in starts.items()))

    firsts, seconds = [], []
    for _ in range(args.runs):
        scene = glint.load(SCENE)
        r1 = glint.render(scene, device=args.device, full=True, **SETTINGS)
        r2 = glint.render(scene, device=args.device, full=True, **{**SETTINGS, "seed": 2})
        firsts.append((r1.stats["wall_seconds"], r1.stats["seconds"]))
        seconds.append((r2.stats["wall_seconds"], r2.stats["seconds"], r2.stats["kernel_reused"]))
    med = lambda xs, i: statistics.median(x[i] for x in xs)  # noqa: E731
    print(f"{args.device}: first render of a scene: wall {med(firsts, 0):.3f} s, rendering {med(firsts, 1):.3f} s; "
          f"second: wall {med(seconds, 0):.3f} s, rendering {med(seconds, 1):.3f} s "
          f"(kernel reused: {all(s[2] for s in seconds)}); medians of {args.runs} fresh scenes "
          f"(the process's first scene opens the device)")
    print(f"  the call's own overhead (wall - rendering), medians: first {statistics.median(w - r for w, r in firsts) * 1e3:.1f} ms, "
          f"second {statistics.median(w - r for w, r, _ in seconds) * 1e3:.1f} ms")
    print("  first: ", " ".join(f"{w:.3f}/{s:.3f}" for w, s in firsts))
    print("  second:", " ".join(f"{w:.3f}/{s:.3f}" for w, s, _ in seconds))


if __name__ == "__main__":
    main()
