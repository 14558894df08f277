"""Bad values, types, names and files raise the documented exceptions, each one line naming the
parameter as Python spells it; the interpreter and the renderer live on."""

from __future__ import annotations

import numpy as np
import pytest

import twister

BAD_SETTINGS = [
    ({"eye_radius": -1}, "eye_radius: "),
    ({"eye_radius": "wide"}, "eye_radius: "),
    ({"width": "abc"}, "width: "),
    ({"width": 1.5}, "width: "),
    ({"width": 10**7}, "width"),
    ({"panorama": "dome"}, "panorama: "),
    ({"method": "fixed:0"}, "method: "),
    ({"eye_radus": 0.03}, "eye_radus: not a setting of render (did you mean eye_radius?)"),
    ({"depth": "yes"}, "depth: expected True or False"),
    ({"viewer": object()}, "viewer: expected a number"),
    ({"viewer": (0, float("nan"), 0)}, "viewer: "),
    ({"max_error_px": float("inf")}, "max_error_px: "),
    ({"frames": range(3)}, "frames: not a setting of render"),
    ({"layout": "12x1"}, "layout: "),
    ({"quality": 50}, "quality: needs format jpg"),
    ({"gaze_path": "/nonexistent/gaze.csv", "lod": "visual-field"}, "gaze_path"),
]


@pytest.mark.parametrize("settings,needle", BAD_SETTINGS, ids=[next(iter(s)) + str(k) for k, (s, _) in enumerate(BAD_SETTINGS)])
def test_bad_settings_raise_twister_error_naming_the_parameter(renderer, settings, needle):
    with pytest.raises(twister.TwisterError) as caught:
        renderer.render("builtin:demo", width=settings.pop("width", 64), samples=1, **settings)
    message = str(caught.value)
    assert isinstance(caught.value, ValueError)
    assert needle in message and "\n" not in message, message
    assert "--" not in message, f"the command line's spelling leaked: {message}"


def test_bad_arguments_of_the_other_methods(renderer):
    cases = [
        (lambda: renderer.error(heatmap="yes"), "heatmap: "),
        (lambda: renderer.error(method="nonsense"), "method: "),
        (lambda: renderer.error(against="slit:0"), "against: "),
        (lambda: renderer.bench_speed(reps=0, width=64), "reps: "),
        (lambda: renderer.bench_speed(json="x"), "json: not a setting"),
        (lambda: list(renderer.render_frames(frames=[-1])), "frames: "),
        (lambda: renderer.render(scene=3), "scene: "),
        (lambda: twister.Renderer(adapter="no such adapter"), "adapter: no adapter's name contains"),
        (lambda: twister.options("view"), "command: "),
    ]
    for call, needle in cases:
        with pytest.raises(twister.TwisterError) as caught:
            call()
        assert needle in str(caught.value) and "--" not in str(caught.value), str(caught.value)


def test_missing_and_corrupt_files_raise_an_oserror_naming_the_file_and_the_renderer_lives_on(renderer, tmp_path):
    garbage = tmp_path / "garbage.gltf"
    garbage.write_text("{ this is not json")
    truncated = tmp_path / "truncated.glb"
    truncated.write_bytes(b"glTF\x02\x00\x00\x00\xa0\x0f\x00\x00" + bytes(8))
    bad_obj = tmp_path / "bad.obj"
    bad_obj.write_text("v 0 0 -3\nv 1 0 -3\nv 0 1 -3\nf 1 2 9\n")
    for path in [tmp_path / "missing.obj", garbage, truncated, bad_obj, tmp_path, "/dev/zero"]:
        for call in (lambda: renderer.render(path, width=64), lambda: renderer.load(path)):
            with pytest.raises(OSError) as caught:
                call()
            assert isinstance(caught.value, twister.TwisterFileError)
            assert str(path) in str(caught.value) and "\n" not in str(caught.value), str(caught.value)
    frame = renderer.render("builtin:demo", width=64, samples=1)
    assert frame.left.any()


def test_save_refuses_a_bad_folder_and_writes_nothing(renderer, tmp_path):
    frame = renderer.render("builtin:demo", width=64, samples=1)
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    with pytest.raises(OSError):
        frame.save(blocker / "out")
    with pytest.raises(twister.TwisterError):
        frame.save(tmp_path / "out", layout="sideways")
    assert not (tmp_path / "out").exists()


def test_arrays_are_the_callers(renderer):
    frame = renderer.render("builtin:demo", width=64, samples=1)
    before = frame.left.copy()
    frame.left[:] = 0  # a caller may write into them
    again = renderer.render("builtin:demo", width=64, samples=1)
    assert np.array_equal(again.left, before)
