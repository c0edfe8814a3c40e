#!/usr/bin/env python3
"""Render a glint scene TOML with Mitsuba 3 and time it, for a side-by-side with glint.

Builds the equivalent Mitsuba scene dict, renders once to warm up (JIT compilation is not
timed), then times N renders and prints one JSON line with the medians. Writes the warm-up
image as a linear float32 EXR (for `glint compare`) and optionally as an sRGB PNG; with
--variance, the mean of all the renders and the variance of that mean per pixel instead, for
glint compare's per-pixel Z-test.

See README.md in this folder for the mapping and its approximations, and run.sh for the
interleaved comparison with glint.
"""

import argparse
import cmath
import json
import math
import os
import statistics
import sys
import time
import tomllib

# Mitsuba's path integrator: depth 1 = emitters seen directly, so depth = bounces + 1.
# glint plays Russian roulette from its 4th scattering event on (bounce index >= 3, see
# ROULETTE_START_BOUNCE in src/scene/mod.rs); Mitsuba plays it once depth >= rr_depth, with
# depth counted after the event, so rr_depth = 3 + 1.
GLINT_ROULETTE_START_BOUNCE = 3
# glint's emitters emit from both sides; Mitsuba's from the front. Emitting quads and spheres
# get a back-facing twin this far behind them, relative to their size.
TWIN_OFFSET = 1e-4


class ConversionError(Exception):
    """The scene cannot be mapped onto Mitsuba; the message names the field."""


def fail(message):
    print(f"compare.py: error: {message}", file=sys.stderr)
    sys.exit(2)


def vec3(value, where):
    if not (isinstance(value, list) and len(value) == 3
            and all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in value)):
        raise ConversionError(f"{where}: expected 3 numbers, got {value!r}")
    out = [float(x) for x in value]
    if not all(math.isfinite(x) for x in out):
        raise ConversionError(f"{where}: every number must be finite, got {value!r}")
    return out


def number(value, where):
    if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value):
        raise ConversionError(f"{where}: expected a finite number, got {value!r}")
    return float(value)


def check_keys(table, allowed, where):
    unknown = sorted(set(table) - set(allowed))
    if unknown:
        raise ConversionError(f"{where}: unknown field(s) {', '.join(unknown)} "
                              "(not mapped to Mitsuba by this script)")


def sub(a, b):
    return [a[i] - b[i] for i in range(3)]


def add(a, b):
    return [a[i] + b[i] for i in range(3)]


def scale3(a, s):
    return [x * s for x in a]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def length(a):
    return math.sqrt(sum(x * x for x in a))


def matmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(4)) for j in range(4)] for i in range(4)]


def rotation(axis, degrees):
    """Right-handed rotation about a coordinate axis (x=0, y=1, z=2)."""
    c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    m = [[1.0 if r == k else 0.0 for k in range(4)] for r in range(4)]
    m[i][i], m[i][j], m[j][i], m[j][j] = c, -s, s, c
    return m


def mesh_to_world(mesh, where):
    """glint's mesh transform: scale, then rotate about x, y, z (degrees), then translate."""
    t = vec3(mesh.get("translate", [0, 0, 0]), f"{where}.translate")
    r = vec3(mesh.get("rotate", [0, 0, 0]), f"{where}.rotate")
    s = mesh.get("scale", 1.0)
    s = [number(s, f"{where}.scale")] * 3 if not isinstance(s, list) else vec3(s, f"{where}.scale")
    if min(s) <= 0:
        raise ConversionError(f"{where}.scale: must be > 0, got {mesh.get('scale')!r}")
    scale = [[s[0], 0, 0, 0], [0, s[1], 0, 0], [0, 0, s[2], 0], [0, 0, 0, 1.0]]
    translate = [[1.0, 0, 0, t[0]], [0, 1.0, 0, t[1]], [0, 0, 1.0, t[2]], [0, 0, 0, 1.0]]
    m = matmul(rotation(0, r[0]), scale)
    m = matmul(rotation(1, r[1]), m)
    m = matmul(rotation(2, r[2]), m)
    return matmul(translate, m)


