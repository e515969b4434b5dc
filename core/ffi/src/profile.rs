//! `LucentProfile`: a material's diffusion profile, from a measured preset or from
//! coefficients, with its total diffuse reflectance and the exitance → radiance conversion.

use std::ffi::c_char;

use crate::bridge::Material;
use crate::ptr;
use crate::status::{Failure, LucentStatus, guard, guard_void};
use crate::types::LucentCoefficients;

/// A material's RGB diffusion profile (the dipole of Jensen et al. 2001 per channel).
/// Opaque; made by `lucent_profile_from_preset` or `lucent_profile_from_coefficients`, freed
/// by `lucent_profile_free`. Immutable: one profile may be used from many threads at once.
pub struct LucentProfile {
    material: Material,
}

impl LucentProfile {
    pub(crate) fn material(&self) -> &Material {
        &self.material
    }
}

fn hand_out(material: Material, out: &mut std::mem::MaybeUninit<*mut LucentProfile>) {
    out.write(ptr::into_handle(LucentProfile { material }));
}

/// Creates the profile of a measured material of Jensen et al. 2001 (`"marble"`, `"skin1"`,
/// `"ketchup"`, ...; ASCII case ignored) for a scene modelled at `mm_per_unit` millimetres
/// per scene unit (10 for centimetres; finite and > 0).
///
/// On success `*out` is a new profile to free with `lucent_profile_free`; on failure `*out`
/// is set to NULL (when `out` is not NULL). Fails with `LUCENT_UNKNOWN_PRESET` for a name
/// that is not in the table, `LUCENT_INVALID_ARGUMENT` for a bad `mm_per_unit` or a name that
/// is not UTF-8, `LUCENT_NULL_POINTER` for a NULL `name` or `out`.
///
/// # Safety
///
/// `name` is NULL or a NUL-terminated string; `out` is NULL or valid for writing a pointer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn lucent_profile_from_preset(
    name: *const c_char,
    mm_per_unit: f32,
    out: *mut *mut LucentProfile,
) -> LucentStatus {
    guard(|| {
        // SAFETY: `out` is NULL or writable (this function's contract).
        let out = unsafe { ptr::output(out, "out") }?;
        out.write(std::ptr::null_mut());
        // SAFETY: `name` is NULL or a NUL-terminated string (this function's contract).
        let name = unsafe { ptr::utf8(name, "name") }?;
        hand_out(Material::from_preset(name, mm_per_unit)?, out);
        Ok(())
    })
}

/// Creates a profile from absorption σ_a and reduced scattering σ_s′ per channel (per scene
/// unit) and the relative index of refraction η.
///
/// On success `*out` is a new profile to free with `lucent_profile_free`; on failure `*out`
/// is set to NULL (when `out` is not NULL). Fails with `LUCENT_INVALID_ARGUMENT` naming the
/// coefficient for a negative or non-finite σ_a, a non-positive σ_s′, or η outside [1, 3];
/// `LUCENT_NULL_POINTER` for a NULL `coefficients` or `out`.
///
/// # Safety
///
/// `coefficients` is NULL or points to a `LucentCoefficients`; `out` is NULL or valid for
/// writing a pointer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn lucent_profile_from_coefficients(
    coefficients: *const LucentCoefficients,
    out: *mut *mut LucentProfile,
) -> LucentStatus {
    guard(|| {
        // SAFETY: `out` is NULL or writable (this function's contract).
        let out = unsafe { ptr::output(out, "out") }?;
        out.write(std::ptr::null_mut());
        // SAFETY: `coefficients` is NULL or points to a LucentCoefficients (contract).
        let coefficients = unsafe { ptr::reference(coefficients, "coefficients") }?;
        hand_out(Material::from_coefficients(coefficients)?, out);
        Ok(())
    })
}

/// Frees a profile. NULL is a no-op. Query plans made with it stay valid (they copy it).
///
/// # Safety
///
/// `profile` is NULL or a profile from this library that has not been freed, and is not used
/// afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn lucent_profile_free(profile: *mut LucentProfile) {
    guard_void(|| {
        // SAFETY: NULL or a live handle made by `ptr::into_handle`, never used again
        // (this function's contract).
        unsafe { ptr::free(profile) }
    })
}

