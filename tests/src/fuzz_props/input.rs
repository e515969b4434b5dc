//! A tiny reader that turns fuzz bytes into typed values.
//!
//! The targets decode their inputs by hand rather than through a derive, so that every byte
//! has a documented meaning, hand-made seeds are easy to write (see `docs/fuzzing.md`), and a
//! one-byte mutation changes one decision. Reading past the end yields zeros, so every input,
//! however short, decodes to something.

/// A cursor over fuzz bytes; past the end every read returns 0.
#[derive(Clone, Debug)]
pub struct Input<'a> {
    data: &'a [u8],
    pos: usize,
}

impl<'a> Input<'a> {
    /// A reader at the start of `data`.
    pub fn new(data: &'a [u8]) -> Self {
        Input { data, pos: 0 }
    }

    /// True when every byte has been read.
    pub fn is_empty(&self) -> bool {
        self.pos >= self.data.len()
    }

    /// Bytes not read yet.
    pub fn remaining(&self) -> usize {
        self.data.len().saturating_sub(self.pos)
    }

    /// The next byte (0 past the end).
    pub fn u8(&mut self) -> u8 {
        let b = self.data.get(self.pos).copied().unwrap_or(0);
        self.pos += 1;
        b
    }

    /// The next byte as a signed value.
    pub fn i8(&mut self) -> i8 {
        self.u8() as i8
    }

    /// The next two bytes, little-endian.
    pub fn u16(&mut self) -> u16 {
        u16::from_le_bytes([self.u8(), self.u8()])
    }

    /// The next four bytes, little-endian.
    pub fn u32(&mut self) -> u32 {
        u32::from_le_bytes([self.u8(), self.u8(), self.u8(), self.u8()])
    }

    /// The next four bytes as the bits of an `f32` (any value: NaN, ±∞, subnormal).
    pub fn f32_bits(&mut self) -> f32 {
        f32::from_bits(self.u32())
    }

    /// A byte mapped to [0, 1].
    pub fn unit(&mut self) -> f32 {
        f32::from(self.u8()) / 255.0
    }

    /// 2^e for a signed byte e (2^−128, a subnormal, up to 2^127).
    pub fn pow2_i8(&mut self) -> f32 {
        pow2(i32::from(self.i8()))
    }
}

/// 2^e for e in [−149, 127], exact (subnormal below −126); 0 or +∞ outside.
pub fn pow2(e: i32) -> f32 {
    if e > 127 {
        f32::INFINITY
    } else if e >= -126 {
        f32::from_bits(((e + 127) as u32) << 23)
    } else if e >= -149 {
        f32::from_bits(1 << (e + 149))
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_little_endian_and_zero_past_the_end() {
        let mut r = Input::new(&[1, 2, 3]);
        assert_eq!(r.u16(), 0x0201);
        assert_eq!(r.remaining(), 1);
        assert_eq!(r.u32(), 3);
        assert!(r.is_empty());
        assert_eq!(r.u8(), 0);
    }

    #[test]
    fn powers_of_two_are_exact() {
        for e in -149..=127 {
            assert_eq!(pow2(e) as f64, 2f64.powi(e), "2^{e}");
        }
        assert_eq!(pow2(128), f32::INFINITY);
        assert_eq!(pow2(-150), 0.0);
    }
}
