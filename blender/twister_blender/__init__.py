"""twister for Blender: the open scene's omnidirectional stereo (the TWISTER display's cylinder,
equirect, VR180, fisheye, cubemap) in seconds, from the active camera's place and stereo
settings, as Cycles' spherical stereo frames it. A Blender extension (blender_manifest.toml)
that also installs as a legacy add-on."""

bl_info = {
    "name": "twister",
    "author": "twister",
    "version": (0, 1, 0),
    "blender": (4, 2, 0),
    "location": "Properties > Output > twister",
    "description": "Omnidirectional stereo from the open scene with twister",
    "category": "Render",
}

from . import camera, ops, props, run, scene_export, settings  # noqa: F401


def register():
    props.register()
    ops.register()


def unregister():
    ops.unregister()
    props.unregister()
