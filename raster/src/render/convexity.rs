//! Which meshes cannot shadow themselves, so that shadow rays leaving them can skip their own
//! triangles.
//!
//! A shadow ray leaves a surface point on the side of its light. If every vertex of the mesh
//! lies behind (or on) the plane of every face, the whole mesh lies in the closed back
//! half-space of each of its faces, and a ray leaving a face into the open front half-space
//! never comes back to it: the mesh cannot block it. (Points whose light is behind them get
//! nothing through the cosine anyway.) Flat meshes, closed convex ones and open pieces of
//! convex ones — spheres, slabs, boxes, floors, domes — all pass, and their own triangles are
//! exactly the ones a ray starting on them has to wade through in the BVH. Inward-facing
//! normals put the vertices in front of the faces: such a mesh is left to shadow itself,
//! which is merely slower.
//!
//! The test is the definition, exhaustively: every vertex against every face's plane, in f64
//! relative to the face's first corner. A local test (convex across every edge) was tried and
//! is not sound: a surface can be convex at every edge and still fold through itself.
//! The V·F pairs are pruned by a tree of oriented boxes over the vertices ([`VertexTree`]): a
//! box entirely behind a plane is skipped, so a convex mesh costs a few boxes per level of the
//! tree for each face (170 visits per face on a 261k-triangle sphere). The work is
//! capped at [`WORK_LIMIT`] box and vertex visits; beyond it the mesh is taken to shadow
//! itself (correct, only slower). A mesh with many faces tests [`PROBE_FACES`] of them first,
//! evenly spread: when their visits extrapolate to well over the cap, it is given up then,
//! not after spending the whole cap (a UV sphere of two million faces would need 1.7 times
//! the cap). A mesh of hundreds of thousands of faces is first probed against a sketch of the
//! tree, over the corners of a few thousand faces ([`sketched_work`]): a probe of the whole
//! tree costs the tree, a second of CPU or more at millions of faces. A flat mesh is
//! recognised first, in one pass. Before the tree is built,
//! [`SCANNED_FACES`] faces spread over the mesh are tested against every vertex directly: a
//! mesh that is not convex (a scan, a character) nearly always fails one of them, and then
//! never pays for the tree.
//!
//! Tolerances are relative to the bounding-box diagonal of the positions ([`TOLERANCE`]), and
//! faces whose corners lie within [`DEGENERATE`] of the diagonal of each other have no
//! reliable plane and are not tested as planes (their corners are still tested as vertices).

use std::sync::atomic::{AtomicU64, Ordering};

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use crate::memory::{self, OutOfMemory};
use crate::scene::Mesh;

/// Relative tolerance (of the bounding-box diagonal) for "behind or on a plane".
const TOLERANCE: f64 = 1e-5;
/// Faces with two corners closer than this (relative to the diagonal) have no plane of their
/// own worth testing.
const DEGENERATE: f64 = 4e-6;
/// Box and vertex visits after which the exhaustive test gives up (the mesh is then assumed
/// to shadow itself): about half a second at most.
const WORK_LIMIT: u64 = 200_000_000;
/// Faces a large mesh's test visits first, spread evenly over it, to estimate its whole work.
const PROBE_FACES: usize = 1024;
/// Faces tested against every vertex directly before the tree is built, spread evenly over
/// the mesh (at most one more than this).
const SCANNED_FACES: usize = 8;
/// A mesh whose estimated work exceeds the budget by this factor is given up before the full
/// test (the estimate from [`PROBE_FACES`] faces is within a few percent on smooth meshes).
const PROBE_MARGIN: f64 = 1.25;
/// How far (relative to the diagonal) a box's bound must stay behind the tolerance for the box
/// to be skipped. Coordinates are taken relative to the bounding box's corner, so they are at
/// most the diagonal, and the boxes' centres, axes and extents round by a few 2⁻⁵² of it.
const MARGIN: f64 = 1e-9;
/// Vertices per leaf of the box tree.
const LEAF: usize = 8;
/// Faces whose corners make the sketch of a large mesh's tree ([`sketched_work`]); a mesh of
/// at least [`SKETCHED_ABOVE`] times as many faces is sketched before anything else.
const SKETCH_FACES: usize = 16_384;
/// See [`SKETCH_FACES`].
const SKETCHED_ABOVE: usize = 16;

