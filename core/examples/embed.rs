//! Embedding lucent-core: a profile from a measured preset, irradiance samples, a cache, and a
//! query with every method at one point. `cargo run -p lucent-core --example embed`.
//!
//! The patch is uniformly lit, so far from its edges the exitance of every method must be the
//! irradiance times the profile's total diffuse reflectance, E·Rd_total (= E·K_d, the
//! dipole's albedo of a semi-infinite slab, `docs/physics.md` §5): the program checks it.

use lucent_core::glam::Vec3;
use lucent_core::{
    IrradianceCache, LocalIntegralTable, Method, Profile, QuerySettings, Sample, ShadingPoint,
};

/// Largest relative deviation from E·Rd_total accepted at the centre of the patch. Measured:
/// 0.12% for hierarchical (ε = 0.05) and exhaustive, which is the profile's tail beyond the
/// patch's edges 3 cm away (3.5 diffuse mean free paths of marble's red channel), and 0.17% for
/// the split methods (their kernel-weighted global sum and table K); 0.5% leaves a margin of 3.
const TOLERANCE: f32 = 0.005;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // Marble (Jensen et al. 2001), modelled in centimetres: 10 mm per scene unit.
    let marble = lucent_core::presets::find("marble").ok_or("no marble preset")?;
    let profile = Profile::from_preset(marble, 10.0)?;

    // A 6 × 6 cm patch of samples 0.02 cm apart (finer than marble's blue mean free path,
    // 0.033 cm, so that the unsplit sums resolve the profile's peak), each standing for its
    // 0.02² cm², under an irradiance E of 2 (any radiometric unit) in every channel.
    let e = Vec3::splat(2.0);
    let (n, h) = (301, 0.02_f32);
    let mut samples = Vec::with_capacity(n * n);
    for i in 0..n {
        for j in 0..n {
            let position = Vec3::new(i as f32 * h - 3.0, j as f32 * h - 3.0, 0.0);
            samples.push(Sample {
                position,
                area: h * h,
                irradiance: e,
            });
        }
    }
    let cache = IrradianceCache::build(&samples)?;
    cache.validate()?;

    // The split methods' smoothing radius α = 1.5·√Ā, and K for it from the table.
    let alpha = cache.smoothing_radius(1.5);
    let table = LocalIntegralTable::new(&profile, alpha, alpha / 1024.0)?;
    let local = table.local_term(profile.mean_free_path());

    // A point between samples, near the centre.
    let point = ShadingPoint {
        position: Vec3::new(0.013, -0.021, 0.0),
        irradiance: e,
    };
    let want = e * profile.total_reflectance();
    println!(
        "{} samples, {} nodes, α = {alpha:.4} cm, K = {:.4}",
        cache.len(),
        cache.node_count(),
        local.k()
    );
    println!("expected E·Rd_total = {want:.4}");
    for method in Method::ALL {
        let settings = QuerySettings {
            method,
            ..QuerySettings::default()
        };
        let m = cache.query(&profile, &point, local, &settings)?;
        let error = ((m.total - want) / want).abs().max_element();
        // Radiance towards a viewer 30° off the normal (`docs/physics.md` §17).
        let radiance = profile.radiance(m.total, 30f32.to_radians().cos());
        println!(
            "{:>13}: exitance {:.4} (local {:.4} + global {:.4}), error {:.3}%, radiance {:.4}",
            method.name(),
            m.total,
            m.local,
            m.global,
            100.0 * error,
            radiance
        );
        if !(error <= TOLERANCE) {
            return Err(format!(
                "{method}: exitance {} deviates {:.3}% from E·Rd_total {want} (tolerance {}%)",
                m.total,
                100.0 * error,
                100.0 * TOLERANCE
            )
            .into());
        }
        // Uniform light: no edge to refine.
        if m.refine {
            return Err(
                format!("{method}: a uniformly lit point was flagged for refinement").into(),
            );
        }
    }
    Ok(())
}
