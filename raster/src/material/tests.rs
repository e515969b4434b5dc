//! The shader's materials against the core: constant and texture-mapped parameters, every
//! diffusion model, and the local-integral source.

use super::*;
use crate::scene::TranslucentMaterial;
use std::path::PathBuf;

fn texture(values: &[Vec3], width: u32) -> Arc<Texture> {
    Arc::new(Texture::from_linear(
        PathBuf::from("test.png"),
        width,
        values.len() as u32 / width,
        values.to_vec(),
    ))
}

fn translucent(medium: Medium) -> TranslucentShader {
    translucent_with(ProfileModel::Dipole, medium)
}

fn translucent_with(model: ProfileModel, medium: Medium) -> TranslucentShader {
    match Shader::new(&Material::Translucent(TranslucentMaterial {
        name: "m".into(),
        medium,
        model,
        specular: None,
    }))
    .unwrap()
    {
        Shader::Translucent(t) => *t,
        Shader::Lambert { .. } => unreachable!(),
    }
}

/// A material of `model` given by K_d and a distance: ℓ_d (`diffuse`) or ℓ_u, η 1.4.
fn reflectance_with(
    model: ProfileModel,
    kd: ColorParam,
    distance: ScalarParam,
    diffuse: bool,
) -> TranslucentShader {
    translucent_with(
        model,
        Medium::Reflectance {
            kd,
            distance: if diffuse {
                Distance::DiffuseMeanFreePath(distance)
            } else {
                Distance::MeanFreePath(distance)
            },
            eta: 1.4,
        },
    )
}

/// A distance map `texture` over [min, max] where `textured`, else the constant (0.3, 0.2, 0.1).
fn distance_param(textured: bool, texture: &Arc<Texture>, min: f32, max: f32) -> ScalarParam {
    if textured {
        ScalarParam::Texture {
            texture: texture.clone(),
            min,
            max,
        }
    } else {
        ScalarParam::Constant(Vec3::new(0.3, 0.2, 0.1))
    }
}

#[test]
fn constant_reflectance_matches_the_core() {
    let kd = Vec3::new(0.8, 0.5, 0.3);
    let shader = translucent(Medium::Reflectance {
        kd: ColorParam::Constant(kd),
        distance: Distance::MeanFreePath(ScalarParam::Constant(Vec3::splat(0.2))),
        eta: 1.3,
    });
    let p = shader.at(Vec2::ZERO).unwrap().profile;
    assert!((p.total_reflectance() - kd).abs().max_element() < 1e-5);
    assert!((p.mean_free_path() - Vec3::splat(0.2)).abs().max_element() < 1e-6);
    assert!(!shader.is_textured());
}

#[test]
fn textured_mean_free_path_maps_logarithmically() {
    // A 2×1 texture: t = 0 on the left, t = 1 on the right; clamp-free lookups at texel
    // centres.
    let tex = texture(&[Vec3::ZERO, Vec3::ONE], 2);
    let shader = translucent(Medium::Reflectance {
        kd: ColorParam::Constant(Vec3::splat(0.6)),
        distance: Distance::MeanFreePath(ScalarParam::Texture {
            texture: tex,
            min: 0.01,
            max: 1.0,
        }),
        eta: 1.3,
    });
    assert!(shader.is_textured());
    let left = shader
        .at(Vec2::new(0.25, 0.5))
        .unwrap()
        .profile
        .mean_free_path();
    let right = shader
        .at(Vec2::new(0.75, 0.5))
        .unwrap()
        .profile
        .mean_free_path();
    assert!(
        (left.x - 0.01).abs() < 1e-6 && (right.x - 1.0).abs() < 1e-5,
        "{left} {right}"
    );
    // K from the single table equals the table's own lookup at that ℓ.
    let term = shader.local_term(0.1, 1e-4).unwrap();
    let point = shader.at(Vec2::new(0.75, 0.5)).unwrap();
    let LocalIntegral::Single(table) = &term else {
        panic!("expected a single table")
    };
    assert_eq!(
        term.lookup(&point),
        table.local_term(point.profile.mean_free_path())
    );
}

