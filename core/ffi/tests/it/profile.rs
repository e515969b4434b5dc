//! Profiles: creation, Rd_total against J01's closed form, ℓ_u, K and radiance.

use std::ptr;

use lucent_ffi::*;

use crate::common::{Profile, coefficients, message, preset, rel_err};

/// Writes one of the per-channel queries.
fn per_channel(
    f: unsafe extern "C" fn(*const LucentProfile, *mut f32) -> LucentStatus,
    profile: &Profile,
) -> [f32; 3] {
    let mut out = [f32::NAN; 3];
    // SAFETY: a live profile and three writable floats.
    let status = unsafe { f(profile.0, out.as_mut_ptr()) };
    assert_eq!(status, LucentStatus::LUCENT_OK, "{}", message());
    out
}

/// J01 eq. 5 with the J01 fit of F_dr (`docs/physics.md` §2), written out independently.
fn rd_total_closed_form(sigma_a: f64, sigma_s_prime: f64, eta: f64) -> f64 {
    let albedo = sigma_s_prime / (sigma_a + sigma_s_prime);
    let fdr = -1.440 / (eta * eta) + 0.710 / eta + 0.668 + 0.0636 * eta;
    let a = (1.0 + fdr) / (1.0 - fdr);
    let s = (3.0 * (1.0 - albedo)).sqrt();
    0.5 * albedo * (1.0 + (-(4.0 / 3.0) * a * s).exp()) * (-s).exp()
}

#[test]
fn a_preset_has_j01s_total_reflectance_and_mean_free_path() {
    // Skin1 of Jensen et al. 2001 (per mm): σ_s′ = (0.74, 0.88, 1.01), σ_a = (0.032, 0.17,
    // 0.48), η = 1.3; at 2 mm per unit the coefficients double.
    let sigma_s = [0.74, 0.88, 1.01];
    let sigma_a = [0.032, 0.17, 0.48];
    for name in ["skin1", "Skin1", "SKIN1"] {
        let skin = preset(name, 2.0).unwrap();
        let rd = per_channel(lucent_profile_total_reflectance, &skin);
        let ell = per_channel(lucent_profile_mean_free_path, &skin);
        for c in 0..3 {
            let want = rd_total_closed_form(sigma_a[c], sigma_s[c], 1.3) as f32;
            assert!((rd[c] - want).abs() < 1e-5 * want, "{rd:?} vs {want}");
            let want = (1.0 / (2.0 * (sigma_a[c] + sigma_s[c]))) as f32;
            assert!((ell[c] - want).abs() < 1e-6 * want, "{ell:?} vs {want}");
        }
    }
}

#[test]
fn coefficients_give_the_same_profile_as_the_preset() {
    let skin = preset("skin1", 1.0).unwrap();
    let same = coefficients(&LucentCoefficients {
        sigma_a: [0.032, 0.17, 0.48],
        sigma_s_prime: [0.74, 0.88, 1.01],
        eta: 1.3,
    })
    .unwrap();
    for f in [
        lucent_profile_total_reflectance as unsafe extern "C" fn(_, _) -> _,
        lucent_profile_mean_free_path,
    ] {
        assert_eq!(per_channel(f, &skin), per_channel(f, &same));
    }
}

#[test]
fn the_local_integral_grows_towards_rd_total() {
    // K(α) = ∫_{r<α} w·Rd dA: positive, increasing in α, below Rd_total, reaching it for α
    // far beyond the diffusion length (ℓ_d ≈ 3.7 mm here in the red channel).
    let skin = preset("skin1", 1.0).unwrap();
    let rd = per_channel(lucent_profile_total_reflectance, &skin);
    let mut previous = [0.0f32; 3];
    for alpha in [0.1, 0.5, 2.0, 8.0, 400.0] {
        let mut k = [f32::NAN; 3];
        // SAFETY: a live profile and three writable floats.
        let status = unsafe { lucent_profile_local_integral(skin.0, alpha, k.as_mut_ptr()) };
        assert_eq!(status, LucentStatus::LUCENT_OK, "{}", message());
        for c in 0..3 {
            assert!(
                k[c] > previous[c] && k[c] <= rd[c] * (1.0 + 1e-5),
                "α {alpha}: {k:?}"
            );
        }
        previous = k;
    }
    assert!(rel_err(previous, rd) < 1e-3, "{previous:?} vs {rd:?}");
}

#[test]
fn radiance_integrates_back_to_the_exitance() {
    // M = 2π ∫₀¹ L(μ) μ dμ (docs/physics.md §17), by the midpoint rule on 20 000 steps.
    for (name, eta) in [("skin1", 1.3), ("marble", 1.5)] {
        let profile = preset(name, 1.0).unwrap();
        let m = [0.25f32, 1.0, 3.0];
        let n = 20_000;
        let mut integral = [0.0f64; 3];
        for i in 0..n {
            let mu = (i as f32 + 0.5) / n as f32;
            let mut l = [f32::NAN; 3];
            // SAFETY: a live profile, three readable and three writable floats.
            let status =
                unsafe { lucent_profile_radiance(profile.0, m.as_ptr(), mu, l.as_mut_ptr()) };
            assert_eq!(status, LucentStatus::LUCENT_OK, "{}", message());
            for c in 0..3 {
                integral[c] += l[c] as f64 * mu as f64 * std::f64::consts::TAU / n as f64;
            }
        }
        let integral = integral.map(|v| v as f32);
        assert!(
            rel_err(integral, m) < 1e-4,
            "{name} (η {eta}): {integral:?} vs {m:?}"
        );
    }
}

#[test]
fn radiance_may_convert_in_place() {
    let marble = preset("marble", 10.0).unwrap();
    let m = [0.5f32, 0.6, 0.7];
    let mut separate = [0.0; 3];
    let mut in_place = m;
    // SAFETY: a live profile; three readable and three writable floats, the second call with
    // the same array for both, which the function allows.
    unsafe {
        lucent_profile_radiance(marble.0, m.as_ptr(), 0.5, separate.as_mut_ptr());
        let p = in_place.as_mut_ptr();
        lucent_profile_radiance(marble.0, p, 0.5, p);
    }
    assert_eq!(separate, in_place);
    assert!(separate.iter().all(|&v| v > 0.0));
}

#[test]
fn freeing_null_is_a_no_op() {
    // SAFETY: NULL is documented as a no-op.
    unsafe {
        lucent_profile_free(ptr::null_mut());
        lucent_cache_free(ptr::null_mut());
    }
}
