"""glint from Python: load scenes (files, TOML text or dictionaries), render them to NumPy
arrays on the GPU or the CPU reference, write and compare images.

    import glint
    scene = glint.load("scenes/cornell.toml")
    img = glint.render(scene, spp=64)                 # float32 array, H×W×3, linear radiance
    glint.write("out.png", img, tonemap="agx")

Everything is done by the same Rust crate as the `glint` command: scenes are validated and
rendered by the CLI's code, with its messages, and a CPU render equals the CLI's bit for bit.
"""

import os as _os
import tempfile as _tempfile

import numpy as _np

from . import _glint
from ._glint import Scene, SceneError, load, load_string

__all__ = [
    "Scene",
    "SceneError",
    "RenderResult",
    "load",
    "load_string",
    "load_dict",
    "render",
    "write",
    "read",
    "compare",
]

AOV_NAMES = ("albedo", "normal", "depth")


def _array(data, height, width):
    """A writable H×W×3 float32 array over the bytes the extension returned."""
    return _np.frombuffer(data, dtype=_np.float32).reshape(height, width, 3)


def _pack(image, what):
    """(bytes, height, width) of an H×W×3 image, as the extension takes it."""
    array = _np.asarray(image, dtype=_np.float32)
    if array.ndim != 3 or array.shape[2] != 3:
        raise ValueError(f"{what}: expected an H×W×3 array, got shape {array.shape}")
    height, width = array.shape[:2]
    if height == 0 or width == 0:
        raise ValueError(f"{what}: the image is empty (shape {array.shape})")
    return _np.ascontiguousarray(array).tobytes(), height, width


def _write_ply(path, vertices, indices, at):
    """A binary PLY of the mesh given as arrays, in the layout of scenes/models/bunny.ply."""
    vertices = _np.asarray(vertices, dtype=_np.float32)
    indices = _np.asarray(indices)
    if vertices.ndim != 2 or vertices.shape[1] != 3:
        raise ValueError(f"{at}.vertices: expected an N×3 array, got shape {vertices.shape}")
    if indices.ndim != 2 or indices.shape[1] != 3 or indices.dtype.kind not in "iu":
        raise ValueError(
            f"{at}.indices: expected an M×3 integer array, got shape {indices.shape} of {indices.dtype}"
        )
    if indices.size and (indices.min() < 0 or indices.max() >= len(vertices)):
        raise ValueError(
            f"{at}.indices: {indices.min()}..{indices.max()} is out of range for {len(vertices)} vertices"
        )
    faces = _np.empty(len(indices), dtype=[("count", "u1"), ("index", "<i4", (3,))])
    faces["count"] = 3
    faces["index"] = indices
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"element vertex {len(vertices)}\nproperty float x\nproperty float y\nproperty float z\n"
        f"element face {len(indices)}\nproperty list uchar int vertex_indices\nend_header\n"
    )
    with open(path, "wb") as f:
        f.write(header.encode())
        f.write(vertices.astype("<f4").tobytes())
        f.write(faces.tobytes())


def load_dict(scene, path="<dict>"):
    """load_dict(scene, path="<dict>") -> Scene

    A scene given as the TOML file's structure in Python: a dict of tables (camera, render,
    materials, ...), lists for arrays (of tables too), and str, int, float and bool values;
    NumPy arrays and scalars count as lists and numbers. It is written out as TOML and read by
    glint's own parser, so it is checked as a file is: a bad scene raises glint.SceneError
    with the CLI's message (its line numbers are those of the TOML text). `path` names the
    scene in messages and gives it its name; relative mesh and texture files are found from
    its folder.

    A mesh may give `vertices` (N×3) and `indices` (M×3, one triangle a row) as arrays in
    place of `file`: they are read as a PLY file with those triangles would be.
    """
    meshes = scene.get("meshes") if isinstance(scene, dict) else None
    inline = isinstance(meshes, (list, tuple)) and any(
        isinstance(m, dict) and ("vertices" in m or "indices" in m) for m in meshes
    )
    if not inline:
        return _glint.load_dict(scene, path)
    with _tempfile.TemporaryDirectory(prefix="glint-meshes-") as folder:
        written = []
        for i, mesh in enumerate(meshes):
            at = f"scene.meshes[{i}]"
            if not (isinstance(mesh, dict) and ("vertices" in mesh or "indices" in mesh)):
                written.append(mesh)
                continue
            if "file" in mesh:
                raise ValueError(f"{at}: give file, or vertices and indices, not both")
            if "vertices" not in mesh or "indices" not in mesh:
                raise ValueError(f"{at}: vertices and indices go together")
            file = _os.path.join(folder, f"mesh{i}.ply")
            _write_ply(file, mesh["vertices"], mesh["indices"], at)
            rest = {k: v for k, v in mesh.items() if k not in ("vertices", "indices")}
            written.append({"file": file, **rest})
        # glint reads the mesh files while loading, so they can go afterwards.
        return _glint.load_dict({**scene, "meshes": written}, path)


