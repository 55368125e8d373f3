"""tessera: hierarchical importance sampling with blue-noise properties.

Numpy arrays in and out of the tessera library (a Rust crate): points on the
unit sphere (HEALPix faces tiled by P-pentominoes) or in the unit square
(Penrose, G-hexomino, P-pentomino tilings), following a density, well spread
at every prefix. Every option means what the ``tessera`` command line's
option of the same name means, and the same request gives the same points,
bit for bit.

>>> import tessera
>>> points = tessera.sphere(1000, "cap:2.35,48.85,10,50")
>>> points.shape
(1000, 3)
>>> lon, lat = tessera.lonlat(points)
>>> bool(((lon >= -180) & (lon < 180)).all())
True

Errors in the request raise ``ValueError`` with the library's message, and
files that cannot be read ``OSError`` (``FileNotFoundError`` when missing).
The GIL is released while sampling.
"""

import operator
import os
import warnings as _warnings

import numpy as np

from . import _tessera
from . import metrics

__all__ = [
    "Map",
    "HealpixMap",
    "sphere",
    "pdf",
    "plane",
    "lights",
    "lonlat",
    "from_lonlat",
    "stream",
    "metrics",
]

__version__ = _tessera.__version__


def _count(n, name="n"):
    try:
        n = operator.index(n)
    except TypeError:
        raise TypeError(f"{name} must be an integer, not {type(n).__name__}") from None
    if not 0 <= n < 1 << 64:
        raise ValueError(f"{name} must be in [0, 2**64), not {n}")
    return n


def _seed(seed):
    if seed is None:
        return None
    return _count(seed, "seed")


def _threads(threads):
    if threads is None:
        return None
    threads = _count(threads, "threads")
    if threads == 0:
        raise ValueError("threads must be >= 1")
    return threads


def _spec(value, count, name):
    """A 'a,b,c' string, or a sequence of `count` numbers written as one."""
    if value is None or isinstance(value, str):
        return value
    numbers = [float(v) for v in value]
    if len(numbers) != count:
        raise ValueError(f"{name} takes {count} numbers, not {len(numbers)}")
    # repr round-trips: the library parses the same doubles back
    return ",".join(repr(v) for v in numbers)


def _densities(density):
    if isinstance(density, str):
        return [density]
    specs = list(density)
    if not all(isinstance(s, str) for s in specs):
        raise TypeError("density is a region string or a list of them")
    return specs


def _path(path):
    """A path as a string, or None."""
    return None if path is None else os.fsdecode(path)


def _map(map, name="map"):
    """(path, array, prepared map) of a map given as a path, an array or a Map."""
    if map is None:
        return None, None, None
    if isinstance(map, Map):
        return None, None, map._native
    if isinstance(map, HealpixMap):
        raise TypeError(f"a {name} is a lat-long map or image; a tessera.HealpixMap goes to healpix=")
    if isinstance(map, (str, bytes, os.PathLike)):
        return os.fsdecode(map), None, None
    array = np.ascontiguousarray(map, dtype=np.float64)
    if array.ndim not in (2, 3) or (array.ndim == 3 and array.shape[2] != 3):
        raise ValueError(f"a {name} array is H x W or H x W x 3; this one has shape {array.shape}")
    return None, array, None


def _warn(messages):
    for message in messages:
        _warnings.warn(message, RuntimeWarning, stacklevel=3)


def _healpix_array(healpix):
    """A HEALPix map given as values, as a float64 vector."""
    array = np.ascontiguousarray(healpix, dtype=np.float64)
    if array.ndim != 1:
        raise ValueError(f"a healpix map is a vector of 12 nside**2 values; this one has shape {array.shape}")
    return array


def _open_healpix(healpix, nest, field, strict):
    """(native HEALPix map, warnings) of a FITS path or an array."""
    if isinstance(healpix, (str, bytes, os.PathLike)):
        if nest:
            raise ValueError("nest applies to a HEALPix array; a FITS file declares its ORDERING")
        field = 0 if field is None else _count(field, "field")
        return _tessera.open_healpix(os.fsdecode(healpix), None, False, field, bool(strict))
    if field is not None:
        raise ValueError("field picks a column of a HEALPix FITS file, not of an array")
    return _tessera.open_healpix(None, _healpix_array(healpix), bool(nest), 0, bool(strict))