def quad_to_world(corner, u, v, where):
    """Mitsuba's rectangle is [-1, 1]² in the xy plane with normal +z; map it onto
    corner + a·u + b·v, a, b in [0, 1], with the normal along u × v (as glint's)."""
    n = cross(u, v)
    area = length(n)
    if area == 0:
        raise ConversionError(f"{where}: u and v are parallel or zero (zero area)")
    n = scale3(n, 1.0 / area)
    c = add(corner, scale3(add(u, v), 0.5))
    return [[u[i] / 2, v[i] / 2, n[i], c[i]] for i in range(3)] + [[0, 0, 0, 1.0]], area


def file_has_normals(path, ext):
    """Whether an OBJ has `vn` lines, or a PLY's vertices have nx, ny, nz."""
    with open(path, "rb") as f:
        if ext == ".obj":
            return any(line.startswith(b"vn ") for line in f)
        for line in f:
            if line.strip() == b"end_header":
                return False
            if line.split()[:1] == [b"property"] and line.split()[-1:] == [b"nx"]:
                return True
    return False


def conductor_fresnel(cos_i, eta, k):
    """Unpolarised Fresnel reflectance of a conductor with IOR eta + ik, from vacuum."""
    n = complex(eta, k)
    cos_t = cmath.sqrt(1 - (1 - cos_i * cos_i) / (n * n))
    r_s = (cos_i - n * cos_t) / (cos_i + n * cos_t)
    r_p = (n * cos_i - cos_t) / (n * cos_i + cos_t)
    return (abs(r_s) ** 2 + abs(r_p) ** 2) / 2


def conductor_ior_for_schlick(f0):
    """(eta, k) whose Fresnel curve is f0 head-on and closest to Schlick's
    f0 + (1 - f0)(1 - cos)^5 elsewhere (least squares weighted by cos, over eta in
    (0, 4]; k follows from f0 and eta). Within 0.005 of Schlick for f0 >= 0.75 and 0.03
    for darker channels."""
    f0 = min(max(f0, 0.0), 0.9999)
    cosines = [(i + 0.5) / 64 for i in range(64)]
    best = (math.inf, 1.0, 0.0)
    for step in range(1, 401):
        eta = step * 0.01
        k2 = (f0 * (eta + 1) ** 2 - (eta - 1) ** 2) / (1 - f0)
        if k2 < 0:
            continue
        k = math.sqrt(k2)
        error = sum(c * (conductor_fresnel(c, eta, k) - f0 - (1 - f0) * (1 - c) ** 5) ** 2
                    for c in cosines)
        best = min(best, (error, eta, k))
    return best[1], best[2]


def rgb(value):
    return {"type": "rgb", "value": value}


def convert_material(name, m):
    """The Mitsuba BSDF for a glint material, and its emitted radiance (or None)."""
    where = f"materials.{name}"
    kind = m.get("type")
    common = ["type", "emission", "strength"]
    if kind == "diffuse":
        check_keys(m, common + ["color"], where)
        bsdf = {"type": "diffuse", "reflectance": rgb(vec3(m["color"], f"{where}.color"))}
    elif kind == "specular":
        # A perfect mirror with reflectance `color`: a conductor with no Fresnel term.
        check_keys(m, common + ["color"], where)
        bsdf = {"type": "conductor", "material": "none",
                "specular_reflectance": rgb(vec3(m["color"], f"{where}.color"))}
    elif kind == "metal":
        # glint: GGX with Schlick's Fresnel, F0 = color. Mitsuba's conductors take a complex
        # IOR: per channel, the one that gives F0 head-on and follows Schlick's curve closest.
        check_keys(m, common + ["color", "roughness"], where)
        roughness = number(m["roughness"], f"{where}.roughness")
        fits = [conductor_ior_for_schlick(f0) for f0 in vec3(m["color"], f"{where}.color")]
        bsdf = {"type": "conductor", "eta": rgb([f[0] for f in fits]),
                "k": rgb([f[1] for f in fits])}
        if roughness > 0:
            bsdf.update(type="roughconductor", distribution="ggx", alpha=roughness * roughness)
    elif kind == "interface":
        # A boundary that only separates media: light passes it unchanged (Mitsuba's null
        # BSDF, which volpath crosses without counting a scattering event).
        check_keys(m, ["type"], where)
        return {"type": "null"}, None
    elif kind == "dielectric":
        check_keys(m, common + ["ior", "color"], where)
        bsdf = {"type": "dielectric", "int_ior": number(m["ior"], f"{where}.ior"),
                "ext_ior": 1.0,
                "specular_transmittance": rgb(vec3(m.get("color", [1, 1, 1]), f"{where}.color"))}
    else:
        raise ConversionError(f"{where}.type: unknown material type {kind!r}")
    if kind != "dielectric":
        # glint's surfaces are two-sided; Mitsuba's reflective BSDFs are black from behind.
        bsdf = {"type": "twosided", "bsdf": bsdf}
    emitted = None
    if "emission" in m:
        strength = number(m.get("strength", 1.0), f"{where}.strength")
        emitted = scale3(vec3(m["emission"], f"{where}.emission"), strength)
        if max(emitted) <= 0:
            emitted = None
    elif "strength" in m:
        raise ConversionError(f"{where}.strength: given without emission")
    return bsdf, emitted


