//! Every call into lucent-core, and every core type the C interface stands on, is in this
//! file: the rest of the crate speaks only the C structs of [`crate::types`] and the
//! [`Material`] and [`Cache`] wrappers below, so that a change of the core's Rust API is a
//! change here alone. Only the core's crate-root names are used.

use lucent_core::glam::Vec3;
use lucent_core::{
    Exitance, IrradianceCache, LocalIntegralTable, LocalQuadrature, LocalTerm, Method, Profile,
    QuerySettings, Sample, ShadingPoint,
};

use crate::status::{Failure, LucentStatus};
use crate::types::{
    LucentCoefficients, LucentExitance, LucentMethod, LucentQueryOptions, LucentSample,
    LucentShadingPoint,
};

/// How far from 1 the length of a shading normal may be (`lucent_query_point_refined`).
pub(crate) const NORMAL_TOLERANCE: f32 = 1e-3;

/// A diffusion profile (the inside of a `LucentProfile` handle).
#[derive(Clone, Debug)]
pub(crate) struct Material(Profile);

/// An irradiance cache (the inside of a `LucentCache` handle). Immutable once built, and
/// `Sync`: queries from many threads at once need no lock.
#[derive(Debug)]
pub(crate) struct Cache(IrradianceCache);

/// A query plan (the inside of a `LucentQuery` handle): the profile, the core's settings, and
/// the local integral K that belongs to their smoothing radius α. Immutable once made.
#[derive(Clone, Debug)]
pub(crate) struct Plan {
    profile: Profile,
    settings: QuerySettings,
    local: LocalTerm,
    /// α for the unsplit methods too (the core's `LocalTerm::NONE` has α = 0).
    smoothing_radius: f32,
    /// The edge-refined method's nodes and weights for the profile and α (edge-refined only).
    quadrature: Option<LocalQuadrature>,
}

/// The caller's irradiance at one quadrature node of the edge-refined local term: called with
/// the node's index, position, the unit normal at the shading point and the shadow-skip
/// distance; returns E per RGB channel (checked here) or the caller's failure.
pub(crate) trait NodeIrradiance {
    fn at(
        &mut self,
        node: usize,
        position: [f32; 3],
        normal: [f32; 3],
        skip: f32,
    ) -> Result<[f32; 3], Failure>;
}

fn invalid(error: impl std::fmt::Display) -> Failure {
    Failure::invalid(error.to_string())
}

impl Material {
    /// A measured material by name (any ASCII case) at `mm_per_unit` millimetres per unit.
    pub(crate) fn from_preset(name: &str, mm_per_unit: f32) -> Result<Material, Failure> {
        let preset = lucent_core::presets::find(name).ok_or_else(|| {
            Failure::new(
                LucentStatus::LUCENT_UNKNOWN_PRESET,
                format!("unknown material preset \"{name}\""),
            )
        })?;
        Profile::from_preset(preset, mm_per_unit)
            .map(Material)
            .map_err(invalid)
    }

    /// From σ_a, σ_s′ (per scene unit) and η.
    pub(crate) fn from_coefficients(c: &LucentCoefficients) -> Result<Material, Failure> {
        Profile::from_coefficients(
            Vec3::from_array(c.sigma_a),
            Vec3::from_array(c.sigma_s_prime),
            c.eta,
        )
        .map(Material)
        .map_err(invalid)
    }

    /// Rd_total per channel: the albedo of a flat, uniformly lit surface.
    pub(crate) fn total_reflectance(&self) -> [f32; 3] {
        self.0.total_reflectance().to_array()
    }

    /// ℓ_u = 1/σ_t′ per channel.
    pub(crate) fn mean_free_path(&self) -> [f32; 3] {
        self.0.mean_free_path().to_array()
    }

    /// Radiance towards a viewer at cos θ_o from radiant exitance (`docs/physics.md` §17).
    pub(crate) fn radiance(&self, exitance: [f32; 3], cos_out: f32) -> Result<[f32; 3], Failure> {
        if !exitance.iter().all(|v| v.is_finite()) {
            return Err(Failure::invalid(format!(
                "exitance must be finite, got {exitance:?}"
            )));
        }
        if !(0.0..=1.0).contains(&cos_out) {
            return Err(Failure::invalid(format!(
                "cos_out must lie in [0, 1], got {cos_out}"
            )));
        }
        Ok(self
            .0
            .radiance(Vec3::from_array(exitance), cos_out)
            .to_array())
    }

    /// The local integral K per channel for smoothing radius α (N10's table, looked up at
    /// this profile's ℓ_u).
    pub(crate) fn local_integral(&self, alpha: f32) -> Result<[f32; 3], Failure> {
        let table = LocalIntegralTable::new(&self.0, alpha, alpha / 1024.0).map_err(invalid)?;
        Ok(table.lookup(self.0.mean_free_path()).to_array())
    }
}

