"""Shared helpers: the command line to compare against, and writers of the
small map files the tests make (nothing is downloaded)."""

import os
import struct
import subprocess
import zlib
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]


def cli_path():
    """The `tessera` binary: $TESSERA_CLI, else the workspace's release build."""
    if os.environ.get("TESSERA_CLI"):
        return Path(os.environ["TESSERA_CLI"])
    target = Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
    return target / "release" / "tessera"


@pytest.fixture(scope="session")
def cli():
    """Runs the command line and returns its standard output (bytes)."""
    binary = cli_path()
    if not binary.exists():
        pytest.fail(f"{binary} is missing: build it with `cargo build --release` (python/ci.sh does)")

    def run(*args):
        done = subprocess.run([str(binary), *map(str, args)], capture_output=True)
        if done.returncode != 0:
            raise AssertionError(f"tessera {' '.join(map(str, args))} failed: {done.stderr.decode()}")
        return done.stdout

    return run


def read_utk(data):
    """A UTK binary point file (what `--format bin` writes) as an (n, dims) array."""
    magic, kind, sets, count, dims = struct.unpack("<I4sIII", data[:20])
    assert magic == 0x214B5455 and kind == b"\x05\x00\x00\x00" and sets == 1
    values = np.frombuffer(data[20:], dtype="<f8")
    assert values.size == count * dims
    return values.reshape(count, dims)


def read_csv(data):
    """A CSV the command line wrote, as (header, float rows): Rust prints
    the shortest decimal that reads back as the same double, so this is exact."""
    lines = data.decode().strip().splitlines()
    header = lines[0].split(",")
    rows = np.array([[float(v) for v in line.split(",")] for line in lines[1:]], dtype=np.float64)
    return header, rows.reshape(-1, len(header))


def write_exr(path, channels):
    """A scanline, uncompressed OpenEXR of float32 channels: a dict name ->
    H x W array (e.g. {"R": r, "G": g, "B": b} or {"Y": y})."""
    names = sorted(channels)
    planes = [np.ascontiguousarray(channels[c], dtype="<f4") for c in names]
    height, width = planes[0].shape

    def attribute(name, kind, value):
        return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value

    chlist = b"".join(c.encode() + b"\0" + struct.pack("<iB3xii", 2, 0, 1, 1) for c in names) + b"\0"
    window = struct.pack("<iiii", 0, 0, width - 1, height - 1)
    header = (
        b"\x76\x2f\x31\x01"
        + struct.pack("<i", 2)
        + attribute("channels", "chlist", chlist)
        + attribute("compression", "compression", b"\0")
        + attribute("dataWindow", "box2i", window)
        + attribute("displayWindow", "box2i", window)
        + attribute("lineOrder", "lineOrder", b"\0")
        + attribute("pixelAspectRatio", "float", struct.pack("<f", 1.0))
        + attribute("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0))
        + attribute("screenWindowWidth", "float", struct.pack("<f", 1.0))
        + b"\0"
    )
    row_bytes = 8 + 4 * width * len(names)
    first = len(header) + 8 * height
    offsets = struct.pack(f"<{height}Q", *(first + y * row_bytes for y in range(height)))
    rows = b"".join(
        struct.pack("<ii", y, 4 * width * len(names)) + b"".join(p[y].tobytes() for p in planes) for y in range(height)
    )
    Path(path).write_bytes(header + offsets + rows)


def write_png(path, pixels):
    """A 16-bit PNG of an H x W x 3 (RGB) or H x W (grey) array of integers
    in [0, 65535]."""
    pixels = np.asarray(pixels)
    grey = pixels.ndim == 2
    height, width = pixels.shape[:2]
    raw = pixels.astype(">u2").reshape(height, -1)
    data = b"".join(b"\0" + row.tobytes() for row in raw)

    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF)

    ihdr = struct.pack(">IIBBBBB", width, height, 16, 0 if grey else 2, 0, 0, 0)
    Path(path).write_bytes(
        b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(data)) + chunk(b"IEND", b"")
    )


def sky(width=64, height=32, seed=5):
    """A lat-long test sky: a smooth gradient, a bright sun and coloured
    noise, float32 RGB."""
    rng = np.random.default_rng(seed)
    theta = (np.arange(height) + 0.5) / height * np.pi
    phi = (np.arange(width) + 0.5) / width * 2 * np.pi
    base = 0.2 + np.outer(np.cos(theta).clip(0), 1 + 0.3 * np.cos(phi))
    rgb = np.stack([base * 0.8, base, base * 1.3], axis=-1) + 0.05 * rng.random((height, width, 3))
    rgb[height // 4, width // 3] = [400.0, 380.0, 300.0]
    return rgb.astype(np.float32)


@pytest.fixture
def sky_exr(tmp_path):
    """(path, float32 H x W x 3 array) of an RGB EXR sky."""
    rgb = sky()
    path = tmp_path / "sky.exr"
    write_exr(path, {"R": rgb[..., 0], "G": rgb[..., 1], "B": rgb[..., 2]})
    return path, rgb
