//! Every status code: NULL for each pointer argument, out-of-range numbers, unknown and
//! unsupported names, misaligned pointers. Each failure names its argument.

use std::ffi::{CString, c_char};
use std::ptr::{null, null_mut};

use lucent_ffi::*;

use crate::common::{build, coefficients, message, options, patch, plan, plan_with, preset, query};

use LucentStatus::{
    LUCENT_INVALID_ARGUMENT, LUCENT_NULL_POINTER, LUCENT_UNKNOWN_PRESET, LUCENT_UNSUPPORTED,
};

/// Asserts a status and the message that came with it.
#[track_caller]
fn fails(status: LucentStatus, want: LucentStatus, says: &str) {
    assert_eq!(status, want, "{}", message());
    assert!(
        message().contains(says),
        "\"{}\" does not contain \"{says}\"",
        message()
    );
}

type Callback = unsafe extern "C-unwind" fn(
    *mut std::ffi::c_void,
    *const f32,
    *const f32,
    f32,
    *mut f32,
) -> std::ffi::c_int;

/// An irradiance callback for calls that fail before any node is evaluated.
unsafe extern "C-unwind" fn never_called(
    _: *mut std::ffi::c_void,
    _: *const f32,
    _: *const f32,
    _: f32,
    _: *mut f32,
) -> std::ffi::c_int {
    unreachable!("a call with a NULL argument evaluates nothing")
}

