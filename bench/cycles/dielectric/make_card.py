# Three rough green alpha-masked cards (glTF alphaMode MASK, cutoff 0.5; base colour texture
# sRGB (0.25, 0.6, 0.15) with an alpha of a disc with holes; roughness 0.7, metallic 0),
# left to right: facing the camera, tilted 60 degrees back (towards the sky), and turned
# away (the camera sees its back). Plus --nomask: the same without the alpha (OPAQUE).
# Usage: python3.11 make_card.py OUT.glb [--nomask]
import math, os, sys
import bpy
import numpy as np
out = sys.argv[1]
nomask = "--nomask" in sys.argv
texdir = os.path.join(os.path.dirname(os.path.abspath(out)), "tex")
os.makedirs(texdir, exist_ok=True)
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
n = 256
u = (np.arange(n) + 0.5) / n
uu, vv = np.meshgrid(u, u)
r = np.hypot(uu - 0.5, vv - 0.5)
holes = np.hypot((uu * 4) % 1 - 0.5, (vv * 4) % 1 - 0.5) < 0.2
alpha = ((r < 0.48) & ~holes).astype(float)
rgba = np.zeros((n, n, 4)); rgba[..., 0] = 0.25; rgba[..., 1] = 0.6; rgba[..., 2] = 0.15; rgba[..., 3] = alpha
img = bpy.data.images.new("leaf", n, n, alpha=True)
img.pixels.foreach_set(np.ascontiguousarray(rgba[::-1]).ravel().astype(np.float32))
img.filepath_raw = os.path.join(texdir, "leaf.png"); img.file_format = "PNG"; img.save()
img.source = "FILE"; img.reload()
m = bpy.data.materials.new("card"); m.use_nodes = True
nt = m.node_tree; bsdf = nt.nodes["Principled BSDF"]
bsdf.inputs["Metallic"].default_value = 0.0
bsdf.inputs["Roughness"].default_value = 0.7
t = nt.nodes.new("ShaderNodeTexImage"); t.image = img
nt.links.new(t.outputs["Color"], bsdf.inputs["Base Color"])
if not nomask:
    rnd = nt.nodes.new("ShaderNodeMath"); rnd.operation = "ROUND"
    nt.links.new(t.outputs["Alpha"], rnd.inputs[0])
    nt.links.new(rnd.outputs[0], bsdf.inputs["Alpha"])
for i, rot in enumerate([(90, 0, 0), (30, 0, 0), (90, 0, 180)]):
    bpy.ops.mesh.primitive_plane_add(size=2.0, location=((i - 1) * 2.4, 0, 0), rotation=tuple(math.radians(a) for a in rot))
    bpy.context.object.data.materials.append(m)
bpy.ops.object.camera_add(location=(0, -12.0, 0), rotation=(math.radians(90), 0, 0))
cam = bpy.context.object.data
cam.sensor_fit = "VERTICAL"; cam.lens_unit = "FOV"; cam.angle_y = 2 * math.atan(1.6 / 12.0)
scene.camera = bpy.context.object
scene.render.resolution_x = 144; scene.render.resolution_y = 48; scene.render.resolution_percentage = 100
bpy.ops.export_scene.gltf(filepath=out, export_format="GLB", export_cameras=True, export_apply=True)
