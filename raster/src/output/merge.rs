//! Assembling tiles ([`super::tile`]) into the whole image, for `lucent merge`.
//!
//! The tiles must be parts of one image: the same display window, the same alpha (present in
//! all or none), the same layers (names and channels) and the same exposure. Together they must
//! cover the display window exactly: a pixel in two tiles is an error (tiles of one render
//! never need to overlap: every tile's pixels are exactly the whole render's), and so is a
//! pixel in none. Each pixel of the result is copied from its tile, so the merged image holds
//! the tiles' floats bit for bit.

use std::path::PathBuf;

use glam::Vec3;

use super::tile::{ExrTile, Region};
use super::{ExrImage, Layer, LayerData, RgbImage};
use crate::memory;

/// The whole image assembled from tiles.
#[derive(Clone, Debug, PartialEq)]
pub struct Merged {
    /// Beauty, alpha and layers of the whole image.
    pub image: ExrImage,
    /// The tiles' exposure attribute (`None` if they have none).
    pub exposure: Option<f32>,
}

/// What a layer is, for comparing tiles: its name and channels.
fn describe(layers: &[Layer]) -> String {
    if layers.is_empty() {
        return "no layers".to_string();
    }
    let names: Vec<String> = layers
        .iter()
        .map(|l| match &l.data {
            LayerData::Rgb(_) => format!("{} (RGB)", l.name),
            LayerData::Scalar { channel, .. } => format!("{}.{channel}", l.name),
        })
        .collect();
    format!("layers {}", names.join(", "))
}

fn same_kind(a: &Layer, b: &Layer) -> bool {
    a.name == b.name
        && match (&a.data, &b.data) {
            (LayerData::Rgb(_), LayerData::Rgb(_)) => true,
            (LayerData::Scalar { channel: x, .. }, LayerData::Scalar { channel: y, .. }) => x == y,
            _ => false,
        }
}

/// Checks that every tile belongs to the same image as the first (display window, alpha,
/// layers, exposure).
fn check_alike(tiles: &[(PathBuf, ExrTile)]) -> Result<(), String> {
    let (first_path, first) = &tiles[0];
    let first_path = first_path.display();
    for (path, tile) in &tiles[1..] {
        let path = path.display();
        if tile.display != first.display {
            return Err(format!(
                "{path}: its full image is {}x{}, {first_path}'s is {}x{} (tiles of different \
                 images)",
                tile.display.0, tile.display.1, first.display.0, first.display.1
            ));
        }
        if tile.image.alpha.is_some() != first.image.alpha.is_some() {
            let has = |t: &ExrTile| {
                if t.image.alpha.is_some() {
                    "has"
                } else {
                    "has no"
                }
            };
            return Err(format!(
                "{path} {} alpha channel, {first_path} {} (tiles of different renders)",
                has(tile),
                has(first)
            ));
        }
        let (a, b) = (&tile.image.layers, &first.image.layers);
        if a.len() != b.len() || a.iter().zip(b).any(|(x, y)| !same_kind(x, y)) {
            return Err(format!(
                "{path} has {}, {first_path} has {} (tiles of different renders)",
                describe(a),
                describe(b)
            ));
        }
        if tile.exposure.map(f32::to_bits) != first.exposure.map(f32::to_bits) {
            let show = |e: Option<f32>| {
                e.map_or("no exposure attribute".to_string(), |e| {
                    format!("exposure {e}")
                })
            };
            return Err(format!(
                "{path} has {}, {first_path} has {} (tiles of different renders)",
                show(tile.exposure),
                show(first.exposure)
            ));
        }
    }
    Ok(())
}

