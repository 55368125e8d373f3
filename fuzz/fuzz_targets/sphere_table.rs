//! Table files: the shipped table with fuzzed byte patches (and an optional
//! truncation) decodes to a validated table or an error, and a table that
//! decodes drives the sampler without a panic.
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::sync::Arc;
use tessera::lut::SphereLut;
use tessera::tiling::sphere::SphereTiling;

static SHIPPED: &[u8] = include_bytes!("../../luts/sphere.lut");

fuzz_target!(|data: &[u8]| {
    let mut bytes = SHIPPED.to_vec();
    // each 5-byte chunk writes one byte at a position; a 4-byte tail truncates
    let mut chunks = data.chunks_exact(5);
    for chunk in &mut chunks {
        let at = u32::from_le_bytes([chunk[0], chunk[1], chunk[2], chunk[3]]) as usize;
        let len = bytes.len();
        bytes[at % len] = chunk[4];
    }
    if let [a, b, c, d] = *chunks.remainder() {
        bytes.truncate(u32::from_le_bytes([a, b, c, d]) as usize % (SHIPPED.len() + 1));
    }
    if let Ok(lut) = SphereLut::from_bytes(&bytes) {
        let tiling = SphereTiling::new(Arc::new(lut));
        let _ = tessera::engine::generate(&tiling, &tessera::density::Uniform, 100, true);
        let _ = tessera::engine::generate(&tiling, &tessera::density::Uniform, 70_000, true);
    }
});
