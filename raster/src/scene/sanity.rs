//! Mesh sanity checks that repair or warn rather than reject: a closed mesh wound inside out
//! is turned outside in again, file normals that contradict the winding are reported, and
//! triangles that repeat another's three corners are dropped.
//!
//! All work on the mesh's *topology by position*: vertices at bit-identical positions are the
//! same point ([`position_ids`]), because files split a vertex wherever its UV or normal
//! changes, which would otherwise open every seam.

use glam::Vec3;
use rayon::prelude::*;

use super::mesh::{drop_unused_vertices, retain_flagged};
use super::model::Mesh;
use super::weld::position_ids;
use crate::parallel::ordered_sum;

/// A mesh's [`position_ids`], computed by the first check that needs them and shared by the
/// checks after it (on a mesh of millions of vertices each computation sorts them all). They
/// are computed again when the vertex count changes (dropping vertices renumbers them);
/// whoever moves a vertex in place calls [`PositionIds::forget`].
#[derive(Debug, Default)]
pub struct PositionIds(Option<Vec<u32>>);

impl PositionIds {
    /// The ids of `mesh`'s vertices.
    fn of(&mut self, mesh: &Mesh) -> &[u32] {
        if self
            .0
            .as_ref()
            .is_none_or(|ids| ids.len() != mesh.positions.len())
        {
            self.0 = Some(position_ids(&mesh.positions));
        }
        self.0.as_deref().unwrap_or_default()
    }

    /// Forgets the ids: the positions changed.
    pub fn forget(&mut self) {
        self.0 = None;
    }
}

/// Drops every triangle whose three corners (by position, in any order or winding) are those
/// of an earlier triangle, and says how many. Such copies lay the same surface twice: the
/// irradiance samples would be placed on it as on a surface that much larger, then thinned
/// against each other at a cost that grows with the square of the copies (a thousand copies
/// of one triangle took over ten minutes), and the surface would scatter twice the light.
/// `keep_with` receives the mask of kept triangles first, so that per-triangle data (an OBJ's
/// material groups) stays aligned.
pub fn drop_coincident_triangles(
    mesh: &mut Mesh,
    ids: &mut PositionIds,
    keep_with: impl FnOnce(&[bool]),
) -> Option<String> {
    let ids_now = ids.of(mesh);
    let mut keys: Vec<([u32; 3], u32)> = mesh
        .triangles
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let mut k = t.map(|v| ids_now[v as usize]);
            k.sort_unstable();
            (k, i as u32)
        })
        .collect();
    // In parallel: the keys are distinct (the index is one), so the order is the same.
    keys.par_sort_unstable();
    let mut keep = vec![true; mesh.triangles.len()];
    let mut dropped = 0usize;
    for pair in keys.windows(2) {
        // Sorted by (corners, index): within a run of equal corners the first is the earliest.
        if pair[0].0 == pair[1].0 {
            keep[pair[1].1 as usize] = false;
            dropped += 1;
        }
    }
    if dropped == 0 {
        return None;
    }
    keep_with(&keep);
    let total = mesh.triangles.len();
    retain_flagged(&mut mesh.triangles, &keep);
    drop_unused_vertices(mesh);
    ids.forget();
    Some(format!(
        "{dropped} of its {total} triangles repeat the corners of another (coincident copies); \
         they were dropped"
    ))
}

/// Whether every edge of the mesh (by position) is used exactly once in each direction: the
/// surface is closed and consistently wound, so its winding says inside from outside.
pub fn is_closed_and_consistent(mesh: &Mesh, ids: &mut PositionIds) -> bool {
    let ids = ids.of(mesh);
    // Each edge as a key of its two ends, smaller first, filed by its direction: the surface
    // is closed and consistently wound when the two files hold the same keys, each once (every
    // edge used once in each direction). Two sorts of 64-bit keys: a sort of (ends, direction)
    // tuples took twice as long on 2 M triangles, a binary search per edge a second, and an
    // LSD radix sort (a byte a pass, constant bytes skipped) about 20% longer than this one.
    let half = 3 * mesh.triangles.len() / 2 + 1;
    let (mut forward, mut backward) = (Vec::with_capacity(half), Vec::with_capacity(half));
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| ids[i as usize]);
        if a == b || b == c || c == a {
            return false;
        }
        for (from, to) in [(a, b), (b, c), (c, a)] {
            let key = (u64::from(from.min(to)) << 32) | u64::from(from.max(to));
            if from < to {
                forward.push(key);
            } else {
                backward.push(key);
            }
        }
    }
    if forward.len() != backward.len() {
        return false;
    }
    rayon::join(
        || forward.par_sort_unstable(),
        || backward.par_sort_unstable(),
    );
    forward == backward && forward.windows(2).all(|pair| pair[0] != pair[1])
}

