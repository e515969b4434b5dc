//! Which meshes cannot shadow themselves, so that shadow rays leaving them can skip their own
//! triangles.
//!
//! A shadow ray leaves a surface point on the side of its light. On a closed convex mesh it
//! then only moves away from the body: the mesh cannot block it (the points facing away from
//! the light get nothing through the cosine anyway). On a flat mesh it cannot either. Both
//! kinds are common in subsurface scenes — spheres, slabs, boxes, floors — and their own
//! triangles are exactly the ones a ray starting on them has to wade through in the BVH.
//!
//! The test is local and linear in the mesh size: with vertices welded by position (meshes
//! split vertices at UV seams and normal creases), the mesh is closed when every edge has
//! exactly two faces that run along it in opposite directions, and convex when, across every
//! edge, each face's third vertex lies behind (or on) the other face's plane. A connected,
//! closed, consistently oriented surface that is convex at every edge bounds a convex body
//! (Tietze's theorem for polyhedra; a mesh that wraps around itself twice is not a case
//! meshes present). Inward-facing normals make every edge look concave: such a mesh is left
//! to shadow itself, which is merely slower. Tolerances are relative to the mesh size, as in
//! the exhaustive vertex-against-plane test this replaced (O(V·F), capped at 50 M steps,
//! which the 16k-triangle sphere of the benchmark already exceeded).

use std::collections::HashMap;

use glam::{DVec3, Vec3};

use crate::scene::Mesh;

/// Relative tolerance (of the bounding-box diagonal) for "behind or on a plane".
const TOLERANCE: f64 = 1e-5;

/// True if no ray leaving a point of the mesh towards a light (from the side the light is on)
/// can hit the mesh again: the mesh is flat, or closed and convex. Zero-area triangles are
/// ignored.
pub fn cannot_shadow_itself(mesh: &Mesh) -> bool {
    let Some(bounds) = Bounds::of(&mesh.positions) else {
        return true;
    };
    let faces = welded_faces(mesh, &bounds);
    if faces.is_empty() {
        return true;
    }
    let tolerance = TOLERANCE * bounds.diagonal;
    is_flat(mesh, &faces[0], tolerance) || is_closed_convex(&faces, tolerance)
}

/// The smallest corner and the diagonal length of the positions' bounding box, in f64: the
/// f32 length overflows for coordinates beyond about 10¹⁹, which made every tolerance
/// infinite.
struct Bounds {
    lo: DVec3,
    diagonal: f64,
}

impl Bounds {
    /// `None` for no positions.
    fn of(positions: &[Vec3]) -> Option<Bounds> {
        if positions.is_empty() {
            return None;
        }
        let (lo, hi) = positions
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &v| {
                (lo.min(v.as_dvec3()), hi.max(v.as_dvec3()))
            });
        Some(Bounds {
            lo,
            diagonal: (hi - lo).length(),
        })
    }
}

/// A triangle by welded vertex ids, with its corners and unit normal. Computed in f64, where
/// the products and sums of f32 coordinates neither overflow nor underflow: in f32 the squared
/// length of the cross product overflows for edges longer than about 10⁹ and underflows below
/// about 10⁻¹⁰, and every face then looked degenerate, so any such mesh was accepted.
struct Face {
    v: [u32; 3],
    p: [DVec3; 3],
    normal: DVec3,
}

/// The non-degenerate triangles with vertices welded by position: corners closer than
/// [`WELD`] of the mesh size are one vertex (generated seams differ in the last bits:
/// sin 2π is not 0 in floating point).
fn welded_faces(mesh: &Mesh, bounds: &Bounds) -> Vec<Face> {
    let weld = weld_positions(&mesh.positions, bounds);
    mesh.triangles
        .iter()
        .filter_map(|t| {
            let v = t.map(|i| weld[i as usize]);
            let [a, b, c] = t.map(|i| mesh.positions[i as usize].as_dvec3());
            let n = (b - a).cross(c - a);
            let len = n.length();
            (v[0] != v[1] && v[1] != v[2] && v[0] != v[2] && len > 0.0 && len.is_finite()).then(
                || Face {
                    v,
                    p: [a, b, c],
                    normal: n / len,
                },
            )
        })
        .collect()
}

/// Relative distance (of the bounding-box diagonal) within which positions are welded.
const WELD: f64 = 1e-6;

