//! The public query API: which method, its settings, and what a query returns.
//!
//! | method | formula (`docs/physics.md`) |
//! |---|---|
//! | [`Method::Hierarchical`] (JB02, §9) | M_o = Σ_cut Rd·E·A |
//! | [`Method::LocalGlobal`] (LM07, §12) | M_o = E(x)·K + Σ_cut (1 − w)·Rd·E·A |
//! | [`Method::EdgeAware`] (N10, §13) | M_o = E_loc·K + Σ_cut (1 − w)·Rd·E·A, E_loc the kernel-weighted cache irradiance with x inserted at r = 0 |
//! | [`Method::EdgeRefined`] (departure from N10, §16) | as N10 where the irradiance within α is uniform; elsewhere local = ∫ w·Rd·E dA′ by a quadrature of E(x′) that the caller evaluates ([`crate::LocalQuadrature`]) |
//! | [`Method::Exhaustive`] (§9) | M_o = Σ_all Rd·E·A |

use alloc::string::String;
use core::fmt;
use core::str::FromStr;

use glam::{DVec3, Vec3};

#[cfg(all(feature = "simd", any(target_arch = "x86", target_arch = "x86_64")))]
use crate::cache::traverse::InRegisters;
use crate::cache::traverse::{
    Compaction, EDGE_AWARE, FLUX_HEADROOM, HIERARCHICAL, LOCAL_GLOBAL, LaneByLane, Params, Sums,
};
use crate::cache::{self, IrradianceCache};
use crate::error::ParseMethodError;
use crate::kernel::Kernel;
use crate::lanes::{DefaultLanes, Lanes};
use crate::local_term::LocalTerm;
use crate::profile::Profile;
use crate::refine::{EDGE_THRESHOLD, uniform_within};
#[cfg(all(feature = "simd", any(target_arch = "x86", target_arch = "x86_64")))]
use crate::stats::QueryStats;
use crate::stats::{NoStats, StatsSink};

/// How a query sums the cache.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Method {
    /// Jensen & Buhler 2002: octree sum with the ΔΩ < ε aggregation rule (ΔΩ from the node's
    /// area or, where wider, its flux spread).
    Hierarchical,
    /// Langlands & Mertens 2007: precomputed local term E(x)·K plus the (1 − w) global sum.
    LocalGlobal,
    /// Neulander 2010: as LM07, with the local irradiance a kernel-weighted query of the cache
    /// (soft, faithful shadow edges), computed in the same traversal.
    #[default]
    EdgeAware,
    /// N10's traversal and result where the samples' irradiance within α is within
    /// [`LocalQuadrature::EDGE_THRESHOLD`](crate::LocalQuadrature::EDGE_THRESHOLD) of E(x); elsewhere the query flags the point
    /// ([`Exitance::refine`]) and the caller replaces the local term by a quadrature of the
    /// irradiance over the α-disc ([`crate::LocalQuadrature`], [`Exitance::with_local`]).
    EdgeRefined,
    /// Every sample, no approximation.
    Exhaustive,
}

impl Method {
    /// All methods, in the order above.
    pub const ALL: [Method; 5] = [
        Method::Hierarchical,
        Method::LocalGlobal,
        Method::EdgeAware,
        Method::EdgeRefined,
        Method::Exhaustive,
    ];

    /// The kebab-case name used by the scene format and the command line.
    pub fn name(self) -> &'static str {
        match self {
            Method::Hierarchical => "hierarchical",
            Method::LocalGlobal => "local-global",
            Method::EdgeAware => "edge-aware",
            Method::EdgeRefined => "edge-refined",
            Method::Exhaustive => "exhaustive",
        }
    }

    /// True for the method whose samples carry, where a shadow edge crosses their cell, the
    /// mean irradiance over the cell ([`crate::CellAverage`]; edge-refined). The others keep
    /// JB02's irradiance at the sample, as published.
    pub fn averages_edge_cells(self) -> bool {
        self == Method::EdgeRefined
    }

    /// True for the methods with a local term (LM07, N10, edge-refined), which need K and α.
    pub fn is_split(self) -> bool {
        matches!(
            self,
            Method::LocalGlobal | Method::EdgeAware | Method::EdgeRefined
        )
    }
}

