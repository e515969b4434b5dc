//! Which instruction set the cache traversal runs on, chosen once per process.
//!
//! The core's default lanes (`wide::f32x8`) are compiled for the baseline of the target: on
//! x86-64, SSE2, two 128-bit registers per eight lanes. On a CPU with AVX2 the renderer calls
//! the core's AVX2 build of the same traversal instead
//! ([`IrradianceCache::query_planned_avx2`]), one 256-bit register per eight lanes. Both
//! give the same bits (no fused multiply-add), so images do not depend on the CPU.
//!
//! `LUCENT_SIMD` overrides the detection: `baseline` forces the baseline lanes, `avx2` the
//! AVX2 ones (an error on a CPU without AVX2), `auto` or unset detects.

use std::fmt;
use std::sync::OnceLock;

use lucent_core::error::QueryError;
use lucent_core::stats::{QueryStats, StatsSink};
use lucent_core::{
    Exitance, IrradianceCache, LocalTerm, Profile, QueryPlan, QuerySettings, ShadingPoint,
};

/// The environment variable that forces a path.
pub const ENV: &str = "LUCENT_SIMD";

/// A traversal path.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Simd {
    /// The core's default lanes, compiled for the target's baseline (SSE2 on x86-64).
    #[default]
    Baseline,
    /// The AVX2 build of the traversal (x86 and x86-64 CPUs with AVX2).
    Avx2,
}

impl Simd {
    /// The name `LUCENT_SIMD` takes and the summary line prints.
    pub fn name(self) -> &'static str {
        match self {
            Simd::Baseline => "baseline",
            Simd::Avx2 => "avx2",
        }
    }
}

impl fmt::Display for Simd {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Why `LUCENT_SIMD` cannot be honoured.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SimdError {
    /// `LUCENT_SIMD=avx2` on a CPU without AVX2.
    Unsupported,
    /// `LUCENT_SIMD` is not one of the names.
    UnknownName(String),
}

impl fmt::Display for SimdError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SimdError::Unsupported => write!(f, "{ENV}=avx2, but this CPU does not support AVX2"),
            SimdError::UnknownName(name) => write!(
                f,
                "{ENV}={name:?} is not a traversal path (expected baseline, avx2 or auto)"
            ),
        }
    }
}

impl std::error::Error for SimdError {}

/// Proof that the CPU supports AVX2: only [`Avx2::detect`] makes one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Avx2(Private);

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Private;

impl Avx2 {
    /// `Some` on a CPU with AVX2.
    pub fn detect() -> Option<Avx2> {
        #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
        if std::is_x86_feature_detected!("avx2") {
            return Some(Avx2(Private));
        }
        None
    }

    /// [`IrradianceCache::query_planned`] on the AVX2 build of the traversal (the same bits).
    #[inline]
    pub fn query_planned<S: StatsSink>(
        self,
        cache: &IrradianceCache,
        plan: &QueryPlan,
        point: &ShadingPoint,
        stats: &mut S,
    ) -> Result<Exitance, QueryError> {
        #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
        {
            let mut counts = QueryStats::default();
            // The renderer's one `unsafe` (the crate's lints deny it everywhere else).
            #[allow(unsafe_code)]
            // SAFETY: `query_planned_avx2` is compiled with AVX2 enabled and needs nothing
            // else; an `Avx2` exists only where `is_x86_feature_detected!("avx2")` found it.
            let result = unsafe { cache.query_planned_avx2(plan, point, &mut counts) };
            stats.merge(&counts);
            result
        }
        #[cfg(not(any(target_arch = "x86", target_arch = "x86_64")))]
        {
            // No `Avx2` exists off x86 (`detect` returns `None`).
            let _ = self;
            cache.query_planned(plan, point, stats)
        }
    }

    /// [`IrradianceCache::query_with_stats`] on the AVX2 build of the traversal (the same
    /// bits): the plan, then [`Avx2::query_planned`]. The checks come in the plan's order (α,
    /// K, the settings, then the point).
    #[inline]
    pub fn query<S: StatsSink>(
        self,
        cache: &IrradianceCache,
        profile: &Profile,
        point: &ShadingPoint,
        local: LocalTerm,
        settings: &QuerySettings,
        stats: &mut S,
    ) -> Result<Exitance, QueryError> {
        let plan = cache.plan(profile, local, settings)?;
        self.query_planned(cache, &plan, point, stats)
    }
}

/// The chosen path: `None` for the baseline.
static CHOICE: OnceLock<Result<Option<Avx2>, SimdError>> = OnceLock::new();

fn choose() -> Result<Option<Avx2>, SimdError> {
    let forced = std::env::var(ENV).unwrap_or_default();
    choose_from(&forced, Avx2::detect())
}

/// The path for the value of `LUCENT_SIMD` (empty if unset) on a CPU where `detected` is
/// `Some` if it has AVX2.
fn choose_from(forced: &str, detected: Option<Avx2>) -> Result<Option<Avx2>, SimdError> {
    match forced {
        "" | "auto" => Ok(detected),
        "baseline" => Ok(None),
        "avx2" => detected.map(Some).ok_or(SimdError::Unsupported),
        other => Err(SimdError::UnknownName(other.to_owned())),
    }
}

/// The process's path: detected (or read from `LUCENT_SIMD`) on the first call, the same
/// afterwards.
pub fn selected() -> Result<Simd, SimdError> {
    match CHOICE.get_or_init(choose) {
        Ok(Some(_)) => Ok(Simd::Avx2),
        Ok(None) => Ok(Simd::Baseline),
        Err(e) => Err(e.clone()),
    }
}

