"""A glTF scene to a VR180 pair plus a depth map: the side-by-side image players take, and each
eye's distance in metres as EXR.

    python examples/python/port_gltf.py SCENE.glb OUT_DIR [WIDTH]

Without a scene it ports the built-in room."""

import sys

import numpy as np

import twister

scene = sys.argv[1] if len(sys.argv) > 1 else "builtin:demo"
out = sys.argv[2] if len(sys.argv) > 2 else "vr180"
width = int(sys.argv[3]) if len(sys.argv) > 3 else 2048
r = twister.Renderer()
placement = {} if scene.startswith("builtin:") else {"fit": 3.0}
frame = r.render(scene, panorama="vr180", width=width, depth=True, **placement)
for path in frame.save(out):
    print(path)
left, _ = frame.depth
seen = np.isfinite(left)
print(f"depth: {seen.mean() * 100:.0f} % of the left eye's pixels see the scene, {left[seen].min():.2f}–{left[seen].max():.2f} m")
