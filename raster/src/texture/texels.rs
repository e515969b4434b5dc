//! How a texture holds its texels: 8- or 16-bit codes beside the values they decode to, or
//! linear floats.
//!
//! ```text
//!   Codes8    codes   [r g b][r g b]…    3 bytes per texel, row-major, top row first
//!             values  [f32; 256]         code → linear value (sRGB-decoded or code/255)
//!   Codes16   codes   [r g b][r g b]…    6 bytes per texel (u16 codes)
//!             values  [f32; 65 536]      code → linear value (sRGB-decoded or code/65535 for
//!                                        16-bit files; the half float's value for OpenEXR)
//!   Linear    [Vec3][Vec3]…              12 bytes per texel
//! ```
//!
//! Most textures are 8-bit files (PNG, JPEG, TGA, BMP), and those keep their codes: an
//! 8192 × 8192 colour map takes 192 MiB instead of the 768 MiB of its linear values; 16-bit
//! files and half-float OpenEXR maps (a half's 16 bits are a code like any other, its table
//! the exact conversion to `f32`) take half of that. A texel reads the same `f32`s in every
//! form (a table holds exactly what decoding each code gives), so lookups, and every image
//! rendered with them, have the same bits whichever form a texture takes. 32-bit float files
//! (Radiance HDR, float OpenEXR) and textures made in code are linear.

use exr::prelude::f16;
use glam::Vec3;

/// The texels of a texture (see the module's layout).
#[derive(Clone, Debug, PartialEq)]
pub(super) enum Texels {
    /// 8-bit codes, three per texel, and the linear value of each code.
    Codes8 {
        /// R, G, B codes of each texel in turn.
        codes: Vec<u8>,
        /// The linear value of each code.
        values: Box<[f32; 256]>,
    },
    /// 16-bit codes, three per texel, and the linear value of each code (65 536 of them).
    Codes16 {
        /// R, G, B codes of each texel in turn.
        codes: Vec<u16>,
        /// The linear value of each code.
        values: Box<[f32; 65_536]>,
    },
    /// Linear values.
    Linear(Vec<Vec3>),
}

const _: () = assert!(size_of::<[u8; 3]>() * 4 == size_of::<Vec3>());
const _: () = assert!(size_of::<[u16; 3]>() * 2 == size_of::<Vec3>());

impl Texels {
    /// 8-bit RGB codes (three per texel), each code's value given by `value`.
    pub(super) fn codes8(codes: Vec<u8>, value: impl Fn(u8) -> f32) -> Texels {
        Texels::Codes8 {
            codes,
            values: Box::new(core::array::from_fn(|c| value(c as u8))),
        }
    }

    /// 16-bit RGB codes (three per texel), each code's value given by `value`.
    pub(super) fn codes16(codes: Vec<u16>, value: impl Fn(u16) -> f32) -> Texels {
        Texels::Codes16 {
            codes,
            // Made on the heap: the table is 256 KiB.
            values: (0..=u16::MAX)
                .map(value)
                .collect::<Box<[f32]>>()
                .try_into()
                .unwrap_or_else(|_| unreachable!("one value per 16-bit code")),
        }
    }

    /// The number of texels held.
    pub(super) fn len(&self) -> usize {
        match self {
            Texels::Codes8 { codes, .. } => codes.len() / 3,
            Texels::Codes16 { codes, .. } => codes.len() / 3,
            Texels::Linear(texels) => texels.len(),
        }
    }

    /// Bytes of texel data, code tables included.
    pub(super) fn bytes(&self) -> usize {
        match self {
            Texels::Codes8 { codes, values } => {
                size_of_val(codes.as_slice()) + size_of_val(&**values)
            }
            Texels::Codes16 { codes, values } => {
                size_of_val(codes.as_slice()) + size_of_val(&**values)
            }
            Texels::Linear(texels) => size_of_val(texels.as_slice()),
        }
    }

    /// The linear value of texel `index` (row-major, top row first).
    #[inline]
    pub(super) fn get(&self, index: usize) -> Vec3 {
        match self {
            Texels::Codes8 { codes, values } => coded(codes, values, index),
            Texels::Codes16 { codes, values } => coded(codes, values, index),
            Texels::Linear(texels) => texels[index],
        }
    }