/// A texture-mapped K_d takes K from the core's tables over K_d at the texel's K_d (their
/// interpolation error is tested in the core, `kd_tables.rs`).
#[test]
fn textured_reflectance_takes_k_from_the_tables_over_kd() {
    let kd = Vec3::new(0.3, 0.55, 0.9);
    let tex = texture(&[kd], 1);
    let shader = translucent(Medium::Reflectance {
        kd: ColorParam::Texture(tex),
        distance: Distance::MeanFreePath(ScalarParam::Constant(Vec3::splat(0.05))),
        eta: 1.4,
    });
    let point = shader.at(Vec2::splat(0.5)).unwrap();
    assert!((point.profile.total_reflectance() - kd).abs().max_element() < 1e-4);
    let alpha = 0.07;
    let term = shader
        .local_term(alpha, alpha / 1024.0)
        .unwrap()
        .lookup(&point);
    // The tables over K_d with the dense grid over the texture's range (K_d from its smallest
    // to its largest channel, the one ℓ_u): the same bits.
    let tables = LocalIntegralByKd::new(1.4, alpha, alpha / 1024.0).unwrap();
    let ell = point.profile.mean_free_path();
    let plain = tables.local_term(kd, ell);
    let want = tables
        .with_range((0.3, 0.9), (0.05, 0.05))
        .local_term(kd, ell);
    assert_eq!(term, want);
    assert_eq!(term.alpha(), alpha);
    // The grid adds little to the tables' own interpolation.
    let rel = ((term.k() - plain.k()) / plain.k()).abs().max_element();
    assert!(rel < 5e-4, "{} vs {}", term.k(), plain.k());
}

#[test]
fn invalid_parameters_name_the_material() {
    let m = Material::Translucent(TranslucentMaterial {
        name: "wax".into(),
        medium: Medium::Coefficients {
            sigma_a: Vec3::new(1.0, -1.0, 1.0),
            sigma_s_prime: Vec3::ONE,
            eta: 1.3,
        },
        model: ProfileModel::default(),
        specular: None,
    });
    let err = Shader::new(&m).unwrap_err();
    let message = err.to_string();
    assert!(
        message.contains("wax") && message.contains("sigma_a"),
        "{err}"
    );
    // The core's error is kept as the source.
    let source = std::error::Error::source(&err).expect("a source");
    assert!(source.downcast_ref::<ParamError>().is_some(), "{source:?}");
    let m = Material::Translucent(TranslucentMaterial {
        name: "stone".into(),
        medium: Medium::Preset {
            name: "granite".into(),
            mm_per_unit: 1.0,
        },
        model: ProfileModel::default(),
        specular: None,
    });
    let err = Shader::new(&m).unwrap_err();
    assert_eq!(
        err.to_string(),
        "material 'stone': unknown preset 'granite'"
    );
}

/// Every way of giving a material builds the profile the core builds for the same parameters
/// under the material's model, the same bits.
#[test]
fn every_form_builds_the_models_profile() {
    let marble = presets::find("marble").unwrap();
    let (sa, ss) = (Vec3::new(0.02, 0.05, 0.3), Vec3::new(10.0, 12.0, 14.0));
    let (kd, ell) = (Vec3::new(0.8, 0.5, 0.3), Vec3::new(0.2, 0.1, 0.05));
    for model in ProfileModel::ALL {
        let cases = [
            (
                Medium::Preset {
                    name: "marble".into(),
                    mm_per_unit: 10.0,
                },
                Profile::from_preset_with(model, marble, 10.0),
            ),
            (
                Medium::Coefficients {
                    sigma_a: sa,
                    sigma_s_prime: ss,
                    eta: 1.33,
                },
                Profile::from_coefficients_with(model, sa, ss, 1.33),
            ),
            (
                Medium::Reflectance {
                    kd: ColorParam::Constant(kd),
                    distance: Distance::MeanFreePath(ScalarParam::Constant(ell)),
                    eta: 1.4,
                },
                Profile::from_reflectance_with(model, kd, CoreDistance::MeanFreePath(ell), 1.4),
            ),
            (
                Medium::Reflectance {
                    kd: ColorParam::Constant(kd),
                    distance: Distance::DiffuseMeanFreePath(ScalarParam::Constant(ell)),
                    eta: 1.4,
                },
                Profile::from_reflectance_with(
                    model,
                    kd,
                    CoreDistance::DiffuseMeanFreePath(ell),
                    1.4,
                ),
            ),
        ];
        for (medium, want) in cases {
            let shader = translucent_with(model, medium);
            let got = shader.at(Vec2::splat(0.5)).unwrap().profile;
            assert_eq!(got.model(), model);
            assert_eq!(got, want.unwrap(), "{}", model.name());
            // (The dipole's in double precision, the profile's decay rate in single.)
            let (smallest, own) = (
                shader.smallest_diffuse_mean_free_path(),
                got.diffuse_mean_free_path(),
            );
            assert!(
                ((smallest - own) / own).abs().max_element() < 1e-6,
                "{smallest} vs {own}"
            );
        }
    }
}