def _on_off(value):
    if value is None or isinstance(value, bool):
        return value
    if value in ("on", "off"):
        return value == "on"
    raise ValueError(f"light_sampling: expected True, False, 'on' or 'off', got {value!r}")


class RenderResult:
    """What `render` returns when asked for more than the image.

    image     H×W×3 float32, the mean radiance per pixel
    variance  H×W×3 float32, the variance of each pixel's mean (σ²/n), or None
    albedo, normal, depth   H×W×3 float32 AOVs, or None where not asked for
    stats     dict: spp, seconds (rendering only), wall_seconds, stopped_by ("spp",
              "time-limit" or "interrupted"), relative_error, device, backend, ...
    """

    def __init__(self, image, variance, albedo, normal, depth, stats):
        self.image = image
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


def render(
    scene,
    *,
    spp=None,
    width=None,
    height=None,
    max_bounces=None,
    seed=None,
    light_sampling=None,
    device="auto",
    variance=False,
    aovs=(),
    denoise=False,
    time_limit=None,
    progress=False,
    full=False,
):
    """Renders `scene` and returns its image: a float32 NumPy array, H×W×3, linear radiance.

    The keyword arguments are `glint render`'s overrides, with the same meanings: spp,
    width, height, max_bounces, seed, light_sampling (True/False or "on"/"off"); None keeps
    the scene's value. device is "auto" (the GPU if there is one, else the CPU reference),
    "gpu" (or a RuntimeError) or "cpu". time_limit (seconds) stops at the first batch
    boundary after it; progress prints the sample count on stderr.

    With variance=True, aovs (a tuple of "albedo", "normal", "depth") or full=True, the result
    is a RenderResult (.image, .variance, .albedo, .normal, .depth, .stats) instead.

    The GIL is released while rendering, so other threads run (and may render too). Ctrl-C
    stops the render at the next batch boundary (about 0.25 s) and returns the samples done so
    far, with stats["stopped_by"] == "interrupted". The GPU device is opened once per
    process, and a scene's GPU renderer is kept for its next render with the same settings.

    A CPU render equals `glint render --cpu -o out.exr` with the same settings bit for bit.
    Bad arguments raise ValueError; a scene the settings make invalid, glint.SceneError.
    """
    if not isinstance(scene, Scene):
        raise ValueError(f"scene: expected a glint.Scene (from glint.load), got {type(scene).__name__}")
    if denoise:
        raise ValueError("denoise=True is not available from Python yet; use `glint render --denoise`")
    if isinstance(aovs, str):
        aovs = (aovs,)
    aovs = tuple(aovs)
    for name in aovs:
        if name not in AOV_NAMES:
            raise ValueError(f"aovs: expected names from {AOV_NAMES}, got {name!r}")
    raw = _glint.render(
        scene,
        spp=spp,
        width=width,
        height=height,
        max_bounces=max_bounces,
        seed=seed,
        light_sampling=_on_off(light_sampling),
        device=device,
        variance=bool(variance),
        aovs=bool(aovs),
        time_limit=None if time_limit is None else float(time_limit),
        progress=bool(progress),
    )
    stats = raw["stats"]
    h, w = stats["height"], stats["width"]
    image = _array(raw["image"], h, w)
    if not (variance or aovs or full):
        return image

    def optional(key, wanted):
        return _array(raw[key], h, w) if wanted and raw.get(key) is not None else None

    return RenderResult(
        image,
        optional("variance", variance),
        optional("albedo", "albedo" in aovs),
        optional("normal", "normal" in aovs),
        optional("depth", "depth" in aovs),
        stats,
    )


def write(path, image, *, tonemap="clamp", exposure=0.0):
    """Writes an H×W×3 linear image: .exr as float32 radiance, .png through the display
    transform (exposure in stops, then tonemap "clamp", "aces" or "agx", then sRGB), as
    `glint render -o` writes them. The write is atomic."""
    data, height, width = _pack(image, "image")
    _glint.write(str(path), data, height, width, tonemap=tonemap, exposure=float(exposure))


def read(path):
    """Reads a linear .exr (as `glint render -o out.exr` writes it) as an H×W×3 float32 array."""
    data, height, width = _glint.read(str(path))
    return _array(data, height, width)


def compare(a, b, *, variance_a=None, variance_b=None):
    """Compares image a against the reference b, with `glint compare`'s figures: a dict of
    rmse, relative_mse, mean_a, mean_b, max_difference, nonfinite_a, nonfinite_b and, given
    both variance images (σ²/n, as render(variance=True) returns them), z_test (pass_rate,
    tested, alpha, z_of_means, variance_ratio)."""
    pack_opt = lambda v, what: None if v is None else _pack(v, what)  # noqa: E731
    return _glint.compare(
        _pack(a, "a"),
        _pack(b, "b"),
        pack_opt(variance_a, "variance_a"),
        pack_opt(variance_b, "variance_b"),
    )