    /// The index of the first texel that is not finite, if any.
    pub(super) fn first_non_finite(&self) -> Option<usize> {
        let finite = |values: &[f32]| values.iter().all(|v| v.is_finite());
        match self {
            // Every texel is one of the table's values.
            Texels::Codes8 { values, .. } if finite(&**values) => None,
            Texels::Codes16 { values, .. } if finite(&**values) => None,
            _ => (0..self.len()).find(|&i| !self.get(i).is_finite()),
        }
    }

    /// The bilinear blend of four texels, `at = [row0, row1, x0, x1]`: `row0 + x0` and
    /// `row0 + x1` mixed by `fx`, the same in `row1`, and the two rows mixed by `fy`. The
    /// storage is matched once, not per texel.
    #[inline]
    pub(super) fn blend(&self, at: [usize; 4], fx: f32, fy: f32) -> Vec3 {
        match self {
            Texels::Codes8 { codes, values } => bilinear(|i| coded(codes, values, i), at, fx, fy),
            Texels::Codes16 { codes, values } => bilinear(|i| coded(codes, values, i), at, fx, fy),
            Texels::Linear(texels) => bilinear(|i| texels[i], at, fx, fy),
        }
    }
}

/// The value of a half float's bits (exact): the code table of a half-float map.
pub(super) fn half_value(bits: u16) -> f32 {
    f16::from_bits(bits).to_f32()
}

/// The bilinear blend of the texels `texel` reads at `[row0, row1, x0, x1]`.
#[inline(always)]
fn bilinear(texel: impl Fn(usize) -> Vec3, at: [usize; 4], fx: f32, fy: f32) -> Vec3 {
    let [row0, row1, x0, x1] = at;
    let top = texel(row0 + x0).lerp(texel(row0 + x1), fx);
    let bottom = texel(row1 + x0).lerp(texel(row1 + x1), fx);
    top.lerp(bottom, fy)
}

