//! The irradiance cache: a linear octree over irradiance samples in flat structure-of-arrays
//! (JB02 §3, with the layout choices of kiddo and obvhs; see the README's architecture notes).
//!
//! # Layout
//!
//! Samples are sorted in Morton order of their quantised positions ([`crate::morton`]), so each
//! leaf owns a contiguous run of them. Nodes are stored breadth-first, so each internal node's
//! children are contiguous too. Every column is padded with [`LANES`] trailing zeros, so that
//! an 8-wide load at any node's children or any leaf's samples stays in bounds; lanes past the
//! real count are masked.
//!
//! ```text
//! samples (Morton order)          s0   s1   s2   s3   s4   s5   s6 … sN-1 | 0 0 0 0 0 0 0 0
//!   pos_x pos_y pos_z area         ─── one f32 column each ───            | padding
//!   flux_r flux_g flux_b           flux = E·A (irradiance times area)
//!
//! nodes (breadth-first)           n0 | n1 n2 n3 n4 | n5 n6 … | … | 8 padding nodes
//!                                 └root┘└children of n0┘
//!   area                          Σ A_i
//!   flux_r flux_g flux_b          Σ E_i A_i            (so E_v = flux / area)
//!   centroid_x/_y/_z              P = Σ w_i p_i / Σ w_i,  w_i = flux_r + flux_g + flux_b
//!                                 (area-weighted where the node has no flux)
//!   radius                        max |p_i − P|: the node's bounding sphere about P
//!   cov_xx cov_yy cov_zz          C = Σ w_i (p_i − P)(p_i − P)ᵀ / Σ w_i, the same weights:
//!   cov_xy cov_xz cov_yz          for the fourth-order aggregate (see `traverse.rs`)
//!   first: u32                    first child (internal) or first sample (leaf)
//!   info:  u32                    bit 31 = leaf; bits 0..4 = count (1..=8)
//! ```
//!
//! Per sample 28 bytes; per node 64 bytes; with at most [`LEAF_CAPACITY`] samples per leaf
//! there are about 0.3–0.5 nodes per sample, so about 48–60 bytes per sample in all
//! ([`IrradianceCache::memory_bytes`] reports the exact figure, measured in the benches).
//!
//! Why a bounding sphere and not a box: the traversal already computes |x − P| for the
//! aggregate, so the sphere's distance costs one square root, and its one column leaves room
//! for the six covariance columns within the same 64 bytes per node as six box columns plus a
//! scalar spread (the first design; the full covariance cut the aggregation error 5–30× more).
//!
//! Why 8 samples per leaf: a leaf is then exactly one 8-lane batch, and so is the set of an
//! internal node's children.

mod construct;
pub(crate) mod exhaustive;
pub(crate) mod traverse;
mod validate;

use alloc::vec::Vec;

use glam::Vec3;

pub use exhaustive::{
    exhaustive_edge_aware, exhaustive_local_global, exhaustive_sum, exhaustive_sum_lanes,
};
pub(crate) use traverse::traverse;
pub use validate::ValidationError;

use crate::lanes::LANES;
use crate::morton::Grid;

/// Most samples a leaf holds (and most children an internal node has).
pub const LEAF_CAPACITY: u32 = 8;
/// Largest sample count a cache accepts (indices are 32-bit with room for flags).
pub const MAX_SAMPLES: usize = (1 << 31) - 64;
/// Deepest node the construction can create: 21 Morton levels plus the levels that split runs
/// of coincident positions by count (⌈log₈ 2³¹⌉ = 11).
pub const MAX_DEPTH: usize = 34;
/// Leaf flag in [`Nodes::info`].
pub(crate) const LEAF_BIT: u32 = 1 << 31;
/// Count bits in [`Nodes::info`].
pub(crate) const COUNT_MASK: u32 = 0xf;

/// One irradiance sample: a patch of surface with its area and the irradiance arriving there.
///
/// ```text
/// offset  0  position    Vec3 (x, y, z: f32)
/// offset 12  area        f32
/// offset 16  irradiance  Vec3
/// size   28
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct Sample {
    /// Position (scene units).
    pub position: Vec3,
    /// Surface area the sample stands for (scene units²), ≥ 0.
    pub area: f32,
    /// Irradiance E per RGB channel (≥ 0).
    pub irradiance: Vec3,
}

/// Sample columns in Morton order (see the module docs for the layout).
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct Samples {
    pub pos_x: Vec<f32>,
    pub pos_y: Vec<f32>,
    pub pos_z: Vec<f32>,
    pub area: Vec<f32>,
    pub flux_r: Vec<f32>,
    pub flux_g: Vec<f32>,
    pub flux_b: Vec<f32>,
}

/// Node columns in breadth-first order (see the module docs for the layout).
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct Nodes {
    pub area: Vec<f32>,
    pub flux_r: Vec<f32>,
    pub flux_g: Vec<f32>,
    pub flux_b: Vec<f32>,
    pub centroid_x: Vec<f32>,
    pub centroid_y: Vec<f32>,
    pub centroid_z: Vec<f32>,
    pub radius: Vec<f32>,
    pub cov_xx: Vec<f32>,
    pub cov_yy: Vec<f32>,
    pub cov_zz: Vec<f32>,
    pub cov_xy: Vec<f32>,
    pub cov_xz: Vec<f32>,
    pub cov_yz: Vec<f32>,
    pub first: Vec<u32>,
    pub info: Vec<u32>,
}

