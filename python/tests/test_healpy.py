"""HEALPix maps against healpy, when it is installed (python/ci.sh tries
to install it; without it these tests are skipped): the files healpy
writes read as healpy reads them, and samples land where healpy's ang2pix
says, in RING and NESTED order."""

import warnings

import numpy as np
import pytest

import tessera
from conftest import read_utk

hp = pytest.importorskip("healpy")


@pytest.mark.parametrize("nest", [False, True])
def test_samples_land_in_healpy_pixels(nest):
    nside = 8
    rng = np.random.default_rng(3)
    values = rng.random(hp.nside2npix(nside))
    points, pdf = tessera.sphere(20_000, healpix=values, nest=nest, seed=1, pdf=True)
    pixels = hp.vec2pix(nside, points[:, 0], points[:, 1], points[:, 2], nest=nest)
    # the pdf is the value of healpy's pixel over 4 pi times the mean
    assert pdf == pytest.approx(values[pixels] / (4 * np.pi * values.mean()), rel=1e-12)
    # and a one-pixel map puts every sample in that pixel
    hot = np.zeros(hp.nside2npix(nside))
    hot[123] = 1.0
    points = tessera.sphere(500, healpix=hot, nest=nest)
    assert (hp.vec2pix(nside, *points.T, nest=nest) == 123).all()


@pytest.mark.parametrize("nest", [False, True])
def test_files_healpy_writes_are_read_as_healpy_reads_them(cli, tmp_path, nest):
    rng = np.random.default_rng(4)
    nside = 16
    maps = [rng.random(hp.nside2npix(nside)) for _ in range(3)]
    maps[1][[5, 77]] = hp.UNSEEN
    path = tmp_path / "iqu.fits"
    hp.write_map(str(path), maps, nest=nest, coord="G", dtype=np.float32)
    for field in range(3):
        read = hp.read_map(str(path), field=field, nest=nest)
        expected = read_utk(cli("sphere", "-n", 3000, "--healpix-map", path, "--field", field, "--format", "bin"))
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            points = tessera.sphere(3000, healpix=read, nest=nest)
        assert any("2 UNSEEN pixel(s)" in str(w.message) for w in caught) == (field == 1)
        assert points.tobytes() == expected.tobytes()
        # the file itself, read by tessera
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            assert tessera.sphere(3000, healpix=path, field=field).tobytes() == expected.tobytes()
            assert tessera.HealpixMap(path, field=field).coordsys == "G"
        pixels = hp.vec2pix(nside, *points.T, nest=nest)
        assert (read[pixels] > 0).all()


def test_partial_sky_files(cli, tmp_path):
    nside = 8
    values = np.full(hp.nside2npix(nside), hp.UNSEEN)
    values[100:140] = np.linspace(1, 2, 40)
    path = tmp_path / "partial.fits"
    hp.write_map(str(path), values, partial=True, dtype=np.float64)
    read = hp.read_map(str(path))
    assert (read == values).all()
    points = read_utk(cli("sphere", "-n", 2000, "--healpix-map", path, "--format", "bin"))
    with pytest.warns(RuntimeWarning, match="UNSEEN"):
        assert tessera.sphere(2000, healpix=path).tobytes() == points.tobytes()
    pixels = hp.vec2pix(nside, *points.T)
    assert ((pixels >= 100) & (pixels < 140)).all()
