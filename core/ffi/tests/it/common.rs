//! Shared helpers: owned handles that free themselves, sample patches, the last message.

use std::ffi::{CStr, CString};
use std::ptr;

use lucent_ffi::*;

/// This thread's last error message, copied.
pub fn message() -> String {
    // SAFETY: the library returns a NUL-terminated string that stays valid until this thread's
    // next `lucent_*` call; it is copied at once.
    unsafe { CStr::from_ptr(lucent_last_error_message()) }
        .to_str()
        .unwrap()
        .to_owned()
}

/// A profile handle freed on drop.
pub struct Profile(pub *mut LucentProfile);

impl Drop for Profile {
    fn drop(&mut self) {
        // SAFETY: the handle came from the library and is freed exactly once, here.
        unsafe { lucent_profile_free(self.0) }
    }
}

/// A cache handle freed on drop.
pub struct Cache(pub *mut LucentCache);

impl Drop for Cache {
    fn drop(&mut self) {
        // SAFETY: the handle came from the library and is freed exactly once, here.
        unsafe { lucent_cache_free(self.0) }
    }
}

/// The profile of a measured material, or the failing status.
pub fn preset(name: &str, mm_per_unit: f32) -> Result<Profile, LucentStatus> {
    let name = CString::new(name).unwrap();
    let mut out = ptr::null_mut();
    // SAFETY: a NUL-terminated name and a writable out pointer.
    let status = unsafe { lucent_profile_from_preset(name.as_ptr(), mm_per_unit, &mut out) };
    if status == LucentStatus::LUCENT_OK {
        assert!(!out.is_null());
        Ok(Profile(out))
    } else {
        assert!(out.is_null(), "a failed creation leaves NULL in *out");
        Err(status)
    }
}

/// A profile from coefficients, or the failing status.
pub fn coefficients(c: &LucentCoefficients) -> Result<Profile, LucentStatus> {
    let mut out = ptr::null_mut();
    // SAFETY: a live struct and a writable out pointer.
    let status = unsafe { lucent_profile_from_coefficients(c, &mut out) };
    if status == LucentStatus::LUCENT_OK {
        assert!(!out.is_null());
        Ok(Profile(out))
    } else {
        assert!(out.is_null(), "a failed creation leaves NULL in *out");
        Err(status)
    }
}

/// A cache from samples, or the failing status.
pub fn build(samples: &[LucentSample]) -> Result<Cache, LucentStatus> {
    let mut out = ptr::null_mut();
    // SAFETY: `samples.len()` readable samples and a writable out pointer.
    let status = unsafe { lucent_cache_build(samples.as_ptr(), samples.len(), &mut out) };
    if status == LucentStatus::LUCENT_OK {
        assert!(!out.is_null());
        Ok(Cache(out))
    } else {
        assert!(out.is_null(), "a failed build leaves NULL in *out");
        Err(status)
    }
}

/// A square grid of spacing `h` over [−half, half]² in the plane z = 0, all with irradiance
/// `e`, each sample standing for h² of area.
pub fn patch(half: f32, h: f32, e: [f32; 3]) -> Vec<LucentSample> {
    let n = (2.0 * half / h).round() as usize;
    let mut samples = Vec::with_capacity(n * n);
    for i in 0..n {
        for j in 0..n {
            samples.push(LucentSample {
                position: [
                    -half + (i as f32 + 0.5) * h,
                    -half + (j as f32 + 0.5) * h,
                    0.0,
                ],
                area: h * h,
                irradiance: e,
            });
        }
    }
    samples
}

/// A query plan freed on drop.
pub struct Query(pub *mut LucentQuery);

impl Drop for Query {
    fn drop(&mut self) {
        // SAFETY: the handle came from the library and is freed exactly once, here.
        unsafe { lucent_query_free(self.0) }
    }
}

/// The default options with another method and smoothing factor.
pub fn options(method: u32, smoothing_factor: f32) -> LucentQueryOptions {
    let mut out = LucentQueryOptions::default();
    // SAFETY: a writable struct.
    let status = unsafe { lucent_query_options_init(&mut out) };
    assert_eq!(status, LucentStatus::LUCENT_OK);
    LucentQueryOptions {
        method,
        smoothing_factor,
        ..out
    }
}

/// A plan from `lucent_query_new`, or the failing status.
pub fn plan_with(
    profile: &Profile,
    cache: &Cache,
    options: &LucentQueryOptions,
) -> Result<Query, LucentStatus> {
    let mut out = ptr::null_mut();
    // SAFETY: live handles, a live struct and a writable out pointer.
    let status = unsafe { lucent_query_new(profile.0, cache.0, options, &mut out) };
    if status == LucentStatus::LUCENT_OK {
        assert!(!out.is_null());
        Ok(Query(out))
    } else {
        assert!(out.is_null(), "a failed creation leaves NULL in *out");
        Err(status)
    }
}

/// A plan for `method` with smoothing factor `k` and the other options at their defaults.
pub fn plan(profile: &Profile, cache: &Cache, method: u32, k: f32) -> Result<Query, LucentStatus> {
    plan_with(profile, cache, &options(method, k))
}

/// One query, or the failing status.
pub fn query(
    plan: &Query,
    cache: &Cache,
    point: &LucentShadingPoint,
) -> Result<LucentExitance, LucentStatus> {
    let mut out = LucentExitance::default();
    // SAFETY: live handles, a live struct and a writable result.
    let status = unsafe { lucent_query_point(plan.0, cache.0, point, &mut out) };
    if status == LucentStatus::LUCENT_OK {
        Ok(out)
    } else {
        Err(status)
    }
}

/// A plan's α and K.
pub fn alpha_and_k(plan: &Query) -> (f32, [f32; 3]) {
    let (mut alpha, mut k) = (f32::NAN, [f32::NAN; 3]);
    // SAFETY: a live plan, a writable float and three writable floats.
    let statuses = unsafe {
        [
            lucent_query_smoothing_radius(plan.0, &mut alpha),
            lucent_query_local_integral(plan.0, k.as_mut_ptr()),
        ]
    };
    assert_eq!(statuses, [LucentStatus::LUCENT_OK; 2]);
    (alpha, k)
}

/// Relative error |a − b| / |b| per channel, the largest.
pub fn rel_err(a: [f32; 3], b: [f32; 3]) -> f32 {
    (0..3)
        .map(|c| (a[c] - b[c]).abs() / b[c].abs())
        .fold(0.0, f32::max)
}

/// Every method `lucent_query_point` offers (edge-refined needs `lucent_query_point_refined`).
pub const METHODS: [LucentMethod; 4] = [
    LucentMethod::LUCENT_METHOD_HIERARCHICAL,
    LucentMethod::LUCENT_METHOD_LOCAL_GLOBAL,
    LucentMethod::LUCENT_METHOD_EDGE_AWARE,
    LucentMethod::LUCENT_METHOD_EXHAUSTIVE,
];