impl Nodes {
    /// Every f32 column with its name.
    pub(crate) fn float_columns(&self) -> [(&'static str, &Vec<f32>); NODE_FLOAT_COLUMNS] {
        [
            ("area", &self.area),
            ("flux_r", &self.flux_r),
            ("flux_g", &self.flux_g),
            ("flux_b", &self.flux_b),
            ("centroid_x", &self.centroid_x),
            ("centroid_y", &self.centroid_y),
            ("centroid_z", &self.centroid_z),
            ("radius", &self.radius),
            ("cov_xx", &self.cov_xx),
            ("cov_yy", &self.cov_yy),
            ("cov_zz", &self.cov_zz),
            ("cov_xy", &self.cov_xy),
            ("cov_xz", &self.cov_xz),
            ("cov_yz", &self.cov_yz),
        ]
    }
}

/// Bytes of one sample across all sample columns.
pub const SAMPLE_BYTES: usize = 7 * core::mem::size_of::<f32>();
/// Bytes of one node across all node columns.
pub const NODE_BYTES: usize = 14 * core::mem::size_of::<f32>() + 2 * core::mem::size_of::<u32>();
/// Every f32 node column, by name (for construction, validation and memory accounting).
pub(crate) const NODE_FLOAT_COLUMNS: usize = 14;
const _: () = assert!(SAMPLE_BYTES == 28 && NODE_BYTES == 64);
const _: () = {
    use core::mem::{offset_of, size_of};
    assert!(size_of::<Sample>() == 28);
    assert!(offset_of!(Sample, area) == 12 && offset_of!(Sample, irradiance) == 16);
};

/// A built irradiance cache: immutable, `Send + Sync`, queried from any number of threads.
#[derive(Clone, Debug, PartialEq)]
pub struct IrradianceCache {
    pub(crate) samples: Samples,
    pub(crate) nodes: Nodes,
    /// Real (unpadded) sample count.
    pub(crate) len: usize,
    /// Real (unpadded) node count.
    pub(crate) node_len: usize,
    pub(crate) grid: Grid,
    pub(crate) mean_area: f32,
    pub(crate) depth: usize,
    /// Axis-aligned bounds of all samples.
    pub(crate) bounds: Option<(Vec3, Vec3)>,
}

impl IrradianceCache {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.len
    }
    /// True if the cache holds no samples.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
    /// Number of octree nodes.
    pub fn node_count(&self) -> usize {
        self.node_len
    }
    /// Depth of the deepest node (the root has depth 0).
    pub fn depth(&self) -> usize {
        self.depth
    }
    /// Mean sample area Ā (scene units²): N10's weight for the inserted shading point, and the
    /// scale of the smoothing radius α = k √Ā.
    pub fn mean_area(&self) -> f32 {
        self.mean_area
    }
    /// The LM07 smoothing radius α = k · √Ā for a user factor k.
    pub fn smoothing_radius(&self, k: f32) -> f32 {
        k * crate::math::sqrt(self.mean_area)
    }
    /// Total area Σ A_i.
    pub fn total_area(&self) -> f32 {
        if self.node_len == 0 {
            0.0
        } else {
            self.nodes.area[0]
        }
    }
    /// Bounds of all samples (`None` when empty).
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        self.bounds
    }

    /// Heap and inline bytes held by the cache, everything included (column capacities and
    /// padding). Divide by [`IrradianceCache::len`] for bytes per sample.
    pub fn memory_bytes(&self) -> usize {
        let s = &self.samples;
        let n = &self.nodes;
        let f = core::mem::size_of::<f32>();
        let sample_cols = [
            &s.pos_x, &s.pos_y, &s.pos_z, &s.area, &s.flux_r, &s.flux_g, &s.flux_b,
        ];
        let floats: usize = sample_cols.iter().map(|c| c.capacity() * f).sum::<usize>()
            + n.float_columns()
                .iter()
                .map(|(_, c)| c.capacity() * f)
                .sum::<usize>();
        let ints = (n.first.capacity() + n.info.capacity()) * core::mem::size_of::<u32>();
        core::mem::size_of::<Self>() + floats + ints
    }

    /// The samples in cache (Morton) order, as they were given (irradiance = flux / area;
    /// samples with zero area come back with zero irradiance).
    pub fn samples(&self) -> impl ExactSizeIterator<Item = Sample> + '_ {
        let s = &self.samples;
        (0..self.len).map(move |i| {
            let area = s.area[i];
            let flux = Vec3::new(s.flux_r[i], s.flux_g[i], s.flux_b[i]);
            Sample {
                position: Vec3::new(s.pos_x[i], s.pos_y[i], s.pos_z[i]),
                area,
                irradiance: if area > 0.0 { flux / area } else { Vec3::ZERO },
            }
        })
    }
}

const _: () = {
    const fn assert_send_sync<T: Send + Sync>() {}
    assert_send_sync::<IrradianceCache>();
    assert!(LANES == LEAF_CAPACITY as usize);
};