/// A cache query on the process's path ([`selected`]; the baseline if `LUCENT_SIMD` is
/// invalid, which [`super::render`] reports before shading).
#[inline]
pub fn query<S: StatsSink>(
    cache: &IrradianceCache,
    profile: &Profile,
    point: &ShadingPoint,
    local: LocalTerm,
    settings: &QuerySettings,
    stats: &mut S,
) -> Result<Exitance, QueryError> {
    match CHOICE.get_or_init(choose) {
        Ok(Some(avx2)) => avx2.query(cache, profile, point, local, settings, stats),
        _ => cache.query_with_stats(profile, point, local, settings, stats),
    }
}

/// A planned cache query ([`IrradianceCache::plan`]) on the process's path, as [`query`].
#[inline]
pub fn query_planned<S: StatsSink>(
    cache: &IrradianceCache,
    plan: &QueryPlan,
    point: &ShadingPoint,
    stats: &mut S,
) -> Result<Exitance, QueryError> {
    match CHOICE.get_or_init(choose) {
        Ok(Some(avx2)) => avx2.query_planned(cache, plan, point, stats),
        _ => cache.query_planned(plan, point, stats),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lucent_core::glam::Vec3;
    use lucent_core::internals::local_term;
    use lucent_core::stats::QueryStats;
    use lucent_core::{Distance, Method, Sample};

    #[test]
    fn names_choose_the_path() {
        assert_eq!(choose_from("baseline", None), Ok(None));
        assert_eq!(choose_from("", None), Ok(None));
        assert_eq!(choose_from("avx2", None), Err(SimdError::Unsupported));
        let err = choose_from("AVX2", None).unwrap_err();
        assert_eq!(err, SimdError::UnknownName("AVX2".into()));
        assert!(err.to_string().contains("LUCENT_SIMD=\"AVX2\""), "{err}");
        if let Some(avx2) = Avx2::detect() {
            assert!(matches!(choose_from("avx2", Some(avx2)), Ok(Some(_))));
            assert!(matches!(choose_from("auto", Some(avx2)), Ok(Some(_))));
            assert_eq!(choose_from("baseline", Some(avx2)), Ok(None));
        }
    }

    /// A SplitMix64 stream of floats in [0, 1).
    fn uniform(seed: u64) -> impl FnMut() -> f32 {
        let mut state = seed;
        move || {
            state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            ((z ^ (z >> 31)) >> 40) as f32 / 16_777_216.0
        }
    }

    /// The AVX2 build of the traversal, through the renderer's one `unsafe` call, gives the
    /// bits of the baseline one and takes the same steps: every method, several ε and cull
    /// tolerances, random sample sets (shadowed and lit, flat and in a volume) and random
    /// points on and off them.
    #[test]
    fn avx2_and_baseline_give_the_same_bits() {
        let Some(avx2) = Avx2::detect() else {
            println!("skipped: this CPU has no AVX2, so there is only the baseline path");
            return;
        };
        let mut u = uniform(42);
        for (set, n) in [(0, 4000), (1, 1500), (2, 200)] {
            let samples: Vec<Sample> = (0..n)
                .map(|_| {
                    let p = Vec3::new(u(), u(), u()) * 2.0 - 1.0;
                    let position = match set {
                        0 => p.normalize_or(Vec3::Z),
                        1 => p * Vec3::new(1.0, 1.0, 0.01),
                        _ => p * 1e-3,
                    };
                    let lit = if position.z > 0.0 || set == 1 {
                        u()
                    } else {
                        0.0
                    };
                    Sample {
                        position,
                        area: u() * 4.0 / n as f32,
                        irradiance: Vec3::new(lit, 0.5 * lit, u() * 0.1),
                    }
                })
                .collect();
            let cache = IrradianceCache::build(&samples).unwrap();
            let scale = if set == 2 { 1e-3 } else { 1.0 };
            let ell = scale * (0.01 + 0.2 * u());
            let profile = Profile::from_reflectance(
                Vec3::new(0.8, 0.6, 0.3),
                Distance::MeanFreePath(Vec3::new(ell, ell * 0.6, ell * 0.3)),
                1.3,
            )
            .unwrap();
            let alpha = cache.smoothing_radius(1.5);
            for i in 0..80 {
                let off = if i % 8 == 0 { 2.0 * u() } else { 1.0 };
                let p = samples[(u() * n as f32) as usize % n].position * off;
                let point = ShadingPoint {
                    position: p,
                    irradiance: Vec3::new(u(), u(), 0.0),
                };
                let local = local_term(alpha, Vec3::new(u(), u(), u()));
                for method in Method::ALL {
                    for (epsilon, cull_tolerance) in [(0.05, 1e-4), (0.5, 0.0), (2.0, 1e-2)] {
                        let settings = QuerySettings {
                            method,
                            epsilon,
                            cull_tolerance,
                        };
                        let (mut sa, mut sb) = (QueryStats::default(), QueryStats::default());
                        let a = cache
                            .query_with_stats(&profile, &point, local, &settings, &mut sa)
                            .unwrap();
                        let b = avx2
                            .query(&cache, &profile, &point, local, &settings, &mut sb)
                            .unwrap();
                        let bits = |e: &Exitance| {
                            [e.total, e.local, e.global, e.local_irradiance]
                                .map(|v| v.to_array().map(f32::to_bits))
                        };
                        let at = format!("{method:?} ε {epsilon} at {p} (set {set})");
                        assert_eq!(bits(&a), bits(&b), "{at}: {a:?} vs {b:?}");
                        assert_eq!(a.refine, b.refine, "{at}");
                        assert_eq!(sa, sb, "{at}");
                    }
                }
            }
        }
    }
}