impl fmt::Display for Method {
    /// The [`Method::name`].
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Method {
    type Err = ParseMethodError;

    /// The method whose [`Method::name`] is `s` (exactly; the error lists the valid names).
    fn from_str(s: &str) -> Result<Method, ParseMethodError> {
        Method::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| ParseMethodError {
                name: String::from(s),
            })
    }
}

/// Query settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QuerySettings {
    /// The method.
    pub method: Method,
    /// JB02's solid-angle threshold ε: a node is aggregated when max(A, 2π tr C)/|x − P|² < ε,
    /// its area or, where wider, the area of its flux spread (0 = never).
    pub epsilon: f32,
    /// Relative tolerance for skipping negligible subtrees (0 = never): everything skipped
    /// adds up to at most `cull_tolerance ×` the global sum, per channel.
    pub cull_tolerance: f32,
}

impl Default for QuerySettings {
    /// Edge-aware, ε = 0.05 (pbrt-v2's default), cull tolerance 1e-4.
    fn default() -> Self {
        QuerySettings {
            method: Method::EdgeAware,
            epsilon: 0.05,
            cull_tolerance: 1e-4,
        }
    }
}

/// The point being shaded.
///
/// ```text
/// offset  0  position    Vec3 (x, y, z: f32)
/// offset 12  irradiance  Vec3
/// size   24
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct ShadingPoint {
    /// Position x (scene units).
    pub position: Vec3,
    /// Irradiance E(x) at x itself (used by the split methods' local term).
    pub irradiance: Vec3,
}

/// A query's result, per RGB channel.
///
/// ```text
/// offset  0  total             Vec3 (x, y, z: f32)
/// offset 12  local             Vec3
/// offset 24  global            Vec3
/// offset 36  local_irradiance  Vec3
/// offset 48  refine            bool (one byte, then 3 bytes of padding)
/// size   52
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub struct Exitance {
    /// Radiant exitance M_o = local + global.
    pub total: Vec3,
    /// The local term E_loc·K (zero for the unsplit methods).
    pub local: Vec3,
    /// The global (octree or exhaustive) sum.
    pub global: Vec3,
    /// The irradiance that drives the local term: E(x) for LM07, E_loc for N10 (and for the
    /// edge-refined method until [`Exitance::with_local`]).
    pub local_irradiance: Vec3,
    /// Edge-refined only: the samples' irradiance within α is not uniform, so the local term
    /// should be refined ([`crate::LocalQuadrature::local_term`], [`Exitance::with_local`]).
    pub refine: bool,
}

impl Exitance {
    /// The same result with the local term replaced (the edge-refined method's quadrature):
    /// total = local + global; `local_irradiance` becomes local / K per channel (0 where K is),
    /// K the one the query was given (`term`).
    pub fn with_local(self, local: Vec3, term: LocalTerm) -> Exitance {
        let k = term.k();
        let e = Vec3::select(k.cmpgt(Vec3::ZERO), local / k, Vec3::ZERO);
        Exitance {
            total: local + self.global,
            local,
            local_irradiance: e,
            ..self
        }
    }
}

/// An invalid query input.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum QueryError {
    /// The shading position is NaN or infinite.
    NonFinitePosition,
    /// The irradiance at the shading point is negative, NaN or infinite.
    InvalidIrradiance,
    /// The local term's K is negative, NaN or infinite, or its smoothing radius α is.
    InvalidLocalIntegral,
    /// A setting is negative, NaN or infinite.
    InvalidSetting {
        /// Which setting.
        name: &'static str,
        /// Its value.
        value: f32,
    },
}

impl fmt::Display for QueryError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            QueryError::NonFinitePosition => write!(f, "shading position is not finite"),
            QueryError::InvalidIrradiance => write!(
                f,
                "irradiance at the shading point must be finite and non-negative"
            ),
            QueryError::InvalidLocalIntegral => {
                write!(f, "local integral K must be finite and non-negative")
            }
            QueryError::InvalidSetting { name, value } => {
                write!(f, "{name} must be finite and non-negative, got {value}")
            }
        }
    }
}

impl core::error::Error for QueryError {}

fn non_negative(v: Vec3) -> bool {
    v.is_finite() && v.min_element() >= 0.0
}

