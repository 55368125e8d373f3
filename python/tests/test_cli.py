"""The Python functions give the command line's output, bit for bit, for the
same requests (UTK binary for the points, CSV for pdfs and lights: both
exact)."""

import json

import numpy as np
import pytest

import tessera
from conftest import REPO, read_csv, read_utk
from maps import write_exr, write_healpix, write_png


def same(a, b):
    """Exactly equal arrays (bits, not tolerances)."""
    a, b = np.asarray(a), np.asarray(b)
    assert a.shape == b.shape, (a.shape, b.shape)
    assert a.dtype == b.dtype == np.float64
    assert a.tobytes() == b.tobytes(), f"{np.sum(a != b)} values differ"


SPHERE_REQUESTS = [
    (dict(n=20000), []),
    (dict(n=3072), []),
    (dict(n=1), []),
    (dict(n=5000, density="cap:10,20,30,10"), ["--density", "cap:10,20,30,10"]),
    (dict(n=4000, density="cap:-120.5,-60,3,1000"), ["--density", "cap:-120.5,-60,3,1000"]),
    (
        dict(n=3000, density=["polygon:-10 30,40 30,40 70,-10 70;16", "cap:100,-20,10,5"]),
        ["--density", "polygon:-10 30,40 30,40 70,-10 70;16", "--density", "cap:100,-20,10,5"],
    ),
    (dict(n=3000, density="cap:10,20,30,10", seed=7), ["--density", "cap:10,20,30,10", "--seed", "7"]),
    (dict(n=3000, seed=2**64 - 1), ["--seed", str(2**64 - 1)]),
    (dict(n=2500, density="cap:1,2,40,8", expected=True), ["--density", "cap:1,2,40,8", "--expected"]),
    (dict(n=2500, density="cap:1,2,40,8", unsorted=True), ["--density", "cap:1,2,40,8", "--unsorted"]),
    (dict(n=3000, farthest_first=True), ["--farthest-first"]),
    (
        dict(n=2500, density="cap:1,2,40,8", seed=3, farthest_first=True),
        ["--density", "cap:1,2,40,8", "--seed", "3", "--farthest-first"],
    ),
    (dict(n=200000, within=(2.35, 48.85, 4)), ["--within", "2.35,48.85,4"]),
    (dict(n=200000, density="cap:0,0,10,20", within="5,5,6"), ["--density", "cap:0,0,10,20", "--within", "5,5,6"]),
    (dict(n=800, density="cap:0,90,40,5", relax=2), ["--density", "cap:0,90,40,5", "--relax", "2"]),
]


@pytest.mark.parametrize("kwargs,args", SPHERE_REQUESTS, ids=lambda v: str(v) if isinstance(v, dict) else "")
def test_sphere_points_are_the_cli_points(cli, kwargs, args):
    kwargs = dict(kwargs)
    n = kwargs.pop("n")
    expected = read_utk(cli("sphere", "-n", n, "--format", "bin", *args))
    same(tessera.sphere(n, **kwargs), expected)


@pytest.mark.parametrize("kwargs,args", SPHERE_REQUESTS[3:8], ids=lambda v: str(v) if isinstance(v, dict) else "")
def test_sphere_pdfs_are_the_cli_pdfs(cli, kwargs, args):
    kwargs = dict(kwargs)
    n = kwargs.pop("n")
    header, rows = read_csv(cli("sphere", "-n", n, "--format", "csv", *args))
    assert header == ["x", "y", "z", "lon", "lat", "pdf"]
    points, pdf = tessera.sphere(n, pdf=True, **kwargs)
    same(points, rows[:, :3])
    same(pdf, rows[:, 5])
    # the pdf of any directions, with the density's options only
    density = kwargs.get("density", "uniform")
    same(tessera.pdf(points, density), pdf)
    # lon/lat as the CLI writes them
    lon, lat = tessera.lonlat(points)
    same(lon, rows[:, 3])
    same(lat, rows[:, 4])