/// The signed volume enclosed by the triangles (positive when they wind counter-clockwise
/// seen from outside), by the divergence theorem: Σ (a − o) · ((b − o) × (c − o)) / 6 about
/// the centroid o of the vertices (which keeps the terms small), in f64.
pub fn signed_volume(mesh: &Mesh) -> f64 {
    let (positions, triangles) = (&mesh.positions, &mesh.triangles);
    let n = positions.len().max(1) as f64;
    let o = ordered_sum(positions.len(), |i| positions[i].as_dvec3()) / n;
    ordered_sum(triangles.len(), |k| {
        let [a, b, c] = triangles[k].map(|i| positions[i as usize].as_dvec3() - o);
        a.dot(b.cross(c))
    }) / 6.0
}

/// Flips a closed, consistently wound mesh whose signed volume is negative (its triangles wind
/// clockwise seen from outside), and says so. With `file_normals`, the vertex normals came
/// from the file: they are negated too when they agreed with the inverted winding (they
/// described the same inside-out surface), and kept when they already pointed out.
pub fn orient_outward(
    mesh: &mut Mesh,
    file_normals: bool,
    ids: &mut PositionIds,
) -> Option<String> {
    if !is_closed_and_consistent(mesh, ids) {
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
    let votes = |t: &[u32; 3]| {
        let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
        let face = (b - a).cross(c - a);
        if face == Vec3::ZERO || !face.is_finite() {
            return (0, 0);
        }
        t.iter().fold((0, 0), |(against, with), &i| {
            let d = face.dot(mesh.normals[i as usize]);
            (against + (d < 0.0) as usize, with + (d > 0.0) as usize)
        })
    };
    let (against, with) = mesh
        .triangles
        .par_iter()
        .map(votes)
        .reduce(|| (0, 0), |x, y| (x.0 + y.0, x.1 + y.1));
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

    /// Copies of a box's triangles, at other vertex indices and with other windings and
    /// corner orders, are dropped; the per-triangle data follows; the box is left as it was.
    #[test]
    fn coincident_copies_of_triangles_are_dropped() {
        let good = shapes::cuboid(Vec3::new(1.0, 2.0, 3.0));
        let mut m = good.clone();
        let n = m.positions.len() as u32;
        m.positions.extend_from_within(..);
        m.normals.extend_from_within(..);
        if let Some(uvs) = &mut m.uvs {
            uvs.extend_from_within(..);
        }
        // Triangle k again at the copied vertices, rotated or reversed by k.
        let copies: Vec<[u32; 3]> = m
            .triangles
            .iter()
            .enumerate()
            .map(|(k, t)| match k % 3 {
                0 => t.map(|v| v + n),
                1 => [t[1] + n, t[2] + n, t[0] + n],
                _ => [t[2] + n, t[1] + n, t[0] + n],
            })
            .collect();
        m.triangles.extend(copies.iter().step_by(2));
        m.triangles.extend(&copies);
        // A triangle sharing two corners only is not a copy.
        m.triangles.push([0, 1, 6]);
        let tags: Vec<usize> = (0..m.triangles.len()).collect();
        let mut kept_tags = tags.clone();
        let w = drop_coincident_triangles(&mut m, &mut PositionIds::default(), |keep| {
            retain_flagged(&mut kept_tags, keep)
        })
        .expect("copies found");
        assert!(
            w.starts_with("18 of its 31 triangles repeat the corners"),
            "{w}"
        );
        assert_eq!(kept_tags, (0..12).chain([30]).collect::<Vec<_>>());
        assert_eq!(m.triangles[..12], good.triangles[..]);
        assert_eq!(m.positions, good.positions);
        assert_eq!(m.triangles[12], [0, 1, 6]);
        assert_eq!(
            drop_coincident_triangles(&mut m, &mut PositionIds::default(), |_| panic!("no copies")),
            None
        );
    }

    /// The definition, edge by edge: no directed edge twice, and each one's reverse present.
    fn closed_and_consistent_oracle(mesh: &Mesh) -> bool {
        let ids = position_ids(&mesh.positions);
        let mut directed = Vec::new();
        for t in &mesh.triangles {
            let [a, b, c] = t.map(|i| ids[i as usize]);
            if a == b || b == c || c == a {
                return false;
            }
            directed.extend([(a, b), (b, c), (c, a)]);
        }
        let count = |e: (u32, u32)| directed.iter().filter(|&&d| d == e).count();
        directed
            .iter()
            .all(|&(a, b)| count((a, b)) == 1 && count((b, a)) == 1)
    }

    #[test]
    fn closedness_agrees_with_the_edge_by_edge_definition() {
        // Closed solids, then random edits of them: a face removed, duplicated, flipped, or a
        // corner moved onto another; and random triangle soups over a few shared positions.
        let mut state = 0x2545_f491_u32;
        let mut next = |n: u32| {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            state % n
        };
        let solids = [
            shapes::cuboid(Vec3::new(1.0, 2.0, 3.0)),
            seamless_sphere(1.0, 4),
            // Split along its seam: closed by position only.
            shapes::sphere(1.0, 6),
            inverted(shapes::cuboid(Vec3::ONE)),
        ];
        let (mut closed, mut open) = (0, 0);
        for round in 0..600 {
            let mut m = solids[round % solids.len()].clone();
            let n = m.triangles.len() as u32;
            match next(8) {
                1 => {
                    m.triangles.remove(next(n) as usize);
                }
                2 => {
                    let t = m.triangles[next(n) as usize];
                    m.triangles.push(t);
                }
                3 => m.triangles[next(n) as usize].swap(1, 2),
                4 => {
                    let t = next(n) as usize;
                    m.triangles[t][next(3) as usize] = next(m.positions.len() as u32);
                }
                5 => {
                    m.positions = (0..5).map(|i| Vec3::splat(i as f32)).collect();
                    m.triangles = (0..2 + next(6))
                        .map(|_| [next(5), next(5), next(5)])
                        .collect();
                }
                _ => {} // unchanged
            }
            let expected = closed_and_consistent_oracle(&m);
            assert_eq!(
                is_closed_and_consistent(&m, &mut PositionIds::default()),
                expected,
                "round {round}: {m:?}"
            );
            if expected {
                closed += 1;
            } else {
                open += 1;
            }
        }
        assert!(closed > 100 && open > 100, "{closed} closed, {open} open");
    }

    #[test]
    fn volume_of_a_box_is_its_product() {
        let b = shapes::cuboid(Vec3::new(1.0, 2.0, 3.0));
        assert!(is_closed_and_consistent(&b, &mut PositionIds::default()));
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
        assert!(is_closed_and_consistent(&good, &mut PositionIds::default()));
        let mut m = inverted(good.clone());
        m.normals = m.normals.iter().map(|n| -*n).collect();
        let w = orient_outward(&mut m, true, &mut PositionIds::default()).expect("flipped");
        assert!(w.contains("inside out") && w.contains("normals"), "{w}");
        assert_eq!(m.triangles, good.triangles);
        assert_eq!(m.normals, good.normals);
        assert!(signed_volume(&m) > 0.0);
        // Outward already: nothing to say, nothing changed.
        assert_eq!(
            orient_outward(&mut m, true, &mut PositionIds::default()),
            None
        );
        assert_eq!(m.triangles, good.triangles);
    }

    /// One `PositionIds` through the checks of a load: reused while the vertices stay, made
    /// again once dropping copies renumbers them (stale ids would index past the vertices or
    /// join the wrong corners).
    #[test]
    fn position_ids_are_shared_until_the_vertices_change() {
        let good = seamless_sphere(1.0, 24);
        let corners = |m: &Mesh| -> Vec<[Vec3; 3]> {
            m.triangles
                .iter()
                .map(|t| t.map(|i| m.positions[i as usize]))
                .collect()
        };
        // Inside out, with copies of every third triangle on vertices of their own.
        let mut m = inverted(good.clone());
        let n = m.positions.len() as u32;
        m.positions.extend_from_within(..);
        m.normals.extend_from_within(..);
        let copies: Vec<[u32; 3]> = m
            .triangles
            .iter()
            .step_by(3)
            .map(|t| t.map(|v| v + n))
            .collect();
        m.triangles.extend(copies);
        let mut ids = PositionIds::default();
        assert!(drop_coincident_triangles(&mut m, &mut ids, |_| {}).is_some());
        assert!(
            m.positions.len() <= n as usize,
            "the copies' vertices are dropped"
        );
        assert!(orient_outward(&mut m, false, &mut ids).is_some());
        assert_eq!(corners(&m), corners(&good));
        // No copies: the ids made for the first check serve the second.
        let mut m = inverted(good.clone());
        let mut ids = PositionIds::default();
        assert_eq!(drop_coincident_triangles(&mut m, &mut ids, |_| {}), None);
        assert!(ids.0.is_some());
        assert!(orient_outward(&mut m, false, &mut ids).is_some());
        assert_eq!(corners(&m), corners(&good));
        // Vertices moved in place need `forget`: with two moved onto a third, the old ids
        // still say closed, fresh ones that three triangles have collapsed.
        assert!(is_closed_and_consistent(&m, &mut ids));
        let [a, b, c] = m.triangles[40];
        m.positions[b as usize] = m.positions[a as usize];
        m.positions[c as usize] = m.positions[a as usize];
        assert!(is_closed_and_consistent(&m, &mut ids), "stale ids");
        ids.forget();
        assert!(!is_closed_and_consistent(&m, &mut ids));
    }

    #[test]
    fn outward_file_normals_survive_a_flip() {
        let good = seamless_sphere(1.0, 16);
        let mut m = inverted(good.clone());
        let w = orient_outward(&mut m, true, &mut PositionIds::default()).expect("flipped");
        assert!(!w.contains("normals"), "{w}");
        assert_eq!(m.normals, good.normals);
    }

    #[test]
    fn open_meshes_are_left_alone() {
        let mut plane = inverted(shapes::plane(glam::Vec2::ONE));
        assert!(!is_closed_and_consistent(
            &plane,
            &mut PositionIds::default()
        ));
        let before = plane.triangles.clone();
        assert_eq!(
            orient_outward(&mut plane, false, &mut PositionIds::default()),
            None
        );
        assert_eq!(plane.triangles, before);
        // A sphere with one triangle wound the other way is not consistent.
        let mut m = seamless_sphere(1.0, 8);
        m.triangles[3].swap(1, 2);
        assert!(!is_closed_and_consistent(&m, &mut PositionIds::default()));
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
