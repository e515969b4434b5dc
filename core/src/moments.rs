//! The fourth-order node aggregate's moment terms, shared by the profiles' point-source terms
//! (derivation at [`crate::Dipole::rd_lanes_corrected`]).
//!
//! A profile is a sum of source terms, each a function of s = ½|x − p|² alone. Two kinds occur:
//!
//! ```text
//! fluence  F = e^(−u)/d,          F⁽ⁿ⁾ = (−1)ⁿ θₙ(u) e^(−u)/d^(2n+1)       (better dipole's φ, Burley)
//! flux     F = z θ₁ e^(−u)/d³,    F⁽ⁿ⁾ = (−1)ⁿ z θₙ₊₁(u) e^(−u)/d^(2n+3)  (both dipoles' E)
//! ```
//!
//! with u = σd and θₙ the reverse Bessel polynomials. Under the uniform-disc closure of the
//! fourth moment, the mean of F over a node is F plus k·(θ₃ c₃ + θ₂ c₂ + θ₁ c₁) for the
//! fluence (k = e^(−u)/d³) and k·(θ₃ c₃′ + θ₂ c₂′) for the flux (k = z e^(−u)/d⁵), with the
//! polynomials in ρ = r²/d² of [`MomentTerms`]. The classical dipole keeps its own inlined copy
//! of the flux case (`dipole.rs`), so that its bits do not depend on this file.

use crate::dipole::NodeMoments;
use crate::lanes::Lanes;

/// The moment combinations of a node seen from x, shared by every source and channel.
#[derive(Clone, Copy, Debug)]
pub(crate) struct MomentTerms<L> {
    inv_r2: L,
    /// q²/12.
    a4: L,
    /// (q tr C + 2p)/6.
    b4: L,
    /// ½q + c₄/r², c₄ = ((tr C)² + 2 tr C²)/12.
    k0: L,
    /// ½ tr C.
    half_trace: L,
}

impl<L: Lanes> MomentTerms<L> {
    /// From 1/r² (capped finite) and the node's moments.
    #[inline(always)]
    pub(crate) fn new(inv_r2: L, m: &NodeMoments<L>) -> Self {
        let two = L::splat(2.0);
        let twelfth = L::splat(1.0 / 12.0);
        let a4 = m.q * m.q * twelfth;
        let b4 = (m.q * m.trace + two * m.cross) * (twelfth + twelfth);
        let c4 = (m.trace * m.trace + two * m.trace_sq) * twelfth;
        MomentTerms {
            inv_r2,
            a4,
            b4,
            k0: L::splat(0.5) * m.q + c4 * inv_r2,
            half_trace: L::splat(0.5) * m.trace,
        }
    }

    /// θ₁, θ₂, θ₃ at u: u + 1, u² + 3u + 3, (u + 3)(θ₂ + 3) − 3.
    #[inline(always)]
    fn thetas(u: L) -> (L, L, L) {
        let three = L::splat(3.0);
        let u3 = u + three;
        let p2 = u3 * u + three;
        (u + L::splat(1.0), p2, u3 * (p2 + three) - three)
    }

    /// The correction of a fluence term e^(−u)/d, given k = e^(−u)/d³:
    /// k [½(θ₂ qρ − θ₁ tr C) + t(θ₄ a₄ρ² − θ₃ b₄ρ + θ₂ c₄)] with θ₄ = 7θ₃ + u²θ₂ and u²t = σ²,
    /// i.e. k [θ₃ ρ²(7a₄ρ − b₄)/r² + θ₂ ρ(k₀ + σ²a₄ρ) − θ₁ ½tr C].
    #[inline(always)]
    pub(crate) fn fluence_correction(&self, k: L, u: L, sigma: L, rho: L) -> L {
        let (p1, p2, p3) = Self::thetas(u);
        let c3 = rho * rho * (L::splat(7.0) * self.a4 * rho - self.b4) * self.inv_r2;
        let c2 = rho * (self.k0 + rho * sigma * sigma * self.a4);
        k * (p3 * c3 + p2 * c2 - p1 * self.half_trace)
    }

    /// The correction of a flux term z θ₁ e^(−u)/d³, given k = z e^(−u)/d⁵ (the classical
    /// dipole's formula): k [θ₃ ρ(k₀ + ρ(σ²a₄ − 7b₄/r² + 63ρa₄/r²)) + θ₂ (ρ(9σ²a₄ρ − σ²b₄) − ½tr C)].
    #[inline(always)]
    pub(crate) fn flux_correction(&self, k: L, u: L, sigma: L, rho: L) -> L {
        let (_, p2, p3) = Self::thetas(u);
        let sigma2 = sigma * sigma;
        let s_a4 = sigma2 * self.a4;
        let k1 = s_a4 - L::splat(7.0) * self.b4 * self.inv_r2;
        let a63 = L::splat(63.0) * self.a4 * self.inv_r2;
        let coeff3 = rho * (self.k0 + rho * (k1 + rho * a63));
        let coeff2 = rho * (rho * L::splat(9.0) * s_a4 - sigma2 * self.b4) - self.half_trace;
        k * (p3 * coeff3 + p2 * coeff2)
    }
}
