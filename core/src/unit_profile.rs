//! The unitless shape of a profile channel (ℓ_u = 1, double precision) for every model: what
//! the local-integral table and the edge-refined quadrature integrate. By the scaling law
//! R_ℓ(r) = R₁(r/ℓ)/ℓ², shared by all three models, any integral of R against a kernel of
//! radius α depends on α/ℓ_u alone (`docs/physics.md` §2).

use crate::better_dipole::{Boundary, UnitBetterDipole};
use crate::burley::UnitBurley;
use crate::dipole::UnitDipole;
use crate::profile::ProfileModel;
use crate::quadrature::GaussLegendre;

/// A radial profile with ℓ_u = 1, for quadratures.
pub trait UnitShape {
    /// R₁(ρ), ρ in units of ℓ_u.
    fn rd(&self, rho: f64) -> f64;
    /// 2πρ R₁(ρ), the integrand of every radial integral (finite at 0 for every model).
    fn ring_density(&self, rho: f64) -> f64 {
        2.0 * core::f64::consts::PI * rho * self.rd(rho)
    }
    /// The slowest exponential decay rate per ℓ_u (quadratures stop e⁻⁶⁰ beyond it).
    fn decay_rate(&self) -> f64;
}

impl UnitShape for UnitDipole {
    fn rd(&self, rho: f64) -> f64 {
        UnitDipole::rd(self, rho)
    }
    fn decay_rate(&self) -> f64 {
        self.sigma_tr()
    }
}

impl UnitShape for UnitBetterDipole {
    fn rd(&self, rho: f64) -> f64 {
        UnitBetterDipole::rd(self, rho)
    }
    fn decay_rate(&self) -> f64 {
        UnitBetterDipole::decay_rate(self)
    }
}

impl UnitShape for UnitBurley {
    fn rd(&self, rho: f64) -> f64 {
        UnitBurley::rd(self, rho)
    }
    fn ring_density(&self, rho: f64) -> f64 {
        UnitBurley::ring_density(self, rho)
    }
    fn decay_rate(&self) -> f64 {
        UnitBurley::decay_rate(self)
    }
}

/// The unit shape of any model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum UnitProfile {
    /// The classical dipole.
    Dipole(UnitDipole),
    /// The better dipole.
    BetterDipole(UnitBetterDipole),
    /// Normalised diffusion.
    Burley(UnitBurley),
}

impl UnitProfile {
    /// For a model, its albedo parameter (α′ for the dipoles, A for Burley) and η.
    pub fn new(model: ProfileModel, albedo: f64, eta: f64) -> Self {
        match model {
            ProfileModel::Dipole => UnitProfile::Dipole(UnitDipole::new(albedo, eta)),
            ProfileModel::BetterDipole => {
                UnitProfile::BetterDipole(UnitBetterDipole::new(albedo, &Boundary::new(eta)))
            }
            ProfileModel::Burley(fit) => UnitProfile::Burley(UnitBurley::new(albedo, fit)),
        }
    }

    /// (K, a·dK/da) at a = α/ℓ_u: N10's local integral and its slope, in closed form for
    /// Burley, else by the table's quadrature ([`crate::table::local_integral_and_slope_unit`]).
    pub fn local_integral_and_slope(&self, a: f64) -> (f64, f64) {
        self.local_integral_and_slope_with(a, &GaussLegendre::new())
    }

    /// [`UnitProfile::local_integral_and_slope`] with the quadrature's rule already built (its
    /// nodes cost about as much as the integral itself; the tables keep one).
    pub(crate) fn local_integral_and_slope_with(
        &self,
        a: f64,
        rule: &GaussLegendre<32>,
    ) -> (f64, f64) {
        use crate::table::local_integral_and_slope_with_rule as quadrature;
        match self {
            UnitProfile::Dipole(u) => quadrature(u, a, rule),
            UnitProfile::BetterDipole(u) => quadrature(u, a, rule),
            UnitProfile::Burley(u) => u.local_integral_and_slope(a),
        }
    }
}

impl UnitShape for UnitProfile {
    fn rd(&self, rho: f64) -> f64 {
        match self {
            UnitProfile::Dipole(u) => UnitShape::rd(u, rho),
            UnitProfile::BetterDipole(u) => UnitShape::rd(u, rho),
            UnitProfile::Burley(u) => UnitShape::rd(u, rho),
        }
    }
    fn ring_density(&self, rho: f64) -> f64 {
        match self {
            UnitProfile::Dipole(u) => u.ring_density(rho),
            UnitProfile::BetterDipole(u) => u.ring_density(rho),
            UnitProfile::Burley(u) => UnitShape::ring_density(u, rho),
        }
    }
    fn decay_rate(&self) -> f64 {
        match self {
            UnitProfile::Dipole(u) => UnitShape::decay_rate(u),
            UnitProfile::BetterDipole(u) => UnitShape::decay_rate(u),
            UnitProfile::Burley(u) => UnitShape::decay_rate(u),
        }
    }
}
