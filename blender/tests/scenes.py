"""The add-on's test scene, built in Blender: a closed room, spheres and boxes at several
distances, one straddling the seam behind the camera, each a flat emissive colour, and a
spherical-stereo camera at eye height (shared by the tests and blender/bench.py)."""

import math

import bpy

# Flat emissive colours (linear), far apart once shown: each object one, the room one.
COLOURS = {
    "room": (0.35, 0.35, 0.35),
    "near": (0.9, 0.05, 0.05),
    "far": (0.05, 0.9, 0.05),
    "seam": (0.05, 0.05, 0.9),
    "up": (0.9, 0.9, 0.05),
    "box": (0.9, 0.05, 0.9),
}


def emissive(name):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (0, 0, 0, 1)
    bsdf.inputs["Emission Color"].default_value = (*COLOURS[name], 1)
    bsdf.inputs["Emission Strength"].default_value = 1.0
    bsdf.inputs["Specular IOR Level"].default_value = 0.0
    bsdf.inputs["Roughness"].default_value = 1.0
    return mat


def add(obj_op, name, **kw):
    obj_op(**kw)
    obj = bpy.context.active_object
    obj.name = name
    obj.data.materials.append(emissive(name))
    return obj


def build_scene(interocular=0.064, pole_merge=(60, 75)):
    """A closed room, spheres and boxes at several distances, one straddling the seam behind the
    camera, and a stereo camera at eye height looking along +Y."""
    add(bpy.ops.mesh.primitive_cube_add, "room", size=8.0, location=(0, 0, 1.5))
    add(bpy.ops.mesh.primitive_uv_sphere_add, "near", radius=0.3, location=(0.4, 1.2, 1.5), segments=48, ring_count=24)
    add(bpy.ops.mesh.primitive_uv_sphere_add, "far", radius=0.6, location=(-1.5, 3.0, 1.0), segments=48, ring_count=24)
    add(bpy.ops.mesh.primitive_uv_sphere_add, "seam", radius=0.5, location=(0.0, -2.5, 1.6), segments=48, ring_count=24)
    add(bpy.ops.mesh.primitive_cube_add, "up", size=0.8, location=(1.0, 0.5, 3.4))
    add(bpy.ops.mesh.primitive_cube_add, "box", size=0.7, location=(2.2, -0.8, 1.2))
    data = bpy.data.cameras.new("stereo")
    data.type = "PANO"
    data.panorama_type = "EQUIRECTANGULAR"
    data.stereo.interocular_distance = interocular
    data.stereo.convergence_mode = "PARALLEL"
    data.stereo.use_spherical_stereo = True
    data.stereo.use_pole_merge = pole_merge is not None
    if pole_merge:
        data.stereo.pole_merge_angle_from, data.stereo.pole_merge_angle_to = map(math.radians, pole_merge)
    camera = bpy.data.objects.new("camera", data)
    bpy.context.scene.collection.objects.link(camera)
    camera.location = (0.0, 0.0, 1.5)
    camera.rotation_euler = (math.radians(90), 0.0, 0.0)
    bpy.context.scene.camera = camera
    return camera


