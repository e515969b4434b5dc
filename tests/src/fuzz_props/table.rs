//! `table_lookup_finite`: arbitrary K_d, η, α, ℓ_min and ℓ_u against the local-integral table.
//!
//! # Input layout
//!
//! ```text
//! flags                      bit 0: raw K_d, bit 1: raw η, bit 2: raw α,
//!                            bits 3–4: ℓ_min mode, bit 5: prefill a range first
//! kd                         3 × u16: (v + ½)/65536 ∈ (0, 1)      (or 3 raw f32)
//! eta                        1 + 1.5·b/255                        (or a raw f32)
//! alpha                      2^(i8/4) · (1 + b/255)               (or a raw f32)
//! ell_min                    0: zero, 1: α·2^(i8/4), 2: raw f32, 3: a subnormal (u8 bits)
//! prefill                    two ℓ (as below), when flag bit 5 is set
//! lookups …                  until the input ends (at most 64), mode b mod 4 then:
//!                            0: raw f32, 1: α·2^(i8/8)·(1 + b/256), 2: α·2^i8 (a node),
//!                            3: ℓ_min·(1 + i8·2⁻²⁰) (around the threshold)
//! ```
//!
//! # What is checked
//!
//! - `Profile::from_reflectance` accepts every K_d ∈ (0, 1) with η ∈ [1, 2.5] (the documented
//!   valid ranges) and rejects non-finite, out-of-range K_d and η < 1;
//!   `LocalIntegralTable::new` fails exactly for a non-finite or non-positive α or a
//!   non-finite or negative ℓ_min.
//! - The limit equals the profile's Rd_total and lies in [0, 1].
//! - Every lookup is finite, ≥ 0 and ≤ Rd_total·(1 + 1e-5); ℓ ≤ ℓ_min or non-finite gives
//!   the limit exactly; a lookup at a node ℓ = α·2^k (k above ℓ_min/α's exponent, ℓ/α exact in
//!   f32) equals the exact quadrature bit for bit (the table's documented node property). The
//!   nodes are powers of two of ℓ/α, not of ℓ (the table is scale invariant): a power of two ℓ
//!   with α not one is between nodes, where the interpolation is within 0.1 %, not exact.
//! - For one table, K is non-increasing in ℓ (up to a relative 2e-6 of rounding in the
//!   interpolation's polynomial exp), whatever order lookups (and a prefill) happen in.

use lucent_core::glam::Vec3;
use lucent_core::{Distance, LocalIntegralTable, Profile};

use super::input::{Input, pow2};

/// Most lookups one input decodes to.
const MAX_LOOKUPS: usize = 64;

fn ell(r: &mut Input, alpha: f32, ell_min: f32) -> f32 {
    match r.u8() % 4 {
        0 => r.f32_bits(),
        1 => alpha * pow2(i32::from(r.i8()) / 8) * (1.0 + f32::from(r.u8()) / 256.0),
        2 => alpha * pow2(i32::from(r.i8())),
        _ => ell_min * (1.0 + f32::from(r.i8()) * pow2(-20)),
    }
}

/// The smallest power of two strictly above ℓ_min/α: the table's first node ℓ = α·2^k, in
/// units of α, as documented.
fn first_node_ratio(alpha: f32, ell_min: f32) -> f32 {
    let ratio_min = ell_min / alpha;
    if !(ratio_min >= f32::MIN_POSITIVE) {
        pow2(-126)
    } else if !ratio_min.is_finite() {
        pow2(127)
    } else {
        let k = ((ratio_min.to_bits() >> 23) as i32 - 127 + 1).min(127);
        pow2(k)
    }
}

/// Whether ℓ is exactly a node α·2^k: ℓ/α is a power of two and ℓ is exactly α times it (no
/// rounding in the product, so the quadrature at α/ℓ sees exactly 2^−k).
fn is_node(alpha: f32, l: f32) -> bool {
    let ratio = l / alpha;
    is_power_of_two(ratio) && f64::from(alpha) * f64::from(ratio) == f64::from(l)
}

fn is_power_of_two(x: f32) -> bool {
    x.is_normal() && x > 0.0 && x.to_bits() & 0x7f_ffff == 0
}