/// True if no ray leaving a point of the mesh towards a light (from the side the light is on)
/// can hit the mesh again: every vertex lies behind or on the plane of every face (within the
/// tolerance), which includes flat meshes. Meshes too large for the exhaustive test within
/// `WORK_LIMIT`, and meshes with non-finite positions, are taken to shadow themselves.
pub fn cannot_shadow_itself(mesh: &Mesh) -> bool {
    cannot_shadow_itself_within(mesh, WORK_LIMIT, SKETCH_FACES).0
}

/// [`cannot_shadow_itself`] with a budget of `limit` box and vertex visits, and the visits
/// made; a mesh of at least [`SKETCHED_ABOVE`] × `sketch` faces is sketched from `sketch`.
fn cannot_shadow_itself_within(mesh: &Mesh, limit: u64, sketch: usize) -> (bool, u64) {
    let Some((origin, diagonal)) = bounds(&mesh.positions) else {
        return (true, 0);
    };
    if !diagonal.is_finite() {
        return (false, 0);
    }
    // Millions of faces: the whole tree and what comes before it cost about 0.35 µs of CPU a
    // vertex (1.4 s on 7.8 M faces), which a mesh far over the budget need not pay to be
    // given up.
    if mesh.triangles.len() >= SKETCHED_ABOVE * sketch {
        let Some((estimate, visits)) = sketched_work(mesh, origin, diagonal, sketch) else {
            return (false, 0);
        };
        if estimate > limit as f64 {
            return (false, visits);
        }
    }
    // A mesh whose test does not fit in memory is taken to shadow itself, like one whose test
    // exceeds the work limit.
    let Ok(faces) = Faces::new(mesh, origin, diagonal) else {
        return (false, 0);
    };
    let Ok(vertices) = referenced_vertices(mesh, origin) else {
        return (false, 0);
    };
    let tolerance = TOLERANCE * diagonal;
    let Some(widest) = faces.widest else {
        return (true, 0); // no face with a plane: nothing a ray could hit but lines and points
    };
    let widest = faces.plane(widest);
    if vertices
        .iter()
        .all(|v| widest.distance(v.at).abs() <= tolerance)
    {
        return (true, 0); // flat
    }
    // A few faces spread over the mesh, each against every vertex directly: a mesh that is not
    // convex nearly always fails one of them, and then the tree is never built (on 2 M faces
    // that is most of the test's cost). A face failing here fails the full test too: this is
    // the comparison its leaves make.
    if let Some(compared) = scanned_face_fails(&faces, &vertices, tolerance) {
        return (false, compared);
    }
    let Ok(tree) = VertexTree::build(vertices) else {
        return (false, 0);
    };
    let margin = MARGIN * diagonal;
    // A mesh of millions of faces can need more than the budget, and the full test would spend
    // all of it before giving up: a few faces spread over the mesh tell first. A face that
    // fails here fails the full test too.
    let mut probe_visits = 0;
    // The faces probed are those at multiples of `stride`; 0 when there is no probe.
    let mut stride = 0;
    let count = faces.with_plane.len();
    if count > 4 * PROBE_FACES {
        stride = count / PROBE_FACES;
        let planes = faces.with_plane.iter().step_by(stride);
        let (estimate, visits) = match probe(
            &tree,
            planes.map(|&face| faces.plane(face)),
            count,
            tolerance,
            margin,
        ) {
            Ok(probed) => probed,
            Err(visits) => return (false, visits),
        };
        probe_visits = visits;
        if estimate > PROBE_MARGIN * limit as f64 {
            return (false, probe_visits);
        }
    }
    // The other faces in parallel, the probe's visits already counted. The answer does not
    // depend on the order: true needs every face to pass, and then the total work is the same
    // sum whatever the order.
    let work = AtomicU64::new(probe_visits);
    let probed = |i: usize| stride != 0 && i.is_multiple_of(stride);
    let passed = faces.with_plane.par_iter().enumerate().all(|(i, &face)| {
        if probed(i) {
            return true;
        }
        let (passed, visits) = tree.nothing_in_front(&faces.plane(face), tolerance, margin);
        passed && work.fetch_add(visits, Ordering::Relaxed) + visits <= limit
    });
    (passed, work.load(Ordering::Relaxed))
}

