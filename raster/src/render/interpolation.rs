//! Exitance interpolated between pixels: the cache is queried at every `step`-th pixel in x and
//! y (the grid), and a pixel between four grid pixels takes the bilinear blend of their
//! exitance where the four are alike; elsewhere it is queried as usual.
//!
//! ```text
//!  x = 0    s       2s        grid columns i·s, the last one clamped to width − 1
//!      ●───────●───────●      ● grid pixel: shaded as usual, its point kept for reuse
//!      │ · · · │ · · · │      · in the block of the four ● around it: blended from them
//!      │ · · · │ · · · │        if they are alike and it lies on their surface, queried
//!      │ · · · │ · · · │        otherwise
//!      ●───────●───────●
//! ```
//!
//! A point of object O is blended from its block's corners when
//!
//! 1. every corner pixel holds one fragment, of O, covering it fully (no silhouette, no other
//!    object), and so does the point's own pixel; O's material does not vary over its surface
//!    (with a texture-mapped K_d or mean free path, the exitance follows the texture's detail,
//!    which the corners do not see, so such objects are queried at every pixel);
//! 2. the corners are alike: per channel, the largest exitance M_o is at most
//!    `1 + tolerance` times the smallest (a shadow edge, a lit rim, a texture edge between
//!    them make them unlike);
//! 3. the point lies on the corners' surface: each corner's shading normal within about 25°
//!    of the point's ([`NORMAL_COS`]), and the point at most [`PLANE_SLOPE`] off each corner's
//!    tangent plane (a fold of the same mesh in front of another part of it fails this).
//!
//! Blended are M_o and its two parts, local and global; everything else is the point's own:
//! its position, normal and material, the Fresnel transmittance F_t(cos θ_o) that turns M_o
//! into radiance, the highlight, and E(x) where the irradiance layer asks for it. So on a
//! curved surface the interpolation error is that of M_o alone, which varies on the scale of
//! the diffusion length rather than of the pixel.
//!
//! Every value depends only on the pixel: a grid pixel's point is the one the usual shading
//! computes (same fragment, same seed), a blended point only on its block's corners. So the
//! image does not depend on the thread count, and a tile (`--crop`) is bit for bit the same
//! part of the whole image: the grid is anchored at pixel (0, 0), and a tile computes the grid
//! pixels around it even where they lie outside it. The grid is built in bands of
//! [`BAND_GRID_ROWS`] grid rows, so that its memory does not grow with the image's height; a
//! grid row between two bands is queried twice.
//!
//! What it misses: a feature narrower than a block that no corner sees (a shadow thinner than
//! `step` pixels), and an exitance ramp whose corners stay within the tolerance but bends
//! between them. The antialiasing pass (`aa > 1`) shades the pixels it splits with queries.

use glam::Vec3;
use lucent_core::Exitance;
use lucent_core::stats::NoStats;
use rayon::prelude::*;

use super::RenderError;
use super::shading::{PixelScratch, Shading, ShadingCounters, ShadingStats, Surface};
use crate::material::Shader;
use crate::output::Region;
use crate::raster::Fragment;

/// A corner's shading normal must be within about 25° of the point's.
const NORMAL_COS: f32 = 0.9;
/// The point may lie at most this far off a corner's tangent plane, per unit of distance from
/// it (about 14°): a smooth surface curves away quadratically, a fold steps away linearly.
const PLANE_SLOPE: f32 = 0.25;
/// Grid rows built at once: the grid's memory is about `(width / step) × BAND_GRID_ROWS`
/// points of a hundred bytes, and one grid row in this many is queried twice.
pub(super) const BAND_GRID_ROWS: u32 = 32;

/// The interpolation settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Interpolation {
    /// Grid spacing in pixels (≥ 2).
    pub step: u32,
    /// Per channel, the corners' largest M_o may be `1 + tolerance` times their smallest.
    pub tolerance: f32,
}

/// A grid pixel's shading point, kept where it can anchor a blend (one fragment covering the
/// pixel, of a translucent object whose material does not vary).
#[derive(Clone, Copy, Debug)]
pub(super) struct Node {
    /// The pixel's one fragment.
    pub fragment: Fragment,
    /// What the usual shading computes for it.
    pub surface: Surface,
}

