"""Renders release the GIL, run in threads at once, and stop on Ctrl-C with what they have."""

import json
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import glint

SETTINGS = dict(width=16, height=12, spp=6, max_bounces=4, device="cpu")
SMALL = dict(width=16, height=12, max_bounces=4, device="cpu")


def test_two_threads_rendering_at_once_give_the_sequential_images(cornell):
    scene = glint.load(cornell)
    expected = [glint.render(scene, seed=seed, **SETTINGS) for seed in (1, 2)]
    results = [None, None]
    # Both wait here, so their renders overlap: each holds no GIL while it renders.
    barrier = threading.Barrier(2)

    def work(i):
        barrier.wait()
        results[i] = glint.render(scene, seed=i + 1, **SETTINGS)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=120)
    for got, want in zip(results, expected):
        assert got is not None and np.array_equal(got, want)


def test_two_threads_rendering_on_the_gpu_at_once(cornell):
    """Two scenes on the process's one GPU device at once, each with its own renderer: the
    images are those of renders one after the other."""
    gpu = {**SETTINGS, "device": "gpu"}
    scenes = [glint.load(cornell), glint.load(cornell)]
    try:
        expected = [glint.render(s, seed=i + 1, **gpu) for i, s in enumerate(scenes)]
    except RuntimeError as e:
        pytest.skip(f"no GPU: {e}")
    results = [None, None]
    barrier = threading.Barrier(2)

    def work(i):
        barrier.wait()
        for _ in range(3):
            results[i] = glint.render(scenes[i], seed=i + 1, **gpu)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=300)
    for got, want in zip(results, expected):
        assert got is not None and np.array_equal(got, want)


def test_the_gil_is_released_while_rendering(cornell):
    """The main thread keeps running Python while another thread renders for a second. Were
    the GIL held, it could only run again once the render was over: one or two ticks."""
    scene = glint.load(cornell)
    results = []
    worker = threading.Thread(
        target=lambda: results.append(
            glint.render(scene, spp=1_000_000, time_limit=1.0, full=True, **SMALL)
        )
    )
    worker.start()
    ticks = 0
    while worker.is_alive():
        ticks += 1
        time.sleep(0.001)
    assert results and results[0].stats["stopped_by"] == "time-limit"
    # About 1000 ticks of 1 ms in the second; 50 leaves room for a busy machine.
    assert ticks >= 50, ticks


# The child handles SIGINT as an interactive Python does, whatever it inherited: a shell
# without job control starts background commands with SIGINT ignored, and a Python started
# so installs no KeyboardInterrupt handler (this test then timed out under `scripts/test &`).
CHILD = r"""
import json, signal, sys, numpy as np, glint
signal.signal(signal.SIGINT, signal.default_int_handler)
scene = glint.load(sys.argv[1])
print("rendering", flush=True)
result = glint.render(scene, width=64, height=64, spp=1_000_000, device="cpu", full=True)
print(json.dumps({"stats": result.stats, "finite": bool(np.isfinite(result.image).all()),
                  "mean": float(result.image.mean())}), flush=True)
"""


def test_ctrl_c_returns_the_samples_done_so_far(cornell):
    child = subprocess.Popen(
        [sys.executable, "-c", CHILD, str(cornell)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert child.stdout.readline().strip() == "rendering"
        # Let a few batches finish: the render itself starts within milliseconds.
        threading.Event().wait(1.5)
        child.send_signal(signal.SIGINT)
        out, err = child.communicate(timeout=60)
    finally:
        child.kill()
    assert child.returncode == 0, err
    report = json.loads(out)
    stats = report["stats"]
    assert stats["stopped_by"] == "interrupted"
    assert 0 < stats["spp"] < 1_000_000
    assert stats["samples"] == [0, stats["spp"]]
    assert report["finite"] and report["mean"] > 0
