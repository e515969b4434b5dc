//! The BVH node: 32 bytes, plain old data.

use glam::Vec3;

use super::aabb::Aabb;

/// One node of the flat BVH node array.
///
/// ```text
///  byte 0        4        8        12       16       20       24       28       32
///       +--------+--------+--------+--------+--------+--------+--------+--------+
///       | min.x  | min.y  | min.z  | first  | max.x  | max.y  | max.z  | count  |
///       +--------+--------+--------+--------+--------+--------+--------+--------+
///        f32      f32      f32      u32      f32      f32      f32      u32
/// ```
///
/// - `count == 0`: an interior node. Its two children are adjacent in the node array:
///   the left child at `first`, the right child at `first + 1`. (Example: the root, node 0,
///   has `first = 1`; its children are nodes 1 and 2.)
/// - `count > 0`: a leaf holding the `count` triangles at slots `first .. first + count` of
///   the BVH's leaf-ordered triangle array. (Example: `first = 40, count = 3` is slots 40, 41,
///   42.)
///
/// Children adjacent in memory means one cache line (64 bytes) holds both boxes a traversal
/// step tests. `min` and `max` bound everything below the node.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BvhNode {
    /// Smallest corner of the bounds.
    pub min: [f32; 3],
    /// Interior: index of the left child (the right one follows it). Leaf: first triangle slot.
    pub first: u32,
    /// Largest corner of the bounds.
    pub max: [f32; 3],
    /// Number of triangles in a leaf; 0 marks an interior node.
    pub count: u32,
}

const _: () = assert!(core::mem::size_of::<BvhNode>() == 32);
const _: () = assert!(core::mem::align_of::<BvhNode>() == 4);

impl BvhNode {
    /// A node with the given bounds and encoded `first`/`count`.
    pub(crate) fn new(bounds: &Aabb, first: u32, count: u32) -> BvhNode {
        BvhNode {
            min: bounds.min.to_array(),
            first,
            max: bounds.max.to_array(),
            count,
        }
    }

    /// True for a leaf.
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }

    /// The node's bounds.
    pub fn bounds(&self) -> Aabb {
        Aabb {
            min: Vec3::from_array(self.min),
            max: Vec3::from_array(self.max),
        }
    }
}
