"""Shared helpers: the command line to compare against, and writers of the
small map files the tests make (nothing is downloaded)."""

import os
import struct
import subprocess
from pathlib import Path

import numpy as np
import pytest

from maps import sky, write_exr

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


@pytest.fixture
def sky_exr(tmp_path):
    """(path, float32 H x W x 3 array) of an RGB EXR sky."""
    rgb = sky()
    path = tmp_path / "sky.exr"
    write_exr(path, {"R": rgb[..., 0], "G": rgb[..., 1], "B": rgb[..., 2]})
    return path, rgb