#[test]
fn every_pointer_argument_is_checked_for_null() {
    let skin = preset("skin1", 1.0).unwrap();
    let cache = build(&patch(1.0, 0.25, [1.0; 3])).unwrap();
    let q = plan(&skin, &cache, 2, 2.0).unwrap();
    let point = LucentShadingPoint::default();
    let name = CString::new("marble").unwrap();
    let c = LucentCoefficients {
        sigma_a: [0.1; 3],
        sigma_s_prime: [1.0; 3],
        eta: 1.3,
    };
    let o = options(2, 2.0);
    let mut profile_out: *mut LucentProfile = null_mut();
    let mut cache_out: *mut LucentCache = null_mut();
    let mut query_out: *mut LucentQuery = null_mut();
    let mut floats = [0.0f32; 3];
    let mut size = 0usize;
    let mut alpha = 0.0f32;
    let mut method = LucentMethod::LUCENT_METHOD_EDGE_AWARE;
    let mut m = LucentExitance::default();
    let mut ms = [LucentExitance::default(); 1];
    let f = floats.as_mut_ptr();
    let e = [1.0f32; 3].as_ptr();
    let one = LucentSample::default();
    let (p, k, qp) = (skin.0.cast_const(), cache.0.cast_const(), q.0.cast_const());
    // Each call, then its message, which names the NULL argument.
    let check = |status: LucentStatus, says: &str| fails(status, LUCENT_NULL_POINTER, says);
    // SAFETY: every pointer is NULL or valid for what the function reads or writes.
    unsafe {
        check(
            lucent_profile_from_preset(null(), 1.0, &mut profile_out),
            "name is NULL",
        );
        check(
            lucent_profile_from_preset(name.as_ptr(), 1.0, null_mut()),
            "out is NULL",
        );
        check(
            lucent_profile_from_coefficients(null(), &mut profile_out),
            "coefficients is NULL",
        );
        check(
            lucent_profile_from_coefficients(&c, null_mut()),
            "out is NULL",
        );
        check(
            lucent_profile_total_reflectance(null(), f),
            "profile is NULL",
        );
        check(
            lucent_profile_total_reflectance(p, null_mut()),
            "out is NULL",
        );
        check(lucent_profile_mean_free_path(null(), f), "profile is NULL");
        check(lucent_profile_mean_free_path(p, null_mut()), "out is NULL");
        check(
            lucent_profile_local_integral(null(), 1.0, f),
            "profile is NULL",
        );
        check(
            lucent_profile_local_integral(p, 1.0, null_mut()),
            "out is NULL",
        );
        check(
            lucent_profile_radiance(null(), e, 1.0, f),
            "profile is NULL",
        );
        check(
            lucent_profile_radiance(p, null(), 1.0, f),
            "exitance is NULL",
        );
        check(
            lucent_profile_radiance(p, e, 1.0, null_mut()),
            "out is NULL",
        );
        check(
            lucent_cache_build(null(), 1, &mut cache_out),
            "samples is NULL",
        );
        check(lucent_cache_build(&one, 1, null_mut()), "out is NULL");
        check(lucent_cache_len(null(), &mut size), "cache is NULL");
        check(lucent_cache_len(k, null_mut()), "out is NULL");
        check(
            lucent_cache_smoothing_radius(null(), 1.0, &mut alpha),
            "cache is NULL",
        );
        check(
            lucent_cache_smoothing_radius(k, 1.0, null_mut()),
            "out is NULL",
        );
        check(lucent_method_from_name(null(), &mut method), "name is NULL");
        check(
            lucent_method_from_name(name.as_ptr(), null_mut()),
            "out is NULL",
        );
        check(lucent_query_options_init(null_mut()), "out is NULL");
        check(
            lucent_query_new(null(), k, &o, &mut query_out),
            "profile is NULL",
        );
        check(
            lucent_query_new(p, null(), &o, &mut query_out),
            "cache is NULL",
        );
        check(
            lucent_query_new(p, k, null(), &mut query_out),
            "options is NULL",
        );
        check(lucent_query_new(p, k, &o, null_mut()), "out is NULL");
        check(
            lucent_query_smoothing_radius(null(), &mut alpha),
            "query is NULL",
        );
        check(lucent_query_smoothing_radius(qp, null_mut()), "out is NULL");
        check(lucent_query_local_integral(null(), f), "query is NULL");
        check(lucent_query_local_integral(qp, null_mut()), "out is NULL");
        check(
            lucent_query_point(null(), k, &point, &mut m),
            "query is NULL",
        );
        check(
            lucent_query_point(qp, null(), &point, &mut m),
            "cache is NULL",
        );
        check(lucent_query_point(qp, k, null(), &mut m), "point is NULL");
        check(lucent_query_point(qp, k, &point, null_mut()), "out is NULL");
        let out = ms.as_mut_ptr();
        check(
            lucent_query_points(null(), k, &point, 1, out),
            "query is NULL",
        );
        check(
            lucent_query_points(qp, null(), &point, 1, out),
            "cache is NULL",
        );
        check(lucent_query_points(qp, k, null(), 1, out), "points is NULL");
        check(
            lucent_query_points(qp, k, &point, 1, null_mut()),
            "out is NULL",
        );
        let (z, cb) = ([0.0f32, 0.0, 1.0].as_ptr(), Some(never_called as Callback));
        let refined = |q, k, point, normal, cb, out| {
            lucent_query_point_refined(q, k, point, normal, 0, cb, null_mut(), out)
        };
        check(refined(null(), k, &point, z, cb, &mut m), "query is NULL");
        check(refined(qp, null(), &point, z, cb, &mut m), "cache is NULL");
        check(refined(qp, k, null(), z, cb, &mut m), "point is NULL");
        check(refined(qp, k, &point, null(), cb, &mut m), "normal is NULL");
        check(refined(qp, k, &point, z, None, &mut m), "callback is NULL");
        check(refined(qp, k, &point, z, cb, null_mut()), "out is NULL");
    }
    assert!(profile_out.is_null() && cache_out.is_null() && query_out.is_null());
    // Zero-length batches accept NULL arrays.
    // SAFETY: count 0 with NULL arrays is allowed.
    let status = unsafe { lucent_query_points(qp, k, null(), 0, null_mut()) };
    assert_eq!(status, LucentStatus::LUCENT_OK);
}

