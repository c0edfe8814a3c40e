# Renders a glTF file with Cycles as glint's helmet comparison does: glint's camera (eye on +z
# in glTF's Y-up frame, looking at the origin, vertical field of view), an equirectangular
# environment map turned to glint's orientation, the same bounces, a near-box pixel filter,
# linear EXR out. Usage: blender -b --python render.py -- MODEL ENV OUT.exr SIZE SPP EYE_Z VFOV
# [EYE_X EYE_Y] (the eye moved across, still looking along −z: glint's target (EYE_X, EYE_Y, 0))
import bpy, math, os, sys
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
from cycles_world import glint_world
import numpy
# Debian 12 Blender 3.4 glTF importer uses np.bool, which newer NumPy removed.
if not hasattr(numpy, "bool") or numpy.bool is not bool:
    numpy.bool = bool
argv = sys.argv[sys.argv.index("--") + 1:]
model, env, out, size, spp, eye_z, vfov = argv[0], argv[1], argv[2], int(argv[3]), int(argv[4]), float(argv[5]), float(argv[6])
eye_x, eye_y = (float(argv[7]), float(argv[8])) if len(argv) > 8 else (0.0, 0.0)
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=model)
scene = bpy.context.scene
# glTF (x, y, z) is Blender (x, -z, y): glint's eye (x, y, eye_z) is Blender (x, -eye_z, y).
cam_data = bpy.data.cameras.new("cam")
cam_data.sensor_fit = 'VERTICAL'
cam_data.angle_y = math.radians(vfov)
cam = bpy.data.objects.new("cam", cam_data)
cam.location = (eye_x, -eye_z, eye_y)
cam.rotation_euler = (math.radians(90.0), 0.0, 0.0)
scene.collection.objects.link(cam)
scene.camera = cam
glint_world(scene, environment=env)
scene.render.engine = 'CYCLES'
cycles = scene.cycles
cycles.device = 'CPU'
cycles.samples = spp
cycles.use_adaptive_sampling = False
cycles.use_denoising = False
cycles.max_bounces = 8
cycles.diffuse_bounces = cycles.glossy_bounces = cycles.transmission_bounces = 8
cycles.volume_bounces = 0
cycles.transparent_max_bounces = 8
cycles.sample_clamp_direct = cycles.sample_clamp_indirect = 0.0
cycles.caustics_reflective = cycles.caustics_refractive = True
cycles.blur_glossy = 0.0
cycles.filter_width = 0.01
cycles.seed = 1
scene.render.resolution_x = scene.render.resolution_y = size
scene.render.resolution_percentage = 100
scene.view_settings.view_transform = 'Standard'
scene.render.image_settings.file_format = 'OPEN_EXR'
scene.render.image_settings.color_depth = '32'
scene.render.filepath = out
bpy.ops.render.render(write_still=True)
