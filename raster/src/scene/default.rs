//! The built-in default scene: `scenes/default.toml` and the Stanford bunny, compiled into the
//! binary so that `lucent` with no arguments works from any directory.
//!
//! The scene is the situation of Figure 1 of Neulander 2010: a translucent (marble) bunny
//! with a sharp shadow edge across its body, cast by an opaque plate from a point light.

use std::borrow::Cow;

use super::load::parse_scene;
use super::model::Scene;
use super::origin::SceneOrigin;

/// The text of `scenes/default.toml` (e.g. for a `--print-default-scene` option).
pub const DEFAULT_SCENE_TOML: &str = include_str!("../../../scenes/default.toml");

/// The Stanford bunny (`assets/bunny.obj`).
const BUNNY_OBJ: &str = include_str!("../../../assets/bunny.obj");

/// The name the default scene has in messages.
pub const DEFAULT_SCENE_NAME: &str = "<built-in>/default.toml";

/// Where the default scene's files come from: memory, under the paths the TOML uses.
pub fn default_scene_origin() -> SceneOrigin {
    SceneOrigin::Embedded {
        name: DEFAULT_SCENE_NAME.to_string(),
        files: vec![(
            "../assets/bunny.obj".to_string(),
            Cow::Borrowed(BUNNY_OBJ.as_bytes()),
        )],
    }
}

/// The built-in default scene (renders to `lucent.png` and `lucent.exr`).
///
/// # Panics
///
/// Never in a released build: the embedded scene is fixed at compile time and a test checks
/// that it loads.
pub fn default_scene() -> Scene {
    parse_scene(DEFAULT_SCENE_TOML, &default_scene_origin())
        .unwrap_or_else(|e| panic!("the built-in default scene does not load: {e}"))
}

#[cfg(test)]
mod tests {
    use glam::{Vec3, Vec4Swizzles};

    use super::super::model::{Light, Material, Medium, Mesh};
    use super::*;
    use lucent_core::Method;

