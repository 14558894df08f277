"""Renders an OBJ scene exported by `cargo run --example cycles_reference` with Blender Cycles'
spherical stereo (equirectangular, both eyes) as flat, unlit colours, so that twister's
full-sphere panorama can be checked against Cycles pixel for pixel.

blender -b -P scripts/cycles/render_cycles.py -- SCENE.obj OUT_PREFIX WIDTH CONVERGENCE POLE_FROM POLE_TO [FILTER [PANORAMA]]
    CONVERGENCE: `parallel`, `mono` (no eye offset) or a distance in metres; POLE_FROM/POLE_TO in degrees (`off` for no merge)
    FILTER: `centre` (default: 64 rays at each pixel's centre, no anti-aliasing, for the boundary
    checks) or `box` (1024 rays spread evenly over the pixel, a one-pixel box filter: each pixel
    the share of it each surface covers, for the anti-aliasing checks)
    PANORAMA: `equirect` (default: 360° × 180°, WIDTH × WIDTH/2), `vr180` (longitudes ±90°,
    WIDTH × WIDTH) or `fisheye:FOV` (equidistant, FOV degrees, WIDTH × WIDTH, looking up with the
    front at the bottom: the fulldome master)

Writes OUT_PREFIX_L.png and OUT_PREFIX_R.png.

The scene is in twister's frame (+y up, −z ahead); the importer turns it into Blender's (+z up,
+y ahead): forward −Z, up Y. The camera stands at the origin looking along +y (rotation 90°
about x), so the panorama's centre column looks where twister's does.
"""
import math
import sys

import bpy

argv = sys.argv[sys.argv.index("--") + 1:]
obj_path, out_prefix, width, convergence, pole_from, pole_to = argv[:6]
pixel_filter = argv[6] if len(argv) > 6 else "centre"
panorama = argv[7] if len(argv) > 7 else "equirect"
width = int(width)

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
if hasattr(bpy.ops.wm, "obj_import"):
    bpy.ops.wm.obj_import(filepath=obj_path, forward_axis="NEGATIVE_Z", up_axis="Y")
else:
    bpy.ops.import_scene.obj(filepath=obj_path, axis_forward="-Z", axis_up="Y")

# Flat colours: every material emits its diffuse colour (linear), nothing else lights.
for mat in bpy.data.materials:
    colour = tuple(mat.diffuse_color)
    mat.use_nodes = True
    nodes = mat.node_tree.nodes
    nodes.clear()
    emission = nodes.new("ShaderNodeEmission")
    emission.inputs["Color"].default_value = colour
    emission.inputs["Strength"].default_value = 1.0
    output = nodes.new("ShaderNodeOutputMaterial")
    mat.node_tree.links.new(emission.outputs["Emission"], output.inputs["Surface"])
world = bpy.data.worlds.new("black")
world.use_nodes = True
world.node_tree.nodes["Background"].inputs["Color"].default_value = (0, 0, 0, 1)
scene.world = world

cam_data = bpy.data.cameras.new("ods")
cam_data.type = "PANO"
pano = cam_data if hasattr(cam_data, "panorama_type") else cam_data.cycles
if panorama.startswith("fisheye"):
    pano.panorama_type = "FISHEYE_EQUIDISTANT"
    pano.fisheye_fov = math.radians(float(panorama.split(":")[1]))
else:
    pano.panorama_type = "EQUIRECTANGULAR"
if panorama == "vr180":
    # The front half: Cycles' equirectangular camera's longitude range (Blender 3.x keeps it
    # in the Cycles settings, 4.x on the camera).
    settings = cam_data if hasattr(cam_data, "longitude_min") else cam_data.cycles
    settings.longitude_min = -math.pi / 2
    settings.longitude_max = math.pi / 2
stereo = cam_data.stereo
# `mono`: both eyes at the centre (Cycles' spherical stereo turns the eye circle with the camera's
# own up axis, so a dome camera looking up would put it upright: twister keeps it level).
stereo.interocular_distance = 0.0 if convergence == "mono" else 0.064
if convergence in ("parallel", "mono"):
    stereo.convergence_mode = "PARALLEL"
else:
    stereo.convergence_mode = "OFFAXIS"
    stereo.convergence_distance = float(convergence)
stereo.use_spherical_stereo = True
if pole_from == "off":
    stereo.use_pole_merge = False
else:
    stereo.use_pole_merge = True
    stereo.pole_merge_angle_from = math.radians(float(pole_from))
    stereo.pole_merge_angle_to = math.radians(float(pole_to))
cam = bpy.data.objects.new("ods", cam_data)
scene.collection.objects.link(cam)
cam.location = (0, 0, 0)
# Looking ahead (+y) for the equirect; up (+z) with the image's top towards the back for the dome.
cam.rotation_euler = (math.pi, 0, 0) if panorama.startswith("fisheye") else (math.pi / 2, 0, 0)
scene.camera = cam

scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.use_denoising = False
if pixel_filter == "box":
    # Rays spread uniformly over the pixel: its value is the mean over its area.
    scene.cycles.samples = 1024
    scene.cycles.pixel_filter_type = "BOX"
    scene.cycles.filter_width = 1.0
else:
    # Rays at the pixel's centre: no anti-aliasing (the boundary checks snap colours).
    scene.cycles.samples = 64
    scene.cycles.filter_width = 0.01
scene.cycles.max_bounces = 0
scene.render.resolution_x = width
scene.render.resolution_y = width // 2 if panorama == "equirect" else width
scene.render.resolution_percentage = 100
scene.view_settings.view_transform = "Standard"
scene.view_settings.look = "None"
scene.render.image_settings.file_format = "PNG"
scene.render.image_settings.color_mode = "RGB"
scene.render.use_multiview = True
scene.render.views_format = "STEREO_3D"
scene.render.image_settings.views_format = "INDIVIDUAL"
scene.render.filepath = out_prefix
bpy.ops.render.render(write_still=True)
