//! How many irradiance samples a render places: the automatic count (`samples = "auto"`, the
//! default), the memory-sized cap on it, and the warning when the samples are too far apart
//! for the material (`docs/physics.md` §7).
//!
//! The dipole profile (Jensen et al. 2001) falls off as e^(−σ_tr·r)/r², so the
//! distance that matters is the **diffuse mean free path ℓ_d = 1/σ_tr**. One Poisson-disk set
//! covers every translucent object, so the shared spacing must resolve the smallest ℓ_d of any
//! channel of any translucent material (for a texture-mapped ℓ, the smallest the texture
//! gives):
//!
//! ```text
//! spacing s = c · ℓ_d,min                      c = AUTO_SPACING = 1/4
//! N         = ⌈A / ((√3/2) · s²)⌉              hexagonal packing over the translucent area A
//!                                              (hex_spacing in sampling/surface.rs inverts it)
//! N         = clamp(N, MIN_AUTO_SAMPLES, max_samples)
//! ```
//!
//! c = 1/4 puts the default scene's marble bunny (A = 218.7 cm², ℓ_d = 0.395 cm in blue) at
//! 25,900 samples, a little above the 23,000 of the talk's Figure 1 it was tuned at.
//!
//! `max_samples` defaults to half the memory the system reports available (Linux:
//! `MemAvailable` in `/proc/meminfo`) at [`PEAK_BYTES_PER_SAMPLE`] each, or
//! [`FALLBACK_MAX_SAMPLES`] where that is unknown, never more than the hard limit
//! [`MAX_SAMPLES`] = 2²⁵.
//!
//! Whatever chose the count (auto with its cap, an explicit count or spacing, a baked set), a
//! spacing above [`WARN_SPACING`] · ℓ_d,min gets one warning ([`DensityPlan::warning`]): the
//! unsplit methods then show blotches around the samples (and a mostly black image from
//! [`BLACK_SPACING`] = 100 ℓ_d on), the split methods hard, stair-stepped shadow edges.

use super::RenderError;
use super::prepare::Prepared;
use crate::material::Shader;
use crate::sampling::{SampleTarget, hex_spacing, triangle_area};
use crate::scene::{MAX_SAMPLES, RenderSettings, SampleDensity, SampleRequest};
use lucent_core::Method;

/// c: the automatic spacing as a fraction of the smallest diffuse mean free path ℓ_d.
pub const AUTO_SPACING: f32 = 0.25;

/// A spacing above this multiple of ℓ_d,min gets the under-resolution warning (4× the
/// automatic spacing, 1/16 of its count).
pub const WARN_SPACING: f32 = 1.0;

/// At this multiple of a channel's ℓ_d (and above) the unsplit methods lose most of that
/// channel's light: the profile falls off as e^(−r/ℓ_d), so most shading points get almost
/// nothing even from the nearest sample and only spots at the samples stay lit (the mean
/// relative error of the exhaustive sum passes 50% between 40× and 110× ℓ_d; below, blotches).
pub const BLACK_SPACING: f32 = 100.0;

/// The automatic count never goes below this, so that the samples still follow the surface's
/// shape when ℓ_d is large against the objects.
pub const MIN_AUTO_SAMPLES: u32 = 4096;

/// Peak memory of a render per irradiance sample (placement, lighting, caches), bytes.
pub const PEAK_BYTES_PER_SAMPLE: u64 = 600;

/// The default cap on the automatic count where the available memory is unknown (2²², about
/// 2.5 GB at [`PEAK_BYTES_PER_SAMPLE`]).
pub const FALLBACK_MAX_SAMPLES: u32 = 1 << 22;

/// The hard limit on any count.
const HARD_MAX: u32 = MAX_SAMPLES as u32;

/// Channel names, for messages.
const CHANNELS: [&str; 3] = ["red", "green", "blue"];

/// Where a render's sample count came from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DensityOrigin {
    /// `samples = "auto"`, with the cap that applied and whether it cut the count.
    Auto {
        /// The cap (`max_samples`, or the machine's default).
        max: u32,
        /// True if the count that resolves ℓ_d was more than `max`.
        capped: bool,
    },
    /// An explicit `samples = N`.
    Count,
    /// An explicit `spacing = s` (scene units).
    Spacing(f32),
    /// A baked sample set (`--samples-from`).
    Baked,
}

