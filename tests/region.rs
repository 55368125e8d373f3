//! Regional refinement (caps and lon/lat polygons, combined) and GeoJSON.

use glam::DVec3;
use tessera::density::region::Regions;
use tessera::density::sphere::lonlat_to_vec;
use tessera::density::Density;
use tessera::tiling::sphere::SphereRegion;
use tessera::Sampler;

#[test]
fn refined_regions_get_their_share() {
    let specs = [
        "polygon:-10 30,40 30,40 70,-10 70;16",
        "cap:120,-30,15,9",
        "cap:130,-30,10,25",
    ];
    let r = Regions::parse(&specs).unwrap();
    let n = 20_000;
    let samples = Sampler::sphere()
        .density(r.clone())
        .count(n)
        .generate()
        .unwrap();
    // expected shares by a fine equal-area quadrature (spherical Fibonacci)
    let quad = tessera::baselines::spherical_fibonacci(400_000);
    let total: f64 = quad
        .iter()
        .map(|&p| Density::<SphereRegion>::value(&r, p))
        .sum();
    for contrast in [1.0, 16.0, 9.0, 25.0] {
        let mass: f64 = quad
            .iter()
            .map(|&p| Density::<SphereRegion>::value(&r, p))
            .filter(|&v| v == contrast)
            .sum();
        let expected = mass / total * n as f64;
        let got = samples
            .iter()
            .filter(|s| Density::<SphereRegion>::value(&r, s.position) == contrast)
            .count() as f64;
        assert!(
            (got - expected).abs() < 0.03 * expected + 10.0,
            "contrast {contrast}: {got} samples, {expected:.0} expected"
        );
    }
}

#[test]
fn polygons_follow_geojson_conventions() {
    // crossing the antimeridian with longitudes beyond 180
    let r = Regions::parse(&["polygon:170 -10,190 -10,190 10,170 10;5"]).unwrap();
    let v = |lon, lat| Density::<SphereRegion>::value(&r, lonlat_to_vec(lon, lat));
    assert_eq!(v(-175.0, 0.0), 5.0);
    assert_eq!(v(175.0, 5.0), 5.0);
    assert_eq!(v(165.0, 0.0), 1.0);
    // a zero-contrast hole stays empty
    let hole = Regions::parse(&["polygon:0 -20,60 -20,60 20,0 20;0"]).unwrap();
    let s = Sampler::sphere()
        .density(hole.clone())
        .count(3000)
        .generate()
        .unwrap();
    assert_eq!(s.len(), 3000);
    assert!(s
        .iter()
        .all(|s| Density::<SphereRegion>::value(&hole, s.position) > 0.0));
}

#[test]
fn bad_region_specs_are_errors() {
    for spec in [
        "polygon:0 0,1 1;2",
        "polygon:0 0,1 1,1 0",
        "polygon:0 0,1 1,1 x;2",
        "polygon:0 0,1 100,1 0;2",
        "polygon:0 0,1 1,1 0;-1",
        "polygon:0 0,1 1,1 0;nan",
        "cap:0,0,5",
        "cap:0,0,500,2",
        "square:1",
    ] {
        let e = Regions::parse(&[spec]).unwrap_err().to_string();
        assert!(e.contains(spec), "{e}");
    }
    // zero everywhere
    assert!(Regions::parse(&["polygon:-200 -90,200 -90,200 90,-200 90;0"]).is_err());
}

#[test]
fn geojson_round_trips_through_the_command_line() {
    let dir = std::env::temp_dir().join(format!("tessera-region-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("set.geojson");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_tessera"))
        .args([
            "sphere",
            "-n",
            "300",
            "--density",
            "cap:0,90,30,4",
            "--density",
        ])
        .arg("polygon:0 0,30 0,30 30;9")
        .args(["--format", "geojson", "--report", "-o"])
        .arg(&path)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("mesh ratio"));
    let json: serde_json::Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    let features = json["features"].as_array().unwrap();
    assert_eq!(features.len(), 300);
    assert!(features
        .iter()
        .all(|f| f["properties"]["pdf"].as_f64().unwrap() > 0.0));
    let points = tessera::io::points::read_points(&path, 3).unwrap();
    assert_eq!(points.len(), 300);
    let p = DVec3::new(points[0][0], points[0][1], points[0][2]);
    assert!((p.length() - 1.0).abs() < 1e-12);
    std::fs::remove_dir_all(&dir).ok();
}
