"""The package's own promises: pdfs that normalise and agree, streams that
are the in-memory sets, conversions that round-trip, errors that are
Python exceptions with the library's message, and a released GIL."""

import doctest
import threading
import time

import numpy as np
import pytest

import tessera
from maps import sky, write_exr


def test_docstring_examples_run():
    for module in (tessera, tessera.metrics):
        result = doctest.testmod(module)
        assert result.attempted > 0 and result.failed == 0, module


def test_pdf_is_normalised_and_follows_the_contrast():
    # the mean of the pdf over a uniform sphere set is 1 / (4 pi)
    uniform = tessera.sphere(200_000)
    for density in ["uniform", "cap:10,20,30,10", ["polygon:-10 30,40 30,40 70,-10 70;16", "cap:100,-20,10,5"]]:
        mean = tessera.pdf(uniform, density).mean() * 4 * np.pi
        assert abs(mean - 1) < 2e-3, (density, mean)
    inside, outside = tessera.from_lonlat([10, -170], [20, -20])
    p_in, p_out = tessera.pdf(np.stack([inside, outside]), "cap:10,20,30,10")
    assert p_in / p_out == pytest.approx(10, rel=1e-12)
    # directions need not be unit vectors
    assert tessera.pdf(inside * 3.5, "cap:10,20,30,10") == p_in


def test_map_pdf_is_the_pixel_value_over_the_integral():
    rgb = sky()
    lum = 0.2126 * rgb[..., 0].astype(np.float64) + 0.7152 * rgb[..., 1] + 0.0722 * rgb[..., 2]
    height, width = lum.shape
    theta = (np.arange(height) + 0.5) / height * np.pi
    phi = (np.arange(width) + 0.5) / width * 2 * np.pi
    centres = np.stack(
        [
            np.outer(np.sin(theta), np.cos(phi)),
            np.outer(np.sin(theta), np.sin(phi)),
            np.outer(np.cos(theta), np.ones(width)),
        ],
        axis=-1,
    ).reshape(-1, 3)
    pdf = tessera.pdf(centres, map=rgb).reshape(height, width)
    edges = np.arange(height + 1) / height * np.pi
    solid_angle = (np.cos(edges[:-1]) - np.cos(edges[1:])) * 2 * np.pi / width
    assert (pdf * solid_angle[:, None]).sum() == pytest.approx(1, rel=1e-12)
    assert np.allclose(pdf / lum, pdf[0, 0] / lum[0, 0], rtol=1e-12)
    # the samples' pdfs are those of their pixels
    points, p = tessera.sphere(3000, map=rgb, pdf=True)
    assert (tessera.pdf(points, map=rgb) == p).all()


def test_healpix_counts_per_pixel_follow_the_map():
    # nside 8: counts per pixel within 4 sqrt(expected) of expected, a hot
    # pixel's share within 10 %, RING and NESTED
    rng = np.random.default_rng(2)
    values = 0.5 + 1.5 * rng.random(768)
    n = 153_600
    for nest in (False, True):
        points, pdf = tessera.sphere(n, healpix=values, nest=nest, pdf=True)
        assert pdf == pytest.approx(tessera.pdf(points, healpix=values, nest=nest), rel=0)
        assert (pdf * 4 * np.pi * values.mean()) == pytest.approx(values[_pixels(points, nest)], rel=1e-12)
        counts = np.bincount(_pixels(points, nest), minlength=768)
        expected = n * values / values.sum()
        assert np.abs(counts - expected).max() <= 4 * np.sqrt(expected).min()
        hot = np.ones(768)
        hot[300] = 1000.0
        share = np.mean(_pixels(tessera.sphere(20_000, healpix=hot, nest=nest, seed=9), nest) == 300)
        assert abs(share / (1000 / 1767) - 1) < 0.1


def _pixels(points, nest):
    """The nside-8 pixel (RING or NESTED index) of each direction, by the
    package's own lookup: a map holding index + 1 has pdf (index + 1) /
    (4 pi mean). (test_healpy.py checks the lookup against healpy.)"""
    index_map = np.arange(768.0) + 1
    p = tessera.pdf(points, healpix=index_map, nest=nest)
    return np.rint(p * 4 * np.pi * index_map.mean()).astype(np.int64) - 1


def test_planar_pdf_is_per_unit_area_of_the_domain():
    points, pdf = tessera.plane(2000, density="ramp", domain=(0, 0, 4, 2), pdf=True)
    # ramp: density 2 x on the unit square, stretched over a 4 x 2 rectangle
    assert np.allclose(pdf, 2 * (points[:, 0] / 4) / 8, rtol=1e-12)
    assert tessera.plane(100, pdf=True)[1].tolist() == [1.0] * 100


def test_stream_chunks_are_the_in_memory_set():
    n = 300_001
    chunks = list(tessera.stream(n, chunk=65536))
    assert [len(c) for c in chunks] == [65536] * 4 + [n - 4 * 65536]
    assert (np.concatenate(chunks) == tessera.sphere(n)).all()
    assert len(tessera.stream(10, chunk=3)) == 10
    # far beyond memory: the first chunk comes at once
    first = next(iter(tessera.stream(10**18, chunk=1000)))
    assert first.shape == (1000, 3) and np.allclose(np.linalg.norm(first, axis=1), 1)


