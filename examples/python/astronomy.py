"""Targets over a survey footprint of caps and polygons on the sky.

Deep fields (caps) get 25 times the base density, a survey stripe (a
polygon in RA/Dec, as GeoJSON lon/lat) 4 times; the finest request wins
where they overlap. Sky coordinates are lon/lat with RA = lon mod 360.
A small field of a huge request is cut out with `within`, which visits
only the tiles reaching it.

HEALPix map input (a healpy map as the density, `healpix=` / `nest=`) is
pending; until then a HEALPix map can be given as caps and polygons, or
resampled to a lat-long array and passed as `map=`.

    python examples/python/astronomy.py
"""

import numpy as np

import tessera

deep_fields = ["cap:150.1,2.2,1.4,25", "cap:53.1,-27.8,1.0,25"]  # COSMOS-, CDF-S-like
stripe = "polygon:-50 -1.25,60 -1.25,60 1.25,-50 1.25;4"  # an equatorial stripe
footprint = deep_fields + [stripe]

points, pdf = tessera.sphere(200_000, footprint, seed=42, pdf=True)
ra, dec = tessera.lonlat(points)
ra = np.mod(ra, 360.0)

contrast = np.round(pdf / pdf.min()).astype(int)
for level, name in [(25, "deep fields"), (4, "stripe"), (1, "elsewhere")]:
    print(f"{name:>12}: {np.sum(contrast == level):6d} targets")

# weights 1 / (N pdf) make sums over targets unbiased integrals over the sky
in_stripe = contrast == 4
area = np.sum(1.0 / (len(points) * pdf[in_stripe]))
exact = np.radians(110.0) * 2 * np.sin(np.radians(1.25))
print(f"stripe area from the targets: {np.degrees(np.degrees(area)):.2f} sq deg (exact {np.degrees(np.degrees(exact)):.2f})")

# 10^9 targets' worth of spacing, but only those within 0.3 degrees of a centre
field = tessera.sphere(10**9, footprint, within=(150.1, 2.2, 0.3))
print(f"within 0.3 deg of (150.1, 2.2) in a 10^9 request: {len(field)} targets")
