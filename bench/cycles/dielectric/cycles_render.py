# Renders a .glb with Cycles 4.5 (CPU, no denoiser, no adaptive sampling, no clamping,
# Standard view, linear EXR; the file's camera; film transparent so alpha is the coverage).
# The environment map is turned to glint's orientation and read nearest-texel
# (../../lib/cycles_world.py). Usage: python3.11 cycles_render.py IN.glb OUT.exr W H SPP (const:V | HDR_PATH) [BOUNCES]
import os
import sys

import bpy

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "lib"))
from cycles_world import glint_world  # noqa: E402

glb, out, w, h, spp, sky = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5]), sys.argv[6]
bounces = int(sys.argv[7]) if len(sys.argv) > 7 else 8
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=glb)
scene = bpy.context.scene
cams = [o for o in scene.objects if o.type == "CAMERA"]
scene.camera = cams[0]
if sky.startswith("const:"):
    glint_world(scene, color=(float(sky[6:]),) * 3)
else:
    glint_world(scene, environment=sky)
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
