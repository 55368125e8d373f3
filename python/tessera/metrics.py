"""Quality measures of point sets: what ``tessera metrics --json`` prints.

>>> import tessera
>>> report = tessera.metrics.sphere(tessera.sphere(1000))
>>> list(report)
['n', 'separation', 'cap_discrepancy_l2', 'riesz1_normalized', 'covering_radius', 'mesh_ratio']
"""

import numpy as np

from . import _tessera

__all__ = ["sphere", "plane"]


#: the command line's default --pairs-up-to
PAIRS_UP_TO = 100_000


def _threads(threads):
    if threads is not None and (int(threads) != threads or threads < 1):
        raise ValueError(f"threads must be an integer >= 1, not {threads}")
    return None if threads is None else int(threads)


def _pairs(pairs_up_to):
    pairs_up_to = int(pairs_up_to)
    if not 0 <= pairs_up_to < 1 << 64:
        raise ValueError(f"pairs_up_to must be in [0, 2**64), not {pairs_up_to}")
    return pairs_up_to


def sphere(points, *, pairs_up_to=PAIRS_UP_TO, threads=None):
    """Separation, cap discrepancy, Riesz energy, covering radius and mesh ratio of unit vectors.

    ``points`` is an (n, 3) array of unit vectors (to 1e-6; others raise
    ``ValueError``, as ``tessera metrics sphere`` refuses them). Returns a
    dict with the keys of ``tessera metrics sphere FILE --json``: ``n``,
    ``separation`` (sqrt(N) x the minimum geodesic distance),
    ``cap_discrepancy_l2`` (Stolarsky), ``riesz1_normalized``,
    ``covering_radius`` (sqrt(N) x the geodesic covering radius) and
    ``mesh_ratio``. The two O(N^2) measures (cap discrepancy and energy;
    about 0.1 s for N = 10^4 on two cores) are computed only up to
    ``pairs_up_to`` points, as ``--pairs-up-to`` does, and are NaN beyond
    it (where the command line prints null). The GIL is released. (The
    command line's ``--spectrum`` and ``--png`` are not here.)

    Examples
    --------
    >>> import tessera
    >>> r = tessera.metrics.sphere(tessera.sphere(2000))
    >>> r["n"], 1.0 < r["mesh_ratio"] < 3.0
    (2000, True)
    """
    points = np.ascontiguousarray(points, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] != 3:
        raise ValueError(f"points are an (n, 3) array; this one has shape {points.shape}")
    return _tessera.metrics_sphere(points, _pairs(pairs_up_to), _threads(threads))


def plane(points, *, pairs_up_to=PAIRS_UP_TO, threads=None):
    """Nearest-neighbour distances, L2 discrepancies and low-frequency power of points in [0, 1)^2.

    ``points`` is an (n, 2) array. Returns a dict with the keys of
    ``tessera metrics plane FILE --json``: ``n``, ``min_distance`` and
    ``mean_nn_distance`` (over the hexagonal spacing),
    ``l2_star_discrepancy`` (Warnock), ``centered_l2_discrepancy``
    (Hickernell) and ``low_frequency_power``. The three O(N^2) measures
    (both discrepancies and the low-frequency power) are NaN beyond
    ``pairs_up_to`` points, as with ``--pairs-up-to``.

    Examples
    --------
    >>> import tessera
    >>> r = tessera.metrics.plane(tessera.plane(1024, "ppentomino"))
    >>> r["n"], 0.0 < r["l2_star_discrepancy"] < 0.01
    (1024, True)
    """
    points = np.ascontiguousarray(points, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] != 2:
        raise ValueError(f"points are an (n, 2) array; this one has shape {points.shape}")
    return _tessera.metrics_plane(points, _pairs(pairs_up_to), _threads(threads))
