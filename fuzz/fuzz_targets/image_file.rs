//! Image files (EXR, Radiance .hdr, PNG) as `tessera sphere --map` reads
//! them: a raster or an error, never a panic that escapes the library, and
//! a raster that loads samples without one. The first input byte picks the
//! format's magic so the fuzzer reaches every decoder.
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::sync::Once;
use tessera::io::image::{read_raster, ReadOptions};

static QUIET: Once = Once::new();

fuzz_target!(|data: &[u8]| {
    // the reader turns third-party decoder panics into errors with
    // catch_unwind; libfuzzer-sys's hook would abort on them first, so
    // only panics that escape the library count as crashes here
    QUIET.call_once(|| std::panic::set_hook(Box::new(|_| {})));
    let Some((&pick, body)) = data.split_first() else {
        return;
    };
    let magic: &[u8] = match pick % 4 {
        0 => &[0x76, 0x2f, 0x31, 0x01],
        1 => b"#?RADIANCE\n",
        2 => b"\x89PNG\r\n\x1a\n",
        _ => b"",
    };
    let path = std::env::temp_dir().join(format!("tessera-fuzz-{}.img", std::process::id()));
    let mut bytes = magic.to_vec();
    bytes.extend_from_slice(body);
    if std::fs::write(&path, &bytes).is_err() {
        return;
    }
    if let Ok(raster) = read_raster(&path, &ReadOptions::default()) {
        assert!(raster.values.iter().all(|v| v.is_finite() && *v >= 0.0));
    }
});
