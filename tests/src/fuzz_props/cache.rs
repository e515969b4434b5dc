//! `cache_query_matches_exhaustive`: arbitrary sample sets and shading points against the
//! irradiance cache.
//!
//! # Input layout
//!
//! ```text
//! header   kd_r kd_g kd_b          K_d = 0.001 + 0.998·b/255 per channel
//!          ell_exp                 ℓ_u = 2^(b mod 41 − 20) · (1 + 3·b_c/255), then b_r b_g b_b
//!          eta                     η = 1 + 1.5·b/255
//!          eps  tol  k             ε = EPSILONS[b mod 8], t = TOLERANCES[b mod 8], α = (b/32)·√Ā
//!          pos  area  irr          scales 2^(b as i8): 2^−128 (subnormal) … 2^127
//!          nq                      1 + b mod 4 shading points, each:
//! point    mode e_r e_g e_b …      mode mod 4: 0 at a sample (u16 index), 1 near a sample
//!                                  (index, 3 × i8·pos/64), 2 at 3 × i8·pos, 3 at 3 raw f32
//! samples  mode …                  until the input ends (at most MAX_FUZZ_SAMPLES):
//!            bits 0–1 position     0: 3 × i8·pos, 1: the previous sample's (coincident),
//!                                  2: on the line through samples 0 and 1 (i8/16), 3: raw f32
//!            bits 2–3 area         0: zero, 1: byte/255·area, 2: area, 3: raw f32
//!            bits 4–5 irradiance   0: zero, 1: 3 bytes·4/255·irr, 2: grey, 3: 3 raw f32
//!            bits 6–7              1: repeat the sample 1 + byte times (coincident copies)
//! ```
//!
//! # What is checked
//!
//! 1. `IrradianceCache::build` never panics; it fails exactly when a sample is invalid (a
//!    non-finite position, a negative or non-finite area or irradiance, a non-finite flux) or
//!    the total area or flux exceeds the f32 range.
//! 2. On success `validate()` holds and the cache holds every sample.
//! 3. The profile (K_d, ℓ_u, η inside the documented valid ranges) and the local-integral
//!    table build, and K is finite and non-negative.
//! 4. Every method, with and without culling, returns non-negative, never NaN results, and
//!    finite ones when every sum a query forms (flux or area-weighted) is bounded well inside
//!    the f32 range (beyond it, overflow to +∞ is allowed); a non-finite shading point is
//!    rejected with `NonFinitePosition`. (The traversal multiplies kernel factors into the flux
//!    before Rd, so a zero factor never meets an overflowed product: found by this target,
//!    `regress-overflow-times-zero-weight-nan`.)
//! 5. (Bounded sums only, as in 4.) Culling with tolerance t skips at most t × the culled
//!    global sum, and never adds.
//! 6. (Likewise.) With ε = 0 and t = 0 the hierarchical, local-global and edge-aware queries
//!    equal the exhaustive sums (core's oracles, and an independent scalar f64 sum) to float
//!    rounding — N10 included where its weights Rd·A would be subnormal in f32 (found by this
//!    target, `regress-subnormal-edge-aware-weights`) or Ā itself is subnormal: the traversal
//!    scales Rd and A apart by powers of two near 1/Rd(0) and 1/Ā (one factor 1/(Rd(0)·Ā)
//!    overflowed Rd·factor where Ā < 2⁻¹²⁷: `crash-subnormal-mean-area-scale-overflow`); and
//!    where x lies in a node whose centroid is beyond 1.8·10¹⁹, whose squared distance
//!    overflows (`crash-centroid-distance-squared-overflows`: the unlit node holding x was
//!    pruned as far, and E_loc lost x's own sample).
//! 7. On a CPU with AVX2, every query of 4 (and every refusal of a non-finite point) gives the
//!    same bits and takes the same steps (`QueryStats`) on the AVX2 build of the traversal as
//!    on the baseline lanes: the two paths differ in how they compile the same operations,
//!    and in the AVX2 path's lane permutation (`vpermps`) for the term buffers.
//!
//! Rounding allowance: every query sums non-negative terms in f32 lanes, each lane adding at
//! most ⌈n/8⌉ + 16 terms, so the relative error is at most about (n/8 + 16)·2⁻²⁴ (the classical
//! bound for recursive summation); the lanes' exponential adds 4e-7. The absolute allowance
//! covers terms that underflow.

