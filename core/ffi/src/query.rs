//! `LucentQuery`: a query plan (profile, method, settings, and the local integral that goes
//! with the smoothing radius), and the queries themselves, one or many points at a time.

use std::ffi::{c_char, c_int, c_void};

use crate::bridge::{self, NodeIrradiance, Plan};
use crate::cache::LucentCache;
use crate::profile::LucentProfile;
use crate::ptr;
use crate::status::{Failure, LucentStatus, guard, guard_void};
use crate::types::{LucentExitance, LucentMethod, LucentQueryOptions, LucentShadingPoint};

/// A query plan: a copy of a profile, a method with its settings, the smoothing radius α and
/// the local integral K computed for it. Opaque; made by `lucent_query_new`, freed by
/// `lucent_query_free`. Immutable: one plan may be used from many threads at once.
pub struct LucentQuery {
    plan: Plan,
}

/// Writes the `LucentMethod` named `name` to `*out`: `"hierarchical"`, `"local-global"`,
/// `"edge-aware"`, `"exhaustive"` or `"edge-refined"` (the scene format's names); any other
/// name gives `LUCENT_INVALID_ARGUMENT`.
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

/// Writes the default options to `*out`: edge-aware, smoothing factor 2, ε = 0.05, cull
/// tolerance 1e-4.
///
/// # Safety
///
/// `out` is NULL or valid for writing a `LucentQueryOptions`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn lucent_query_options_init(out: *mut LucentQueryOptions) -> LucentStatus {
    guard(|| {
        // SAFETY: `out` is NULL or writable (this function's contract).
        unsafe { ptr::output(out, "out") }?.write(bridge::default_options());
        Ok(())
    })
}

/// Makes a query plan for `profile` with `options`: the smoothing radius is α =
/// `options->smoothing_factor`·√Ā with Ā the mean sample area of `cache` (see
/// `lucent_cache_smoothing_radius`), and for local-global, edge-aware and edge-refined the
/// local integral K of the profile for α (and edge-refined's quadrature nodes) are computed
/// here (a few numerical quadratures: make one plan per material and cache, not one per
/// query). The plan copies what it needs: `profile` may be freed afterwards, and the plan may
/// query any cache (α stays what it was made with).
///
/// On success `*out` is a new plan to free with `lucent_query_free`; on failure `*out` is set
/// to NULL (when `out` is not NULL). Fails with `LUCENT_INVALID_ARGUMENT` for an unknown
/// method, a negative or non-finite option, or a zero α with local-global, edge-aware or
/// edge-refined (factor 0, or an empty cache); `LUCENT_NULL_POINTER` for a NULL argument.
///
/// # Safety
///
/// `profile` and `cache` are NULL or live handles; `options` is NULL or points to a
/// `LucentQueryOptions`; `out` is NULL or valid for writing a pointer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn lucent_query_new(
    profile: *const LucentProfile,
    cache: *const LucentCache,
    options: *const LucentQueryOptions,
    out: *mut *mut LucentQuery,
) -> LucentStatus {
    guard(|| {
        // SAFETY: `out` is NULL or writable (this function's contract).
        let out = unsafe { ptr::output(out, "out") }?;
        out.write(std::ptr::null_mut());
        // SAFETY: `profile` is NULL or a live profile (this function's contract).
        let profile = unsafe { ptr::reference(profile, "profile") }?;
        // SAFETY: `cache` is NULL or a live cache (this function's contract).
        let cache = unsafe { ptr::reference(cache, "cache") }?;
        // SAFETY: `options` is NULL or a LucentQueryOptions (this function's contract).
        let options = unsafe { ptr::reference(options, "options") }?;
        let plan = Plan::new(profile.material(), cache.cache(), options)?;
        out.write(ptr::into_handle(LucentQuery { plan }));
        Ok(())
    })
}

/// Frees a query plan. NULL is a no-op.
///
/// # Safety
///
/// `query` is NULL or a plan from this library that has not been freed, is not used
/// afterwards, and no other thread is using it.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn lucent_query_free(query: *mut LucentQuery) {
    guard_void(|| {
        // SAFETY: NULL or a live handle made by `ptr::into_handle`, never used again
        // (this function's contract).
        unsafe { ptr::free(query) }
    })
}

/// Writes the plan's smoothing radius α (scene units) to `*out`.
///
/// # Safety
///
/// `query` is NULL or a live plan; `out` is NULL or valid for writing a float.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn lucent_query_smoothing_radius(
    query: *const LucentQuery,
    out: *mut f32,
) -> LucentStatus {
    guard(|| {
        // SAFETY: `query` is NULL or a live plan (this function's contract).
        let query = unsafe { ptr::reference(query, "query") }?;
        // SAFETY: `out` is NULL or writable (this function's contract).
        unsafe { ptr::output(out, "out") }?.write(query.plan.smoothing_radius());
        Ok(())
    })
}