def convert_medium(name, m, channel=None):
    """Mitsuba's `homogeneous` medium (a dict) for glint's `[media.NAME]`: σt = σa + σs and
    the albedo σs / σt per channel, and a Henyey–Greenstein phase function with glint's g
    (both take g > 0 as forwards). σt is given as a colour in [0, 1] times `scale`, so that
    Mitsuba's RGB colour stays in the range it accepts. With `channel` (0, 1, 2), every
    channel takes that channel's coefficients: a grey medium whose render is, in that channel,
    the same as the coloured one's (RGB channels do not mix), without the noise of sampling
    free flights in a medium whose σt differs per channel."""
    where = f"media.{name}"
    if not isinstance(m, dict):
        raise ConversionError(f"{where}: expected a table")
    check_keys(m, ["sigma_a", "sigma_s", "color", "density", "mean_free_path", "g"], where)
    physical = "sigma_a" in m or "sigma_s" in m
    artist = [k for k in ["color", "density", "mean_free_path"] if k in m]
    if physical and artist:
        raise ConversionError(f"{where}.{artist[0]}: give either sigma_a and sigma_s, or color "
                              "with density or mean_free_path, not both")
    if physical:
        sigma_a = vec3(m.get("sigma_a", [0, 0, 0]), f"{where}.sigma_a")
        sigma_s = vec3(m.get("sigma_s", [0, 0, 0]), f"{where}.sigma_s")
        if min(sigma_a + sigma_s) < 0:
            raise ConversionError(f"{where}: coefficients must be >= 0")
    else:
        if "color" not in m:
            raise ConversionError(f"{where}.color: missing: a medium needs sigma_a and "
                                  "sigma_s, or color with density or mean_free_path")
        albedo = vec3(m["color"], f"{where}.color")
        if min(albedo) < 0 or max(albedo) > 1:
            raise ConversionError(f"{where}.color: must be in [0, 1] per channel")
        if ("density" in m) == ("mean_free_path" in m):
            raise ConversionError(f"{where}: give density or mean_free_path (one of them)")
        if "density" in m:
            sigma_t = [number(m["density"], f"{where}.density")] * 3
        else:
            path = m["mean_free_path"]
            path = (vec3(path, f"{where}.mean_free_path") if isinstance(path, list)
                    else [number(path, f"{where}.mean_free_path")] * 3)
            if min(path) <= 0:
                raise ConversionError(f"{where}.mean_free_path: must be > 0")
            sigma_t = [1 / x for x in path]
        if min(sigma_t) < 0:
            raise ConversionError(f"{where}.density: must be >= 0")
        sigma_a = [t * (1 - a) for t, a in zip(sigma_t, albedo)]
        sigma_s = [t * a for t, a in zip(sigma_t, albedo)]
    g = number(m.get("g", 0.0), f"{where}.g")
    if abs(g) >= 1:
        raise ConversionError(f"{where}.g: must be in (-1, 1), got {g}")
    if channel is not None:
        sigma_a, sigma_s = [sigma_a[channel]] * 3, [sigma_s[channel]] * 3
    sigma_t = add(sigma_a, sigma_s)
    scale = max(sigma_t)
    return {
        "type": "homogeneous",
        "sigma_t": rgb([t / scale for t in sigma_t] if scale > 0 else [0.0] * 3),
        "scale": scale if scale > 0 else 1.0,
        "albedo": rgb([s / t if t > 0 else 0.0 for s, t in zip(sigma_s, sigma_t)]),
        "phase": {"type": "hg", "g": g},
    }


