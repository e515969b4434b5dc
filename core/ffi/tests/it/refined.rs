//! `lucent_query_point_refined`: the edge-refined local term with the caller's irradiance at
//! the quadrature nodes, against lucent-core called directly through the same steps, and its
//! failures (NULL callback, a failing or lying callback, a bad normal, a panic).

use std::ffi::{c_int, c_void};

use lucent_core::glam::Vec3;
use lucent_core::{
    IrradianceCache, LocalIntegralTable, LocalQuadrature, Method, Profile as CoreProfile,
    QuerySettings, Sample, ShadingPoint,
};
use lucent_ffi::*;

use crate::common::{Cache, METHODS, Profile, Query, alpha_and_k, build, message, plan, query};

use LucentStatus::{
    LUCENT_CALLBACK_FAILED, LUCENT_INVALID_ARGUMENT, LUCENT_NULL_POINTER, LUCENT_OK, LUCENT_PANIC,
};

const EDGE_REFINED: u32 = LucentMethod::LUCENT_METHOD_EDGE_REFINED as u32;
const E: [f32; 3] = [1.0, 2.0, 0.5];
const HALF: f32 = 40.0;
const SPACING: f32 = 0.5;
/// A point 0.3 mm on the lit side of the shadow edge x = 0 (α = 2·0.5 = 1 mm).
const NEAR_EDGE: [f32; 3] = [0.3, 0.1, 0.0];
/// The total exitance at `NEAR_EDGE` with seed 7 (printed by the half-lit test; the C example
/// `examples/embed.c` checks its own query of the same scene against these numbers).
const NEAR_EDGE_TOTAL: [f32; 3] = [0.25488898, 0.29473466, 0.0476227];

/// What the test callback does, and what it saw.
#[derive(Default)]
struct Lighting {
    /// E for x > 0 and 0 elsewhere; when false, E everywhere.
    half_plane: bool,
    /// Returned instead of 0 from the first call.
    fail_with: c_int,
    /// Written at this node instead of the irradiance.
    bad_value: Option<(usize, [f32; 3])>,
    /// Panics at the first call.
    panic: bool,
    /// Every call's position, normal and shadow skip.
    calls: Vec<([f32; 3], [f32; 3], f32)>,
}

/// The Rust stand-in for a C renderer's callback: `user` is a `Lighting`.
unsafe extern "C-unwind" fn irradiance(
    user: *mut c_void,
    position: *const f32,
    normal: *const f32,
    shadow_skip: f32,
    out: *mut f32,
) -> c_int {
    // SAFETY: the tests pass a `&mut Lighting` as `user`, alive and unaliased during the call;
    // the library passes 3 readable floats in `position` and `normal` and 3 writable in `out`.
    let (lighting, position, normal, out) = unsafe {
        (
            &mut *user.cast::<Lighting>(),
            std::slice::from_raw_parts(position, 3),
            std::slice::from_raw_parts(normal, 3),
            std::slice::from_raw_parts_mut(out, 3),
        )
    };
    let node = lighting.calls.len();
    let p = [position[0], position[1], position[2]];
    lighting
        .calls
        .push((p, [normal[0], normal[1], normal[2]], shadow_skip));
    if lighting.panic {
        panic!("the renderer's callback panicked");
    }
    if lighting.fail_with != 0 {
        return lighting.fail_with;
    }
    let e = match lighting.bad_value {
        Some((at, value)) if at == node => value,
        _ if lighting.half_plane && !(p[0] > 0.0) => [0.0; 3],
        _ => E,
    };
    out.copy_from_slice(&e);
    0
}

/// The callback that writes nothing and reports success.
unsafe extern "C-unwind" fn silent(
    _: *mut c_void,
    _: *const f32,
    _: *const f32,
    _: f32,
    _: *mut f32,
) -> c_int {
    0
}

/// `lucent_query_point_refined` with `callback`, or the failing status.
fn refined(
    q: &Query,
    cache: &Cache,
    point: &LucentShadingPoint,
    normal: [f32; 3],
    seed: u64,
    callback: LucentIrradianceFn,
    lighting: &mut Lighting,
) -> Result<LucentExitance, LucentStatus> {
    let sentinel = LucentExitance {
        total: [-1.0; 3],
        ..LucentExitance::default()
    };
    let mut out = sentinel;
    // SAFETY: live handles, a live point, 3 readable floats, the test callback with its
    // `Lighting`, and a writable result.
    let status = unsafe {
        lucent_query_point_refined(
            q.0,
            cache.0,
            point,
            normal.as_ptr(),
            seed,
            callback,
            std::ptr::from_mut(lighting).cast(),
            &mut out,
        )
    };
    if status == LUCENT_OK {
        Ok(out)
    } else {
        assert_eq!(out, sentinel, "a failed query writes nothing");
        Err(status)
    }
}

