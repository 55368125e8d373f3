"""Targets over a survey footprint of caps and polygons on the sky.

Deep fields (caps) get 25 times the base density, a survey stripe (a
polygon in RA/Dec, as GeoJSON lon/lat) 4 times; the finest request wins
where they overlap. Sky coordinates are lon/lat with RA = lon mod 360.
A small field of a huge request is cut out with `within`, which visits
only the tiles reaching it.

A HEALPix map (what healpy holds: 12 nside^2 values, RING order, or
NESTED with `nest=True`) is a density too: here a selection function in
Galactic coordinates, the plane masked with UNSEEN. From a FITS file the
command line reads it directly: `tessera sphere --healpix-map sel.fits`.

    python examples/python/astronomy.py
"""

import warnings

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

# A HEALPix selection map, nside 64 in RING order: no targets within 10
# degrees of the Galactic plane (UNSEEN), then a density rising as sin|b|.
# RING pixels run ring by ring from the north pole, so each pixel's
# latitude follows from its ring (the HEALPix ring formulas).
nside = 64
npix = 12 * nside**2
pix = np.arange(npix)
cap = 2 * nside * (nside - 1)


def ring_of(p):
    return np.floor((1 + np.sqrt(1 + 2 * p)) / 2).astype(int)


ring = np.where(pix < cap, ring_of(pix), nside + (pix - cap) // (4 * nside))
ring = np.where(pix >= npix - cap, 4 * nside - ring_of(npix - 1 - pix), ring)
z = np.where(ring <= nside, 1 - ring**2 / (3 * nside**2), 4 / 3 - 2 * ring / (3 * nside))
z = np.where(ring >= 3 * nside, -(1 - (4 * nside - ring) ** 2 / (3 * nside**2)), z)
selection = np.abs(z)
masked = np.abs(z) < np.sin(np.radians(10))
selection[masked] = -1.6375e30  # healpy's UNSEEN

with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    targets, pdf = tessera.sphere(50_000, healpix=selection, seed=7, pdf=True)
for w in caught:
    print(f"warning: {w.message}")
_, b = tessera.lonlat(targets)
weights = np.where(masked, 0.0, selection)
for lo, hi in [(0, 10), (10, 30), (30, 60), (60, 90)]:
    band = (np.abs(np.degrees(np.arcsin(z))) >= lo) & (np.abs(np.degrees(np.arcsin(z))) < hi)
    share = weights[band].sum() / weights.sum()
    got = np.mean((np.abs(b) >= lo) & (np.abs(b) < hi))
    print(f"|b| in [{lo:2d}, {hi:2d}) deg: {got:6.2%} of targets, {share:6.2%} of the map (pixels by centre)")
print(f"unmasked sky from the targets' pdfs: {np.mean(1 / pdf[pdf > 0]) / (4 * np.pi):.4f} of the sphere "
      f"(map: {1 - masked.mean():.4f})")
