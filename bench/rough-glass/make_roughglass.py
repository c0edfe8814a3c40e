# Three clear rough glass spheres (glTF metallic 0, base colour 1, KHR_materials_transmission 1,
# ior 1.5, roughness 0.3 / 0.6 / 1.0 left to right), radius 0.7, centres 1.8 apart on glTF's
# x axis at y = z = 0, seen by a perspective camera on glTF's +z (distance 8, vertical fov
# 2 atan(1.62/8)), 80x48. Built in Blender 4.5, exported as roughglass.glb, then (with
# --cycles) re-imported and rendered by Cycles under royal_esplanade_1k.hdr turned to glint's
# orientation (as bench/cycles/render.py), writing the EXR, the per-sphere masks and means.
# Usage, in a scratch directory, with bpy 4.5 (pip install "bpy==4.5.*" OpenEXR numpy):
#   python make_roughglass.py [--cycles SPP BOUNCES OUT.exr]
#   glint render roughglass.glb --gpu --width 80 --height 48 --spp 2048 --max-bounces 32 \
#       --environment ../shared/assets/royal_esplanade_1k.hdr -o glint.exr
#   python side_by_side.py masks.npy cycles-glint.png OUT.exr glint.exr
import math, os, sys, json
import bpy
import numpy as np
# Everything is written to the current directory (never into the checkout).
here = os.getcwd()
glb = os.path.join(here, "roughglass.glb")
W, H = 80, 48
R, DX, DIST, HALF_H = 0.7, 1.8, 8.0, 1.62
ROUGH = [0.3, 0.6, 1.0]

def build():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    for i, r in enumerate(ROUGH):
        m = bpy.data.materials.new(f"glass{r}"); m.use_nodes = True
        b = m.node_tree.nodes["Principled BSDF"]
        b.inputs["Base Color"].default_value = (1, 1, 1, 1)
        b.inputs["Metallic"].default_value = 0.0
        b.inputs["Roughness"].default_value = r
        b.inputs["IOR"].default_value = 1.5
        b.inputs["Transmission Weight"].default_value = 1.0
        bpy.ops.mesh.primitive_uv_sphere_add(radius=R, location=((i - 1) * DX, 0, 0), segments=96, ring_count=48)
        bpy.ops.object.shade_smooth()
        bpy.context.object.data.materials.append(m)
    bpy.ops.object.camera_add(location=(0, -DIST, 0), rotation=(math.radians(90), 0, 0))
    cam = bpy.context.object.data
    cam.sensor_fit = "VERTICAL"; cam.lens_unit = "FOV"; cam.angle_y = 2 * math.atan(HALF_H / DIST)
    scene.camera = bpy.context.object
    scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = W, H, 100
    bpy.ops.export_scene.gltf(filepath=glb, export_format="GLB", export_cameras=True, export_apply=True)

def masks(sub=8):
    """Per sphere, the fraction of each pixel's area (sub x sub points) whose camera ray hits it
    (glTF frame: eye (0, 0, DIST) looking along -z, image row 0 at the top)."""
    out = np.zeros((3, H, W))
    t = HALF_H / DIST
    for j in range(H):
        for i in range(W):
            s = (np.arange(sub) + 0.5) / sub
            px, py = np.meshgrid(i + s, j + s)
            x = (2 * px / W - 1) * t * W / H
            y = (1 - 2 * py / H) * t
            d = np.stack([x, y, -np.ones_like(x)], -1)
            d /= np.linalg.norm(d, axis=-1, keepdims=True)
            o = np.array([0, 0, DIST])
            for k in range(3):
                c = np.array([(k - 1) * DX, 0, 0])
                oc = o - c
                bq = d @ oc
                disc = bq * bq - (oc @ oc - R * R)
                out[k, j, i] = (disc > 0).mean()
    return out

build()
if "--cycles" in sys.argv:
    a = sys.argv[sys.argv.index("--cycles") + 1:]
    spp, bounces, exr = int(a[0]), int(a[1]), a[2]
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=glb)
    scene = bpy.context.scene
    scene.camera = [o for o in scene.objects if o.type == "CAMERA"][0]
    world = bpy.data.worlds.new("world"); world.use_nodes = True; scene.world = world
    nodes, links = world.node_tree.nodes, world.node_tree.links
    tex = nodes.new("ShaderNodeTexEnvironment")
    tex.image = bpy.data.images.load(os.environ.get("GLINT_ASSETS", "../shared/assets") + "/royal_esplanade_1k.hdr")
    tex.interpolation = "Closest"
    coords = nodes.new("ShaderNodeTexCoord"); mapping = nodes.new("ShaderNodeMapping")
    mapping.inputs["Rotation"].default_value = (0.0, 0.0, math.radians(90.0))
    links.new(coords.outputs["Generated"], mapping.inputs["Vector"])
    links.new(mapping.outputs["Vector"], tex.inputs["Vector"])
    links.new(tex.outputs["Color"], nodes["Background"].inputs["Color"])
    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device = "CPU"; c.samples = spp; c.use_adaptive_sampling = False; c.use_denoising = False
    c.max_bounces = bounces
    c.diffuse_bounces = c.glossy_bounces = c.transmission_bounces = bounces
    c.transparent_max_bounces = bounces; c.volume_bounces = 0
    c.sample_clamp_direct = c.sample_clamp_indirect = 0.0
    c.caustics_reflective = c.caustics_refractive = True
    c.blur_glossy = 0.0; c.seed = int(os.environ.get("SEED", "1"))
    scene.render.film_transparent = False
    scene.render.filter_size = 0.01
    scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = W, H, 100
    scene.view_settings.view_transform = "Standard"
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.image_settings.color_mode = "RGB"
    scene.render.filepath = exr
    bpy.ops.render.render(write_still=True)
    m = masks()
    np.save(os.path.join(here, "masks.npy"), m)
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from side_by_side import read_rgb
    rgb = read_rgb(exr)
    res = {}
    for k, r in enumerate(ROUGH):
        full = m[k] >= 1.0
        res[f"roughness {r}"] = {"pixels": int(full.sum()), "mean_rgb": [round(float(v), 5) for v in rgb[full].mean(0)]}
    print(json.dumps(res, indent=1))
    json.dump(res, open(exr.replace(".exr", "_means.json"), "w"), indent=1)