impl QuerySettings {
    /// Checks every setting is finite and non-negative.
    pub fn validate(&self) -> Result<(), QueryError> {
        for (name, value) in [
            ("epsilon", self.epsilon),
            ("cull_tolerance", self.cull_tolerance),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(QueryError::InvalidSetting { name, value });
            }
        }
        Ok(())
    }
}

impl IrradianceCache {
    /// Radiant exitance at `point` for a material with diffusion profile `profile`.
    ///
    /// `local` is the split methods' smoothing radius α with the local integral K for it (from
    /// [`crate::LocalIntegralTable::local_term`], [`crate::LocalIntegralByKd::local_term`] or
    /// [`LocalTerm::exact`]); the unsplit methods ignore it ([`LocalTerm::NONE`]). Errors only
    /// on non-finite or negative inputs.
    pub fn query(
        &self,
        profile: &Profile,
        point: &ShadingPoint,
        local: LocalTerm,
        settings: &QuerySettings,
    ) -> Result<Exitance, QueryError> {
        self.query_with::<DefaultLanes, _>(profile, point, local, settings, &mut NoStats)
    }

    /// [`IrradianceCache::query`], reporting the traversal's events to `stats` (a
    /// [`crate::stats::QueryStats`] counts them; a [`crate::stats::NoStats`] makes this
    /// `query`).
    #[inline]
    pub fn query_with_stats<S: StatsSink>(
        &self,
        profile: &Profile,
        point: &ShadingPoint,
        local: LocalTerm,
        settings: &QuerySettings,
        stats: &mut S,
    ) -> Result<Exitance, QueryError> {
        stats.query();
        self.query_with::<DefaultLanes, S>(profile, point, local, settings, stats)
    }

    /// [`IrradianceCache::query_planned`] compiled for AVX2: the traversal in 256-bit
    /// registers, one ymm register per eight lanes where the baseline x86-64 build uses two
    /// SSE registers (`wide::f32x8` fixes its representation when the crate is compiled).
    /// The result is bit-identical to [`IrradianceCache::query_planned`]: the same IEEE-754
    /// operations in the same order, without fused multiply-add. (An unplanned query is
    /// [`IrradianceCache::plan`] and then this.)
    ///
    /// # Safety
    ///
    /// A `#[target_feature]` function: calling it from code not itself compiled for AVX2 is
    /// `unsafe`, and sound only on a CPU with AVX2 (check with
    /// `std::is_x86_feature_detected!("avx2")`, once). The `lucent` renderer does this in one
    /// place, `raster/src/render/simd.rs`.
    ///
    /// Not generic (the counts go to a [`QueryStats`]; [`StatsSink::merge`] passes them on):
    /// the whole traversal, inlined, is about 400 kB of machine code, so it is compiled once,
    /// here, instead of once per statistics type in every crate that calls it.
    #[cfg(all(feature = "simd", any(target_arch = "x86", target_arch = "x86_64")))]
    #[target_feature(enable = "avx2")]
    #[inline(never)]
    pub fn query_planned_avx2(
        &self,
        plan: &QueryPlan,
        point: &ShadingPoint,
        stats: &mut QueryStats,
    ) -> Result<Exitance, QueryError> {
        stats.query();
        check_point(point)?;
        // `ArrayLanes` inlines the whole traversal here (`Lanes::INLINE_TRAVERSAL`), so that all
        // of it is compiled for AVX2, the closure too: there `vpermps` is safe to call.
        let compaction = InRegisters(|values, order| crate::lanes::permute_avx2(values, order));
        Ok(self.run::<crate::lanes::ArrayLanes, QueryStats, _>(plan, point, stats, compaction))
    }

    /// [`IrradianceCache::query_with_stats`] with an explicit lane type (SIMD or scalar): for
    /// benchmarks and for testing the two lane types against each other. Not part of the API.
    /// Always inlined (for the lane types other than `ArrayLanes` the traversal itself stays
    /// out of line).
    #[doc(hidden)]
    #[inline(always)]
    pub fn query_with<L: Lanes, S: StatsSink>(
        &self,
        profile: &Profile,
        point: &ShadingPoint,
        local: LocalTerm,
        settings: &QuerySettings,
        stats: &mut S,
    ) -> Result<Exitance, QueryError> {
        // The checks in their documented order: α, the point, then K and the settings.
        let alpha = local.alpha();
        if !(alpha.is_finite() && alpha >= 0.0) {
            return Err(QueryError::InvalidLocalIntegral);
        }
        check_point(point)?;
        let plan = self.plan(profile, local, settings)?;
        Ok(self.run::<L, S, _>(&plan, point, stats, LaneByLane))
    }