def _sphere_density(density, map, up, channel, strict, healpix, nest, field):
    """(region strings, native map, native HEALPix map, warnings) of the
    density options of ``sphere`` and ``pdf``: a map given as a path or an
    array is read here, as ``Map`` and ``HealpixMap`` read it."""
    if healpix is not None:
        if map is not None or density != "uniform":
            raise ValueError("a healpix map replaces the density: pass one of density=, map= and healpix=")
        if channel is not None or up != "z":
            raise ValueError("up and channel apply to a lat-long map (map=...), not to healpix=")
        if isinstance(healpix, HealpixMap):
            if nest or strict or field is not None:
                raise ValueError(
                    "a tessera.HealpixMap was read with its nest, field and strict: give them to HealpixMap()"
                )
            return [], None, healpix._native, []
        native, notes = _open_healpix(healpix, nest, field, strict)
        return [], None, native, notes
    if nest or field is not None:
        raise ValueError("nest and field apply to a HEALPix map (healpix=...)")
    if map is None:
        if channel is not None or strict or up != "z":
            raise ValueError("up, channel and strict apply to a map (map=... or healpix=...)")
        return _densities(density), None, None, []
    if density != "uniform":
        raise ValueError("a map replaces the density: pass map= or density=, not both")
    if isinstance(map, Map):
        if channel is not None or strict or up != "z":
            raise ValueError("a tessera.Map was read with its up, channel and strict: give them to Map()")
        return [], map._native, None, []
    path, array, _ = _map(map)
    native, notes = _tessera.open_map(path, array, up, channel, bool(strict))
    return [], native, None, notes


class Map:
    """A lat-long map read once, for many ``sphere`` and ``pdf`` calls.

    ``sphere(n, map=path_or_array)`` reads the file (or copies the array)
    and builds the map on every call; a renderer asking for samples and
    pdfs again and again passes a ``Map`` instead: it is read once, and the
    bounds sampling builds over it are kept. The arguments are those of
    ``sphere``'s ``map``, ``up``, ``channel`` and ``strict``; warnings about
    the map are given here.

    Attributes: ``width``, ``height`` and ``integral`` (of the map over the
    sphere, value x sr: the pdf's normaliser).

    Examples
    --------
    >>> import numpy as np, tessera
    >>> sky = tessera.Map(np.ones((32, 64)))
    >>> sky.width, sky.height, round(sky.integral / np.pi, 12)
    (64, 32, 4.0)
    >>> points, p = tessera.sphere(100, map=sky, pdf=True)
    >>> bool((tessera.pdf(points, map=sky) == p).all())
    True
    """

    def __init__(self, map, *, up="z", channel=None, strict=False):
        if isinstance(map, Map):
            raise TypeError("map is already a tessera.Map")
        path, array, _ = _map(map)
        self._native, notes = _tessera.open_map(path, array, up, channel, bool(strict))
        _warn(notes)

    @property
    def width(self):
        return self._native.width

    @property
    def height(self):
        return self._native.height

    @property
    def integral(self):
        return self._native.integral

    def __repr__(self):
        return f"tessera.Map({self.width}x{self.height}, integral {self.integral:g})"


