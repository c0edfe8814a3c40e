# Renders one glint scene with Cycles 4.5 (bpy) at several sample counts in one process and
# prints one JSON line per render: spp, wall seconds and process CPU seconds (user + sys, all
# threads) of bpy.ops.render.render, and the EXR written. Cycles as a reference: CPU device,
# a fixed number of threads, no adaptive sampling, no denoiser, no clamping, 8 bounces of
# every kind, a box pixel filter one pixel wide (glint's jitter over the pixel square),
# Standard view, linear EXR.
#
# Usage: python cycles_worker.py SCENE.toml OUT_PREFIX SIZE SEED THREADS SPP[,SPP...]
#
# Mapped: the camera (eye, target, up, vfov), quads, spheres (UV spheres of 128 x 64
# segments, smooth shaded: Cycles has no analytic sphere here), PLY meshes with glint's
# transform (translate . Rz . Ry . Rx . scale), diffuse, specular (a sharp Glossy BSDF),
# emission x strength (Cycles' mesh emission is two-sided, as glint's), the background colour,
# and a glTF mesh with an environment map (the helmet: as ../cycles/render.py does it,
# with ../lib/cycles_world.py).
# glint's frame (x, y, z) is Blender's (x, -z, y).
import json
import math
import os
import resource
import sys
import time
import tomllib

import bpy
from mathutils import Matrix, Vector

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
from cycles_world import glint_world  # noqa: E402

scene_path, prefix, size, seed, threads = sys.argv[1:6]
size, seed, threads = int(size), int(seed), int(threads)
spps = [int(s) for s in sys.argv[6].split(",")]
scene_dir = os.path.dirname(os.path.abspath(scene_path))
with open(scene_path, "rb") as f:
    toml = tomllib.load(f)
FRAME = Matrix(((1, 0, 0, 0), (0, 0, -1, 0), (0, 1, 0, 0), (0, 0, 0, 1)))


def b(v):
    """A glint point or direction in Blender's frame."""
    return Vector((v[0], -v[2], v[1]))


def resolve(path):
    if os.path.isabs(path):
        return path
    local = os.path.join(scene_dir, path)
    if os.path.exists(local):
        return local
    assets = os.environ.get("GLINT_ASSETS", "")
    for candidate in [os.path.join(assets, path), os.path.join(assets, os.path.basename(path))]:
        if assets and os.path.exists(candidate):
            return candidate
    sys.exit(f"cycles_worker: {path}: not found next to the scene or in GLINT_ASSETS")


bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene


def material(name, m):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    kind = m.get("type", "diffuse")
    emission = [e * m.get("strength", 1.0) for e in m.get("emission", [0.0, 0.0, 0.0])]
    color = m.get("color", [0.8, 0.8, 0.8])
    if kind == "diffuse":
        bsdf = nodes.new("ShaderNodeBsdfDiffuse")
        bsdf.inputs["Roughness"].default_value = 0.0
    elif kind == "specular":
        bsdf = nodes.new("ShaderNodeBsdfGlossy")
        bsdf.distribution = "GGX"
        bsdf.inputs["Roughness"].default_value = 0.0
    else:
        sys.exit(f"cycles_worker: material {name}: type {kind!r} not mapped")
    bsdf.inputs["Color"].default_value = (*color, 1.0)
    shader = bsdf
    if any(e > 0 for e in emission):
        em = nodes.new("ShaderNodeEmission")
        em.inputs["Color"].default_value = (*emission, 1.0)
        em.inputs["Strength"].default_value = 1.0
        if max(color) == 0.0:
            shader = em
        else:
            add = nodes.new("ShaderNodeAddShader")
            links.new(bsdf.outputs[0], add.inputs[0])
            links.new(em.outputs[0], add.inputs[1])
            shader = add
    links.new(shader.outputs[0], out.inputs["Surface"])
    return mat


def link(name, mesh, mat, matrix=None):
    if mat is not None:
        mesh.materials.append(mat)
    obj = bpy.data.objects.new(name, mesh)
    if matrix is not None:
        obj.matrix_world = matrix
    scene.collection.objects.link(obj)
    return obj


def rotation(axis, degrees):
    return Matrix.Rotation(math.radians(degrees), 4, axis)


