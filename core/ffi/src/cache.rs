//! `LucentCache`: the irradiance cache (a linear octree over the samples), built once and then
//! queried, from any number of threads.

use crate::bridge::Cache;
use crate::ptr;
use crate::status::{LucentStatus, guard, guard_void};
use crate::types::LucentSample;

/// An irradiance cache built from samples. Opaque; made by `lucent_cache_build`, freed by
/// `lucent_cache_free`. Immutable once built: queries from many threads at once on one cache
/// are safe and need no lock.
pub struct LucentCache {
    cache: Cache,
}

impl LucentCache {
    pub(crate) fn cache(&self) -> &Cache {
        &self.cache
    }
}

/// Builds a cache from `count` samples (any order; the cache keeps its own copy, so the array
/// may be reused or freed afterwards). `samples` may be NULL when `count` is 0 (an empty
/// cache: queries give zero).
///
/// On success `*out` is a new cache to free with `lucent_cache_free`; on failure `*out` is set
/// to NULL (when `out` is not NULL). Fails with `LUCENT_INVALID_ARGUMENT` naming the first
/// sample with a non-finite position or a negative or non-finite area or irradiance, or when
/// the total area or flux exceeds single precision; `LUCENT_NULL_POINTER` for a NULL `out`, or
/// a NULL `samples` with `count` > 0.
///
/// # Safety
///
/// `samples` is NULL or points to `count` `LucentSample`s; `out` is NULL or valid for
/// writing a pointer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn lucent_cache_build(
    samples: *const LucentSample,
    count: usize,
    out: *mut *mut LucentCache,
) -> LucentStatus {
    guard(|| {
        // SAFETY: `out` is NULL or writable (this function's contract).
        let out = unsafe { ptr::output(out, "out") }?;
        out.write(std::ptr::null_mut());
        // SAFETY: `samples` is NULL or `count` readable samples (this function's contract).
        let samples = unsafe { ptr::slice(samples, count, "samples") }?;
        let cache = Cache::build(samples)?;
        out.write(ptr::into_handle(LucentCache { cache }));
        Ok(())
    })
}

/// Frees a cache. NULL is a no-op.
///
/// # Safety
///
/// `cache` is NULL or a cache from this library that has not been freed, is not used
/// afterwards, and no other thread is querying it.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn lucent_cache_free(cache: *mut LucentCache) {
    guard_void(|| {
        // SAFETY: NULL or a live handle made by `ptr::into_handle`, never used again
        // (this function's contract).
        unsafe { ptr::free(cache) }
    })
}

/// Writes the number of samples in the cache to `*out`.
///
/// # Safety
///
/// `cache` is NULL or a live cache; `out` is NULL or valid for writing a `size_t`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn lucent_cache_len(
    cache: *const LucentCache,
    out: *mut usize,
) -> LucentStatus {
    guard(|| {
        // SAFETY: `cache` is NULL or a live cache (this function's contract).
        let cache = unsafe { ptr::reference(cache, "cache") }?;
        // SAFETY: `out` is NULL or writable (this function's contract).
        unsafe { ptr::output(out, "out") }?.write(cache.cache.len());
        Ok(())
    })
}

/// Writes the smoothing radius α = `factor`·√Ā (scene units) to `*out`, Ā the mean sample
/// area: the radius of the local term of local-global and edge-aware, scaled to the sample
/// spacing. `factor` must be finite and ≥ 0; 2 is a good start (N10 suggests 1 to 4).
///
/// # Safety
///
/// `cache` is NULL or a live cache; `out` is NULL or valid for writing a float.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn lucent_cache_smoothing_radius(
    cache: *const LucentCache,
    factor: f32,
    out: *mut f32,
) -> LucentStatus {
    guard(|| {
        // SAFETY: `cache` is NULL or a live cache (this function's contract).
        let cache = unsafe { ptr::reference(cache, "cache") }?;
        // SAFETY: `out` is NULL or writable (this function's contract).
        let out = unsafe { ptr::output(out, "out") }?;
        if !(factor.is_finite() && factor >= 0.0) {
            return Err(crate::status::Failure::invalid(format!(
                "factor must be finite and non-negative, got {factor}"
            )));
        }
        out.write(cache.cache.smoothing_radius(factor));
        Ok(())
    })
}
