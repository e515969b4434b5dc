//! Which decoder reads a texture file: the file's leading bytes, or its extension for TGA.
//!
//! | format | recognised by |
//! |---|---|
//! | PNG | signature `89 50 4E 47 0D 0A 1A 0A` |
//! | JPEG | start-of-image marker `FF D8 FF` |
//! | BMP | `BM` |
//! | Radiance HDR (RGBE) | `#?RADIANCE` or `#?RGBE` |
//! | OpenEXR | magic number `76 2F 31 01` |
//! | TGA | no signature: the extension `.tga` (any case), when none of the above matches |
//!
//! The content decides, not the name: a JPEG saved as `kd.png` is read as a JPEG.

use std::fmt;
use std::path::Path;

/// A texture file format lucent reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TextureFormat {
    /// Portable Network Graphics: any colour type, 1 to 16 bits.
    Png,
    /// Baseline and progressive JPEG (JFIF/Exif), grey or colour.
    Jpeg,
    /// Truevision TGA: true-colour, grey or colour-mapped, raw or run-length encoded.
    Tga,
    /// Windows bitmap.
    Bmp,
    /// Radiance RGBE (`.hdr`): linear floating-point RGB.
    Hdr,
    /// OpenEXR: linear floating-point channels (half, float or unsigned int).
    Exr,
}

impl TextureFormat {
    /// Every format, in the order the documentation lists them.
    pub const ALL: [TextureFormat; 6] = [
        TextureFormat::Png,
        TextureFormat::Jpeg,
        TextureFormat::Tga,
        TextureFormat::Bmp,
        TextureFormat::Hdr,
        TextureFormat::Exr,
    ];

    /// The format's name as messages give it.
    pub fn name(self) -> &'static str {
        match self {
            TextureFormat::Png => "PNG",
            TextureFormat::Jpeg => "JPEG",
            TextureFormat::Tga => "TGA",
            TextureFormat::Bmp => "BMP",
            TextureFormat::Hdr => "Radiance HDR",
            TextureFormat::Exr => "OpenEXR",
        }
    }

    /// True for the formats whose samples are linear floating-point values: they are used as
    /// they are for colour and for data textures alike (no sRGB decoding).
    pub fn is_float(self) -> bool {
        matches!(self, TextureFormat::Hdr | TextureFormat::Exr)
    }

    /// The format of a file from its leading bytes, or, for TGA (which has no signature), from
    /// the extension of `path`. `None` if neither identifies a supported format.
    pub fn detect(bytes: &[u8], path: &Path) -> Option<TextureFormat> {
        const SIGNATURES: [(&[u8], TextureFormat); 6] = [
            (b"\x89PNG\r\n\x1a\n", TextureFormat::Png),
            (b"\xff\xd8\xff", TextureFormat::Jpeg),
            (b"BM", TextureFormat::Bmp),
            (b"#?RADIANCE", TextureFormat::Hdr),
            (b"#?RGBE", TextureFormat::Hdr),
            (b"\x76\x2f\x31\x01", TextureFormat::Exr),
        ];
        if let Some((_, format)) = SIGNATURES.iter().find(|(sig, _)| bytes.starts_with(sig)) {
            return Some(*format);
        }
        let tga = path
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| e.eq_ignore_ascii_case("tga"));
        tga.then_some(TextureFormat::Tga)
    }
}

impl fmt::Display for TextureFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}
