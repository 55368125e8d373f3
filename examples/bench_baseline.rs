//! The Rust side of `python/bench.py`: runs the library calls that the
//! Python package's functions make (`SphereRequest::points` and
//! `PlaneRequest::points`, which return positions as the Python functions
//! do, and cost what `Sampler::generate` does within noise), one per
//! request name read from
//! standard input, and answers each with `WALL CPU` (seconds of wall-clock
//! and of this process's CPU time, all threads), so that the bench can
//! alternate Rust and Python calls one by one under the same machine load.
//! Run: `cargo run --release --example bench_baseline -- N MAP.exr`, then
//! type `sphere_uniform`, `sphere_cap`, `plane_ghexomino`, `sphere_map` or
//! `sphere_map_array`.

use std::io::{BufRead, Write};
use std::time::Instant;
use tessera::density::envmap::{EnvMap, Up};
use tessera::request::{PlaneKind, PlaneRequest, SphereDensity, SphereRequest};

/// This process's CPU time (all threads), in seconds.
#[cfg(target_os = "linux")]
fn cpu_seconds() -> f64 {
    let mut t = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `t` is a valid timespec for the call to fill.
    unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut t) };
    t.tv_sec as f64 + t.tv_nsec as f64 * 1e-9
}

#[cfg(not(target_os = "linux"))]
fn cpu_seconds() -> f64 {
    f64::NAN
}

/// Wall-clock and CPU seconds of `f`; its result is freed outside the
/// timing, as Python frees the array later.
fn time<T>(f: impl FnOnce() -> T) -> (f64, f64) {
    let (started, cpu) = (Instant::now(), cpu_seconds());
    let out = f();
    let elapsed = (started.elapsed().as_secs_f64(), cpu_seconds() - cpu);
    drop(out);
    elapsed
}

fn main() -> Result<(), tessera::Error> {
    let mut args = std::env::args().skip(1);
    let n: usize = args
        .next()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1_000_000);
    let path = args.next().unwrap_or_else(|| "sky.exr".into());
    let uniform = SphereDensity::parse(&["uniform"])?;
    let cap = SphereDensity::parse(&["cap:10,20,30,10"])?;
    let ghexomino = tessera::density::plane::parse("uniform", false)?;
    let sphere = SphereRequest {
        count: n,
        ..Default::default()
    };
    let plane = PlaneRequest::new(PlaneKind::Ghexomino, n);
    // a map built once and sampled again and again (`tessera.Map`)
    let map = SphereDensity::Map(EnvMap::open(path.as_ref(), &Default::default(), Up::Z)?);
    // its pixels, to build a map from for each request (an array passed
    // to `tessera.sphere`)
    let raster = tessera::io::image::read_raster(path.as_ref(), &Default::default())?;
    let mut out = std::io::stdout().lock();
    for line in std::io::stdin().lock().lines() {
        let line = line.map_err(|source| tessera::Error::Io {
            path: "standard input".into(),
            source,
        })?;
        let (wall, cpu) = match line.trim() {
            "sphere_uniform" => time(|| sphere.points(&uniform)),
            "sphere_cap" => time(|| sphere.points(&cap)),
            "plane_ghexomino" => time(|| plane.points(&*ghexomino)),
            "sphere_map" => time(|| sphere.points(&map)),
            "sphere_map_array" => time(|| {
                let map = EnvMap::new(raster.clone(), Up::Z)?;
                sphere.points(&SphereDensity::Map(map))
            }),
            other => {
                eprintln!("unknown request '{other}'");
                std::process::exit(2);
            }
        };
        writeln!(out, "{wall:.6} {cpu:.6}")
            .and_then(|()| out.flush())
            .map_err(|source| tessera::Error::Io {
                path: "standard output".into(),
                source,
            })?;
    }
    Ok(())
}