/// The patch of `common::patch` (80 × 80 mm of skin1, 0.5 mm apart), lit by E where x > 0
/// when `half_plane`, everywhere otherwise.
fn samples(half_plane: bool) -> Vec<LucentSample> {
    let mut samples = crate::common::patch(HALF, SPACING, E);
    for s in &mut samples {
        if half_plane && !(s.position[0] > 0.0) {
            s.irradiance = [0.0; 3];
        }
    }
    samples
}

fn scene(half_plane: bool) -> (Profile, Cache) {
    let skin = crate::common::preset("skin1", 1.0).unwrap();
    (skin, build(&samples(half_plane)).unwrap())
}

fn lit(position: [f32; 3]) -> LucentShadingPoint {
    LucentShadingPoint {
        position,
        irradiance: E,
    }
}

/// The edge-refined query done by hand with lucent-core's Rust API, as the renderer does it:
/// the core's query, then (if flagged) the quadrature of `light` at the nodes. Returns the
/// result, whether it was refined, and the nodes.
fn by_hand(
    half_plane: bool,
    position: [f32; 3],
    seed: u64,
    light: impl Fn(Vec3) -> Vec3,
) -> (lucent_core::Exitance, bool, Vec<Vec3>) {
    let profile =
        CoreProfile::from_preset(lucent_core::presets::find("skin1").unwrap(), 1.0).unwrap();
    let core_samples: Vec<Sample> = samples(half_plane)
        .iter()
        .map(|s| Sample {
            position: Vec3::from_array(s.position),
            area: s.area,
            irradiance: Vec3::from_array(s.irradiance),
        })
        .collect();
    let cache = IrradianceCache::build(&core_samples).unwrap();
    let alpha = cache.smoothing_radius(2.0);
    let term = LocalIntegralTable::new(&profile, alpha, alpha / 1024.0)
        .unwrap()
        .local_term(profile.mean_free_path());
    let settings = QuerySettings {
        method: Method::EdgeRefined,
        ..QuerySettings::default()
    };
    let x = Vec3::from_array(position);
    let point = ShadingPoint {
        position: x,
        irradiance: Vec3::from_array(E),
    };
    let m = cache.query(&profile, &point, term, &settings).unwrap();
    if !m.refine {
        return (m, false, Vec::new());
    }
    let quadrature = LocalQuadrature::new(
        &profile,
        alpha,
        LocalQuadrature::DEFAULT_RINGS,
        LocalQuadrature::DEFAULT_PER_RING,
    );
    let (t1, t2) = Vec3::Z.any_orthonormal_pair();
    let rotation = LocalQuadrature::rotation_for_seed(seed);
    let nodes: Vec<Vec3> = (0..quadrature.len())
        .map(|n| {
            let o = quadrature.offset(n, rotation);
            x + t1 * o.x + t2 * o.y + Vec3::Z * quadrature.lift(n)
        })
        .collect();
    let at: Vec<Vec3> = nodes.iter().map(|&p| light(p)).collect();
    let local = quadrature.local_term(point.irradiance, term, &at);
    (m.with_local(local, term), true, nodes)
}

fn half_plane_light(p: Vec3) -> Vec3 {
    if p.x > 0.0 {
        Vec3::from_array(E)
    } else {
        Vec3::ZERO
    }
}

#[track_caller]
fn same(m: LucentExitance, want: lucent_core::Exitance) {
    assert_eq!(m.total, want.total.to_array(), "total");
    assert_eq!(m.local, want.local.to_array(), "local");
    assert_eq!(m.global, want.global.to_array(), "global");
    assert_eq!(
        m.local_irradiance,
        want.local_irradiance.to_array(),
        "local_irradiance"
    );
}

#[test]
fn a_uniformly_lit_patch_is_edge_aware_and_calls_nothing() {
    let (skin, cache) = scene(false);
    let refined_plan = plan(&skin, &cache, EDGE_REFINED, 2.0).unwrap();
    let edge_aware = plan(&skin, &cache, 2, 2.0).unwrap();
    for position in [[0.0, 0.0, 0.0], [0.13, -0.21, 0.0], [1.1, 0.6, 0.0]] {
        let mut lighting = Lighting::default();
        let m = refined(
            &refined_plan,
            &cache,
            &lit(position),
            [0.0, 0.0, 1.0],
            3,
            Some(irradiance),
            &mut lighting,
        )
        .unwrap();
        assert!(
            lighting.calls.is_empty(),
            "uniform irradiance is not refined"
        );
        assert_eq!(m, query(&edge_aware, &cache, &lit(position)).unwrap());
        let (want, flagged, _) = by_hand(false, position, 3, |_| unreachable!());
        assert!(!flagged);
        same(m, want);
    }
}