/// The translucent material with the smallest diffuse mean free path.
#[derive(Clone, Debug, PartialEq)]
pub struct Finest {
    /// Object index in the scene.
    pub object: usize,
    /// Object name.
    pub object_name: String,
    /// Material name.
    pub material: String,
    /// Channel (0 red, 1 green, 2 blue).
    pub channel: usize,
    /// ℓ_d = 1/σ_tr there (scene units).
    pub ell_d: f32,
    /// The object's smallest ℓ_d in each channel (`ell_d` is the least of them).
    pub channels: [f32; 3],
}

/// The sample count of one render and what it resolves.
#[derive(Clone, Debug, PartialEq)]
pub struct DensityPlan {
    /// Where the count came from.
    pub origin: DensityOrigin,
    /// Samples over all translucent objects.
    pub count: u32,
    /// Translucent surface area (scene units²).
    pub area: f64,
    /// The smallest ℓ_d.
    pub finest: Finest,
}

impl DensityPlan {
    /// What the sample placement is given.
    pub fn density(&self) -> SampleDensity {
        match self.origin {
            DensityOrigin::Spacing(s) => SampleDensity::Spacing(s),
            _ => SampleDensity::Count(self.count),
        }
    }

    /// The sample spacing: the given one, or the hexagonal-packing spacing of the count.
    pub fn spacing(&self) -> f32 {
        match self.origin {
            DensityOrigin::Spacing(s) => s,
            _ => hex_spacing(self.area, self.count),
        }
    }

    /// Spacing / ℓ_d,min.
    pub fn ratio(&self) -> f32 {
        self.spacing() / self.finest.ell_d
    }

    /// The count that resolves ℓ_d,min at the automatic spacing (not capped, maybe beyond the
    /// hard limit).
    pub fn resolving_count(&self) -> u64 {
        resolving_count(self.area, f64::from(self.finest.ell_d))
    }

    /// For the summary line: how the count was chosen and the spacing against ℓ_d, e.g.
    /// `auto: spacing 0.0988 = 0.25 ℓ_d` or `auto, capped at 4194304: spacing … = 1.3 ℓ_d`.
    pub fn describe(&self) -> String {
        let how = match self.origin {
            DensityOrigin::Auto { capped: false, .. } => "auto".to_string(),
            DensityOrigin::Auto { max, capped: true } => format!("auto, capped at {max}"),
            DensityOrigin::Count => "given".to_string(),
            DensityOrigin::Spacing(_) => "from spacing".to_string(),
            DensityOrigin::Baked => "baked".to_string(),
        };
        // Two decimals for the usual ratios (0.25 ℓ_d for auto); significant digits below
        // 0.1, where two decimals would print 0.00 for a dense set.
        let ratio = self.ratio();
        let ratio = if ratio < 0.1 {
            Sig(ratio).to_string()
        } else {
            format!("{ratio:.2}")
        };
        format!("{how}: spacing {:.3} = {ratio} ℓ_d", Sig(self.spacing()))
    }

