"""`scene.twister`: the add-on's settings, stored on the scene; names as the command line's
options (`panorama`, `layout`, `method`, `width`, `samples`, `output_dir`, …)."""

from __future__ import annotations

import bpy

from . import settings as s


def _items(values, names=None):
    return [(v, (names or {}).get(v, v), "") for v in values]


class TwisterSettings(bpy.types.PropertyGroup):
    panorama: bpy.props.EnumProperty(
        name="Panorama",
        items=[
            ("cylinder", "Cylinder", "The TWISTER display's concentric mosaics"),
            ("equirect", "Equirect", "The full sphere, 360° × 180° per eye (Cycles' spherical stereo)"),
            ("vr180", "VR180", "The front half, 180° × 180° per eye"),
            ("fisheye", "Fisheye", "A dome master (the camera looking up)"),
            ("cubemap", "Cubemap", "Six 90° faces per eye, 3×2"),
        ],
        default="equirect",
    )
    layout: bpy.props.EnumProperty(name="Layout", items=_items(s.LAYOUTS), default="default")
    method: bpy.props.EnumProperty(name="Method", items=_items(s.METHODS), default="adaptive")
    width: bpy.props.IntProperty(name="Width per eye", default=2048, min=16, max=32768)
    height: bpy.props.IntProperty(name="Height per eye", description="0: the panorama's own", default=0, min=0, max=32768)
    samples: bpy.props.EnumProperty(name="Samples", items=_items(("1", "2", "4", "8", "16", "32")), default="4")
    anisotropy: bpy.props.IntProperty(name="Anisotropy", default=16, min=1, max=16)
    eyes_from_camera: bpy.props.BoolProperty(
        name="Eyes from the camera", description="Interocular, convergence and pole merge from the camera's stereo settings", default=True
    )
    eye_radius: bpy.props.FloatProperty(name="Eye radius", description="Half the interocular distance, metres", default=0.032, min=0.0, max=1.0)
    output_dir: bpy.props.StringProperty(name="Output folder", subtype="DIR_PATH", default="//twister/")
    format: bpy.props.EnumProperty(name="Format", items=_items(s.FORMATS), default="png")
    depth: bpy.props.BoolProperty(name="Depth", description="Also write each eye's distance as EXR", default=False)
    video: bpy.props.BoolProperty(
        name="Video", description="Animation: also encode twister.mp4 with spherical metadata (ffmpeg; the twister command)", default=False
    )

    def values(self) -> dict:
        return {
            "panorama": self.panorama,
            "layout": self.layout,
            "method": self.method,
            "width": self.width,
            "height": self.height,
            "samples": int(self.samples),
            "anisotropy": self.anisotropy,
            "eyes_from_camera": self.eyes_from_camera,
            "eye_radius": self.eye_radius,
            "format": self.format,
            "depth": self.depth,
        }


class TwisterPreferences(bpy.types.AddonPreferences):
    bl_idname = __package__

    twister_bin: bpy.props.StringProperty(
        name="twister command", description="Used where the twister Python package is not importable (else PATH, TWISTER_BIN)", subtype="FILE_PATH"
    )

    def draw(self, context):
        self.layout.prop(self, "twister_bin")


def preferences(context) -> str:
    addon = context.preferences.addons.get(__package__)
    return addon.preferences.twister_bin if addon is not None else ""


CLASSES = (TwisterSettings, TwisterPreferences)


def register():
    for c in CLASSES:
        bpy.utils.register_class(c)
    bpy.types.Scene.twister = bpy.props.PointerProperty(type=TwisterSettings)


def unregister():
    del bpy.types.Scene.twister
    for c in reversed(CLASSES):
        bpy.utils.unregister_class(c)
