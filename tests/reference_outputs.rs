//! The samples of a fixed set of requests, held in
//! `tests/data/reference_outputs.txt`: speed and layout work must keep them
//! (to 1e-12, so other CPUs and libm versions pass). Only a change that
//! alters sampling on purpose regenerates them, with
//! `TESSERA_BLESS=1 cargo test --release --test reference_outputs`, and
//! says so in its commit.

use glam::DVec3;
use tessera::density::envmap::{EnvMap, Up};
use tessera::density::plane::{Ramp, Raster, Shifted};
use tessera::density::sphere::{Cap, Rotated};
use tessera::density::Uniform;
use tessera::engine;
use tessera::synth::{Raster2d, Sky};
use tessera::tiling::penrose::PenroseTiling;
use tessera::tiling::plane::PlaneTiling;
use tessera::tiling::sphere::SphereTiling;

/// Each request's name and its samples as rows of numbers (position, rank).
fn requests() -> Vec<(String, Vec<Vec<f64>>)> {
    let sphere = SphereTiling::default();
    let rows3 = |s: Vec<tessera::Sample<DVec3>>| -> Vec<Vec<f64>> {
        s.iter()
            .map(|s| vec![s.position.x, s.position.y, s.position.z, s.rank])
            .collect()
    };
    let rows2 = |s: Vec<tessera::Sample<glam::DVec2>>| -> Vec<Vec<f64>> {
        s.iter()
            .map(|s| vec![s.position.x, s.position.y, s.rank])
            .collect()
    };
    let cap = Cap::new(30.0, 20.0, 25.0, 16.0).unwrap();
    let map = EnvMap::new(Sky::ClearSky.generate(256, 128, 1).raster(), Up::Z).unwrap();
    let raster = Raster::new(128, 128, Raster2d::Mixed.generate(128, 128, 1), false).unwrap();
    let (ghex, ppent) = (PlaneTiling::ghexomino(), PlaneTiling::ppentomino());
    let generate3 = |d: &dyn tessera::density::Density<_>, n| {
        rows3(engine::generate(&sphere, d, n, true).unwrap())
    };
    vec![
        ("sphere uniform 700".into(), generate3(&Uniform, 700)),
        ("sphere cap 600".into(), generate3(&cap, 600)),
        (
            "sphere cap seed 3, 400".into(),
            generate3(&Rotated::new(cap, 3), 400),
        ),
        ("sky map 500".into(), rows3(map.generate(500).unwrap())),
        (
            "sky map seed 5, 300".into(),
            rows3(map.with_seed(5).generate(300).unwrap()),
        ),
        (
            "G-hexomino ramp 600".into(),
            rows2(engine::generate(&ghex, &Ramp, 600, true).unwrap()),
        ),
        (
            "P-pentomino raster seed 2, 500".into(),
            rows2(engine::generate(&ppent, &Shifted::new(&raster, 2), 500, true).unwrap()),
        ),
        (
            "Penrose ramp 400".into(),
            rows2(engine::generate(&PenroseTiling::default(), &Ramp, 400, true).unwrap()),
        ),
        (
            "P-pentomino uniform 500".into(),
            rows2(engine::generate(&ppent, &Uniform, 500, true).unwrap()),
        ),
    ]
}

fn render(requests: &[(String, Vec<Vec<f64>>)]) -> String {
    let mut out = String::new();
    for (name, rows) in requests {
        out.push_str(&format!("# {name}: {} samples\n", rows.len()));
        for row in rows {
            let cells: Vec<String> = row.iter().map(|v| format!("{v:.17e}")).collect();
            out.push_str(&cells.join(" "));
            out.push('\n');
        }
    }
    out
}

#[test]
fn fixed_requests_give_the_reference_samples() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/reference_outputs.txt");
    let now = requests();
    if std::env::var_os("TESSERA_BLESS").is_some() {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, render(&now)).unwrap();
        return;
    }
    let stored =
        std::fs::read_to_string(&path).expect("the reference file (TESSERA_BLESS=1 writes it)");
    let mut lines = stored.lines();
    for (name, rows) in &now {
        let header = lines.next().expect("a request header");
        assert_eq!(
            header,
            format!("# {name}: {} samples", rows.len()),
            "request {name}"
        );
        for (k, row) in rows.iter().enumerate() {
            let line = lines.next().expect("a sample line");
            let want: Vec<f64> = line.split(' ').map(|v| v.parse().unwrap()).collect();
            assert_eq!(want.len(), row.len(), "{name}, sample {k}");
            for (a, b) in row.iter().zip(&want) {
                assert!(
                    (a - b).abs() <= 1e-12,
                    "{name}, sample {k}: {a} against {b}"
                );
            }
        }
    }
    assert!(
        lines.next().is_none(),
        "the reference holds more requests than the test"
    );
}
