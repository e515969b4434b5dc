//! The plain C structs that cross the boundary by value or in arrays. Every field is `f32`
//! (C `float`) or `u32`, so the layouts have no padding; the assertions below pin them.

/// One irradiance sample: a patch of surface, the area it stands for and the irradiance
/// arriving there. The same seven floats as lucent-core's `Sample`.
///
/// ```text
/// offset  0        12     16              28
///         | x y z  | area | r g b         |
///         position         irradiance
/// ```
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LucentSample {
    /// Position (scene units).
    pub position: [f32; 3],
    /// Surface area the sample stands for (scene units²), finite and ≥ 0.
    pub area: f32,
    /// Irradiance per RGB channel, finite and ≥ 0.
    pub irradiance: [f32; 3],
}

/// The point being shaded.
///
/// ```text
/// offset  0        12        24
///         | x y z  | r g b   |
///         position  irradiance
/// ```
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LucentShadingPoint {
    /// Position x (scene units), finite.
    pub position: [f32; 3],
    /// Irradiance E(x) at x itself per RGB channel, finite and ≥ 0 (the local-global
    /// method's local term is E(x)·K; edge-aware and edge-refined weigh it in; the others
    /// ignore it).
    pub irradiance: [f32; 3],
}

/// A query's result per RGB channel: total = local + global.
///
/// ```text
/// offset  0        12       24       36                 48
///         | total  | local  | global | local_irradiance |
/// ```
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LucentExitance {
    /// Radiant exitance M_o (same radiometric unit as the irradiance).
    pub total: [f32; 3],
    /// The local term E_loc·K (zero for hierarchical and exhaustive).
    pub local: [f32; 3],
    /// The octree (or exhaustive) sum.
    pub global: [f32; 3],
    /// The irradiance that drives the local term: E(x) for local-global, the kernel-weighted
    /// E_loc for edge-aware (and edge-refined where it is not refined), local / K where
    /// edge-refined refines it, zero for the others.
    pub local_irradiance: [f32; 3],
}

/// Material coefficients per RGB channel, in inverse scene units.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LucentCoefficients {
    /// Absorption σ_a per channel, finite and ≥ 0.
    pub sigma_a: [f32; 3],
    /// Reduced scattering σ_s′ per channel, finite and > 0.
    pub sigma_s_prime: [f32; 3],
    /// Relative index of refraction η (inside / outside), in [1, 3].
    pub eta: f32,
}

/// Which sum a query evaluates (`LucentQueryOptions.method`).
#[repr(C)]
#[allow(non_camel_case_types)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LucentMethod {
    /// Jensen & Buhler 2002: octree sum, nodes aggregated when their solid angle is below ε.
    LUCENT_METHOD_HIERARCHICAL = 0,
    /// Langlands & Mertens 2007: E(x)·K plus the octree sum weighted by (1 − w).
    LUCENT_METHOD_LOCAL_GLOBAL = 1,
    /// Neulander 2010 (the default): as local-global with E(x) replaced by the kernel-weighted
    /// irradiance of the cache around x, which keeps shadow edges soft and in place.
    LUCENT_METHOD_EDGE_AWARE = 2,
    /// Every sample, no approximation: the reference, and slow.
    LUCENT_METHOD_EXHAUSTIVE = 3,
    /// Edge-aware, except where the samples' irradiance within α is not uniform (a shadow
    /// edge): there the local term is a quadrature of the irradiance that the caller
    /// evaluates at nodes around x (`docs/physics.md` §16). Queried only with
    /// `lucent_query_point_refined`, which takes the callback.
    LUCENT_METHOD_EDGE_REFINED = 4,
}

/// How to query: the input of `lucent_query_new`. `lucent_query_options_init` fills in the
/// defaults (edge-aware, smoothing factor 2, ε = 0.05, cull tolerance 1e-4).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LucentQueryOptions {
    /// A `LucentMethod` value.
    pub method: u32,
    /// k in the smoothing radius α = k·√Ā of the split methods (Ā the cache's mean
    /// sample area; N10 suggests 1 to 4), finite and ≥ 0. Ignored by the other methods.
    pub smoothing_factor: f32,
    /// JB02's solid-angle threshold ε: a node is aggregated when A/|x − P|² < ε (0 = never).
    pub epsilon: f32,
    /// Relative tolerance for skipping negligible subtrees (0 = never).
    pub cull_tolerance: f32,
}

const _: () = {
    use core::mem::{align_of, size_of};
    assert!(size_of::<LucentSample>() == 7 * size_of::<f32>());
    assert!(align_of::<LucentSample>() == align_of::<f32>());
    assert!(size_of::<LucentShadingPoint>() == 6 * size_of::<f32>());
    assert!(size_of::<LucentExitance>() == 12 * size_of::<f32>());
    assert!(size_of::<LucentCoefficients>() == 7 * size_of::<f32>());
    assert!(size_of::<LucentQueryOptions>() == 4 * size_of::<f32>());
    assert!(size_of::<LucentMethod>() == size_of::<core::ffi::c_int>());
};