    /// Checks `settings` and `local` and computes what every query of `profile` on this cache
    /// shares (the kernel, N10's power-of-two scales), once: for a material that does not vary
    /// over the surface, [`IrradianceCache::query_planned`] then skips that work at every
    /// shading point. The plan belongs to this cache (its scales depend on the mean sample
    /// area); its result is bit for bit [`IrradianceCache::query`]'s.
    pub fn plan(
        &self,
        profile: &Profile,
        local: LocalTerm,
        settings: &QuerySettings,
    ) -> Result<QueryPlan, QueryError> {
        check_local(local)?;
        settings.validate()?;
        // N10's sums are scaled by powers of two near 1/Rd(0) and 1/Ā (see `Params`).
        let area_scale = reciprocal_pow2(self.mean_area());
        let flux_scale = pow2_clamped(f64::from(area_scale) * f64::from(FLUX_HEADROOM));
        let params = Params {
            epsilon: settings.epsilon,
            cull_tolerance: settings.cull_tolerance,
            kernel: Kernel::new(local.alpha()),
            irradiance: Vec3::ZERO,
            rd_scale: [1.0; 3],
            area_scale,
            flux_scale,
        };
        Ok(self.plan_material(params, settings.method, profile, local))
    }

    /// The plan of another material (`profile`, `local`) with the settings `plan` was made
    /// with, on the cache it was made on (this one): for a material that varies over the
    /// surface, only what depends on the material is redone at each shading point — the
    /// settings were checked and the cache's scales computed when `plan` was made, and the
    /// kernel is kept when α is the same. Checks `local` as [`IrradianceCache::plan`] does and
    /// gives the plan it would give, bit for bit.
    #[inline]
    pub fn replan(
        &self,
        plan: &QueryPlan,
        profile: &Profile,
        local: LocalTerm,
    ) -> Result<QueryPlan, QueryError> {
        let mut out = *plan;
        self.replan_into(&mut out, profile, local)?;
        Ok(out)
    }

    /// [`IrradianceCache::replan`] in place: `plan` (made on this cache) becomes the plan of
    /// `profile` and `local` with the same settings, the same bits as `replan` gives. For a
    /// material that varies over the surface, one plan kept per thread and re-made at each
    /// point is not copied at each point. On an error (a bad `local`) `plan` is unchanged.
    #[inline]
    pub fn replan_into(
        &self,
        plan: &mut QueryPlan,
        profile: &Profile,
        local: LocalTerm,
    ) -> Result<(), QueryError> {
        check_local(local)?;
        debug_assert_eq!(
            plan.params.area_scale,
            reciprocal_pow2(self.mean_area()),
            "replan with a plan of another cache"
        );
        // Every plan's kernel is its α's (as `plan` builds it).
        if local.alpha().to_bits() != plan.local.alpha().to_bits() {
            plan.params.kernel = Kernel::new(local.alpha());
        }
        self.set_material(plan, profile, local);
        Ok(())
    }

    /// A plan from the settings' and the cache's part (`params`) and the material.
    #[inline]
    fn plan_material(
        &self,
        params: Params,
        method: Method,
        profile: &Profile,
        local: LocalTerm,
    ) -> QueryPlan {
        let mut plan = QueryPlan {
            profile: *profile,
            local,
            method,
            rd_zero: [0.0; 3],
            params,
        };
        self.set_material(&mut plan, profile, local);
        plan
    }

    /// Writes the material's part of `plan`: the profile (capped for this cache's sample area),
    /// Rd(0) and N10's power-of-two scales of it, and the local term.
    #[inline]
    fn set_material(&self, plan: &mut QueryPlan, profile: &Profile, local: LocalTerm) {
        plan.profile = profile.for_sample_area(self.mean_area());
        plan.rd_zero = plan.profile.rd_zero().to_array();
        plan.params.rd_scale = plan.rd_zero.map(reciprocal_pow2);
        plan.local = local;
    }

