# Builds a 3x3 grid of glTF dielectrics (metallic 0, ior 1.5) in Blender 4.5 and exports it,
# with its camera, as .glb: the same file for glint and for Cycles.
# Rows (top to bottom in the image; back to front with --floor): base colour 1, 0.5, and a
# checker texture (sRGB bytes 0.8/0.2, 8 squares a side). Columns (left to right): roughness
# 0.1, 0.5, 1.0 (the factor; times the texture's G with --roughtex).
# Shapes: spheres of radius 0.6 facing a camera 12 away (120x120), or with --plane squares
# facing it, or with --floor squares facing up, seen from 35 degrees above (120x60).
# Options: --normal (a bumpy tangent-space normal map), --roughtex (a metallicRoughness texture
# whose G runs 0.1 -> 1 along u), --nospec (Specular IOR Level 0, exported as
# KHR_materials_specular specularFactor 0: diffuse only), --closest (the checker read
# nearest-texel: glTF sampler NEAREST).
# Usage: python3.11 make_scene.py OUT.glb [--floor|--plane] [--normal] [--roughtex] [--nospec] [--closest]
import math
import os
import sys

import bpy
import numpy as np

args = sys.argv[1:]
out = args[0]
normal = "--normal" in args
roughtex = "--roughtex" in args
nospec = "--nospec" in args
plane = "--plane" in args
closest = "--closest" in args
floor = "--floor" in args
W = H = 120
texdir = os.path.join(os.path.dirname(os.path.abspath(out)), "tex")
os.makedirs(texdir, exist_ok=True)

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene


def image(name, rgba, colorspace):
    """rgba: (h, w, 4) float array in [0,1], row 0 = top."""
    h, w, _ = rgba.shape
    img = bpy.data.images.new(name, w, h, alpha=True)
    img.colorspace_settings.name = colorspace
    # Blender's pixel rows start at the bottom.
    img.pixels.foreach_set(np.ascontiguousarray(rgba[::-1]).ravel().astype(np.float32))
    path = os.path.join(texdir, name + ".png")
    img.filepath_raw = path
    img.file_format = "PNG"
    img.save()
    img.source = "FILE"
    img.reload()
    return img


n = 256
u = (np.arange(n) + 0.5) / n
uu, vv = np.meshgrid(u, u)
# checker, 8 squares a side, sRGB-encoded values 0.8 and 0.2 (these are the stored bytes)
chk = ((np.floor(uu * 8) + np.floor(vv * 8)) % 2)[..., None]
checker = np.concatenate([np.where(chk > 0, 0.8, 0.2)] * 3 + [np.ones((n, n, 1))], axis=2)
# roughness: G from 0.1 to 1 along u; B (metallic) 0
rough = np.zeros((n, n, 4))
rough[..., 1] = 0.1 + 0.9 * uu
rough[..., 3] = 1
# normal map: height h = 0.5 sin(2pi 6u) sin(2pi 6v) / (2pi 6) * k
k = 6.0
amp = 0.35
dhdu = amp * np.cos(2 * np.pi * k * uu) * np.sin(2 * np.pi * k * vv)
dhdv = amp * np.sin(2 * np.pi * k * uu) * np.cos(2 * np.pi * k * vv)
nm = np.stack([-dhdu, -dhdv, np.ones_like(uu)], axis=-1)
nm /= np.linalg.norm(nm, axis=-1, keepdims=True)
nmap = np.concatenate([(nm + 1) / 2, np.ones((n, n, 1))], axis=2)

imgs = {}
imgs["checker"] = image("checker", checker, "sRGB")
if roughtex:
    imgs["rough"] = image("rough", rough, "Non-Color")
if normal:
    imgs["normal"] = image("normal", nmap, "Non-Color")


def material(name, base, roughness):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nt = m.node_tree
    bsdf = nt.nodes["Principled BSDF"]
    bsdf.inputs["Metallic"].default_value = 0.0
    bsdf.inputs["Roughness"].default_value = roughness
    bsdf.inputs["IOR"].default_value = 1.5
    if nospec:
        bsdf.inputs["Specular IOR Level"].default_value = 0.0
    if base == "checker":
        t = nt.nodes.new("ShaderNodeTexImage")
        t.image = imgs["checker"]
        if closest:
            t.interpolation = "Closest"
        nt.links.new(t.outputs["Color"], bsdf.inputs["Base Color"])
    else:
        bsdf.inputs["Base Color"].default_value = (base, base, base, 1.0)
    if roughtex:
        t = nt.nodes.new("ShaderNodeTexImage")
        t.image = imgs["rough"]
        sep = nt.nodes.new("ShaderNodeSeparateColor")
        nt.links.new(t.outputs["Color"], sep.inputs["Color"])
        if roughness != 1.0:
            mul = nt.nodes.new("ShaderNodeMath")
            mul.operation = "MULTIPLY"
            nt.links.new(sep.outputs["Green"], mul.inputs[0])
            mul.inputs[1].default_value = roughness
            nt.links.new(mul.outputs[0], bsdf.inputs["Roughness"])
        else:
            nt.links.new(sep.outputs["Green"], bsdf.inputs["Roughness"])
        nt.links.new(sep.outputs["Blue"], bsdf.inputs["Metallic"])
    if normal:
        t = nt.nodes.new("ShaderNodeTexImage")
        t.image = imgs["normal"]
        nmn = nt.nodes.new("ShaderNodeNormalMap")
        nt.links.new(t.outputs["Color"], nmn.inputs["Color"])
        nt.links.new(nmn.outputs["Normal"], bsdf.inputs["Normal"])
    return m


for r, base in enumerate([1.0, 0.5, "checker"]):
    for c, rough_v in enumerate([0.1, 0.5, 1.0]):
        loc = ((c - 1) * 2.4, 0.0, (1 - r) * 2.4)
        if floor:
            bpy.ops.mesh.primitive_plane_add(size=1.4, location=((c - 1) * 2.4, (1 - r) * 2.4, 0.0))
        elif plane:
            bpy.ops.mesh.primitive_plane_add(size=1.4, location=loc, rotation=(math.radians(90), 0, 0))
        else:
            bpy.ops.mesh.primitive_uv_sphere_add(radius=0.6, location=loc, segments=64, ring_count=32)
            bpy.ops.object.shade_smooth()
        o = bpy.context.object
        o.name = f"s{r}{c}"
        o.data.materials.append(material(f"m{r}{c}", base, rough_v))

if floor:
    W, H = 120, 60
    el = math.radians(35)
    bpy.ops.object.camera_add(location=(0, -12.0 * math.cos(el), 12.0 * math.sin(el)), rotation=(math.radians(90) - el, 0, 0))
else:
    bpy.ops.object.camera_add(location=(0, -12.0, 0), rotation=(math.radians(90), 0, 0))
cam = bpy.context.object.data
cam.sensor_fit = "VERTICAL"
cam.lens_unit = "FOV"
cam.angle_y = 2 * math.atan((2.0 if floor else 4.0) / 12.0)
scene.camera = bpy.context.object
scene.render.resolution_x = W
scene.render.resolution_y = H
scene.render.resolution_percentage = 100

bpy.ops.export_scene.gltf(
    filepath=out,
    export_format="GLB",
    export_cameras=True,
    export_apply=True,
    export_tangents=normal,
)