    /// The under-resolution warning for `method`, if the spacing is above [`WARN_SPACING`] ·
    /// ℓ_d,min; `smoothing` is the split methods' factor k (α = k·√(A/N)).
    pub fn warning(&self, method: Method, smoothing: f32) -> Option<String> {
        let ratio = self.ratio();
        if !(ratio > WARN_SPACING) {
            return None;
        }
        let f = &self.finest;
        let why = match self.origin {
            DensityOrigin::Auto { max, .. } => {
                format!("samples = \"auto\" capped by max_samples = {max}")
            }
            DensityOrigin::Count => format!("samples = {}", self.count),
            DensityOrigin::Spacing(s) => format!("spacing = {}", Sig(s)),
            DensityOrigin::Baked => format!("a baked set of {} samples", self.count),
        };
        let name = method.name();
        // The unsplit methods sum the samples alone; the split ones smooth over α.
        let effect = match method {
            m if !m.is_split() && ratio >= BLACK_SPACING => {
                let spacing = self.spacing();
                let lost: Vec<&str> = (0..3)
                    .filter(|&c| spacing >= BLACK_SPACING * f.channels[c])
                    .map(|c| CHANNELS[c])
                    .collect();
                let why = "the profile falls off as e^(−r/ℓ_d), and most points are many ℓ_d \
                           from every sample";
                if lost.len() == 3 {
                    format!("{name} will render the object mostly black ({why})")
                } else {
                    format!(
                        "{name} will lose most of the object's {} light ({why}) and show \
                         blotches",
                        lost.join(" and ")
                    )
                }
            }
            m if !m.is_split() => format!(
                "{name} will show blotches (bright spots at the samples, dark between them)"
            ),
            _ => {
                let alpha = smoothing * (self.area / f64::from(self.count.max(1))).sqrt() as f32;
                format!(
                    "{name} will render hard, stair-stepped shadow edges (its smoothing radius \
                     α = {} is {}× ℓ_d)",
                    Sig(alpha),
                    Sig(alpha / f.ell_d)
                )
            }
        };
        let need = self.resolving_count();
        let fix = if need > u64::from(HARD_MAX) {
            // In exponent form: the count itself can be beyond u64 (and saturated to it).
            let estimate = resolving_estimate(self.area, f64::from(self.finest.ell_d));
            format!(
                "resolving it takes about {estimate:.2e} samples, more than the limit of \
                 {HARD_MAX} (check the scene's units and mm_per_unit)"
            )
        } else {
            let how = match self.origin {
                DensityOrigin::Auto { .. } => "raise max_samples / --max-samples",
                _ => "samples = \"auto\" / --samples auto gives that",
            };
            format!(
                "about {need} samples (spacing {} = ℓ_d/4) would resolve it ({how})",
                Sig(AUTO_SPACING * f.ell_d)
            )
        };
        Some(format!(
            "object '{}': irradiance samples {} apart ({why}) are {}× its smallest \
             diffuse mean free path ℓ_d = {} ({} channel of material '{}'): {effect}; {fix}",
            f.object_name,
            Sig(self.spacing()),
            Sig(ratio),
            Sig(f.ell_d),
            CHANNELS[f.channel],
            f.material,
        ))
    }
}

/// Three significant digits, without an exponent for everyday magnitudes.
struct Sig(f32);

impl std::fmt::Display for Sig {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let x = self.0;
        if x == 0.0 || !x.is_finite() {
            return write!(f, "{x}");
        }
        let digits = 2 - x.abs().log10().floor() as i32;
        if (0..=6).contains(&digits) {
            write!(f, "{x:.*}", digits as usize)
        } else {
            write!(f, "{x:.2e}")
        }
    }
}

/// The count at spacing [`AUTO_SPACING`] · `ell_d` over `area`: ⌈A / ((√3/2) s²)⌉, saturated.
pub fn resolving_count(area: f64, ell_d: f64) -> u64 {
    let n = resolving_estimate(area, ell_d).ceil();
    if n.is_finite() { n as u64 } else { u64::MAX }
}

/// [`resolving_count`] before rounding and saturation: A / ((√3/2) s²).
fn resolving_estimate(area: f64, ell_d: f64) -> f64 {
    let s = f64::from(AUTO_SPACING) * ell_d;
    area / (0.75f64.sqrt() * s * s)
}

/// The automatic count for `area` and `ell_d` under the cap `max`, and whether the cap cut it.
pub fn auto_count(area: f64, ell_d: f64, max: u32) -> (u32, bool) {
    let n = resolving_count(area, ell_d);
    let floored = n.max(u64::from(MIN_AUTO_SAMPLES));
    if floored > u64::from(max) {
        (max, n > u64::from(max))
    } else {
        (floored as u32, false)
    }
}

/// The default cap for `available` bytes of free memory (`None` = unknown): half of it at
/// [`PEAK_BYTES_PER_SAMPLE`], within [`MIN_AUTO_SAMPLES`]..=2²⁵.
pub fn max_samples_for_memory(available: Option<u64>) -> u32 {
    match available {
        Some(bytes) => (bytes / 2 / PEAK_BYTES_PER_SAMPLE)
            .clamp(u64::from(MIN_AUTO_SAMPLES), u64::from(HARD_MAX)) as u32,
        None => FALLBACK_MAX_SAMPLES,
    }
}

