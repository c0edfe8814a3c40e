# Figures for bench/rough-glass/README.md: each render's RMSE against the reference (the
# reference's own noise, √(mean of its variance image), printed beside it), and for
# spheres.toml the mean of each sphere, roughness 0.3, 0.6 and 1 (pixels whose centre lies within 0.9 of the sphere's
# projected radius, so no edge pixel mixes in the background).
# Usage: measure.py REFERENCE.exr REFERENCE-VARIANCE.exr [spheres] RENDER.exr ...
# Needs: pip install OpenEXR numpy
import sys, math, numpy as np, OpenEXR

def read(path):
    ch = OpenEXR.File(path).channels()
    if "RGB" in ch or "RGBA" in ch:
        return np.asarray(ch.get("RGB", ch.get("RGBA")).pixels, dtype=np.float64)[..., :3]
    return np.stack([np.asarray(ch[c].pixels, dtype=np.float64) for c in "RGB"], axis=-1)

def sphere_masks(h, w):
    # spheres.toml: the eye 9 in front, vfov 26°, spheres of radius 1 at x = −2.2, 0, 2.2. In
    # pixels, a centre projects to w/2 − x · px (the camera looks along +z, so +x is on the
    # left) and the silhouette's radius is about px · 9/√80
    # (its angular radius is asin(1/9) head on; off the axis it is a slightly larger ellipse).
    px = (h / 2) / (9.0 * math.tan(math.radians(13.0)))
    radius = 0.9 * px * 9.0 / math.sqrt(80.0)
    ys, xs = np.mgrid[0:h, 0:w]
    return [
        (xs + 0.5 - (w / 2 - cx * px)) ** 2 + (ys + 0.5 - h / 2) ** 2 < radius**2
        for cx in (-2.2, 0.0, 2.2)
    ]

ref, ref_var = read(sys.argv[1]), read(sys.argv[2])
args = sys.argv[3:]
spheres = bool(args) and args[0] == "spheres"
if spheres:
    args = args[1:]
print(f"reference noise (RMS of its standard errors) {math.sqrt(ref_var.mean()):.5f}")
if spheres:
    noise = [math.sqrt(ref_var[m].mean()) for m in sphere_masks(*ref.shape[:2])]
    print("reference noise per sphere " + " ".join(f"{e:.4f}" for e in noise))
masks = sphere_masks(*ref.shape[:2]) if spheres else []
def variance_of(path):
    # render --variance writes X-var.exr beside X.exr in these measurements.
    try:
        return read(path.replace(".exr", "-var.exr"))
    except Exception:
        return None

for name, image, variance in [("reference", ref, ref_var)] + [
    (p, read(p), variance_of(p)) for p in args
]:
    rmse = math.sqrt(((image - ref) ** 2).mean()) if image is not ref else 0.0
    line = f"{name}: RMSE {rmse:.5f}, mean {image.mean():.5f}"
    if spheres:
        means = [image[m].mean(axis=0) for m in masks]
        if variance is not None:
            # The standard error of each sphere's mean, from its variance image.
            sigma = [math.sqrt(variance[m].sum(axis=0).mean()) / m.sum() for m in masks]
            line += ", their standard errors " + " ".join(f"{e:.4f}" for e in sigma)
        line += ", sphere means (RGB) " + "; ".join(" ".join(f"{v:.4f}" for v in mm) for mm in means)
        errors = [math.sqrt(((image[m] - ref[m]) ** 2).mean()) for m in masks]
        line += ", sphere RMSE " + " ".join(f"{e:.4f}" for e in errors)
    print(line)