/// Whether one of [`SCANNED_FACES`] faces with a plane, spread evenly over them, has a vertex
/// in front of it (farther than `tolerance`), and if so the vertex comparisons made up to that
/// vertex. One pass over the vertices for all those faces, so that each vertex is read once.
fn scanned_face_fails(faces: &Faces, vertices: &[Vertex], tolerance: f64) -> Option<u64> {
    let count = faces.with_plane.len();
    let scanned: Vec<Plane> = faces
        .with_plane
        .iter()
        .step_by(count.div_ceil(SCANNED_FACES).max(1))
        .map(|&face| faces.plane(face))
        .collect();
    vertices
        .iter()
        .position(|v| scanned.iter().any(|plane| plane.distance(v.at) > tolerance))
        .map(|k| (k as u64 + 1) * scanned.len() as u64)
}

/// The whole test's box and vertex visits estimated from a sketch of the tree, and the visits
/// that took; `None` if a face has a vertex in front of it or the sketch does not fit in
/// memory (either way the mesh is taken to shadow itself).
///
/// The sketch is the tree over the corners of `sketch` faces spread evenly over the mesh (each
/// corner with its face's normal), probed by [`PROBE_FACES`] faces spread likewise. It is
/// shallower than the whole tree, and the visits per face grow with the depth (see
/// `the_work_is_bounded`), so the estimate is low: 0.67 and 0.72 of the probe's on UV spheres
/// of 7.8 M and 2 M faces. An estimate above the budget therefore says that the whole test
/// would be given up too, for a few milliseconds instead of the tree's second or more. A face
/// failing against the sketch's corners (mesh vertices) fails the full test too.
fn sketched_work(mesh: &Mesh, origin: DVec3, diagonal: f64, sketch: usize) -> Option<(f64, u64)> {
    let count = mesh.triangles.len();
    let corners = mesh
        .triangles
        .iter()
        .step_by((count / sketch.max(1)).max(1))
        .flat_map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize].as_dvec3());
            let normal = (b - a).cross(c - a);
            let normal = if normal.is_finite() {
                normal
            } else {
                DVec3::ZERO
            };
            [a, b, c].map(|at| Vertex {
                at: at - origin,
                normal,
            })
        });
    let tree = VertexTree::build(corners.collect()).ok()?;
    let (tolerance, margin, apart) = (
        TOLERANCE * diagonal,
        MARGIN * diagonal,
        DEGENERATE * diagonal,
    );
    let planes = (0..count as u32)
        .step_by((count / PROBE_FACES).max(1))
        .filter_map(|face| plane_of(mesh, origin, apart, face));
    probe(&tree, planes, count, tolerance, margin).ok()
}

/// Tests the faces of `planes` against `tree` and extrapolates their visits to `count` faces:
/// the estimate and the visits made, or, if a face has a vertex in front of it, the visits
/// made up to it.
fn probe(
    tree: &VertexTree,
    planes: impl Iterator<Item = Plane>,
    count: usize,
    tolerance: f64,
    margin: f64,
) -> Result<(f64, u64), u64> {
    let (mut visits, mut probed) = (0u64, 0u64);
    for plane in planes {
        let (passed, v) = tree.nothing_in_front(&plane, tolerance, margin);
        visits += v;
        probed += 1;
        if !passed {
            return Err(visits);
        }
    }
    Ok((visits as f64 / probed.max(1) as f64 * count as f64, visits))
}

/// The smallest corner of the positions' bounding box and its diagonal's length, in f64 (the
/// f32 length overflows for coordinates beyond about 10¹⁹); `None` for no positions.
fn bounds(positions: &[Vec3]) -> Option<(DVec3, f64)> {
    if positions.is_empty() {
        return None;
    }
    let (lo, hi) = positions
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v.as_dvec3()), hi.max(v.as_dvec3()))
        });
    Some((lo, (hi - lo).length()))
}

/// A face's plane: a corner (relative to the bounding box's corner) and the unit normal
/// (counter-clockwise winding faces the viewer), in f64, where the products and sums of f32
/// coordinates neither overflow nor underflow.
struct Plane {
    at: DVec3,
    normal: DVec3,
    /// Twice the face's area, to pick the most reliable plane for the flatness test.
    area: f64,
}

