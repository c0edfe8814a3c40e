"""What the bidirectional benchmarks share: reading an EXR, rendering once on the CPU reference
(or, with GLINT_DEVICE=gpu, the GPU kernel) with its CPU seconds kept beside the image, and the
relative MSE."""
import os, resource, subprocess, sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
from exr import read_rgb as load, rel_mse  # noqa: E402,F401 (the benchmarks import them from here)

GLINT = os.environ.get("GLINT", "target/release/glint")
# "cpu" (the CPU reference) or "gpu" (the kernel; on lavapipe its threads are this process's
# children too, so CPU seconds count them).
DEVICE = os.environ.get("GLINT_DEVICE", "cpu")


def render(scene, w, h, spp, integrator, seed, out, device=None):
    """Renders once on `device` (default DEVICE) and returns its CPU seconds (user + system, so
    that a busy machine does not skew it). The seconds are kept beside the image, so that
    regions can be changed and the errors measured again without rendering."""
    device = device or DEVICE
    if os.path.exists(out + ".seconds"):
        return float(open(out + ".seconds").read())
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run([GLINT, "render", scene, "--" + device, "--width", str(w), "--height", str(h),
                    "--spp", str(spp), "--seed", str(seed), "--integrator", integrator,
                    "-o", out], check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    seconds = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    open(out + ".seconds", "w").write(str(seconds))
    return seconds

