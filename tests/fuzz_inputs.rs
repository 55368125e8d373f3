//! Bounded fuzzing of every parser a user's bytes reach: no input panics,
//! and every refusal is an error value.

use proptest::prelude::*;
use tessera::io::points::read_points_from;
use tessera::lut::SphereLut;

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]

    #[test]
    fn density_strings_never_panic(spec in ".{0,40}") {
        let _ = tessera::density::sphere::parse(&spec);
    }

    #[test]
    fn cap_like_strings_never_panic(numbers in proptest::collection::vec(any::<f64>(), 0..6)) {
        let spec = format!("cap:{}", numbers.iter().map(f64::to_string).collect::<Vec<_>>().join(","));
        if let Ok(density) = tessera::density::sphere::parse(&spec) {
            // whatever parses must also sample
            let n = tessera::engine::generate(
                &tessera::tiling::sphere::SphereTiling::default(), &*density, 50, true,
            ).map(|s| s.len());
            prop_assert!(matches!(n, Ok(50) | Err(_)));
        }
    }

    #[test]
    fn point_files_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..300), dims in 1usize..4) {
        let _ = read_points_from(&bytes[..], dims, "fuzz");
    }

    #[test]
    fn utk_headers_never_panic(count in any::<u32>(), dims in any::<u32>(), body in 0usize..64) {
        let mut bytes = 0x214B5455u32.to_le_bytes().to_vec();
        bytes.extend_from_slice(&[5, 0, 0, 0]);
        bytes.extend_from_slice(&1u32.to_le_bytes());
        bytes.extend_from_slice(&count.to_le_bytes());
        bytes.extend_from_slice(&dims.to_le_bytes());
        bytes.extend(std::iter::repeat_n(0u8, body));
        let _ = read_points_from(&bytes[..], 3, "fuzz");
    }

    #[test]
    fn table_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..200)) {
        let _ = SphereLut::from_bytes(&bytes);
    }

    #[test]
    fn table_frames_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..200)) {
        // zstd's magic, then garbage: the decompressor must refuse it
        let framed = [&[0x28, 0xb5, 0x2f, 0xfd][..], &bytes].concat();
        prop_assert!(SphereLut::from_bytes(&framed).is_err());
    }
}

/// The shipped table's zstd frames (its header, then its offset tables),
/// each decompressed.
fn decoded_frames() -> &'static [Vec<u8>] {
    static FRAMES: std::sync::OnceLock<Vec<Vec<u8>>> = std::sync::OnceLock::new();
    FRAMES.get_or_init(|| {
        let mut rest = &include_bytes!("../luts/sphere.lut")[..];
        let mut frames = Vec::new();
        while !rest.is_empty() {
            let size = zstd::zstd_safe::find_frame_compressed_size(rest).unwrap();
            frames.push(zstd::stream::decode_all(&rest[..size]).unwrap());
            rest = &rest[size..];
        }
        frames
    })
}

proptest! {
    // each case compresses a frame of up to 6 MB again and decodes them all
    #![proptest_config(ProptestConfig { cases: 128, ..ProptestConfig::default() })]

    #[test]
    fn mutated_tables_decode_or_fail_cleanly(
        which in any::<prop::sample::Index>(),
        at in any::<prop::sample::Index>(),
        value in any::<u8>(),
    ) {
        // mutated inside a frame, so the table's own checks meet them
        let frames = decoded_frames();
        let which = which.index(frames.len());
        let mut bytes = Vec::new();
        for (k, frame) in frames.iter().enumerate() {
            let mut frame = frame.clone();
            if k == which && !frame.is_empty() {
                let i = at.index(frame.len());
                frame[i] = value;
            }
            bytes.extend(zstd::bulk::compress(&frame, 1).unwrap());
        }
        if let Ok(lut) = SphereLut::from_bytes(&bytes) {
            // a table that validates drives the sampler without panicking
            let tiling = tessera::tiling::sphere::SphereTiling::new(std::sync::Arc::new(lut));
            let s = tessera::engine::generate(&tiling, &tessera::density::Uniform, 300, true);
            prop_assert!(s.is_ok());
        }
    }
}
