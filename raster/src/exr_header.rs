//! What every OpenEXR reader here checks in a part's header before the `exr` decoder sees the
//! pixel data: textures ([`crate::texture`]) and the images `lucent merge` and `lucent compare`
//! read ([`crate::output`]). Each reader adds its own size limits; these two checks are about
//! the decoder itself.

use exr::compression::Compression;
use exr::meta::BlockDescription;
use exr::meta::header::Header;

/// Bytes a block may always hold, whatever the part's size: a tile overhanging a small image,
/// or 256 scan lines of four float channels at the widest texture (16384 × 256 × 16 bytes).
const BLOCK_BYTES_FLOOR: u64 = 64 << 20;

/// Refuses a part the decoder must not be given (the message names what and why).
pub(crate) fn check_part(header: &Header) -> Result<(), String> {
    check_block_size(header)?;
    check_compression(header)
}

/// Refuses B44 and B44A parts: `exr`'s B44 decoder does OpenEXR's unsigned 16-bit arithmetic
/// with subtractions that wrap, which a build with overflow checks (tests, fuzzing, debug)
/// turns into a panic on ordinary data. These lossy formats are meant for images to look at,
/// not for data to render from or measure.
fn check_compression(header: &Header) -> Result<(), String> {
    let name = match header.compression {
        Compression::B44 => "B44",
        Compression::B44A => "B44A",
        _ => return Ok(()),
    };
    Err(format!(
        "OpenEXR {name} compression is not read (save the file with ZIP, PIZ or no compression)"
    ))
}

/// Refuses a part whose blocks (tiles, or runs of scan lines) hold more bytes than the whole
/// part, or than [`BLOCK_BYTES_FLOOR`] if that is more.
///
/// The decoder reads each block into a buffer of the size the block's header claims, checked
/// only against the size the part's header implies for a block, before it finds out whether
/// the file holds that many bytes; and the header's tile size is not tied to the image's: a
/// 2.5 KB file declaring 64 × 16 449 600-pixel tiles on a 64 × 64 image made it zero-fill a
/// gigabyte. A real block is a piece of its image, so only a part smaller than one block (a
/// tiny image in large tiles) comes near the bound.
fn check_block_size(header: &Header) -> Result<(), String> {
    let (w, h) = (header.layer_size.0 as u64, header.layer_size.1 as u64);
    let bytes_per_pixel = header.channels.bytes_per_pixel as u64;
    let (block_pixels, what) = match header.blocks {
        BlockDescription::Tiles(tiles) => {
            let (tw, th) = (tiles.tile_size.0 as u64, tiles.tile_size.1 as u64);
            (
                tw.saturating_mul(th),
                format!("tiles of {tw} × {th} pixels"),
            )
        }
        BlockDescription::ScanLines => {
            let lines = header.compression.scan_lines_per_block() as u64;
            (
                lines.saturating_mul(w),
                format!("blocks of {lines} scan lines"),
            )
        }
    };
    let block_bytes = block_pixels.saturating_mul(bytes_per_pixel);
    let allowed = w
        .saturating_mul(h)
        .saturating_mul(bytes_per_pixel)
        .max(BLOCK_BYTES_FLOOR);
    if block_bytes > allowed {
        return Err(format!(
            "OpenEXR part of {w} × {h} pixels declares {what} ({block_bytes} bytes each, more \
             than the {allowed} bytes lucent allows a block of this part)"
        ));
    }
    Ok(())
}
