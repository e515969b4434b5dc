//! `lucent merge`: tiles rendered with `render --crop … --exr` back into the whole image.

use std::path::PathBuf;

use super::MergeArgs;
use super::commands::check_outputs;
use crate::memory;
use crate::output::{
    ExrImage, ExrTile, LayerData, merge_tiles, read_exr_tile, write_exr, write_png,
};

/// `lucent merge`.
pub fn merge(args: &MergeArgs) -> Result<(), String> {
    if args.output.is_none() && args.exr.is_none() {
        return Err("merge: name the merged image with -o OUT.png and/or --exr OUT.exr".into());
    }
    if let Some(x) = args.exposure
        && !(x.is_finite() && x.abs() <= 64.0)
    {
        return Err(format!("--exposure {x}: must be between −64 and 64 stops"));
    }
    let outputs: Vec<&std::path::Path> = [&args.output, &args.exr]
        .into_iter()
        .flatten()
        .map(|p| p.as_path())
        .collect();
    let tiles: Vec<&std::path::Path> = args.tiles.iter().map(|p| p.as_path()).collect();
    check_outputs(&outputs, &tiles)?;
    for (i, path) in args.tiles.iter().enumerate() {
        if args.tiles[..i].contains(path) {
            return Err(format!("{}: given twice", path.display()));
        }
    }
    let tiles: Vec<(PathBuf, ExrTile)> = args
        .tiles
        .iter()
        .map(|path| {
            read_exr_tile(path)
                .map(|tile| (path.clone(), tile))
                .map_err(|e| e.to_string())
        })
        .collect::<Result<_, _>>()?;
    let merged = merge_tiles(&tiles)?;
    let image = &merged.image;
    // Check everything before writing anything.
    let exposure = match (args.exposure, merged.exposure) {
        (Some(x), _) | (None, Some(x)) => x,
        (None, None) if args.output.is_some() => {
            return Err(format!(
                "{}: no {} attribute (the file was not written by `lucent render --crop`): give \
                 the PNG's exposure with --exposure",
                args.tiles[0].display(),
                crate::output::tile::EXPOSURE_ATTRIBUTE
            ));
        }
        (None, None) => 0.0,
    };
    memory::probe(encoder_bytes(image, args), memory::MERGED).map_err(|e| e.to_string())?;
    let mut written = Vec::new();
    if let Some(png) = &args.output {
        write_png(png, &image.beauty, exposure).map_err(|e| e.to_string())?;
        written.push(png.display().to_string());
    }
    if let Some(exr) = &args.exr {
        write_exr(exr, &image.beauty, image.alpha.as_deref(), &image.layers)
            .map_err(|e| e.to_string())?;
        written.push(exr.display().to_string());
    }
    if !args.quiet {
        let (w, h) = image.beauty.size();
        outln!(
            "lucent merge: {} tile{} → {w}×{h} → {}",
            tiles.len(),
            if tiles.len() == 1 { "" } else { "s" },
            written.join(", ")
        );
    }
    Ok(())
}

/// What writing the merged image asks for at once, in bytes: the PNG's 8-bit copy and stream
/// (about 6 bytes per pixel), or the EXR encoder's copy of every channel.
fn encoder_bytes(image: &ExrImage, args: &MergeArgs) -> u64 {
    let n = image.beauty.pixels().len() as u64;
    let png = if args.output.is_some() { 6 * n } else { 0 };
    let exr = if args.exr.is_some() {
        let alpha = if image.alpha.is_some() { 4 } else { 0 };
        let layers: u64 = image
            .layers
            .iter()
            .map(|l| match l.data {
                LayerData::Rgb(_) => 12,
                LayerData::Scalar { .. } => 4,
            })
            .sum();
        (12 + alpha + layers) * n
    } else {
        0
    };
    png.max(exr)
}