/// The grid's points over a band of the image.
#[derive(Debug)]
pub(super) struct ExitanceGrid {
    settings: Interpolation,
    /// The image's last column and row.
    last: (u32, u32),
    /// The grid's last column and row (the ones clamped to `last`).
    last_index: (u32, u32),
    /// The first grid column and row held, and how many.
    origin: (u32, u32),
    cols: u32,
    rows: u32,
    /// Row-major, `cols × rows`.
    nodes: Vec<Option<Node>>,
    /// Per block, by its first corner (same layout): the object of its four corners if they
    /// may be blended from.
    blocks: Vec<Option<u32>>,
}

/// The four corners of a point's block, alike, with the point's bilinear weights.
#[derive(Clone, Copy, Debug)]
pub(super) struct Block<'g> {
    corners: [&'g Node; 4],
    weights: [f32; 4],
}

/// One grid row's points and what they cost.
type GridRow = (Vec<Option<Node>>, GridCost);

/// What building a band of the grid cost.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct GridCost {
    /// Traversal counters and translucent time of the grid points.
    pub stats: ShadingCounters,
    /// Grid points queried.
    pub queries: u64,
}

impl ExitanceGrid {
    /// Grid index of the column (or row) holding pixel coordinate `x`, at or before it.
    fn index(step: u32, x: u32) -> u32 {
        x / step
    }

    /// Pixel coordinate of grid column (or row) `i`, the last one clamped to `last`.
    fn coordinate(step: u32, i: u32, last: u32) -> u32 {
        i.saturating_mul(step).min(last)
    }

    /// The grid points needed to shade `region` (the corners of every block it touches),
    /// queried in parallel.
    pub fn build(
        shading: &Shading,
        settings: Interpolation,
        region: Region,
        collect_stats: bool,
    ) -> Result<(ExitanceGrid, GridCost), RenderError> {
        let step = settings.step.max(1);
        let last = (
            shading.camera.width.saturating_sub(1),
            shading.camera.height.saturating_sub(1),
        );
        let last_index = (last.0.div_ceil(step), last.1.div_ceil(step));
        let span = |lo: u32, hi: u32, last_index: u32| {
            let first = Self::index(step, lo);
            let end = (Self::index(step, hi.saturating_sub(1)) + 1).min(last_index);
            (first, end.saturating_sub(first) + 1)
        };
        let (i0, cols) = span(region.x0, region.x1, last_index.0);
        let (j0, rows) = span(region.y0, region.y1, last_index.1);
        let rows_out: Vec<Result<GridRow, RenderError>> = (j0..j0 + rows)
            .into_par_iter()
            .map_init(PixelScratch::default, |scratch, j| {
                let y = Self::coordinate(step, j, last.1);
                let mut cost = GridCost::default();
                let mut row = Vec::with_capacity(cols as usize);
                for i in i0..i0 + cols {
                    let x = Self::coordinate(step, i, last.0);
                    let node = if collect_stats {
                        Self::node(shading, x, y, scratch, &mut cost.stats)?
                    } else {
                        Self::node(shading, x, y, scratch, &mut NoStats)?
                    };
                    cost.queries += u64::from(node.is_some());
                    row.push(node);
                }
                Ok((row, cost))
            })
            .collect();
        let mut nodes = Vec::with_capacity(cols as usize * rows as usize);
        let mut cost = GridCost::default();
        for row in rows_out {
            let (row, c) = row?;
            nodes.extend(row);
            cost.stats.add(&c.stats);
            cost.queries += c.queries;
        }
        let mut grid = ExitanceGrid {
            settings: Interpolation { step, ..settings },
            last,
            last_index,
            origin: (i0, j0),
            cols,
            rows,
            nodes,
            blocks: Vec::new(),
        };
        grid.decide_blocks();
        Ok((grid, cost))
    }

    /// The point of grid pixel (x, y) if it can anchor a blend: shaded as
    /// [`Shading::pixel`] shades it.
    fn node<S: ShadingStats>(
        shading: &Shading,
        x: u32,
        y: u32,
        scratch: &mut PixelScratch,
        stats: &mut S,
    ) -> Result<Option<Node>, RenderError> {
        shading.resolve(x, y, &mut scratch.fragments);
        let [fragment] = scratch.fragments[..] else {
            return Ok(None);
        };
        let object = fragment.key as usize;
        let uniform = match shading.prep.shader_of(object) {
            Shader::Translucent(shader) => !shader.is_textured(),
            Shader::Lambert { .. } => false,
        };
        if !uniform || !shading.is_full(&fragment) || shading.caches[object].is_none() {
            return Ok(None);
        }
        let seed = shading.point_seed(x, y, 0);
        let surface = shading.timed_surface(&fragment, seed, scratch, None, stats)?;
        Ok(Some(Node { fragment, surface }))
    }

