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

/// Which tile holds each pixel; an error for a pixel in two tiles or in none.
fn owners(tiles: &[(PathBuf, ExrTile)], width: u32, height: u32) -> Result<(), String> {
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
                        "{} (region {r}) overlaps {} (region {}) in {both}: every pixel must \
                         come from exactly one tile",
                        path.display(),
                        other.display(),
                        o.region
                    ));
                }
                *slot = i as u32;
            }
        }
    }
    let gaps: Vec<usize> = owner
        .iter()
        .enumerate()
        .filter(|&(_, &o)| o == NONE)
        .map(|(i, _)| i)
        .collect();
    if let (Some(&first), Some(&last)) = (gaps.first(), gaps.last()) {
        let at = |i: usize| (i % width as usize, i / width as usize);
        let (xa, ya) = at(first);
        let (xb, yb) = at(last);
        return Err(format!(
            "the tiles leave {} of the {width}×{height} pixels uncovered (the first at ({xa}, \
             {ya}), the last at ({xb}, {yb})): a tile is missing",
            gaps.len()
        ));
    }
    Ok(())
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
    owners(tiles, width, height)?;

    let n = width as usize * height as usize;
    let mut beauty = vec![Vec3::ZERO; n];
    let mut alpha = first.image.alpha.as_ref().map(|_| vec![0.0; n]);
    let mut layers: Vec<Layer> = first
        .image
        .layers
        .iter()
        .map(|l| Layer {
            name: l.name.clone(),
            data: match &l.data {
                LayerData::Rgb(_) => LayerData::Rgb(vec![Vec3::ZERO; n]),
                LayerData::Scalar { channel, .. } => LayerData::Scalar {
                    channel: channel.clone(),
                    values: vec![0.0; n],
                },
            },
        })
        .collect();
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
