//! UDIM texture sets: one image per unit square of UV space, the convention of scanned and
//! sculpted assets whose UVs spread over several tiles.
//!
//! A texture path with the token `<UDIM>` in its file name (`skin.<UDIM>.png`) names every file
//! in which the token is a four-digit tile number from 1001 to 1100. Tile `1001 + a + 10·b`
//! covers u ∈ [a, a + 1) and v ∈ [b, b + 1), for a, b in 0…9:
//!
//! ```text
//!   v
//!   2 ┌──────┬──────┬──────┬─
//!     │ 1011 │ 1012 │ 1013 │ …      each tile: its own image, sampled at (u − a, v − b)
//!   1 ├──────┼──────┼──────┼─       with the bilinear, repeat-wrapped lookup of one texture
//!     │ 1001 │ 1002 │ 1003 │ …
//!   0 └──────┴──────┴──────┴─ u
//!     0      1      2      3
//! ```
//!
//! A point whose tile has no file, or whose UV lies outside the 10 × 10 tiles, samples as black
//! (0), as an empty texture does. A single texture repeats over all of UV space instead.

use glam::{Vec2, Vec3};

use super::{Texture, floor};

/// The token that marks a UDIM set in a texture path.
pub const UDIM_TOKEN: &str = "<UDIM>";

/// The first tile number (u ∈ [0, 1), v ∈ [0, 1)).
pub const FIRST_TILE: u32 = 1001;

/// Tiles per row of UV space, and rows.
const SIDE: u32 = 10;

/// The last tile number (u ∈ [9, 10), v ∈ [9, 10)).
pub const LAST_TILE: u32 = FIRST_TILE + SIDE * SIDE - 1;

/// Largest number of texels in all the tiles of a set (2^28: 768 MiB of 8-bit codes).
pub const MAX_UDIM_TEXELS: u64 = 1 << 28;

/// The tiles of a UDIM set.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Udim {
    /// For tile `FIRST_TILE + k`, its index in `tiles` plus one; 0 where it has no file.
    slot: [u8; (SIDE * SIDE) as usize],
    /// The tiles' images, in increasing tile number.
    tiles: Vec<Texture>,
}

impl Udim {
    /// The set of `tiles` (tile number, image); `None` if a number is outside 1001…1100 or
    /// repeated.
    pub(super) fn new(mut tiles: Vec<(u32, Texture)>) -> Option<Udim> {
        tiles.sort_by_key(|(tile, _)| *tile);
        let mut slot = [0u8; (SIDE * SIDE) as usize];
        for (i, (tile, _)) in tiles.iter().enumerate() {
            let k = tile.checked_sub(FIRST_TILE)? as usize;
            if k >= slot.len() || slot[k] != 0 {
                return None;
            }
            slot[k] = i as u8 + 1;
        }
        Some(Udim {
            slot,
            tiles: tiles.into_iter().map(|(_, t)| t).collect(),
        })
    }

    /// The tiles' images, in increasing tile number.
    pub(super) fn tiles(&self) -> &[Texture] {
        &self.tiles
    }

    /// The bilinear lookup of the tile that `uv` falls in, at `uv` less the tile's corner;
    /// black outside the tiles that have a file. Non-finite coordinates are taken as 0, as a
    /// single texture takes them.
    pub(super) fn sample(&self, uv: Vec2) -> Vec3 {
        let finite = |x: f32| if x.is_finite() { x } else { 0.0 };
        let (u, v) = (finite(uv.x), finite(uv.y));
        let (a, b) = (floor(u), floor(v));
        let side = SIDE as f32;
        if !((0.0..side).contains(&a) && (0.0..side).contains(&b)) {
            return Vec3::ZERO;
        }
        match self.slot[a as usize + SIDE as usize * b as usize] {
            0 => Vec3::ZERO,
            s => self.tiles[usize::from(s) - 1].sample(Vec2::new(u - a, v - b)),
        }
    }
}