def test_lonlat_is_the_cli_lonlat_format(cli):
    text = cli("sphere", "-n", 5000, "--density", "cap:170,-30,20,9", "--format", "lonlat").decode()
    lines = text.splitlines()
    assert lines[0].startswith("#")
    rows = np.array([[float(v) for v in line.split()] for line in lines[1:]])
    lon, lat = tessera.lonlat(tessera.sphere(5000, "cap:170,-30,20,9"))
    same(lon, rows[:, 0])
    same(lat, rows[:, 1])
    assert lon.min() >= -180 and lon.max() < 180


def test_map_file_and_array_are_the_cli_map(cli, sky_exr):
    path, rgb = sky_exr
    expected = read_utk(cli("sphere", "-n", 4000, "--map", path, "--format", "bin"))
    same(tessera.sphere(4000, map=path), expected)
    same(tessera.sphere(4000, map=str(path)), expected)
    # the same values as an array (float32, as the file holds them), or in float64
    same(tessera.sphere(4000, map=rgb), expected)
    same(tessera.sphere(4000, map=rgb.astype(np.float64)), expected)
    # or read once, for many calls
    prepared = tessera.Map(path)
    same(tessera.sphere(4000, map=prepared), expected)
    same(tessera.sphere(4000, map=tessera.Map(rgb)), expected)
    # with a seed, the other axis, a channel, the pdf column
    for options, args in [
        (dict(seed=11), ["--seed", "11"]),
        (dict(up="y"), ["--up", "y"]),
        (dict(channel="R"), ["--channel", "R"]),
        (dict(expected=True, unsorted=True), ["--expected", "--unsorted"]),
    ]:
        header, rows = read_csv(cli("sphere", "-n", 3000, "--map", path, "--format", "csv", *args))
        points, pdf = tessera.sphere(3000, map=path, pdf=True, **options)
        same(points, rows[:, :3])
        same(pdf, rows[:, 5])
        read_as = {k: v for k, v in options.items() if k in ("up", "channel")}
        request = {k: v for k, v in options.items() if k not in read_as}
        prepared = tessera.Map(path, **read_as)
        same(tessera.sphere(3000, map=prepared, **request), points)
        same(tessera.pdf(points, map=prepared), pdf)
        if "channel" not in options:
            same(tessera.sphere(3000, map=rgb, **options), points)
    # a grey array is the file's Y channel
    grey = rgb[..., 1]
    write_exr(path.with_name("grey.exr"), {"Y": grey})
    expected = read_utk(cli("sphere", "-n", 2000, "--map", path.with_name("grey.exr"), "--format", "bin"))
    same(tessera.sphere(2000, map=grey), expected)


def test_healpix_maps_are_the_cli_healpix_maps(cli, tmp_path):
    rng = np.random.default_rng(8)
    # nside 16 (rows of 1024 float32 in the file), a hot pixel, UNSEEN pixels
    values = (0.2 + rng.random(3072)).astype(np.float32)
    values[1000] = 500.0
    values[[7, 2000]] = -1.6375e30
    for nest in (False, True):
        path = tmp_path / f"map-{nest}.fits"
        write_healpix(path, values, nest=nest)
        ordering = dict(nest=True) if nest else {}
        for options, args in [({}, []), (dict(seed=5), ["--seed", "5"]), (dict(unsorted=True), ["--unsorted"])]:
            header, rows = read_csv(cli("sphere", "-n", 4000, "--healpix-map", path, "--format", "csv", *args))
            with pytest.warns(RuntimeWarning, match="2 UNSEEN pixel"):
                points, pdf = tessera.sphere(4000, healpix=values, pdf=True, **ordering, **options)
            same(points, rows[:, :3])
            same(pdf, rows[:, 5])
            with pytest.warns(RuntimeWarning, match="UNSEEN"):
                same(tessera.pdf(points, healpix=values.astype(np.float64), **ordering), pdf)
            # the file itself, and maps read once from the file and the array
            with pytest.warns(RuntimeWarning, match="2 UNSEEN pixel"):
                same(tessera.sphere(4000, healpix=path, **options), points)
            with pytest.warns(RuntimeWarning, match="2 UNSEEN pixel"):
                prepared = [tessera.HealpixMap(path), tessera.HealpixMap(values, **ordering)]
            for read_once in prepared:
                assert read_once.nside == 16
                same(tessera.sphere(4000, healpix=read_once, **options), points)
                same(tessera.pdf(points, healpix=read_once), pdf)
    # nside 8 in float64, one value a row
    values = 1.0 + rng.random(768)
    write_healpix(tmp_path / "d.fits", values, nest=True, dtype=">f8")
    expected = read_utk(cli("sphere", "-n", 1500, "--healpix-map", tmp_path / "d.fits", "--format", "bin"))
    same(tessera.sphere(1500, healpix=values, nest=True), expected)