/// A texture-mapped K_d is inverted by the model's own Rd_total: Burley's albedo is K_d itself,
/// the better dipole's α′ gives back K_d (to its inverter's accuracy), and K comes from that
/// model's tables over K_d.
#[test]
fn textured_reflectance_follows_the_model() {
    let kd = Vec3::new(0.3, 0.55, 0.9);
    let ell = Vec3::splat(0.05);
    for model in ProfileModel::ALL {
        let shader = translucent_with(
            model,
            Medium::Reflectance {
                kd: ColorParam::Texture(texture(&[kd], 1)),
                distance: Distance::MeanFreePath(ScalarParam::Constant(ell)),
                eta: 1.4,
            },
        );
        let point = shader.at(Vec2::splat(0.5)).unwrap();
        assert_eq!(point.profile.model(), model);
        let reflectance = point.profile.total_reflectance();
        assert!(
            (reflectance - kd).abs().max_element() < 1e-4,
            "{}: {reflectance} vs {kd}",
            model.name()
        );
        if let ProfileModel::Burley(_) = model {
            assert_eq!(
                point.profile.albedo_parameters(),
                kd.to_array().map(f64::from)
            );
        }
        let alpha = 0.07;
        let term = shader
            .local_term(alpha, alpha / 1024.0)
            .unwrap()
            .lookup(&point);
        let want = LocalIntegralByKd::for_model(model, 1.4, alpha, alpha / 1024.0)
            .unwrap()
            .with_range((0.3, 0.9), (0.05, 0.05))
            .local_term(kd, point.profile.mean_free_path());
        assert_eq!(term, want, "{}", model.name());
    }
}

/// ℓ_d is converted with the classical dipole's α′ under every model, at textured points as for
/// constants: the point's ℓ_u is the core's for the same (K_d, ℓ_d).
#[test]
fn textured_diffuse_mean_free_path_converts_with_the_dipole() {
    let kd = Vec3::new(0.2, 0.6, 0.95);
    let ell_d = Vec3::new(0.3, 0.2, 0.1);
    for model in ProfileModel::ALL {
        let shader = translucent_with(
            model,
            Medium::Reflectance {
                kd: ColorParam::Texture(texture(&[kd], 1)),
                distance: Distance::DiffuseMeanFreePath(ScalarParam::Constant(ell_d)),
                eta: 1.3,
            },
        );
        let got = shader
            .at(Vec2::splat(0.5))
            .unwrap()
            .profile
            .mean_free_path();
        let want = Profile::from_reflectance_with(
            model,
            kd,
            CoreDistance::DiffuseMeanFreePath(ell_d),
            1.3,
        )
        .unwrap()
        .mean_free_path();
        assert!(
            ((got - want) / want).abs().max_element() < 1e-5,
            "{}: {got} vs {want}",
            model.name()
        );
    }
}