def boxes_overlap(a, b):
    """Whether two axis-aligned boxes (min, max) share a volume (touching is not enough)."""
    return all(a[0][i] < b[1][i] and b[0][i] < a[1][i] for i in range(3))


def convert_scene(scene_path, overrides):
    """The Mitsuba scene dict and a summary of the settings used."""
    import mitsuba as mi

    with open(scene_path, "rb") as f:
        try:
            scene = tomllib.load(f)
        except tomllib.TOMLDecodeError as e:
            raise ConversionError(f"{scene_path}: {e}") from e
    check_keys(scene, ["camera", "render", "materials", "spheres", "quads", "meshes", "media"],
               "scene")
    folder = os.path.dirname(os.path.abspath(scene_path))

    render = dict(scene.get("render", {}))
    check_keys(render, ["width", "height", "spp", "max_bounces", "background", "seed",
                        "light_sampling", "russian_roulette", "medium"], "render")
    for key in ["width", "height", "spp", "max_bounces", "seed"]:
        if overrides.get(key) is not None:
            render[key] = overrides[key]
    if not render.get("light_sampling", True):
        raise ConversionError("render.light_sampling: false cannot be matched: Mitsuba's path "
                              "integrator always samples emitters")
    width, height, spp = int(render["width"]), int(render["height"]), int(render["spp"])
    max_bounces = int(render["max_bounces"])
    max_depth = max_bounces + 1
    rr_depth = GLINT_ROULETTE_START_BOUNCE + 1
    if not render.get("russian_roulette", True):
        rr_depth = max_depth + 1  # never reached
    background = vec3(render.get("background", [0, 0, 0]), "render.background")

    cam = scene["camera"]
    check_keys(cam, ["eye", "target", "up", "vfov", "aperture", "focus_distance", "medium"],
               "camera")
    eye, target, up = (vec3(cam[k], f"camera.{k}") for k in ["eye", "target", "up"])
    to_world = mi.ScalarTransform4f().look_at(origin=eye, target=target, up=up)
    aperture = number(cam.get("aperture", 0.0), "camera.aperture")
    sensor = {
        "fov": number(cam["vfov"], "camera.vfov"),
        "fov_axis": "y",
        "to_world": to_world,
        # glint's camera rays have no clipping planes; keep Mitsuba's out of the way.
        "near_clip": 1e-3,
        "far_clip": 1e8,
        "sampler": {"type": "independent", "sample_count": spp},
        "film": {
            "type": "hdrfilm", "width": width, "height": height, "pixel_format": "rgb",
            "component_format": "float32",
            # glint jitters each sample uniformly over its pixel square: a box filter.
            "rfilter": {"type": "box"},
        },
    }
    if aperture > 0:
        sensor["type"] = "thinlens"
        sensor["aperture_radius"] = aperture / 2
        sensor["focus_distance"] = number(
            cam.get("focus_distance", length(sub(target, eye))), "camera.focus_distance")
    else:
        sensor["type"] = "perspective"

    # Media: Mitsuba's homogeneous media, one object per glint medium, which every shape
    # bounding it (and the sensor inside it) shares.
    media_toml = scene.get("media", {})
    if not isinstance(media_toml, dict):
        raise ConversionError("media: expected tables [media.NAME]")
    grey = overrides.get("medium_channel")
    media_dicts = {name: convert_medium(name, m, grey) for name, m in media_toml.items()}
    spectral = any(len(set(d["sigma_t"]["value"])) > 1 for d in media_dicts.values())
    media = {name: mi.load_dict(d) for name, d in media_dicts.items()}

    def medium_named(name, where):
        if name is None:
            return None
        if name not in media:
            raise ConversionError(f"{where}: unknown medium {name!r}")
        return media[name]

    global_medium = medium_named(render.get("medium"), "render.medium")
    camera_medium = medium_named(cam.get("medium", render.get("medium")), "camera.medium")
    if camera_medium is not None:
        sensor["medium"] = camera_medium
        # Mitsuba's camera rays start at the near clip plane: in a medium, the fog in front of
        # it would be missing (1e-3 of a unit-sized scene is 0.1% of its depth).
        sensor["near_clip"] = 1e-6 * length(sub(target, eye))
    integrator = overrides.get("integrator") or ("volpath" if media else "path")
    if media and integrator == "path":
        raise ConversionError("media: Mitsuba's path integrator ignores media; use volpath "
                              "or volpathmis")

    out = {
        "type": "scene",
        "integrator": {"type": integrator, "max_depth": max_depth, "rr_depth": rr_depth},
        "sensor": sensor,
    }
    if max(background) > 0:
        out["background"] = {"type": "constant", "radiance": rgb(background)}

    materials = {}
    for name, m in scene.get("materials", {}).items():
        materials[name] = convert_material(name, m)
        if (media and m.get("type") == "dielectric" and m.get("ior") == 1
                and m.get("color", [1, 1, 1]) == [1, 1, 1] and "emission" not in m):
            # In a scene with media glint crosses an index-matched, untinted dielectric as an
            # interface (no scattering event), as Mitsuba's volpath crosses a null BSDF.
            materials[name] = ({"type": "null"}, None)

    def material_of(shape, where):
        name = shape.get("material")
        if name is None:
            raise ConversionError(f"{where}.material: missing (the file's own materials are "
                                  "not mapped to Mitsuba by this script; name a material)")
        if name not in materials:
            raise ConversionError(f"{where}.material: unknown material {name!r}")
        return materials[name]

    # Which medium each side of a shape is in. Mitsuba takes it from the shape (its interior and
    # exterior), glint from the boundaries the path has crossed (a stack): they agree where each
    # object with a medium sits in the global medium, apart from every other shape. Shapes
    # that bound no medium have the global medium on both sides (glint: "a glass ball in fog
    # is full of fog").
    boxes = []  # (where, bounding box, whether the shape bounds a medium)

    def set_media(shape, inside, where, box):
        if inside is not None:
            shape["interior"] = inside
            if global_medium is not None:
                shape["exterior"] = global_medium
        elif global_medium is not None:
            shape["interior"] = shape["exterior"] = global_medium
        if media:
            boxes.append((where, box, inside is not None))
        return shape

    def attach(shape, material, power_per_radiance):
        """Adds the BSDF and, for emitters, an area emitter whose selection weight is glint's
        (mean emitted radiance × area); the shape's media stay as set_media set them."""
        bsdf, emitted = material
        shape["bsdf"] = bsdf
        if emitted is not None:
            emitter = {"type": "area", "radiance": rgb(emitted)}
            if power_per_radiance is not None:
                emitter["sampling_weight"] = sum(emitted) / 3 * power_per_radiance
            shape["emitter"] = emitter
        return shape

    counts = {"spheres": 0, "quads": 0, "meshes": 0}
    for i, s in enumerate(scene.get("spheres", [])):
        where = f"spheres[{i}]"
        check_keys(s, ["center", "radius", "material", "medium"], where)
        radius = number(s["radius"], f"{where}.radius")
        center = vec3(s["center"], f"{where}.center")
        material = material_of(s, where)
        inside = medium_named(s.get("medium"), f"{where}.medium")
        box = (sub(center, [radius] * 3), add(center, [radius] * 3))
        shape = set_media({"type": "sphere", "center": center, "radius": radius}, inside,
                          where, box)
        out[f"sphere_{i}"] = attach(dict(shape), material, 4 * math.pi * radius * radius)
        if material[1] is not None:
            # glint's emitters emit from both sides, Mitsuba's area lights from the front
            # only: a slightly smaller twin facing inwards emits into the sphere.
            twin = dict(shape, radius=radius * (1 - TWIN_OFFSET), flip_normals=True)
            if inside is not None:  # flipped: its outside faces the sphere's inside
                twin["interior"], twin["exterior"] = shape.get("exterior"), inside
                twin = {k: v for k, v in twin.items() if v is not None}
            out[f"sphere_{i}_inside"] = attach(twin, material, 4 * math.pi * radius * radius)
        counts["spheres"] += 1
    for i, q in enumerate(scene.get("quads", [])):
        where = f"quads[{i}]"
        check_keys(q, ["corner", "u", "v", "material", "medium"], where)
        if "medium" in q:
            raise ConversionError(f"{where}.medium: a quad bounds no volume (glint refuses it "
                                  "too)")
        corner, u, v = (vec3(q[k], f"{where}.{k}") for k in ["corner", "u", "v"])
        matrix, area = quad_to_world(corner, u, v, where)
        material = material_of(q, where)
        to_world = mi.ScalarTransform4f(matrix)
        corners = [corner, add(corner, u), add(corner, v), add(add(corner, u), v)]
        box = ([min(c[k] for c in corners) for k in range(3)],
               [max(c[k] for c in corners) for k in range(3)])
        shape = set_media({"type": "rectangle", "to_world": to_world}, None, where, box)
        out[f"quad_{i}"] = attach(dict(shape), material, area)
        if material[1] is not None:
            # Back-side emission (see spheres): a twin facing the other way, moved behind
            # the quad by a hair; turning y and z over keeps the frame right-handed.
            behind = -TWIN_OFFSET * math.sqrt(area)
            flip = [[1.0, 0, 0, 0], [0, -1.0, 0, 0], [0, 0, -1.0, behind], [0, 0, 0, 1.0]]
            out[f"quad_{i}_back"] = attach(
                dict(shape, to_world=to_world @ mi.ScalarTransform4f(flip)), material, area)
        counts["quads"] += 1
    for i, mesh in enumerate(scene.get("meshes", [])):
        where = f"meshes[{i}]"
        check_keys(mesh, ["file", "material", "translate", "rotate", "scale", "smooth", "medium"],
                   where)
        file = mesh.get("file")
        if not isinstance(file, str):
            raise ConversionError(f"{where}.file: missing or not a string")
        path = os.path.join(folder, file)
        ext = os.path.splitext(file)[1].lower()
        if ext not in (".obj", ".ply"):
            raise ConversionError(f"{where}.file: {file!r}: Mitsuba 3 reads .obj and .ply "
                                  "only (no glTF); convert it first")
        if not os.path.isfile(path):
            raise ConversionError(f"{where}.file: {path}: no such file")
        smooth = mesh.get("smooth", True)
        if not isinstance(smooth, bool):
            raise ConversionError(f"{where}.smooth: expected true or false, got {smooth!r}")
        shape = {"type": ext[1:], "filename": path,
                 "to_world": mi.ScalarTransform4f(mesh_to_world(mesh, where)),
                 # glint interpolates only the file's own vertex normals; Mitsuba would
                 # compute smooth ones for a file without them, so ask for face normals then.
                 "face_normals": not (smooth and file_has_normals(path, ext))}
        material = material_of(mesh, where)
        inside = medium_named(mesh.get("medium"), f"{where}.medium")
        area, box = None, None
        if material[1] is not None or media:
            try:
                loaded = mi.load_dict(dict(shape))
            except Exception as e:  # Mitsuba's loaders raise plain exceptions
                raise ConversionError(f"{where}.file: {path}: Mitsuba cannot read it: {e}")
            area = loaded.surface_area()
            area = float(area[0] if hasattr(area, "__len__") else area)
            bbox = loaded.bbox()
            box = ([float(bbox.min[k]) for k in range(3)], [float(bbox.max[k]) for k in range(3)])
        # Mitsuba does not check that a mesh bounding a medium is closed; glint refuses an
        # open one, so a scene glint renders has a closed one here.
        shape = set_media(shape, inside, where, box)
        out[f"mesh_{i}"] = attach(shape, material, area if material[1] is not None else None)
        if material[1] is not None:
            print(f"compare.py: warning: {where}: Mitsuba's area lights emit on the front "
                  "side only (the triangles' winding); glint's emit on both", file=sys.stderr)
        counts["meshes"] += 1

    for a, (where_a, box_a, bounds_a) in enumerate(boxes):
        for where_b, box_b, bounds_b in boxes[a + 1:]:
            if (bounds_a or bounds_b) and boxes_overlap(box_a, box_b):
                raise ConversionError(
                    f"{where_a} and {where_b}: an object filled with a medium overlaps or holds "
                    "another shape (their bounding boxes share a volume); not mapped: Mitsuba "
                    "takes each shape's inside and outside medium from the shape, glint from "
                    "the boundaries a path has crossed, and this script maps only objects with "
                    "a medium set apart in the global one")

    summary = {"width": width, "height": height, "spp": spp, "max_bounces": max_bounces,
               "max_depth": max_depth, "rr_depth": rr_depth, "integrator": integrator,
               "media": len(media), "spectral_extinction": spectral, "medium_channel": grey,
               "seed": int(render.get("seed", 0)), **counts}
    return out, summary


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", help="glint scene TOML")
    parser.add_argument("--width", type=int)
    parser.add_argument("--height", type=int)
    parser.add_argument("--spp", type=int)
    parser.add_argument("--max-bounces", type=int, dest="max_bounces")
    parser.add_argument("--seed", type=int)
    parser.add_argument("--runs", type=int, default=3, help="timed runs after the warm-up")
    parser.add_argument("--variant", default="llvm_ad_rgb")
    parser.add_argument("--integrator", choices=["path", "volpath", "volpathmis"],
                        help="Mitsuba's integrator (default: volpath if the scene has media, "
                        "else path)")
    parser.add_argument("--medium-channel", type=int, choices=[0, 1, 2], dest="medium_channel",
                        help="give every medium the coefficients of this channel (0 red, 1 "
                        "green, 2 blue) in all three: the image is right in that channel only, "
                        "and is a low-noise reference for it where σt differs per channel")
    parser.add_argument("--threads", type=int, help="Dr.Jit's thread pool size (default: all)")
    parser.add_argument("-o", "--output", help="EXR of the warm-up render (linear float32)")
    parser.add_argument("--png", help="PNG of the warm-up render (clamped, sRGB)")
    parser.add_argument("--variance", metavar="FILE.exr",
                        help="write to -o the mean of all runs + 1 renders (independent seeds) "
                        "instead of the warm-up render, and here the variance of that mean per "
                        "pixel (σ²/n, estimated from the spread between the renders), for "
                        "glint compare's Z-test; needs --runs >= 1 and -o")
    args = parser.parse_args()
    if args.variance is not None and args.output is None:
        fail("--variance: needs -o")
    if args.runs < 1:
        fail("--runs: must be >= 1")
    for path, ext in [(args.output, ".exr"), (args.png, ".png"), (args.variance, ".exr")]:
        if path is not None and not path.lower().endswith(ext):
            fail(f"{path}: expected a {ext} file name")

    import drjit as dr
    import mitsuba as mi

    try:
        mi.set_variant(args.variant)
    except Exception as e:
        fail(f"--variant {args.variant}: {e}")
    if args.threads:
        dr.set_thread_count(args.threads)
    try:
        scene_dict, summary = convert_scene(args.scene, vars(args))
    except ConversionError as e:
        fail(str(e))
    except KeyError as e:
        fail(f"{args.scene}: missing field {e.args[0]!r}")
    except OSError as e:
        fail(f"{args.scene}: {e}")
    try:
        scene = mi.load_dict(scene_dict)
    except RuntimeError as e:  # e.g. a malformed OBJ/PLY, named by Mitsuba's message
        fail(f"{args.scene}: Mitsuba cannot load the converted scene: {e}")

    jit = args.variant.startswith(("llvm", "cuda"))
    if jit:
        dr.set_flag(dr.JitFlag.KernelHistory, True)

    cpu_seconds = []  # process CPU time (all threads) of each render

    def render(seed):
        """Wall seconds of one render, and the seconds its kernels ran (JIT variants); appends
        its CPU seconds to cpu_seconds."""
        if jit:
            dr.kernel_history()  # clear
        start, cpu_start = time.perf_counter(), time.process_time()
        image = mi.render(scene, seed=seed, spp=summary["spp"])
        dr.eval(image)
        dr.sync_thread()
        seconds = time.perf_counter() - start
        cpu_seconds.append(time.process_time() - cpu_start)
        kernel_seconds, compiled = None, False
        if jit:
            history = [k for k in dr.kernel_history() if "execution_time" in k]
            kernel_seconds = sum(k["execution_time"] for k in history) / 1000
            compiled = any(k.get("cache_hit") is not None and not k["cache_hit"] for k in history)
        return image, seconds, kernel_seconds, compiled

    def channel_means(image):
        """Mean of each channel over the image, outside the timed part."""
        flat, n = image.array, summary["width"] * summary["height"]
        channel = [dr.gather(type(flat), flat, dr.arange(mi.UInt32, n) * 3 + c) for c in range(3)]
        return [float(dr.mean(x)[0]) for x in channel]

    image, warm_seconds, _, _ = render(summary["seed"])
    means = [channel_means(image)]
    # Welford's running mean and sum of squared deviations over the renders, per pixel.
    mean_image, m2_image = image, dr.zeros(mi.TensorXf, image.shape)
    if args.output and args.variance is None:
        mi.Bitmap(image).write(args.output)
    if args.png:
        mi.Bitmap(image).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.UInt8,
                                 srgb_gamma=True).write(args.png)

    seconds, kernel_seconds, recompiled = [], [], 0
    for run in range(args.runs):
        # A new seed per run, as glint's timed batches draw new samples.
        timed_image, s, k, compiled = render(summary["seed"] + 1 + run)
        means.append(channel_means(timed_image))
        if args.variance is not None:
            delta = timed_image - mean_image
            mean_image = mean_image + delta / len(means)
            m2_image = m2_image + delta * (timed_image - mean_image)
            dr.eval(mean_image, m2_image)
        seconds.append(s)
        if k is not None:
            kernel_seconds.append(k)
        recompiled += compiled
    if args.variance is not None:
        k = len(means)
        mi.Bitmap(mean_image).write(args.output)
        mi.Bitmap(m2_image / (k * (k - 1))).write(args.variance)
    paths = summary["width"] * summary["height"] * summary["spp"]
    median = statistics.median(seconds)
    result = {
        "renderer": "mitsuba",
        "mitsuba": mi.__version__,
        "drjit": dr.__version__,
        "variant": args.variant,
        "threads": dr.thread_count() if jit else None,
        "scene": args.scene,
        **summary,
        "paths": paths,
        "runs": args.runs,
        "seconds": seconds,
        "seconds_median": median,
        "paths_per_second": paths / median,
        # Process CPU time (user + sys, all threads) of a timed render, per path: less
        # disturbed than wall time by other processes on shared cores.
        "cpu_seconds_per_path": statistics.median(cpu_seconds[1:]) / paths,
        "kernel_seconds_median": statistics.median(kernel_seconds) if kernel_seconds else None,
        "paths_per_second_kernel": paths / statistics.median(kernel_seconds)
        if kernel_seconds else None,
        "warm_up_seconds": warm_seconds,
        "timed_runs_that_compiled": recompiled,
        # Per channel, over the warm-up and timed renders (independent seeds): the mean, and
        # its standard error from the spread between renders (when there are 2 or more).
        "image_mean_rgb": [statistics.fmean(m[c] for m in means) for c in range(3)],
        "image_mean_standard_error_rgb": [statistics.stdev(m[c] for m in means)
                                          / math.sqrt(len(means)) for c in range(3)],
        "output": args.output,
        "png": args.png,
    }
    print(json.dumps(result))


if __name__ == "__main__":
    main()