use lucent_core::error::QueryError;
use lucent_core::glam::{DVec3, Vec3};
use lucent_core::internals::{exhaustive_edge_aware, exhaustive_local_global, exhaustive_sum};
use lucent_core::stats::QueryStats;
use lucent_core::{
    Distance, Exitance, IrradianceCache, LocalIntegralTable, LocalTerm, Method, Profile,
    QuerySettings, Sample, ShadingPoint,
};
use lucent_raster::render::simd::Avx2;

use super::input::Input;

/// Most samples one input decodes to.
pub const MAX_FUZZ_SAMPLES: usize = 2048;

/// The ε choices (zero twice: the exactly checkable case is the interesting one).
const EPSILONS: [f32; 8] = [0.0, 0.0, 1e-4, 1e-3, 0.01, 0.05, 0.5, 10.0];
/// The cull tolerance choices.
const TOLERANCES: [f32; 8] = [0.0, 1e-6, 1e-4, 1e-3, 1e-2, 0.1, 0.5, 1.0];

/// Where a shading point goes, resolved once the samples are known.
#[derive(Clone, Copy, Debug)]
enum Place {
    /// At sample `index mod n`, plus an offset.
    NearSample(u16, Vec3),
    /// At an absolute position.
    At(Vec3),
}

/// One decoded input.
#[derive(Clone, Debug)]
struct Case {
    kd: Vec3,
    ell: Vec3,
    eta: f32,
    epsilon: f32,
    tolerance: f32,
    smoothing: f32,
    queries: Vec<(Place, Vec3)>,
    samples: Vec<Sample>,
}

fn vec3(mut f: impl FnMut() -> f32) -> Vec3 {
    let x = f();
    let y = f();
    let z = f();
    Vec3::new(x, y, z)
}

fn decode(data: &[u8]) -> Case {
    let mut r = Input::new(data);
    let kd = vec3(|| 0.001 + 0.998 * r.unit());
    let ell_base = super::input::pow2(i32::from(r.u8() % 41) - 20);
    let ell = vec3(|| ell_base * (1.0 + 3.0 * r.unit()));
    let eta = 1.0 + 1.5 * r.unit();
    let epsilon = EPSILONS[usize::from(r.u8() % 8)];
    let tolerance = TOLERANCES[usize::from(r.u8() % 8)];
    let smoothing = f32::from(r.u8()) / 32.0;
    let pos = r.pow2_i8();
    let area = r.pow2_i8();
    let irr = r.pow2_i8();
    let nq = 1 + r.u8() % 4;
    let mut queries = Vec::new();
    for _ in 0..nq {
        let mode = r.u8();
        let e = vec3(|| 4.0 * r.unit());
        let place = match mode % 4 {
            0 => Place::NearSample(r.u16(), Vec3::ZERO),
            1 => {
                let index = r.u16();
                Place::NearSample(index, vec3(|| f32::from(r.i8()) * pos / 64.0))
            }
            2 => Place::At(vec3(|| f32::from(r.i8()) * pos)),
            _ => Place::At(vec3(|| r.f32_bits())),
        };
        queries.push((place, e));
    }
    let mut samples: Vec<Sample> = Vec::new();
    while !r.is_empty() && samples.len() < MAX_FUZZ_SAMPLES {
        let m = r.u8();
        let position = match m & 3 {
            0 => vec3(|| f32::from(r.i8()) * pos),
            1 => samples.last().map_or(Vec3::ZERO, |s| s.position),
            2 if samples.len() >= 2 => {
                let (a, b) = (samples[0].position, samples[1].position);
                a + (b - a) * (f32::from(r.i8()) / 16.0)
            }
            2 => vec3(|| f32::from(r.i8()) * pos),
            _ => vec3(|| r.f32_bits()),
        };
        let a = match (m >> 2) & 3 {
            0 => 0.0,
            1 => r.unit() * area,
            2 => area,
            _ => r.f32_bits(),
        };
        let irradiance = match (m >> 4) & 3 {
            0 => Vec3::ZERO,
            1 => vec3(|| 4.0 * r.unit() * irr),
            2 => Vec3::splat(4.0 * r.unit() * irr),
            _ => vec3(|| r.f32_bits()),
        };
        let copies = if m >> 6 == 1 {
            1 + usize::from(r.u8())
        } else {
            1
        };
        let sample = Sample {
            position,
            area: a,
            irradiance,
        };
        let room = MAX_FUZZ_SAMPLES - samples.len();
        samples.extend(std::iter::repeat_n(sample, copies.min(room)));
    }
    Case {
        kd,
        ell,
        eta,
        epsilon,
        tolerance,
        smoothing,
        queries,
        samples,
    }
}

