//! Smooth normals for meshes whose files split every vertex (`weld = true`, `crease_angle`).
//!
//! Exporters of STL-like or "flat shaded" OBJ files write each triangle with its own three
//! vertices, so area-weighted vertex normals are just face normals and the surface shades
//! faceted. Welding finds the triangles that meet at the same point (bit-identical positions)
//! and, at each corner, averages the area-weighted normals of the triangles reachable around
//! that point across edges whose dihedral angle is below the crease angle. Edges sharper than
//! that stay creases. Output vertices are merged per (position, UV, fan): a vertex split by a
//! UV seam stays split (both copies get the same smooth normal), and a point whose corners fall
//! into different smoothing fans keeps one copy per fan.
//!
//! ```text
//!   corner c = 3·triangle + k    fan: union of corners at one position joined across
//!   ┌───┬───┬───┐                 smooth edges → one normal (Σ area-weighted face normals)
//!   │c0 │c1 │c2 │ … 3·T corners   (position, UV, fan) → one output vertex
//!   └───┴───┴───┘
//! ```

use std::collections::HashMap;

use glam::Vec3;
use rayon::slice::ParallelSliceMut;

use super::model::Mesh;

/// The largest accepted crease angle (degrees): 180 smooths across every edge.
pub const MAX_CREASE_DEGREES: f32 = 180.0;

/// For each vertex, the index of the first vertex with a bit-identical position (−0 and +0
/// count as equal), so that equal ids mean the same point.
///
/// One sort of (position bits, index): a run of equal positions starts with its lowest index.
/// A hash map of positions took 3–4 times as long on a million vertices, and a sort's time
/// does not depend on how the positions collide.
pub fn position_ids(positions: &[Vec3]) -> Vec<u32> {
    let mut keyed: Vec<([u32; 3], u32)> = positions
        .iter()
        .enumerate()
        .map(|(i, p)| (position_bits(*p), i as u32))
        .collect();
    // In parallel: the keys are distinct (the index is one), so the order is the same.
    keyed.par_sort_unstable();
    let mut ids = vec![0; positions.len()];
    let mut first = 0;
    for (j, &(key, i)) in keyed.iter().enumerate() {
        if j == 0 || key != keyed[j - 1].0 {
            first = i;
        }
        ids[i as usize] = first;
    }
    ids
}

/// The bits that identify a position: −0 is made +0 (adding +0 does that and nothing else).
fn position_bits(p: Vec3) -> [u32; 3] {
    (p + Vec3::ZERO).to_array().map(f32::to_bits)
}

/// A triangle using a welded edge: (triangle, its corner at the edge's smaller position id,
/// its corner at the larger one).
type EdgeUse = (u32, u32, u32);

/// Union–find over corners, with path halving.
struct Fans(Vec<u32>);

impl Fans {
    fn root(&mut self, mut x: u32) -> u32 {
        while self.0[x as usize] != x {
            let up = self.0[self.0[x as usize] as usize];
            self.0[x as usize] = up;
            x = up;
        }
        x
    }

    fn join(&mut self, a: u32, b: u32) {
        let (a, b) = (self.root(a), self.root(b));
        // The smaller root wins, so the result does not depend on the order of joins.
        let (lo, hi) = if a < b { (a, b) } else { (b, a) };
        self.0[hi as usize] = lo;
    }
}

