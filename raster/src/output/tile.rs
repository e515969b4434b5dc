//! Tiles of a render: a rectangular [`Region`] of the image, written as an OpenEXR whose data
//! window says where it lies in the full image (the display window), and read back for
//! `lucent merge`.
//!
//! # File layout
//!
//! A tile is the EXR of [`super::exr`] (same channels, compression, header) with two
//! differences: the display window is the full image, `[0, width−1] × [0, height−1]`, and the
//! data window is the region, `[x0, x1−1] × [y0, y1−1]`; and the header holds the exposure the
//! render used, as the float attribute [`EXPOSURE_ATTRIBUTE`], so that the merged PNG is the one
//! a single render writes. A whole image written through [`write_exr`](super::write_exr) has
//! neither (data window = display window, no exposure), so its bytes do not change.

use std::fmt;
use std::path::Path;

use super::exr::{Frame, decode_exr_framed, read_exr_framed, write_exr_placed};
use super::image::MAX_PIXELS;
use super::{ExrImage, Layer, OutputError, RgbImage};

/// The header attribute holding the PNG exposure (stops, 32-bit float) of a tile.
pub const EXPOSURE_ATTRIBUTE: &str = "lucentExposure";

/// A rectangle of pixels: columns `x0..x1` and rows `y0..y1` (upper bounds exclusive).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Region {
    /// First column.
    pub x0: u32,
    /// First row.
    pub y0: u32,
    /// One past the last column.
    pub x1: u32,
    /// One past the last row.
    pub y1: u32,
}

impl Region {
    /// The whole of a `width × height` image.
    pub fn full(width: u32, height: u32) -> Self {
        Region {
            x0: 0,
            y0: 0,
            x1: width,
            y1: height,
        }
    }

    /// Columns.
    pub fn width(&self) -> u32 {
        self.x1.saturating_sub(self.x0)
    }

    /// Rows.
    pub fn height(&self) -> u32 {
        self.y1.saturating_sub(self.y0)
    }

    /// Pixels.
    pub fn pixels(&self) -> u64 {
        u64::from(self.width()) * u64::from(self.height())
    }

    /// True if `(x, y)` is inside.
    pub fn contains(&self, x: u32, y: u32) -> bool {
        (self.x0..self.x1).contains(&x) && (self.y0..self.y1).contains(&y)
    }

    /// True if this is the whole of a `width × height` image.
    pub fn is_full(&self, width: u32, height: u32) -> bool {
        *self == Region::full(width, height)
    }

    /// Parses `x0,y0,x1,y1` (pixel coordinates, `x1` and `y1` exclusive): four integers, the
    /// region non-empty. Whether it fits an image is [`Region::check_within`]'s part.
    pub fn parse(text: &str) -> Result<Region, String> {
        let parts: Vec<&str> = text.split(',').map(str::trim).collect();
        let [x0, y0, x1, y1] = parts.as_slice() else {
            return Err(format!(
                "'{text}': expected four pixel coordinates x0,y0,x1,y1 (x1 and y1 exclusive), \
                 got {} value{}",
                parts.len(),
                if parts.len() == 1 { "" } else { "s" }
            ));
        };
        let number = |name: &str, s: &str| {
            s.parse::<u32>().map_err(|_| {
                format!("'{text}': {name} = '{s}' is not a pixel coordinate (an integer ≥ 0)")
            })
        };
        let region = Region {
            x0: number("x0", x0)?,
            y0: number("y0", y0)?,
            x1: number("x1", x1)?,
            y1: number("y1", y1)?,
        };
        if region.x1 <= region.x0 || region.y1 <= region.y0 {
            return Err(format!(
                "'{text}': the region is empty (x1 must exceed x0 and y1 must exceed y0; x1 \
                 and y1 are exclusive)"
            ));
        }
        Ok(region)
    }

    /// Checks that the region is non-empty and inside a `width × height` image.
    pub fn check_within(&self, width: u32, height: u32) -> Result<(), String> {
        if self.width() == 0 || self.height() == 0 {
            return Err(format!("the region {self} is empty"));
        }
        if self.x1 > width || self.y1 > height {
            return Err(format!(
                "the region {self} is not inside the {width}×{height} image (x1 ≤ {width} and \
                 y1 ≤ {height}, exclusive bounds)"
            ));
        }
        Ok(())
    }

    /// The region grown by `margin` pixels on every side, clipped to a `width × height` image.
    pub fn grown(&self, margin: u32, width: u32, height: u32) -> Region {
        Region {
            x0: self.x0.saturating_sub(margin),
            y0: self.y0.saturating_sub(margin),
            x1: self.x1.saturating_add(margin).min(width),
            y1: self.y1.saturating_add(margin).min(height),
        }
    }

    /// The part of a row-major buffer of the `outer` region (which contains this one) that
    /// covers this region, row-major.
    pub fn cut<T: Copy>(&self, outer: &Region, values: &[T]) -> Vec<T> {
        let w = outer.width() as usize;
        (self.y0..self.y1)
            .flat_map(|y| {
                let start = (y - outer.y0) as usize * w + (self.x0 - outer.x0) as usize;
                values[start..start + self.width() as usize].iter().copied()
            })
            .collect()
    }
}

