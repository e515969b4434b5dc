//! Image textures over mesh UVs: decoding PNG, JPEG, TGA, BMP, Radiance HDR and OpenEXR files
//! to linear RGB, and bilinear lookup.
//!
//! Two kinds of texture data exist in a scene, and they decode differently:
//!
//! - **colour** (the diffuse reflectance K_d): 8- and 16-bit integer files (PNG, JPEG, TGA,
//!   BMP) hold sRGB-encoded values, which are decoded to linear with the sRGB transfer
//!   function (IEC 61966-2-1) on load;
//! - **data** (a distance mapped through `min · (max/min)^t`): integer values are used as they
//!   are, `t = code / (2^bits − 1)`, so that equal steps in the image are equal steps in t.
//!
//! Floating-point files (Radiance HDR, OpenEXR) hold linear values and are used as they are
//! for both kinds; a non-finite texel is an error.
//!
//! The format is chosen by the file's content ([`TextureFormat::detect`]: the leading bytes;
//! the `.tga` extension only for TGA, which has no signature). Grey is replicated to RGB and
//! alpha is ignored. Sizes are capped ([`MAX_TEXTURE_SIDE`], [`MAX_TEXTURE_TEXELS`]) from the
//! header, before any pixel memory is allocated, so a hostile header cannot exhaust memory.
//!
//! | file | module |
//! |---|---|
//! | format detection | `format` |
//! | PNG, JPEG, TGA, BMP, HDR (`image` crate) | `image_formats` |
//! | OpenEXR (`exr` crate) | `openexr` |
//! | the texels in memory: 8-bit codes or linear values | `texels` |
//! | UDIM sets: one image per unit square of UV space | `udim` |
//! | errors | `error` |

use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};

mod error;
mod format;
mod image_formats;
mod openexr;
mod texels;
mod udim;

pub use error::{TextureError, TextureSource};
pub use format::TextureFormat;
use texels::Texels;
use udim::Udim;
pub use udim::{FIRST_TILE, LAST_TILE, MAX_UDIM_TEXELS, UDIM_TOKEN, tile_of};

/// Largest accepted texture width or height, in texels.
pub const MAX_TEXTURE_SIDE: u32 = 16_384;

/// Largest accepted number of texels (2^26, e.g. 8192 × 8192: 192 MiB as 8-bit codes, 768 MiB
/// as linear values).
pub const MAX_TEXTURE_TEXELS: u64 = 1 << 26;

/// A decoded RGB texture, read as linear values (held as its file's codes where it has them:
/// see `texels`).
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// Where it was loaded from.
    pub path: PathBuf,
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Row-major texels, top row first: 8-bit codes or linear RGB.
    texels: Texels,
    /// The tiles of a UDIM set, whose own size is 0 × 0 with no texels; `None` for one image.
    udim: Option<Box<Udim>>,
}

/// How the integer values stored in a file map to the texture's linear values. Floating-point
/// files (HDR, OpenEXR) are linear whichever is asked for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TextureEncoding {
    /// Colour: sRGB-encoded, decoded to linear on load.
    Srgb,
    /// Data: the normalised code value itself (`code / (2^bits − 1)`).
    Linear,
}

/// The size caps checked against a file's header before decoding.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TextureLimits {
    /// Largest width or height, in texels.
    pub max_side: u32,
    /// Largest number of texels.
    pub max_texels: u64,
}

impl Default for TextureLimits {
    /// [`MAX_TEXTURE_SIDE`] and [`MAX_TEXTURE_TEXELS`]: what scenes use.
    fn default() -> Self {
        TextureLimits {
            max_side: MAX_TEXTURE_SIDE,
            max_texels: MAX_TEXTURE_TEXELS,
        }
    }
}

impl TextureLimits {
    /// Rejects empty and oversized images (from their header, before anything is allocated).
    pub fn check(&self, width: u32, height: u32) -> Result<(), String> {
        if width == 0 || height == 0 {
            return Err(format!("empty image ({width} × {height})"));
        }
        let max = self.max_side;
        if width > max || height > max {
            return Err(format!(
                "image is {width} × {height}, larger than {max} texels per side"
            ));
        }
        if u64::from(width) * u64::from(height) > self.max_texels {
            return Err(format!(
                "image is {width} × {height}, more than {} texels",
                self.max_texels
            ));
        }
        Ok(())
    }
}

impl Texture {
    /// A texture of linear RGB values, row-major, top row first. A `texels` shorter than
    /// `width × height` makes a texture that samples as black.
    pub fn from_linear(
        path: impl Into<PathBuf>,
        width: u32,
        height: u32,
        texels: Vec<Vec3>,
    ) -> Self {
        Texture {
            path: path.into(),
            width,
            height,
            texels: Texels::Linear(texels),
            udim: None,
        }
    }