def test_lonlat_round_trips():
    points = tessera.sphere(50_000, seed=3)
    lon, lat = tessera.lonlat(points)
    assert lon.min() >= -180 and lon.max() < 180 and np.abs(lat).max() <= 90
    # degrees to radians and back costs a few ulps
    assert np.abs(tessera.from_lonlat(lon, lat) - points).max() < 4e-15
    lon = np.linspace(-180, 179.99, 1001)
    lat = np.linspace(-89.9, 89.9, 1001)
    back_lon, back_lat = tessera.lonlat(tessera.from_lonlat(lon, lat))
    assert np.abs(back_lon - lon).max() < 1e-10 and np.abs(back_lat - lat).max() < 1e-10
    # shapes broadcast and come back
    grid = tessera.from_lonlat(lon[:5, None], lat[None, :7])
    assert grid.shape == (5, 7, 3)
    assert tessera.lonlat(grid)[0].shape == (5, 7)
    # the antimeridian is -180, as the CLI writes it
    assert tessera.lonlat([[-1.0, 0.0, 0.0]])[0][0] == -180.0


def test_threads_do_not_change_the_output():
    for density in ["uniform", "cap:30,40,20,25"]:
        assert (tessera.sphere(20_000, density, threads=1) == tessera.sphere(20_000, density)).all()
    assert (tessera.plane(5000, "penrose", "ramp", threads=1) == tessera.plane(5000, "penrose", "ramp")).all()


def test_the_gil_is_released_while_sampling():
    done = threading.Event()

    def work():
        tessera.sphere(2_000_000, "cap:10,20,30,10", threads=1)
        done.set()

    worker = threading.Thread(target=work)
    ticks = 0
    worker.start()
    time.sleep(0.02)  # let the worker enter the library
    while not done.is_set():
        ticks += 1
    worker.join()
    # with the GIL held this thread would not run until the call returned
    assert ticks > 1000, ticks


def test_seeds_and_windows():
    a, b = tessera.sphere(1000, seed=1), tessera.sphere(1000, seed=2)
    assert not np.array_equal(a, b)
    assert np.array_equal(a, tessera.sphere(1000, seed=1))
    near = tessera.sphere(1_000_000, within=(0, 0, 2))
    lon, lat = tessera.lonlat(near)
    assert np.degrees(np.arccos(near[:, 0].clip(-1, 1))).max() <= 2
    # a 2-degree cap holds 0.0305 % of the sphere
    assert 280 < len(near) < 330


def test_bad_requests_raise_value_error_with_the_library_message(tmp_path):
    cases = [
        (lambda: tessera.sphere(10, "cap:1,2"), "density 'cap:1,2': expected 4 numbers"),
        (lambda: tessera.sphere(10, "cap:0,100,5,2"), "latitude must be in [-90, 90]"),
        (lambda: tessera.sphere(10, ["uniform", "cap:0,0,5,3"]), "uniform"),
        (lambda: tessera.sphere(10, "polygon:0 0,1 1;5"), "3 vertices"),
        (lambda: tessera.sphere(10, within="0,0"), "window '0,0'"),
        (lambda: tessera.sphere(10, within=(0, 0, 5), seed=1), "a seed"),
        (lambda: tessera.sphere(10, map=np.ones((4, 8)), within=(0, 0, 5)), "a map"),
        (lambda: tessera.sphere(10, map=np.zeros((4, 8))), "nothing to sample"),
        (lambda: tessera.sphere(10, map=np.ones((4, 8, 2))), "H x W x 3"),
        (lambda: tessera.sphere(10, up="y"), "apply to a map"),
        (lambda: tessera.sphere(10, "cap:0,0,5,3", map=np.ones((4, 8))), "not both"),
        (lambda: tessera.sphere(10**15), "do not fit in memory"),
        (lambda: tessera.sphere(-1), "n must be in"),
        (lambda: tessera.sphere(10, seed=-3), "seed must be in"),
        (lambda: tessera.sphere(10, threads=0), "threads must be >= 1"),
        (lambda: tessera.sphere(10, unsorted=True, farthest_first=True), "two orders"),
        (lambda: tessera.sphere(10, within=(0, 0, 5), farthest_first=True), "farthest-first order"),
        (lambda: tessera.plane(10, unsorted=True, farthest_first=True), "two orders"),
        (lambda: tessera.plane(10, "hexagon"), "unknown planar system 'hexagon'"),
        (lambda: tessera.plane(10, density="ramp:2"), "density 'ramp:2'"),
        (lambda: tessera.plane(10, domain=(0, 0, 1)), "domain takes 4 numbers"),
        (lambda: tessera.plane(10, domain="0,0,1,-1"), "expected x1 > x0"),
        (lambda: tessera.plane(10, invert=True), "invert applies to image densities"),
        (lambda: tessera.lights(np.ones((8, 16, 3)), 0), "at least one light"),
        (lambda: tessera.lights(np.ones((8, 16, 3)), 4, exponent=9), "outside [0, 4]"),
        (lambda: tessera.pdf(np.zeros((2, 3))), "not a finite non-zero vector"),
        (lambda: tessera.pdf(np.ones((2, 2))), "(n, 3)"),
        (lambda: tessera.metrics.sphere(np.ones((5, 3))), "not a unit vector"),
        (lambda: tessera.metrics.plane(np.zeros((0, 2))), "no points"),
        (lambda: tessera.metrics.plane(np.zeros((5, 2)), only="separation_sqrt_n"), "unknown measure 'separation_sqrt_n'"),
        (lambda: tessera.stream(10, chunk=0), "chunk must be at least 1"),
        (lambda: tessera.sphere(10, map=tessera.Map(np.ones((4, 8))), up="y"), "give them to Map()"),
        (lambda: tessera.Map(np.zeros((4, 8))), "nothing to sample"),
        (lambda: tessera.stream(10**30), "must be in"),
        (lambda: tessera.sphere(10, healpix=np.ones(768), field=1), "field picks a column"),
        (lambda: tessera.sphere(10, healpix="m.fits", nest=True), "declares its ORDERING"),
        (lambda: tessera.sphere(10, nest=True), "apply to a HEALPix map"),
        (lambda: tessera.sphere(10, healpix=tessera.HealpixMap(np.ones(48)), nest=True), "give them to HealpixMap()"),
        (lambda: tessera.HealpixMap(np.ones(50)), "12 nside^2"),
        (lambda: tessera.HealpixMap(np.ones((12, 4))), "vector of 12 nside**2"),
    ]
    for call, message in cases:
        with pytest.raises(ValueError) as raised:
            call()
        assert message in str(raised.value), (message, str(raised.value))