/// `x0,y0,x1,y1`, as `--crop` takes it.
impl fmt::Display for Region {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{},{},{},{}", self.x0, self.y0, self.x1, self.y1)
    }
}

/// Where a tile lies: the full image's size and the tile's region of it, and the exposure of
/// the render (for the merged PNG).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    /// Width and height of the whole image (the display window).
    pub display: (u32, u32),
    /// The tile's pixels (the data window).
    pub region: Region,
    /// PNG exposure in stops.
    pub exposure: f32,
}

impl Placement {
    /// Checks that the region is inside the display window and the exposure finite.
    pub fn check(&self, path: &Path) -> Result<(), OutputError> {
        let (w, h) = self.display;
        self.region
            .check_within(w, h)
            .map_err(|e| OutputError::invalid(path, e))?;
        if !self.exposure.is_finite() {
            return Err(OutputError::invalid(
                path,
                format!("exposure must be finite, got {}", self.exposure),
            ));
        }
        Ok(())
    }
}

/// Writes a tile: `beauty`, its `alpha` (if any) and `layers` hold the pixels of
/// `placement.region`, row-major (layout in the module doc). Atomic, like
/// [`write_exr`](super::write_exr).
pub fn write_exr_tile(
    path: &Path,
    placement: &Placement,
    beauty: &RgbImage,
    alpha: Option<&[f32]>,
    layers: &[Layer],
) -> Result<(), OutputError> {
    write_exr_placed(path, beauty, alpha, layers, Some(placement))
}

/// A decoded OpenEXR with where its pixels lie.
#[derive(Clone, Debug, PartialEq)]
pub struct ExrTile {
    /// Width and height of the display window (the whole image).
    pub display: (u32, u32),
    /// The data window: where `image`'s pixels lie in the display window.
    pub region: Region,
    /// The [`EXPOSURE_ATTRIBUTE`], if the file has it.
    pub exposure: Option<f32>,
    /// The pixels.
    pub image: ExrImage,
}

/// Reads an OpenEXR as a tile: any file [`read_exr`](super::read_exr) reads whose display
/// window starts at (0, 0) and holds its data window (a whole image is the one tile that
/// covers it).
pub fn read_exr_tile(path: &Path) -> Result<ExrTile, OutputError> {
    tile_of(path, read_exr_framed(path)?)
}

/// [`read_exr_tile`] of a file held in memory (`path` names it in errors), refusing files of
/// more than `max_samples` samples before decoding (see [`decode_exr_framed`]).
pub fn decode_exr_tile(
    bytes: &[u8],
    path: &Path,
    max_samples: u64,
) -> Result<ExrTile, OutputError> {
    tile_of(path, decode_exr_framed(bytes, path, max_samples)?)
}