/// One id per position; positions within `WELD · diagonal` of an earlier one share its id.
/// A hash grid of that cell size: a match lies in one of the 27 cells around a point.
fn weld_positions(positions: &[Vec3], bounds: &Bounds) -> Vec<u32> {
    let lo = bounds.lo;
    // In f64 the cell of a mesh of subnormal f32 coordinates is still tiny against the mesh;
    // clamping it to the smallest normal f32 welded such a mesh into one point (no faces, so
    // accepted). Found by `convexity_is_sound`: `crash-subnormal-mesh-welded-to-a-point`.
    let cell = (WELD * bounds.diagonal).max(f64::MIN_POSITIVE);
    let key = |p: DVec3| ((p - lo) / cell).floor().as_ivec3().to_array();
    let mut grid: HashMap<[i32; 3], Vec<u32>> = HashMap::new();
    let mut ids = Vec::with_capacity(positions.len());
    for (index, p) in positions.iter().enumerate() {
        let p = p.as_dvec3();
        let [x, y, z] = key(p);
        let mut found = None;
        'search: for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let Some(list) = grid.get(&[x + dx, y + dy, z + dz]) else {
                        continue;
                    };
                    for &j in list {
                        if positions[j as usize].as_dvec3().distance(p) <= cell {
                            found = Some(ids[j as usize]);
                            break 'search;
                        }
                    }
                }
            }
        }
        ids.push(found.unwrap_or(index as u32));
        grid.entry([x, y, z]).or_default().push(index as u32);
    }
    ids
}

/// Every vertex on the plane of `face`.
fn is_flat(mesh: &Mesh, face: &Face, tolerance: f64) -> bool {
    mesh.positions
        .iter()
        .all(|&p| face.normal.dot(p.as_dvec3() - face.p[0]).abs() <= tolerance)
}

/// Closed (two opposite faces per edge), connected and convex at every edge.
fn is_closed_convex(faces: &[Face], tolerance: f64) -> bool {
    // Directed edge (from, to) → the face it belongs to; a repeat is not a manifold.
    let mut directed: HashMap<(u32, u32), u32> = HashMap::with_capacity(faces.len() * 3);
    for (i, f) in faces.iter().enumerate() {
        for k in 0..3 {
            if directed
                .insert((f.v[k], f.v[(k + 1) % 3]), i as u32)
                .is_some()
            {
                return false;
            }
        }
    }
    let mut components = UnionFind::new(faces.len());
    for (i, f) in faces.iter().enumerate() {
        for k in 0..3 {
            let (from, to) = (f.v[k], f.v[(k + 1) % 3]);
            // Closed and consistently oriented: the neighbour runs the edge backwards.
            let Some(&j) = directed.get(&(to, from)) else {
                return false;
            };
            components.union(i, j as usize);
            // The neighbour's third vertex lies behind this face's plane.
            let g = &faces[j as usize];
            let third = (0..3)
                .find(|&m| g.v[m] != from && g.v[m] != to)
                .unwrap_or(0);
            if f.normal.dot(g.p[third] - f.p[k]) > tolerance {
                return false;
            }
        }
    }
    components.count() == 1
}

/// Disjoint sets over face indices, to count connected pieces.
struct UnionFind {
    parent: Vec<u32>,
}

impl UnionFind {
    fn new(n: usize) -> Self {
        UnionFind {
            parent: (0..n as u32).collect(),
        }
    }

    fn find(&mut self, mut i: usize) -> usize {
        while self.parent[i] as usize != i {
            let up = self.parent[self.parent[i] as usize];
            self.parent[i] = up;
            i = up as usize;
        }
        i
    }

    fn union(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            self.parent[ra.max(rb)] = ra.min(rb) as u32;
        }
    }

    fn count(&mut self) -> usize {
        (0..self.parent.len())
            .filter(|&i| self.find(i) == i)
            .count()
    }
}

#[cfg(test)]
mod tests {
    use glam::{Mat4, Vec2};

    use super::*;
    use crate::scene::shapes;

    fn moved(mut mesh: Mesh, m: Mat4) -> Mesh {
        for p in &mut mesh.positions {
            *p = m.transform_point3(*p);
        }
        mesh
    }

    /// The exhaustive definition, for small meshes: every vertex behind every face's plane.
    fn every_vertex_behind_every_face(mesh: &Mesh) -> bool {
        let bounds = Bounds::of(&mesh.positions).expect("a mesh with vertices");
        welded_faces(mesh, &bounds).iter().all(|f| {
            mesh.positions
                .iter()
                .all(|&p| f.normal.dot(p.as_dvec3() - f.p[0]) <= 1e-5)
        })
    }

