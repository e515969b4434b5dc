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

/// One node of the 4-wide BVH that queries traverse: the binary tree collapsed so that each
/// node holds up to four children's boxes, tested together with one 4-lane slab test
/// (Wald, Benthin & Boulos 2008, "Getting Rid of Packets"; Dammertz et al. 2008, "Shallow
/// Bounding Volume Hierarchies"). The tree is about half as deep as the binary one, so a ray
/// makes fewer, though wider, visits, each a few SIMD instructions on two cache lines.
///
/// ```text
///  byte 0          16          32          48          64
///       +-----------+-----------+-----------+-----------+
///       | min.x ×4  | min.y ×4  | min.z ×4  | max.x ×4  |   cache line 1
///       +-----------+-----------+-----------+-----------+
///       | max.y ×4  | max.z ×4  | child ×4  | count ×4, valid, padding |   cache line 2
///       +-----------+-----------+-----------+-----------+
///        f32 ×4 each; child u32 ×4; count u8 ×4; valid u8; 11 bytes of padding
/// ```
///
/// Lane `i` (bit `i` of `valid`) is a child when set; the used lanes come first (`valid` is
/// `0b1`, `0b11`, `0b111` or `0b1111`) and unused lanes hold zeros.
/// - `count[i] == 0`: an interior child, the wide node at index `child[i]` (always greater
///   than this node's index).
/// - `count[i] > 0`: a leaf of `count[i]` triangles at slots `child[i] .. child[i] + count[i]`.
///
/// The lane's box bounds everything below it; the root (node 0) has no box of its own.
/// Aligned to 64 bytes so that a node spans exactly two cache lines.
#[repr(C, align(64))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WideNode {
    /// Smallest corners: `min[axis][lane]`.
    pub min: [[f32; 4]; 3],
    /// Largest corners: `max[axis][lane]`.
    pub max: [[f32; 4]; 3],
    /// Per lane: wide node index (interior) or first triangle slot (leaf).
    pub child: [u32; 4],
    /// Per lane: number of triangles of a leaf; 0 for an interior child or an unused lane.
    pub count: [u8; 4],
    /// Bit `i` set: lane `i` is used.
    pub valid: u8,
}

const _: () = assert!(core::mem::size_of::<WideNode>() == 128);
const _: () = assert!(core::mem::align_of::<WideNode>() == 64);

impl WideNode {
    /// A node with no lane used.
    pub(crate) const EMPTY: WideNode = WideNode {
        min: [[0.0; 4]; 3],
        max: [[0.0; 4]; 3],
        child: [0; 4],
        count: [0; 4],
        valid: 0,
    };

    /// Number of used lanes.
    pub fn len(&self) -> usize {
        self.valid.count_ones() as usize
    }

    /// True if no lane is used (never the case in a built BVH).
    pub fn is_empty(&self) -> bool {
        self.valid == 0
    }

    /// The bounds of lane `lane`.
    pub fn lane_bounds(&self, lane: usize) -> Aabb {
        Aabb {
            min: Vec3::new(self.min[0][lane], self.min[1][lane], self.min[2][lane]),
            max: Vec3::new(self.max[0][lane], self.max[1][lane], self.max[2][lane]),
        }
    }

    /// Sets lane `lane` to the given bounds and encoded `child`/`count`.
    pub(crate) fn set_lane(&mut self, lane: usize, bounds: &Aabb, child: u32, count: u8) {
        for axis in 0..3 {
            self.min[axis][lane] = bounds.min[axis];
            self.max[axis][lane] = bounds.max[axis];
        }
        self.child[lane] = child;
        self.count[lane] = count;
        self.valid |= 1 << lane;
    }
}