mats = {name: material(name, m) for name, m in toml.get("materials", {}).items()}
# 128 segments by default; fewer (TTQ_SPHERE_SEGMENTS) for scenes of many small spheres.
SEGMENTS = int(os.environ.get("TTQ_SPHERE_SEGMENTS", "128"))
for i, q in enumerate(toml.get("quads", [])):
    c, u, v = Vector(q["corner"]), Vector(q["u"]), Vector(q["v"])
    mesh = bpy.data.meshes.new(f"quad{i}")
    mesh.from_pydata([b(c), b(c + u), b(c + u + v), b(c + v)], [], [(0, 1, 2, 3)])
    link(f"quad{i}", mesh, mats[q["material"]])
for i, s in enumerate(toml.get("spheres", [])):
    bpy.ops.mesh.primitive_uv_sphere_add(segments=SEGMENTS, ring_count=SEGMENTS // 2,
                                         radius=s["radius"],
                                         location=b(s["center"]))
    obj = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    obj.data.materials.append(mats[s["material"]])
for i, m in enumerate(toml.get("meshes", [])):
    path = resolve(m["file"])
    if path.lower().endswith((".glb", ".gltf")):
        bpy.ops.import_scene.gltf(filepath=path)
        continue
    if not path.lower().endswith(".ply"):
        sys.exit(f"cycles_worker: {path}: only PLY and glTF meshes are mapped")
    bpy.ops.wm.ply_import(filepath=path, forward_axis="Y", up_axis="Z")
    obj = bpy.context.selected_objects[0]
    rx, ry, rz = m.get("rotate", [0.0, 0.0, 0.0])
    sc = m.get("scale", 1.0)
    sc = Matrix.Diagonal((*(sc if isinstance(sc, list) else [sc] * 3), 1.0))
    t = Matrix.Translation(Vector(m.get("translate", [0.0, 0.0, 0.0])))
    obj.matrix_world = FRAME @ t @ rotation("Z", rz) @ rotation("Y", ry) @ rotation("X", rx) @ sc
    obj.data.materials.clear()
    if "material" in m:
        obj.data.materials.append(mats[m["material"]])

cam = toml["camera"]
cam_data = bpy.data.cameras.new("cam")
cam_data.sensor_fit = "VERTICAL"
cam_data.angle_y = math.radians(cam.get("vfov", 40.0))
cam_data.clip_start, cam_data.clip_end = 1e-3, 1e6
cam_obj = bpy.data.objects.new("cam", cam_data)
eye, target = b(cam["eye"]), b(cam["target"])
cam_obj.location = eye
cam_obj.rotation_euler = (target - eye).to_track_quat("-Z", "Y").to_euler()
scene.collection.objects.link(cam_obj)
scene.camera = cam_obj

if "environment" in toml:
    glint_world(scene, environment=resolve(toml["environment"]["file"]))
else:
    glint_world(scene, color=toml.get("render", {}).get("background", [0.0, 0.0, 0.0]))

bounces = toml.get("render", {}).get("max_bounces", 8)
scene.render.engine = "CYCLES"
c = scene.cycles
c.device = "CPU"
c.use_adaptive_sampling = False
c.use_denoising = False
c.max_bounces = bounces
c.diffuse_bounces = c.glossy_bounces = c.transmission_bounces = bounces
c.volume_bounces = 0
c.transparent_max_bounces = bounces
c.sample_clamp_direct = c.sample_clamp_indirect = 0.0
c.caustics_reflective = c.caustics_refractive = True
c.blur_glossy = 0.0
# glint jitters each sample uniformly over its pixel square: a box filter one pixel wide.
# (A width of 0.01 would put every sample at the pixel centre, without the edge noise.)
c.pixel_filter_type = "BOX"
c.filter_width = 1.0
c.seed = seed
scene.render.threads_mode = "FIXED"
scene.render.threads = threads
scene.render.resolution_x = scene.render.resolution_y = size
scene.render.resolution_percentage = 100
scene.view_settings.view_transform = "Standard"
scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.image_settings.color_depth = "32"


def cpu():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


for spp in spps:
    c.samples = spp
    out = f"{prefix}-{spp}.exr"
    scene.render.filepath = out
    load = os.getloadavg()[0]
    t0, c0 = time.perf_counter(), cpu()
    bpy.ops.render.render(write_still=True)
    print("TTQ " + json.dumps(dict(spp=spp, wall=time.perf_counter() - t0, cpu=cpu() - c0,
                                   load=load, exr=out)), flush=True)