impl Plane {
    /// Signed distance of `p` from the plane, positive in front.
    fn distance(&self, p: DVec3) -> f64 {
        self.normal.dot(p - self.at)
    }
}

/// The faces whose corners are pairwise farther apart than [`DEGENERATE`] of the diagonal and
/// whose normal is non-zero: those with a plane worth testing. Each plane is computed when it
/// is tested, not stored (56 bytes a face, 440 MB on a mesh of 7.8 M faces, most of which a
/// large mesh's test never reaches).
struct Faces<'m> {
    mesh: &'m Mesh,
    origin: DVec3,
    apart: f64,
    /// The faces with a plane, ascending.
    with_plane: Vec<u32>,
    /// The one of largest area (the last of equals), the most reliable plane.
    widest: Option<u32>,
}

impl<'m> Faces<'m> {
    fn new(mesh: &'m Mesh, origin: DVec3, diagonal: f64) -> Result<Self, OutOfMemory> {
        let mut faces = Faces {
            mesh,
            origin,
            apart: DEGENERATE * diagonal,
            with_plane: memory::with_capacity(mesh.triangles.len(), memory::TRIANGLES)?,
            widest: None,
        };
        let mut widest = f64::NEG_INFINITY;
        for face in 0..mesh.triangles.len() as u32 {
            if let Some(plane) = faces.try_plane(face) {
                faces.with_plane.push(face);
                if plane.area >= widest {
                    (widest, faces.widest) = (plane.area, Some(face));
                }
            }
        }
        Ok(faces)
    }

    /// The plane of `face`, if it has one worth testing.
    fn try_plane(&self, face: u32) -> Option<Plane> {
        plane_of(self.mesh, self.origin, self.apart, face)
    }

    /// The plane of a face of [`Faces::with_plane`].
    fn plane(&self, face: u32) -> Plane {
        self.try_plane(face)
            .expect("a face listed as having a plane has one")
    }
}

/// The plane of `face` relative to `origin`, if its corners are pairwise farther apart than
/// `apart` and its normal is non-zero.
fn plane_of(mesh: &Mesh, origin: DVec3, apart: f64, face: u32) -> Option<Plane> {
    let t = mesh.triangles[face as usize];
    let [a, b, c] = t.map(|i| mesh.positions[i as usize].as_dvec3());
    if a.distance(b) <= apart || b.distance(c) <= apart || a.distance(c) <= apart {
        return None;
    }
    let n = (b - a).cross(c - a);
    let area = n.length();
    (area > 0.0 && area.is_finite()).then(|| Plane {
        at: a - origin,
        normal: n / area,
        area,
    })
}

/// Every face's plane, in face order (for the tests' references).
#[cfg(test)]
fn face_planes(mesh: &Mesh, origin: DVec3, diagonal: f64) -> Result<Vec<Plane>, OutOfMemory> {
    let faces = Faces::new(mesh, origin, diagonal)?;
    Ok(faces.with_plane.iter().map(|&f| faces.plane(f)).collect())
}

/// The positions some triangle uses, each once, relative to `origin`, with an outward
/// direction for each: the sum of its faces' area-weighted normals (only a hint for the
/// orientation of [`VertexTree`]'s boxes; any direction keeps the test exact).
fn referenced_vertices(mesh: &Mesh, origin: DVec3) -> Result<Vec<Vertex>, OutOfMemory> {
    let n = mesh.positions.len();
    let mut normals = memory::filled(n, DVec3::ZERO, memory::TRIANGLES)?;
    let mut used = memory::filled(n, false, memory::TRIANGLES)?;
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| mesh.positions[i as usize].as_dvec3());
        let n = (b - a).cross(c - a);
        for &i in t {
            used[i as usize] = true;
            if n.is_finite() {
                normals[i as usize] += n;
            }
        }
    }
    let mut vertices = memory::with_capacity(n, memory::TRIANGLES)?;
    vertices.extend(
        mesh.positions
            .iter()
            .zip(normals)
            .zip(used)
            .filter(|&(_, used)| used)
            .map(|((p, normal), _)| Vertex {
                at: p.as_dvec3() - origin,
                normal,
            }),
    );
    Ok(vertices)
}

