"""A global point set refined by a raster of desired spacing in km.

The spacing raster (here made up: 25 km along a fault line and around a
volcano, 250 km elsewhere; in practice read from your model) sits on a
lon/lat grid. Points per unit area go as 1 / spacing^2, which is the
density tessera samples; the count follows from the area each point
covers (a hexagonal cell of side-to-side spacing h has area
sqrt(3)/2 h^2). The set is written as `lon lat` degrees, as
`tessera sphere --format lonlat` writes it.

    python examples/python/geophysics.py [points.txt]
"""

import sys

import numpy as np

import tessera

EARTH_RADIUS_KM = 6371.0
out = sys.argv[1] if len(sys.argv) > 1 else "refined-lonlat.txt"

# the raster: 0.5-degree cells, row 0 at the north pole, columns from lon -180
lat = 90 - (np.arange(360) + 0.5) * 0.5
lon = -180 + (np.arange(720) + 0.5) * 0.5
LON, LAT = np.meshgrid(lon, lat)
fault = np.abs(LAT - (0.6 * LON - 20)) < 2.0  # a band 4 degrees wide
fault &= (LON > 0) & (LON < 60)
volcano = np.hypot(LON + 155.3, LAT - 19.4) < 3.0
spacing_km = np.where(fault | volcano, 25.0, 250.0)

# tessera's lat-long maps start at lon 0 (phi = atan2(y, x)): roll the columns
density = np.roll(1.0 / spacing_km**2, -360, axis=1)
cell_area = (np.radians(0.5) * EARTH_RADIUS_KM) ** 2 * np.cos(np.radians(LAT))
n = int(round(np.sum(cell_area / (np.sqrt(3) / 2 * spacing_km**2))))

points = tessera.sphere(n, map=density)
lon_out, lat_out = tessera.lonlat(points)
np.savetxt(out, np.column_stack([lon_out, lat_out]), header="lon lat (degrees)", fmt="%.10g")

# check: nearest-neighbour distances where 25 km and 250 km were asked for
# (a blue-noise set's are about 0.8 of the hexagonal spacing)
fine = (np.abs(lat_out - (0.6 * lon_out - 20)) < 1.5) & (lon_out > 5) & (lon_out < 55)
for name, mask, asked in [("fault", fine, 25.0), ("elsewhere", ~fine, 250.0)]:
    probe = points[mask][:300]
    d = np.arccos(np.clip(probe @ points.T, -1, 1))
    d[d < 1e-12] = np.inf
    km = np.median(d.min(axis=1)) * EARTH_RADIUS_KM
    print(f"{name:>9}: median nearest-neighbour distance {km:6.1f} km ({km / asked:.2f} of the spacing asked)")
print(f"{n} points written to {out}")
