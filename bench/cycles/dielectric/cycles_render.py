# Renders a .glb with Cycles 4.5 (CPU, no denoiser, no adaptive sampling, no clamping,
# Standard view, linear EXR; the file's camera; film transparent so alpha is the coverage).
# The environment map is turned to glint's orientation and read nearest-texel, as in
# ../render.py. Usage: python3.11 cycles_render.py IN.glb OUT.exr W H SPP (const:V | HDR_PATH) [BOUNCES]
import math
import sys

import bpy

glb, out, w, h, spp, sky = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5]), sys.argv[6]
bounces = int(sys.argv[7]) if len(sys.argv) > 7 else 8
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=glb)
scene = bpy.context.scene
cams = [o for o in scene.objects if o.type == "CAMERA"]
scene.camera = cams[0]
world = bpy.data.worlds.new("world")
world.use_nodes = True
scene.world = world
nodes, links = world.node_tree.nodes, world.node_tree.links
bg = nodes["Background"]
if sky.startswith("const:"):
    v = float(sky[6:])
    bg.inputs["Color"].default_value = (v, v, v, 1.0)
else:
    tex = nodes.new("ShaderNodeTexEnvironment")
    tex.image = bpy.data.images.load(sky)
    tex.interpolation = "Closest"  # glint reads the nearest texel
    coords = nodes.new("ShaderNodeTexCoord")
    mapping = nodes.new("ShaderNodeMapping")
    # as bench/cycles/render.py: glint's u = atan2(x, -z)/2pi is Cycles' + 0.25
    mapping.inputs["Rotation"].default_value = (0.0, 0.0, math.radians(90.0))
    links.new(coords.outputs["Generated"], mapping.inputs["Vector"])
    links.new(mapping.outputs["Vector"], tex.inputs["Vector"])
    links.new(tex.outputs["Color"], bg.inputs["Color"])
scene.render.engine = "CYCLES"
c = scene.cycles
c.device = "CPU"
c.samples = spp
c.use_adaptive_sampling = False
c.use_denoising = False
c.max_bounces = bounces
c.diffuse_bounces = c.glossy_bounces = c.transmission_bounces = bounces
c.transparent_max_bounces = 16
c.volume_bounces = 0
c.sample_clamp_direct = c.sample_clamp_indirect = 0.0
c.caustics_reflective = c.caustics_refractive = True
c.blur_glossy = 0.0
c.seed = 1
scene.render.threads_mode = "FIXED"
scene.render.threads = 2
scene.render.film_transparent = True
scene.render.filter_size = 0.01
scene.render.resolution_x = w
scene.render.resolution_y = h
scene.render.resolution_percentage = 100
scene.view_settings.view_transform = "Standard"
scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.image_settings.color_depth = "32"
scene.render.image_settings.color_mode = "RGBA"
scene.render.filepath = out
bpy.ops.render.render(write_still=True)
