"""The add-on's speed against Cycles (issue 61): the test scene (tests/scenes.py) at W × W/2 per
eye, equirect spherical stereo; the add-on's whole operator (export included) against Cycles'
render of both eyes at 64 and 128 samples, the same machine and threads.

    TWISTER_BIN=target/release/twister python blender/bench.py [WIDTH]   (a Python with bpy 4.5)

Prints one JSON object (seconds)."""

import json
import math
import pathlib
import sys
import tempfile
import time

import bpy

HERE = pathlib.Path(__file__).resolve().parent
sys.path[:0] = [str(HERE), str(HERE / "tests")]
import twister_blender  # noqa: E402
from scenes import build_scene  # noqa: E402

width = int(sys.argv[1]) if len(sys.argv) > 1 else 2048
out = {"width": width, "height": width // 2}
with tempfile.TemporaryDirectory() as tmp:
    bpy.ops.wm.read_factory_settings(use_empty=True)
    twister_blender.register()
    build_scene()
    scene = bpy.context.scene
    t = scene.twister
    t.panorama, t.width, t.output_dir = "equirect", width, f"{tmp}/twister"
    for k in range(2):  # the first opens the device and builds the pipelines
        start = time.perf_counter()
        assert bpy.ops.twister.render() == {"FINISHED"}
        out["twister_first_s" if k == 0 else "twister_s"] = time.perf_counter() - start
    from twister_blender import run

    out["via"] = "package" if run.package() else "command"
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = width, width // 2, 100
    scene.render.use_multiview = True
    scene.render.views_format = "STEREO_3D"
    scene.render.image_settings.views_format = "INDIVIDUAL"
    scene.render.filepath = f"{tmp}/cycles"
    for samples in (64, 128):
        scene.cycles.samples = samples
        scene.cycles.use_adaptive_sampling = False
        start = time.perf_counter()
        bpy.ops.render.render(write_still=True)
        out[f"cycles_{samples}_s"] = time.perf_counter() - start
    for samples in (64, 128):
        out[f"speedup_{samples}"] = out[f"cycles_{samples}_s"] / out["twister_s"]
print(json.dumps(out, indent=2), flush=True)
# Blender as a module hangs on its way out while any Python class is still registered.
twister_blender.unregister()
