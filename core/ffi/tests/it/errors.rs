//! Every status code: NULL for each pointer argument, out-of-range numbers, unknown and
//! unsupported names, misaligned pointers. Each failure names its argument.

use std::ffi::{CString, c_char};
use std::ptr::{null, null_mut};

use lucent_ffi::*;

use crate::common::{build, coefficients, message, patch, preset, query, settings};

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

#[test]
fn every_pointer_argument_is_checked_for_null() {
    let skin = preset("skin1", 1.0).unwrap();
    let cache = build(&patch(1.0, 0.25, [1.0; 3])).unwrap();
    let s = settings(&skin, &cache, 2, 2.0).unwrap();
    let point = LucentShadingPoint::default();
    let name = CString::new("marble").unwrap();
    let c = LucentCoefficients {
        sigma_a: [0.1; 3],
        sigma_s_prime: [1.0; 3],
        eta: 1.3,
    };
    let mut profile_out: *mut LucentProfile = null_mut();
    let mut cache_out: *mut LucentCache = null_mut();
    let mut floats = [0.0f32; 3];
    let mut size = 0usize;
    let mut alpha = 0.0f32;
    let mut method = LucentMethod::LUCENT_METHOD_EDGE_AWARE;
    let mut qs = LucentQuerySettings::default();
    let mut m = LucentExitance::default();
    let mut ms = [LucentExitance::default(); 1];
    let f = floats.as_mut_ptr();
    let one = LucentSample::default();
    let (p, k) = (skin.0.cast_const(), cache.0.cast_const());
    // SAFETY: every pointer is NULL or valid for what the function reads or writes.
    let cases: Vec<(LucentStatus, &str)> = unsafe {
        vec![
            (
                lucent_profile_from_preset(null(), 1.0, &mut profile_out),
                "name is NULL",
            ),
            (
                lucent_profile_from_preset(name.as_ptr(), 1.0, null_mut()),
                "out is NULL",
            ),
            (
                lucent_profile_from_coefficients(null(), &mut profile_out),
                "coefficients is NULL",
            ),
            (
                lucent_profile_from_coefficients(&c, null_mut()),
                "out is NULL",
            ),
            (
                lucent_profile_total_reflectance(null(), f),
                "profile is NULL",
            ),
            (
                lucent_profile_total_reflectance(p, null_mut()),
                "out is NULL",
            ),
            (lucent_profile_mean_free_path(null(), f), "profile is NULL"),
            (lucent_profile_mean_free_path(p, null_mut()), "out is NULL"),
            (
                lucent_profile_local_integral(null(), 1.0, f),
                "profile is NULL",
            ),
            (
                lucent_profile_local_integral(p, 1.0, null_mut()),
                "out is NULL",
            ),
            (
                lucent_profile_radiance(null(), [1.0f32; 3].as_ptr(), 1.0, f),
                "profile is NULL",
            ),
            (
                lucent_profile_radiance(p, null(), 1.0, f),
                "exitance is NULL",
            ),
            (
                lucent_profile_radiance(p, [1.0f32; 3].as_ptr(), 1.0, null_mut()),
                "out is NULL",
            ),
            (
                lucent_cache_build(null(), 1, &mut cache_out),
                "samples is NULL",
            ),
            (lucent_cache_build(&one, 1, null_mut()), "out is NULL"),
            (lucent_cache_len(null(), &mut size), "cache is NULL"),
            (lucent_cache_len(k, null_mut()), "out is NULL"),
            (
                lucent_cache_smoothing_radius(null(), 1.0, &mut alpha),
                "cache is NULL",
            ),
            (
                lucent_cache_smoothing_radius(k, 1.0, null_mut()),
                "out is NULL",
            ),
            (lucent_method_from_name(null(), &mut method), "name is NULL"),
            (
                lucent_method_from_name(name.as_ptr(), null_mut()),
                "out is NULL",
            ),
            (
                lucent_query_settings_init(null(), k, 2, 2.0, &mut qs),
                "profile is NULL",
            ),
            (
                lucent_query_settings_init(p, null(), 2, 2.0, &mut qs),
                "cache is NULL",
            ),
            (
                lucent_query_settings_init(p, k, 2, 2.0, null_mut()),
                "out is NULL",
            ),
            (
                lucent_query(null(), k, &s, &point, &mut m),
                "profile is NULL",
            ),
            (lucent_query(p, null(), &s, &point, &mut m), "cache is NULL"),
            (
                lucent_query(p, k, null(), &point, &mut m),
                "settings is NULL",
            ),
            (lucent_query(p, k, &s, null(), &mut m), "point is NULL"),
            (lucent_query(p, k, &s, &point, null_mut()), "out is NULL"),
            (
                lucent_query_many(null(), k, &s, &point, 1, ms.as_mut_ptr()),
                "profile is NULL",
            ),
            (
                lucent_query_many(p, null(), &s, &point, 1, ms.as_mut_ptr()),
                "cache is NULL",
            ),
            (
                lucent_query_many(p, k, null(), &point, 1, ms.as_mut_ptr()),
                "settings is NULL",
            ),
            (
                lucent_query_many(p, k, &s, null(), 1, ms.as_mut_ptr()),
                "points is NULL",
            ),
            (
                lucent_query_many(p, k, &s, &point, 1, null_mut()),
                "out is NULL",
            ),
        ]
    };
    // Each status was recorded right after its call, but the message is per call: check the
    // statuses here and each message by calling again below.
    for (i, (status, says)) in cases.iter().enumerate() {
        assert_eq!(*status, LUCENT_NULL_POINTER, "case {i}: {says}");
    }
    // The messages, one call at a time.
    // SAFETY: as above.
    unsafe {
        fails(
            lucent_query_many(p, k, &s, null(), 1, ms.as_mut_ptr()),
            LUCENT_NULL_POINTER,
            "points is NULL",
        );
        fails(
            lucent_query(p, k, &s, null(), &mut m),
            LUCENT_NULL_POINTER,
            "point is NULL",
        );
        fails(
            lucent_profile_radiance(p, null(), 1.0, f),
            LUCENT_NULL_POINTER,
            "exitance is NULL",
        );
        fails(
            lucent_cache_len(null(), &mut size),
            LUCENT_NULL_POINTER,
            "cache is NULL",
        );
    }
    assert!(profile_out.is_null() && cache_out.is_null());
    // Zero-length batches accept NULL arrays.
    // SAFETY: count 0 with NULL arrays is allowed.
    let status = unsafe { lucent_query_many(p, k, &s, null(), 0, null_mut()) };
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
    let mut qs = LucentQuerySettings::default();
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
        fails(
            lucent_query_settings_init(p, k, 2, f32::INFINITY, &mut qs),
            LUCENT_INVALID_ARGUMENT,
            "smoothing_factor must be finite and non-negative, got inf",
        );
        fails(
            lucent_query_settings_init(p, k, 2, 0.0, &mut qs),
            LUCENT_INVALID_ARGUMENT,
            "the edge-aware method needs a positive smoothing radius",
        );
        fails(
            lucent_query_settings_init(p, k, 9, 2.0, &mut qs),
            LUCENT_INVALID_ARGUMENT,
            "method 9 is not a LucentMethod (0 to 3)",
        );
    }
    assert_eq!(
        qs,
        LucentQuerySettings::default(),
        "failures write no settings"
    );

    let s = settings(&skin, &cache, 2, 2.0).unwrap();
    let point = LucentShadingPoint {
        position: [0.0; 3],
        irradiance: [1.0; 3],
    };
    for (bad_settings, bad_point, says) in [
        (
            LucentQuerySettings { epsilon: -0.1, ..s },
            point,
            "epsilon must be finite and non-negative, got -0.1",
        ),
        (
            LucentQuerySettings {
                cull_tolerance: f32::NAN,
                ..s
            },
            point,
            "cull_tolerance must be finite",
        ),
        (
            LucentQuerySettings {
                local_integral: [0.1, -0.1, 0.1],
                ..s
            },
            point,
            "local integral K must be finite and non-negative",
        ),
        (
            LucentQuerySettings { method: 77, ..s },
            point,
            "method 77 is not a LucentMethod",
        ),
        (
            s,
            LucentShadingPoint {
                position: [f32::INFINITY, 0.0, 0.0],
                ..point
            },
            "shading position is not finite",
        ),
    ] {
        assert_eq!(
            query(&skin, &cache, &bad_settings, &bad_point).err(),
            Some(LUCENT_INVALID_ARGUMENT)
        );
        assert!(message().contains(says), "{} vs {says}", message());
    }
}

