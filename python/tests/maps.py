"""Writers of small map files (OpenEXR, PNG) and a test sky, in plain
Python and numpy: the tests and python/bench.py make their own data."""

import struct
import zlib
from pathlib import Path

import numpy as np


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


def write_healpix(path, values, nest=False, coordsys="C", dtype=">f4"):
    """A full-sky HEALPix map in FITS as healpy's write_map lays it out: an
    empty primary HDU, then a binary table of one column, in rows of 1024
    values when there are more than 1024."""
    values = np.asarray(values, dtype=dtype)
    nside = int(round(np.sqrt(values.size / 12)))
    repeat = 1024 if values.size > 1024 else 1
    letter = {">f4": "E", ">f8": "D"}[dtype]

    def header(cards):
        text = "".join(f"{key:<8}= {value:<70}" for key, value in cards) + f"{'END':<80}"
        return (text + " " * (-len(text) % 2880)).encode("ascii")

    primary = header([("SIMPLE", "T"), ("BITPIX", "8"), ("NAXIS", "0"), ("EXTEND", "T")])
    table = header(
        [
            ("XTENSION", "'BINTABLE'"),
            ("BITPIX", "8"),
            ("NAXIS", "2"),
            ("NAXIS1", str(repeat * values.itemsize)),
            ("NAXIS2", str(values.size // repeat)),
            ("PCOUNT", "0"),
            ("GCOUNT", "1"),
            ("TFIELDS", "1"),
            ("TTYPE1", "'TEMPERATURE'"),
            ("TFORM1", f"'{repeat}{letter}' " if repeat > 1 else f"'{letter}'"),
            ("PIXTYPE", "'HEALPIX '"),
            ("ORDERING", "'NESTED  '" if nest else "'RING    '"),
            ("COORDSYS", f"'{coordsys}'"),
            ("NSIDE", str(nside)),
            ("FIRSTPIX", "0"),
            ("LASTPIX", str(values.size - 1)),
            ("INDXSCHM", "'IMPLICIT'"),
        ]
    )
    data = values.tobytes()
    Path(path).write_bytes(primary + table + data + b"\0" * (-len(data) % 2880))