class HealpixMap:
    """A HEALPix map read once, for many ``sphere`` and ``pdf`` calls.

    ``sphere(n, healpix=values_or_path)`` reads the map and builds the
    bounds sampling needs on every call; a ``HealpixMap`` is read once and
    keeps them. ``map`` is a vector of 12 nside**2 values (RING order
    unless ``nest``; a healpy map) or the path of a HEALPix FITS file
    (healpy's binary table, whose ORDERING header gives the order;
    ``field`` picks its column, 0 by default). ``strict`` refuses NaN,
    infinite and negative pixels; otherwise they count as 0, as UNSEEN
    pixels do, with a warning given here.

    Attributes: ``nside``, and ``coordsys`` (the file's COORDSYS, or
    None).

    Examples
    --------
    >>> import numpy as np, tessera
    >>> hot = np.ones(768); hot[300] = 1000.0  # nside 8, RING
    >>> sky = tessera.HealpixMap(hot)
    >>> sky.nside
    8
    >>> points = tessera.sphere(2000, healpix=sky)
    >>> bool((tessera.sphere(2000, healpix=hot) == points).all())
    True
    """

    def __init__(self, map, *, nest=False, field=None, strict=False):
        if isinstance(map, HealpixMap):
            raise TypeError("map is already a tessera.HealpixMap")
        self._native, notes = _open_healpix(map, nest, field, strict)
        _warn(notes)

    @property
    def nside(self):
        return self._native.nside

    @property
    def coordsys(self):
        return self._native.coordsys

    def __repr__(self):
        return f"tessera.HealpixMap(nside {self.nside})"


def sphere(
    n,
    density="uniform",
    *,
    map=None,
    healpix=None,
    nest=False,
    field=None,
    up="z",
    channel=None,
    strict=False,
    within=None,
    seed=None,
    threads=None,
    expected=False,
    unsorted=False,
    farthest_first=False,
    pdf=False,
    relax=0,
    table=None,
):
    """Samples of the unit sphere: an (n, 3) float64 array of unit vectors.

    What ``tessera sphere -n N`` writes, with the options of the same name.

    Parameters
    ----------
    n : int
        Number of samples (exact unless ``expected``).
    density : str or list of str
        ``"uniform"``, ``"cap:LON,LAT,RADIUS_DEG,CONTRAST"`` (degrees; the
        density is CONTRAST inside the cap, 1 outside) or
        ``"polygon:LON LAT,LON LAT,...;CONTRAST"`` (a GeoJSON-style lon/lat
        polygon). A list combines regions: the largest contrast of the
        regions containing a point wins, 1 elsewhere.
    map : path, array or Map, optional
        Importance from a lat-long map instead of ``density``: a file
        (OpenEXR, Radiance .hdr or PNG), a ``tessera.Map`` read once for
        many calls, or an H x W array (importance) or
        H x W x 3 array (linear RGB, taken in float32 as a file's channels
        are, reduced to Rec.709 luminance as the library reduces a file's).
        Row 0 is at +Z (theta = 0); column i covers phi = atan2(y, x) in
        [2 pi i / W, 2 pi (i + 1) / W). Constant per pixel per unit solid
        angle.
    healpix : array, path or HealpixMap, optional
        Importance from a HEALPix map instead of ``density``: a vector of
        12 nside**2 values (nside a power of two; a healpy map), RING
        order unless ``nest``; a HEALPix FITS file (its ORDERING header
        gives the order); or a ``tessera.HealpixMap`` read once for many
        calls. Constant per pixel per unit solid angle, in
        the map's frame (theta from +Z, phi = atan2(y, x), as
        ``healpy.ang2pix``). UNSEEN pixels count as 0 with a warning, as
        do NaN, infinite and negative ones (``strict`` refuses those).
    nest : bool
        The ``healpix`` array is in NESTED order.
    field : int, optional
        The column of a ``healpix`` FITS file to read (default 0), as
        ``tessera sphere --field``.
    up : {"z", "y"}
        The map's up axis; with "y" a direction (x, y, z) is looked up as
        (z, x, y).
    channel : str, optional
        Use this channel of the map file (e.g. "R", "Y") instead of luminance.
    strict : bool
        Refuse maps with NaN or infinite pixels, or negative ones beyond a
        lossy codec's noise (a HEALPix map: any negative one); otherwise
        they count as 0 (with a warning).
    within : str or (lon, lat, radius_deg), optional
        Return only the samples of the request inside this cap; only the
        tiles reaching it are visited, so a small window on a huge request
        costs what the window holds. The count is then the expected one.
        Not with a map, a seed or relax.
    seed : int, optional
        Sample in a uniformly random frame (a rotation) drawn from this
        seed: estimates averaged over seeds are unbiased. Without it the
        set is deterministic.
    threads : int, optional
        Worker threads (default: all cores). The output does not depend on it.
    expected : bool
        Skip the exactness pass: return the natural count near n.
    unsorted : bool
        The same samples in tile order instead of progressive order (a
        prefix is then not well spread).
    farthest_first : bool
        The same samples farthest first: each is the one farthest, in local
        spacings, from those before it, so that every prefix is evenly
        spread whatever its length (a sequential pass after sampling).
    pdf : bool
        Also return the pdf per steradian of each sample.
    relax : int
        Density-weighted Lloyd iterations run on the set: more even
        spacing, but prefixes are no longer progressive and the pdf is the
        target density's.
    table : path, optional
        Sample with this sphere table (written by ``tessera lut build``)
        instead of the built-in one, as ``tessera sphere --table``.

    Returns
    -------
    points : (n, 3) ndarray, or (points, pdf) with ``pdf=True``.

    Examples
    --------
    >>> import numpy as np, tessera
    >>> points = tessera.sphere(4096)
    >>> bool(np.allclose(np.linalg.norm(points, axis=1), 1.0))
    True
    >>> points, p = tessera.sphere(2000, ["cap:0,90,20,10", "cap:0,-90,20,10"], pdf=True)
    >>> int((np.abs(points[:, 2]) > np.cos(np.radians(20))).sum()) > 700  # 39 % expected
    True
    >>> sky = np.ones((32, 64)); sky[2, 10] = 1000.0
    >>> tessera.sphere(100, map=sky, seed=1).shape
    (100, 3)
    >>> hot = np.ones(768); hot[300] = 1000.0  # nside 8, RING
    >>> points = tessera.sphere(2000, healpix=hot)
    >>> 0.5 < float((tessera.pdf(points, healpix=hot) > 1).mean()) < 0.62  # 1000 / 1767
    True
    """
    n = _count(n)
    specs, native_map, native_healpix, notes = _sphere_density(
        density, map, up, channel, strict, healpix, nest, field
    )
    _warn(notes)
    points, pdfs = _tessera.sphere(
        n,
        specs,
        native_map,
        native_healpix,
        _spec(within, 3, "within"),
        _seed(seed),
        _threads(threads),
        bool(expected),
        bool(unsorted),
        bool(farthest_first),
        bool(pdf),
        _count(relax, "relax"),
        _path(table),
    )
    return (points, pdfs) if pdf else points


