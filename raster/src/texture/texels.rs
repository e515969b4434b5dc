//! How a texture holds its texels: 8-bit codes beside the 256 values they decode to, or linear
//! floats.
//!
//! ```text
//!   Codes    codes   [r g b][r g b][r g b]…   3 bytes per texel, row-major, top row first
//!            values  [f32; 256]               code → linear value (sRGB-decoded or code/255)
//!   Linear   [Vec3][Vec3][Vec3]…              12 bytes per texel
//! ```
//!
//! Most textures are 8-bit files (PNG, JPEG, TGA, BMP), and those keep their codes: an
//! 8192 × 8192 colour map takes 192 MiB instead of the 768 MiB of its linear values. A texel
//! reads the same `f32`s either way (the table holds exactly what decoding each code gives), so
//! lookups, and every image rendered with them, have the same bits whichever form a texture
//! takes. 16-bit and floating-point files (and textures made in code) are linear.

use glam::Vec3;

/// The texels of a texture (see the module's layout).
#[derive(Clone, Debug, PartialEq)]
pub(super) enum Texels {
    /// 8-bit codes, three per texel, and the linear value of each code.
    Codes {
        /// R, G, B codes of each texel in turn.
        codes: Vec<u8>,
        /// The linear value of each code.
        values: Box<[f32; 256]>,
    },
    /// Linear values.
    Linear(Vec<Vec3>),
}

const _: () = assert!(size_of::<[u8; 3]>() * 4 == size_of::<Vec3>());

impl Texels {
    /// 8-bit RGB codes (three bytes per texel) decoded through `values`.
    pub(super) fn codes(codes: Vec<u8>, values: [f32; 256]) -> Texels {
        Texels::Codes {
            codes,
            values: Box::new(values),
        }
    }

    /// The number of texels held.
    pub(super) fn len(&self) -> usize {
        match self {
            Texels::Codes { codes, .. } => codes.len() / 3,
            Texels::Linear(texels) => texels.len(),
        }
    }

    /// Bytes of texel data.
    pub(super) fn bytes(&self) -> usize {
        match self {
            Texels::Codes { codes, values } => codes.len() + size_of_val(&**values),
            Texels::Linear(texels) => size_of_val(texels.as_slice()),
        }
    }

    /// The linear value of texel `index` (row-major, top row first).
    #[inline]
    pub(super) fn get(&self, index: usize) -> Vec3 {
        match self {
            Texels::Codes { codes, values } => decode(codes, values, index),
            Texels::Linear(texels) => texels[index],
        }
    }

    /// The index of the first texel that is not finite, if any.
    pub(super) fn first_non_finite(&self) -> Option<usize> {
        match self {
            // Every texel is one of the table's values.
            Texels::Codes { values, .. } if values.iter().all(|v| v.is_finite()) => None,
            _ => (0..self.len()).find(|&i| !self.get(i).is_finite()),
        }
    }

    /// The bilinear blend of four texels, `at = [row0, row1, x0, x1]`: `row0 + x0` and
    /// `row0 + x1` mixed by `fx`, the same in `row1`, and the two rows mixed by `fy`. The
    /// storage is matched once, not per texel.
    #[inline]
    pub(super) fn blend(&self, at: [usize; 4], fx: f32, fy: f32) -> Vec3 {
        match self {
            Texels::Codes { codes, values } => bilinear(|i| decode(codes, values, i), at, fx, fy),
            Texels::Linear(texels) => bilinear(|i| texels[i], at, fx, fy),
        }
    }
}

/// The bilinear blend of the texels `texel` reads at `[row0, row1, x0, x1]`.
#[inline(always)]
fn bilinear(texel: impl Fn(usize) -> Vec3, at: [usize; 4], fx: f32, fy: f32) -> Vec3 {
    let [row0, row1, x0, x1] = at;
    let top = texel(row0 + x0).lerp(texel(row0 + x1), fx);
    let bottom = texel(row1 + x0).lerp(texel(row1 + x1), fx);
    top.lerp(bottom, fy)
}

/// Texel `index` of three-byte codes, decoded.
#[inline]
fn decode(codes: &[u8], values: &[f32; 256], index: usize) -> Vec3 {
    let [r, g, b] = [codes[3 * index], codes[3 * index + 1], codes[3 * index + 2]];
    Vec3::new(
        values[usize::from(r)],
        values[usize::from(g)],
        values[usize::from(b)],
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A code table that is not the identity, so a texel read through the wrong index shows.
    fn table() -> [f32; 256] {
        core::array::from_fn(|c| (c as f32 / 255.0).powi(2) + 0.001 * c as f32)
    }

    /// Codes and the linear texels they decode to give the same value at every texel and the
    /// same bits in every blend.
    #[test]
    fn codes_read_as_their_linear_values() {
        let values = table();
        let codes: Vec<u8> = (0..4 * 3 * 3).map(|i| (i * 37 % 256) as u8).collect();
        let linear: Vec<Vec3> = codes
            .chunks_exact(3)
            .map(|c| {
                Vec3::new(
                    values[c[0] as usize],
                    values[c[1] as usize],
                    values[c[2] as usize],
                )
            })
            .collect();
        let (a, b) = (Texels::codes(codes, values), Texels::Linear(linear.clone()));
        assert_eq!(a.len(), 12);
        assert_eq!(b.len(), 12);
        for (i, &want) in linear.iter().enumerate() {
            assert_eq!(a.get(i), want, "texel {i}");
            assert_eq!(b.get(i), want, "texel {i}");
        }
        // A 4-wide, 3-high image: every footprint, at uneven weights.
        for (row0, row1) in [(0, 4), (4, 8), (8, 0)] {
            for (x0, x1) in [(0, 1), (2, 3), (3, 0)] {
                for (fx, fy) in [(0.0, 0.0), (0.3, 0.71), (1.0, 0.5)] {
                    let at = [row0, row1, x0, x1];
                    let want = {
                        let t = |i: usize| linear[i];
                        let top = t(row0 + x0).lerp(t(row0 + x1), fx);
                        top.lerp(t(row1 + x0).lerp(t(row1 + x1), fx), fy)
                    };
                    assert_eq!(a.blend(at, fx, fy), want);
                    assert_eq!(b.blend(at, fx, fy), want);
                }
            }
        }
    }

    /// Codes take three bytes a texel (and the table); linear values twelve.
    #[test]
    fn codes_take_a_quarter_of_the_memory() {
        let n = 1000;
        let codes = Texels::codes(vec![7; 3 * n], table());
        let linear = Texels::Linear(vec![Vec3::ONE; n]);
        assert_eq!(codes.bytes(), 3 * n + 1024);
        assert_eq!(linear.bytes(), 12 * n);
    }

    /// A table with a non-finite value reports the first texel that uses it; a finite table
    /// needs no scan.
    #[test]
    fn non_finite_texels_are_found_in_either_form() {
        let mut values = table();
        assert_eq!(
            Texels::codes(vec![0, 1, 2, 3, 4, 5], values).first_non_finite(),
            None
        );
        values[4] = f32::NAN;
        assert_eq!(
            Texels::codes(vec![0, 1, 2, 3, 4, 5], values).first_non_finite(),
            Some(1)
        );
        let linear = Texels::Linear(vec![
            Vec3::ONE,
            Vec3::ONE,
            Vec3::new(0.0, f32::INFINITY, 0.0),
        ]);
        assert_eq!(linear.first_non_finite(), Some(2));
    }
}