/// Writes the plan's local integral K per RGB channel to `out[0..3]` (zero for hierarchical
/// and exhaustive): the fraction of a uniform irradiance that the local term gathers within α.
///
/// # Safety
///
/// `query` is NULL or a live plan; `out` is NULL or valid for writing 3 floats.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn lucent_query_local_integral(
    query: *const LucentQuery,
    out: *mut f32,
) -> LucentStatus {
    guard(|| {
        // SAFETY: `query` is NULL or a live plan (this function's contract).
        let query = unsafe { ptr::reference(query, "query") }?;
        // SAFETY: `out` is NULL or valid for writing 3 floats (this function's contract).
        let out = unsafe { ptr::output_slice(out, 3, "out") }?;
        for (slot, k) in out.iter_mut().zip(query.plan.local_integral()) {
            slot.write(k);
        }
        Ok(())
    })
}

/// Writes the radiant exitance at `point` to `*out`: light that entered the surface at the
/// cache's samples and leaves it at `point`, through the plan's profile, by its method.
///
/// Fails with `LUCENT_INVALID_ARGUMENT` for a non-finite position or a negative or
/// non-finite irradiance; `LUCENT_NULL_POINTER` for a NULL argument; `LUCENT_UNSUPPORTED` for
/// an edge-refined plan (it needs the irradiance callback of `lucent_query_point_refined`).
/// `*out` is written only on success.
///
/// # Safety
///
/// `query` and `cache` are NULL or live handles; `point` is NULL or points to a
/// `LucentShadingPoint`; `out` is NULL or valid for writing a `LucentExitance`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn lucent_query_point(
    query: *const LucentQuery,
    cache: *const LucentCache,
    point: *const LucentShadingPoint,
    out: *mut LucentExitance,
) -> LucentStatus {
    guard(|| {
        // SAFETY: `query` is NULL or a live plan (this function's contract).
        let query = unsafe { ptr::reference(query, "query") }?;
        // SAFETY: `cache` is NULL or a live cache (this function's contract).
        let cache = unsafe { ptr::reference(cache, "cache") }?;
        // SAFETY: `point` is NULL or a LucentShadingPoint (this function's contract).
        let point = unsafe { ptr::reference(point, "point") }?;
        // SAFETY: `out` is NULL or writable (this function's contract).
        let out = unsafe { ptr::output(out, "out") }?;
        out.write(query.plan.query(cache.cache(), point)?);
        Ok(())
    })
}

/// `lucent_query_point` for `count` points (not for an edge-refined plan): `out[i]` is the
/// exitance at `points[i]`. Either
/// every query succeeds and all of `out` is written, or the call fails naming the first bad
/// point and `out` is left untouched. Runs on the calling thread; to use several cores, split
/// the points and call this from several threads with the same plan and cache. `points` and
/// `out` may be NULL when `count` is 0.
///
/// # Safety
///
/// `query` and `cache` are NULL or live handles; `points` is NULL or `count` readable points;
/// `out` is NULL or valid for writing `count` `LucentExitance`s and does not overlap `points`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn lucent_query_points(
    query: *const LucentQuery,
    cache: *const LucentCache,
    points: *const LucentShadingPoint,
    count: usize,
    out: *mut LucentExitance,
) -> LucentStatus {
    guard(|| {
        // SAFETY: `query` is NULL or a live plan (this function's contract).
        let query = unsafe { ptr::reference(query, "query") }?;
        // SAFETY: `cache` is NULL or a live cache (this function's contract).
        let cache = unsafe { ptr::reference(cache, "cache") }?;
        // SAFETY: `points` is NULL or `count` readable points (this function's contract).
        let points = unsafe { ptr::slice(points, count, "points") }?;
        // SAFETY: `out` is NULL or `count` writable results, not overlapping `points`
        // (this function's contract).
        let out = unsafe { ptr::output_slice(out, count, "out") }?;
        let results = query.plan.query_many(cache.cache(), points)?;
        for (slot, m) in out.iter_mut().zip(results) {
            slot.write(m);
        }
        Ok(())
    })
}

/// The caller's irradiance at a point, for the edge-refined local term: writes E per RGB
/// channel (finite, ≥ 0, the same radiometric unit as the samples' irradiance) at `position`
/// on a surface facing `normal` to `irradiance[0..3]`, and returns 0; any other value
/// abandons the query (`LUCENT_CALLBACK_FAILED`).
///
/// E is what the lights deliver there through the occluders, the same way the cache's samples
/// were lit: occluders closer than `shadow_skip` to the node should be ignored (they are the
/// surface near the shading point curving up, not a shadow's edge; `docs/physics.md` §16).
/// `position` and `normal` point to 3 floats each, valid during the call only; `normal` is the
/// unit normal at the shading point (the nodes lie on its tangent disc, bent slightly towards
/// it). `user` is the pointer given to `lucent_query_point_refined`.
///
/// The callback is called on the thread that called `lucent_query_point_refined`, only
/// during that call (threads querying at once call it at once). It must return normally: a C++ exception or a `longjmp` out of it is
/// undefined behaviour (a Rust panic, in an `extern "C-unwind"` function, is caught and
/// reported as `LUCENT_PANIC`).
pub type LucentIrradianceFn = Option<
    unsafe extern "C-unwind" fn(
        user: *mut c_void,
        position: *const f32,
        normal: *const f32,
        shadow_skip: f32,
        irradiance: *mut f32,
    ) -> c_int,
