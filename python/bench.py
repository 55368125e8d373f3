"""Python overhead against the Rust API at N = 10^6 (target: at most 5 %).

Times each Python call against the library call it stands for, made by the
Rust example `examples/bench_baseline.rs` (built here with cargo) in a
process that answers one request at a time: the two sides alternate call
by call (in ABBA order), so that both see the same machine load, and the
medians are compared. Run from anywhere:
`python python/bench.py [--n N] [--runs R] [--threads T] [--no-build]`
(T worker threads on both sides, through RAYON_NUM_THREADS; default all
cores).

The map is a 1024 x 512 float32 sky made here, written as an EXR for the
Rust side: `sphere_map` samples a map built once (`tessera.Map`; an
`EnvMap` in Rust), `sphere_map_array` builds it from its pixels for each
request (the array passed to `tessera.sphere`; `EnvMap::new` of the raster
in Rust).
"""

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

# glibc's malloc maps large blocks afresh (fresh pages, a page fault each
# 4 KB) below a threshold it raises as it frees large blocks, so whether a
# 24-32 MB output costs page faults on every call depends on each
# process's history: the uniform sphere took 6-11 % longer from Python
# than from Rust when timed first, 2-4 % less when timed after the other
# requests, and both sides 75 ms with the threshold fixed (against
# 90-100). Both processes run with the same fixed thresholds (the Rust one
# inherits them), unless --allocator-as-is.
ALLOCATOR = {"MALLOC_MMAP_THRESHOLD_": str(1 << 28), "MALLOC_TRIM_THRESHOLD_": str(1 << 29)}
if "--allocator-as-is" not in sys.argv and any(os.environ.get(k) != v for k, v in ALLOCATOR.items()):
    # glibc reads them at start-up: start again with them set
    os.execve(sys.executable, [sys.executable, *sys.argv], {**os.environ, **ALLOCATOR})

# numpy's OpenBLAS starts worker threads at import that spin on a core now
# and then (`blas_thread_server` in a profile of this script, 2.5 % of its
# CPU time), though nothing here calls BLAS: they would be counted as the
# package's overhead. One BLAS thread starts none.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
# the installed package, not its sources beside this script
sys.path = [p for p in sys.path if Path(p or ".").resolve() != HERE]
sys.path.insert(0, str(HERE / "tests"))

from maps import sky, write_exr  # noqa: E402

CAP = "cap:10,20,30,10"


def python_calls(tessera, n, rgb):
    prepared = tessera.Map(rgb)
    return {
        "sphere_uniform": lambda: tessera.sphere(n),
        "sphere_cap": lambda: tessera.sphere(n, CAP),
        "plane_ghexomino": lambda: tessera.plane(n),
        "sphere_map": lambda: tessera.sphere(n, map=prepared),
        "sphere_map_array": lambda: tessera.sphere(n, map=rgb),
    }


def time_python(call):
    """(wall, CPU) seconds of one call; its result is freed outside the timing."""
    started, cpu = time.perf_counter(), time.process_time()
    out = call()
    elapsed = (time.perf_counter() - started, time.process_time() - cpu)
    del out
    return elapsed


def time_rust(server, name):
    server.stdin.write(name + "\n")
    server.stdin.flush()
    wall, cpu = server.stdout.readline().split()
    return float(wall), float(cpu)


def quartiles(times):
    q = statistics.quantiles(times, n=4)
    return q[0], q[2]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=10**6)
    parser.add_argument("--runs", type=int, default=20, help="timed calls per request and side")
    parser.add_argument("--threads", type=int, help="worker threads on both sides (default: all cores)")
    parser.add_argument("--no-build", action="store_true", help="use the example binary as built")
    parser.add_argument(
        "--allocator-as-is", action="store_true", help="keep glibc's dynamic malloc thresholds (see above)"
    )
    args = parser.parse_args()
    if args.threads:
        # read by rayon's global pool, in the Rust example and in this process
        os.environ["RAYON_NUM_THREADS"] = str(args.threads)
    import tessera

    target = Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
    baseline = target / "release" / "examples" / "bench_baseline"
    if not args.no_build:
        subprocess.run(["cargo", "build", "--release", "--example", "bench_baseline"], cwd=REPO, check=True)
    rgb = sky(1024, 512)
    with tempfile.TemporaryDirectory() as tmp:
        exr = Path(tmp) / "sky.exr"
        write_exr(exr, {"R": rgb[..., 0], "G": rgb[..., 1], "B": rgb[..., 2]})
        # the same request gives the same points from the array and the file
        assert (tessera.sphere(1000, map=rgb) == tessera.sphere(1000, map=exr)).all()
        calls = python_calls(tessera, args.n, rgb)
        rust = {name: [] for name in calls}
        python = {name: [] for name in calls}
        server = subprocess.Popen(
            [str(baseline), str(args.n), str(exr)], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True
        )
        try:
            for name, call in calls.items():
                time_rust(server, name), time_python(call)  # warm-up
                for run in range(args.runs):
                    if run % 4 in (0, 3):
                        rust[name].append(time_rust(server, name))
                        python[name].append(time_python(call))
                    else:
                        python[name].append(time_python(call))
                        rust[name].append(time_rust(server, name))
        finally:
            server.stdin.close()
            server.wait()

    threads = args.threads or os.cpu_count()
    print(f"N = {args.n}, {args.runs} alternating calls per request and side, {threads} thread(s)")
    print("median [quartiles]")
    worst = {}
    for k, clock in enumerate(["wall-clock", "CPU"]):
        print(f"{clock + ' ms':<18}{'Rust':>22}{'Python':>22}{'overhead':>10}")
        for name in calls:
            r_times = [t[k] for t in rust[name]]
            p_times = [t[k] for t in python[name]]
            r, p = statistics.median(r_times), statistics.median(p_times)
            (r1, r3), (p1, p3) = quartiles(r_times), quartiles(p_times)
            overhead = p / r - 1
            worst[clock] = max(worst.get(clock, -1.0), overhead)
            print(
                f"{name:<18}{r * 1e3:>8.1f} [{r1 * 1e3:6.1f},{r3 * 1e3:6.1f}]"
                f"{p * 1e3:>8.1f} [{p1 * 1e3:6.1f},{p3 * 1e3:6.1f}]{overhead * 100:>9.1f}%"
            )
    for clock, overhead in worst.items():
        print(f"largest {clock} overhead {overhead * 100:.1f}% (target: at most 5%)")


if __name__ == "__main__":
    main()