    /// [`IrradianceCache::query_with_stats`] with the material's work done once
    /// ([`IrradianceCache::plan`], on this cache): checks only the point.
    #[inline]
    pub fn query_planned<S: StatsSink>(
        &self,
        plan: &QueryPlan,
        point: &ShadingPoint,
        stats: &mut S,
    ) -> Result<Exitance, QueryError> {
        stats.query();
        check_point(point)?;
        Ok(self.run::<DefaultLanes, S, _>(plan, point, stats, LaneByLane))
    }

    /// The query proper, its inputs checked. Always inlined, so that
    /// [`IrradianceCache::query_planned_avx2`] compiles all of it for AVX2.
    #[inline(always)]
    fn run<L: Lanes, S: StatsSink, K: Compaction>(
        &self,
        plan: &QueryPlan,
        point: &ShadingPoint,
        stats: &mut S,
        compaction: K,
    ) -> Exitance {
        let profile = &plan.profile;
        let local_integral = plan.local.k();
        let rd_zero = plan.rd_zero;
        let Params {
            rd_scale,
            area_scale,
            flux_scale,
            ..
        } = plan.params;
        let params = Params {
            irradiance: point.irradiance,
            ..plan.params
        };
        let x = point.position;
        let e = point.irradiance;
        match plan.method {
            Method::Exhaustive => {
                let global = cache::exhaustive::exhaustive_sum_lanes::<L>(self, profile, x);
                Exitance {
                    total: global,
                    global,
                    ..Exitance::default()
                }
            }
            Method::Hierarchical => {
                let sums = cache::traverse::<L, S, K, HIERARCHICAL>(
                    self, profile, x, &params, stats, compaction,
                );
                Exitance {
                    total: sums.global,
                    global: sums.global,
                    ..Exitance::default()
                }
            }
            Method::LocalGlobal => {
                let sums = cache::traverse::<L, S, K, LOCAL_GLOBAL>(
                    self, profile, x, &params, stats, compaction,
                );
                split_result(sums, e, local_integral)
            }
            Method::EdgeAware | Method::EdgeRefined => {
                let sums = cache::traverse::<L, S, K, EDGE_AWARE>(
                    self, profile, x, &params, stats, compaction,
                );
                let refine = plan.method == Method::EdgeRefined
                    && !uniform_within(sums.irradiance_range, e, EDGE_THRESHOLD);
                // N10: the shading point joins the kernel-weighted average at r = 0 with weight
                // Rd(0)·Ā, in (1/4, 1] in the traversal's scaled weights (0 if Ā = 0). The
                // scaled flux sum is Σ w·Rd·E·A·rd_scale·flux_scale: times area_scale /
                // flux_scale (a power of two, exact in f64) it is on the weights' scale.
                let centre = (Vec3::from_array(rd_zero)
                    * Vec3::from_array(rd_scale)
                    * (self.mean_area() * area_scale))
                    .as_dvec3();
                let den = centre + sums.local_weight;
                let unscale = f64::from(area_scale) / f64::from(flux_scale);
                let num = centre * e.as_dvec3() + sums.local_flux * unscale;
                let e_loc = (num / den).as_vec3();
                // With no weight at all (Ā = 0 and no samples within α) fall back to E(x).
                let e_loc = Vec3::select(den.cmpgt(DVec3::ZERO) & e_loc.is_finite_mask(), e_loc, e);
                Exitance {
                    refine,
                    ..split_result(sums, e_loc, local_integral)
                }
            }
        }
    }
}

/// What [`IrradianceCache::plan`] computes once for a material and a cache.
#[derive(Clone, Copy, Debug)]
pub struct QueryPlan {
    profile: Profile,
    local: LocalTerm,
    method: Method,
    rd_zero: [f32; 3],
    params: Params,
}

impl QueryPlan {
    /// The local term the plan was made with.
    pub fn local(&self) -> LocalTerm {
        self.local
    }
    /// The profile the plan was made with.
    pub fn profile(&self) -> &Profile {
        &self.profile
    }
}

/// The local term's checks: α finite and non-negative, K finite and non-negative.
fn check_local(local: LocalTerm) -> Result<(), QueryError> {
    let alpha = local.alpha();
    if !(alpha.is_finite() && alpha >= 0.0 && non_negative(local.k())) {
        return Err(QueryError::InvalidLocalIntegral);
    }
    Ok(())
}

