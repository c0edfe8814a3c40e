#!/usr/bin/env python3
"""Writes tests/models/blender-lamps.glb with Blender itself, as a user's export is written,
and renders the same scene with Cycles for comparison (issue 31, item 1).

Blender's glTF exporter lists KHR_lights_punctual in extensionsRequired whenever the scene
holds a point, spot or sun lamp; glint once refused every such file. The scene: a grey floor
(10 x 10 m), a white box and a red sphere; a camera; a point, a spot and a sun lamp; a black
world (Blender exports no world, so the glint scene has no environment either).

Needs Blender 4.5 as a Python module (`pip install "bpy==4.5.*"`, Python 3.11):

  python3.11 tests/models/make_blender_lamps.py [--cycles OUT.exr] [--spp N]

Without --cycles it only writes the .glb (byte-stable for a given Blender version).
"""

import argparse
import math
import os

import bpy

here = os.path.dirname(os.path.abspath(__file__))
parser = argparse.ArgumentParser()
parser.add_argument("--cycles", help="also render with Cycles to this EXR")
parser.add_argument("--spp", type=int, default=1024)
parser.add_argument("--width", type=int, default=96)
parser.add_argument("--height", type=int, default=72)
args = parser.parse_args()

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene


def material(name, color, roughness):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    bsdf = m.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*color, 1.0)
    bsdf.inputs["Roughness"].default_value = roughness
    bsdf.inputs["Metallic"].default_value = 0.0
    return m


bpy.ops.mesh.primitive_plane_add(size=10, location=(0, 0, 0))
bpy.context.object.name = "floor"
bpy.context.object.data.materials.append(material("floor", (0.5, 0.5, 0.5), 0.8))
bpy.ops.mesh.primitive_cube_add(size=1.2, location=(-1.0, 0.5, 0.6))
bpy.context.object.name = "box"
bpy.context.object.data.materials.append(material("box", (0.8, 0.8, 0.8), 0.5))
bpy.ops.mesh.primitive_uv_sphere_add(radius=0.7, location=(1.1, -0.2, 0.7), segments=48, ring_count=24)
bpy.ops.object.shade_smooth()
bpy.context.object.name = "ball"
bpy.context.object.data.materials.append(material("ball", (0.8, 0.1, 0.1), 0.3))

bpy.ops.object.light_add(type="POINT", location=(1.5, -1.5, 2.5))
bpy.context.object.data.energy = 300.0  # W
bpy.context.object.data.shadow_soft_size = 0.0
bpy.ops.object.light_add(type="SPOT", location=(-2.0, 1.0, 3.5), rotation=(math.radians(20), 0, 0))
spot = bpy.context.object.data
spot.energy = 500.0
spot.spot_size = math.radians(60)
spot.spot_blend = 0.3
spot.shadow_soft_size = 0.0
spot.color = (1.0, 0.85, 0.6)
bpy.ops.object.light_add(type="SUN", rotation=(math.radians(50), 0, math.radians(30)))
sun = bpy.context.object.data
sun.energy = 2.0  # W/m^2
sun.angle = 0.0
sun.color = (0.7, 0.8, 1.0)

bpy.ops.object.camera_add(location=(0, -7.5, 3.2), rotation=(math.radians(72), 0, 0))
bpy.context.object.data.lens_unit = "FOV"
bpy.context.object.data.angle = math.radians(50)
scene.camera = bpy.context.object

world = bpy.data.worlds.new("black")
world.use_nodes = True
world.node_tree.nodes["Background"].inputs["Color"].default_value = (0, 0, 0, 1)
scene.world = world

# The image's shape before the export: the exporter derives yfov and aspectRatio from it.
scene.render.resolution_x = args.width
scene.render.resolution_y = args.height
scene.render.resolution_percentage = 100

bpy.ops.export_scene.gltf(
    filepath=os.path.join(here, "blender-lamps.glb"),
    export_format="GLB",
    export_lights=True,
    export_cameras=True,
    export_apply=True,
)

if args.cycles:
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = args.spp
    scene.cycles.use_denoising = False
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.max_bounces = 8
    scene.cycles.sample_clamp_direct = 0
    scene.cycles.sample_clamp_indirect = 0
    scene.cycles.blur_glossy = 0
    scene.cycles.caustics_reflective = True
    scene.cycles.caustics_refractive = True
    scene.render.film_transparent = False
    scene.render.filter_size = 0.01
    scene.view_settings.view_transform = "Standard"
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.filepath = args.cycles
    bpy.ops.render.render(write_still=True)