/// `MemAvailable` of a `/proc/meminfo` text, in bytes.
pub fn parse_meminfo(text: &str) -> Option<u64> {
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let mut words = line["MemAvailable:".len()..].split_whitespace();
    let value: u64 = words.next()?.parse().ok()?;
    match words.next() {
        Some("kB") => value.checked_mul(1024),
        None => Some(value),
        Some(_) => None,
    }
}

/// The memory the system reports available, if it does (Linux).
pub fn available_memory() -> Option<u64> {
    std::fs::read_to_string("/proc/meminfo")
        .ok()
        .as_deref()
        .and_then(parse_meminfo)
}

/// The default `max_samples` of this machine.
pub fn default_max_samples() -> u32 {
    max_samples_for_memory(available_memory())
}

/// The smallest ℓ_d over the translucent objects' materials and channels (the first object
/// wins ties); `None` without translucent objects.
pub fn finest(prep: &Prepared) -> Option<Finest> {
    let mut best: Option<Finest> = None;
    for object in prep.translucent_objects() {
        let Shader::Translucent(shader) = prep.shader_of(object) else {
            continue;
        };
        let ell = shader.smallest_diffuse_mean_free_path();
        let channel = (0..3).fold(0, |b, c| if ell[c] < ell[b] { c } else { b });
        if best.as_ref().is_none_or(|b| ell[channel] < b.ell_d) {
            best = Some(Finest {
                object,
                object_name: prep.scene.objects[object].name.clone(),
                material: shader.name.clone(),
                channel,
                ell_d: ell[channel],
                channels: ell.to_array(),
            });
        }
    }
    best
}

/// The translucent surface area, summed in the order the sample placement sums it.
pub fn translucent_area(prep: &Prepared) -> f64 {
    prep.translucent_objects()
        .iter()
        .flat_map(|&o| {
            let (a, b) = (
                prep.first_triangle[o] as usize,
                prep.first_triangle[o + 1] as usize,
            );
            &prep.triangles[a..b]
        })
        .map(triangle_area)
        .sum()
}