/// An error for a pixel in two tiles or in none. Worked out from the regions alone, so that
/// tiles claiming an image larger than memory are refused without a buffer of its size.
///
/// An overlap is reported for the first tile (in order) that has one, with the earlier tile
/// holding its first doubled pixel in row order; a gap with its first and last pixel in row
/// order. (The per-pixel ownership map this replaces is the test's oracle.)
fn check_cover(tiles: &[(PathBuf, ExrTile)], width: u32, height: u32) -> Result<(), String> {
    for (i, (path, tile)) in tiles.iter().enumerate() {
        let r = tile.region;
        let first_doubled = tiles[..i]
            .iter()
            .map(|(other, o)| (other, o, overlap(&o.region, &r)))
            .filter(|(_, _, both)| both.x0 < both.x1 && both.y0 < both.y1)
            .min_by_key(|(_, _, both)| (both.y0, both.x0));
        if let Some((other, o, both)) = first_doubled {
            return Err(format!(
                "{} (region {r}) overlaps {} (region {}) in {both}: every pixel must come from \
                 exactly one tile",
                path.display(),
                other.display(),
                o.region
            ));
        }
    }
    let covered: u64 = tiles
        .iter()
        .map(|(_, t)| u64::from(t.region.width()) * u64::from(t.region.height()))
        .sum();
    let all = u64::from(width) * u64::from(height);
    if covered == all {
        return Ok(());
    }
    // Rows between two consecutive region edges are covered alike: one row per band.
    let mut edges: Vec<u32> = tiles
        .iter()
        .flat_map(|(_, t)| [t.region.y0, t.region.y1])
        .chain([0, height])
        .collect();
    edges.sort_unstable();
    edges.dedup();
    let first = edges.windows(2).find_map(|band| {
        let gaps = row_gaps(tiles, band[0], width);
        gaps.first().map(|&(x0, _)| (x0, band[0]))
    });
    let last = edges.windows(2).rev().find_map(|band| {
        let gaps = row_gaps(tiles, band[0], width);
        gaps.last().map(|&(_, x1)| (x1 - 1, band[1] - 1))
    });
    let (Some((xa, ya)), Some((xb, yb))) = (first, last) else {
        return Err("internal error: tiles cover fewer pixels than the image, but no gap".into());
    };
    Err(format!(
        "the tiles leave {} of the {width}×{height} pixels uncovered (the first at ({xa}, {ya}), \
         the last at ({xb}, {yb})): a tile is missing",
        all - covered,
    ))
}

/// The runs `[x0, x1)` of row `y` that no tile covers, left to right.
fn row_gaps(tiles: &[(PathBuf, ExrTile)], y: u32, width: u32) -> Vec<(u32, u32)> {
    let mut spans: Vec<(u32, u32)> = tiles
        .iter()
        .map(|(_, t)| t.region)
        .filter(|r| r.y0 <= y && y < r.y1)
        .map(|r| (r.x0, r.x1))
        .collect();
    spans.sort_unstable();
    let mut gaps = Vec::new();
    let mut x = 0;
    for (x0, x1) in spans {
        if x0 > x {
            gaps.push((x, x0));
        }
        x = x.max(x1);
    }
    if x < width {
        gaps.push((x, width));
    }
    gaps
}

/// The intersection of two overlapping regions.
fn overlap(a: &Region, b: &Region) -> Region {
    Region {
        x0: a.x0.max(b.x0),
        y0: a.y0.max(b.y0),
        x1: a.x1.min(b.x1),
        y1: a.y1.min(b.y1),
    }
}

/// Copies a tile's row-major `values` into the row-major whole-image `out` of width `width`.
fn paste<T: Copy>(out: &mut [T], width: u32, region: &Region, values: &[T]) {
    let w = region.width() as usize;
    for (row, y) in (region.y0..region.y1).enumerate() {
        let start = y as usize * width as usize + region.x0 as usize;
        out[start..start + w].copy_from_slice(&values[row * w..(row + 1) * w]);
    }
}