#[test]
fn every_other_method_ignores_the_callback() {
    let (skin, cache) = scene(true);
    for method in METHODS {
        let q = plan(&skin, &cache, method as u32, 2.0).unwrap();
        let mut lighting = Lighting::default();
        let m = refined(
            &q,
            &cache,
            &lit(NEAR_EDGE),
            [0.0, 0.0, 1.0],
            7,
            Some(irradiance),
            &mut lighting,
        )
        .unwrap();
        assert!(lighting.calls.is_empty(), "{method:?}");
        assert_eq!(m, query(&q, &cache, &lit(NEAR_EDGE)).unwrap(), "{method:?}");
    }
}

#[test]
fn a_uniform_callback_at_a_flagged_point_gives_e_times_k_exactly() {
    // The samples see an edge, the callback none: the quadrature is E(x)·K bit for bit.
    let (skin, cache) = scene(true);
    let q = plan(&skin, &cache, EDGE_REFINED, 2.0).unwrap();
    let (_, k) = alpha_and_k(&q);
    let mut lighting = Lighting::default();
    let m = refined(
        &q,
        &cache,
        &lit(NEAR_EDGE),
        [0.0, 0.0, 1.0],
        7,
        Some(irradiance),
        &mut lighting,
    )
    .unwrap();
    assert_eq!(lighting.calls.len(), 12, "3 rings of 4 nodes");
    let want: [f32; 3] = std::array::from_fn(|c| E[c] * k[c]);
    assert_eq!(m.local, want);
    assert_eq!(m.local_irradiance, E);
    for c in 0..3 {
        assert_eq!(m.total[c], m.local[c] + m.global[c]);
    }
    let (by_hand, flagged, _) = by_hand(true, NEAR_EDGE, 7, |_| Vec3::from_array(E));
    assert!(flagged);
    same(m, by_hand);
}

#[test]
fn a_half_lit_patch_near_the_edge_is_what_the_core_gives_by_hand() {
    let (skin, cache) = scene(true);
    let q = plan(&skin, &cache, EDGE_REFINED, 2.0).unwrap();
    let (alpha, k) = alpha_and_k(&q);
    let mut lighting = Lighting {
        half_plane: true,
        ..Lighting::default()
    };
    let m = refined(
        &q,
        &cache,
        &lit(NEAR_EDGE),
        [0.0, 0.0, 1.0],
        7,
        Some(irradiance),
        &mut lighting,
    )
    .unwrap();
    let (want, flagged, nodes) = by_hand(true, NEAR_EDGE, 7, half_plane_light);
    assert!(flagged, "the point 0.3 α from the edge is flagged");
    same(m, want);

    // The callback was asked at the nodes, with the normal at x and α/2 as the skip.
    let seen: Vec<[f32; 3]> = lighting.calls.iter().map(|c| c.0).collect();
    let nodes: Vec<[f32; 3]> = nodes.iter().map(|p| p.to_array()).collect();
    assert_eq!(seen, nodes);
    assert!(
        lighting
            .calls
            .iter()
            .all(|c| c.1 == [0.0, 0.0, 1.0] && c.2 == alpha / 2.0)
    );
    let dark = nodes.iter().filter(|p| !(p[0] > 0.0)).count();
    assert!(
        (1..nodes.len()).contains(&dark),
        "{dark} of {} nodes in the shadow: no test of the quadrature",
        nodes.len()
    );

    // Darker than the uniform E·K and brighter than nothing, and not edge-aware's value.
    let edge_aware = query(
        &plan(&skin, &cache, 2, 2.0).unwrap(),
        &cache,
        &lit(NEAR_EDGE),
    );
    let edge_aware = edge_aware.unwrap();
    for c in 0..3 {
        assert!(
            0.0 < m.local[c] && m.local[c] < E[c] * k[c],
            "{:?}",
            m.local
        );
        assert_eq!(m.global[c], edge_aware.global[c]);
        assert!(m.local[c] != edge_aware.local[c], "{c}: {:?}", m.local);
    }
    println!("edge-refined total at {NEAR_EDGE:?}, seed 7: {:?}", m.total);
    for c in 0..3 {
        let err = (m.total[c] - NEAR_EDGE_TOTAL[c]).abs() / NEAR_EDGE_TOTAL[c];
        assert!(err < 1e-6, "{:?} vs {NEAR_EDGE_TOTAL:?}", m.total);
    }

    // The seed turns the pattern: another seed, other nodes; the same seed, the same bytes.
    let mut again = Lighting {
        half_plane: true,
        ..Lighting::default()
    };
    let normal = [0.0, 0.0, 1.0];
    let repeat = refined(
        &q,
        &cache,
        &lit(NEAR_EDGE),
        normal,
        7,
        Some(irradiance),
        &mut again,
    );
    assert_eq!(repeat, Ok(m));
    let mut turned = Lighting {
        half_plane: true,
        ..Lighting::default()
    };
    refined(
        &q,
        &cache,
        &lit(NEAR_EDGE),
        normal,
        8,
        Some(irradiance),
        &mut turned,
    )
    .unwrap();
    assert!(turned.calls[0].0 != lighting.calls[0].0);
}

