//! `texture_load_never_panics`: arbitrary bytes decoded as each texture format.
//!
//! Input layout: byte 0 chooses how to decode the rest, the file. Its low three bits pick the
//! format: 0 to 5 are `TextureFormat::ALL` (PNG, JPEG, TGA, BMP, Radiance HDR, OpenEXR) forced
//! whatever the content; 6 and 7 detect the format from the content as a scene load does, the
//! file named `t.png` or `t.tga` (TGA has no signature and is known by its extension). Bit 3
//! picks the encoding: clear = colour (sRGB), set = data (linear).
//!
//! Decoding returns a texture or an error, never a panic, and within bounded memory: the caps
//! are [`FUZZ_LIMITS`] (small, so that each input decodes in well under a millisecond; the
//! scene caps are the same code with larger numbers, tested in `lucent-raster`), and libFuzzer's
//! `-rss_limit_mb` catches any allocation beyond what they allow. A texture must respect the
//! caps, hold exactly width × height finite texels, and for integer formats (PNG, JPEG, TGA,
//! BMP) lie in [0, 1]. An error names the file.

use std::path::Path;

use lucent_raster::texture::{Texture, TextureEncoding, TextureFormat, TextureLimits};

use super::assert_error_names_the_file;

/// The caps the fuzz target decodes with: 1024 texels per side, 2¹⁶ in all.
pub const FUZZ_LIMITS: TextureLimits = TextureLimits {
    max_side: 1024,
    max_texels: 1 << 16,
};

/// The property of the fuzz target `texture_load_never_panics` (see the module docs).
pub fn texture_load_never_panics(data: &[u8]) {
    let Some((&selector, file)) = data.split_first() else {
        return;
    };
    let encoding = if selector & 8 == 0 {
        TextureEncoding::Srgb
    } else {
        TextureEncoding::Linear
    };
    let choice = usize::from(selector & 7);
    let (name, format) = match TextureFormat::ALL.get(choice) {
        Some(&format) => ("t.bin", Some(format)),
        None if choice == 6 => ("t.png", TextureFormat::detect(file, Path::new("t.png"))),
        None => ("t.tga", TextureFormat::detect(file, Path::new("t.tga"))),
    };
    let path = Path::new(name);
    let result = match format {
        Some(format) => Texture::decode(file, path, format, encoding, &FUZZ_LIMITS),
        // Nothing recognised: the scene loader's path, which must refuse it.
        None => {
            let refused = Texture::from_bytes(file, path, encoding);
            assert!(refused.is_err(), "an unrecognised file decoded");
            refused
        }
    };
    match result {
        Ok(t) => {
            let (w, h) = (t.width, t.height);
            assert!(w >= 1 && h >= 1, "empty texture {w} × {h}");
            assert!(
                w <= FUZZ_LIMITS.max_side
                    && h <= FUZZ_LIMITS.max_side
                    && u64::from(w) * u64::from(h) <= FUZZ_LIMITS.max_texels,
                "{w} × {h} is beyond the caps"
            );
            assert_eq!(t.texel_count() as u64, u64::from(w) * u64::from(h));
            assert!(t.texels().all(|v| v.is_finite()), "non-finite texel");
            let integer = format.is_some_and(|f| !f.is_float());
            if integer {
                assert!(
                    t.texels()
                        .all(|v| v.min_element() >= 0.0 && v.max_element() <= 1.0),
                    "an integer format decoded outside [0, 1]"
                );
            }
        }
        Err(e) => {
            assert_error_names_the_file(&e.to_string(), &format!("texture {name}: "), name);
        }
    }
}
