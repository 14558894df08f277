"""A sweep reuses one device; threads share a renderer; Ctrl-C stops a sweep between frames; the
stub declares every setting; help() lists them; the examples run."""

from __future__ import annotations

import ast
import os
import pathlib
import signal
import subprocess
import sys
import threading
import time

import numpy as np

import twister
from conftest import ROOT


def test_a_sweep_opens_one_adapter_and_reuses_it():
    before = twister.Renderer().stats["adapters_opened"]
    r = twister.Renderer()
    frames = [r.render("builtin:demo", width=64, samples=1, eye_radius=d) for d in (0.0, 0.02, 0.04, 0.06)]
    assert r.stats["adapters_opened"] == before + 1 and r.stats["renders"] == 4
    assert not np.array_equal(frames[0].left, frames[3].left), "the eye radius changes the image"


def test_two_threads_share_one_renderer_and_draw_what_each_would_alone(renderer):
    radii = [0.01, 0.05]
    alone = [renderer.render("builtin:demo", width=64, samples=1, eye_radius=d).left for d in radii]
    results: dict = {}
    errors: list = []

    def work(k):
        try:
            for _ in range(3):
                results.setdefault(k, []).append(renderer.render("builtin:demo", width=64, samples=1, eye_radius=radii[k]).left)
        except Exception as e:  # noqa: BLE001 - reported below
            errors.append(e)

    threads = [threading.Thread(target=work, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors
    for k in range(2):
        assert all(np.array_equal(a, alone[k]) for a in results[k]), k


def test_the_gil_is_released_while_the_gpu_works(renderer):
    ticks = []
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    t = threading.Thread(target=count)
    t.start()
    start = time.perf_counter()
    renderer.render("builtin:demo", width=256, samples=4, method="adaptive")
    end = time.perf_counter()
    stop.set()
    t.join()
    during = [x for x in ticks if start < x < end]
    assert len(during) >= 0.3 * (end - start) / 0.002, f"{len(during)} ticks in {end - start:.3f} s: the GIL was held"


def test_ctrl_c_stops_a_sweep_between_frames_with_keyboard_interrupt(tmp_path):
    script = (
        "import sys, twister\n"
        "r = twister.Renderer()\n"
        "for k, f in enumerate(r.render_frames('builtin:demo', frames=range(10_000), width=64, samples=1)):\n"
        "    print(k, flush=True)\n"
    )
    child = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert child.stdout.readline().strip() == "0"
    child.send_signal(signal.SIGINT)
    start = time.perf_counter()
    out, err = child.communicate(timeout=60)
    assert time.perf_counter() - start < 30
    assert child.returncode != 0 and "KeyboardInterrupt" in err, err
    assert len(out.split()) < 50, "the sweep went on after Ctrl-C"


def test_the_stub_is_current_and_declares_every_setting():
    stub = ROOT / "python" / "twister" / "__init__.pyi"
    done = subprocess.run([sys.executable, str(ROOT / "python" / "tools" / "stubgen.py"), "--check"])
    assert done.returncode == 0, "the stub is stale: run python/tools/stubgen.py"
    tree = ast.parse(stub.read_text())
    renderer = next(n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == "Renderer")
    render = next(n for n in renderer.body if isinstance(n, ast.FunctionDef) and n.name == "render")
    declared = {a.arg for a in render.args.kwonlyargs}
    assert declared == {o["name"] for o in twister.options("render")} - {"frames"}
    assert len(render.args.kw_defaults) == len(render.args.kwonlyargs), "every setting has its default"


def test_help_lists_every_setting_with_its_default():
    doc = twister.Renderer.render.__doc__
    for o in twister.options("render"):
        if o["name"] != "frames":
            assert f"    {o['name']}" in doc, o["name"]
    assert "eye_radius [default: 0.032]" in doc


def test_the_examples_run(tmp_path):
    env = dict(os.environ, TWISTER_QUICK="1", MPLBACKEND="Agg")
    examples = ROOT / "examples" / "python"
    runs = [
        ["sweep_eye_radius.py", str(tmp_path / "sweep.png")],
        ["slit_width.py", str(tmp_path / "slit.png")],
        ["port_gltf.py", "builtin:demo", str(tmp_path / "vr180"), "256"],
    ]
    for name, *args in runs:
        done = subprocess.run([sys.executable, str(examples / name), *args], env=env, capture_output=True, text=True)
        assert done.returncode == 0, f"{name}: {done.stderr}"
    for made in ["sweep.png", "slit.png", "vr180/stereo_180_LR.png", "vr180/depth_LR.exr"]:
        assert (tmp_path / made).stat().st_size > 0, made