>;

/// A C callback with its user pointer, as the bridge's node irradiance.
struct Callback {
    function:
        unsafe extern "C-unwind" fn(*mut c_void, *const f32, *const f32, f32, *mut f32) -> c_int,
    user: *mut c_void,
}

impl NodeIrradiance for Callback {
    fn at(
        &mut self,
        node: usize,
        position: [f32; 3],
        normal: [f32; 3],
        skip: f32,
    ) -> Result<[f32; 3], Failure> {
        // NaN until written: a callback that returns 0 without writing fails the check.
        let mut irradiance = [f32::NAN; 3];
        // SAFETY: by `lucent_query_point_refined`'s contract the function may be called with
        // `user` and pointers to 3 readable floats (position, normal) and 3 writable ones
        // (irradiance); all three arrays are locals that outlive the call.
        let code = unsafe {
            (self.function)(
                self.user,
                position.as_ptr(),
                normal.as_ptr(),
                skip,
                irradiance.as_mut_ptr(),
            )
        };
        if code != 0 {
            return Err(Failure::new(
                LucentStatus::LUCENT_CALLBACK_FAILED,
                format!(
                    "the irradiance callback returned {code} at node {node} (position {position:?})"
                ),
            ));
        }
        Ok(irradiance)
    }
}

/// `lucent_query_point` with the caller's irradiance: any plan, and the only call for an
/// edge-refined one. Where the edge-refined query finds the samples' irradiance within α not
/// uniform, `callback` is called once per quadrature node (12 nodes) for E there, and the
/// local term becomes K·(E(x) + Σ fᵢ·(E(x′ᵢ) − E(x))) with the profile's weights fᵢ
/// (`docs/physics.md` §16); elsewhere, and for every other method, the result is that of
/// `lucent_query_point` and `callback` is not called.
///
/// `normal` is the unit surface normal at `point` (3 floats, length within 1e-3 of 1; it is
/// renormalised). `seed` turns the node pattern about the normal: give neighbouring shading
/// points different seeds (a pixel or sample index will do) so that the quadrature's angular
/// error becomes fine noise instead of a pattern; the same seed gives the same nodes.
///
/// Fails with `LUCENT_NULL_POINTER` for a NULL argument (`user` excepted, which is only
/// passed on); `LUCENT_INVALID_ARGUMENT` for a bad point (as `lucent_query_point`), a normal
/// that is not a finite unit vector, or a callback result that is not finite and
/// non-negative (the message names the node); `LUCENT_CALLBACK_FAILED` when the callback
/// returns non-zero. `*out` is written only on success.
///
/// # Safety
///
/// `query` and `cache` are NULL or live handles; `point` is NULL or points to a
/// `LucentShadingPoint`; `normal` is NULL or points to 3 floats; `callback` is NULL or a
/// function that honours `LucentIrradianceFn`'s contract for this `user`; `out` is NULL or
/// valid for writing a `LucentExitance`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn lucent_query_point_refined(
    query: *const LucentQuery,
    cache: *const LucentCache,
    point: *const LucentShadingPoint,
    normal: *const f32,
    seed: u64,
    callback: LucentIrradianceFn,
    user: *mut c_void,
    out: *mut LucentExitance,
) -> LucentStatus {
    guard(|| {
        // SAFETY: `query` is NULL or a live plan (this function's contract).
        let query = unsafe { ptr::reference(query, "query") }?;
        // SAFETY: `cache` is NULL or a live cache (this function's contract).
        let cache = unsafe { ptr::reference(cache, "cache") }?;
        // SAFETY: `point` is NULL or a LucentShadingPoint (this function's contract).
        let point = unsafe { ptr::reference(point, "point") }?;
        // SAFETY: `normal` is NULL or 3 readable floats (this function's contract).
        let normal = unsafe { ptr::slice(normal, 3, "normal") }?;
        let function = callback.ok_or_else(|| Failure::null("callback"))?;
        // SAFETY: `out` is NULL or writable (this function's contract).
        let out = unsafe { ptr::output(out, "out") }?;
        let normal = [normal[0], normal[1], normal[2]];
        let mut callback = Callback { function, user };
        out.write(
            query
                .plan
                .query_refined(cache.cache(), point, normal, seed, &mut callback)?,
        );
        Ok(())
    })
}