/// The tile number that the file name `name` stands for under the file-name pattern
/// `pattern` (which holds [`UDIM_TOKEN`] once): `skin.<UDIM>.png` and `skin.1002.png` give
/// 1002. `None` if `name` does not match, or its number is not a tile.
pub fn tile_of(pattern: &str, name: &str) -> Option<u32> {
    let (before, after) = pattern.split_once(UDIM_TOKEN)?;
    let digits = name.strip_prefix(before)?.strip_suffix(after)?;
    if digits.len() != 4 || !digits.bytes().all(|d| d.is_ascii_digit()) {
        return None;
    }
    let tile: u32 = digits.parse().ok()?;
    (FIRST_TILE..=LAST_TILE).contains(&tile).then_some(tile)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flat(value: Vec3) -> Texture {
        Texture::from_linear("t.png", 1, 1, vec![value])
    }

    #[test]
    fn file_names_give_their_tiles() {
        let p = "skin.<UDIM>.png";
        assert_eq!(tile_of(p, "skin.1001.png"), Some(1001));
        assert_eq!(tile_of(p, "skin.1100.png"), Some(1100));
        assert_eq!(tile_of(p, "skin.1037.png"), Some(1037));
        for other in [
            "skin.1000.png",
            "skin.1101.png",
            "skin.0999.png",
            "skin.10011.png",
            "skin.101.png",
            "skin.10a1.png",
            "skin.+101.png",
            "skin.1001.jpg",
            "skin.1001.png.bak",
            "Skin.1001.png",
            "skin.png",
        ] {
            assert_eq!(tile_of(p, other), None, "{other}");
        }
        assert_eq!(tile_of("<UDIM>", "1012"), Some(1012));
        assert_eq!(tile_of("no token.png", "no token.png"), None);
    }

    /// Each point reads the tile it falls in at its offset in the tile; tiles without a file,
    /// and UVs beyond the 10 × 10 tiles, are black.
    #[test]
    fn a_point_reads_its_own_tile() {
        let (red, green, blue) = (Vec3::X, Vec3::Y, Vec3::Z);
        let set = Udim::new(
            vec![(1012, blue), (1001, red), (1002, green)]
                .into_iter()
                .map(|(t, c)| (t, flat(c)))
                .collect(),
        )
        .expect("valid tiles");
        assert_eq!(set.tiles().len(), 3);
        assert_eq!(set.sample(Vec2::new(0.5, 0.5)), red);
        assert_eq!(set.sample(Vec2::new(1.0, 0.0)), green);
        assert_eq!(set.sample(Vec2::new(1.99, 0.99)), green);
        assert_eq!(set.sample(Vec2::new(1.5, 1.5)), blue);
        for empty in [
            (2.5, 0.5),
            (0.5, 1.5),
            (-0.5, 0.5),
            (0.5, -0.01),
            (10.5, 0.5),
            (0.5, 10.0),
        ] {
            assert_eq!(set.sample(Vec2::from(empty)), Vec3::ZERO, "{empty:?}");
        }
        assert_eq!(set.sample(Vec2::new(f32::NAN, 0.5)), red);
        // Within a tile, the tile's own bilinear lookup at the offset, to the bit.
        let ramp =
            Texture::from_linear("r.png", 2, 2, vec![Vec3::ZERO, Vec3::ONE, Vec3::X, Vec3::Y]);
        let set = Udim::new(vec![(1002, ramp.clone())]).expect("valid");
        for (u, v) in [(1.0, 0.0), (1.3, 0.7), (1.75, 0.25), (1.999, 0.5)] {
            assert_eq!(
                set.sample(Vec2::new(u, v)),
                ramp.sample(Vec2::new(u - 1.0, v)),
                "{u} {v}"
            );
        }
    }

    #[test]
    fn tiles_out_of_range_or_repeated_are_refused() {
        let one = || flat(Vec3::ONE);
        assert!(Udim::new(vec![(1000, one())]).is_none());
        assert!(Udim::new(vec![(1101, one())]).is_none());
        assert!(Udim::new(vec![(1005, one()), (1005, one())]).is_none());
        assert!(Udim::new(vec![(1001, one()), (1100, one())]).is_some());
    }
}