/// Replaces the mesh's normals by welded, crease-limited smooth normals (see the module
/// docs). Triangles keep their order and winding; vertices may be split where a crease passes
/// through them. `crease_degrees` is in [0, 180].
pub fn weld_normals(mesh: &mut Mesh, crease_degrees: f32) {
    let ids = position_ids(&mesh.positions);
    let cos_crease = crease_degrees.to_radians().cos();
    let faces: Vec<Vec3> = mesh
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            (b - a).cross(c - a)
        })
        .collect();
    let units: Vec<Option<Vec3>> = faces.iter().map(|n| n.try_normalize()).collect();

    // Welded edges (smaller id first) → the corners at each end, per triangle using it.
    let mut edges: HashMap<(u32, u32), Vec<EdgeUse>> = HashMap::new();
    for (f, t) in mesh.triangles.iter().enumerate() {
        for k in 0..3 {
            let (ka, kb) = (k, (k + 1) % 3);
            let (a, b) = (ids[t[ka] as usize], ids[t[kb] as usize]);
            if a == b {
                continue;
            }
            let (ca, cb) = ((3 * f + ka) as u32, (3 * f + kb) as u32);
            let entry = if a < b {
                (f as u32, ca, cb)
            } else {
                (f as u32, cb, ca)
            };
            edges.entry((a.min(b), a.max(b))).or_default().push(entry);
        }
    }
    let mut fans = Fans((0..3 * mesh.triangles.len() as u32).collect());
    let mut keys: Vec<&(u32, u32)> = edges.keys().collect();
    keys.sort_unstable();
    for key in keys {
        let users = &edges[key];
        for (i, &(f, lo_f, hi_f)) in users.iter().enumerate() {
            for &(g, lo_g, hi_g) in &users[i + 1..] {
                let (Some(nf), Some(ng)) = (units[f as usize], units[g as usize]) else {
                    continue;
                };
                if f != g && nf.dot(ng) > cos_crease {
                    fans.join(lo_f, lo_g);
                    fans.join(hi_f, hi_g);
                }
            }
        }
    }

    // One normal per fan: the sum of its triangles' area-weighted normals.
    let corners = 3 * mesh.triangles.len();
    let mut sum = vec![Vec3::ZERO; corners];
    for c in 0..corners as u32 {
        let r = fans.root(c);
        sum[r as usize] += faces[c as usize / 3];
    }
    // One output vertex per (position, UV, fan), in order of first use.
    let uv_bits = |v: u32| {
        mesh.uvs
            .as_ref()
            .map_or([0; 2], |u| u[v as usize].to_array().map(f32::to_bits))
    };
    let mut vertex_of: HashMap<(u32, [u32; 2], u32), u32> =
        HashMap::with_capacity(mesh.positions.len());
    let mut positions = Vec::with_capacity(mesh.positions.len());
    let mut normals = Vec::with_capacity(mesh.positions.len());
    let mut uvs = mesh.uvs.as_ref().map(|u| Vec::with_capacity(u.len()));
    for f in 0..mesh.triangles.len() {
        for k in 0..3 {
            let v = mesh.triangles[f][k];
            let r = fans.root((3 * f + k) as u32);
            let next = positions.len() as u32;
            let out = *vertex_of
                .entry((ids[v as usize], uv_bits(v), r))
                .or_insert(next);
            if out == next {
                positions.push(mesh.positions[v as usize]);
                normals.push(sum[r as usize].try_normalize().unwrap_or(Vec3::Z));
                if let (Some(out_uvs), Some(in_uvs)) = (uvs.as_mut(), mesh.uvs.as_ref()) {
                    out_uvs.push(in_uvs[v as usize]);
                }
            }
            mesh.triangles[f][k] = out;
        }
    }
    mesh.positions = positions;
    mesh.normals = normals;
    mesh.uvs = uvs;
}

