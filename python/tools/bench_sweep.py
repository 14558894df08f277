"""The Python package's benchmark (issue 60's goals), release builds:

1. a sweep of N renders (demo room, equirect 512x256, one sample, the eye radius varied) in one
   Renderer against N `twister render` processes with the same settings (each writes its PNGs,
   as a process sweep must): the Renderer's frames kept in memory, and saved as the processes do;
2. resident memory after 1,000 renders against after 100, in one Renderer.

    python python/tools/bench_sweep.py [--renders 50] [--memory 1000] [--cli target/release/twister]

Prints one JSON object (times in seconds, memory in MiB)."""

from __future__ import annotations

import argparse
import json
import os
import pathlib
import resource
import subprocess
import tempfile
import time

import twister

ROOT = pathlib.Path(__file__).resolve().parents[2]
SETTINGS = {"panorama": "equirect", "width": 512, "samples": 1}


def rss_mib() -> float:
    """Resident memory now (Linux: /proc/self/statm), MiB."""
    with open("/proc/self/statm") as f:
        pages = int(f.read().split()[1])
    return pages * os.sysconf("SC_PAGE_SIZE") / 2**20


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--renders", type=int, default=50)
    parser.add_argument("--memory", type=int, default=1000)
    parser.add_argument("--cli", default=str(ROOT / "target" / "release" / "twister"))
    a = parser.parse_args()
    radii = [0.064 * k / max(1, a.renders - 1) for k in range(a.renders)]
    out: dict = {"renders": a.renders, "settings": SETTINGS}

    with tempfile.TemporaryDirectory() as tmp:
        start = time.perf_counter()
        for k, d_e in enumerate(radii):
            args = [a.cli, "render", "builtin:demo", "--panorama=equirect", "--width=512", "--samples=1"]
            args += [f"--eye-radius={d_e}", f"--out={tmp}/{k}"]
            subprocess.run(args, check=True, capture_output=True)
        out["processes_s"] = time.perf_counter() - start

    start = time.perf_counter()
    r = twister.Renderer()
    for d_e in radii:
        r.render("builtin:demo", eye_radius=d_e, **SETTINGS)
    out["renderer_s"] = time.perf_counter() - start
    out["speedup"] = out["processes_s"] / out["renderer_s"]
    # The same sweep writing each frame's PNGs as the processes do.
    with tempfile.TemporaryDirectory() as tmp:
        start = time.perf_counter()
        for k, d_e in enumerate(radii):
            r.render("builtin:demo", eye_radius=d_e, **SETTINGS).save(f"{tmp}/{k}")
        out["renderer_saving_s"] = time.perf_counter() - start
    out["speedup_saving"] = out["processes_s"] / out["renderer_saving_s"]
    out["adapter"] = r.adapter
    out["adapters_opened"] = r.stats["adapters_opened"]

    if a.memory:
        for k in range(a.memory):
            r.render("builtin:demo", eye_radius=radii[k % len(radii)], **SETTINGS)
            if k + 1 == min(100, a.memory):
                out["rss_after_100_mib"] = rss_mib()
        out["rss_after_%d_mib" % a.memory] = rss_mib()
        out["rss_growth_mib"] = out["rss_after_%d_mib" % a.memory] - out["rss_after_100_mib"]
        out["max_rss_mib"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
