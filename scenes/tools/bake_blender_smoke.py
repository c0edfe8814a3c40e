"""Bakes a Blender smoke simulation (mantaflow) and keeps one frame of its OpenVDB cache as
scenes/blender-smoke.vdb, the file scenes/blender-smoke.toml renders; or renders that file in
Cycles with the scene's camera, sun, sky and floor, to compare with glint.

Bake (Blender's own executable, headless; Debian's `apt-get install blender`, 3.4, does):

    blender -b --factory-startup --python scenes/tools/bake_blender_smoke.py -- \\
        [--res 32] [--frame 24] [--out scenes/blender-smoke.vdb] [--facts facts.json]

The scene is Blender's Quick Smoke on a 0.5 cube at (0, 0, 0.3) (z up): a domain of
2.5 × 2.5 × 4.5 centred at (0, 0, 1.3), `--res` cells along its longest side, a cache of type
ALL in Blender's default OpenVDB format (Blosc, half floats). Frames 1 to `--frame` are baked
into a temporary folder and the last one, `data/fluid_data_NNNN.vdb`, copied as it is to
`--out`. The script prints (and writes to `--facts`) what Blender reports of that frame: the
domain's placement, resolution and cell size, and the mass (the sum of the densities), largest
density and count of voxels above the cache's clipping of the domain's own density grid
(`domain_settings.density_grid`), which tests/suite/grid_media.rs checks the file against.

The `bpy` module (pip's Blender 4.5 as a Python module) cannot bake: mantaflow's scripts fail
in it with "'LevelsetGrid' object has no attribute 'setConst'" (also when stepping frames of a
REPLAY cache), then abort ("can't clean grid cache"). The executable's bake works.

Cycles (the `bpy` module renders, and imports a VDB as a volume object):

    python scenes/tools/bake_blender_smoke.py --cycles out.exr [--vdb scenes/blender-smoke.vdb] \\
        [--size 128] [--spp 256] [--step-rate 1.0]

The cache's grids are in the domain's cells times the cell size, from the domain's lowest
corner, so the volume object sits at that corner, (−1.25, −1.25, −0.95) (Blender puts a voxel's
centre half a voxel above its index, as mantaflow's cells are; glint, as OpenVDB, at the index,
so scenes/blender-smoke.toml adds the half voxel to its translation). Its material is a
Principled Volume of the glint medium's `density` and `color` and anisotropy `g`, absorption
colour black, so that σs = density · color and σa = density · (1 − color) as in glint.
"""

import json
import math
import os
import shutil
import sys
import tempfile

import bpy

# The scene, shared with scenes/blender-smoke.toml (which has it in glint's y-up axes:
# Blender's (x, y, z) is glint's (x, z, −y)).
EMITTER = dict(size=0.5, location=(0.0, 0.0, 0.3))
CORNER = (-1.25, -1.25, -0.95)  # the domain's lowest corner (Quick Smoke's domain)
DENSITY, COLOR, G = 8.0, 0.9, 0.3  # [media.smoke] density, color, g
CAMERA = dict(eye=(0.0, -5.5, 0.9), target=(0.0, 0.0, 0.9), vfov=40.0)
SUN = dict(direction=(-0.6, 0.4, -0.7), irradiance=3.0)  # the way the light travels
SKY = 0.15  # the background, a constant radiance
FLOOR = 0.5  # a diffuse floor at z = −0.95 (glint's y = −0.95), 20 × 20


def args():
    argv = sys.argv[sys.argv.index("--") + 1 :] if "--" in sys.argv else sys.argv[1:]
    out = dict(res=32, frame=24, out="scenes/blender-smoke.vdb", facts=None, cycles=None,
               vdb="scenes/blender-smoke.vdb", size=128, spp=256, step_rate=1.0)
    it = iter(argv)
    for a in it:
        key = a.lstrip("-").replace("-", "_")
        if key not in out:
            sys.exit(f"unknown argument {a}")
        value = next(it)
        out[key] = type(out[key])(value) if out[key] is not None else value
    return out