/// What `build` must accept (written from its documentation, not its code).
fn sample_is_valid(s: &Sample) -> bool {
    let non_negative = |v: f32| v.is_finite() && v >= 0.0;
    s.position.is_finite()
        && non_negative(s.area)
        && s.irradiance.to_array().into_iter().all(non_negative)
        && (s.irradiance * s.area).is_finite()
}

/// The total area and flux, which the cache keeps in f32 node sums, must fit in f32.
fn totals_fit_f32(samples: &[Sample]) -> bool {
    let area: f64 = samples.iter().map(|s| f64::from(s.area)).sum();
    let flux: DVec3 = samples
        .iter()
        .map(|s| (s.irradiance * s.area).as_dvec3())
        .sum();
    area.max(flux.max_element()) <= f64::from(f32::MAX)
}

/// M_o(x) = Σ Rd(|x − p_i|)·E_i·A_i over the input samples: scalar Rd, f64 sums.
fn scalar_oracle(samples: &[Sample], profile: &Profile, x: Vec3) -> DVec3 {
    samples
        .iter()
        .map(|s| {
            let flux = s.irradiance * s.area;
            profile.rd((s.position - x).length_squared()).as_dvec3() * flux.as_dvec3()
        })
        .sum()
}

/// Rounding allowances for one cache (see the module docs).
#[derive(Clone, Copy, Debug)]
struct Slack {
    rel: f64,
    abs: f64,
}

impl Slack {
    fn close(&self, got: f64, want: f64) -> bool {
        (got - want).abs() <= self.rel * got.abs().max(want.abs()) + self.abs
    }
}

fn assert_sane(what: &str, m: &Exitance, representable: bool) {
    for (name, v) in [
        ("total", m.total),
        ("local", m.local),
        ("global", m.global),
        ("local irradiance", m.local_irradiance),
    ] {
        for c in v.to_array() {
            assert!(c >= 0.0, "{what}: {name} {v} is negative or NaN");
            assert!(
                c.is_finite() || !representable,
                "{what}: {name} {v} is not finite though the exact sum is representable"
            );
        }
    }
}

/// Every field of an exitance, as bits.
fn exitance_bits(e: &Exitance) -> ([[u32; 3]; 4], bool) {
    let bits = [e.total, e.local, e.global, e.local_irradiance];
    (bits.map(|v| v.to_array().map(f32::to_bits)), e.refine)
}