#[test]
fn unknown_and_unsupported_names_have_their_own_statuses() {
    assert_eq!(preset("granite", 1.0).err(), Some(LUCENT_UNKNOWN_PRESET));
    assert_eq!(message(), "unknown material preset \"granite\"");

    let not_utf8 = [b'm' as c_char, 0xff_u8 as c_char, 0];
    let mut out = null_mut();
    // SAFETY: a NUL-terminated (if not UTF-8) string and a writable out pointer.
    let status = unsafe { lucent_profile_from_preset(not_utf8.as_ptr(), 1.0, &mut out) };
    fails(status, LUCENT_INVALID_ARGUMENT, "name is not UTF-8");
    assert!(out.is_null());

    let mut method = LucentMethod::LUCENT_METHOD_HIERARCHICAL;
    for (name, want, says) in [
        (
            "edge-refined",
            LUCENT_UNSUPPORTED,
            "edge-refined method needs the caller's irradiance",
        ),
        (
            "Edge-Aware",
            LUCENT_INVALID_ARGUMENT,
            "unknown method \"Edge-Aware\"",
        ),
    ] {
        let name = CString::new(name).unwrap();
        // SAFETY: a NUL-terminated name and a writable LucentMethod.
        let status = unsafe { lucent_method_from_name(name.as_ptr(), &mut method) };
        fails(status, want, says);
    }
    assert_eq!(
        method,
        LucentMethod::LUCENT_METHOD_HIERARCHICAL,
        "failures write nothing"
    );

    // The edge-refined value itself, in the settings or to the initialiser.
    let skin = preset("skin1", 1.0).unwrap();
    let cache = build(&patch(1.0, 0.25, [1.0; 3])).unwrap();
    assert_eq!(settings(&skin, &cache, 4, 2.0), Err(LUCENT_UNSUPPORTED));
    let s = LucentQuerySettings {
        method: 4,
        ..settings(&skin, &cache, 2, 2.0).unwrap()
    };
    let point = LucentShadingPoint::default();
    assert_eq!(
        query(&skin, &cache, &s, &point).err(),
        Some(LUCENT_UNSUPPORTED)
    );
    assert!(message().contains("use edge-aware"), "{}", message());
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