/// A vertex for [`VertexTree`].
#[derive(Clone, Copy)]
struct Vertex {
    at: DVec3,
    normal: DVec3,
}

/// A tree of oriented boxes over the vertices, for "is any vertex in front of this plane?".
///
/// ```text
/// nodes[0]             the root: all vertices
/// nodes[i].children    index of the first of two children (the second follows), 0 for a leaf
/// nodes[i].start..end  its vertices in `vertices` (a leaf holds at most LEAF)
/// nodes[i].box         an oriented box holding them: centre, three orthonormal axes (the
///                      third along the vertices' summed normals), half sizes along each
/// ```
///
/// Built by median splits along the longest axis of the vertices' axis-aligned box, so the
/// depth is about log₂(V / LEAF). Why oriented: near a face of a curved convex mesh its
/// neighbours lie just behind its plane, and an axis-aligned box around them reaches in front
/// of it by about its own size, so every box near the face had to be opened (√V vertices per
/// face on a sphere). A box turned to the surface is only as thick as the surface's sag across
/// it, and lies behind the plane.
struct VertexTree {
    vertices: Vec<Vertex>,
    nodes: Vec<Node>,
}

/// One box of [`VertexTree`].
struct Node {
    center: DVec3,
    axes: [DVec3; 3],
    half: DVec3,
    children: u32,
    start: u32,
    end: u32,
}

impl VertexTree {
    fn build(mut vertices: Vec<Vertex>) -> Result<Self, OutOfMemory> {
        let mut nodes =
            memory::with_capacity(2 * vertices.len().div_ceil(LEAF) + 1, memory::TRIANGLES)?;
        nodes.push(Node::of(&vertices, 0, vertices.len()));
        let mut stack = vec![0usize];
        while let Some(i) = stack.pop() {
            let (start, end) = (nodes[i].start as usize, nodes[i].end as usize);
            if end - start <= LEAF {
                continue;
            }
            let (lo, hi) = vertices[start..end]
                .iter()
                .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), v| {
                    (lo.min(v.at), hi.max(v.at))
                });
            let axis = (hi - lo).max_position();
            let mid = start + (end - start) / 2;
            vertices[start..end]
                .select_nth_unstable_by(mid - start, |a, b| a.at[axis].total_cmp(&b.at[axis]));
            let left = nodes.len();
            nodes.push(Node::of(&vertices, start, mid));
            nodes.push(Node::of(&vertices, mid, end));
            nodes[i].children = left as u32;
            stack.extend([left, left + 1]);
        }
        Ok(VertexTree { vertices, nodes })
    }

    /// Whether no vertex lies more than `tolerance` in front of `plane` (whose corner is
    /// relative to the tree's origin), and the number of box and vertex visits it took. A box
    /// is skipped when its bound is more than `margin` behind the tolerance: `margin` must
    /// exceed the f64 rounding of the boxes.
    fn nothing_in_front(&self, plane: &Plane, tolerance: f64, margin: f64) -> (bool, u64) {
        let reach = |node: &Node| {
            let [u, v, w] = node.axes;
            let n = plane.normal;
            plane.distance(node.center)
                + n.dot(u).abs() * node.half.x
                + n.dot(v).abs() * node.half.y
                + n.dot(w).abs() * node.half.z
        };
        let open = |i: usize| reach(&self.nodes[i]) + margin > tolerance;
        let mut stack = Vec::with_capacity(64);
        let mut visits = 1;
        if open(0) {
            stack.push(0usize);
        }
        while let Some(i) = stack.pop() {
            let node = &self.nodes[i];
            if node.children == 0 {
                let vertices = &self.vertices[node.start as usize..node.end as usize];
                visits += vertices.len() as u64;
                if vertices.iter().any(|v| plane.distance(v.at) > tolerance) {
                    return (false, visits);
                }
            } else {
                visits += 2;
                let (a, b) = (node.children as usize, node.children as usize + 1);
                let (reach_a, reach_b) = (reach(&self.nodes[a]), reach(&self.nodes[b]));
                // Push the box reaching farther in front last, so that it is opened first: a
                // vertex in front, if any, is found sooner.
                let (first, second) = if reach_a > reach_b { (b, a) } else { (a, b) };
                let (reach_first, reach_second) = if reach_a > reach_b {
                    (reach_b, reach_a)
                } else {
                    (reach_a, reach_b)
                };
                if reach_first + margin > tolerance {
                    stack.push(first);
                }
                if reach_second + margin > tolerance {
                    stack.push(second);
                }
            }
        }
        (true, visits)
    }

    /// Checks the structure: every node's box holds its vertices, children split their
    /// parent's range, leaves hold at most [`LEAF`] vertices.
    #[cfg(test)]
    fn validate(&self) {
        for node in &self.nodes {
            for v in &self.vertices[node.start as usize..node.end as usize] {
                for (axis, half) in node.axes.iter().zip(node.half.to_array()) {
                    let off = axis.dot(v.at - node.center).abs() - half;
                    assert!(off <= 1e-9 * (1.0 + half), "{off} outside the box");
                }
            }
            if node.children == 0 {
                assert!(node.end - node.start <= LEAF as u32);
            } else {
                let (a, b) = (
                    &self.nodes[node.children as usize],
                    &self.nodes[node.children as usize + 1],
                );
                assert_eq!((a.start, a.end, b.end), (node.start, b.start, node.end));
            }
        }
    }
}

