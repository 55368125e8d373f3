"""Quality measures of point sets: what ``tessera metrics --json`` prints.

The keys, their meanings and normalisations are those of
``tessera metrics --help`` (and of docs/QUALITY.md, "Metrics").

>>> import tessera
>>> report = tessera.metrics.sphere(tessera.sphere(1000))
>>> list(report)
['n', 'separation_sqrt_n', 'cap_discrepancy_l2', 'riesz1_excess_over_n1_5', 'covering_radius_sqrt_n', 'mesh_ratio']
"""

import numpy as np

from . import _tessera

__all__ = ["sphere", "plane", "PAIRS_UP_TO"]


#: the command line's default --pairs-up-to
PAIRS_UP_TO = _tessera.PAIRS_UP_TO


def _measure(domain, width, points, only, pairs_up_to, threads):
    """The report of ``points`` (an (n, width) array) on ``domain``."""
    points = np.ascontiguousarray(points, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] != width:
        raise ValueError(f"points are an (n, {width}) array; this one has shape {points.shape}")
    from . import _threads  # the package imports this module first

    pairs_up_to = int(pairs_up_to)
    if not 0 <= pairs_up_to < 1 << 64:
        raise ValueError(f"pairs_up_to must be in [0, 2**64), not {pairs_up_to}")
    if only is not None and not isinstance(only, str):
        only = ",".join(only)
    return _tessera.metrics(domain, points, only, pairs_up_to, _threads(threads))


def sphere(points, *, only=None, pairs_up_to=PAIRS_UP_TO, threads=None):
    """Separation, cap discrepancy, Riesz energy, covering radius and mesh ratio of unit vectors.

    ``points`` is an (n, 3) array of unit vectors (to 1e-6; others raise
    ``ValueError``, as ``tessera metrics sphere`` refuses them). Returns a
    dict with the keys of ``tessera metrics sphere FILE --json``: ``n``,
    ``separation_sqrt_n`` (sqrt(N) x the smallest geodesic angle),
    ``cap_discrepancy_l2`` (Stolarsky), ``riesz1_excess_over_n1_5``
    ((E - N^2) / N^1.5 of the Riesz s = 1 energy E),
    ``covering_radius_sqrt_n`` (sqrt(N) x the geodesic covering radius) and
    ``mesh_ratio``. ``only`` (keys, as a list or a comma-separated string)
    computes just those, whatever N. Otherwise the two O(N^2) measures (cap
    discrepancy and energy; about 0.1 s for N = 10^4 on two cores) are
    computed only up to ``pairs_up_to`` points, as ``--pairs-up-to`` does,
    and are NaN beyond it (where the command line prints null). The GIL is
    released. (The command line's ``--spectrum`` and ``--png`` are not
    here.)

    Examples
    --------
    >>> import tessera
    >>> r = tessera.metrics.sphere(tessera.sphere(2000))
    >>> r["n"], 1.0 < r["mesh_ratio"] < 3.0
    (2000, True)
    >>> tessera.metrics.sphere(tessera.sphere(100), only=["mesh_ratio"]).keys()
    dict_keys(['n', 'mesh_ratio'])
    """
    return _measure("sphere", 3, points, only, pairs_up_to, threads)


def plane(points, *, only=None, pairs_up_to=PAIRS_UP_TO, threads=None):
    """Nearest-neighbour distances, L2 discrepancies and low-frequency power of points in [0, 1)^2.

    ``points`` is an (n, 2) array. Returns a dict with the keys of
    ``tessera metrics plane FILE --json``: ``n``,
    ``min_distance_over_hex_spacing`` and
    ``mean_nn_distance_over_hex_spacing`` (over the spacing of the
    hexagonal lattice of the same density), ``l2_star_discrepancy``
    (Warnock), ``centered_l2_discrepancy`` (Hickernell) and
    ``low_frequency_power`` (white noise 1). ``only`` and ``pairs_up_to``
    are as for :func:`sphere`; the three O(N^2) measures are both
    discrepancies and the low-frequency power.

    Examples
    --------
    >>> import tessera
    >>> r = tessera.metrics.plane(tessera.plane(1024, "ppentomino"))
    >>> r["n"], 0.0 < r["l2_star_discrepancy"] < 0.01
    (1024, True)
    """
    return _measure("plane", 2, points, only, pairs_up_to, threads)