#[test]
fn out_of_range_numbers_name_the_argument() {
    assert_eq!(preset("marble", 0.0).err(), Some(LUCENT_INVALID_ARGUMENT));
    assert_eq!(message(), "mm_per_unit must be positive, got 0");
    assert_eq!(
        preset("marble", f32::NAN).err(),
        Some(LUCENT_INVALID_ARGUMENT)
    );
    assert_eq!(message(), "mm_per_unit must be a finite number, got NaN");
    let good = LucentCoefficients {
        sigma_a: [0.1; 3],
        sigma_s_prime: [1.0; 3],
        eta: 1.3,
    };
    for (c, says) in [
        (
            LucentCoefficients { eta: 0.9, ..good },
            "eta (relative index of refraction) must be at least 1",
        ),
        (LucentCoefficients { eta: 3.5, ..good }, "must be at most 3"),
        (
            LucentCoefficients {
                sigma_a: [0.1, f32::NAN, 0.1],
                ..good
            },
            "must be a finite number",
        ),
        (
            LucentCoefficients {
                sigma_s_prime: [1.0, 1.0, 0.0],
                ..good
            },
            "must be positive",
        ),
    ] {
        assert_eq!(
            coefficients(&c).err(),
            Some(LUCENT_INVALID_ARGUMENT),
            "{c:?}"
        );
        assert!(message().contains(says), "{}", message());
    }

    let skin = preset("skin1", 1.0).unwrap();
    let cache = build(&patch(1.0, 0.25, [1.0; 3])).unwrap();
    let (p, k) = (skin.0.cast_const(), cache.0.cast_const());
    let mut out = [0.0f32; 3];
    let mut alpha = 0.0;
    // SAFETY: live handles and writable outputs throughout.
    unsafe {
        fails(
            lucent_profile_radiance(p, [1.0f32; 3].as_ptr(), 1.5, out.as_mut_ptr()),
            LUCENT_INVALID_ARGUMENT,
            "cos_out must lie in [0, 1], got 1.5",
        );
        fails(
            lucent_profile_radiance(p, [1.0, f32::NAN, 1.0].as_ptr(), 0.5, out.as_mut_ptr()),
            LUCENT_INVALID_ARGUMENT,
            "exitance must be finite",
        );
        fails(
            lucent_profile_local_integral(p, 0.0, out.as_mut_ptr()),
            LUCENT_INVALID_ARGUMENT,
            "smoothing radius must be positive, got 0",
        );
        fails(
            lucent_cache_smoothing_radius(k, -1.0, &mut alpha),
            LUCENT_INVALID_ARGUMENT,
            "factor must be finite and non-negative, got -1",
        );
    }
    for (o, says) in [
        (
            options(2, f32::INFINITY),
            "smoothing_factor must be finite and non-negative, got inf",
        ),
        (
            options(2, 0.0),
            "the edge-aware method needs a positive smoothing radius",
        ),
        (options(9, 2.0), "method 9 is not a LucentMethod (0 to 4)"),
        (
            LucentQueryOptions {
                epsilon: -0.1,
                ..options(2, 2.0)
            },
            "epsilon must be finite and non-negative, got -0.1",
        ),
        (
            LucentQueryOptions {
                cull_tolerance: f32::NAN,
                ..options(0, 2.0)
            },
            "cull_tolerance must be finite",
        ),
    ] {
        assert_eq!(
            plan_with(&skin, &cache, &o).err(),
            Some(LUCENT_INVALID_ARGUMENT)
        );
        assert!(message().contains(says), "{} vs {says}", message());
    }

    let q = plan(&skin, &cache, 2, 2.0).unwrap();
    let point = LucentShadingPoint {
        position: [0.0; 3],
        irradiance: [1.0; 3],
    };
    for (bad_point, says) in [
        (
            LucentShadingPoint {
                position: [f32::INFINITY, 0.0, 0.0],
                ..point
            },
            "shading position is not finite",
        ),
        (
            LucentShadingPoint {
                irradiance: [1.0, f32::NAN, 1.0],
                ..point
            },
            "irradiance at the shading point must be finite and non-negative",
        ),
    ] {
        assert_eq!(
            query(&q, &cache, &bad_point).err(),
            Some(LUCENT_INVALID_ARGUMENT)
        );
        assert_eq!(message(), says);
    }
}

