"""The display-position error and the eyes' disparity against the eye radius d_e (seed 002 §4):
one renderer, one device, a sweep of renders; a plot with matplotlib.

    python examples/python/sweep_eye_radius.py [OUT.png]

TWISTER_QUICK=1 runs a small sweep (the test suite does)."""

import os
import sys

import numpy as np

import twister

quick = os.environ.get("TWISTER_QUICK") == "1"
radii = np.linspace(0.0, 0.064, 4 if quick else 17)
size = {"width": 256 if quick else 1024, "samples": 1}
r = twister.Renderer()
errors, disparities = [], []
for d_e in radii:
    result = r.error("builtin:demo", method="adaptive", eye_radius=float(d_e), **size)
    errors.append(result["mean_px"])
    # The disparity (seed 002 eq. 2): the eyes draw a point 2α apart, α = acos(d_e/r) −
    # acos(d_e/R_T), r its distance from the axis: from each pixel's depth d along the eye's
    # tangent ray, r = √(d² + d_e²) (rays near the horizon). In pixels: 2α · W / 2π.
    frame = r.render("builtin:demo", eye_radius=float(d_e), depth=True, **size)
    depth = frame.depth[0]
    d = depth[np.isfinite(depth)]
    screen = frame.stats.get("screen_radius", 1.0)
    dist = np.sqrt(d**2 + d_e**2)
    alpha = np.arccos(np.clip(d_e / dist, -1, 1)) - np.arccos(min(d_e / screen, 1.0))
    disparities.append(float(np.mean(2 * np.abs(alpha)) * frame.width / (2 * np.pi)))
    print(f"d_e {d_e:.3f} m: error {errors[-1]:.3f} px, mean disparity {disparities[-1]:.2f} px")
print(r.stats)

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    sys.exit("matplotlib is not installed: pip install matplotlib (the figures above are the sweep)")
fig, ax = plt.subplots(figsize=(6, 4))
ax.plot(radii * 1000, errors, "o-", label="mean error (px)")
ax.set_xlabel("eye radius d_e (mm)")
ax.set_ylabel("display-position error (px)")
twin = ax.twinx()
twin.plot(radii * 1000, disparities, "s--", color="tab:orange", label="mean disparity (px)")
twin.set_ylabel("mean disparity between the eyes (px)")
fig.legend(loc="upper left")
out = sys.argv[1] if len(sys.argv) > 1 else "sweep_eye_radius.png"
fig.savefig(out, dpi=120, bbox_inches="tight")
print(out)
