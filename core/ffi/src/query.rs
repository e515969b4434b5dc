//! Queries: radiant exitance at shading points, one or many at a time.

use std::ffi::c_char;

use crate::bridge;
use crate::cache::LucentCache;
use crate::profile::LucentProfile;
use crate::ptr;
use crate::status::{LucentStatus, guard};
use crate::types::{LucentExitance, LucentMethod, LucentQuerySettings, LucentShadingPoint};

/// Writes the `LucentMethod` named `name` to `*out`: `"hierarchical"`, `"local-global"`,
/// `"edge-aware"` or `"exhaustive"` (the scene format's names). `"edge-refined"` gives
/// `LUCENT_UNSUPPORTED`; any other name `LUCENT_INVALID_ARGUMENT`.
///
/// # Safety
///
/// `name` is NULL or a NUL-terminated string; `out` is NULL or valid for writing a
/// `LucentMethod`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn lucent_method_from_name(
    name: *const c_char,
    out: *mut LucentMethod,
) -> LucentStatus {
    guard(|| {
        // SAFETY: `out` is NULL or writable (this function's contract).
        let out = unsafe { ptr::output(out, "out") }?;
        // SAFETY: `name` is NULL or a NUL-terminated string (this function's contract).
        let name = unsafe { ptr::utf8(name, "name") }?;
        out.write(bridge::method_from_name(name)?);
        Ok(())
    })
}

/// Fills `*out` with settings for `method` (a `LucentMethod` value) on this profile and cache:
/// ε = 0.05, cull tolerance 1e-4, smoothing radius α = `smoothing_factor`·√Ā (Ā the cache's
/// mean sample area; see `lucent_cache_smoothing_radius`), and for local-global and
/// edge-aware the local integral K of the profile for α (a few quadratures: call this once per
/// profile, cache and method, not per query).
///
/// Fails with `LUCENT_INVALID_ARGUMENT` for an unknown method, a negative or non-finite
/// `smoothing_factor`, or a zero α with local-global or edge-aware (factor 0, or an empty
/// cache); `LUCENT_UNSUPPORTED` for edge-refined (4); `LUCENT_NULL_POINTER` for a NULL
/// argument. `*out` is written only on success.
///
/// # Safety
///
/// `profile` and `cache` are NULL or live handles; `out` is NULL or valid for writing a
/// `LucentQuerySettings`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn lucent_query_settings_init(
    profile: *const LucentProfile,
    cache: *const LucentCache,
    method: u32,
    smoothing_factor: f32,
    out: *mut LucentQuerySettings,
) -> LucentStatus {
    guard(|| {
        // SAFETY: `profile` is NULL or a live profile (this function's contract).
        let profile = unsafe { ptr::reference(profile, "profile") }?;
        // SAFETY: `cache` is NULL or a live cache (this function's contract).
        let cache = unsafe { ptr::reference(cache, "cache") }?;
        // SAFETY: `out` is NULL or writable (this function's contract).
        let out = unsafe { ptr::output(out, "out") }?;
        let settings =
            bridge::settings_for(profile.material(), cache.cache(), method, smoothing_factor)?;
        out.write(settings);
        Ok(())
    })
}

/// Writes the radiant exitance at `point` to `*out`: light that entered the surface at the
/// cache's samples and leaves it at `point`, through `profile`, summed by `settings->method`.
///
/// Fails with `LUCENT_INVALID_ARGUMENT` for a non-finite position, a negative or non-finite
/// irradiance, local integral or setting, or an unknown method; `LUCENT_UNSUPPORTED` for
/// edge-refined; `LUCENT_NULL_POINTER` for a NULL argument. `*out` is written only on success.
///
/// # Safety
///
/// `profile` and `cache` are NULL or live handles; `settings` and `point` are NULL or point to
/// their structs; `out` is NULL or valid for writing a `LucentExitance`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn lucent_query(
    profile: *const LucentProfile,
    cache: *const LucentCache,
    settings: *const LucentQuerySettings,
    point: *const LucentShadingPoint,
    out: *mut LucentExitance,
) -> LucentStatus {
    guard(|| {
        // SAFETY: `profile` is NULL or a live profile (this function's contract).
        let profile = unsafe { ptr::reference(profile, "profile") }?;
        // SAFETY: `cache` is NULL or a live cache (this function's contract).
        let cache = unsafe { ptr::reference(cache, "cache") }?;
        // SAFETY: `settings` is NULL or a LucentQuerySettings (this function's contract).
        let settings = unsafe { ptr::reference(settings, "settings") }?;
        // SAFETY: `point` is NULL or a LucentShadingPoint (this function's contract).
        let point = unsafe { ptr::reference(point, "point") }?;
        // SAFETY: `out` is NULL or writable (this function's contract).
        let out = unsafe { ptr::output(out, "out") }?;
        out.write(cache.cache().query(profile.material(), settings, point)?);
        Ok(())
    })
}

/// `lucent_query` for `count` points: `out[i]` is the exitance at `points[i]`. Either every
/// query succeeds and all of `out` is written, or the call fails naming the first bad point
/// and `out` is left untouched. Runs on the calling thread; to use several cores, split the
/// points and call this from several threads on the same cache and profile. `points` and
/// `out` may be NULL when `count` is 0.
///
/// # Safety
///
/// `profile` and `cache` are NULL or live handles; `settings` is NULL or points to a
/// `LucentQuerySettings`; `points` is NULL or `count` readable points; `out` is NULL or valid
/// for writing `count` `LucentExitance`s and does not overlap `points`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn lucent_query_many(
    profile: *const LucentProfile,
    cache: *const LucentCache,
    settings: *const LucentQuerySettings,
    points: *const LucentShadingPoint,
    count: usize,
    out: *mut LucentExitance,
) -> LucentStatus {
    guard(|| {
        // SAFETY: `profile` is NULL or a live profile (this function's contract).
        let profile = unsafe { ptr::reference(profile, "profile") }?;
        // SAFETY: `cache` is NULL or a live cache (this function's contract).
        let cache = unsafe { ptr::reference(cache, "cache") }?;
        // SAFETY: `settings` is NULL or a LucentQuerySettings (this function's contract).
        let settings = unsafe { ptr::reference(settings, "settings") }?;
        // SAFETY: `points` is NULL or `count` readable points (this function's contract).
        let points = unsafe { ptr::slice(points, count, "points") }?;
        // SAFETY: `out` is NULL or `count` writable results, not overlapping `points`
        // (this function's contract).
        let out = unsafe { ptr::output_slice(out, count, "out") }?;
        let results = cache
            .cache()
            .query_many(profile.material(), settings, points)?;
        for (slot, m) in out.iter_mut().zip(results) {
            slot.write(m);
        }
        Ok(())
    })
}
