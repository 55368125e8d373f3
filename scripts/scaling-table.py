#!/usr/bin/env python3
"""Prints docs/PERFORMANCE.md's "Against the baselines" table from the
medians `cargo bench --bench scaling` leaves in target/criterion.

    cargo bench --bench scaling && python3 scripts/scaling-table.py

Ratio = baseline median / tessera median (above 1: tessera is faster).
"""
import json
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent / "target" / "criterion"


def median(group, function, n):
    """Median seconds of one criterion benchmark, None if it did not run."""
    path = ROOT / group / function / str(n) / "new" / "estimates.json"
    if not path.exists():
        return None
    return json.loads(path.read_text())["median"]["point_estimate"] / 1e9


def seconds(t):
    if t is None:
        return "-"
    for unit, scale in (("s", 1.0), ("ms", 1e-3)):
        if t >= scale:
            return f"{t / scale:.3g} {unit}"
    return f"{t / 1e-3:.3g} ms"


def ratio(baseline, tessera):
    if baseline is None or tessera is None:
        return "-"
    r = baseline / tessera
    return f"{r:,.0f}" if r >= 100 else f"{r:.3g}"


def power(n):
    return f"10^{len(str(n)) - 1}"


# (density, group, tessera systems, sizes, baselines: function and label)
SPHERE = [("fibonacci", "spherical Fibonacci"), ("jittered_healpix", "jittered HEALPix"),
          ("iid", "i.i.d."), ("sobol", "Sobol (Owen), equal-area warp")]
SKY = [("inverse_cdf", "i.i.d. inverse-CDF"), ("alias", "alias table"),
       ("sobol_inverse_cdf", "Sobol (Owen), inverse-CDF warp")]
SQUARE = [("iid", "i.i.d."), ("sobol", "Sobol (Owen)"), ("bridson", "Bridson (fast_poisson)")]
RASTER = [("iid_inverse_cdf", "i.i.d. inverse-CDF"),
          ("sobol_inverse_cdf", "Sobol (Owen), inverse-CDF warp")]
PLANE = ["ghexomino", "ppentomino", "penrose"]
ROWS = [
    ("sphere, uniform", "sphere_uniform", [("sphere", "tessera")], [100_000, 10_000_000], SPHERE),
    ("sphere, generated sky map", "envmap_sky", [("sphere", "tessera")], [100_000], SKY),
    ("square, uniform", "plane_uniform", [(s, s) for s in PLANE], [100_000], SQUARE),
    ("square, uniform", "plane_uniform", [(s, s) for s in PLANE], [10_000_000], SQUARE),
    ("square, 256x256 image", "plane_raster", [(s, s) for s in PLANE], [100_000], RASTER),
]


def main():
    if not ROOT.exists():
        sys.exit(f"{ROOT} not found: run `cargo bench --bench scaling` first")
    print("| density | tessera system | N | baseline | baseline median | tessera, 1 thread "
          "| ratio | tessera, 2 threads | ratio |")
    print("|---|---|---:|---|---:|---:|---:|---:|---:|")
    for density, group, systems, sizes, baselines in ROWS:
        for n in sizes:
            for system, label in systems:
                one = median(group, f"{label}_1t", n)
                two = median(group, f"{label}_2t", n)
                for function, name in baselines:
                    base = median(group, function, n)
                    if base is None:
                        continue
                    print(f"| {density} | {system} | {power(n)} | {name} | {seconds(base)} "
                          f"| {seconds(one)} | {ratio(base, one)} | {seconds(two)} "
                          f"| {ratio(base, two)} |")
    n = 100_000_000
    one, base = median("sphere_stream", "tessera_1t", n), median("sphere_stream", "fibonacci", n)
    print(f"| sphere, uniform, streamed into a sink | sphere | {power(n)} | spherical Fibonacci "
          f"| {seconds(base)} | {seconds(one)} | {ratio(base, one)} | - | - |")
    print()
    n = 100_000
    adaptive = [("sphere under a cap (`sphere/cap`)", "sphere_cap", "tessera")] + [
        (f"{s} on the ramp (`plane/ramp`)", "plane_ramp", s) for s in PLANE]
    for text, group, label in adaptive:
        print(f"- {text}, N = 10^5, one thread: {seconds(median(group, f'{label}_1t', n))}")


if __name__ == "__main__":
    main()
