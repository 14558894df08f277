"""Frames from Python are the command line's: pixels, files, statistics; error and bench_speed
carry their JSON's fields; a scene loaded once is reused; sequences yield their frames."""

from __future__ import annotations

import json
import pathlib

import numpy as np
import pytest

import twister
from conftest import read_png, run_cli

SMALL = {"width": 96, "samples": 1}

CASES = [
    ("cylinder", "vertex", {}),
    ("cylinder", "fixed:4", {}),
    ("cylinder", "adaptive", {}),
    ("cylinder", "adaptive:length", {}),
    ("cylinder", "slit:4", {}),
    ("cylinder", "trace", {"vertical": "exact"}),
    ("equirect", "vertex", {}),
    ("equirect", "adaptive", {"eye_radius": 0.05}),
    ("vr180", "adaptive", {}),
    ("fisheye", "adaptive", {"fov": 200}),
    ("cubemap", "adaptive", {"width": 96, "height": 64}),
]


def cli_args(settings: dict) -> list:
    """Keyword settings as the command line's options (the test's own spelling of them)."""
    args = []
    for name, value in settings.items():
        flag = "--" + name.replace("_", "-")
        args += [flag] if value is True else [f"{flag}={value}"]
    return args


@pytest.mark.parametrize("panorama,method,extra", CASES, ids=[f"{p}-{m}" for p, m, _ in CASES])
def test_every_panorama_and_method_draws_the_command_lines_pixels(renderer, cli, tmp_path, panorama, method, extra):
    settings = dict(SMALL, panorama=panorama, method=method, **extra)
    run_cli(cli, "render", "builtin:demo", *cli_args(settings), "--layout", "eyes", "--out", str(tmp_path / "cli"))
    frame = renderer.render("builtin:demo", **settings)
    assert isinstance(frame, twister.Frame)
    for eye, image in [("left", frame.left), ("right", frame.right)]:
        assert image.dtype == np.uint8 and image.shape == (frame.height, frame.width, 4)
        png = read_png(tmp_path / "cli" / f"{eye}.png")
        assert png.shape[:2] == image.shape[:2]
        assert np.array_equal(png, image[:, :, : png.shape[2]]), f"{eye}: the pixels differ from the command line's"
    # Saved, the files are the command line's, byte for byte (metadata included).
    saved = frame.save(tmp_path / "py", layout="eyes")
    assert sorted(pathlib.Path(p).name for p in saved) == ["left.png", "right.png"]
    for p in saved:
        assert pathlib.Path(p).read_bytes() == (tmp_path / "cli" / pathlib.Path(p).name).read_bytes()


def test_the_default_layout_depth_hdr_and_stats_are_the_command_lines(renderer, cli, tmp_path):
    settings = dict(SMALL, panorama="equirect", depth=True, hdr=True)
    stats = tmp_path / "stats.json"
    run_cli(cli, "render", "builtin:demo", *cli_args(settings), "--stats", str(stats), "--out", str(tmp_path / "cli"))
    frame = renderer.render("builtin:demo", **settings)
    left, right = frame.depth
    assert left.dtype == np.float32 and left.shape == (frame.height, frame.width)
    assert np.isfinite(left).any() and (left[np.isfinite(left)] > 0).all()
    assert frame.hdr[0].dtype == np.float32 and frame.hdr[0].shape == (frame.height, frame.width, 3)
    written = sorted(p.name for p in (tmp_path / "cli").iterdir())
    saved = frame.save(tmp_path / "py")
    assert sorted(pathlib.Path(p).name for p in saved) == written
    for p in saved:
        assert pathlib.Path(p).read_bytes() == (tmp_path / "cli" / pathlib.Path(p).name).read_bytes(), p
    cli_stats = json.loads(stats.read_text())
    assert set(frame.stats) == set(cli_stats)
    for key in ("width", "height", "eye_radius", "triangles_in", "triangles_out", "method", "panorama"):
        assert frame.stats[key] == cli_stats[key], key