impl Node {
    /// An oriented box of `vertices[start..end]`: the third axis along their summed normals
    /// (the z axis if those cancel), the extents exact along each axis.
    fn of(vertices: &[Vertex], start: usize, end: usize) -> Node {
        let vertices = &vertices[start..end];
        let normal = vertices
            .iter()
            .fold(DVec3::ZERO, |sum, v| sum + v.normal)
            .try_normalize()
            .unwrap_or(DVec3::Z);
        let (u, v) = normal.any_orthonormal_pair();
        let axes = [u, v, normal];
        let (lo, hi) = vertices.iter().fold(
            (DVec3::INFINITY, DVec3::NEG_INFINITY),
            |(lo, hi), vertex| {
                let p = DVec3::from_array(axes.map(|axis| axis.dot(vertex.at)));
                (lo.min(p), hi.max(p))
            },
        );
        let mid = (lo + hi) * 0.5;
        Node {
            center: u * mid.x + v * mid.y + normal * mid.z,
            axes,
            half: (hi - lo) * 0.5,
            children: 0,
            start: start as u32,
            end: end as u32,
        }
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

    /// The definition by brute force, without the tree: every corner of every triangle
    /// behind every face's plane.
    fn every_vertex_behind_every_face(mesh: &Mesh) -> bool {
        let (origin, diagonal) = bounds(&mesh.positions).expect("a mesh with vertices");
        face_planes(mesh, origin, diagonal)
            .unwrap()
            .iter()
            .all(|f| {
                mesh.triangles.iter().flatten().all(|&i| {
                    let p = mesh.positions[i as usize].as_dvec3() - origin;
                    f.distance(p) <= TOLERANCE * diagonal
                })
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
        // A box with one face removed is open but still on the back of all its faces: a ray
        // leaving a face outwards cannot come back.
        let mut open = shapes::cuboid(Vec3::ONE);
        open.triangles.truncate(open.triangles.len() - 2);
        assert!(cannot_shadow_itself(&open));
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
        let mut inside_out = shapes::cuboid(Vec3::new(1.0, 2.0, 4.0));
        for t in &mut inside_out.triangles {
            t.swap(1, 2);
        }
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
            assert!(
                !cannot_shadow_itself(&moved(inside_out.clone(), s)),
                "inside out 2^{e}"
            );
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
        huge.triangles[3].swap(1, 2);
        assert!(!cannot_shadow_itself(&huge));
    }

    #[test]
    fn the_tree_agrees_with_the_brute_force() {
        // Spheres with one vertex pushed out or in by various amounts, and turned inside out.
        for (k, scale) in [1.0f32, 1.5, 0.999, 0.9, 1.0001, 1.00002, 0.99998]
            .into_iter()
            .enumerate()
        {
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
        // Random point clouds triangulated arbitrarily, and their convex subsets: a sphere's
        // vertices with random triangles among them are convex only if each triangle faces out.
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 33) as u32
        };
        let sphere = shapes::sphere(1.0, 24);
        for round in 0..200 {
            let mut mesh = sphere.clone();
            let n = mesh.positions.len() as u32;
            let count = 1 + round % 40;
            mesh.triangles = (0..count)
                .map(|_| [next() % n, next() % n, next() % n])
                .collect();
            let (origin, _) = bounds(&mesh.positions).expect("vertices");
            let tree = VertexTree::build(referenced_vertices(&mesh, origin).unwrap()).unwrap();
            tree.validate();
            assert_eq!(
                cannot_shadow_itself(&mesh),
                every_vertex_behind_every_face(&mesh),
                "round {round}"
            );
        }
    }

    /// A surface convex at every edge can still fold through itself: a 10-segment sphere with
    /// its south pole pulled up through the body, far out of the north pole (the input
    /// `regress-needle-through-sphere-local-tolerance` of the fuzz target `convexity_is_sound`
    /// found it accepted by a local, edge-by-edge test).
    #[test]
    fn a_surface_folded_through_itself_is_found() {
        let mut needle = shapes::sphere(1.0, 10);
        let south = needle
            .positions
            .iter()
            .copied()
            .min_by(|a, b| a.z.total_cmp(&b.z))
            .expect("vertices");
        for p in &mut needle.positions {
            if p.distance(south) < 1e-6 {
                *p = Vec3::new(0.0, 0.0, 25_000.0);
            }
        }
        assert!(!cannot_shadow_itself(&needle));
        assert!(!every_vertex_behind_every_face(&needle));
    }

    /// Box and vertex visits per face for the whole test, and whether it passed.
    fn visits_per_face(mesh: &Mesh) -> (f64, bool) {
        let (origin, diagonal) = bounds(&mesh.positions).expect("vertices");
        let planes = face_planes(mesh, origin, diagonal).unwrap();
        let tree = VertexTree::build(referenced_vertices(mesh, origin).unwrap()).unwrap();
        tree.validate();
        let (passed, visits) = planes.iter().fold((true, 0), |(all, sum), plane| {
            let (one, visits) =
                tree.nothing_in_front(plane, TOLERANCE * diagonal, MARGIN * diagonal);
            (all && one, sum + visits)
        });
        (visits as f64 / planes.len() as f64, passed)
    }

    #[test]
    fn the_work_is_bounded() {
        let small = visits_per_face(&shapes::sphere(1.0, 64));
        let large = visits_per_face(&shapes::sphere(1.0, 256));
        assert!(small.1 && large.1);
        // With 16 times the vertices, the visits per face grow like the tree's depth (about
        // 1.5 times), not like √V (4 times) as with axis-aligned boxes.
        assert!(
            large.0 < 2.0 * small.0 && large.0 < 200.0,
            "{small:?} {large:?} visits per face"
        );
        // The budget stops the test: the sphere is then taken to shadow itself.
        let sphere = shapes::sphere(1.0, 64);
        let needed = (small.0 * sphere.triangles.len() as f64) as u64;
        assert!(cannot_shadow_itself_within(&sphere, needed + 1000, SKETCH_FACES).0);
        assert!(!cannot_shadow_itself_within(&sphere, needed / 2, SKETCH_FACES).0);
    }

    #[test]
    fn a_mesh_far_over_the_budget_is_given_up_after_a_probe() {
        let sphere = shapes::sphere(1.0, 256);
        let faces = sphere.triangles.len();
        assert!(faces > 4 * PROBE_FACES, "{faces} faces");
        let (per_face, convex) = visits_per_face(&sphere);
        assert!(convex);
        let needed = (per_face * faces as f64) as u64;
        // Within the budget: the probe, then the whole test, passes.
        let (passed, work) =
            cannot_shadow_itself_within(&sphere, needed + needed / 4, SKETCH_FACES);
        assert!(passed && work >= needed, "{work} visits for {needed}");
        // Far over it: given up after the probe's visits, not after the budget's.
        let (passed, work) = cannot_shadow_itself_within(&sphere, needed / 4, SKETCH_FACES);
        assert!(!passed);
        let probe = (2.0 * per_face * PROBE_FACES as f64) as u64;
        assert!(
            work < probe,
            "{work} visits, a probe of {PROBE_FACES} faces needs about {probe}"
        );
        // A mesh that fails is refused before the tree: the sphere turned inside out has
        // vertices in front of the first face scanned, so its work is that scan's comparisons.
        let mut inverted = sphere.clone();
        for t in &mut inverted.triangles {
            t.swap(1, 2);
        }
        let (passed, work) = cannot_shadow_itself_within(&inverted, WORK_LIMIT, SKETCH_FACES);
        assert!(
            !passed && work <= sphere.positions.len() as u64,
            "{work} visits"
        );
    }

    /// The sketch's estimate is below the whole test's work, and not far below.
    #[test]
    fn the_sketch_estimates_the_work_from_below() {
        let sphere = shapes::sphere(1.0, 256);
        let (per_face, _) = visits_per_face(&sphere);
        let needed = per_face * sphere.triangles.len() as f64;
        let (origin, diagonal) = bounds(&sphere.positions).expect("vertices");
        for sketch in [1024, 4096] {
            let (estimate, visits) =
                sketched_work(&sphere, origin, diagonal, sketch).expect("convex");
            assert!(
                estimate < needed && estimate > 0.4 * needed,
                "{estimate} from {sketch} faces' corners, {needed} needed"
            );
            assert!(visits < 2 * PROBE_FACES as u64 * per_face as u64);
        }
        let mut inverted = sphere.clone();
        for t in &mut inverted.triangles {
            t.swap(1, 2);
        }
        assert!(sketched_work(&inverted, origin, diagonal, 1024).is_none());
    }

    /// A mesh far over the budget is given up after the sketch's probe, before its tree is
    /// built; within the budget the sketch changes nothing.
    #[test]
    fn a_mesh_far_over_the_budget_is_given_up_by_its_sketch() {
        let sphere = shapes::sphere(1.0, 256);
        let sketch = 2048;
        assert!(sphere.triangles.len() >= SKETCHED_ABOVE * sketch);
        let (per_face, _) = visits_per_face(&sphere);
        let needed = (per_face * sphere.triangles.len() as f64) as u64;
        let (origin, diagonal) = bounds(&sphere.positions).expect("vertices");
        let (_, sketch_visits) = sketched_work(&sphere, origin, diagonal, sketch).unwrap();
        assert_eq!(
            cannot_shadow_itself_within(&sphere, needed / 4, sketch),
            (false, sketch_visits)
        );
        let (passed, work) = cannot_shadow_itself_within(&sphere, needed + needed / 4, sketch);
        assert!(passed && work >= needed, "{work} visits for {needed}");
        // Not sketched below the size: the probe of the whole tree gives it up.
        let (passed, work) =
            cannot_shadow_itself_within(&sphere, needed / 4, sphere.triangles.len());
        assert!(!passed && work != sketch_visits);
    }

    /// A bumpy sphere (not convex, its dents hidden from most faces' planes by the bumps
    /// around them) is refused by one of the faces scanned directly, and agrees with the
    /// definition.
    #[test]
    fn a_bumpy_sphere_is_refused_by_the_direct_scan() {
        let mut bumpy = shapes::sphere(1.0, 64);
        for p in &mut bumpy.positions {
            let (theta, phi) = (p.z.clamp(-1.0, 1.0).acos(), p.y.atan2(p.x));
            *p *= 1.0 + 0.03 * (6.0 * theta).sin() * (6.0 * phi).sin();
        }
        assert!(!cannot_shadow_itself(&bumpy));
        assert!(!every_vertex_behind_every_face(&bumpy));
        let scan = |mesh: &Mesh| {
            let (origin, diagonal) = bounds(&mesh.positions).expect("vertices");
            let faces = Faces::new(mesh, origin, diagonal).unwrap();
            let vertices = referenced_vertices(mesh, origin).unwrap();
            scanned_face_fails(&faces, &vertices, TOLERANCE * diagonal)
        };
        let compared = scan(&bumpy).expect("a scanned face fails");
        assert!(compared <= (SCANNED_FACES as u64 + 1) * bumpy.positions.len() as u64);
        // A convex mesh passes the scan (and then the whole test).
        assert_eq!(scan(&shapes::sphere(1.0, 64)), None);
        assert_eq!(scan(&shapes::cuboid(Vec3::new(1.0, 2.0, 3.0))), None);
    }
}
