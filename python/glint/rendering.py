"""glint.render and what it returns."""

from . import _glint
from .scene import Scene

AOV_NAMES = ("albedo", "normal", "depth")


class RenderResult:
    """What `render` returns when asked for more than the image.

    image     H×W×3 float32, the mean radiance per pixel (denoised, with denoise=True)
    raw       with denoise=True: the mean radiance before denoising; else None
    variance  H×W×3 float32, the variance of each pixel's mean (σ²/n; bdpt's from batch means), or None
    albedo, normal, depth   H×W×3 float32 AOVs, or None where not asked for
    stats     dict: spp, seconds (rendering only), wall_seconds (the whole call),
              stopped_by ("spp", "time-limit" or "interrupted"), relative_error, device,
              backend, kernel_reused (a GPU render that reused the scene's compiled kernel),
              denoise_seconds, ...
    """

    __slots__ = ("image", "raw", "variance", "albedo", "normal", "depth", "stats")

    def __init__(self, image, raw, variance, albedo, normal, depth, stats):
        self.image = image
        self.raw = raw
        self.variance = variance
        self.albedo = albedo
        self.normal = normal
        self.depth = depth
        self.stats = stats

    def __repr__(self):
        s = self.stats
        return (
            f"<glint.RenderResult {s['width']}×{s['height']}, {s['spp']} spp on "
            f"{s['device']}, stopped by {s['stopped_by']}>"
        )


def _on_off(value):
    if value is None or isinstance(value, bool):
        return value
    if value in ("on", "off"):
        return value == "on"
    raise ValueError(f"light_sampling: expected True, False, 'on' or 'off', got {value!r}")


def _integer(name, value):
    """An override as an int; a float or string is a ValueError, as a bad flag is the CLI's."""
    if value is None:
        return None
    try:
        return int(value.__index__())
    except (AttributeError, TypeError):
        raise ValueError(f"{name}: expected an integer, got {value!r}") from None


def render(
    scene,
    *,
    spp=None,
    width=None,
    height=None,
    max_bounces=None,
    seed=None,
    light_sampling=None,
    sampler=None,
    integrator=None,
    light_sampler=None,
    device="auto",
    traversal="auto",
    variance=False,
    aovs=(),
    denoise=False,
    time_limit=None,
    progress=False,
    full=False,
):
    """Renders `scene` and returns its image: a float32 NumPy array, H×W×3, linear radiance.

    The keyword arguments are `glint render`'s overrides, with the same names and meanings:
    spp, width, height, max_bounces, seed, light_sampling (True/False or "on"/"off"), sampler
    ("independent" or "sobol"), integrator ("path" or "bdpt"), light_sampler ("tree" or "power");
    None keeps the scene's value.
    device is "auto" (the GPU if there is one, else the CPU reference; bdpt renders on the CPU
    reference, as `glint render` does without --gpu), "gpu" (or a RuntimeError) or "cpu". time_limit (seconds) stops at the first
    batch boundary after it; progress prints the sample count on stderr. denoise=True runs
    Open Image Denoise on the result as `glint render --denoise` does (a RuntimeError with
    the install step when OIDN is missing).

    With variance=True, aovs (a tuple of "albedo", "normal", "depth"), denoise=True or
    full=True, the result is a RenderResult (.image, .raw, .variance, .albedo, .normal,
    .depth, .stats) instead.

    The GIL is released while rendering, so other threads run (and may render too). Ctrl-C
    stops the render at the next batch boundary (about 0.25 s) and returns the samples done so
    far, with stats["stopped_by"] == "interrupted". The GPU device is opened once per
    process, and a scene keeps its GPU renderer and compiled kernel for its next render,
    which reuses them unless the scene's objects, materials or image size changed.

    A CPU render equals `glint render --cpu -o out.exr` with the same settings bit for bit.
    Bad arguments raise ValueError; a scene the settings make invalid, glint.SceneError.
    """
    if not isinstance(scene, Scene):
        raise ValueError(
            f"scene: expected a glint.Scene (from glint.load), got {type(scene).__name__}"
        )
    if isinstance(aovs, str):
        aovs = (aovs,)
    aovs = tuple(aovs)
    for name in aovs:
        if name not in AOV_NAMES:
            raise ValueError(f"aovs: expected names from {AOV_NAMES}, got {name!r}")
    if time_limit is not None:
        try:
            time_limit = float(time_limit)
        except (TypeError, ValueError):
            raise ValueError(f"time_limit: expected seconds, got {time_limit!r}") from None
    raw = _glint.render(
        scene._compiled,
        spp=_integer("spp", spp),
        width=_integer("width", width),
        height=_integer("height", height),
        max_bounces=_integer("max_bounces", max_bounces),
        seed=_integer("seed", seed),
        light_sampling=_on_off(light_sampling),
        sampler=sampler,
        integrator=integrator,
        light_sampler=light_sampler,
        device=device,
        traversal=traversal,
        variance=bool(variance),
        aovs=bool(aovs),
        denoise=bool(denoise),
        time_limit=time_limit,
        progress=bool(progress),
    )
    if not (variance or aovs or denoise or full):
        return raw["image"]
    return RenderResult(
        raw["image"],
        raw["raw"],
        raw["variance"] if variance else None,
        raw.get("albedo") if "albedo" in aovs else None,
        raw.get("normal") if "normal" in aovs else None,
        raw.get("depth") if "depth" in aovs else None,
        raw["stats"],
    )
