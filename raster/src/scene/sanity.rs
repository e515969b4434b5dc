//! Mesh sanity checks that repair or warn rather than reject: a closed mesh wound inside out
//! is turned outside in again, and file normals that contradict the winding are reported.
//!
//! Both work on the mesh's *topology by position*: vertices at bit-identical positions are the
//! same point ([`position_ids`]), because files split a vertex wherever its UV or normal
//! changes, which would otherwise open every seam.

use glam::{DVec3, Vec3};

use super::model::Mesh;
use super::weld::position_ids;

/// Whether every edge of the mesh (by position) is used exactly once in each direction: the
/// surface is closed and consistently wound, so its winding says inside from outside.
pub fn is_closed_and_consistent(mesh: &Mesh) -> bool {
    let ids = position_ids(&mesh.positions);
    let mut directed: Vec<(u32, u32)> = Vec::with_capacity(3 * mesh.triangles.len());
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| ids[i as usize]);
        if a == b || b == c || c == a {
            return false;
        }
        directed.extend([(a, b), (b, c), (c, a)]);
    }
    directed.sort_unstable();
    if directed.windows(2).any(|w| w[0] == w[1]) {
        return false;
    }
    directed
        .iter()
        .all(|&(a, b)| directed.binary_search(&(b, a)).is_ok())
}

/// The signed volume enclosed by the triangles (positive when they wind counter-clockwise
/// seen from outside), by the divergence theorem: Σ (a − o) · ((b − o) × (c − o)) / 6 about
/// the centroid o of the vertices (which keeps the terms small), in f64.
pub fn signed_volume(mesh: &Mesh) -> f64 {
    let n = mesh.positions.len().max(1) as f64;
    let o = mesh
        .positions
        .iter()
        .fold(DVec3::ZERO, |s, p| s + p.as_dvec3())
        / n;
    mesh.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize].as_dvec3() - o);
            a.dot(b.cross(c))
        })
        .sum::<f64>()
        / 6.0
}

/// Flips a closed, consistently wound mesh whose signed volume is negative (its triangles wind
/// clockwise seen from outside), and says so. With `file_normals`, the vertex normals came
/// from the file: they are negated too when they agreed with the inverted winding (they
/// described the same inside-out surface), and kept when they already pointed out.
pub fn orient_outward(mesh: &mut Mesh, file_normals: bool) -> Option<String> {
    if !is_closed_and_consistent(mesh) {
        return None;
    }
    let volume = signed_volume(mesh);
    if !(volume < 0.0) {
        return None;
    }
    let normals_inward = file_normals && normals_against_winding(mesh).is_none();
    for t in &mut mesh.triangles {
        t.swap(1, 2);
    }
    if normals_inward {
        for n in &mut mesh.normals {
            *n = -*n;
        }
    }
    Some(format!(
        "the closed mesh is wound inside out (signed volume {volume:.3e}); its triangles{} \
         were flipped",
        if normals_inward { " and normals" } else { "" }
    ))
}

/// A warning when most vertex normals point against the face they belong to (negative dot
/// product with the face's winding normal, counted per triangle corner; zero-area triangles do
/// not vote): the file's normals and its winding disagree, and one of them is wrong.
pub fn normals_against_winding(mesh: &Mesh) -> Option<String> {
    let (mut against, mut with) = (0usize, 0usize);
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
        let face = (b - a).cross(c - a);
        if face == Vec3::ZERO || !face.is_finite() {
            continue;
        }
        for &i in t {
            let d = face.dot(mesh.normals[i as usize]);
            if d < 0.0 {
                against += 1;
            } else if d > 0.0 {
                with += 1;
            }
        }
    }
    (against > with).then(|| {
        format!(
            "{against} of {} vertex normals point against their triangle's winding \
             (counter-clockwise seen from outside): the normals or the winding are wrong",
            against + with
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::shapes;
    use crate::scene::weld::seamless_sphere;

    fn inverted(mut m: Mesh) -> Mesh {
        for t in &mut m.triangles {
            t.swap(1, 2);
        }
        m
    }

    #[test]
    fn volume_of_a_box_is_its_product() {
        let b = shapes::cuboid(Vec3::new(1.0, 2.0, 3.0));
        assert!(is_closed_and_consistent(&b));
        assert!(
            (signed_volume(&b) - 6.0).abs() < 1e-9,
            "{}",
            signed_volume(&b)
        );
        assert!((signed_volume(&inverted(b)) + 6.0).abs() < 1e-9);
    }

    #[test]
    fn an_inside_out_sphere_is_flipped_once() {
        let good = seamless_sphere(1.0, 24);
        assert!(is_closed_and_consistent(&good));
        let mut m = inverted(good.clone());
        m.normals = m.normals.iter().map(|n| -*n).collect();
        let w = orient_outward(&mut m, true).expect("flipped");
        assert!(w.contains("inside out") && w.contains("normals"), "{w}");
        assert_eq!(m.triangles, good.triangles);
        assert_eq!(m.normals, good.normals);
        assert!(signed_volume(&m) > 0.0);
        // Outward already: nothing to say, nothing changed.
        assert_eq!(orient_outward(&mut m, true), None);
        assert_eq!(m.triangles, good.triangles);
    }

    #[test]
    fn outward_file_normals_survive_a_flip() {
        let good = seamless_sphere(1.0, 16);
        let mut m = inverted(good.clone());
        let w = orient_outward(&mut m, true).expect("flipped");
        assert!(!w.contains("normals"), "{w}");
        assert_eq!(m.normals, good.normals);
    }

    #[test]
    fn open_meshes_are_left_alone() {
        let mut plane = inverted(shapes::plane(glam::Vec2::ONE));
        assert!(!is_closed_and_consistent(&plane));
        let before = plane.triangles.clone();
        assert_eq!(orient_outward(&mut plane, false), None);
        assert_eq!(plane.triangles, before);
        // A sphere with one triangle wound the other way is not consistent.
        let mut m = seamless_sphere(1.0, 8);
        m.triangles[3].swap(1, 2);
        assert!(!is_closed_and_consistent(&m));
    }

    #[test]
    fn normals_against_the_winding_are_reported() {
        let mut m = seamless_sphere(1.0, 12);
        assert_eq!(normals_against_winding(&m), None);
        m.normals = m.normals.iter().map(|n| -*n).collect();
        let w = normals_against_winding(&m).expect("reported");
        let corners = 3 * m.triangles.len();
        assert!(w.starts_with(&format!("{corners} of {corners}")), "{w}");
    }
}
