//! `exr_tile_read_never_panics`: arbitrary bytes read as an OpenEXR tile, as `lucent merge`
//! reads its inputs (and `lucent compare` its images: the same reader without the tile's
//! checks).
//!
//! Reading returns a tile or an error naming the file, never a panic, and within bounded
//! memory: files of more than [`MAX_EXR_SAMPLES`] samples are refused from the header (the
//! renderer reads any size memory permits, asked for before decoding), and libFuzzer's
//! `-rss_limit_mb` catches what a header could still make the decoder allocate. A tile's
//! beauty image, alpha and layers all hold its data window's pixels, and the data window lies
//! in the display window.

use std::path::Path;

use lucent_raster::output::decode_exr_tile;

use super::assert_error_names_the_file;

/// The most samples (pixels times channels, all parts) the fuzz target decodes: 2¹⁶.
pub const MAX_EXR_SAMPLES: u64 = 1 << 16;

/// The property of the fuzz target `exr_tile_read_never_panics` (see the module docs).
pub fn exr_tile_read_never_panics(data: &[u8]) {
    let name = "t.exr";
    match decode_exr_tile(data, Path::new(name), MAX_EXR_SAMPLES) {
        Ok(tile) => {
            let (w, h) = tile.image.beauty.size();
            let pixels = w as usize * h as usize;
            assert!(w >= 1 && h >= 1, "empty beauty image {w} × {h}");
            assert!(
                3 * pixels as u64 <= MAX_EXR_SAMPLES,
                "{w} × {h} beyond the cap"
            );
            assert_eq!(tile.image.beauty.pixels().len(), pixels);
            let r = tile.region;
            assert_eq!(
                (r.x1 - r.x0, r.y1 - r.y0),
                (w, h),
                "region {r} for {w} × {h}"
            );
            assert!(
                r.x1 <= tile.display.0 && r.y1 <= tile.display.1,
                "region {r} outside the {:?} display window",
                tile.display
            );
            if let Some(alpha) = &tile.image.alpha {
                assert_eq!(alpha.len(), pixels, "alpha");
            }
            for layer in &tile.image.layers {
                assert_eq!(layer.len(), pixels, "layer {}", layer.name);
            }
        }
        Err(e) => {
            assert_error_names_the_file(&e.to_string(), &format!("{name}: "), name);
        }
    }
}
