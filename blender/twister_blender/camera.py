"""The active camera as twister's viewer and eyes (no bpy here: plain numbers in, settings out).

Blender is Z-up, twister Y-up: a point (x, y, z) in Blender is (x, z, −y) in twister. A camera
looks along its local −Z; twister's viewer looks along −z at yaw 0 and a positive yaw turns it
left (counter-clockwise seen from above), as a rotation about Blender's Z does. Cycles' spherical
stereo puts the eyes on a circle of radius interocular/2 about the camera (twister's d_e), its
rays parallel (tangent to that circle) or converging at the convergence distance, faded towards
the poles between the pole-merge angles."""

from __future__ import annotations

import math
from typing import Dict, Optional, Sequence, Tuple

# A pitch or roll smaller than this (degrees) is taken as level.
LEVEL_DEG = 0.5


def viewer_from_blender(location: Sequence[float]) -> Tuple[float, float, float]:
    """A Blender point (Z-up) in twister's frame (Y-up)."""
    x, y, z = location
    return (x, z, -y)


def view_angles(forward: Sequence[float], up: Sequence[float]) -> Tuple[float, float, float]:
    """(yaw, pitch, roll) in degrees of a camera whose view direction and up vector are given in
    Blender's world frame: yaw 0 looks along Blender's +Y (twister's −z), positive left."""
    fx, fy, fz = forward
    horizontal = math.hypot(fx, fy)
    yaw = math.degrees(math.atan2(-fx, fy)) if horizontal > 1e-9 else 0.0
    pitch = math.degrees(math.atan2(fz, horizontal))
    # Roll: the up vector's tilt away from the plane through the view direction and world Z.
    if horizontal > 1e-9:
        right = (fy / horizontal, -fx / horizontal, 0.0)
        roll = math.degrees(math.asin(max(-1.0, min(1.0, sum(r * u for r, u in zip(right, up))))))
    else:
        roll = 0.0
    return yaw, pitch, roll


def eyes_from_stereo(
    interocular: float,
    convergence_mode: str,
    convergence_distance: float,
    use_spherical_stereo: bool,
    use_pole_merge: bool,
    pole_from_rad: float,
    pole_to_rad: float,
) -> Dict[str, object]:
    """Cycles' stereo settings as twister's: eye_radius, convergence, pole_merge."""
    eyes: Dict[str, object] = {"eye_radius": interocular / 2 if use_spherical_stereo else 0.0}
    eyes["convergence"] = "parallel" if convergence_mode == "PARALLEL" else f"{convergence_distance:g}"
    if use_pole_merge:
        eyes["pole_merge"] = f"{math.degrees(pole_from_rad):g},{math.degrees(pole_to_rad):g}"
    else:
        eyes["pole_merge"] = "off"
    return eyes


def level_warning(pitch: float, roll: float) -> Optional[str]:
    """One line saying a tilted camera's pitch and roll are not followed, or None."""
    if abs(pitch) < LEVEL_DEG and abs(roll) < LEVEL_DEG:
        return None
    return (
        f"the camera's pitch ({pitch:.1f}°) and roll ({roll:.1f}°) are ignored: "
        "twister's panoramas stay level (only the turn about the vertical axis is followed)"
    )
