//! The accuracy bench at a tiny size: i.i.d. converges like 1/N, the files
//! are written, and the tile samplers beat i.i.d.

use tessera::accuracy::{run, Config};

#[test]
fn tiny_accuracy_bench_fits_iid_slope_and_writes_its_files() {
    let results = run(&Config::tiny());
    let iid: Vec<f64> = ["sphere-uniform", "plane-uniform"]
        .iter()
        .flat_map(|s| {
            let r = &results;
            [
                "sh-mixture",
                "vmf-8",
                "gaussian",
                "gaussian-mixture",
                "cap-30deg",
                "disc",
            ]
            .iter()
            .map(move |i| r.mse_slope(s, "i.i.d.", i))
        })
        .filter(|v| v.is_finite())
        .collect();
    assert_eq!(iid.len(), 6, "each i.i.d. integrand fitted once");
    let mean = iid.iter().sum::<f64>() / iid.len() as f64;
    assert!(
        (mean + 1.0).abs() < 0.3,
        "i.i.d. MSE slope {mean} ({iid:?})"
    );
    // at N = 2^10 every tile sampler beats i.i.d. on the smooth integrands
    for row in results
        .rows
        .iter()
        .filter(|r| r.tessera && r.smooth && r.n == 1 << 10)
    {
        let iid = results
            .rows
            .iter()
            .find(|r| {
                r.scenario == row.scenario
                    && r.method == "i.i.d."
                    && r.integrand == row.integrand
                    && r.n == row.n
            })
            .expect("i.i.d. measured alongside");
        assert!(row.rel_rmse < iid.rel_rmse, "{row:?} against {iid:?}");
    }
    let dir = std::env::temp_dir().join(format!("tessera-accuracy-{}", std::process::id()));
    let files = results.write(&dir, "test").unwrap();
    assert!(dir.join("ACCURACY.md").exists());
    assert!(
        files
            .iter()
            .filter(|f| f.extension().is_some_and(|e| e == "png"))
            .count()
            >= 20
    );
    for png in files
        .iter()
        .filter(|f| f.extension().is_some_and(|e| e == "png"))
    {
        assert_eq!(image::open(png).unwrap().width(), 840);
    }
    let md = std::fs::read_to_string(dir.join("ACCURACY.md")).unwrap();
    for needle in [
        "fibonacci",
        "jittered-healpix",
        "sobol",
        "bridson",
        "ghexomino",
        "ppentomino",
        "penrose",
        "i.i.d. alias",
    ] {
        assert!(md.contains(needle), "{needle} missing from the report");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
