"""The open Blender scene for twister: exported with Blender's own glTF exporter (visible
objects, modifiers applied, materials, punctual lights, animation), the active camera as the
viewer and its stereo settings as the eyes, the world's Environment Texture as the environment;
what cannot be carried over listed as warnings."""

from __future__ import annotations

import math
import os
from typing import Dict, List, Optional, Tuple

import bpy

from . import camera as cam

# Shader nodes twister's glTF look renders (the exporter turns them into glTF materials).
KNOWN_NODES = {
    "BSDF_PRINCIPLED", "OUTPUT_MATERIAL", "TEX_IMAGE", "NORMAL_MAP", "MAPPING", "TEX_COORD", "UVMAP",
    "SEPRGB", "SEPARATE_COLOR", "EMISSION", "MIX_SHADER", "BSDF_TRANSPARENT", "ADD_SHADER", "VERTEX_COLOR",
}


def camera_settings(scene: bpy.types.Scene) -> Optional[Dict[str, object]]:
    """The active camera as the viewer (twister's frame), its yaw, pitch and roll, and its eyes."""
    camera = scene.camera
    if camera is None:
        return None
    bpy.context.view_layer.update()  # the camera's world matrix as its settings now say
    m = camera.matrix_world
    forward = tuple(m.to_3x3() @ bpy_vector((0.0, 0.0, -1.0)))
    up = tuple(m.to_3x3() @ bpy_vector((0.0, 1.0, 0.0)))
    if math.hypot(forward[0], forward[1]) < 1e-3:
        # Looking straight up or down (a dome): the image's front is where the camera's up
        # vector points away from.
        yaw, _, _ = cam.view_angles(tuple(-c for c in up), (0.0, 0.0, 1.0))
        pitch, roll = (90.0 if forward[2] > 0 else -90.0), 0.0
    else:
        yaw, pitch, roll = cam.view_angles(forward, up)
    stereo = camera.data.stereo
    eyes = cam.eyes_from_stereo(
        stereo.interocular_distance,
        stereo.convergence_mode,
        stereo.convergence_distance,
        stereo.use_spherical_stereo,
        stereo.use_pole_merge,
        stereo.pole_merge_angle_from,
        stereo.pole_merge_angle_to,
    )
    viewer = cam.viewer_from_blender(tuple(m.translation))
    return {"viewer": viewer, "yaw": yaw, "pitch": pitch, "roll": roll, "eyes": eyes}


def bpy_vector(v):
    from mathutils import Vector

    return Vector(v)


# Where twister draws a Blender world map's azimuth 0 (degrees): see `world_settings`.
BLENDER_MAP_YAW = 90.0


def world_settings(scene: bpy.types.Scene) -> Tuple[Optional[Dict[str, object]], List[str]]:
    """The world's Environment Texture (image path, strength, rotation about Z), or None."""
    world = scene.world
    if world is None or not world.use_nodes:
        return None, []
    nodes = world.node_tree.nodes
    background = next((n for n in nodes if n.type == "BACKGROUND"), None)
    texture = next((n for n in nodes if n.type == "TEX_ENVIRONMENT"), None)
    if background is None or texture is None or texture.image is None:
        return None, []
    path = bpy.path.abspath(texture.image.filepath)
    if not os.path.isfile(path) or not path.lower().endswith((".hdr", ".exr")):
        return None, [f"the world's environment image {texture.image.name!r} is not an .hdr or .exr file on disk: not carried over"]
    mapping = next((n for n in nodes if n.type == "MAPPING"), None)
    # Blender's equirectangular image has its centre towards −X; twister's towards −z, Blender's
    # +Y: the same map turned a quarter turn. A mapping's turn about Z turns the lookup, so what
    # the map shows turns the other way, which in twister's azimuth (clockwise seen from above)
    # is the same sign.
    turn = math.degrees(mapping.inputs["Rotation"].default_value[2]) if mapping is not None else 0.0
    yaw = BLENDER_MAP_YAW + turn
    strength = background.inputs["Strength"].default_value
    return {"image": path, "strength": strength, "yaw_deg": yaw}, []


def unsupported(scene: bpy.types.Scene) -> List[str]:
    """What the export cannot carry over: volumes, shader nodes twister does not render."""
    warnings = []
    for obj in scene.objects:
        if not obj.visible_get() or obj.type not in {"MESH", "CURVE", "SURFACE", "META", "FONT"}:
            continue
        if obj.type == "MESH" and any(m.type == "VOLUME_TO_MESH" for m in obj.modifiers):
            warnings.append(f"{obj.name}: volume modifiers are not carried over")
        for slot in obj.material_slots:
            mat = slot.material
            if mat is None or not mat.use_nodes:
                continue
            output = next((n for n in mat.node_tree.nodes if n.type == "OUTPUT_MATERIAL"), None)
            if output is not None and output.inputs["Volume"].is_linked:
                warnings.append(f"{mat.name}: its volume shader is not carried over")
            other = sorted({n.bl_idname for n in mat.node_tree.nodes if n.type not in KNOWN_NODES and n.type != "FRAME" and n.type != "REROUTE"})
            if other:
                warnings.append(f"{mat.name}: shader nodes {', '.join(other)} are not carried over (the exporter bakes what it can)")
    return sorted(set(warnings))


def export(scene: bpy.types.Scene, folder: str, animation: bool = False) -> str:
    """The visible scene as a glTF binary in `folder` (Y up, modifiers applied, lights)."""
    path = os.path.join(folder, "scene.glb")
    bpy.ops.export_scene.gltf(
        filepath=path,
        export_format="GLB",
        use_visible=True,
        export_apply=True,
        export_yup=True,
        export_cameras=False,
        export_lights=True,
        export_animations=animation,
    )
    return path


def has_geometry(scene: bpy.types.Scene) -> bool:
    return any(o.visible_get() and o.type in {"MESH", "CURVE", "SURFACE", "META", "FONT"} for o in scene.objects)