/// The per-point checks: a finite position, a finite non-negative irradiance.
fn check_point(point: &ShadingPoint) -> Result<(), QueryError> {
    if !point.position.is_finite() {
        return Err(QueryError::NonFinitePosition);
    }
    if !non_negative(point.irradiance) {
        return Err(QueryError::InvalidIrradiance);
    }
    Ok(())
}

/// A power of two v (in f64) clamped to [2⁻¹²⁶, 2¹²⁶].
fn pow2_clamped(v: f64) -> f32 {
    let (lo, hi) = (crate::math::pow2i(-126), crate::math::pow2i(126));
    v.clamp(f64::from(lo), f64::from(hi)) as f32
}

/// 2^−⌈log₂ v⌉ for positive finite v, clamped to [2⁻¹²⁶, 2¹²⁶] (1 for 0): v times it is in
/// (1/2, 1] unless v is subnormal (then below 1) or above 2¹²⁶ (then below 4). Scaling by a
/// power of two is exact, so N10's scaled sums lose no digits to it.
#[inline]
fn reciprocal_pow2(v: f32) -> f32 {
    let bits = v.to_bits();
    // Positive finite f32s, subnormals included, are the bit patterns 1 ..= 0x7f7f_ffff (one
    // comparison instead of a class test).
    if bits.wrapping_sub(1) >= 0x7f7f_ffff {
        return 1.0;
    }
    // From the bits: ⌊log₂ v⌋ is the exponent, one more unless the mantissa is 0. A subnormal
    // reads as 2⁻¹²⁷·(1 + m) and gives −126, which the clamp gives its true ⌈log₂ v⌉ anyway.
    // So ⌈log₂ v⌉ ∈ [−126, 128], and only the lower end of −⌈log₂ v⌉ needs clamping.
    let ceil = (bits >> 23) as i32 - 127 + i32::from(bits & 0x7f_ffff != 0);
    crate::math::pow2i((-ceil).max(-126))
}

fn split_result(sums: Sums, local_irradiance: Vec3, k: Vec3) -> Exitance {
    let local = local_irradiance * k;
    Exitance {
        total: local + sums.global,
        local,
        global: sums.global,
        local_irradiance,
        refine: false,
    }
}

const _: () = {
    use core::mem::{offset_of, size_of};
    assert!(size_of::<ShadingPoint>() == 24 && offset_of!(ShadingPoint, irradiance) == 12);
    assert!(size_of::<Exitance>() == 52);
    assert!(offset_of!(Exitance, local) == 12 && offset_of!(Exitance, global) == 24);
    assert!(offset_of!(Exitance, local_irradiance) == 36 && offset_of!(Exitance, refine) == 48);
};

#[cfg(test)]
mod tests {
    extern crate std;

    use super::*;

    /// Against ⌈log₂ v⌉ found by doubling in f64 (every f32 is exact there): normal and
    /// subnormal values, powers of two and their neighbours, and the non-positive, infinite
    /// and NaN inputs that give 1.
    #[test]
    fn reciprocal_pow2_is_two_to_minus_the_ceiling_of_log2() {
        let oracle = |v: f32| {
            let v = f64::from(v);
            let mut ceil = 0i32;
            while f64::powi(2.0, ceil) < v {
                ceil += 1;
            }
            while f64::powi(2.0, ceil - 1) >= v {
                ceil -= 1;
            }
            f64::powi(2.0, (-ceil).clamp(-126, 126)) as f32
        };
        let mut values = alloc::vec::Vec::new();
        for k in -149..=127 {
            let p = f64::powi(2.0, k) as f32;
            values.extend([
                p,
                f32::from_bits(p.to_bits() + 1),
                f32::from_bits(p.to_bits() - 1),
            ]);
            values.push(p * 1.37);
        }
        values.extend([f32::MIN_POSITIVE, f32::MAX, 1e-45, 3.0e38, 0.3, 7.0]);
        for v in values.into_iter().filter(|v| *v > 0.0 && v.is_finite()) {
            assert_eq!(reciprocal_pow2(v), oracle(v), "{v:e}");
        }
        for v in [0.0, -0.0, -1.0, f32::INFINITY, f32::NAN] {
            assert_eq!(reciprocal_pow2(v), 1.0, "{v}");
        }
    }
}