/// Assembles `tiles` (each with the path it was read from, for messages) into the whole image;
/// the error names the files and the problem.
pub fn merge_tiles(tiles: &[(PathBuf, ExrTile)]) -> Result<Merged, String> {
    let Some((_, first)) = tiles.first() else {
        return Err("no tiles to merge".to_string());
    };
    check_alike(tiles)?;
    let (width, height) = first.display;
    check_cover(tiles, width, height)?;

    let n = width as usize * height as usize;
    let oom = |e: memory::OutOfMemory| e.to_string();
    let mut beauty = memory::filled(n, Vec3::ZERO, memory::MERGED).map_err(oom)?;
    let mut alpha = match &first.image.alpha {
        Some(_) => Some(memory::filled(n, 0.0, memory::MERGED).map_err(oom)?),
        None => None,
    };
    let mut layers = Vec::with_capacity(first.image.layers.len());
    for l in &first.image.layers {
        let data = match &l.data {
            LayerData::Rgb(_) => {
                LayerData::Rgb(memory::filled(n, Vec3::ZERO, memory::MERGED).map_err(oom)?)
            }
            LayerData::Scalar { channel, .. } => LayerData::Scalar {
                channel: channel.clone(),
                values: memory::filled(n, 0.0, memory::MERGED).map_err(oom)?,
            },
        };
        layers.push(Layer {
            name: l.name.clone(),
            data,
        });
    }
    for (_, tile) in tiles {
        let r = &tile.region;
        paste(&mut beauty, width, r, tile.image.beauty.pixels());
        if let (Some(out), Some(values)) = (&mut alpha, &tile.image.alpha) {
            paste(out, width, r, values);
        }
        for (out, layer) in layers.iter_mut().zip(&tile.image.layers) {
            match (&mut out.data, &layer.data) {
                (LayerData::Rgb(out), LayerData::Rgb(values)) => paste(out, width, r, values),
                (LayerData::Scalar { values: out, .. }, LayerData::Scalar { values, .. }) => {
                    paste(out, width, r, values)
                }
                // Kinds were checked equal for every tile.
                _ => return Err("internal error: tile layers of different kinds".to_string()),
            }
        }
    }
    let beauty = RgbImage::from_pixels(width, height, beauty).map_err(|e| e.to_string())?;
    Ok(Merged {
        image: ExrImage {
            beauty,
            alpha,
            layers,
        },
        exposure: first.exposure,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The oracle of [`check_cover`]: which tile holds each pixel, pixel by pixel.
    fn cover_per_pixel(
        tiles: &[(PathBuf, ExrTile)],
        width: u32,
        height: u32,
    ) -> Result<(), String> {
        const NONE: u32 = u32::MAX;
        let mut owner = vec![NONE; width as usize * height as usize];
        for (i, (path, tile)) in tiles.iter().enumerate() {
            let r = tile.region;
            for y in r.y0..r.y1 {
                let row = y as usize * width as usize;
                for x in r.x0..r.x1 {
                    let slot = &mut owner[row + x as usize];
                    if *slot != NONE {
                        let (other, o) = &tiles[*slot as usize];
                        let both = overlap(&o.region, &r);
                        return Err(format!(
                            "{} (region {r}) overlaps {} (region {}) in {both}: every pixel \
                             must come from exactly one tile",
                            path.display(),
                            other.display(),
                            o.region
                        ));
                    }
                    *slot = i as u32;
                }
            }
        }
        let gaps: Vec<usize> = (0..owner.len()).filter(|&i| owner[i] == NONE).collect();
        if let (Some(&first), Some(&last)) = (gaps.first(), gaps.last()) {
            let at = |i: usize| (i % width as usize, i / width as usize);
            let (xa, ya) = at(first);
            let (xb, yb) = at(last);
            return Err(format!(
                "the tiles leave {} of the {width}×{height} pixels uncovered (the first at \
                 ({xa}, {ya}), the last at ({xb}, {yb})): a tile is missing",
                gaps.len()
            ));
        }
        Ok(())
    }

    /// Random sets of up to six regions on small images, half of them a grid with one
    /// region dropped or grown: the same verdict and message as pixel by pixel.
    #[test]
    fn cover_check_agrees_with_the_per_pixel_oracle() {
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = |n: u32| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % u64::from(n)) as u32
        };
        let (mut ok, mut errors) = (0, 0);
        for case in 0..3000 {
            let (w, h) = (1 + next(9), 1 + next(9));
            let mut regions = Vec::new();
            if case % 2 == 0 {
                let (cx, cy) = (next(w + 1), next(h + 1));
                for (x0, x1) in [(0, cx), (cx, w)] {
                    for (y0, y1) in [(0, cy), (cy, h)] {
                        if x0 < x1 && y0 < y1 {
                            regions.push(Region { x0, y0, x1, y1 });
                        }
                    }
                }
                match next(3) {
                    0 if regions.len() > 1 => {
                        regions.remove(next(regions.len() as u32) as usize);
                    }
                    1 => {
                        let i = next(regions.len() as u32) as usize;
                        let r = &mut regions[i];
                        r.x1 = (r.x1 + next(2)).min(w);
                        r.y1 = (r.y1 + next(2)).min(h);
                    }
                    _ => {}
                }
            } else {
                for _ in 0..1 + next(6) {
                    let (x0, y0) = (next(w), next(h));
                    let (x1, y1) = (x0 + 1 + next(w - x0), y0 + 1 + next(h - y0));
                    regions.push(Region { x0, y0, x1, y1 });
                }
            }
            let parts: Vec<(PathBuf, ExrTile)> = regions
                .iter()
                .map(|&r| (PathBuf::from(format!("{r}.exr")), tile(w, h, r)))
                .collect();
            let expected = cover_per_pixel(&parts, w, h);
            assert_eq!(check_cover(&parts, w, h), expected, "{w}×{h}: {regions:?}");
            if expected.is_ok() {
                ok += 1
            } else {
                errors += 1
            }
        }
        assert!(ok > 300 && errors > 300, "{ok} covers, {errors} errors");
    }

    /// A tile of a `w × h` image whose pixel (x, y) holds (x, y, x·y), alpha x + y and a depth
    /// layer y − x: any misplaced pixel shows.
    fn tile(w: u32, h: u32, r: Region) -> ExrTile {
        let coords: Vec<(u32, u32)> = (r.y0..r.y1)
            .flat_map(|y| (r.x0..r.x1).map(move |x| (x, y)))
            .collect();
        let beauty = coords
            .iter()
            .map(|&(x, y)| Vec3::new(x as f32, y as f32, (x * y) as f32))
            .collect();
        ExrTile {
            display: (w, h),
            region: r,
            exposure: Some(0.5),
            image: ExrImage {
                beauty: RgbImage::from_pixels(r.width(), r.height(), beauty).unwrap(),
                alpha: Some(coords.iter().map(|&(x, y)| (x + y) as f32).collect()),
                layers: vec![Layer::depth(
                    coords.iter().map(|&(x, y)| y as f32 - x as f32).collect(),
                )],
            },
        }
    }

    fn tiles(w: u32, h: u32, regions: &[&str]) -> Vec<(PathBuf, ExrTile)> {
        regions
            .iter()
            .map(|r| {
                let region = Region::parse(r).unwrap();
                (PathBuf::from(format!("{r}.exr")), tile(w, h, region))
            })
            .collect()
    }

    #[test]
    fn uneven_tiles_assemble_into_the_whole_image() {
        let parts = tiles(7, 5, &["0,0,3,2", "3,0,7,2", "0,2,1,5", "1,2,7,5"]);
        let merged = merge_tiles(&parts).unwrap();
        assert_eq!(
            merged,
            Merged {
                image: tile(7, 5, Region::full(7, 5)).image,
                exposure: Some(0.5),
            }
        );
    }

    #[test]
    fn gaps_and_overlaps_are_named() {
        let e = merge_tiles(&tiles(7, 5, &["0,0,7,2", "0,2,7,4"])).unwrap_err();
        assert!(
            e.contains("leave 7 of the 7×5 pixels uncovered (the first at (0, 4)"),
            "{e}"
        );
        let e = merge_tiles(&tiles(7, 5, &["0,0,7,3", "2,2,7,5", "0,3,2,5"])).unwrap_err();
        assert!(
            e.contains(
                "2,2,7,5.exr (region 2,2,7,5) overlaps 0,0,7,3.exr (region 0,0,7,3) in 2,2,7,3"
            ),
            "{e}"
        );
        assert!(merge_tiles(&[]).unwrap_err().contains("no tiles"));
    }

    #[test]
    fn tiles_of_different_images_are_refused() {
        let mut parts = tiles(7, 5, &["0,0,7,2", "0,2,7,5"]);
        parts[1].1.display = (7, 6);
        let e = merge_tiles(&parts).unwrap_err();
        assert!(
            e.contains("0,2,7,5.exr: its full image is 7x6, 0,0,7,2.exr's is 7x5"),
            "{e}"
        );

        let mut parts = tiles(7, 5, &["0,0,7,2", "0,2,7,5"]);
        parts[1].1.image.alpha = None;
        let e = merge_tiles(&parts).unwrap_err();
        assert!(e.contains("has no alpha channel, 0,0,7,2.exr has"), "{e}");

        let mut parts = tiles(7, 5, &["0,0,7,2", "0,2,7,5"]);
        parts[0].1.image.layers[0].name = "z".to_string();
        let e = merge_tiles(&parts).unwrap_err();
        assert!(
            e.contains("has layers depth.Z, 0,0,7,2.exr has layers z.Z"),
            "{e}"
        );

        let mut parts = tiles(7, 5, &["0,0,7,2", "0,2,7,5"]);
        parts[1].1.exposure = None;
        let e = merge_tiles(&parts).unwrap_err();
        assert!(
            e.contains("has no exposure attribute, 0,0,7,2.exr has exposure 0.5"),
            "{e}"
        );
    }
}