/// Writes three floats to `out`: the profile's value per RGB channel.
///
/// # Safety
///
/// As the public functions that call it: `profile` NULL or live, `out` NULL or 3 writable
/// floats.
unsafe fn per_channel(
    profile: *const LucentProfile,
    out: *mut f32,
    value: impl FnOnce(&Material) -> Result<[f32; 3], Failure>,
) -> LucentStatus {
    guard(|| {
        // SAFETY: `profile` is NULL or a live profile (the caller's contract).
        let profile = unsafe { ptr::reference(profile, "profile") }?;
        // SAFETY: `out` is NULL or valid for writing 3 floats (the caller's contract).
        let out = unsafe { ptr::output_slice(out, 3, "out") }?;
        let v = value(&profile.material)?;
        for (slot, v) in out.iter_mut().zip(v) {
            slot.write(v);
        }
        Ok(())
    })
}

/// Writes Rd_total per RGB channel to `out[0..3]`: the total diffuse reflectance, i.e. the
/// albedo of a flat, uniformly lit surface (its exitance is E·Rd_total).
///
/// # Safety
///
/// `profile` is NULL or a live profile; `out` is NULL or valid for writing 3 floats.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn lucent_profile_total_reflectance(
    profile: *const LucentProfile,
    out: *mut f32,
) -> LucentStatus {
    // SAFETY: the same contract as this function's.
    unsafe { per_channel(profile, out, |m| Ok(m.total_reflectance())) }
}

/// Writes the mean free path ℓ_u = 1/σ_t′ per RGB channel (scene units) to `out[0..3]`.
///
/// # Safety
///
/// `profile` is NULL or a live profile; `out` is NULL or valid for writing 3 floats.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn lucent_profile_mean_free_path(
    profile: *const LucentProfile,
    out: *mut f32,
) -> LucentStatus {
    // SAFETY: the same contract as this function's.
    unsafe { per_channel(profile, out, |m| Ok(m.mean_free_path())) }
}

/// Writes the local integral K per RGB channel for smoothing radius `alpha` (scene units,
/// finite and > 0) to `out[0..3]`: the fraction of a uniform irradiance that the local term of
/// local-global and edge-aware gathers within α (`lucent_query_new` computes it for its plan).
/// Costs a few numerical quadratures.
///
/// # Safety
///
/// `profile` is NULL or a live profile; `out` is NULL or valid for writing 3 floats.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn lucent_profile_local_integral(
    profile: *const LucentProfile,
    alpha: f32,
    out: *mut f32,
) -> LucentStatus {
    // SAFETY: the same contract as this function's.
    unsafe { per_channel(profile, out, |m| m.local_integral(alpha)) }
}

/// Writes the outgoing radiance per RGB channel towards a viewer at `cos_out` = cos θ_o (in
/// [0, 1]) from the radiant exitance `exitance[0..3]` (a query's `total`) to `out[0..3]`:
/// L_o = F_t(η, cos θ_o) / (π (1 − F_dr(η))) · M_o, which integrates back to M_o over the
/// hemisphere. `exitance` and `out` may be the same array.
///
/// # Safety
///
/// `profile` is NULL or a live profile; `exitance` is NULL or 3 readable floats; `out` is NULL
/// or valid for writing 3 floats.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn lucent_profile_radiance(
    profile: *const LucentProfile,
    exitance: *const f32,
    cos_out: f32,
    out: *mut f32,
) -> LucentStatus {
    let mut m = [0.0; 3];
    let status = guard(|| {
        // SAFETY: `exitance` is NULL or 3 readable floats (this function's contract); they
        // are copied before `out`, which may alias them, is borrowed.
        let e = unsafe { ptr::slice(exitance, 3, "exitance") }?;
        m.copy_from_slice(e);
        Ok(())
    });
    if status != LucentStatus::LUCENT_OK {
        return status;
    }
    // SAFETY: the same contract as this function's.
    unsafe { per_channel(profile, out, |p| p.radiance(m, cos_out)) }
}
