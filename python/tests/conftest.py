"""Shared fixtures: one Renderer per session, the `twister` binary to compare against, a PNG
reader (numpy and zlib only)."""

from __future__ import annotations

import os
import pathlib
import subprocess
import zlib

import numpy as np
import pytest

import twister

ROOT = pathlib.Path(__file__).resolve().parents[2]
os.environ.setdefault("NODEVICE_SELECT", "1")


@pytest.fixture(scope="session")
def renderer() -> twister.Renderer:
    return twister.Renderer()


@pytest.fixture(scope="session")
def cli() -> pathlib.Path:
    """The command line to compare with: TWISTER_BIN, else the workspace's debug build (built
    here when absent)."""
    path = pathlib.Path(os.environ.get("TWISTER_BIN", ROOT / "target" / "debug" / "twister"))
    if not path.exists():
        subprocess.run(["cargo", "build", "-q", "-p", "twister-cli"], cwd=ROOT, check=True)
    return path


def run_cli(cli: pathlib.Path, *args: str) -> subprocess.CompletedProcess:
    done = subprocess.run([str(cli), *args], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return done


def read_png(path: pathlib.Path) -> np.ndarray:
    """An 8-bit RGBA or RGB, non-interlaced PNG as an (H, W, C) uint8 array."""
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", path
    pos, idat, header = 8, b"", None
    while pos < len(data):
        n = int.from_bytes(data[pos : pos + 4], "big")
        kind, body = data[pos + 4 : pos + 8], data[pos + 8 : pos + 8 + n]
        if kind == b"IHDR":
            header = body
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    w, h = int.from_bytes(header[0:4], "big"), int.from_bytes(header[4:8], "big")
    depth, colour, interlace = header[8], header[9], header[12]
    assert depth == 8 and colour in (2, 6) and interlace == 0, (path, depth, colour)
    c = 4 if colour == 6 else 3
    raw = np.frombuffer(zlib.decompress(idat), np.uint8).reshape(h, w * c + 1)
    out = np.zeros((h, w * c), np.int32)
    for y in range(h):
        f, line = raw[y, 0], raw[y, 1:].astype(np.int32)
        up = out[y - 1] if y else np.zeros(w * c, np.int32)
        if f == 0:
            out[y] = line
        elif f == 2:
            out[y] = (line + up) & 255
        else:
            row = np.zeros(w * c, np.int32)
            for x in range(w * c):
                left = row[x - c] if x >= c else 0
                ul = up[x - c] if x >= c else 0
                if f == 1:
                    pred = left
                elif f == 3:
                    pred = (left + up[x]) // 2
                else:
                    p = left + up[x] - ul
                    pa, pb, pc = abs(p - left), abs(p - up[x]), abs(p - ul)
                    pred = left if pa <= pb and pa <= pc else (up[x] if pb <= pc else ul)
                row[x] = (line[x] + pred) & 255
            out[y] = row
    return out.astype(np.uint8).reshape(h, w, c)
