"""twister: omnidirectional stereo on the GPU, from Python.

A :class:`Renderer` opens one GPU adapter and keeps its pipelines: renders, error measurements
and benchmarks on it reuse them, so a sweep pays the device's start once. Settings are the
command line's long options in snake case (``--eye-radius 0.032`` is ``eye_radius=0.032``) and
mean exactly what they mean there: ``r.render(...).left`` holds the bytes ``twister render
--layout eyes`` writes to ``left.png`` with the same settings.

>>> import twister
>>> r = twister.Renderer()
>>> frame = r.render("builtin:demo", panorama="equirect", width=512, samples=1)
>>> frame.left.shape
(256, 512, 4)

Bad settings raise :class:`TwisterError` (a ``ValueError``) naming the parameter; files that
cannot be read or written raise :class:`TwisterFileError` (an ``OSError``); a missing GPU
driver or a failing device raises :class:`TwisterDeviceError` (a ``RuntimeError``).
"""

from __future__ import annotations

import difflib
import json
import os
from typing import Any, Dict, Iterable, Iterator, List, Optional, Sequence, Union

from . import _twister
from ._twister import Frame, Scene, TwisterDeviceError, TwisterError, TwisterFileError

__all__ = ["Renderer", "Frame", "Scene", "TwisterError", "TwisterFileError", "TwisterDeviceError", "options"]
__version__ = _twister.__version__

_COMMANDS = ("render", "error", "bench_speed")
_OPTIONS: Dict[str, Dict[str, dict]] = {c: {o["name"]: o for o in _twister.options(c)} for c in _COMMANDS}


def options(command: str = "render") -> List[dict]:
    """The settings ``command`` takes ("render", "error" or "bench_speed"): each a dict with
    ``name``, ``flag`` (the command line's), ``type``, ``default``, ``choices`` and ``help``."""
    if command not in _OPTIONS:
        raise TwisterError(f"command: {command!r} is not one of {', '.join(_COMMANDS)}")
    return [dict(o) for o in _OPTIONS[command].values()]


def _text(name: str, value: Any) -> str:
    """One setting's value as the command line writes it."""
    if isinstance(value, bool):
        raise TwisterError(f"{name}: expected a value, got {value!r}")
    if isinstance(value, (str, int, float)):
        return str(value)
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    if hasattr(value, "item") and getattr(value, "ndim", 1) == 0:  # a numpy scalar
        return str(value.item())
    if isinstance(value, (tuple, list, range)) or hasattr(value, "tolist"):
        items = value.tolist() if hasattr(value, "tolist") else list(value)
        return ",".join(_text(name, v) for v in items)
    raise TwisterError(f"{name}: expected a number, text, a path or a sequence, got {type(value).__name__}")


def _argv(command: str, settings: Dict[str, Any], reserved: Sequence[str] = ()) -> List[str]:
    """Keyword arguments as the command's options; an unknown name or a bad value raises
    TwisterError naming it."""
    known = _OPTIONS[command]
    argv: List[str] = []
    for name, value in settings.items():
        option = known.get(name)
        if option is None or name in reserved:
            close = difflib.get_close_matches(name, [n for n in known if n not in reserved], n=1)
            hint = f" (did you mean {close[0]}?)" if close else ""
            raise TwisterError(f"{name}: not a setting of {command}{hint}")
        if value is None:
            continue
        if not option["takes_value"]:
            if not isinstance(value, bool):
                raise TwisterError(f"{name}: expected True or False, got {value!r}")
            if value:
                argv.append(option["flag"])
            continue
        argv.append(f"{option['flag']}={_text(name, value)}")
    return argv


SceneLike = Union[str, "os.PathLike[str]", Scene]


def _scene(scene: SceneLike) -> tuple:
    """(positional options, loaded Scene or None) for a scene argument."""
    if isinstance(scene, Scene):
        return [], scene
    if isinstance(scene, (str, os.PathLike)):
        spec = os.fspath(scene)
        if spec.startswith("-"):
            spec = os.path.join(".", spec)
        return [spec], None
    raise TwisterError(f"scene: expected a path, a built-in name or a twister.Scene, got {type(scene).__name__}")


def _views(frames: List[Frame]) -> Union[Frame, Dict[str, Frame]]:
    """One frame, or a CAVE's frames by wall."""
    if len(frames) == 1 and frames[0].wall is None:
        return frames[0]
    return {f.wall: f for f in frames}


