//! Caches: building, size, the smoothing radius, bad samples.

use std::ptr;

use lucent_ffi::*;

use crate::common::{build, message, patch};

fn len(cache: &crate::common::Cache) -> usize {
    let mut n = usize::MAX;
    // SAFETY: a live cache and a writable size_t.
    let status = unsafe { lucent_cache_len(cache.0, &mut n) };
    assert_eq!(status, LucentStatus::LUCENT_OK);
    n
}

#[test]
fn a_cache_holds_every_sample_and_scales_alpha_by_the_spacing() {
    let samples = patch(2.0, 0.25, [1.0; 3]);
    assert_eq!(samples.len(), 256);
    let cache = build(&samples).unwrap();
    assert_eq!(len(&cache), 256);
    // Ā = 0.25², so α = k·0.25.
    for k in [0.0, 1.0, 2.0, 3.5] {
        let mut alpha = f32::NAN;
        // SAFETY: a live cache and a writable float.
        let status = unsafe { lucent_cache_smoothing_radius(cache.0, k, &mut alpha) };
        assert_eq!(status, LucentStatus::LUCENT_OK);
        assert!((alpha - k * 0.25).abs() < 1e-6, "k {k}: α {alpha}");
    }
}

#[test]
fn an_empty_cache_may_come_from_a_null_array() {
    let mut out = ptr::null_mut();
    // SAFETY: count 0 with a NULL array is allowed; `out` is writable.
    let status = unsafe { lucent_cache_build(ptr::null(), 0, &mut out) };
    assert_eq!(status, LucentStatus::LUCENT_OK);
    let cache = crate::common::Cache(out);
    assert_eq!(len(&cache), 0);
}

#[test]
fn a_bad_sample_is_named_and_nothing_is_built() {
    let good = patch(1.0, 0.5, [1.0; 3]);
    for (field, sample, says) in [
        (
            "position",
            LucentSample {
                position: [0.0, f32::NAN, 0.0],
                ..good[0]
            },
            "sample 2: position is not finite",
        ),
        (
            "area",
            LucentSample {
                area: -1.0,
                ..good[0]
            },
            "sample 2: area must be finite and non-negative, got -1",
        ),
        (
            "irradiance",
            LucentSample {
                irradiance: [1.0, 1.0, f32::INFINITY],
                ..good[0]
            },
            "sample 2: irradiance must be finite and non-negative, got inf",
        ),
    ] {
        let mut samples = good.clone();
        samples[2] = sample;
        assert_eq!(
            build(&samples).err(),
            Some(LucentStatus::LUCENT_INVALID_ARGUMENT),
            "{field}"
        );
        assert_eq!(message(), says);
    }
}

#[test]
fn totals_beyond_single_precision_are_refused() {
    let huge = LucentSample {
        area: 3e38,
        ..LucentSample::default()
    };
    assert_eq!(
        build(&[huge, huge]).err(),
        Some(LucentStatus::LUCENT_INVALID_ARGUMENT)
    );
    assert!(
        message().starts_with("the samples' total area"),
        "{}",
        message()
    );
}

#[test]
fn a_count_beyond_the_address_space_is_refused_before_any_read() {
    let one = LucentSample::default();
    let mut out = ptr::null_mut();
    // SAFETY: the count is checked before the array is read; `out` is writable.
    let status = unsafe { lucent_cache_build(&one, usize::MAX / 8, &mut out) };
    assert_eq!(status, LucentStatus::LUCENT_INVALID_ARGUMENT);
    assert!(
        message().contains("exceeds the address space"),
        "{}",
        message()
    );
    assert!(out.is_null());
}

#[test]
fn the_handles_are_shareable_across_threads() {
    fn shareable<T: Send + Sync>() {}
    shareable::<LucentCache>();
    shareable::<LucentProfile>();
    shareable::<LucentQuery>();
}