def bake(a):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.mesh.primitive_cube_add(**EMITTER)
    bpy.ops.object.quick_smoke()
    domain = next(o for o in bpy.context.scene.objects if o.name.startswith("Smoke Domain"))
    settings = domain.modifiers["Fluid"].domain_settings
    cache = tempfile.mkdtemp(prefix="glint-smoke-")
    settings.resolution_max = a["res"]
    settings.cache_type = "ALL"
    settings.cache_data_format = "OPENVDB"  # Blender's defaults, kept:
    settings.openvdb_cache_compress_type = "BLOSC"
    settings.openvdb_data_depth = "16"  # half floats
    settings.cache_directory = cache
    settings.cache_frame_start = 1
    settings.cache_frame_end = a["frame"]
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, a["frame"]
    with bpy.context.temp_override(object=domain, active_object=domain, scene=scene):
        result = bpy.ops.fluid.bake_all()
    path = os.path.join(cache, "data", f"fluid_data_{a['frame']:04d}.vdb")
    if result != {"FINISHED"} or not os.path.exists(path):
        sys.exit(f"the bake did not write {path} ({result}); see the errors above")
    # Load the frame from the cache and read the domain's own density grid.
    scene.frame_set(a["frame"])
    domain = bpy.context.evaluated_depsgraph_get().objects[domain.name]
    settings = domain.modifiers["Fluid"].domain_settings
    density = list(settings.density_grid)
    res = list(settings.domain_resolution)
    kept = [d for d in density if d > settings.clipping]
    facts = dict(
        blender=bpy.app.version_string,
        file=os.path.basename(path),
        bytes=os.path.getsize(path),
        compression=settings.openvdb_cache_compress_type,
        data_depth=settings.openvdb_data_depth,
        clipping=settings.clipping,
        domain_location=list(domain.matrix_world.translation),
        domain_dimensions=list(domain.dimensions),
        domain_resolution=res,
        cell_size=list(settings.cell_size),
        density_cells=len(density),
        density_sum=math.fsum(density),
        density_max=max(density),
        density_above_clipping=len(kept),
    )
    # The cells above the clipping, as index bounds (x fastest in density_grid).
    at = [i for i, d in enumerate(density) if d > settings.clipping]
    xs = [i % res[0] for i in at]
    ys = [(i // res[0]) % res[1] for i in at]
    zs = [i // (res[0] * res[1]) for i in at]
    facts["active_lo"] = [min(xs), min(ys), min(zs)]
    facts["active_hi"] = [max(xs), max(ys), max(zs)]
    os.makedirs(os.path.dirname(os.path.abspath(a["out"])), exist_ok=True)
    shutil.copyfile(path, a["out"])
    text = json.dumps(facts, indent=1)
    print(text)
    if a["facts"]:
        with open(a["facts"], "w") as f:
            f.write(text + "\n")
    shutil.rmtree(cache)


def cycles(a):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = a["spp"]
    scene.cycles.use_denoising = False
    scene.cycles.max_bounces = 8
    scene.cycles.volume_bounces = 8
    scene.cycles.volume_step_rate = a["step_rate"]  # ray marching's step, times the voxel size
    scene.cycles.transparent_max_bounces = 8
    scene.cycles.sample_clamp_indirect = 0.0
    scene.render.resolution_x = scene.render.resolution_y = a["size"]
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = "Standard"
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"

    bpy.ops.object.volume_import(filepath=os.path.abspath(a["vdb"]), location=CORNER)
    volume = bpy.context.active_object
    volume.location = CORNER
    material = bpy.data.materials.new("smoke")
    material.use_nodes = True
    nodes = material.node_tree.nodes
    nodes.clear()
    principled = nodes.new("ShaderNodeVolumePrincipled")
    principled.inputs["Color"].default_value = (COLOR, COLOR, COLOR, 1.0)
    principled.inputs["Density"].default_value = DENSITY
    principled.inputs["Anisotropy"].default_value = G
    principled.inputs["Absorption Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    output = nodes.new("ShaderNodeOutputMaterial")
    material.node_tree.links.new(principled.outputs["Volume"], output.inputs["Volume"])
    volume.data.materials.append(material)

    bpy.ops.mesh.primitive_plane_add(size=20.0, location=(0.0, 0.0, CORNER[2]))
    floor = bpy.data.materials.new("floor")
    floor.use_nodes = True
    nodes = floor.node_tree.nodes
    nodes.clear()
    diffuse = nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (FLOOR, FLOOR, FLOOR, 1.0)
    output = nodes.new("ShaderNodeOutputMaterial")
    floor.node_tree.links.new(diffuse.outputs["BSDF"], output.inputs["Surface"])
    bpy.context.active_object.data.materials.append(floor)

    world = bpy.data.worlds.new("sky")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (SKY, SKY, SKY, 1.0)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 1.0
    scene.world = world

    from mathutils import Vector

    sun = bpy.data.lights.new("sun", "SUN")
    sun.energy = SUN["irradiance"]
    sun.angle = 0.0
    sun_object = bpy.data.objects.new("sun", sun)
    scene.collection.objects.link(sun_object)
    sun_object.rotation_euler = Vector(SUN["direction"]).to_track_quat("-Z", "Y").to_euler()

    camera = bpy.data.cameras.new("camera")
    camera.sensor_fit = "VERTICAL"
    camera.angle_y = math.radians(CAMERA["vfov"])
    camera_object = bpy.data.objects.new("camera", camera)
    scene.collection.objects.link(camera_object)
    camera_object.location = CAMERA["eye"]
    look = Vector(CAMERA["target"]) - Vector(CAMERA["eye"])
    camera_object.rotation_euler = look.to_track_quat("-Z", "Y").to_euler()
    scene.camera = camera_object

    scene.render.filepath = os.path.abspath(a["cycles"])
    bpy.ops.render.render(write_still=True)


if __name__ == "__main__":
    options = args()
    if options["cycles"]:
        cycles(options)
    else:
        bake(options)