    fn object<'s>(scene: &'s Scene, name: &str) -> &'s Mesh {
        &scene
            .objects
            .iter()
            .find(|o| o.name == name)
            .unwrap_or_else(|| panic!("no object {name}"))
            .mesh
    }

    /// Möller–Trumbore: does the open segment `from → to` cross any triangle of `mesh`?
    fn segment_blocked(mesh: &Mesh, from: Vec3, to: Vec3) -> bool {
        let d = to - from;
        mesh.triangles.iter().any(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            let (e1, e2) = (b - a, c - a);
            let p = d.cross(e2);
            let det = e1.dot(p);
            if det.abs() < 1e-12 {
                return false;
            }
            let s = from - a;
            let u = s.dot(p) / det;
            let q = s.cross(e1);
            let v = d.dot(q) / det;
            let t = e2.dot(q) / det;
            u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 1e-4 && t < 1.0 - 1e-4
        })
    }

    #[test]
    fn default_scene_loads_with_its_settings() {
        let s = default_scene();
        assert_eq!((s.camera.width, s.camera.height), (512, 512));
        assert_eq!(s.render.method, Method::EdgeRefined);
        assert_eq!(
            s.output.png.as_deref(),
            Some(std::path::Path::new("lucent.png"))
        );
        assert_eq!(
            s.output.exr.as_deref(),
            Some(std::path::Path::new("lucent.exr"))
        );
        assert!(s.source.is_none());
        assert_eq!(s.lights.len(), 2); // the key (casting the plate's shadow) and a dim fill
        let bunny = s.objects.iter().find(|o| o.name == "bunny").expect("bunny");
        assert_eq!(bunny.mesh.triangles.len(), 3674);
        match &s.materials[bunny.material] {
            Material::Translucent(m) => match &m.medium {
                Medium::Preset { name, mm_per_unit } => {
                    assert_eq!(name, "marble");
                    assert_eq!(*mm_per_unit, 10.0);
                }
                other => panic!("unexpected medium {other:?}"),
            },
            other => panic!("bunny is not translucent: {other:?}"),
        }
    }

    #[test]
    fn bunny_stands_on_the_ground_about_ten_units_tall() {
        let s = default_scene();
        let bunny = object(&s, "bunny");
        let (lo, hi) = bunny
            .positions
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(*p), hi.max(*p))
            });
        assert!(lo.z.abs() < 0.01, "lowest point at z = {}", lo.z);
        assert!(
            (9.0..11.0).contains(&(hi.z - lo.z)),
            "height {}",
            hi.z - lo.z
        );
        // Standing upright: taller than deep.
        assert!(hi.z - lo.z > hi.y - lo.y);
        let ground = object(&s, "ground");
        assert!(ground.positions.iter().all(|p| p.z == 0.0));
        let (glo, ghi) = ground
            .positions
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(*p), hi.max(*p))
            });
        assert!(glo.x < lo.x && glo.y < lo.y && ghi.x > hi.x && ghi.y > hi.y);
    }

    #[test]
    fn camera_frames_the_bunny_and_sees_neither_plate_nor_clipped_ground() {
        let s = default_scene();
        let vp = s.camera.view_projection(0.1, 1000.0);
        let ndc = |p: Vec3| {
            let c = vp * p.extend(1.0);
            (c.w, c.xyz() / c.w)
        };
        for p in &object(&s, "bunny").positions {
            let (w, n) = ndc(*p);
            assert!(w > 1.0, "bunny vertex {p} behind the camera");
            assert!(
                n.x.abs() < 0.95 && n.y.abs() < 0.95,
                "bunny vertex {p} outside the view"
            );
        }
        // The bunny fills a good part of the frame.
        let ys: Vec<f32> = object(&s, "bunny")
            .positions
            .iter()
            .map(|p| ndc(*p).1.y)
            .collect();
        let span = ys.iter().cloned().fold(f32::MIN, f32::max)
            - ys.iter().cloned().fold(f32::MAX, f32::min);
        assert!(
            span > 1.2,
            "bunny spans only {span} of the 2-unit NDC height"
        );
        // The plate is in front of the camera and entirely left of the view.
        for p in &object(&s, "occluder").positions {
            let (w, n) = ndc(*p);
            assert!(w > 0.1, "plate vertex {p} behind the camera");
            assert!(
                n.x < -1.0,
                "plate vertex {p} inside the view (ndc x {})",
                n.x
            );
        }
        // The ground does not cross the camera plane (no near clipping needed).
        for p in &object(&s, "ground").positions {
            assert!(ndc(*p).0 > 0.1, "ground vertex {p} behind the camera");
        }
    }

    #[test]
    fn the_plate_shadow_edge_crosses_the_bunny_diagonally() {
        let s = default_scene();
        let light = match &s.lights[0] {
            Light::Point { position, .. } => *position,
            other => panic!("expected a point light, got {other:?}"),
        };
        let bunny = object(&s, "bunny");
        let plate = object(&s, "occluder");
        let vp = s.camera.view_projection(0.1, 1000.0);
        let (mut lit, mut shadowed) = (Vec::new(), Vec::new());
        for (p, n) in bunny.positions.iter().zip(&bunny.normals) {
            // Vertices facing both the camera and the light.
            if n.dot(s.camera.position - *p) <= 0.0 || n.dot(light - *p) <= 0.0 {
                continue;
            }
            let c = vp * p.extend(1.0);
            let image = c.xy() / c.w;
            if segment_blocked(plate, *p, light) {
                shadowed.push(image);
            } else {
                lit.push(image);
            }
        }
        let total = (lit.len() + shadowed.len()) as f32;
        assert!(total > 300.0, "only {total} candidate vertices");
        let fraction = shadowed.len() as f32 / total;
        // Face and ears lit, the back and haunch in shadow: a quarter to a half shadowed.
        assert!(
            (0.2..0.5).contains(&fraction),
            "{} lit, {} shadowed",
            lit.len(),
            shadowed.len()
        );
        // The lit and shadowed parts sit on either side of a diagonal: their centroids differ
        // in both image directions (shadow up and to the right).
        let mean = |v: &[glam::Vec2]| v.iter().sum::<glam::Vec2>() / v.len() as f32;
        let d = mean(&shadowed) - mean(&lit);
        let angle = d.y.atan2(d.x).to_degrees();
        assert!(
            (20.0..70.0).contains(&angle),
            "centroid offset {d} at {angle}°"
        );
        // The plate does not block the camera's view of the bunny either.
        let eye = s.camera.position;
        assert!(
            bunny
                .positions
                .iter()
                .all(|p| !segment_blocked(plate, eye, *p))
        );
    }
}
