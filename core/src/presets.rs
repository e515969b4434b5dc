//! Measured materials of Jensen et al. 2001 (J01, Figure 5), as carried by pbrt; coefficients in
//! mm⁻¹ (`docs/physics.md` §4). Use with [`crate::Profile::from_preset`] and a unit scale.

/// One measured material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Preset {
    /// Name as printed in J01 (matched case-insensitively by [`find`]).
    pub name: &'static str,
    /// Reduced scattering σ_s′ per mm, RGB.
    pub sigma_s_prime: [f32; 3],
    /// Absorption σ_a per mm, RGB.
    pub sigma_a: [f32; 3],
    /// Relative index of refraction.
    pub eta: f32,
}

const fn p(name: &'static str, s: [f32; 3], a: [f32; 3], eta: f32) -> Preset {
    Preset {
        name,
        sigma_s_prime: s,
        sigma_a: a,
        eta,
    }
}

/// The J01 table.
pub const PRESETS: [Preset; 11] = [
    p("Apple", [2.29, 2.39, 1.97], [0.0030, 0.0034, 0.046], 1.3),
    p("Chicken1", [0.15, 0.21, 0.38], [0.015, 0.077, 0.19], 1.3),
    p("Chicken2", [0.19, 0.25, 0.32], [0.018, 0.088, 0.20], 1.3),
    p("Cream", [7.38, 5.47, 3.15], [0.0002, 0.0028, 0.0163], 1.3),
    p("Ketchup", [0.18, 0.07, 0.03], [0.061, 0.97, 1.45], 1.3),
    p("Marble", [2.19, 2.62, 3.00], [0.0021, 0.0041, 0.0071], 1.5),
    p("Potato", [0.68, 0.70, 0.55], [0.0024, 0.0090, 0.12], 1.3),
    p(
        "Skimmilk",
        [0.70, 1.22, 1.90],
        [0.0014, 0.0025, 0.0142],
        1.3,
    ),
    p("Skin1", [0.74, 0.88, 1.01], [0.032, 0.17, 0.48], 1.3),
    p("Skin2", [1.09, 1.59, 1.79], [0.013, 0.070, 0.145], 1.3),
    p(
        "Wholemilk",
        [2.55, 3.21, 3.77],
        [0.0011, 0.0024, 0.014],
        1.3,
    ),
];

/// The preset with this name, ignoring ASCII case.
pub fn find(name: &str) -> Option<&'static Preset> {
    PRESETS.iter().find(|p| p.name.eq_ignore_ascii_case(name))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lookup_ignores_case_and_rejects_unknown_names() {
        assert_eq!(find("marble").unwrap().eta, 1.5);
        assert_eq!(find("SKIN1").unwrap().sigma_a, [0.032, 0.17, 0.48]);
        assert!(find("jade").is_none());
        assert!(find("").is_none());
    }

    #[test]
    fn every_preset_makes_a_valid_profile() {
        for preset in &PRESETS {
            let profile = crate::Profile::from_preset(preset, 1.0).unwrap();
            let rd = profile.total_reflectance();
            assert!(
                rd.min_element() > 0.0 && rd.max_element() < 1.0,
                "{}",
                preset.name
            );
        }
    }
}
