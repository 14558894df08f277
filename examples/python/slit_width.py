"""The paper's speed comparison (seed 002 §4.2): the slit renderer at several slit widths against
`adaptive`, timed on one renderer; a plot with matplotlib.

    python examples/python/slit_width.py [OUT.png]

TWISTER_QUICK=1 times small images once each (the test suite does)."""

import os
import sys

import twister

quick = os.environ.get("TWISTER_QUICK") == "1"
widths = [4, 16] if quick else [1, 2, 4, 8, 16, 32]
methods = ["adaptive"] + [f"slit:{w}" for w in widths]
r = twister.Renderer()
rows = r.bench_speed(["builtin:demo"], methods=methods, reps=1 if quick else 5, width=256 if quick else 1584)
ms = {row["method"]: row["ms_frame"] for row in rows}
for m in methods:
    print(f"{m:10s} {ms[m]:8.2f} ms  ({ms[m] / ms['adaptive']:.2f} × adaptive)")

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    sys.exit("matplotlib is not installed: pip install matplotlib (the table above is the comparison)")
fig, ax = plt.subplots(figsize=(6, 4))
ax.plot(widths, [ms[f"slit:{w}"] for w in widths], "o-", label="slit renderer")
ax.axhline(ms["adaptive"], color="tab:green", label="adaptive (one pass)")
ax.set_xscale("log", base=2)
ax.set_xlabel("slit width (px)")
ax.set_ylabel("frame time (ms)")
ax.legend()
out = sys.argv[1] if len(sys.argv) > 1 else "slit_width.png"
fig.savefig(out, dpi=120, bbox_inches="tight")
print(out)