def pdf(
    directions,
    density="uniform",
    *,
    map=None,
    healpix=None,
    nest=False,
    field=None,
    up="z",
    channel=None,
    strict=False,
    threads=None,
    **request,
):
    """The pdf per steradian that ``sphere`` samples follow, at any directions.

    For multiple importance sampling: the same density options as
    ``sphere`` (``density``, ``map``, ``healpix``, ``nest``, ``field``,
    ``up``, ``channel``, ``strict``); in a render loop pass a
    ``tessera.Map`` (or ``tessera.HealpixMap``), read once.
    ``sphere``'s other options (``within``, ``seed``, ``expected``,
    ``unsorted``, ``farthest_first``, ``relax``, ``table``, ``n``) are accepted and do not change the pdf,
    as in ``tessera sphere --format csv``. Directions (an (n, 3) or (3,)
    array) need not be normalised.

    Examples
    --------
    >>> import numpy as np, tessera
    >>> float(tessera.pdf([0, 0, 1]) * 4 * np.pi)
    1.0
    >>> points, p = tessera.sphere(500, "cap:10,20,30,8", pdf=True)
    >>> bool((tessera.pdf(points, "cap:10,20,30,8") == p).all())
    True
    """
    unknown = set(request) - {
        "n",
        "within",
        "seed",
        "expected",
        "unsorted",
        "farthest_first",
        "relax",
        "pdf",
        "table",
    }
    if unknown:
        raise TypeError(f"pdf() got unexpected keyword argument(s): {', '.join(sorted(unknown))}")
    directions = np.ascontiguousarray(directions, dtype=np.float64)
    single = directions.ndim == 1
    rows = directions.reshape(1, -1) if single else directions
    if rows.ndim != 2 or rows.shape[1] != 3:
        raise ValueError(f"directions are an (n, 3) array; this one has shape {directions.shape}")
    specs, native_map, native_healpix, notes = _sphere_density(
        density, map, up, channel, strict, healpix, nest, field
    )
    _warn(notes)
    values = _tessera.pdf(rows, specs, native_map, native_healpix, _threads(threads))
    return values[0] if single else values