/// The smallest decay length over a textured K_d (and ℓ_u) is the brute-force minimum over the
/// surface: the texel centres, where the extremes of a bilinear texture are, and points between
/// them for the K_d the decay length need not be monotone in (Burley's s(A) is not).
#[test]
fn smallest_decay_length_over_textures_is_the_surface_minimum() {
    // K_d on both sides of Burley's minimum of s(A) (at A ≈ 0.58) and ℓ_u over a decade; from
    // ℓ_d the minimum over K_d may lie between the ends (found on the grid of 65 K_d).
    let kd = texture(
        &[
            Vec3::new(0.2, 0.5, 0.95),
            Vec3::new(0.9, 0.6, 0.3),
            Vec3::new(0.5, 0.05, 0.7),
            Vec3::new(0.7, 0.9, 0.1),
        ],
        2,
    );
    let ell = texture(
        &[Vec3::ZERO, Vec3::splat(0.5), Vec3::ONE, Vec3::splat(0.25)],
        2,
    );
    for model in ProfileModel::ALL {
        let cases = [
            (true, false, false),
            (false, true, false),
            (true, true, false),
            (true, false, true),
        ];
        for (kd_textured, ell_textured, diffuse) in cases {
            let ell = if ell_textured {
                ScalarParam::Texture {
                    texture: ell.clone(),
                    min: 0.01,
                    max: 0.1,
                }
            } else {
                ScalarParam::Constant(Vec3::splat(0.05))
            };
            let kd = if kd_textured {
                ColorParam::Texture(kd.clone())
            } else {
                ColorParam::Constant(Vec3::new(0.3, 0.6, 0.9))
            };
            let shader = reflectance_with(model, kd, ell, diffuse);
            let bound = shader.smallest_diffuse_mean_free_path();
            // 2 × 2 texels, centres at 1/4 and 3/4: sampled at 1/64 steps, centres included.
            let mut brute = Vec3::INFINITY;
            for j in 0..64 {
                for i in 0..64 {
                    let uv = Vec2::new(i as f32, j as f32) / 64.0;
                    let p = shader.at(uv).unwrap().profile;
                    brute = brute.min(p.diffuse_mean_free_path());
                }
            }
            let name = model.name();
            assert!(
                (bound / brute).max_element() <= 1.0 + 1e-5,
                "{name}: {bound} above the surface's {brute}"
            );
            if !(kd_textured && ell_textured) {
                assert!(
                    (bound / brute).min_element() > 1.0 - 1e-4,
                    "{name}: {bound} below the surface's {brute}"
                );
            }
        }
    }
}

/// Texture-mapped K_d and radius together, every model: K from the tables (interpolated in K_d
/// between levels and in ℓ between powers of two) against K by quadrature at each point's own
/// profile, over K_d ∈ [0.05, 0.95] and ℓ_u ∈ [α/32, 8α] (a `radius` texture, already times
/// `radius_scale` here), off the table levels in both.
#[test]
fn textured_albedo_and_radius_interpolate_k_within_half_a_percent() {
    // 2 texels along u for K_d (each channel its own range), 2 along v for the distance; uv
    // between the texel centres (0.25 and 0.75) interpolates both continuously.
    let kd = texture(
        &[Vec3::new(0.005, 0.2, 0.35), Vec3::new(0.995, 0.8, 0.65)],
        2,
    );
    let radius = texture(&[Vec3::new(1.0, 0.8, 0.6), Vec3::new(0.0, 0.2, 0.4)], 1);
    let alpha = 0.04;
    let (lo, hi) = (alpha / 32.0, 8.0 * alpha);
    for model in ProfileModel::ALL {
        let shader = translucent_with(
            model,
            Medium::Reflectance {
                kd: ColorParam::Texture(kd.clone()),
                distance: Distance::MeanFreePath(ScalarParam::Texture {
                    texture: radius.clone(),
                    min: lo,
                    max: hi,
                }),
                eta: 1.4,
            },
        );
        let source = shader.local_term(alpha, alpha / 1024.0).unwrap();
        let mut worst = 0.0f32;
        let steps = 41;
        for i in 0..steps {
            for j in 0..steps {
                let uv = Vec2::new(
                    0.25 + 0.5 * i as f32 / (steps - 1) as f32,
                    0.25 + 0.5 * j as f32 / (steps - 1) as f32,
                );
                let point = shader.at(uv).unwrap();
                let table = source.lookup(&point).k();
                let exact = source.exact(&point).k();
                let ell = point.profile.mean_free_path();
                assert!(
                    ell.cmpge(Vec3::splat(lo * 0.999)).all()
                        && ell.cmple(Vec3::splat(hi * 1.001)).all(),
                    "{ell}"
                );
                let rel = ((table - exact) / exact).abs().max_element();
                assert!(exact.min_element() > 0.0 && rel.is_finite(), "{exact}");
                worst = worst.max(rel);
            }
        }
        std::println!(
            "{}: worst relative K error {:.3}%",
            model.name(),
            worst * 100.0
        );
        assert!(worst < 0.005, "{}: {worst}", model.name());
    }
}