def test_tables_read_at_run_time_are_the_cli_tables(cli, tmp_path):
    table = REPO / "luts" / "ppentomino.lut"
    expected = read_utk(cli("plane", "--system", "ppentomino", "-n", 2000, "--table", table, "--format", "bin"))
    same(tessera.plane(2000, "ppentomino", table=table), expected)
    # the shipped table is the built-in one
    same(tessera.plane(2000, "ppentomino", table=str(table)), tessera.plane(2000, "ppentomino"))
    for wrong in (lambda: tessera.sphere(10, table=table), lambda: tessera.plane(10, "ghexomino", table=table)):
        with pytest.raises(ValueError, match="ppentomino.lut: not a"):
            wrong()
    with pytest.raises(FileNotFoundError, match="missing.lut"):
        tessera.sphere(10, table=tmp_path / "missing.lut")


def test_png_map_is_the_cli_png_map(cli, tmp_path):
    rng = np.random.default_rng(3)
    pixels = rng.integers(0, 65536, size=(16, 32, 3))
    pixels[4, 7] = 65535
    path = tmp_path / "sky.png"
    write_png(path, pixels)
    expected = read_utk(cli("sphere", "-n", 3000, "--map", path, "--seed", "4", "--format", "bin"))
    same(tessera.sphere(3000, map=path, seed=4), expected)


PLANE_REQUESTS = [
    (dict(n=5000), ["--system", "ghexomino"]),
    (dict(n=5000, system="ppentomino"), ["--system", "ppentomino"]),
    (dict(n=3000, system="penrose", density="ramp"), ["--system", "penrose", "--density", "ramp"]),
    (dict(n=3000, density="ramp", seed=3), ["--system", "ghexomino", "--density", "ramp", "--seed", "3"]),
    (dict(n=3000, domain=(0, 0, 3, 1)), ["--system", "ghexomino", "--domain", "0,0,3,1"]),
    (
        dict(n=3000, system="ppentomino", density="ramp", domain="-1,-1,1,3", seed=9, unsorted=True),
        ["--system", "ppentomino", "--density", "ramp", "--domain=-1,-1,1,3", "--seed", "9", "--unsorted"],
    ),
    (dict(n=2000, system="penrose", expected=True), ["--system", "penrose", "--expected"]),
    (dict(n=3000, density="ramp", farthest_first=True), ["--system", "ghexomino", "--density", "ramp", "--farthest-first"]),
]


@pytest.mark.parametrize("kwargs,args", PLANE_REQUESTS, ids=lambda v: str(v) if isinstance(v, dict) else "")
def test_plane_points_and_pdfs_are_the_cli_ones(cli, kwargs, args):
    kwargs = dict(kwargs)
    n = kwargs.pop("n")
    same(tessera.plane(n, **kwargs), read_utk(cli("plane", "-n", n, "--format", "bin", *args)))
    header, rows = read_csv(cli("plane", "-n", n, "--format", "csv", *args))
    assert header == ["x", "y", "pdf"]
    points, pdf = tessera.plane(n, pdf=True, **kwargs)
    same(points, rows[:, :2])
    same(pdf, rows[:, 2])


