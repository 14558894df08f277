"""Runs twister: through the Python package where Blender's Python can import it, else through
the `twister` command (the add-on's preferences, `TWISTER_BIN`, or PATH). No bpy here."""

from __future__ import annotations

import os
import shutil
import subprocess
from typing import Dict, List, Optional, Sequence


class TwisterMissing(RuntimeError):
    """Neither the package nor the command is there."""


def package():
    """The `twister` Python package, or None."""
    try:
        import twister  # noqa: F401

        return twister
    except ImportError:
        return None


def command(preferred: str = "") -> Optional[str]:
    """The `twister` command: the preference's path, `TWISTER_BIN`, or the one on PATH."""
    for candidate in (preferred, os.environ.get("TWISTER_BIN", "")):
        if candidate and os.path.isfile(candidate) and os.access(candidate, os.X_OK):
            return candidate
    return shutil.which("twister")


def argv(settings: Dict[str, object]) -> List[str]:
    """Keyword settings as the command line's options."""
    out = []
    for name, value in settings.items():
        flag = "--" + name.replace("_", "-")
        if value is True:
            out.append(flag)
        elif value is False or value is None:
            continue
        elif isinstance(value, (tuple, list)):
            out.append(f"{flag}={','.join(str(v) for v in value)}")
        else:
            out.append(f"{flag}={value}")
    return out


def render_still(scene_file: str, out_dir: str, settings: Dict[str, object], preferred_bin: str = "") -> List[str]:
    """Renders `scene_file` into `out_dir` (render's files, metadata included); returns the
    paths written. Raises ValueError / OSError / RuntimeError with twister's one-line message."""
    pkg = package()
    if pkg is not None:
        frame = renderer().render(scene_file, **settings)
        frames = frame.values() if isinstance(frame, dict) else [frame]
        return [str(p) for f in frames for p in f.save(out_dir)]
    binary = command(preferred_bin)
    if binary is None:
        raise TwisterMissing(
            "twister not found: install the Python package into Blender's Python, set TWISTER_BIN, "
            "or set the command's path in the add-on's preferences"
        )
    done = subprocess.run([binary, "render", scene_file, *argv(settings), "--out", out_dir], capture_output=True, text=True)
    if done.returncode != 0:
        lines = done.stderr.strip().splitlines() or [f"twister exited with {done.returncode}"]
        raise RuntimeError(lines[-1].removeprefix("error: "))
    return [line for line in done.stdout.splitlines() if line.strip()]


_RENDERER = None


def renderer():
    """One twister.Renderer for the Blender session (the device opened once)."""
    global _RENDERER
    if _RENDERER is None:
        _RENDERER = package().Renderer()
    return _RENDERER


def sequence_command(
    scene_file: str, out_dir: str, settings: Dict[str, object], frames: Sequence[int], fps: float, preferred_bin: str = ""
) -> List[str]:
    """The command line that renders a sequence (numbered frames), for a process the operator
    watches and can stop."""
    binary = command(preferred_bin)
    if binary is None:
        raise TwisterMissing("twister not found: set TWISTER_BIN or the command's path in the add-on's preferences")
    first, last = frames[0], frames[-1]
    return [binary, "render", scene_file, *argv(settings), f"--frames={first}..{last}", f"--fps={fps:g}", "--out", out_dir]