/// The sample count of a render of `settings` (`baked`: the size of a baked set in use);
/// `None` without translucent objects.
pub fn plan(
    prep: &Prepared,
    settings: &RenderSettings,
    baked: Option<usize>,
) -> Result<Option<DensityPlan>, RenderError> {
    let Some(finest) = finest(prep) else {
        return Ok(None);
    };
    let area = translucent_area(prep);
    let (origin, count) = match (baked, settings.samples) {
        (Some(n), _) => (DensityOrigin::Baked, u32::try_from(n).unwrap_or(u32::MAX)),
        (None, SampleRequest::Auto) => {
            let max = settings.max_samples.unwrap_or_else(default_max_samples);
            let (count, capped) = auto_count(area, f64::from(finest.ell_d), max);
            (DensityOrigin::Auto { max, capped }, count)
        }
        (None, SampleRequest::Density(SampleDensity::Count(n))) => (DensityOrigin::Count, n),
        (None, SampleRequest::Density(SampleDensity::Spacing(s))) => {
            let n = SampleTarget::Spacing(s)
                .resolve(area)
                .map_err(RenderError::Sampling)?;
            (DensityOrigin::Spacing(s), n)
        }
    };
    Ok(Some(DensityPlan {
        origin,
        count,
        area,
        finest,
    }))
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::render::{RenderOptions, render};
    use crate::scene::{SceneOrigin, default_scene, parse_scene};

    /// √3/2, the area per point of a unit hexagonal lattice, computed independently.
    const HEX: f64 = 0.866_025_403_784_438_6;

    #[test]
    fn the_count_is_the_hexagonal_packing_at_a_quarter_of_ell_d() {
        // A = 1, ℓ_d = 0.04: s = 0.01, N = 1 / (0.866… · 1e-4) = 11547.005… → 11548.
        assert_eq!(resolving_count(1.0, 0.04), 11_548);
        for (area, ell) in [(218.69, 0.395), (0.5, 0.0273), (64.0, 0.045), (3.0, 1e-3)] {
            let n = resolving_count(area, ell);
            let s = 0.25 * ell;
            assert_eq!(n, (area / (HEX * s * s)).ceil() as u64);
            // The spacing of N samples is at most ℓ_d/4, and one sample fewer would exceed it.
            let tol = 1.0 + 1e-6;
            assert!(
                f64::from(hex_spacing(area, n as u32)) <= s * tol,
                "{area} {ell}"
            );
            assert!(
                f64::from(hex_spacing(area, n as u32 - 1)) * tol > s,
                "{area} {ell}"
            );
        }
        assert_eq!(resolving_count(1.0, 0.0), u64::MAX);
    }

    #[test]
    fn the_count_is_floored_and_capped() {
        // Uncapped.
        assert_eq!(auto_count(1.0, 0.04, 1 << 25), (11_548, false));
        // The cap cuts it, and says so.
        assert_eq!(auto_count(1.0, 0.04, 10_000), (10_000, true));
        assert_eq!(auto_count(1e12, 1e-6, 1 << 25), (1 << 25, true));
        // The floor: a tiny area or a huge ℓ_d still gets MIN_AUTO_SAMPLES…
        assert_eq!(auto_count(1.0, 10.0, 1 << 25), (MIN_AUTO_SAMPLES, false));
        // … unless the cap is lower; that is not a cut of the resolving count.
        assert_eq!(auto_count(1.0, 10.0, 100), (100, false));
    }

    #[test]
    fn the_default_cap_follows_the_available_memory() {
        let gib = 1u64 << 30;
        // Half of 12 GiB at 600 bytes per sample.
        assert_eq!(
            max_samples_for_memory(Some(12 * gib)),
            (6 * gib / 600) as u32
        );
        assert_eq!(max_samples_for_memory(Some(1 << 50)), 1 << 25);
        assert_eq!(max_samples_for_memory(Some(1000)), MIN_AUTO_SAMPLES);
        assert_eq!(max_samples_for_memory(None), FALLBACK_MAX_SAMPLES);
        let default = default_max_samples();
        assert!((MIN_AUTO_SAMPLES..=1 << 25).contains(&default));
    }

    #[test]
    fn meminfo_is_parsed() {
        let text = "MemTotal:       24684084 kB\nMemFree:         7284724 kB\n\
                    MemAvailable:   22617188 kB\nBuffers:          123 kB\n";
        assert_eq!(parse_meminfo(text), Some(22_617_188 * 1024));
        assert_eq!(parse_meminfo("MemAvailable: 4096\n"), Some(4096));
        assert_eq!(parse_meminfo("MemTotal: 5 kB\n"), None);
        assert_eq!(parse_meminfo("MemAvailable: lots kB\n"), None);
        assert_eq!(parse_meminfo("MemAvailable: 5 MB\n"), None);
    }

    fn plan_of(scene: &crate::scene::Scene) -> DensityPlan {
        let prep = Prepared::new(scene).unwrap();
        plan(&prep, &scene.render, None).unwrap().unwrap()
    }

    #[test]
    fn the_default_scene_gets_at_least_its_23000_samples() {
        let mut scene = default_scene();
        scene.render.samples = SampleRequest::Auto;
        scene.render.max_samples = Some(1 << 25);
        let p = plan_of(&scene);
        // Marble at 10 mm per unit: ℓ_d = 1/√(3 σ_a (σ_a + σ_s′)) = 3.95 mm in blue.
        let (sa, ss) = (0.0071_f64, 3.00_f64);
        let ell = 0.1 / (3.0 * sa * (sa + ss)).sqrt();
        assert_eq!(
            (p.finest.channel, p.finest.object_name.as_str()),
            (2, "bunny")
        );
        assert!(
            (f64::from(p.finest.ell_d) / ell - 1.0).abs() < 1e-4,
            "{p:?}"
        );
        assert!((p.area - 218.69).abs() < 0.01, "{}", p.area);
        assert_eq!(
            p.origin,
            DensityOrigin::Auto {
                max: 1 << 25,
                capped: false
            }
        );
        assert_eq!(
            u64::from(p.count),
            resolving_count(p.area, f64::from(p.finest.ell_d))
        );
        assert_eq!(p.count, 25_879);
        assert!(p.count >= 23_000);
        assert_eq!(p.describe(), "auto: spacing 0.0988 = 0.25 ℓ_d");
        assert_eq!(p.warning(Method::Hierarchical, 1.5), None);
        // The shipped scene asks for the automatic count.
        let shipped = plan_of(&default_scene());
        assert_eq!(shipped.count, 25_879);
        assert!(matches!(shipped.origin, DensityOrigin::Auto { .. }));
    }

    #[test]
    fn the_shipped_scenes_keep_their_counts_and_would_get_these_automatically() {
        for (file, shipped, auto) in [
            ("sphere-shadow.toml", 23_000, MIN_AUTO_SAMPLES),
            ("textured-mfp.toml", 40_000, 576_149),
        ] {
            let path = format!("{}/../scenes/{file}", env!("CARGO_MANIFEST_DIR"));
            let mut scene = crate::scene::load_scene(std::path::Path::new(&path)).unwrap();
            let p = plan_of(&scene);
            assert_eq!(
                (p.origin, p.count),
                (DensityOrigin::Count, shipped),
                "{file}"
            );
            // The shipped counts resolve ℓ_d for their method: no warning.
            assert_eq!(
                p.warning(scene.render.method, scene.render.smoothing),
                None,
                "{file}"
            );
            scene.render.samples = SampleRequest::Auto;
            scene.render.max_samples = Some(1 << 25);
            assert_eq!(plan_of(&scene).count, auto, "{file}");
        }
    }

    /// A scene of translucent spheres: `(name, radius, material TOML)` each.
    fn spheres(objects: &[(&str, f32, &str)], render: &str) -> crate::scene::Scene {
        let mut text = String::from(
            "[camera]\nposition = [0, -10, 0]\ntarget = [0, 0, 0]\nfov = 30\nwidth = 16\n\
             height = 16\n[[light]]\ntype = 'directional'\ndirection = [0, 1, 0]\n\
             irradiance = 1\n",
        );
        for (i, (name, radius, material)) in objects.iter().enumerate() {
            text += &format!(
                "[[object]]\nname = '{name}'\nshape = 'sphere'\nradius = {radius}\n\
                 segments = 32\ntranslate = [{}, 0, 0]\nmaterial = 'm{i}'\n\
                 [material.m{i}]\ntype = 'translucent'\n{material}\n",
                3.0 * i as f32
            );
        }
        text += &format!("[render]\n{render}\n");
        let origin = SceneOrigin::Embedded {
            name: "t.toml".into(),
            files: vec![],
        };
        parse_scene(&text, &origin).unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn the_smallest_ell_d_of_any_object_sets_the_spacing() {
        let skin = "preset = 'skin1'\nmm_per_unit = 25";
        let marble = "preset = 'marble'\nmm_per_unit = 10";
        let scene = spheres(
            &[("stone", 1.0, marble), ("head", 0.2, skin)],
            "max_samples = 33554432",
        );
        let p = plan_of(&scene);
        // skin1 blue: σ_a = 0.48, σ_s′ = 1.01 per mm, at 25 mm per unit.
        let ell = 1.0 / (25.0 * (3.0 * 0.48 * (0.48 + 1.01_f64)).sqrt());
        assert_eq!(p.finest.object_name, "head");
        assert_eq!(p.finest.material, "m1");
        assert_eq!(p.finest.channel, 2);
        assert!((f64::from(p.finest.ell_d) / ell - 1.0).abs() < 1e-4);
        // Both spheres' area counts, at the head's spacing.
        let head = spheres(&[("head", 0.2, skin)], "samples = 'auto'");
        let alone = plan_of(&head);
        assert!(p.area > 10.0 * alone.area);
        assert_eq!(u64::from(p.count), resolving_count(p.area, ell));
        assert_eq!(alone.finest.ell_d, p.finest.ell_d);
    }

    /// A plan with skin1's ℓ_d ratios across the channels (red 5.4×, green 2× the blue).
    fn plan_with(origin: DensityOrigin, count: u32, ell_d: f32) -> DensityPlan {
        DensityPlan {
            origin,
            count,
            area: 227.0,
            finest: Finest {
                object: 0,
                object_name: "head".into(),
                material: "skin".into(),
                channel: 2,
                ell_d,
                channels: [5.4 * ell_d, 2.0 * ell_d, ell_d],
            },
        }
    }

    #[test]
    fn the_warning_names_the_object_the_spacing_and_the_cure_per_method() {
        // The scanned head: 227 units², skin1 at 25 mm per unit, 23000 samples.
        let p = plan_with(DensityOrigin::Count, 23_000, 0.0273);
        let split = p.warning(Method::EdgeAware, 1.5).unwrap();
        assert_eq!(
            split,
            "object 'head': irradiance samples 0.107 apart (samples = 23000) are 3.91× its \
             smallest diffuse mean free path ℓ_d = 0.0273 (blue channel of material 'skin'): \
             edge-aware will render hard, stair-stepped shadow edges (its smoothing radius α = \
             0.149 is 5.46× ℓ_d); about 5627169 samples (spacing 0.00683 = ℓ_d/4) would resolve \
             it (samples = \"auto\" / --samples auto gives that)"
        );
        let lg = p.warning(Method::LocalGlobal, 1.5).unwrap();
        assert!(lg.contains("local-global will render hard, stair-stepped shadow edges"));
        let h = p.warning(Method::Hierarchical, 1.5).unwrap();
        assert!(
            h.contains("hierarchical will show blotches (bright spots at the samples"),
            "{h}"
        );
        // Far beyond ℓ_d in blue and green, not in red: those two channels' light is lost.
        let sparse = plan_with(DensityOrigin::Count, 23_000, 0.0005);
        assert!(sparse.ratio() > 2.0 * BLACK_SPACING);
        assert!(sparse.spacing() < 5.4 * 0.0005 * BLACK_SPACING);
        for m in [Method::Hierarchical, Method::Exhaustive] {
            let w = sparse.warning(m, 1.5).unwrap();
            let lost = "will lose most of the object's green and blue light (the profile";
            assert!(w.contains(lost), "{w}");
            assert!(
                w.ends_with("(check the scene's units and mm_per_unit)"),
                "{w}"
            );
        }
        // Beyond in every channel: black.
        let black = plan_with(DensityOrigin::Count, 23_000, 0.0001);
        let w = black.warning(Method::Exhaustive, 1.5).unwrap();
        assert!(
            w.contains("exhaustive will render the object mostly black"),
            "{w}"
        );
        // Just below the black threshold: blotches.
        let blotchy = plan_with(DensityOrigin::Count, 23_000, 0.107 / 99.0);
        let w = blotchy.warning(Method::Hierarchical, 1.5).unwrap();
        assert!(w.contains("hierarchical will show blotches"), "{w}");
        // Capped auto points at the cap.
        let capped = plan_with(
            DensityOrigin::Auto {
                max: 100_000,
                capped: true,
            },
            100_000,
            0.0273,
        );
        let w = capped.warning(Method::EdgeAware, 1.5).unwrap();
        assert!(
            w.contains("(samples = \"auto\" capped by max_samples = 100000)"),
            "{w}"
        );
        assert!(w.contains("raise max_samples / --max-samples"), "{w}");
        assert_eq!(
            capped.describe(),
            "auto, capped at 100000: spacing 0.0512 = 1.88 ℓ_d"
        );
        // A dense set keeps significant digits of its ratio (two decimals would give 0.02).
        let dense = plan_with(DensityOrigin::Count, 4_000_000, 0.4);
        assert_eq!(dense.describe(), "given: spacing 0.00810 = 0.0202 ℓ_d");
        // Spacings and baked sets.
        let s = plan_with(DensityOrigin::Spacing(0.05), 104_830, 0.0273);
        assert!(
            s.warning(Method::EdgeAware, 1.5)
                .unwrap()
                .contains("(spacing = 0.0500)")
        );
        let b = plan_with(DensityOrigin::Baked, 23_000, 0.0273);
        let w = b.warning(Method::EdgeAware, 1.5).unwrap();
        assert!(w.contains("(a baked set of 23000 samples)"), "{w}");
        // Beyond the hard limit: the units are suspect.
        let tiny = plan_with(DensityOrigin::Count, 23_000, 1e-4);
        let w = tiny.warning(Method::Exhaustive, 1.5).unwrap();
        assert!(w.contains("more than the limit of 33554432"), "{w}");
        // 227 / (0.866 · (0.25e-4)²) = 4.19e11 samples, in exponent form.
        assert!(w.contains("about 4.19e11 samples"), "{w}");
        // Far beyond u64 (which the count saturates to), the estimate is still the estimate.
        let absurd = plan_with(DensityOrigin::Count, 23_000, 1e-12);
        let w = absurd.warning(Method::Exhaustive, 1.5).unwrap();
        assert!(w.contains("about 4.19e27 samples"), "{w}");
        assert!(!w.contains(&u64::MAX.to_string()), "{w}");
        // At or below ℓ_d: no warning, for any method.
        let fine = plan_with(DensityOrigin::Count, 23_000, 0.107);
        assert!(fine.ratio() <= WARN_SPACING);
        for m in Method::ALL {
            assert_eq!(fine.warning(m, 1.5), None);
        }
    }

    #[test]
    fn a_render_reports_its_plan_and_warning() {
        let skin = "preset = 'skin1'\nmm_per_unit = 25";
        let scene = spheres(
            &[("head", 4.0, skin)],
            "samples = 200\nmethod = 'hierarchical'",
        );
        let r = render(&scene, &RenderOptions::default()).unwrap();
        let plan = r.stats.density.as_ref().unwrap();
        assert_eq!(plan.count as usize, r.stats.samples);
        let w = r.stats.warning.as_deref().unwrap();
        assert!(w.starts_with("object 'head': irradiance samples"), "{w}");
        assert!(w.contains("hierarchical will show blotches"), "{w}");
        // Auto under a cap: the render places the capped count and says so.
        let scene = spheres(&[("head", 4.0, skin)], "max_samples = 5000");
        let r = render(&scene, &RenderOptions::default()).unwrap();
        let plan = r.stats.density.as_ref().unwrap();
        assert_eq!(
            plan.origin,
            DensityOrigin::Auto {
                max: 5000,
                capped: true
            }
        );
        assert_eq!(r.stats.samples, 5000);
        assert!(r.stats.warning.is_some());
    }

    #[test]
    fn texture_mapped_ell_gives_its_smallest_ell_d() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/textured-mfp.toml");
        let scene = crate::scene::load_scene(std::path::Path::new(path)).unwrap();
        let prep = Prepared::new(&scene).unwrap();
        let Shader::Translucent(shader) = prep.shader_of(0) else {
            panic!("the slab is translucent")
        };
        let bound = shader.smallest_diffuse_mean_free_path();
        // Brute force: the profile at every texel centre of the ramp.
        let m = scene.materials.iter().find_map(|m| match m {
            crate::scene::Material::Translucent(t) => Some(t),
            _ => None,
        });
        let m = m.expect("a translucent material");
        let crate::scene::Medium::Reflectance {
            distance:
                crate::scene::Distance::MeanFreePath(crate::scene::ScalarParam::Texture {
                    texture, ..
                }),
            ..
        } = &m.medium
        else {
            panic!("the ramp's ℓ_u is a texture")
        };
        let (w, h) = (texture.width, texture.height);
        let mut brute = Vec3::splat(f32::INFINITY);
        for j in 0..h {
            for i in 0..w {
                let uv = glam::Vec2::new(
                    (i as f32 + 0.5) / w as f32,
                    1.0 - (j as f32 + 0.5) / h as f32,
                );
                brute = brute.min(shader.at(uv).unwrap().profile.diffuse_mean_free_path());
            }
        }
        for c in 0..3 {
            assert!((bound[c] / brute[c] - 1.0).abs() < 1e-4, "{bound} {brute}");
        }
        // ℓ_u = 0.005 at the ramp's dark end, K_d 0.75 in blue.
        assert!(
            bound.z < bound.x && (0.04..0.05).contains(&bound.z),
            "{bound}"
        );
        let p = plan(&prep, &scene.render, None).unwrap().unwrap();
        assert_eq!(p.finest.ell_d, bound.min_element());
    }
}