#[test]
fn the_normal_sets_the_tangent_disc() {
    // A tilted normal at x: every node lies on the plane through x orthogonal to it (lifted
    // by at most 0.13 α towards it), within α of x.
    let (skin, cache) = scene(true);
    let q = plan(&skin, &cache, EDGE_REFINED, 2.0).unwrap();
    let (alpha, _) = alpha_and_k(&q);
    let n = Vec3::new(0.6, 0.0, 0.8);
    let mut lighting = Lighting::default();
    refined(
        &q,
        &cache,
        &lit(NEAR_EDGE),
        n.to_array(),
        1,
        Some(irradiance),
        &mut lighting,
    )
    .unwrap();
    assert_eq!(lighting.calls.len(), 12);
    let x = Vec3::from_array(NEAR_EDGE);
    for (p, normal, _) in &lighting.calls {
        let d = Vec3::from_array(*p) - x;
        let height = d.dot(n);
        assert!((0.0..=0.14 * alpha).contains(&height), "{height}");
        assert!(d.length() <= alpha * 1.001, "{}", d.length());
        assert_eq!(*normal, n.to_array());
    }
}

#[test]
fn bad_normals_and_a_null_callback_are_rejected() {
    let (skin, cache) = scene(true);
    let q = plan(&skin, &cache, EDGE_REFINED, 2.0).unwrap();
    let point = lit(NEAR_EDGE);
    for normal in [
        [0.0, 0.0, 2.0],
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 0.998],
        [f32::NAN, 0.0, 1.0],
        [0.0, f32::INFINITY, 1.0],
    ] {
        let mut lighting = Lighting::default();
        let got = refined(
            &q,
            &cache,
            &point,
            normal,
            0,
            Some(irradiance),
            &mut lighting,
        );
        assert_eq!(got, Err(LUCENT_INVALID_ARGUMENT), "{normal:?}");
        assert!(
            message().starts_with("normal must be a finite unit vector (length within 0.001 of 1)"),
            "{}",
            message()
        );
        assert!(lighting.calls.is_empty());
    }
    // Within the tolerance: accepted and renormalised.
    let mut lighting = Lighting::default();
    let nearly = [0.0, 0.0, 1.0005];
    refined(
        &q,
        &cache,
        &point,
        nearly,
        0,
        Some(irradiance),
        &mut lighting,
    )
    .unwrap();
    assert!(lighting.calls.iter().all(|c| c.1 == [0.0, 0.0, 1.0]));

    let got = refined(&q, &cache, &point, [0.0, 0.0, 1.0], 0, None, &mut lighting);
    assert_eq!(got, Err(LUCENT_NULL_POINTER));
    assert_eq!(message(), "callback is NULL");

    let mut out = LucentExitance::default();
    // SAFETY: live handles and a live point; the normal is NULL (checked); `user` is unused.
    let status = unsafe {
        lucent_query_point_refined(
            q.0,
            cache.0,
            &point,
            std::ptr::null(),
            0,
            Some(irradiance),
            std::ptr::null_mut(),
            &mut out,
        )
    };
    assert_eq!(status, LUCENT_NULL_POINTER);
    assert_eq!(message(), "normal is NULL");
}

