"""What the bidirectional benchmarks share: reading an EXR, rendering once on the CPU reference
(or, with GLINT_DEVICE=gpu, the GPU kernel) with its CPU seconds kept beside the image, and the
relative MSE."""
import os, resource, subprocess
import numpy as np
import OpenEXR, Imath

GLINT = os.environ.get("GLINT", "target/release/glint")
# "cpu" (the CPU reference) or "gpu" (the kernel; on lavapipe its threads are this process's
# children too, so CPU seconds count them).
DEVICE = os.environ.get("GLINT_DEVICE", "cpu")


def load(path):
    f = OpenEXR.InputFile(path)
    dw = f.header()["dataWindow"]
    w, h = dw.max.x - dw.min.x + 1, dw.max.y - dw.min.y + 1
    pt = Imath.PixelType(Imath.PixelType.FLOAT)
    return np.stack([np.frombuffer(f.channel(c, pt), np.float32).reshape(h, w) for c in "RGB"], -1)


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


def rel_mse(img, ref, box=None):
    """Mean of (img − ref)² / (ref² + 0.01) over the image, or over box = (x0, y0, x1, y1)."""
    if box:
        x0, y0, x1, y1 = box
        img, ref = img[y0:y1, x0:x1], ref[y0:y1, x0:x1]
    return float(np.mean((img - ref) ** 2 / (ref ** 2 + 1e-2)))
