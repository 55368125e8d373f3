//! Writes every generated environment map (`tessera::synth::Sky`) as a
//! 1024x512 f32 EXR (ZIP) and a 512x256 f16 EXR (DWAB), and every planar
//! raster as a 512x512 grey f32 EXR, into a folder:
//! `cargo run --release --example synth_maps -- DIR [--large]`. With
//! `--large`, also the clear sky at 4096x2048 and 8192x4096 (f32), for
//! timing large maps.

use std::path::PathBuf;
use tessera::synth::{Sky, SynthMap};

fn main() -> Result<(), tessera::Error> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let large = args.iter().any(|a| a == "--large");
    let dir = PathBuf::from(
        args.iter()
            .find(|a| *a != "--large")
            .cloned()
            .unwrap_or_else(|| "synth-maps".into()),
    );
    std::fs::create_dir_all(&dir).map_err(|source| tessera::Error::Io {
        path: dir.clone(),
        source,
    })?;
    for sky in Sky::all() {
        for (w, h, half) in [(1024, 512, false), (512, 256, true)] {
            let kind = if half { "f16_dwab" } else { "f32" };
            let path = dir.join(format!("{}_{w}x{h}_{kind}.exr", sky.name()));
            sky.generate(w, h, 1).write_exr(&path, half)?;
            println!("{}", path.display());
        }
    }
    if large {
        for (w, h) in [(4096, 2048), (8192, 4096)] {
            let path = dir.join(format!("clear-sky_{w}x{h}_f32.exr"));
            Sky::ClearSky.generate(w, h, 1).write_exr(&path, false)?;
            println!("{}", path.display());
        }
    }
    for raster in tessera::synth::Raster2d::all() {
        let (w, h) = (512, 512);
        let grey = raster.generate(w, h, 1);
        let map = SynthMap {
            width: w,
            height: h,
            rgb: grey.iter().map(|&v| [v as f32; 3]).collect(),
        };
        let path = dir.join(format!("plane_{}_{w}x{h}.exr", raster.name()));
        map.write_exr(&path, false)?;
        println!("{}", path.display());
    }
    Ok(())
}
