//! In-memory float images: the beauty image and the extra layers written to OpenEXR.
//!
//! Pixels are linear RGB (no transfer function), stored row-major with the top row first,
//! matching the camera's pixel convention (pixel (0, 0) is the top-left corner, y grows
//! downwards).

use glam::Vec3;

use super::OutputError;

/// The largest image (in pixels) the readers accept: 2^27 ≈ 134 million pixels, e.g.
/// 16384 × 8192. It bounds the memory a malformed header can make a reader allocate.
pub const MAX_PIXELS: u64 = 1 << 27;

/// Name of the translucent-exitance layer (M_o).
pub const LAYER_EXITANCE: &str = "exitance";
/// Name of the layer holding the local term of the split.
pub const LAYER_LOCAL: &str = "local";
/// Name of the layer holding the global term of the split.
pub const LAYER_GLOBAL: &str = "global";
/// Name of the irradiance layer.
pub const LAYER_IRRADIANCE: &str = "irradiance";
/// Name of the depth layer.
pub const LAYER_DEPTH: &str = "depth";
/// Channel name of the depth layer (the OpenEXR convention for depth is `Z`).
pub const DEPTH_CHANNEL: &str = "Z";

/// A linear RGB float image.
///
/// Invariant: `pixels().len() == width * height`. The fields are private so that the invariant
/// cannot be broken; build one with [`RgbImage::new`] or [`RgbImage::from_pixels`].
#[derive(Clone, Debug, PartialEq)]
pub struct RgbImage {
    width: u32,
    height: u32,
    pixels: Vec<Vec3>,
}

impl RgbImage {
    /// A black image. Zero-sized images are representable but every writer rejects them.
    pub fn new(width: u32, height: u32) -> Self {
        let n = width as usize * height as usize;
        RgbImage {
            width,
            height,
            pixels: vec![Vec3::ZERO; n],
        }
    }

    /// Wraps a pixel buffer (row-major, top row first); fails when its length is not
    /// `width * height`.
    pub fn from_pixels(width: u32, height: u32, pixels: Vec<Vec3>) -> Result<Self, OutputError> {
        let expected = width as u64 * height as u64;
        if pixels.len() as u64 != expected {
            return Err(OutputError::invalid(
                "",
                format!(
                    "a {width}x{height} image needs {expected} pixels, the buffer has {}",
                    pixels.len()
                ),
            ));
        }
        Ok(RgbImage {
            width,
            height,
            pixels,
        })
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// `(width, height)`.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// All pixels, row-major, top row first.
    pub fn pixels(&self) -> &[Vec3] {
        &self.pixels
    }

    /// All pixels, mutable.
    pub fn pixels_mut(&mut self) -> &mut [Vec3] {
        &mut self.pixels
    }

    /// Gives up the pixel buffer.
    pub fn into_pixels(self) -> Vec<Vec3> {
        self.pixels
    }

    /// The pixel at column `x`, row `y`, or `None` outside the image.
    pub fn get(&self, x: u32, y: u32) -> Option<Vec3> {
        if x < self.width && y < self.height {
            self.pixels
                .get(y as usize * self.width as usize + x as usize)
                .copied()
        } else {
            None
        }
    }

    /// Sets the pixel at column `x`, row `y`; returns `false` (and does nothing) outside the
    /// image.
    pub fn set(&mut self, x: u32, y: u32, value: Vec3) -> bool {
        if x < self.width && y < self.height {
            let i = y as usize * self.width as usize + x as usize;
            if let Some(p) = self.pixels.get_mut(i) {
                *p = value;
                return true;
            }
        }
        false
    }
}

/// An extra image layer written next to the beauty image in the OpenEXR file.
///
/// See [`super::exr`] for how layer and channel names appear in the file.
#[derive(Clone, Debug, PartialEq)]
pub struct Layer {
    /// Layer name: 1 to 24 characters from `[A-Za-z0-9_-]`, e.g. [`LAYER_EXITANCE`].
    pub name: String,
    /// The pixels, same size and order as the beauty image.
    pub data: LayerData,
}

/// The pixels of a [`Layer`].
#[derive(Clone, Debug, PartialEq)]
pub enum LayerData {
    /// Three channels, written as `<layer>.R`, `<layer>.G`, `<layer>.B`.
    Rgb(Vec<Vec3>),
    /// One channel, written as `<layer>.<channel>`.
    Scalar {
        /// Channel name (same character rules as layer names), e.g. [`DEPTH_CHANNEL`].
        channel: String,
        /// The values.
        values: Vec<f32>,
    },
}

impl Layer {
    /// An RGB layer.
    pub fn rgb(name: impl Into<String>, pixels: Vec<Vec3>) -> Self {
        Layer {
            name: name.into(),
            data: LayerData::Rgb(pixels),
        }
    }

    /// A single-channel layer.
    pub fn scalar(name: impl Into<String>, channel: impl Into<String>, values: Vec<f32>) -> Self {
        Layer {
            name: name.into(),
            data: LayerData::Scalar {
                channel: channel.into(),
                values,
            },
        }
    }

    /// The depth layer (`depth.Z`): camera-space distance along the view axis, +∞ where no
    /// surface is visible.
    pub fn depth(values: Vec<f32>) -> Self {
        Layer::scalar(LAYER_DEPTH, DEPTH_CHANNEL, values)
    }

    /// Number of pixels in the layer.
    pub fn len(&self) -> usize {
        match &self.data {
            LayerData::Rgb(p) => p.len(),
            LayerData::Scalar { values, .. } => values.len(),
        }
    }

    /// Whether the layer has no pixels.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Whether `name` is a valid layer or channel name: 1 to 24 characters from `[A-Za-z0-9_-]`.
/// The restriction keeps full channel names (`layer.channel`) within the 31 bytes that old
/// OpenEXR readers accept, and free of the `.` separator.
pub fn is_valid_name(name: &str) -> bool {
    (1..=24).contains(&name.len())
        && name
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'-')
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn from_pixels_checks_length() {
        assert!(RgbImage::from_pixels(2, 3, vec![Vec3::ZERO; 6]).is_ok());
        let err = RgbImage::from_pixels(2, 3, vec![Vec3::ZERO; 5]).unwrap_err();
        assert!(
            err.to_string().contains("2x3 image needs 6 pixels"),
            "{err}"
        );
    }

    #[test]
    fn get_and_set_are_row_major_top_first() {
        let mut img = RgbImage::new(3, 2);
        assert!(img.set(2, 1, Vec3::ONE));
        assert!(!img.set(3, 0, Vec3::ONE));
        assert!(!img.set(0, 2, Vec3::ONE));
        assert_eq!(img.pixels()[5], Vec3::ONE);
        assert_eq!(img.get(2, 1), Some(Vec3::ONE));
        assert_eq!(img.get(0, 0), Some(Vec3::ZERO));
        assert_eq!(img.get(0, 2), None);
    }

    #[test]
    fn names() {
        assert!(is_valid_name("exitance"));
        assert!(is_valid_name("Z"));
        assert!(!is_valid_name(""));
        assert!(!is_valid_name("a.b"));
        assert!(!is_valid_name("déjà"));
        assert!(!is_valid_name(&"x".repeat(25)));
    }
}
