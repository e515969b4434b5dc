//! Rays and the bounding volume hierarchy used for shadow rays.
//!
//! The renderer asks one question many times: is the segment from a surface point to a light
//! blocked? [`Bvh::build`] builds a compact binned-SAH hierarchy over the scene's world-space
//! triangles once; [`Bvh::occluded`] answers that question (any hit, early exit),
//! [`Bvh::occluded_hinted`] answers it faster for coherent rays by trying the last occluder
//! first, and
//! [`Bvh::intersect`] finds the closest hit. Shadow rays start at [`offset_origin`] so they do
//! not hit the triangle they leave.
//!
//! Robustness: the triangle test is watertight (Woop et al. 2013) and box tests are
//! conservative (Ize 2013), so rays through shared edges and vertices of a closed mesh always
//! hit it; non-finite triangles are skipped, degenerate ones never hit.
//!
//! | file | what |
//! |---|---|
//! | `aabb.rs` | boxes and the slab test |
//! | `ray.rs` | prepared rays, the watertight triangle test, hits, origin offset |
//! | `node.rs` | the 32-byte binary node and the 128-byte 4-wide node |
//! | `build.rs` | binned SAH construction, collapse to the 4-wide tree |
//! | `cluster.rs` | runs of touching triangles built as one item (large scenes) |
//! | `bvh.rs` | the BVH, its queries and `validate` |
//! | `shapes.rs` | procedural meshes for tests and benchmarks |

mod aabb;
mod build;
mod bvh;
mod cluster;
mod node;
mod ray;
pub mod shapes;

pub use aabb::Aabb;
pub(crate) use aabb::{in_strips, vertex_bounds};
pub use bvh::{Bvh, InvariantError, ShadowHint};
pub use cluster::{CLUSTER, CLUSTERED_FROM};
pub use node::WideNode;
pub use ray::{Hit, OFFSET_RELATIVE, Ray, offset_origin};

#[cfg(test)]
mod tests;
