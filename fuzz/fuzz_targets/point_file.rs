//! Point files (text and UTK binary) as `tessera metrics` reads them.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    for dims in 1..=3 {
        let _ = tessera::io::points::read_points_from(data, dims, "fuzz");
    }
});