/// The property of the fuzz target `table_lookup_finite` (see the module docs); panics when it
/// fails.
pub fn table_lookup_finite(data: &[u8]) {
    let mut r = Input::new(data);
    let flags = r.u8();
    let kd = if flags & 1 != 0 {
        Vec3::new(r.f32_bits(), r.f32_bits(), r.f32_bits())
    } else {
        let mut c = || (f32::from(r.u16()) + 0.5) / 65536.0;
        Vec3::new(c(), c(), c())
    };
    let eta = if flags & 2 != 0 {
        r.f32_bits()
    } else {
        1.0 + 1.5 * r.unit()
    };
    let alpha = if flags & 4 != 0 {
        r.f32_bits()
    } else {
        pow2(i32::from(r.i8()) / 4) * (1.0 + r.unit())
    };
    let ell_min = match (flags >> 3) & 3 {
        0 => 0.0,
        1 => alpha * pow2(i32::from(r.i8()) / 4),
        2 => r.f32_bits(),
        _ => f32::from_bits(u32::from(r.u8())),
    };

    let kd_valid = kd.to_array().iter().all(|&k| k > 0.0 && k < 1.0);
    let profile = Profile::from_reflectance(kd, Distance::MeanFreePath(Vec3::ONE), eta);
    let profile = match profile {
        Ok(p) => {
            assert!(
                kd_valid && eta >= 1.0 && eta.is_finite(),
                "K_d {kd} η {eta} accepted"
            );
            p
        }
        Err(e) => {
            assert!(
                !(kd_valid && (1.0..=2.5).contains(&eta)),
                "K_d {kd} η {eta} are in the valid ranges, yet: {e}"
            );
            return;
        }
    };
    let table = match LocalIntegralTable::new(&profile, alpha, ell_min) {
        Ok(t) => {
            assert!(
                alpha.is_finite() && alpha > 0.0 && ell_min.is_finite() && ell_min >= 0.0,
                "table accepted α {alpha} ℓ_min {ell_min}"
            );
            t
        }
        Err(e) => {
            assert!(
                !(alpha.is_finite() && alpha > 0.0 && ell_min.is_finite() && ell_min >= 0.0),
                "table rejected α {alpha} ℓ_min {ell_min}: {e}"
            );
            return;
        }
    };
    let limit = table.limit();
    assert_eq!(limit, profile.total_reflectance());
    assert!(
        limit.is_finite() && limit.min_element() >= 0.0 && limit.max_element() <= 1.0,
        "limit {limit}"
    );

    if flags & 0x20 != 0 {
        let (a, b) = (ell(&mut r, alpha, ell_min), ell(&mut r, alpha, ell_min));
        table.prefill(a, b);
    }
    let first = first_node_ratio(alpha, ell_min);
    let mut seen: Vec<(f32, Vec3)> = Vec::new();
    while !r.is_empty() && seen.len() < MAX_LOOKUPS {
        let l = ell(&mut r, alpha, ell_min);
        let k = table.lookup(Vec3::splat(l));
        let what = format!("K_d {kd} η {eta} α {alpha} ℓ_min {ell_min}: K({l}) = {k}");
        assert!(k.is_finite() && k.min_element() >= 0.0, "{what}");
        assert!(
            (k - limit * (1.0 + 1e-5)).max_element() <= 0.0,
            "{what} exceeds Rd_total {limit}"
        );
        if !(l > ell_min) || !l.is_finite() {
            assert_eq!(k, limit, "{what}: below ℓ_min the limit is used");
        }
        if l > ell_min && is_node(alpha, l) && l / alpha >= first {
            let exact = table.exact(Vec3::splat(l));
            assert_eq!(k, exact, "{what}: a node must equal the exact quadrature");
        }
        if l.is_finite() {
            seen.push((l, k));
        }
    }
    seen.sort_by(|a, b| a.0.total_cmp(&b.0));
    for w in seen.windows(2) {
        let ((l0, k0), (l1, k1)) = (w[0], w[1]);
        for c in 0..3 {
            assert!(
                k1[c] <= k0[c] * (1.0 + 2e-6) + 1e-38,
                "K_d {kd} η {eta} α {alpha} ℓ_min {ell_min}: K rises from {k0} at ℓ {l0} \
                 to {k1} at ℓ {l1}"
            );
        }
    }
}