    /// The kept point of (x, y), if it is a grid pixel with one.
    fn node_at(&self, i: u32, j: u32) -> Option<&Node> {
        let (i, j) = (i.checked_sub(self.origin.0)?, j.checked_sub(self.origin.1)?);
        if i >= self.cols || j >= self.rows {
            return None;
        }
        self.nodes[(j * self.cols + i) as usize].as_ref()
    }

    /// The kept point of pixel (x, y) if it is a grid pixel and `fragment` is its fragment:
    /// the usual shading's result, reused.
    pub fn kept(&self, x: u32, y: u32, fragment: &Fragment) -> Option<&Node> {
        let step = self.settings.step;
        let on_grid = |x: u32, last: u32| x.is_multiple_of(step) || x == last;
        if !on_grid(x, self.last.0) || !on_grid(y, self.last.1) {
            return None;
        }
        let i = Self::index(step, x) + u32::from(!x.is_multiple_of(step));
        let j = Self::index(step, y) + u32::from(!y.is_multiple_of(step));
        self.node_at(i, j).filter(|n| n.fragment == *fragment)
    }

    /// The corners of the block whose first corner is grid point (i, j): the next column
    /// and row, or the same ones at the grid's last.
    fn corner_indices(&self, i: u32, j: u32) -> [(u32, u32); 4] {
        let (i1, j1) = (
            (i + 1).min(self.last_index.0),
            (j + 1).min(self.last_index.1),
        );
        [(i, j), (i1, j), (i, j1), (i1, j1)]
    }

    /// Decides every block held ([`ExitanceGrid::alike`]).
    fn decide_blocks(&mut self) {
        let (i0, j0) = self.origin;
        self.blocks = (j0..j0 + self.rows)
            .flat_map(|j| (i0..i0 + self.cols).map(move |i| (i, j)))
            .map(|(i, j)| self.alike(i, j))
            .collect();
    }

    /// The object whose points are the four corners of block (i, j), if they are alike within
    /// the tolerance (rules 1 and 2 of the module docs); decided once per block when the
    /// grid is built.
    fn alike(&self, i: u32, j: u32) -> Option<u32> {
        let corners = self.corner_indices(i, j).map(|(i, j)| self.node_at(i, j));
        let key = corners[0]?.fragment.key;
        let limit = 1.0 + self.settings.tolerance;
        let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::ZERO);
        for n in corners {
            let n = n.filter(|n| n.fragment.key == key)?;
            lo = lo.min(n.surface.exitance);
            hi = hi.max(n.surface.exitance);
        }
        // Written so that a NaN fails.
        (hi.cmple(lo * limit).all()).then_some(key)
    }

    /// The block of pixel (x, y) for `fragment` if its four corners are alike points of the
    /// fragment's object, with the pixel's bilinear weights.
    pub fn block(&self, x: u32, y: u32, fragment: &Fragment) -> Option<Block<'_>> {
        let step = self.settings.step;
        let (i, j) = (Self::index(step, x), Self::index(step, y));
        let (bi, bj) = (i.wrapping_sub(self.origin.0), j.wrapping_sub(self.origin.1));
        if bi >= self.cols || bj >= self.rows {
            return None;
        }
        let at = (bj * self.cols + bi) as usize;
        if self.blocks[at] != Some(fragment.key) {
            return None;
        }
        // The next column and row, or the same ones at the grid's last; held, since the block
        // was decided alike.
        let right = i < self.last_index.0;
        let down = j < self.last_index.1;
        let di = usize::from(right);
        let dj = if down { self.cols as usize } else { 0 };
        let node = |k: usize| self.nodes.get(k)?.as_ref();
        let corners = [
            node(at)?,
            node(at + di)?,
            node(at + dj)?,
            node(at + di + dj)?,
        ];
        // Where the pixel lies between the corners' columns (or rows): i·step and the next,
        // clamped to the image's last; 0 on the grid's last.
        let fraction = |p: u32, i: u32, next: bool, last: u32| {
            if !next {
                return 0.0;
            }
            let a = i * step;
            let b = (a + step).min(last);
            (p - a) as f32 / (b - a) as f32
        };
        let u = fraction(x, i, right, self.last.0);
        let v = fraction(y, j, down, self.last.1);
        Some(Block {
            corners,
            weights: [(1.0 - u) * (1.0 - v), u * (1.0 - v), (1.0 - u) * v, u * v],
        })
    }
}