def plane(
    n,
    system="ghexomino",
    density="uniform",
    *,
    image=None,
    invert=False,
    domain=None,
    seed=None,
    threads=None,
    expected=False,
    unsorted=False,
    farthest_first=False,
    pdf=False,
    table=None,
):
    """Samples of the unit square (or a rectangle): an (n, 2) float64 array.

    What ``tessera plane --system SYSTEM -n N`` writes, with the options of
    the same name.

    Parameters
    ----------
    n : int
        Number of samples (exact unless ``expected``).
    system : {"ghexomino", "ppentomino", "penrose"}
        The tile system.
    density : str
        ``"uniform"``, ``"ramp"`` (proportional to x) or ``"image:PATH"``.
    image : path or array, optional
        Importance from an image instead of ``density``: a file (OpenEXR,
        Radiance .hdr or PNG; luminance as stored) or an H x W array (or
        H x W x 3, reduced to luminance). x runs along the columns, y down
        the rows from row 0.
    invert : bool
        Sample the image's complement ``max - value`` (stippling).
    domain : str or (x0, y0, x1, y1), optional
        Sample this rectangle instead of the unit square (the density's
        unit square stretched over it).
    seed : int, optional
        Sample under a uniformly random toroidal shift drawn from this seed.
    threads, expected, unsorted, farthest_first : as for ``sphere``.
    pdf : bool
        Also return the pdf per unit area of the domain of each sample.
    table : path, optional
        Sample with this table of ``system`` (written by ``tessera lut
        build``) instead of the built-in one, as ``tessera plane --table``.

    Examples
    --------
    >>> import tessera
    >>> tessera.plane(1000).shape
    (1000, 2)
    >>> points = tessera.plane(500, "penrose", "ramp", domain=(0, 0, 2, 1))
    >>> bool((points[:, 0] < 2).all() and (points[:, 1] < 1).all())
    True
    """
    n = _count(n)
    if image is not None and density != "uniform":
        raise ValueError("an image replaces the density: pass image= or density=, not both")
    if isinstance(image, Map):
        raise TypeError("an image is a path or an array, not a tessera.Map")
    image_path, image_array, _ = _map(image, "image")
    points, pdfs, notes = _tessera.plane(
        n,
        str(system),
        str(density),
        image_path,
        image_array,
        bool(invert),
        _spec(domain, 4, "domain"),
        _seed(seed),
        _threads(threads),
        bool(expected),
        bool(unsorted),
        bool(farthest_first),
        bool(pdf),
        _path(table),
    )
    _warn(notes)
    return (points, pdfs) if pdf else points


