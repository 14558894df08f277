"""The add-on's settings as twister's (no bpy here): the scene's `scene.twister` values, the
camera and the world, turned into the keyword arguments of `twister.Renderer.render` (the
command line's options in snake case)."""

from __future__ import annotations

import math
from typing import Dict, List, Optional, Tuple

PANORAMAS = ("cylinder", "equirect", "vr180", "fisheye", "cubemap")
LAYOUTS = ("default", "eyes", "top-bottom", "side-by-side", "twister")
METHODS = ("adaptive", "adaptive:length", "vertex", "fixed:4", "fixed:8", "trace")
FORMATS = ("png", "jpg")


def render_settings(
    props: Dict[str, object],
    camera: Optional[Dict[str, object]],
    world: Optional[Dict[str, object]],
) -> Tuple[Dict[str, object], List[str]]:
    """(settings, warnings) for a render: `props` the scene.twister values, `camera` the active
    camera's (viewer, yaw, pitch, roll, eyes), `world` the environment (image, strength, yaw)."""
    from . import camera as cam

    warnings: List[str] = []
    s: Dict[str, object] = {
        "panorama": props["panorama"],
        "method": props["method"],
        "width": props["width"],
        "samples": props["samples"],
        "anisotropy": props["anisotropy"],
        "format": props["format"],
        "depth": bool(props["depth"]),
    }
    if props.get("height"):
        s["height"] = props["height"]
    if props.get("layout", "default") != "default":
        s["layout"] = props["layout"]
    if camera is not None:
        s["viewer"] = camera["viewer"]
        pitch, roll = float(camera["pitch"]), float(camera["roll"])
        if props["panorama"] == "fisheye":
            # A dome camera looks up: its tilt from the zenith is the dome's.
            tilt = 90.0 - pitch
            if abs(tilt) >= cam.LEVEL_DEG:
                s["dome_tilt"] = max(-90.0, min(90.0, tilt))
            pitch = 0.0
        s["yaw"] = camera["yaw"]
        warning = cam.level_warning(pitch, roll)
        if warning:
            warnings.append(warning)
        if props.get("eyes_from_camera", True):
            s.update(camera["eyes"])
    if not props.get("eyes_from_camera", True) or camera is None:
        s["eye_radius"] = props["eye_radius"]
    if props["panorama"] not in ("equirect", "vr180", "fisheye", "cubemap"):
        s.pop("convergence", None)
        s.pop("pole_merge", None)
    if world and world.get("image"):
        s["environment"] = world["image"]
        s["environment_yaw"] = world.get("yaw_deg", 0.0)
        strength = float(world.get("strength", 1.0))
        if strength > 0:
            s["exposure"] = math.log2(strength)
        s["lighting"] = "pbr"
    return s, warnings