def test_plane_images_are_the_cli_images(cli, tmp_path):
    rng = np.random.default_rng(8)
    y = np.linspace(0, 1, 48)[:, None] * np.linspace(0.2, 1, 40)[None, :] + 0.1 * rng.random((48, 40))
    y = y.astype(np.float32)
    path = tmp_path / "photo.exr"
    write_exr(path, {"Y": y})
    for invert, flags in [(False, []), (True, ["--invert"])]:
        expected = read_utk(cli("plane", "--system", "ghexomino", "-n", 4000, "--density", f"image:{path}", "--format", "bin", *flags))
        same(tessera.plane(4000, image=path, invert=invert), expected)
        same(tessera.plane(4000, density=f"image:{path}", invert=invert), expected)
        same(tessera.plane(4000, image=y, invert=invert), expected)
    png = tmp_path / "photo.png"
    write_png(png, (y * 65535).astype(np.int64))
    expected = read_utk(cli("plane", "--system", "penrose", "-n", 3000, "--density", f"image:{png}", "--format", "bin"))
    same(tessera.plane(3000, "penrose", image=png), expected)


def test_lights_are_the_cli_lights(cli, sky_exr):
    path, rgb = sky_exr
    for options, args in [
        (dict(), []),
        (dict(seed=5, exponent=0.8, lloyd=1), ["--seed", "5", "--exponent", "0.8", "--lloyd", "1"]),
        (dict(up="y"), ["--up", "y"]),
    ]:
        header, rows = read_csv(cli("lights", "--map", path, "-n", 24, *args))
        assert header == ["x", "y", "z", "r", "g", "b", "luminance", "solid_angle"]
        for given in (path, rgb):
            lights = tessera.lights(given, 24, **options)
            same(lights["direction"], rows[:, :3])
            same(lights["rgb"], rows[:, 3:6])
            same(lights["luminance"], rows[:, 6])
            same(lights["solid_angle"], rows[:, 7])
    header, rows = read_csv(cli("lights", "--map", path, "-n", 10, "--channel", "B"))
    same(tessera.lights(path, 10, channel="B")["luminance"], rows[:, 6])


def test_metrics_are_the_cli_metrics(cli, tmp_path):
    points_file = tmp_path / "points.bin"
    points_file.write_bytes(cli("sphere", "-n", 1500, "--density", "cap:0,0,30,4", "--format", "bin"))
    expected = json.loads(cli("metrics", "sphere", points_file, "--json"))
    report = tessera.metrics.sphere(read_utk(points_file.read_bytes()))
    # the same keys in the same order, and the same values, exactly
    assert list(report) == list(expected)
    assert report == expected
    plane_file = tmp_path / "plane.bin"
    plane_file.write_bytes(cli("plane", "--system", "penrose", "-n", 1200, "--density", "ramp", "--format", "bin"))
    expected = json.loads(cli("metrics", "plane", plane_file, "--json"))
    report = tessera.metrics.plane(tessera.plane(1200, "penrose", "ramp"))
    assert list(report) == list(expected)
    assert report == expected
    # beyond --pairs-up-to the O(N^2) measures are null there, NaN here
    for domain, path, measure in [("sphere", points_file, tessera.metrics.sphere), ("plane", plane_file, tessera.metrics.plane)]:
        expected = json.loads(cli("metrics", domain, path, "--json", "--pairs-up-to", 1000))
        dims = 3 if domain == "sphere" else 2
        report = measure(read_utk(path.read_bytes()).reshape(-1, dims), pairs_up_to=1000)
        skipped = [k for k, v in expected.items() if v is None]
        assert skipped and all(np.isnan(report[k]) for k in skipped)
        assert {k: v for k, v in report.items() if k not in skipped} == {k: v for k, v in expected.items() if k not in skipped}
    # --only / only=: just those keys, computed whatever N
    only = ["low_frequency_power", "min_distance_over_hex_spacing"]
    expected = json.loads(cli("metrics", "plane", plane_file, "--json", "--pairs-up-to", 10, "--only", ",".join(only)))
    report = tessera.metrics.plane(read_utk(plane_file.read_bytes()).reshape(-1, 2), only=only, pairs_up_to=10)
    assert list(report) == list(expected) == ["n", "min_distance_over_hex_spacing", "low_frequency_power"]
    assert report == expected