/// The second pass's cheap parameters agree with the profile built at the same point, for
/// textured K_d and either distance, every model.
#[test]
fn parameters_at_match_the_profile_at_the_point() {
    let kd = texture(&[Vec3::new(0.1, 0.5, 0.9), Vec3::new(0.7, 0.3, 0.05)], 2);
    let ell = texture(&[Vec3::splat(0.2), Vec3::splat(0.9)], 2);
    for model in ProfileModel::ALL {
        for diffuse in [false, true] {
            let param = ScalarParam::Texture {
                texture: ell.clone(),
                min: 0.01,
                max: 2.0,
            };
            let shader = reflectance_with(model, ColorParam::Texture(kd.clone()), param, diffuse);
            for u in [0.1, 0.3, 0.62, 0.9] {
                let uv = Vec2::new(u, 0.5);
                let profile = shader.at(uv).unwrap().profile;
                let [total, ell_u] = shader.parameters_at(uv);
                let close = |a: Vec3, b: Vec3| ((a - b) / b).abs().max_element() < 1e-3;
                assert!(
                    close(total, profile.total_reflectance()),
                    "{} {u}: {total} vs {}",
                    model.name(),
                    profile.total_reflectance()
                );
                assert!(
                    close(ell_u, profile.mean_free_path()),
                    "{} {u}: {ell_u} vs {}",
                    model.name(),
                    profile.mean_free_path()
                );
            }
        }
    }
}

/// The material written into one kept value, point after point and material after material
/// (textured K_d, radius, both, or neither; every model; either distance), is `at`'s, bit for
/// bit.
#[test]
fn material_written_in_place_equals_material_made_anew() {
    let kd = texture(&[Vec3::new(0.1, 0.5, 0.9), Vec3::new(0.7, 0.3, 0.05)], 2);
    let ell = texture(&[Vec3::splat(0.2), Vec3::new(0.9, 0.4, 0.1)], 2);
    let mut kept = translucent(Medium::Reflectance {
        kd: ColorParam::Constant(Vec3::splat(0.5)),
        distance: Distance::MeanFreePath(ScalarParam::Constant(Vec3::ONE)),
        eta: 1.3,
    })
    .at(Vec2::ZERO)
    .unwrap();
    let mut checked = 0;
    for model in ProfileModel::ALL {
        for diffuse in [false, true] {
            for (textured_kd, textured_ell) in [(true, true), (true, false), (false, true)] {
                let param = distance_param(textured_ell, &ell, 0.01, 2.0);
                let kd = if textured_kd {
                    ColorParam::Texture(kd.clone())
                } else {
                    ColorParam::Constant(Vec3::new(0.8, 0.6, 0.4))
                };
                let shader = reflectance_with(model, kd, param, diffuse);
                for u in [0.1, 0.3, 0.62, 0.9] {
                    let uv = Vec2::new(u, 1.0 - u);
                    let want = shader.at(uv).unwrap();
                    shader.at_into(uv, &mut kept).unwrap();
                    assert_eq!(kept.profile, want.profile, "{} {u}", model.name());
                    assert_eq!(kept.kd, want.kd, "{} {u}", model.name());
                    checked += 1;
                }
            }
        }
    }
    assert_eq!(checked, ProfileModel::ALL.len() * 2 * 3 * 4);
}

/// Every point of a texture-mapped K_d reads K from the dense grid over the range the textures
/// reach (not the slower tables), with either distance textured or constant, every model.
#[test]
fn textured_points_fall_inside_the_k_grid() {
    let kd = texture(&[Vec3::new(0.1, 0.5, 0.9), Vec3::new(0.7, 0.3, 0.05)], 2);
    let ell = texture(&[Vec3::splat(0.0), Vec3::new(1.0, 0.4, 0.1)], 2);
    let alpha = 0.04;
    for model in ProfileModel::ALL {
        for diffuse in [false, true] {
            for textured_ell in [false, true] {
                let param = distance_param(textured_ell, &ell, 0.005, 0.5);
                let shader =
                    reflectance_with(model, ColorParam::Texture(kd.clone()), param, diffuse);
                let LocalIntegral::ByKd(tables) = shader.local_term(alpha, alpha / 1024.0).unwrap()
                else {
                    panic!("a textured K_d takes the tables over K_d");
                };
                assert_eq!(tables.validate(), Ok(()));
                for i in 0..=20 {
                    for j in 0..=20 {
                        let uv = Vec2::new(i as f32 / 20.0, j as f32 / 20.0);
                        let point = shader.at(uv).unwrap();
                        let (kd, ell) = (point.kd.unwrap(), point.profile.mean_free_path());
                        assert!(
                            tables.in_grid(kd, ell),
                            "{} diffuse {diffuse}: {kd} {ell}",
                            model.name()
                        );
                    }
                }
            }
        }
    }
}