def test_files_raise_os_errors_naming_the_file(tmp_path):
    missing = tmp_path / "missing.exr"
    with pytest.raises(FileNotFoundError, match="missing.exr"):
        tessera.sphere(10, map=missing)
    with pytest.raises(FileNotFoundError, match="missing.exr"):
        tessera.lights(missing, 4)
    with pytest.raises(FileNotFoundError, match="missing.exr"):
        tessera.plane(10, image=missing)
    with pytest.raises(IsADirectoryError):
        tessera.sphere(10, map=tmp_path)
    # hostile contents are refused, never a crash
    hostile = tmp_path / "hostile.exr"
    hostile.write_bytes(b"\x76\x2f\x31\x01" + bytes(range(256)) * 4)
    with pytest.raises(ValueError, match="hostile.exr"):
        tessera.sphere(10, map=hostile)
    text = tmp_path / "notes.txt"
    text.write_text("not an image")
    with pytest.raises(ValueError, match="unrecognised first bytes"):
        tessera.lights(text, 4)
    rgb = sky()
    path = tmp_path / "sky.exr"
    write_exr(path, {"R": rgb[..., 0], "G": rgb[..., 1], "B": rgb[..., 2]})
    with pytest.raises(ValueError, match="no channel named 'Q'"):
        tessera.sphere(10, map=path, channel="Q")


def test_maps_read_once_are_reused():
    rgb = sky()
    prepared = tessera.Map(rgb, up="y")
    assert (prepared.width, prepared.height) == (64, 32)
    assert prepared.integral > 0
    for seed in (None, 3):
        assert (tessera.sphere(700, map=prepared, seed=seed) == tessera.sphere(700, map=rgb, up="y", seed=seed)).all()
    with pytest.raises(TypeError, match="colour"):
        tessera.lights(prepared, 4)
    with pytest.warns(RuntimeWarning, match="not a 2:1"):
        tessera.Map(np.ones((10, 10)))


def test_bad_pixels_warn_or_are_refused_with_strict():
    rgb = sky().astype(np.float64)
    rgb[3, 5, 1] = np.nan
    rgb[6, 2] = -1.0
    with pytest.warns(RuntimeWarning, match="2 negative, NaN or infinite pixel"):
        points = tessera.sphere(500, map=rgb)
    assert points.shape == (500, 3)
    with pytest.raises(ValueError, match="column 5, row 3"):
        tessera.sphere(500, map=rgb, strict=True)
    with pytest.warns(RuntimeWarning, match="4 colour sample"):
        lights = tessera.lights(rgb, 8)
    assert (lights["rgb"] >= 0).all()
    with pytest.raises(ValueError, match="map array"):
        tessera.lights(rgb, 8, strict=True)
    with pytest.warns(RuntimeWarning, match="not a 2:1"):
        tessera.sphere(100, map=np.ones((10, 10)))


def test_outputs_are_fresh_float64_arrays():
    points = tessera.sphere(1000)
    assert points.dtype == np.float64 and points.flags["C_CONTIGUOUS"] and points.flags["WRITEABLE"]
    points[:] = 0  # the caller's to keep and change
    assert (tessera.sphere(1000) != 0).any()
    assert tessera.sphere(0).shape == (0, 3)
    assert tessera.plane(0).shape == (0, 2)
    assert len(tessera.sphere(1000, "cap:0,0,30,5", expected=True)) != 0