/// The tile a decoded image and its frame describe, if they describe one.
fn tile_of(path: &Path, (image, frame): (ExrImage, Frame)) -> Result<ExrTile, OutputError> {
    if frame.display_origin != (0, 0) {
        return Err(OutputError::invalid(
            path,
            format!(
                "the display window starts at ({}, {}); tiles of a lucent render start at (0, 0)",
                frame.display_origin.0, frame.display_origin.1
            ),
        ));
    }
    let (dw, dh) = frame.display_size;
    if dw.saturating_mul(dh) > MAX_PIXELS || dw == 0 || dh == 0 {
        return Err(OutputError::invalid(
            path,
            format!(
                "the display window is {dw}x{dh} pixels; lucent merges images of 1 to \
                 {MAX_PIXELS} pixels"
            ),
        ));
    }
    let (x0, y0) = frame.data_origin;
    let (w, h) = image.beauty.size();
    let inside =
        x0 >= 0 && y0 >= 0 && x0 as u64 + u64::from(w) <= dw && y0 as u64 + u64::from(h) <= dh;
    if !inside {
        return Err(OutputError::invalid(
            path,
            format!(
                "the data window ({w}x{h} pixels at ({x0}, {y0})) is not inside the {dw}x{dh} \
                 display window"
            ),
        ));
    }
    let (x0, y0) = (x0 as u32, y0 as u32);
    Ok(ExrTile {
        // Both at most MAX_PIXELS (checked above).
        display: (dw as u32, dh as u32),
        region: Region {
            x0,
            y0,
            x1: x0 + w,
            y1: y0 + h,
        },
        exposure: frame.exposure,
        image,
    })
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::super::atomic::tests::TestDir;
    use super::*;

    #[test]
    fn a_tile_records_its_place_and_exposure() {
        let dir = TestDir::new("exr-tile");
        let path = dir.path("t.exr");
        let region = Region::parse("3,1,5,4").unwrap();
        let pixels: Vec<Vec3> = (0..6).map(|i| Vec3::new(i as f32, 0.5, -1.0)).collect();
        let beauty = RgbImage::from_pixels(2, 3, pixels).unwrap();
        let alpha = [0.25; 6];
        let layers = [Layer::depth(vec![2.0; 6])];
        let placement = Placement {
            display: (8, 6),
            region,
            exposure: -1.5,
        };
        write_exr_tile(&path, &placement, &beauty, Some(&alpha), &layers).unwrap();
        let meta = exr::prelude::MetaData::read_from_file(&path, false).unwrap();
        let header = &meta.headers[0];
        let display = header.shared_attributes.display_window;
        assert_eq!((display.position.0, display.position.1), (0, 0));
        assert_eq!((display.size.0, display.size.1), (8, 6));
        let data = header.data_window();
        assert_eq!((data.position.0, data.position.1), (3, 1));
        assert_eq!((data.size.0, data.size.1), (2, 3));

        let tile = read_exr_tile(&path).unwrap();
        assert_eq!(
            (tile.display, tile.region, tile.exposure),
            ((8, 6), region, Some(-1.5))
        );
        assert_eq!(tile.image.beauty, beauty);
        assert_eq!(tile.image.alpha.as_deref(), Some(&alpha[..]));
        assert_eq!(tile.image.layers, layers);

        // A whole image is the tile that covers it, without an exposure.
        let whole = dir.path("w.exr");
        super::super::write_exr(&whole, &beauty, None, &[]).unwrap();
        let tile = read_exr_tile(&whole).unwrap();
        assert_eq!(
            (tile.display, tile.region, tile.exposure),
            ((2, 3), Region::full(2, 3), None)
        );

        // A data window outside the display window is not a tile.
        let mut bytes = std::fs::read(&path).unwrap();
        let key = b"displayWindow\0box2i\0";
        let at = bytes.windows(key.len()).position(|w| w == key).unwrap() + key.len() + 4;
        for (i, v) in [0i32, 0, 3, 3].into_iter().enumerate() {
            bytes[at + 4 * i..at + 4 * i + 4].copy_from_slice(&v.to_le_bytes());
        }
        let outside = dir.path("outside.exr");
        std::fs::write(&outside, bytes).unwrap();
        let e = read_exr_tile(&outside).unwrap_err().to_string();
        assert!(
            e.ends_with(
                "the data window (2x3 pixels at (3, 1)) is not inside the 4x4 display window"
            ),
            "{e}"
        );

        // A region that does not fit the display window or the pixels is not written.
        for (display, text, message) in [
            ((4, 6), "3,1,5,4", "not inside the 4×6 image"),
            (
                (8, 6),
                "3,1,6,4",
                "the region 3,1,6,4 is 3x3, the image 2x3",
            ),
        ] {
            let bad = Placement {
                display,
                region: Region::parse(text).unwrap(),
                exposure: 0.0,
            };
            let e = write_exr_tile(&dir.path("bad.exr"), &bad, &beauty, None, &[]).unwrap_err();
            assert!(e.to_string().contains(message), "{e}");
        }
        assert!(!dir.path("bad.exr").exists());
    }

    #[test]
    fn parse_accepts_four_coordinates_and_names_every_problem() {
        let r = Region::parse("3, 4,10,7").unwrap();
        assert_eq!((r.x0, r.y0, r.x1, r.y1), (3, 4, 10, 7));
        assert_eq!((r.width(), r.height(), r.pixels()), (7, 3, 21));
        assert_eq!(r.to_string(), "3,4,10,7");
        for (text, message) in [
            ("1,2,3", "got 3 values"),
            ("", "got 1 value"),
            ("1,2,3,4,5", "got 5 values"),
            ("a,0,4,4", "x0 = 'a'"),
            ("0,-1,4,4", "y0 = '-1'"),
            ("0,0,4.5,4", "x1 = '4.5'"),
            ("0,0,4,99999999999", "y1 = '99999999999'"),
            ("4,0,4,4", "empty"),
            ("0,5,4,4", "empty"),
        ] {
            let e = Region::parse(text).unwrap_err();
            assert!(e.contains(message), "{text}: {e}");
        }
    }

    #[test]
    fn regions_must_lie_inside_the_image() {
        let r = Region::parse("0,0,8,6").unwrap();
        assert!(r.check_within(8, 6).is_ok());
        let e = r.check_within(7, 6).unwrap_err();
        assert!(e.contains("not inside the 7×6 image"), "{e}");
        assert!(r.check_within(8, 5).is_err());
        assert!(Region::full(8, 6).is_full(8, 6));
        assert!(!r.is_full(8, 7));
    }

    #[test]
    fn growing_clips_to_the_image_and_cutting_takes_the_inner_pixels() {
        let r = Region::parse("1,0,3,2").unwrap();
        let g = r.grown(1, 4, 3);
        assert_eq!(g, Region::parse("0,0,4,3").unwrap());
        // The grown region's pixels numbered row-major; the cut is the inner 2 × 2.
        let values: Vec<u32> = (0..g.pixels() as u32).collect();
        assert_eq!(r.cut(&g, &values), vec![1, 2, 5, 6]);
        assert!(g.contains(3, 2) && !g.contains(4, 2) && !r.contains(0, 0));
    }
}