#[test]
fn a_failing_or_lying_callback_abandons_the_query() {
    let (skin, cache) = scene(true);
    let q = plan(&skin, &cache, EDGE_REFINED, 2.0).unwrap();
    let point = lit(NEAR_EDGE);
    let normal = [0.0, 0.0, 1.0];

    let mut lighting = Lighting {
        fail_with: 7,
        ..Lighting::default()
    };
    let got = refined(
        &q,
        &cache,
        &point,
        normal,
        0,
        Some(irradiance),
        &mut lighting,
    );
    assert_eq!(got, Err(LUCENT_CALLBACK_FAILED));
    assert!(
        message().starts_with("the irradiance callback returned 7 at node 0 (position ["),
        "{}",
        message()
    );
    assert_eq!(lighting.calls.len(), 1, "no call after a failure");

    for (node, value, shows) in [
        (0, [f32::NAN, 1.0, 1.0], "[NaN, 1.0, 1.0] at node 0"),
        (5, [1.0, -0.5, 1.0], "[1.0, -0.5, 1.0] at node 5"),
        (11, [1.0, 1.0, f32::INFINITY], "[1.0, 1.0, inf] at node 11"),
    ] {
        let mut lighting = Lighting {
            bad_value: Some((node, value)),
            ..Lighting::default()
        };
        let got = refined(
            &q,
            &cache,
            &point,
            normal,
            0,
            Some(irradiance),
            &mut lighting,
        );
        assert_eq!(got, Err(LUCENT_INVALID_ARGUMENT));
        assert!(
            message().starts_with(&format!("the irradiance callback gave {shows}")),
            "{}",
            message()
        );
        assert!(
            message().ends_with("irradiance must be finite and non-negative"),
            "{}",
            message()
        );
    }

    // A callback that reports success without writing is caught too (the slot starts NaN).
    let got = refined(
        &q,
        &cache,
        &point,
        normal,
        0,
        Some(silent),
        &mut Lighting::default(),
    );
    assert_eq!(got, Err(LUCENT_INVALID_ARGUMENT));
    assert!(
        message().contains("[NaN, NaN, NaN] at node 0"),
        "{}",
        message()
    );
}

#[test]
fn a_panicking_callback_is_caught_at_the_boundary() {
    let (skin, cache) = scene(true);
    let q = plan(&skin, &cache, EDGE_REFINED, 2.0).unwrap();
    let mut lighting = Lighting {
        panic: true,
        ..Lighting::default()
    };
    let normal = [0.0, 0.0, 1.0];
    let point = lit(NEAR_EDGE);
    let got = refined(
        &q,
        &cache,
        &point,
        normal,
        0,
        Some(irradiance),
        &mut lighting,
    );
    assert_eq!(got, Err(LUCENT_PANIC));
    assert_eq!(
        message(),
        "internal error: the renderer's callback panicked"
    );
    assert_eq!(lighting.calls.len(), 1);
    // The handles are untouched: the next query succeeds.
    let mut lighting = Lighting::default();
    refined(
        &q,
        &cache,
        &point,
        normal,
        0,
        Some(irradiance),
        &mut lighting,
    )
    .unwrap();
    assert_eq!(message(), "");
}

#[test]
fn threads_share_one_plan_and_cache_with_their_own_callbacks() {
    // Points along y next to the edge, each with its own seed, serially and on 4 threads.
    let (skin, cache) = scene(true);
    let q = plan(&skin, &cache, EDGE_REFINED, 2.0).unwrap();
    let points: Vec<(LucentShadingPoint, u64)> = (0..32)
        .map(|i| (lit([0.3, i as f32 * 0.25 - 4.0, 0.0]), i))
        .collect();
    // SAFETY: both handles are live until the end of this test, after the threads joined.
    let (shared_plan, shared_cache) = unsafe { (&*q.0, &*cache.0) };
    let one = |(point, seed): &(LucentShadingPoint, u64)| {
        let mut lighting = Lighting {
            half_plane: true,
            ..Lighting::default()
        };
        let mut out = LucentExitance::default();
        // SAFETY: live handles (borrowed for the test), a live point, 3 readable floats, the
        // test callback with this thread's own `Lighting`, and a writable result.
        let status = unsafe {
            lucent_query_point_refined(
                shared_plan,
                shared_cache,
                point,
                [0.0f32, 0.0, 1.0].as_ptr(),
                *seed,
                Some(irradiance),
                std::ptr::from_mut(&mut lighting).cast(),
                &mut out,
            )
        };
        assert_eq!(status, LUCENT_OK);
        assert_eq!(lighting.calls.len(), 12);
        out
    };
    let serial: Vec<LucentExitance> = points.iter().map(one).collect();
    let parallel: Vec<LucentExitance> = std::thread::scope(|scope| {
        let one = &one;
        let quarters: Vec<_> = points
            .chunks(8)
            .map(|chunk| scope.spawn(move || chunk.iter().map(one).collect::<Vec<_>>()))
            .collect();
        quarters
            .into_iter()
            .flat_map(|h| h.join().unwrap())
            .collect()
    });
    assert_eq!(serial, parallel);
}