/// A UV sphere whose seam column repeats the first column's positions bit for bit (the
/// built-in shape computes them from sin 2π, which is not exactly 0 in f32).
#[cfg(test)]
pub(crate) fn seamless_sphere(radius: f32, segments: u32) -> Mesh {
    let mut m = super::shapes::sphere(radius, segments);
    let row = segments as usize + 1;
    for j in 0..m.positions.len() / row {
        m.positions[j * row + row - 1] = m.positions[j * row];
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::mesh::validate_mesh;
    use crate::scene::shapes;

    /// Every triangle with its own three vertices and its face normal: what a faceted export
    /// looks like.
    fn unwelded(m: &Mesh) -> Mesh {
        let mut out = Mesh {
            uvs: m.uvs.as_ref().map(|_| Vec::new()),
            ..Mesh::default()
        };
        for t in &m.triangles {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            let n = (b - a).cross(c - a).normalize();
            let base = out.positions.len() as u32;
            for &i in t {
                out.positions.push(m.positions[i as usize]);
                out.normals.push(n);
                if let (Some(o), Some(u)) = (out.uvs.as_mut(), m.uvs.as_ref()) {
                    o.push(u[i as usize]);
                }
            }
            out.triangles.push([base, base + 1, base + 2]);
        }
        out
    }

    /// The largest angle between a vertex normal and the exact sphere normal p / |p|, over
    /// the vertices with |z| < `z_limit`, of the faceted input and of its welded result.
    fn sphere_errors(segments: u32, z_limit: f32) -> (f32, f32, Mesh) {
        let mut m = unwelded(&seamless_sphere(1.0, segments));
        let error = |m: &Mesh| {
            m.positions
                .iter()
                .zip(&m.normals)
                .filter(|(p, _)| p.z.abs() < z_limit)
                // |n × p̂| = sin of the angle: accurate for small angles, unlike acos.
                .map(|(p, n)| n.cross(p.normalize()).length())
                .fold(0.0f32, f32::max)
        };
        let faceted = error(&m);
        weld_normals(&mut m, MAX_CREASE_DEGREES);
        validate_mesh(&m).unwrap();
        (faceted, error(&m), m)
    }

    #[test]
    fn welded_sphere_normals_match_the_analytic_ones() {
        // The exact normal of a sphere at p is p / |p|. Facet normals are off by O(h) (h the
        // angular step). Area-weighted averages are off by O(h²) where the UV grid's cells
        // are nearly alike around a vertex (|z| < 0.9: measured 3.7e-3 at 64 segments, 9.8e-4
        // at 128); towards the poles the cells shrink fast and the error is O(h) (measured
        // 1.65e-2 at 64 segments on the rings next to them), still 4× below the facets'.
        let (faceted_64, welded_64, _) = sphere_errors(64, 0.9);
        let (faceted_128, welded_128, _) = sphere_errors(128, 0.9);
        assert!(faceted_64 > 0.04, "facets deviate by {faceted_64}");
        assert!(welded_64 < faceted_64 / 10.0, "{welded_64} vs {faceted_64}");
        assert!(
            welded_64 / welded_128 > 3.5,
            "not second order: {welded_64} → {welded_128}"
        );
        assert!(
            faceted_64 / faceted_128 < 2.5,
            "{faceted_64} → {faceted_128}"
        );
        let (faceted, worst, m) = sphere_errors(64, f32::INFINITY);
        assert!(worst < faceted / 3.0, "worst {worst} vs faceted {faceted}");
        assert!(worst < 2e-2, "worst {worst}");
        // UV seams stay: the output keeps every (position, UV) pair of the input.
        let input = unwelded(&seamless_sphere(1.0, 64));
        let pairs: std::collections::HashSet<_> = input
            .positions
            .iter()
            .zip(input.uvs.as_ref().unwrap())
            .map(|(p, t)| {
                (
                    p.to_array().map(f32::to_bits),
                    t.to_array().map(f32::to_bits),
                )
            })
            .collect();
        assert_eq!(m.positions.len(), pairs.len());
        assert_eq!(m.uvs.as_ref().map(Vec::len), Some(pairs.len()));
    }

    #[test]
    fn creases_keep_a_box_faceted_and_180_degrees_rounds_it() {
        let mut sharp = unwelded(&shapes::cuboid(Vec3::ONE));
        weld_normals(&mut sharp, 60.0);
        // Each face's two triangles share a fan per corner: 6 faces × 4 corners.
        assert_eq!(sharp.positions.len(), 24);
        for t in &sharp.triangles {
            let [a, b, c] = t.map(|i| sharp.positions[i as usize]);
            let face = (b - a).cross(c - a).normalize();
            for &i in t {
                assert!((sharp.normals[i as usize] - face).length() < 1e-6);
            }
        }
        let mut round = unwelded(&shapes::cuboid(Vec3::ONE));
        weld_normals(&mut round, 180.0);
        // Every corner of the box gets the normalised sum of its three faces' normals
        // (each face contributes two triangles at some corners, one at others: the split
        // diagonal decides, so only the octant is certain).
        for (p, n) in round.positions.iter().zip(&round.normals) {
            assert!(
                n.x * p.x > 0.0 && n.y * p.y > 0.0 && n.z * p.z > 0.0,
                "{p} {n}"
            );
        }
        // No corner is split any more: one vertex per (position, UV) of the input's 24.
        assert!(round.positions.len() <= 24);
    }

    #[test]
    fn position_ids_treat_signed_zeros_alike() {
        let ids = position_ids(&[Vec3::ZERO, Vec3::new(-0.0, 0.0, -0.0), Vec3::X]);
        assert_eq!(ids, vec![0, 0, 2]);
    }

    #[test]
    fn position_ids_name_the_first_vertex_at_each_position() {
        // The definition, vertex by vertex: the smallest index whose position has the same
        // bits (after −0 → +0). Positions drawn from a small set so that most repeat, with
        // signed zeros, infinities and NaNs among them.
        let values = [0.0, -0.0, 1.0, -2.5, f32::INFINITY, f32::NAN, 1e-40];
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut pick = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            values[(state % values.len() as u64) as usize]
        };
        let positions: Vec<Vec3> = (0..2000)
            .map(|_| Vec3::new(pick(), pick(), pick()))
            .collect();
        let ids = position_ids(&positions);
        for (i, p) in positions.iter().enumerate() {
            let bits = position_bits(*p);
            let first = positions
                .iter()
                .position(|q| position_bits(*q) == bits)
                .unwrap();
            assert_eq!(ids[i], first as u32, "vertex {i} at {p}");
        }
        assert!(ids.iter().enumerate().any(|(i, &id)| id as usize != i));
        assert_eq!(position_ids(&[]), Vec::<u32>::new());
    }
}