/// The property of the fuzz target `cache_query_matches_exhaustive` (see the module docs);
/// panics when it fails.
pub fn cache_query_matches_exhaustive(data: &[u8]) {
    let case = decode(data);
    let n = case.samples.len();
    let valid = case.samples.iter().all(sample_is_valid) && totals_fit_f32(&case.samples);
    let cache = match (IrradianceCache::build(&case.samples), valid) {
        (Ok(cache), true) => cache,
        (Err(_), false) => return,
        (Ok(_), false) => panic!("build accepted an invalid sample set"),
        (Err(e), true) => panic!("build rejected a valid sample set: {e}"),
    };
    if let Err(e) = cache.validate() {
        panic!("{e}");
    }
    assert_eq!(cache.len(), n, "the cache lost samples");

    let profile = Profile::from_reflectance(case.kd, Distance::MeanFreePath(case.ell), case.eta)
        .unwrap_or_else(|e| {
            panic!(
                "K_d {} ℓ_u {} η {} are in the valid ranges, yet: {e}",
                case.kd, case.ell, case.eta
            )
        });
    let alpha = cache.smoothing_radius(case.smoothing);
    let local = if alpha > 0.0 && alpha.is_finite() {
        let table = LocalIntegralTable::new(&profile, alpha, alpha / 1024.0)
            .unwrap_or_else(|e| panic!("table for α {alpha}: {e}"));
        table.local_term(profile.mean_free_path())
    } else {
        LocalTerm::NONE
    };
    let (alpha, k) = (local.alpha(), local.k());
    assert!(
        k.is_finite() && k.min_element() >= 0.0,
        "K {k} for α {alpha}"
    );

    // An upper bound of every sum a query forms (Rd ≤ Rd(0), w ≤ 1, K ≤ 1, E(x) ≤ 4): the
    // flux sums, and N10's area-weighted sums Σ w·Rd·A and Rd(0)·Ā.
    let rd0 = profile.rd_zero().as_dvec3();
    let bound: f64 = case
        .samples
        .iter()
        .map(|s| {
            let flux = (rd0 * (s.irradiance * s.area).as_dvec3()).max_element();
            flux + rd0.max_element() * f64::from(s.area)
        })
        .sum::<f64>()
        + 4.0;
    let representable = bound < 1e36;
    let slack = Slack {
        rel: (n / 8 + 16) as f64 * 2f64.powi(-24) * 1.01 + 1e-6,
        abs: 1e-25 * bound + 1e-37,
    };

    let avx2 = Avx2::detect();
    for &(place, e) in &case.queries {
        let x = match place {
            Place::At(x) => x,
            Place::NearSample(i, offset) => {
                let base = case
                    .samples
                    .get(usize::from(i) % n.max(1))
                    .map_or(Vec3::ZERO, |s| s.position);
                base + offset
            }
        };
        let point = ShadingPoint {
            position: x,
            irradiance: e,
        };
        let settings = |method, epsilon, cull_tolerance| QuerySettings {
            method,
            epsilon,
            cull_tolerance,
        };
        let query = |s: QuerySettings| {
            let mut counts = QueryStats::default();
            let got = cache.query_with_stats(&profile, &point, local, &s, &mut counts);
            if let Some(avx2) = avx2 {
                let mut avx2_counts = QueryStats::default();
                let other = avx2.query(&cache, &profile, &point, local, &s, &mut avx2_counts);
                assert_eq!(
                    got.as_ref().map(exitance_bits),
                    other.as_ref().map(exitance_bits),
                    "{} at {x}, ε {}, t {}: the AVX2 path's bits differ ({got:?} vs {other:?})",
                    s.method.name(),
                    s.epsilon,
                    s.cull_tolerance
                );
                assert_eq!(counts, avx2_counts, "the AVX2 path took other steps at {x}");
            }
            got
        };
        if !x.is_finite() {
            for method in Method::ALL {
                let got = query(settings(method, 0.0, 0.0));
                assert_eq!(got, Err(QueryError::NonFinitePosition), "x = {x}");
            }
            continue;
        }

        for method in Method::ALL {
            let what = |t: f32| format!("{} at {x}, ε {}, t {t}", method.name(), case.epsilon);
            let full = query(settings(method, case.epsilon, 0.0))
                .unwrap_or_else(|err| panic!("{}: {err}", what(0.0)));
            let culled = query(settings(method, case.epsilon, case.tolerance))
                .unwrap_or_else(|err| panic!("{}: {err}", what(case.tolerance)));
            assert_sane(&what(0.0), &full, representable);
            assert_sane(&what(case.tolerance), &culled, representable);
            if !representable {
                continue;
            }
            let t = f64::from(case.tolerance);
            for c in 0..3 {
                let (f, g) = (f64::from(full.global[c]), f64::from(culled.global[c]));
                let allowance = slack.rel * f + slack.abs;
                assert!(
                    g <= f + allowance,
                    "{}: culled global {} exceeds the full {}",
                    what(case.tolerance),
                    culled.global,
                    full.global
                );
                assert!(
                    f - g <= t * g + allowance,
                    "{}: culling skipped {} of {}, more than t × {}",
                    what(case.tolerance),
                    f - g,
                    f,
                    g
                );
                let (lf, lg) = (f64::from(full.local[c]), f64::from(culled.local[c]));
                assert!(
                    slack.close(lg, lf),
                    "{}: culling changed the local term {} → {}",
                    what(case.tolerance),
                    full.local,
                    culled.local
                );
            }
        }

        if !representable {
            continue;
        }
        // ε = 0, t = 0: every octree method against exhaustive sums.
        let exhaustive = exhaustive_sum(&cache, &profile, x).as_dvec3();
        let scalar = scalar_oracle(&case.samples, &profile, x);
        let exact_exitance = |method| query(settings(method, 0.0, 0.0)).expect("checked above");
        let exact = |method| exact_exitance(method).total.as_dvec3();
        let edge_aware = (
            "edge-aware vs exhaustive_edge_aware",
            exact(Method::EdgeAware),
            exhaustive_edge_aware(&cache, &profile, x, e, k, alpha).as_dvec3(),
        );
        let oracles = [
            ("exhaustive_sum vs scalar oracle", exhaustive, scalar),
            (
                "exhaustive method vs scalar oracle",
                exact(Method::Exhaustive),
                scalar,
            ),
            (
                "hierarchical vs exhaustive_sum",
                exact(Method::Hierarchical),
                exhaustive,
            ),
            (
                "local-global vs exhaustive_local_global",
                exact(Method::LocalGlobal),
                exhaustive_local_global(&cache, &profile, x, e, k, alpha).as_dvec3(),
            ),
            edge_aware,
        ];
        for (what, got, want) in oracles {
            for c in 0..3 {
                assert!(
                    slack.close(got[c], want[c]),
                    "{what} at {x} (ε = 0, t = 0, α {alpha}): {got} vs {want}"
                );
            }
        }
    }
}