    #[test]
    fn closed_convex_and_flat_shapes_cannot_shadow_themselves() {
        let turn = Mat4::from_rotation_translation(
            glam::Quat::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 2.0),
            Vec3::new(4.0, -2.0, 7.0),
        );
        for mesh in [
            shapes::sphere(1.0, 16),
            shapes::sphere(1.0, 128),
            shapes::cuboid(Vec3::new(1.0, 2.0, 3.0)),
            shapes::plane(Vec2::new(4.0, 2.0)),
        ] {
            assert!(cannot_shadow_itself(&mesh));
            assert!(cannot_shadow_itself(&moved(mesh, turn)));
        }
    }

    #[test]
    fn what_can_shadow_itself_is_found() {
        // Two spheres side by side: closed and convex at every edge, but not connected.
        let mut two = shapes::sphere(1.0, 12);
        let other = moved(
            shapes::sphere(1.0, 12),
            Mat4::from_translation(Vec3::X * 3.0),
        );
        let base = two.positions.len() as u32;
        two.positions.extend(other.positions);
        two.normals.extend(other.normals);
        two.triangles
            .extend(other.triangles.iter().map(|t| t.map(|i| i + base)));
        if let (Some(a), Some(b)) = (&mut two.uvs, &other.uvs) {
            a.extend(b);
        }
        assert!(!cannot_shadow_itself(&two));
        // A box with one face removed: open, and not flat.
        let mut open = shapes::cuboid(Vec3::ONE);
        open.triangles.truncate(open.triangles.len() - 2);
        assert!(!cannot_shadow_itself(&open));
        // A box with a vertex pushed in: closed, concave at some edges.
        let mut dented = shapes::cuboid(Vec3::ONE);
        let corner = dented.positions[0];
        for p in &mut dented.positions {
            if *p == corner {
                *p *= 0.2;
            }
        }
        assert!(!every_vertex_behind_every_face(&dented));
        assert!(!cannot_shadow_itself(&dented));
        // Turned inside out (normals inward): left to shadow itself.
        let mut inside_out = shapes::cuboid(Vec3::ONE);
        for t in &mut inside_out.triangles {
            t.swap(1, 2);
        }
        assert!(!cannot_shadow_itself(&inside_out));
    }

    /// Found by the fuzz target `convexity_is_sound` (`crash-huge-open-box-no-faces`,
    /// `crash-huge-coordinates-infinite-tolerance`, `crash-subnormal-mesh-welded-to-a-point`,
    /// the 2⁻¹⁴⁰ case): in f32 the face normals' squared lengths
    /// overflowed for edges beyond about 10⁹ (underflowed below about 10⁻¹⁰) and the diagonal
    /// overflowed for coordinates beyond about 10¹⁹, so every face looked degenerate or every
    /// tolerance was infinite, and any mesh at those scales was accepted.
    #[test]
    fn the_test_holds_at_every_scale() {
        let mut open = shapes::cuboid(Vec3::new(1.0, 2.0, 4.0));
        open.triangles.truncate(open.triangles.len() - 2);
        let mut dented = shapes::cuboid(Vec3::ONE);
        let corner = dented.positions[0];
        for p in &mut dented.positions {
            if *p == corner {
                *p *= 0.2;
            }
        }
        for e in [-140, -120, -100, -60, -40, 0, 40, 60, 100, 120] {
            // (2^e in two steps: `powi(-140)` is 1/2¹⁴⁰ = 1/∞ = 0 in f32.)
            let s = Mat4::from_scale(Vec3::splat(2f32.powi(e / 2) * 2f32.powi(e - e / 2)));
            assert!(!cannot_shadow_itself(&moved(open.clone(), s)), "open 2^{e}");
            assert!(
                !cannot_shadow_itself(&moved(dented.clone(), s)),
                "dented 2^{e}"
            );
            let cube = moved(shapes::cuboid(Vec3::ONE), s);
            assert!(cannot_shadow_itself(&cube), "cube 2^{e}");
        }
        // Coordinates near the f32 limit: the diagonal exceeds f32.
        let mut huge = shapes::cuboid(Vec3::splat(2.0));
        for p in &mut huge.positions {
            *p *= 3e38;
        }
        assert!(cannot_shadow_itself(&huge));
        huge.triangles.truncate(huge.triangles.len() - 2);
        assert!(!cannot_shadow_itself(&huge));
    }

    #[test]
    fn the_edge_test_agrees_with_the_exhaustive_one_on_closed_meshes() {
        // Spheres with one vertex pushed out or in by various amounts.
        for (k, scale) in [1.0f32, 1.5, 0.999, 0.9, 1.0001].into_iter().enumerate() {
            let mut mesh = shapes::sphere(1.0, 10);
            let target = mesh.positions[37 + k];
            for p in &mut mesh.positions {
                if *p == target {
                    *p *= scale;
                }
            }
            assert_eq!(
                cannot_shadow_itself(&mesh),
                every_vertex_behind_every_face(&mesh),
                "scale {scale}"
            );
        }
    }
}