impl Cache {
    /// Builds a cache from samples in any order.
    pub(crate) fn build(samples: &[LucentSample]) -> Result<Cache, Failure> {
        let samples: Vec<Sample> = samples
            .iter()
            .map(|s| Sample {
                position: Vec3::from_array(s.position),
                area: s.area,
                irradiance: Vec3::from_array(s.irradiance),
            })
            .collect();
        let cache = IrradianceCache::build(&samples).map_err(invalid)?;
        Ok(Cache(cache))
    }

    /// Number of samples.
    pub(crate) fn len(&self) -> usize {
        self.0.len()
    }

    /// Mean sample area Ā.
    pub(crate) fn mean_area(&self) -> f32 {
        self.0.mean_area()
    }

    /// α = k·√Ā.
    pub(crate) fn smoothing_radius(&self, k: f32) -> f32 {
        self.0.smoothing_radius(k)
    }
}

impl Plan {
    /// Settings from the options, with α = k·√Ā of `cache` and, for local-global, edge-aware
    /// and edge-refined, K for `material` and α (zero for the others), and edge-refined's
    /// quadrature.
    pub(crate) fn new(
        material: &Material,
        cache: &Cache,
        options: &LucentQueryOptions,
    ) -> Result<Plan, Failure> {
        let method = method(options.method)?;
        let factor = options.smoothing_factor;
        if !(factor.is_finite() && factor >= 0.0) {
            return Err(Failure::invalid(format!(
                "smoothing_factor must be finite and non-negative, got {factor}"
            )));
        }
        let alpha = cache.smoothing_radius(factor);
        let local_integral = if method.is_split() {
            if !(alpha > 0.0) {
                return Err(Failure::invalid(format!(
                    "the {} method needs a positive smoothing radius, got {alpha} \
                     (smoothing_factor {factor} times the square root of the mean sample \
                     area {})",
                    method.name(),
                    cache.mean_area()
                )));
            }
            LocalIntegralTable::new(&material.0, alpha, alpha / 1024.0)
                .map_err(invalid)?
                .local_term(material.0.mean_free_path())
        } else {
            LocalTerm::NONE
        };
        let settings = QuerySettings {
            method,
            epsilon: options.epsilon,
            cull_tolerance: options.cull_tolerance,
        };
        settings.validate().map_err(invalid)?;
        let quadrature = (method == Method::EdgeRefined).then(|| {
            LocalQuadrature::new(
                &material.0,
                alpha,
                LocalQuadrature::DEFAULT_RINGS,
                LocalQuadrature::DEFAULT_PER_RING,
            )
        });
        Ok(Plan {
            profile: material.0,
            settings,
            local: local_integral,
            smoothing_radius: alpha,
            quadrature,
        })
    }

    /// The smoothing radius α.
    pub(crate) fn smoothing_radius(&self) -> f32 {
        self.smoothing_radius
    }

    /// The local integral K per channel (zero for the methods without a local term).
    pub(crate) fn local_integral(&self) -> [f32; 3] {
        self.local.k().to_array()
    }

    /// The core's query at `point`, the local term unrefined.
    fn query_core(&self, cache: &Cache, point: &LucentShadingPoint) -> Result<Exitance, Failure> {
        let point = ShadingPoint {
            position: Vec3::from_array(point.position),
            irradiance: Vec3::from_array(point.irradiance),
        };
        cache
            .0
            .query(&self.profile, &point, self.local, &self.settings)
            .map_err(invalid)
    }

    /// One query without a callback: every method but edge-refined.
    pub(crate) fn query(
        &self,
        cache: &Cache,
        point: &LucentShadingPoint,
    ) -> Result<LucentExitance, Failure> {
        if self.quadrature.is_some() {
            return Err(Failure::new(
                LucentStatus::LUCENT_UNSUPPORTED,
                "an edge-refined plan needs the caller's irradiance at quadrature nodes: \
                 query it with lucent_query_point_refined",
            ));
        }
        Ok(exitance(self.query_core(cache, point)?))
    }

    /// Many queries, all or nothing: the first failure names its point.
    pub(crate) fn query_many(
        &self,
        cache: &Cache,
        points: &[LucentShadingPoint],
    ) -> Result<Vec<LucentExitance>, Failure> {
        points
            .iter()
            .enumerate()
            .map(|(i, point)| {
                self.query(cache, point)
                    .map_err(|f| Failure::new(f.status, format!("point {i}: {}", f.message)))
            })
            .collect()
    }