class Renderer:
    """One GPU adapter and its pipelines, open as long as this object lives.

    ``adapter``: a part of the adapter's name to open (any case), e.g. ``"llvmpipe"``; the
    default adapter when None (the command line's ``TWISTER_ADAPTER``). Threads may share a
    renderer: their calls take turns, each releasing the GIL while the GPU works.
    """

    def __init__(self, adapter: Optional[str] = None) -> None:
        self._r = _twister.Renderer(adapter)

    @property
    def adapter(self) -> str:
        """The adapter's description (name, backend, driver)."""
        return self._r.adapter

    @property
    def stats(self) -> Dict[str, int]:
        """``renders`` (frames drawn here), ``scenes_loaded`` (files read by :meth:`load`),
        ``adapters_opened`` (by this process: a sweep on one renderer opens one)."""
        return dict(self._r.stats)

    def load(self, path: SceneLike, **placement: Any) -> Scene:
        """Reads a scene file once (``fit``, ``scale``, ``viewer`` and the other settings given
        here are applied at each render that uses it, before the render's own)."""
        positional, scene = _scene(path)
        if scene is not None:
            return scene
        return self._r._load(positional[0], _argv("render", placement))

    def render(self, scene: SceneLike = "builtin:demo", **settings: Any) -> Union[Frame, Dict[str, Frame]]:
        """Draws both eyes of ``scene`` as ``twister render`` does; a CAVE gives a dict of
        frames by wall. ``depth=True`` adds ``frame.depth``, ``hdr=True`` ``frame.hdr``."""
        positional, loaded = _scene(scene)
        argv = positional + _argv("render", settings, reserved=("frames",))
        return _views(self._r._render(argv, loaded))

    def render_frames(
        self, scene: SceneLike = "builtin:demo", frames: Iterable[int] = range(1), **settings: Any
    ) -> Iterator[Union[Frame, Dict[str, Frame]]]:
        """Yields the frames of a sequence (animation at ``fps``, ``viewer_path``,
        ``gaze_path``, ``head_path``) as ``twister render --frames`` draws them, one by one as
        they finish. Ctrl-C stops between frames with ``KeyboardInterrupt``."""
        positional, loaded = _scene(scene)
        argv = positional + _argv("render", settings, reserved=("frames",))
        for frame in frames:
            if not isinstance(frame, int) or isinstance(frame, bool) or frame < 0:
                raise TwisterError(f"frames: expected frame numbers ≥ 0, got {frame!r}")
            yield _views(self._r._render_frame(argv, frame, loaded))

    def error(
        self,
        scene: SceneLike = "builtin:demo",
        method: str = "adaptive",
        against: Optional[str] = None,
        heatmap: bool = False,
        **settings: Any,
    ) -> Union[Dict[str, Any], List[Dict[str, Any]]]:
        """Measures the display-position error of ``method`` (seed 002 §4.1): ``twister error
        --json``'s fields; ``against`` ("slit:1", "trace") adds the comparison's; with
        ``heatmap=True``, ``"heatmap"`` holds each eye's per-pixel error in pixels (float32,
        -1: background). A CAVE gives a list, one dict per wall."""
        if not isinstance(heatmap, bool):
            raise TwisterError(f"heatmap: expected True or False, got {heatmap!r}")
        positional, loaded = _scene(scene)
        given = dict(settings, method=method, against=against)
        argv = positional + _argv("error", given, reserved=("json", "heatmap", "heatmap_max"))
        results = []
        for text, maps in self._r._error(argv, loaded, heatmap):
            result = json.loads(text)
            if heatmap:
                result["heatmap"] = maps
            results.append(result)
        return results[0] if len(results) == 1 else results

    def bench_speed(
        self,
        scenes: Union[SceneLike, Sequence[str]] = ("builtin:demo",),
        methods: Sequence[str] = ("vertex", "adaptive"),
        reps: int = 5,
        **settings: Any,
    ) -> List[Dict[str, Any]]:
        """Times ``methods`` on ``scenes`` as ``twister bench speed`` does (median of ``reps``
        frames after a warm-up, the methods in turn): its JSON's rows."""
        if isinstance(scenes, (str, os.PathLike)):
            scenes = [scenes]
        specs = [os.fspath(s) for s in scenes]
        given = dict(settings, methods=list(methods), reps=reps)
        argv = specs + _argv("bench_speed", given, reserved=("json",))
        return json.loads(self._r._bench_speed(argv))

    def __repr__(self) -> str:
        return f"<twister.Renderer on {self.adapter}>"


def _settings_doc(command: str, leave_out: Sequence[str] = ()) -> str:
    """The settings a method takes, for help(): name, default and the option's help line."""
    lines = ["", "", "    Settings (the command line's options, in snake case):", ""]
    for o in _OPTIONS[command].values():
        if o["name"] in leave_out:
            continue
        default = "" if o["default"] is None else f" [default: {o['default']}]"
        choices = f" {{{', '.join(o['choices'])}}}" if o["choices"] else ""
        lines.append(f"    {o['name']}{choices}{default}: {o['help']}")
    return "\n".join(lines) + "\n"


for _method, _command, _leave_out in [
    (Renderer.load, "render", ("frames",)),
    (Renderer.render, "render", ("frames",)),
    (Renderer.render_frames, "render", ("frames",)),
    (Renderer.error, "error", ("method", "against", "json", "heatmap", "heatmap_max")),
    (Renderer.bench_speed, "bench_speed", ("methods", "reps", "json")),
]:
    _method.__doc__ = (_method.__doc__ or "") + _settings_doc(_command, _leave_out)