#[test]
fn unknown_names_and_unsupported_calls_have_their_own_statuses() {
    assert_eq!(preset("granite", 1.0).err(), Some(LUCENT_UNKNOWN_PRESET));
    assert_eq!(message(), "unknown material preset \"granite\"");

    let not_utf8 = [b'm' as c_char, 0xff_u8 as c_char, 0];
    let mut out = null_mut();
    // SAFETY: a NUL-terminated (if not UTF-8) string and a writable out pointer.
    let status = unsafe { lucent_profile_from_preset(not_utf8.as_ptr(), 1.0, &mut out) };
    fails(status, LUCENT_INVALID_ARGUMENT, "name is not UTF-8");
    assert!(out.is_null());

    let mut method = LucentMethod::LUCENT_METHOD_HIERARCHICAL;
    let name = CString::new("Edge-Aware").unwrap();
    // SAFETY: a NUL-terminated name and a writable LucentMethod.
    let status = unsafe { lucent_method_from_name(name.as_ptr(), &mut method) };
    fails(
        status,
        LUCENT_INVALID_ARGUMENT,
        "unknown method \"Edge-Aware\"",
    );
    assert_eq!(
        method,
        LucentMethod::LUCENT_METHOD_HIERARCHICAL,
        "failures write nothing"
    );
    let name = CString::new("edge-refined").unwrap();
    // SAFETY: a NUL-terminated name and a writable LucentMethod.
    let status = unsafe { lucent_method_from_name(name.as_ptr(), &mut method) };
    assert_eq!(status, LucentStatus::LUCENT_OK);
    assert_eq!(method, LucentMethod::LUCENT_METHOD_EDGE_REFINED);

    // An edge-refined plan is made, but only the call with a callback queries it.
    let skin = preset("skin1", 1.0).unwrap();
    let cache = build(&patch(1.0, 0.25, [1.0; 3])).unwrap();
    let q = plan(&skin, &cache, method as u32, 2.0).unwrap();
    let point = LucentShadingPoint {
        position: [0.0; 3],
        irradiance: [1.0; 3],
    };
    assert_eq!(query(&q, &cache, &point).err(), Some(LUCENT_UNSUPPORTED));
    assert!(
        message().contains("query it with lucent_query_point_refined"),
        "{}",
        message()
    );
    let mut out = [LucentExitance::default(); 2];
    let points = [point; 2];
    // SAFETY: live handles, two readable points and two writable results.
    let status = unsafe { lucent_query_points(q.0, cache.0, points.as_ptr(), 2, out.as_mut_ptr()) };
    fails(status, LUCENT_UNSUPPORTED, "point 0: an edge-refined plan");
    assert_eq!(
        out,
        [LucentExitance::default(); 2],
        "failures write nothing"
    );
}

#[test]
fn misaligned_pointers_are_rejected_not_dereferenced() {
    let skin = preset("skin1", 1.0).unwrap();
    // Room for three floats one byte into a float-aligned buffer.
    let mut bytes = [0.0f32; 4];
    let misaligned = bytes
        .as_mut_ptr()
        .cast::<u8>()
        .wrapping_add(1)
        .cast::<f32>();
    // SAFETY: the function checks alignment before it writes.
    let status = unsafe { lucent_profile_total_reflectance(skin.0, misaligned) };
    fails(
        status,
        LUCENT_INVALID_ARGUMENT,
        "out is not aligned to 4 bytes",
    );
    assert_eq!(bytes, [0.0; 4]);
}