impl Block<'_> {
    /// The blended exitance at a point of the block, if it lies on the corners' surface (rule
    /// 3 of the module docs).
    pub fn blend(&self, position: Vec3, normal: Vec3) -> Option<Exitance> {
        for n in &self.corners {
            let s = &n.surface;
            let d = position - s.position;
            let off_plane = s.normal.dot(d);
            if s.normal.dot(normal) < NORMAL_COS
                || off_plane * off_plane > PLANE_SLOPE * PLANE_SLOPE * d.length_squared()
            {
                return None;
            }
        }
        let mut m = Exitance::default();
        for (n, &w) in self.corners.iter().zip(&self.weights) {
            m.total += n.surface.exitance * w;
            m.local += n.surface.local * w;
            m.global += n.surface.global * w;
        }
        Some(m)
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec2;

    use super::*;

    const KEY: u32 = 3;

    fn fragment(key: u32) -> Fragment {
        Fragment {
            key,
            triangle: 0,
            coverage: 1,
            sample: Vec2::ZERO,
            depth: 0.5,
        }
    }

    /// A point of the plane z = 0 at pixel (x, y), one unit per pixel.
    fn on_plane(x: u32, y: u32, exitance: Vec3) -> Node {
        Node {
            fragment: fragment(KEY),
            surface: Surface {
                position: Vec3::new(x as f32, y as f32, 0.0),
                normal: Vec3::Z,
                exitance,
                local: exitance * 0.25,
                global: exitance * 0.75,
                ..Surface::default()
            },
        }
    }

    /// The whole grid of a `width × height` image, each grid pixel's point from `node`.
    fn grid(
        step: u32,
        (width, height): (u32, u32),
        tolerance: f32,
        node: impl Fn(u32, u32) -> Option<Node>,
    ) -> ExitanceGrid {
        let last = (width - 1, height - 1);
        let last_index = (last.0.div_ceil(step), last.1.div_ceil(step));
        let mut nodes = Vec::new();
        for j in 0..=last_index.1 {
            for i in 0..=last_index.0 {
                let x = ExitanceGrid::coordinate(step, i, last.0);
                let y = ExitanceGrid::coordinate(step, j, last.1);
                nodes.push(node(x, y));
            }
        }
        let mut g = ExitanceGrid {
            settings: Interpolation { step, tolerance },
            last,
            last_index,
            origin: (0, 0),
            cols: last_index.0 + 1,
            rows: last_index.1 + 1,
            nodes,
            blocks: Vec::new(),
        };
        g.decide_blocks();
        g
    }

    fn linear(x: u32, y: u32) -> Vec3 {
        Vec3::new(1.0, 2.0, 3.0) + Vec3::new(0.01, 0.002, 0.0) * x as f32
            - Vec3::new(0.0, 0.003, 0.005) * y as f32
    }

    #[test]
    fn grid_coordinates_clamp_the_last_column_to_the_image() {
        assert_eq!(ExitanceGrid::coordinate(4, 0, 9), 0);
        assert_eq!(ExitanceGrid::coordinate(4, 2, 9), 8);
        assert_eq!(ExitanceGrid::coordinate(4, 3, 9), 9);
        assert_eq!(ExitanceGrid::coordinate(4, u32::MAX, 9), 9);
        assert_eq!(ExitanceGrid::index(4, 7), 1);
    }

    /// Bilinear blending reproduces an exitance linear in the pixel coordinates at every
    /// pixel, the clamped last column and row (9 and 6 with step 4) included.
    #[test]
    fn a_linear_exitance_is_blended_exactly() {
        let (w, h) = (10, 7);
        let g = grid(4, (w, h), 0.25, |x, y| Some(on_plane(x, y, linear(x, y))));
        for y in 0..h {
            for x in 0..w {
                let block = g.block(x, y, &fragment(KEY)).expect("alike corners");
                let m = block
                    .blend(Vec3::new(x as f32, y as f32, 0.0), Vec3::Z)
                    .expect("on the corners' plane");
                let want = linear(x, y);
                for (got, want) in [
                    (m.total, want),
                    (m.local, want * 0.25),
                    (m.global, want * 0.75),
                ] {
                    assert!(
                        (got - want).abs().max_element() < 1e-5,
                        "({x}, {y}): {got} vs {want}"
                    );
                }
            }
        }
    }

    #[test]
    fn corners_of_another_object_or_unlike_corners_are_not_blended() {
        let other = grid(4, (9, 9), 0.25, |x, y| {
            let mut n = on_plane(x, y, Vec3::ONE);
            if (x, y) == (4, 4) {
                n.fragment.key = KEY + 1;
            }
            Some(n)
        });
        assert!(other.block(2, 2, &fragment(KEY)).is_none());
        assert!(other.block(6, 2, &fragment(KEY)).is_none());
        assert!(other.block(2, 6, &fragment(KEY + 1)).is_none());
        let missing = grid(4, (9, 9), 0.25, |x, y| {
            ((x, y) != (8, 8)).then(|| on_plane(x, y, Vec3::ONE))
        });
        assert!(missing.block(6, 6, &fragment(KEY)).is_none());
        assert!(missing.block(2, 2, &fragment(KEY)).is_some());
        // One channel of one corner 1.3× the others' against a tolerance of 0.25: unlike;
        // 1.2×: alike.
        for (factor, alike) in [(1.3, false), (1.2, true)] {
            let g = grid(4, (9, 9), 0.25, |x, y| {
                let m = if (x, y) == (4, 0) {
                    Vec3::new(1.0, factor, 1.0)
                } else {
                    Vec3::ONE
                };
                Some(on_plane(x, y, m))
            });
            assert_eq!(g.block(1, 1, &fragment(KEY)).is_some(), alike, "{factor}");
            assert!(g.block(1, 5, &fragment(KEY)).is_some());
        }
        // All dark: alike (zero within any factor of zero).
        let dark = grid(4, (9, 9), 0.25, |x, y| Some(on_plane(x, y, Vec3::ZERO)));
        assert!(dark.block(3, 3, &fragment(KEY)).is_some());
    }

    #[test]
    fn points_off_the_corners_surface_are_not_blended() {
        let g = grid(4, (9, 9), 0.25, |x, y| Some(on_plane(x, y, Vec3::ONE)));
        let block = g.block(2, 2, &fragment(KEY)).unwrap();
        let at = Vec3::new(2.0, 2.0, 0.0);
        assert!(block.blend(at, Vec3::Z).is_some());
        // Curving away a little (a sphere of radius 40 pixels): blended.
        assert!(block.blend(at + Vec3::Z * 0.1, Vec3::Z).is_some());
        // A fold: the point two pixels in front of the corners' plane.
        assert!(block.blend(at + Vec3::Z * 2.0, Vec3::Z).is_none());
        // A normal 30° away from the corners'.
        let tilted = Vec3::new(0.5, 0.0, 0.75_f32.sqrt());
        assert!(block.blend(at, tilted).is_none());
        let slightly = Vec3::new(0.2, 0.0, 0.96_f32.sqrt());
        assert!(block.blend(at, slightly).is_some());
    }

    #[test]
    fn kept_points_are_the_grid_pixels_own() {
        let g = grid(4, (10, 7), 0.25, |x, y| Some(on_plane(x, y, linear(x, y))));
        let f = fragment(KEY);
        for (x, y) in [(0, 0), (4, 0), (8, 4), (9, 4), (9, 6), (4, 6)] {
            let n = g.kept(x, y, &f).expect("a grid pixel");
            assert_eq!(n.surface.position, Vec3::new(x as f32, y as f32, 0.0));
        }
        for (x, y) in [(1, 0), (5, 4), (8, 5), (7, 6)] {
            assert!(g.kept(x, y, &f).is_none(), "({x}, {y})");
        }
        let other = Fragment { triangle: 1, ..f };
        assert!(g.kept(4, 4, &other).is_none());
    }
}