def test_cave_walls_come_by_name(renderer, cli, tmp_path):
    cave = tmp_path / "cave.json"
    wall = '{{"name": "{}", "lower_left": {}, "lower_right": {}, "upper_left": {}, "pixels": [48, 32]}}'
    front = wall.format("front", "[-1.5,-1.5,-1.5]", "[1.5,-1.5,-1.5]", "[-1.5,1.5,-1.5]")
    floor = wall.format("floor", "[-1.5,-1.5,1.5]", "[1.5,-1.5,1.5]", "[-1.5,-1.5,-1.5]")
    cave.write_text(f'{{"walls": [{front}, {floor}]}}')
    settings = {"panorama": "cave", "cave": str(cave), "head": "0.1,0,0.2", "samples": 1}
    run_cli(cli, "render", *cli_args(settings), "--out", str(tmp_path / "cli"))
    walls = renderer.render(**settings)
    assert sorted(walls) == ["floor", "front"]
    for name, frame in walls.items():
        assert frame.wall == name and frame.left.shape == (32, 48, 4)
        assert np.array_equal(read_png(tmp_path / "cli" / f"{name}_left.png"), frame.left)


def test_error_carries_the_jsons_fields_and_each_eyes_heatmap(renderer, cli):
    settings = {"panorama": "equirect", "width": 128, "samples": 1}
    done = run_cli(cli, "error", "builtin:demo", "--method", "vertex", "--json", *cli_args(settings))
    expected = json.loads(done.stdout)
    got = renderer.error("builtin:demo", method="vertex", heatmap=True, **settings)
    assert set(got) == set(expected) | {"heatmap"}
    for key in ("mean_px", "p50_px", "p99_px", "max_px", "pixels", "triangles_out", "method", "width"):
        assert got[key] == expected[key], key
    left, right = got["heatmap"]
    assert left.shape == (64, 128) and left.dtype == np.float32
    drawn = np.concatenate([left[left >= 0], right[right >= 0]])
    assert drawn.size == got["pixels"]
    assert abs(float(drawn.mean()) - got["mean_px"]) <= 1e-3 * max(1.0, got["mean_px"])


def test_bench_speed_rows_carry_the_jsons_fields(renderer, cli, tmp_path):
    out = tmp_path / "speed.json"
    run_cli(cli, "bench", "speed", "builtin:demo", "--methods", "vertex", "--reps", "1", "--width", "64", "--json", str(out))
    expected = json.loads(out.read_text())["rows"]
    rows = renderer.bench_speed(["builtin:demo"], methods=["vertex"], reps=1, width=64)
    assert len(rows) == len(expected) and set(rows[0]) == set(expected[0])
    assert rows[0]["method"] == expected[0]["method"] and rows[0]["triangles_in"] == expected[0]["triangles_in"]


def test_a_loaded_scene_is_read_once_and_draws_what_its_path_draws(tmp_path):
    obj = tmp_path / "room.obj"
    obj.write_text("v -1 -1 -3\nv 1 -1 -3\nv 0 1 -3\nv 0 -1 3\nf 1 2 3\nf 2 4 3\n")
    r = twister.Renderer()
    scene = r.load(obj, scale=2.0)
    assert scene.triangles == 2 and r.stats["scenes_loaded"] == 1
    a = r.render(scene, width=64, samples=1)
    b = r.render(scene, width=64, samples=1, eye_radius=0.05)
    c = r.render(str(obj), scale=2.0, width=64, samples=1)
    assert np.array_equal(a.left, c.left) and not np.array_equal(a.left, b.left)
    assert r.stats == {"renders": 3, "scenes_loaded": 1, "adapters_opened": r.stats["adapters_opened"]}


def test_render_frames_yields_the_sequences_frames(renderer, cli, tmp_path):
    path = tmp_path / "viewer.csv"
    path.write_text("time,x,y,z\n0,0,0,0\n1,0.5,0,0\n")
    settings = dict(SMALL, viewer_path=str(path), fps=2)
    run_cli(cli, "render", "builtin:demo", *cli_args(settings), "--frames", "0..2", "--out", str(tmp_path / "cli"))
    frames = list(renderer.render_frames("builtin:demo", frames=range(3), **settings))
    assert len(frames) == 3 and not np.array_equal(frames[0].left, frames[2].left)
    for k, frame in enumerate(frames):
        assert np.array_equal(read_png(tmp_path / "cli" / f"frame_{k:06d}_left.png"), frame.left), k
        assert frame.stats["frame"] == k and frame.frame == k
        # Saved, a frame's files are named and written as the sequence's.
        for p in frame.save(tmp_path / "py"):
            name = pathlib.Path(p).name
            assert name.startswith(f"frame_{k:06d}_"), name
            assert pathlib.Path(p).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