def lights(map, n, *, up="z", channel=None, strict=False, seed=None, exponent=None, lloyd=None, threads=None):
    """An environment map as n directional lights with exact powers.

    What ``tessera lights --map MAP -n N`` writes, as a dict of arrays:
    ``direction`` (n, 3) unit vectors towards the lights, ``rgb`` (n, 3)
    the integral of each channel over the light's cell (map units x sr),
    ``luminance`` (n,) the integral of the importance over the cell, and
    ``solid_angle`` (n,) the cell's solid angle (sr). The cells partition
    the sphere, so the powers sum to the map's integral.

    Parameters
    ----------
    map : path or array
        A lat-long map file (OpenEXR, Radiance .hdr, PNG) or an H x W x 3
        (linear RGB, taken in float32) or H x W array, row 0 at +Z.
    n : int
        Number of lights (exactly).
    up, channel, strict, seed, threads : as for ``sphere``.
    exponent : float, optional
        Directions follow value**exponent (default: a rule of n, 0.2 at
        n <= 64 rising to 0.875 at 256-1024 and 0.95 from 4096).
    lloyd : int, optional
        Lloyd steps after the first cut (default: a rule of n, 10 at
        n <= 128, 20 at 256-1024, 4 from 4096).

    Examples
    --------
    >>> import numpy as np, tessera
    >>> sky = np.ones((64, 128, 3)); sky[10, 40] = 500.0
    >>> l = tessera.lights(sky, 16)
    >>> sorted(l)
    ['direction', 'luminance', 'rgb', 'solid_angle']
    >>> bool(np.isclose(l["solid_angle"].sum(), 4 * np.pi))
    True
    """
    if isinstance(map, Map):
        raise TypeError("lights read their map's colour: pass the path or the array, not a tessera.Map")
    map_path, map_array, _ = _map(map)
    if map_path is None and map_array is None:
        raise ValueError("lights need a map (a path or an array)")
    direction, rgb, luminance, solid_angle, notes = _tessera.lights(
        map_path,
        map_array,
        _count(n),
        up,
        channel,
        bool(strict),
        _seed(seed),
        None if exponent is None else float(exponent),
        None if lloyd is None else _count(lloyd, "lloyd"),
        _threads(threads),
    )
    _warn(notes)
    return {"direction": direction, "rgb": rgb, "luminance": luminance, "solid_angle": solid_angle}


def lonlat(points):
    """Longitude and latitude in degrees of vectors (..., 3): a (lon, lat) pair.

    Longitude in [-180, 180) and latitude in [-90, 90], as ``tessera sphere
    --format lonlat`` writes them (Z up, lon = atan2(y, x)). Vectors need
    not be normalised.

    Examples
    --------
    >>> import tessera
    >>> lon, lat = tessera.lonlat([[-1.0, 0.0, 1.0]])
    >>> float(lon[0]), round(float(lat[0]), 12)
    (-180.0, 45.0)
    """
    points = np.ascontiguousarray(points, dtype=np.float64)
    if points.shape[-1:] != (3,):
        raise ValueError(f"points are a (..., 3) array; this one has shape {points.shape}")
    lon, lat = _tessera.lonlat(points.reshape(-1, 3))
    return lon.reshape(points.shape[:-1]), lat.reshape(points.shape[:-1])


def from_lonlat(lon, lat):
    """Unit vectors (..., 3) of longitudes and latitudes in degrees.

    The inverse of ``lonlat`` (Z up); ``lon`` and ``lat`` broadcast.

    Examples
    --------
    >>> import tessera
    >>> tessera.from_lonlat(0.0, 90.0).round(12).tolist()
    [0.0, 0.0, 1.0]
    >>> tessera.from_lonlat([0, 90], 0).round(12).tolist()
    [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
    """
    lon, lat = np.broadcast_arrays(np.asarray(lon, dtype=np.float64), np.asarray(lat, dtype=np.float64))
    shape = lon.shape
    points = _tessera.from_lonlat(np.ascontiguousarray(lon).reshape(-1), np.ascontiguousarray(lat).reshape(-1))
    return points.reshape(shape + (3,))


def stream(n, chunk=1 << 20):
    """Uniform sphere samples in chunks of at most ``chunk`` rows, in bounded memory.

    The n samples of ``sphere(n)``, in the same order (the library computes
    uniform samples from their codes a block at a time, in bounded memory),
    yielded as (k, 3) arrays: a billion points never need to be held at
    once. Each chunk is computed without the GIL, on one thread.

    Examples
    --------
    >>> import numpy as np, tessera
    >>> chunks = list(tessera.stream(2500, chunk=1000))
    >>> [len(c) for c in chunks]
    [1000, 1000, 500]
    >>> bool((np.concatenate(chunks) == tessera.sphere(2500)).all())
    True
    """
    n = _count(n)
    chunk = _count(chunk, "chunk")
    return _tessera.Stream(n, chunk)