    /// One query of any method, the edge-refined local term evaluated with the caller's
    /// irradiance at the quadrature nodes where the core flags the point (`docs/physics.md`
    /// §16). Node n lies at x + t₁·o.x + t₂·o.y + n·lift(n), (t₁, t₂) the normal's orthonormal
    /// pair and o the node's offset with the pattern turned by a hash of `seed`: the steps of
    /// the renderer's refinement, with the lights and occluders on the caller's side.
    pub(crate) fn query_refined(
        &self,
        cache: &Cache,
        point: &LucentShadingPoint,
        normal: [f32; 3],
        seed: u64,
        irradiance: &mut impl NodeIrradiance,
    ) -> Result<LucentExitance, Failure> {
        let n = Vec3::from_array(normal);
        let length = n.length();
        if !(n.is_finite() && (length - 1.0).abs() <= NORMAL_TOLERANCE) {
            return Err(Failure::invalid(format!(
                "normal must be a finite unit vector (length within {NORMAL_TOLERANCE} of 1), \
                 got {normal:?} of length {length}"
            )));
        }
        let n = n / length;
        let m = self.query_core(cache, point)?;
        let (true, Some(quadrature)) = (m.refine, self.quadrature.as_ref()) else {
            return Ok(exitance(m));
        };
        let x = Vec3::from_array(point.position);
        let (t1, t2) = n.any_orthonormal_pair();
        let rotation = LocalQuadrature::rotation_for_seed(seed);
        let skip = quadrature.shadow_skip();
        let mut at = [Vec3::ZERO; LocalQuadrature::MAX_NODES];
        for (node, e) in at.iter_mut().enumerate().take(quadrature.len()) {
            let o = quadrature.offset(node, rotation);
            let p = x + t1 * o.x + t2 * o.y + n * quadrature.lift(node);
            let value = irradiance.at(node, p.to_array(), n.to_array(), skip)?;
            if !value.iter().all(|v| v.is_finite() && *v >= 0.0) {
                return Err(Failure::invalid(format!(
                    "the irradiance callback gave {value:?} at node {node} (position {:?}): \
                     irradiance must be finite and non-negative",
                    p.to_array()
                )));
            }
            *e = Vec3::from_array(value);
        }
        let e_x = Vec3::from_array(point.irradiance);
        let local = quadrature.local_term(e_x, self.local, &at[..quadrature.len()]);
        Ok(exitance(m.with_local(local, self.local)))
    }
}

/// The C struct of a core result.
fn exitance(m: Exitance) -> LucentExitance {
    LucentExitance {
        total: m.total.to_array(),
        local: m.local.to_array(),
        global: m.global.to_array(),
        local_irradiance: m.local_irradiance.to_array(),
    }
}

/// The core's method for a `LucentMethod` value.
fn method(value: u32) -> Result<Method, Failure> {
    Ok(match value {
        v if v == LucentMethod::LUCENT_METHOD_HIERARCHICAL as u32 => Method::Hierarchical,
        v if v == LucentMethod::LUCENT_METHOD_LOCAL_GLOBAL as u32 => Method::LocalGlobal,
        v if v == LucentMethod::LUCENT_METHOD_EDGE_AWARE as u32 => Method::EdgeAware,
        v if v == LucentMethod::LUCENT_METHOD_EXHAUSTIVE as u32 => Method::Exhaustive,
        v if v == LucentMethod::LUCENT_METHOD_EDGE_REFINED as u32 => Method::EdgeRefined,
        v => {
            return Err(Failure::invalid(format!(
                "method {v} is not a LucentMethod (0 to 4)"
            )));
        }
    })
}

/// The `LucentMethod` with this scene-format name (`hierarchical`, `local-global`,
/// `edge-aware`, `exhaustive`, `edge-refined`).
pub(crate) fn method_from_name(name: &str) -> Result<LucentMethod, Failure> {
    let found = Method::ALL
        .into_iter()
        .find(|m| m.name() == name)
        .ok_or_else(|| Failure::invalid(format!("unknown method \"{name}\"")))?;
    Ok(match found {
        Method::Hierarchical => LucentMethod::LUCENT_METHOD_HIERARCHICAL,
        Method::LocalGlobal => LucentMethod::LUCENT_METHOD_LOCAL_GLOBAL,
        Method::EdgeAware => LucentMethod::LUCENT_METHOD_EDGE_AWARE,
        Method::Exhaustive => LucentMethod::LUCENT_METHOD_EXHAUSTIVE,
        Method::EdgeRefined => LucentMethod::LUCENT_METHOD_EDGE_REFINED,
    })
}

/// The core's defaults, for `lucent_query_options_init`.
pub(crate) fn default_options() -> LucentQueryOptions {
    let defaults = QuerySettings::default();
    LucentQueryOptions {
        method: LucentMethod::LUCENT_METHOD_EDGE_AWARE as u32,
        smoothing_factor: 2.0,
        epsilon: defaults.epsilon,
        cull_tolerance: defaults.cull_tolerance,
    }
}

/// The core's own `Sample` must stay the seven floats `LucentSample` mirrors.
const _: () = assert!(size_of::<Sample>() == size_of::<LucentSample>());