/// Texel `index` of three codes a texel, each decoded through `values`. One bounds check: a
/// code cannot index a table of all its values out of range.
#[inline]
fn coded<C: Copy, const N: usize>(codes: &[C], values: &[f32; N], index: usize) -> Vec3
where
    usize: From<C>,
{
    let at = 3 * index;
    let &[r, g, b] = &codes[at..at + 3] else {
        unreachable!("a range of three codes")
    };
    let value = |c: C| values[usize::from(c)];
    Vec3::new(value(r), value(g), value(b))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Texels of a 4 × 3 image.
    const N: usize = 12;

    /// Code tables that are not the identity, so a texel read through the wrong index shows.
    fn value8(c: u8) -> f32 {
        (f32::from(c) / 255.0).powi(2) + 0.001 * f32::from(c)
    }
    fn value16(c: u16) -> f32 {
        (f32::from(c) / 65535.0).powf(2.2)
    }

    /// Each compact form with the linear values its texels decode to.
    fn forms() -> Vec<(&'static str, Texels, Vec<Vec3>)> {
        let rgb = |v: Vec<f32>| -> Vec<Vec3> { v.chunks_exact(3).map(Vec3::from_slice).collect() };
        let codes8: Vec<u8> = (0..3 * N).map(|i| (i * 37 % 256) as u8).collect();
        let codes16: Vec<u16> = (0..3 * N).map(|i| (i * 7919 % 65536) as u16).collect();
        // Normal, subnormal, negative, zero and the largest finite halves, as their bits.
        let halves: Vec<u16> = (0..3 * N)
            .map(|i| f16::from_f32(i as f32 * 0.37 - 1.5))
            .chain([6.0e-8, -0.0, 65504.0].map(f16::from_f32))
            .skip(3)
            .map(f16::to_bits)
            .collect();
        vec![
            (
                "codes8",
                Texels::codes8(codes8.clone(), value8),
                rgb(codes8.iter().map(|&c| value8(c)).collect()),
            ),
            (
                "codes16",
                Texels::codes16(codes16.clone(), value16),
                rgb(codes16.iter().map(|&c| value16(c)).collect()),
            ),
            (
                "half",
                Texels::codes16(halves.clone(), half_value),
                rgb(halves.iter().map(|&h| f16::from_bits(h).to_f32()).collect()),
            ),
        ]
    }

    /// Every form reads the linear values its texels decode to, bit for bit, one texel at a
    /// time and in every bilinear blend.
    #[test]
    fn every_form_reads_as_its_linear_values() {
        for (name, texels, linear) in forms() {
            assert_eq!(linear.len(), N, "{name}");
            assert_eq!(texels.len(), N, "{name}");
            for (i, &want) in linear.iter().enumerate() {
                assert_eq!(
                    texels.get(i).to_array().map(f32::to_bits),
                    want.to_array().map(f32::to_bits),
                    "{name} texel {i}"
                );
            }
            let as_linear = Texels::Linear(linear.clone());
            for (row0, row1) in [(0, 4), (4, 8), (8, 0)] {
                for (x0, x1) in [(0, 1), (2, 3), (3, 0)] {
                    for (fx, fy) in [(0.0, 0.0), (0.3, 0.71), (1.0, 0.5)] {
                        let at = [row0, row1, x0, x1];
                        let want = {
                            let t = |i: usize| linear[i];
                            let top = t(row0 + x0).lerp(t(row0 + x1), fx);
                            top.lerp(t(row1 + x0).lerp(t(row1 + x1), fx), fy)
                        };
                        assert_eq!(texels.blend(at, fx, fy), want, "{name} {at:?}");
                        assert_eq!(as_linear.blend(at, fx, fy), want, "{name} {at:?}");
                    }
                }
            }
        }
    }

    /// 8-bit codes take 3 bytes a texel and a 1 KiB table; 16-bit codes and halves 6 and
    /// 256 KiB; linear values 12.
    #[test]
    fn each_form_takes_its_share_of_memory() {
        let bytes: Vec<(&str, usize)> = forms().iter().map(|(n, t, _)| (*n, t.bytes())).collect();
        assert_eq!(
            bytes,
            [
                ("codes8", 3 * N + 1024),
                ("codes16", 6 * N + 262_144),
                ("half", 6 * N + 262_144)
            ]
        );
        assert_eq!(Texels::Linear(vec![Vec3::ONE; N]).bytes(), 12 * N);
    }

    /// A table with a non-finite value (a half's infinity or NaN among them) reports the first
    /// texel that uses it (a finite table needs no scan); linear values are scanned.
    #[test]
    fn non_finite_texels_are_found_in_every_form() {
        let codes = vec![0, 1, 2, 3, 4, 5];
        assert_eq!(
            Texels::codes8(codes.clone(), value8).first_non_finite(),
            None
        );
        let nan_at_4 = |c: u8| if c == 4 { f32::NAN } else { value8(c) };
        assert_eq!(
            Texels::codes8(codes.clone(), nan_at_4).first_non_finite(),
            Some(1)
        );
        let codes16 = codes
            .iter()
            .map(|&c| u16::from(c) * 300)
            .collect::<Vec<_>>();
        let inf_at_1500 = |c: u16| if c == 1500 { f32::INFINITY } else { value16(c) };
        assert_eq!(
            Texels::codes16(codes16.clone(), value16).first_non_finite(),
            None
        );
        assert_eq!(
            Texels::codes16(codes16, inf_at_1500).first_non_finite(),
            Some(1)
        );
        let mut halves = vec![f16::ONE.to_bits(); 9];
        assert_eq!(
            Texels::codes16(halves.clone(), half_value).first_non_finite(),
            None
        );
        halves[7] = f16::NAN.to_bits();
        assert_eq!(
            Texels::codes16(halves, half_value).first_non_finite(),
            Some(2)
        );
        let linear = Texels::Linear(vec![
            Vec3::ONE,
            Vec3::ONE,
            Vec3::new(0.0, f32::INFINITY, 0.0),
        ]);
        assert_eq!(linear.first_non_finite(), Some(2));
    }
}