    /// The UDIM set of `tiles` (tile number, image), named `path` (the pattern); `None` if a
    /// tile number is outside 1001…1100 or repeated.
    pub fn udim(path: impl Into<PathBuf>, tiles: Vec<(u32, Texture)>) -> Option<Self> {
        Some(Texture {
            path: path.into(),
            width: 0,
            height: 0,
            texels: Texels::Linear(Vec::new()),
            udim: Some(Box::new(Udim::new(tiles)?)),
        })
    }

    /// Whether this is a UDIM set.
    pub fn is_udim(&self) -> bool {
        self.udim.is_some()
    }

    /// The images holding the texels: a UDIM set's tiles in increasing tile number, or this
    /// texture alone.
    fn images(&self) -> &[Texture] {
        match &self.udim {
            Some(set) => set.tiles(),
            None => std::slice::from_ref(self),
        }
    }

    /// The linear value of texel `index` (row-major, top row first; a UDIM set's tiles one
    /// after the other). Panics past the last.
    pub fn texel(&self, index: usize) -> Vec3 {
        let mut index = index;
        for image in self.images() {
            match index.checked_sub(image.texels.len()) {
                Some(rest) => index = rest,
                None => return image.texels.get(index),
            }
        }
        panic!("texel {index} past the last of {}", self.path.display())
    }

    /// The linear values of every texel, row-major, top row first (a UDIM set's tiles in
    /// increasing tile number).
    pub fn texels(&self) -> impl Iterator<Item = Vec3> + '_ {
        self.images()
            .iter()
            .flat_map(|image| (0..image.texels.len()).map(|i| image.texels.get(i)))
    }

    /// The number of texels held (in all the tiles of a UDIM set).
    pub fn texel_count(&self) -> usize {
        self.images().iter().map(|image| image.texels.len()).sum()
    }

    /// The bytes its texels take: 3 per texel for 8-bit files, 6 for 16-bit and half-float
    /// ones, 12 for 32-bit floats (and the code tables).
    pub fn texel_bytes(&self) -> usize {
        self.images().iter().map(|image| image.texels.bytes()).sum()
    }

    /// Bilinear lookup with repeat wrapping. `uv = (0, 0)` is the bottom-left corner of the
    /// image (the OBJ convention), `(1, 1)` the top-right.
    ///
    /// Texel centres sit at half-integer positions: texel column `i`, row `j` (from the top) is
    /// returned exactly at `uv = ((i + ½)/width, 1 − (j + ½)/height)`. Non-finite coordinates
    /// are treated as 0. An empty (or inconsistent) texture samples as black. A UDIM set
    /// samples the tile that `uv` falls in (see `udim`).
    pub fn sample(&self, uv: Vec2) -> Vec3 {
        if let Some(set) = &self.udim {
            return set.sample(uv);
        }
        match self.footprint(uv) {
            Some(at) => self.sample_at(&at),
            None => Vec3::ZERO,
        }
    }

    /// [`Texture::sample`] of two textures at one `uv`: where they have the same size, the
    /// texels and weights are found once (a material's K_d and radius maps usually share a
    /// resolution).
    pub fn sample_pair(a: &Texture, b: &Texture, uv: Vec2) -> (Vec3, Vec3) {
        if a.is_udim() {
            return (a.sample(uv), b.sample(uv));
        }
        let Some(at) = a.footprint(uv) else {
            return (Vec3::ZERO, b.sample(uv));
        };
        let second = if (a.width, a.height) == (b.width, b.height) && b.is_complete() {
            b.sample_at(&at)
        } else {
            b.sample(uv)
        };
        (a.sample_at(&at), second)
    }

    /// Where a bilinear lookup at `uv` reads; `None` for an empty (or inconsistent) texture.
    fn footprint(&self, uv: Vec2) -> Option<Footprint> {
        if !self.is_complete() {
            return None;
        }
        let (w, h) = (self.width as usize, self.height as usize);
        let (x0, x1, fx) = wrap_axis(uv.x, w);
        // Rows are stored top first, v grows upwards: flip before wrapping.
        let (y0, y1, fy) = wrap_axis(1.0 - uv.y, h);
        Some(Footprint {
            row0: y0 * w,
            row1: y1 * w,
            x0,
            x1,
            fx,
            fy,
        })
    }

    /// Whether the texture is not empty and holds all its texels.
    fn is_complete(&self) -> bool {
        let (w, h) = (self.width as usize, self.height as usize);
        w != 0 && h != 0 && self.texels.len() >= w * h
    }

    /// The bilinear blend at a footprint of this texture (or of one of the same size).
    fn sample_at(&self, at: &Footprint) -> Vec3 {
        self.texels
            .blend([at.row0, at.row1, at.x0, at.x1], at.fx, at.fy)
    }

    /// Decodes a file held in memory, its format detected from its content
    /// ([`TextureFormat::detect`]). `path` names the file in messages (and, for TGA, gives the
    /// extension).
    pub fn from_bytes(
        bytes: &[u8],
        path: &Path,
        encoding: TextureEncoding,
    ) -> Result<Texture, TextureError> {
        let Some(format) = TextureFormat::detect(bytes, path) else {
            let head: Vec<String> = bytes.iter().take(8).map(|b| format!("{b:02x}")).collect();
            return Err(TextureError::new(
                path,
                if bytes.is_empty() {
                    "empty file".to_string()
                } else {
                    format!(
                        "not a PNG, JPEG, BMP, Radiance HDR or OpenEXR file (it starts with {}), \
                         nor named .tga",
                        head.join(" ")
                    )
                },
            ));
        };
        Texture::decode(bytes, path, format, encoding, &TextureLimits::default())
    }

    /// Decodes a file held in memory as `format`, with explicit size caps.
    pub fn decode(
        bytes: &[u8],
        path: &Path,
        format: TextureFormat,
        encoding: TextureEncoding,
        limits: &TextureLimits,
    ) -> Result<Texture, TextureError> {
        let (width, height, texels) = match format {
            TextureFormat::Exr => openexr::decode_exr(bytes, path, limits)?,
            _ => image_formats::decode_with_image(bytes, path, format, encoding, limits)?,
        };
        if texels.len() as u64 != u64::from(width) * u64::from(height) {
            return Err(TextureError::new(
                path,
                format!(
                    "decoded {} texels, expected {width} × {height}",
                    texels.len()
                ),
            ));
        }
        if let Some(i) = texels.first_non_finite() {
            let (x, y) = (i % width as usize, i / width as usize);
            return Err(TextureError::new(
                path,
                format!(
                    "texel ({x}, {y}) (column, row from the top) is {}: {} values must be finite",
                    texels.get(i),
                    format.name()
                ),
            ));
        }
        Ok(Texture {
            path: path.to_path_buf(),
            width,
            height,
            texels,
            udim: None,
        })
    }

    /// Reads and decodes a texture file from disk (format detected from its content).
    pub fn load(path: &Path, encoding: TextureEncoding) -> Result<Texture, TextureError> {
        let bytes = std::fs::read(path).map_err(|e| TextureError {
            path: path.to_path_buf(),
            message: format!("cannot read: {e}"),
            source: Some(TextureSource::Io(e)),
        })?;
        Texture::from_bytes(&bytes, path, encoding)
    }
}

