//! Density strings from the command line: parse, and sample whatever parses.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(spec) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(density) = tessera::density::sphere::parse(spec) {
        let tiling = tessera::tiling::sphere::SphereTiling::default();
        if let Ok(samples) = tessera::engine::generate(&tiling, &*density, 64, true) {
            assert!(samples.iter().all(|s| s.position.is_finite()));
        }
    }
});