/// Maps a normalised code value in [0, 1] to a linear texture value.
fn decode(c: f32, encoding: TextureEncoding) -> f32 {
    match encoding {
        TextureEncoding::Srgb => srgb_to_linear(c),
        TextureEncoding::Linear => c,
    }
}

/// The sRGB electro-optical transfer function (IEC 61966-2-1): encoded value → linear.
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// ⌊x⌋ of a finite `x` without a call into the C library (the x86-64 baseline has no rounding
/// instruction, and a texture lookup floors four times): from |x| = 2²³ on every f32 is an
/// integer.
#[inline]
fn floor(x: f32) -> f32 {
    if !(x.abs() < 8_388_608.0) {
        return x;
    }
    let t = x as i32 as f32;
    if t > x { t - 1.0 } else { t }
}

/// The four texels a bilinear lookup reads (`row0`, `row1`: the offsets of its two rows;
/// `x0`, `x1`: its two columns) and the weights of the second column and row.
#[derive(Clone, Copy, Debug)]
struct Footprint {
    row0: usize,
    row1: usize,
    x0: usize,
    x1: usize,
    fx: f32,
    fy: f32,
}

/// Repeat-wraps one texture coordinate: the two texel indices to blend and the weight of the
/// second. `coord` is in texture units (0 = first edge, 1 = last edge of the image).
fn wrap_axis(coord: f32, n: usize) -> (usize, usize, f32) {
    let coord = if coord.is_finite() { coord } else { 0.0 };
    // [0, 1] (1 only by rounding); most coordinates are already in [0, 1).
    let wrapped = if (0.0..1.0).contains(&coord) {
        coord
    } else {
        coord - floor(coord)
    };
    let x = wrapped * n as f32 - 0.5; // [−0.5, n − 0.5]
    let x0 = floor(x);
    let frac = x - x0;
    // x0 ∈ [−1, n − 1]: wrap without an integer division (this runs twice per lookup, at every
    // shading point of a textured material).
    let i0 = if x0 < 0.0 {
        n - 1
    } else {
        // x0 < n ≤ the decoder's size cap, far below 2³¹: the i32 conversion is exact and
        // cheaper than usize's.
        (x0 as i32 as usize).min(n - 1)
    };
    let i1 = if i0 + 1 == n { 0 } else { i0 + 1 };
    (i0, i1, frac)
}

#[cfg(test)]
pub(crate) mod tests;
