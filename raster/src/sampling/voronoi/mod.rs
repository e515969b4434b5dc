//! Per-sample quadrature weights: each sample's share of the surface is its cell of the
//! restricted Voronoi diagram (RVD) — the points of the mesh closer to it, in 3-D Euclidean
//! distance, than to any other sample of the same object (Edelsbrunner & Shah 1997; computed
//! as in Lévy & Liu, "Lp Centroidal Voronoi Tessellation", SIGGRAPH 2010, by clipping).
//!
//! Equal areas (`total / N`) are unbiased on average, but blue noise still has local density
//! fluctuations, and a finite surface gets more samples near its borders; with equal areas both
//! become error in the subsurface sum. With Voronoi areas a sample that stands closer to its
//! neighbours weighs less, so the sum is the integral of the nearest-sample interpolant of the
//! irradiance: for uniform irradiance it is exact whatever the arrangement.
//!
//! Each cell's **centroid** comes with its area ([`VoronoiAreas::centroids`]). A sample moved
//! there turns the sum Σ A_i·f(x_i) from a rule exact for integrands constant over each cell
//! into one exact for linear ones (the first moment of the cell about its centroid vanishes),
//! the midpoint rule of the partition. The partition stays the one of the placed samples: the
//! moved samples are not the sites of their cells, which the rule does not need. On a curved
//! mesh the centroid of a cell spanning several triangles lies slightly inside the surface; it
//! moves to the nearest point of the triangles near the site.
//!
//! # Method
//!
//! For every site `s` (in parallel over occupied grid cells) and every triangle `t` within
//! `REACH` spacings of it, `t` is clipped in its own plane by the bisectors of `s` and its
//! neighbours, nearest first (Sutherland–Hodgman, `clip.rs`), until the **security radius**
//! proves the cell: every unconsidered neighbour is at least twice as far from `s` as the
//! polygon's farthest vertex, so its bisector cannot cut. Neighbours come from the 3×3×3 cells
//! around the site's (cells of `CELL` spacings, `cells.rs`); a cell not proven by them is
//! clipped again with a wider block. A triangle whose three corners are all robustly nearest
//! to one site lies wholly in that site's cell (`owners.rs`): that site takes it unclipped and
//! the others skip it, with the bits clipping would give. The polygons' areas and first
//! moments are summed per site in triangle order, in `f64`: no reduction across threads, the
//! same bits for any thread count.
//!
//! **Completeness.** A triangle is fully shared out when every bisector edge of every polygon
//! on it leads to a site that also processed it (the region across that edge belongs to that
//! site's exact cell): then the polygons tile it. A triangle where some edge leads to a site
//! farther than `REACH`, or that no site reached, is redone with every site within 2, 4, 8, …
//! times the reach (until all of the object's sites), and the sites the first pass skipped add
//! their polygons in (site, triangle) order. So the areas always sum to the object's area, to
//! float rounding (about 1e-14 relative in `f64`, then each area rounds to `f32`).
//!
//! **Degenerate input.** Triangles without area own nothing and are skipped. Samples at
//! exactly the same position share their cell equally (each computes the same polygon and
//! divides it by the number of coincident samples). A sample placed by
//! [`poisson_samples`](super::poisson_samples) lies on a triangle with area, at least the
//! weight-limiting distance from the others, so its cell is never empty; if one still ends up
//! with no area (a site off every triangle), it gets the smallest positive `f32`, counted in
//! [`VoronoiStats::empty`]. Non-finite sites get area 0 and take part in nothing.
//!
//! **Thin geometry.** Cells are 3-D: where the surface comes back within about a sample
//! spacing of itself (a thin sheet, an ear), a cell takes area from the other side too, and a
//! sample there stands for both sides. The sum stays exact, and it is the partition that the
//! placement itself implies: sample elimination measures 3-D distances too, so both sides of a
//! sheet thinner than the spacing already share one Poisson set. The irradiance of the two sides
//! mixes at that scale, as it did with equal areas.
//!
//! # Cost
//!
//! About 1.7 µs of CPU per sample on the bunny at 1M samples (1.3 triangles clipped per
//! sample, each by the bisectors of the neighbours within twice the cell's radius, plus the
//! neighbour sort); at most 33 bytes per sample of transient memory (`cells.rs`: positions,
//! order and cells about 20, the areas 4, 4 per (cell, patch) pair; the grid's sort peaks at
//! 20), 4 bytes per triangle for the owners, and about 2 per triangle for the patches of a mesh
//! finer than the samples (28 per patch of up to 16 triangles). On such a mesh most triangles
//! have an owner: on a 2 M-triangle sphere with 23 000 samples the areas take a fifth less
//! time than clipping every pair. Measured with the `voronoi_cost` example;
//! figures in `BENCHMARKS.md`.
//!
//! # Accuracy
//!
//! Tested against a brute-force oracle (every triangle finely subdivided, each sub-point given
//! to its nearest sample): per sample within the oracle's discretisation error; on a regular
//! grid of samples on a plane the interior cells are exactly the grid cell; the areas sum to the
//! mesh area to 1e-6 relative in `f32` (`tests.rs`).

mod cells;
mod clip;
mod owners;
#[cfg(test)]
mod tests;

use std::sync::atomic::{AtomicU8, AtomicU64, Ordering};

use glam::{DVec3, Vec2, Vec3};
use rayon::prelude::*;

use super::surface::{SurfacePoint, hex_spacing, triangle_area};
use crate::parallel::ordered_sum;
use cells::Cells;
use clip::{
    Frame, Neighbour, Outcome, Polygon, box_distance2_below, box_distance2_below_all,
    distance2_to_triangle, nearest_on_triangle,
};
use owners::{SHARED, triangle_owners};

/// Grid cell edge, in hexagonal-packing spacings. A cell's 3×3×3 block guarantees every
/// neighbour within one cell edge of its sites, which proves cells whose farthest vertex is
/// within a spacing (a hexagonal cell's is 0.58); at 1.5 spacings 8% of the cells needed a
/// wider search, at 2 fewer than 0.1%, and the whole ran 15% faster.
const CELL: f64 = 2.0;
/// A site processes the triangles within this many spacings. The nearest sample of any surface
/// point is nearly always closer than this (0.58 for hexagonal packing); where it is not, the
/// triangle is redone with a wider reach.
const REACH: f64 = 1.0;
/// Neighbours closer than this many spacings are sorted; the rest are scanned in any order
/// only when a cell reaches beyond half of it (which is rare: a hexagonal cell's radius is
/// 0.58 spacings). Sorting all of a cell's block cost a third of the time.
const SORTED: f64 = 1.6;
/// Occupied cells per parallel task.
const CELLS_PER_TASK: usize = 64;
/// Triangle flags of the first pass.
const TOUCHED: u8 = 1;
const INCOMPLETE: u8 = 2;

/// Per-sample areas and what it took to compute them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct VoronoiAreas {
    /// The area of each site's restricted Voronoi cell (scene units²), in input order.
    pub areas: Vec<f32>,
    /// Each cell's centroid, on the surface: the nearest point to the centroid of the cell's
    /// polygons on the triangles near the site (`triangle` indexes the input slice). Where the
    /// cell lies in one plane that is the centroid itself. A site that takes part in nothing
    /// (not finite, or no triangle with area) keeps its position, with `triangle` `u32::MAX`.
    pub centroids: Vec<SurfacePoint>,
    /// Counters.
    pub stats: VoronoiStats,
}

/// Counters of a [`voronoi_areas`] run (for tests and benchmarks).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct VoronoiStats {
    /// (site, triangle) pairs clipped in the first pass.
    pub clipped: u64,
    /// Of those, pairs whose cell needed neighbours beyond the 3×3×3 block.
    pub widened: u64,
    /// (site, triangle) pairs of the first pass where the triangle lies wholly in the site's
    /// cell, taken without clipping.
    pub whole: u64,
    /// Triangles redone with a wider reach.
    pub redone: u64,
    /// Sites that share their position with another.
    pub shared: u64,
    /// Sites whose cell was empty (given the smallest positive area).
    pub empty: u64,
}

/// The area of each site's cell of the restricted Voronoi diagram of `sites` on `triangles`
/// (see the module documentation): the cells tile the triangles, so the areas sum to their
/// total area. The sites should lie on the triangles (those of one object); the result is a
/// pure function of the input.
pub fn voronoi_areas(triangles: &[[Vec3; 3]], sites: &[Vec3]) -> VoronoiAreas {
    areas_of_cells(triangles, sites, true, &|_| {})
}

/// [`voronoi_areas`], calling `progress` with the share of the work done, from 0 to 1, from
/// any of the threads (so not always in increasing order). The shares are those of the steps'
/// times on meshes of 2 M and 7.8 M triangles with 23 000 sites: registering the triangles
/// with the sites' grid 0.3, finding the triangles wholly in one cell 0.25, clipping the cells
/// 0.35 (in steps of one task), their centroids 0.1.
pub fn voronoi_areas_with_progress(
    triangles: &[[Vec3; 3]],
    sites: &[Vec3],
    progress: &(dyn Fn(f32) + Sync),
) -> VoronoiAreas {
    areas_of_cells(triangles, sites, true, progress)
}

/// [`voronoi_areas_with_progress`], taking the triangles that lie wholly in one cell without
/// clipping them when `whole_triangles` (the same bits either way).
fn areas_of_cells(
    triangles: &[[Vec3; 3]],
    sites: &[Vec3],
    whole_triangles: bool,
    progress: &(dyn Fn(f32) + Sync),
) -> VoronoiAreas {
    let mut out = VoronoiAreas {
        areas: vec![0.0; sites.len()],
        centroids: sites
            .iter()
            .map(|&position| SurfacePoint {
                position,
                triangle: u32::MAX,
                bary: Vec2::ZERO,
            })
            .collect(),
        stats: VoronoiStats::default(),
    };
    let live: Vec<bool> = triangles
        .par_iter()
        .map(|t| Frame::new(t).is_some())
        .collect();
    // A triangle without a frame has no area (or a non-finite one): it adds nothing.
    let total = ordered_sum(triangles.len(), |t| {
        if live[t] {
            triangle_area(&triangles[t])
        } else {
            0.0
        }
    });
    let (count, lo, hi) = sites.iter().filter(|p| p.is_finite()).fold(
        (0usize, Vec3::INFINITY, Vec3::NEG_INFINITY),
        |(n, l, h), &p| (n + 1, l.min(p), h.max(p)),
    );
    if count == 0 {
        progress(1.0);
        return out;
    }
    if total <= 0.0 {
        for (a, p) in out.areas.iter_mut().zip(sites) {
            if p.is_finite() {
                *a = f32::MIN_POSITIVE;
            }
        }
        out.stats.empty = count as u64;
        progress(1.0);
        return out;
    }
    let spacing = hex_spacing(total, count.min(u32::MAX as usize) as u32) as f64;
    // Cells no smaller than 1/2²⁰ of the extent, so that no site's coordinate is clamped.
    let extent = (hi - lo).max_element() as f64;
    let size = (CELL * spacing).max(extent / (1 << 20) as f64);
    let reach = REACH / CELL * size;
    let mut cells = Cells::new(sites, size);
    // Registration reaches a little further than the pass, so that float rounding in the
    // boxes cannot drop a triangle a site reaches.
    cells.register_triangles(triangles, &live, reach * 1.01);
    progress(0.3);
    let owners = if whole_triangles {
        triangle_owners(&cells, triangles, &live, reach)
    } else {
        vec![SHARED; triangles.len()]
    };
    progress(0.55);
    let pass = Pass {
        triangles,
        live: &live,
        owners: &owners,
        cells: &cells,
        reach2: reach * reach,
        sorted: SORTED / CELL * size,
    };
    let (cell_sums, stats) = pass.run(&|done| progress(0.55 + 0.35 * done));
    out.stats = stats;
    let centroids = pass.centroids_on_surface(&cell_sums);
    progress(1.0);
    for ((&i, &(a, _)), c) in cells.order.iter().zip(&cell_sums).zip(centroids) {
        out.stats.empty += (a <= 0.0) as u64;
        out.areas[i as usize] = a.max(f32::MIN_POSITIVE);
        out.centroids[i as usize] = c;
    }
    out
}

/// A sorted site's cell: its area and the centroid of its polygons (the site where the area
/// is 0).
type CellSum = (f32, Vec3);

/// The nearest point found so far: its squared distance, triangle, barycentrics and position.
type Best = (f64, u32, [f64; 3], DVec3);

/// A polygon the redo pass found for a site the first pass skipped.
struct Piece {
    site: u32,
    triangle: u32,
    area: f64,
    centroid: DVec3,
}

/// One run over an object's sites.
struct Pass<'a> {
    triangles: &'a [[Vec3; 3]],
    /// Whether each triangle has a frame (an area): the others are skipped.
    live: &'a [bool],
    /// The site holding each triangle wholly, or [`SHARED`] (`owners.rs`).
    owners: &'a [u32],
    cells: &'a Cells,
    /// Squared reach: a site processes the triangles at most this far away.
    reach2: f64,
    /// Neighbours closer than this are sorted.
    sorted: f64,
}

/// Per-thread buffers.
#[derive(Default)]
struct Scratch {
    block: Vec<u32>,
    neighbours: Vec<Neighbour>,
    wide: Vec<Neighbour>,
    far: Vec<Neighbour>,
    gathered: Vec<u32>,
    polygon: Polygon,
}

impl Pass<'_> {
    /// Area and centroid per sorted site, and the counters; `progress` gets the share of the
    /// tasks done after each.
    fn run(&self, progress: &(dyn Fn(f32) + Sync)) -> (Vec<CellSum>, VoronoiStats) {
        let cells = self.cells;
        let n = cells.sites.len();
        let flags: Vec<AtomicU8> = (0..self.triangles.len())
            .map(|_| AtomicU8::new(0))
            .collect();
        let [clipped, widened, shared, whole] = [(); 4].map(|_| AtomicU64::new(0));
        let mut areas: Vec<CellSum> = vec![(0.0, Vec3::ZERO); n];
        // Tasks of CELLS_PER_TASK cells, each with its slice of the output.
        let mut tasks = Vec::new();
        let mut rest = &mut areas[..];
        for first in (0..cells.len()).step_by(CELLS_PER_TASK) {
            let last = (first + CELLS_PER_TASK).min(cells.len());
            let len = cells.sites_of(last - 1).end - cells.sites_of(first).start;
            let (head, tail) = rest.split_at_mut(len);
            tasks.push((first..last, head));
            rest = tail;
        }
        let task_count = tasks.len().max(1) as f32;
        let tasks_done = AtomicU64::new(0);
        tasks
            .into_par_iter()
            .for_each_init(Scratch::default, |scratch, (range, out)| {
                let base = cells.sites_of(range.start).start;
                let mut counts = [0u64; 4];
                let mut cursors = [0usize; 9];
                for (k, c) in range.clone().enumerate() {
                    let home = cells.cell_coords(c);
                    scratch.block.clear();
                    for (col, cursor) in cursors.iter_mut().enumerate() {
                        let (dx, dy) = (col as i64 / 3 - 1, col as i64 % 3 - 1);
                        let (x, y) = (home[0] + dx, home[1] + dy);
                        if x < 0 || y < 0 {
                            continue;
                        }
                        let from = if k == 0 { 0 } else { *cursor };
                        *cursor = cells.seek([x, y, home[2] - 1], from);
                        let (a, b) = cells.column_sites(*cursor, [x, y, home[2] + 1]);
                        scratch.block.extend(a..b);
                    }
                    self.cell(c, home, &mut out[..], base, &flags, scratch, &mut counts);
                }
                clipped.fetch_add(counts[0], Ordering::Relaxed);
                widened.fetch_add(counts[1], Ordering::Relaxed);
                shared.fetch_add(counts[2], Ordering::Relaxed);
                whole.fetch_add(counts[3], Ordering::Relaxed);
                let done = tasks_done.fetch_add(1, Ordering::Relaxed) + 1;
                progress(done as f32 / task_count);
            });
        let mut stats = VoronoiStats {
            clipped: clipped.into_inner(),
            whole: whole.into_inner(),
            widened: widened.into_inner(),
            shared: shared.into_inner(),
            ..VoronoiStats::default()
        };

        // Triangles not proven complete, redone in index order; the extra polygons are added in
        // (site, triangle) order.
        let redo: Vec<u32> = (0..self.triangles.len() as u32)
            .filter(|&t| {
                let f = flags[t as usize].load(Ordering::Relaxed);
                self.live[t as usize] && (f & TOUCHED == 0 || f & INCOMPLETE != 0)
            })
            .collect();
        stats.redone = redo.len() as u64;
        let extra: Vec<Vec<Piece>> = redo
            .par_iter()
            .map_init(Scratch::default, |scratch, &t| self.redo(t, scratch))
            .collect();
        let mut extra: Vec<Piece> = extra.into_iter().flatten().collect();
        extra.sort_unstable_by_key(|p| (p.site, p.triangle));
        for p in extra {
            let (area, centroid) = &mut areas[p.site as usize];
            let before = *area as f64;
            let sum = before + p.area;
            if sum > 0.0 {
                *centroid = ((centroid.as_dvec3() * before + p.centroid * p.area) / sum).as_vec3();
            }
            *area += p.area as f32;
        }
        if stats.shared > 0 {
            self.share_coincident(&mut areas);
        }
        (areas, stats)
    }

    /// The first pass over the sites of occupied cell `c`; `out[k − base]` is sorted site k's
    /// area and centroid. `counts`: pairs clipped, widened, coincident sites, whole triangles.
    #[allow(clippy::too_many_arguments)]
    fn cell(
        &self,
        c: usize,
        home: [i64; 3],
        out: &mut [CellSum],
        base: usize,
        flags: &[AtomicU8],
        scratch: &mut Scratch,
        counts: &mut [u64; 4],
    ) {
        let cells = self.cells;
        for s in cells.sites_of(c) {
            let ps = cells.sites[s].as_dvec3();
            let guaranteed = cells.block_margin(ps, home, 1);
            let sorted = self.sorted.min(guaranteed);
            let mut neighbours = std::mem::take(&mut scratch.neighbours);
            self.sorted_neighbours(
                s,
                ps,
                &scratch.block,
                sorted,
                &mut neighbours,
                &mut scratch.far,
            );
            counts[2] += neighbours.iter().take_while(|n| n.0 == 0.0).count().min(1) as u64;
            // Σ a and Σ a·(c − site) over the polygons.
            let (mut area, mut first) = (0.0, DVec3::ZERO);
            // Most of a grid cell's triangles are beyond the reach of each of its sites: the
            // bounding boxes of runs of patches of them, then of each patch and each triangle,
            // say so for a fraction of the exact test's cost.
            for (run, [lo, hi]) in cells.patch_runs(c) {
                if box_distance2_below_all(ps, *lo, *hi) > self.reach2 {
                    continue;
                }
                for &p in run {
                    let (patch, [lo, hi]) = cells.patch(p as usize);
                    // A single triangle's box is tested below.
                    if patch.len() > 1 && box_distance2_below_all(ps, *lo, *hi) > self.reach2 {
                        continue;
                    }
                    for t in patch {
                        // A patch may hold triangles without area (they have no frame).
                        if !self.live[t as usize] {
                            continue;
                        }
                        // Wholly another site's: clipping would leave nothing.
                        let owner = self.owners[t as usize];
                        if owner != SHARED && owner as usize != s {
                            continue;
                        }
                        let tri = &self.triangles[t as usize];
                        if box_distance2_below(ps, tri) > self.reach2
                            || distance2_to_triangle(ps, tri) > self.reach2
                        {
                            continue;
                        }
                        let Some(frame) = Frame::new(tri) else {
                            continue;
                        };
                        let mut outcome = Outcome::Done;
                        if owner == SHARED {
                            counts[0] += 1;
                            outcome = scratch.polygon.clip_cell(
                                &frame,
                                ps,
                                &cells.sites,
                                &neighbours,
                                sorted,
                                guaranteed,
                            );
                        } else {
                            counts[3] += 1;
                            scratch.polygon.whole(&frame, ps);
                        }
                        if let Outcome::NeedMore(r2) = outcome {
                            counts[1] += 1;
                            outcome = self.clip_wide(s, ps, &frame, r2, scratch);
                        }
                        if outcome != Outcome::Done {
                            continue;
                        }
                        let (a, c) = scratch.polygon.moment();
                        area += a;
                        first += (frame.point(c.x, c.y) - ps) * a;
                        let mut flag = if a > 0.0 { TOUCHED } else { 0 };
                        if !self.leads_to_processing(&scratch.polygon, tri, self.reach2) {
                            flag |= INCOMPLETE;
                        }
                        if flag != 0 {
                            flags[t as usize].fetch_or(flag, Ordering::Relaxed);
                        }
                    }
                }
            }
            scratch.neighbours = neighbours;
            let centroid = if area > 0.0 { ps + first / area } else { ps };
            out[s - base] = (area as f32, centroid.as_vec3());
        }
    }

    /// The sites of `candidates` other than `s`: those closer than `sorted` first, nearest
    /// first (ties by index), then the others in candidate order (see
    /// [`Polygon::clip_cell`]).
    fn sorted_neighbours(
        &self,
        s: usize,
        ps: DVec3,
        candidates: &[u32],
        sorted: f64,
        out: &mut Vec<Neighbour>,
        far: &mut Vec<Neighbour>,
    ) {
        out.clear();
        far.clear();
        let s2 = sorted * sorted;
        for &j in candidates {
            if j as usize == s {
                continue;
            }
            let d2 = ps.distance_squared(self.cells.sites[j as usize].as_dvec3());
            if d2 <= s2 {
                out.push((d2, j));
            } else {
                far.push((d2, j));
            }
        }
        out.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        out.extend_from_slice(far);
    }

    /// Clips site `s`'s cell on `frame` with every neighbour out to twice the polygon radius
    /// (`r2` is its square), widening until proven; the polygon is left in the scratch.
    fn clip_wide(
        &self,
        s: usize,
        ps: DVec3,
        frame: &Frame,
        mut r2: f64,
        scratch: &mut Scratch,
    ) -> Outcome {
        let cells = self.cells;
        let home = cells.coords(ps);
        let mut k = 2i64;
        loop {
            let need = (2.0 * r2.sqrt() / cells.size).ceil();
            if need.is_finite() {
                k = k.max(need.min(1e9) as i64);
            }
            scratch.gathered.clear();
            cells.gather(home, k, &mut scratch.gathered);
            let everyone = scratch.gathered.len() == cells.sites.len();
            let guaranteed = if everyone {
                f64::INFINITY
            } else {
                cells.block_margin(ps, home, k)
            };
            let mut wide = std::mem::take(&mut scratch.wide);
            self.sorted_neighbours(
                s,
                ps,
                &scratch.gathered,
                guaranteed,
                &mut wide,
                &mut scratch.far,
            );
            let outcome =
                scratch
                    .polygon
                    .clip_cell(frame, ps, &cells.sites, &wide, guaranteed, guaranteed);
            scratch.wide = wide;
            match outcome {
                Outcome::NeedMore(r) if !everyone => {
                    r2 = r;
                    k *= 2;
                }
                Outcome::NeedMore(_) => return Outcome::Done,
                done => return done,
            }
        }
    }

    /// Whether every neighbour across a bisector edge of `polygon` (a cell on `tri`) is within
    /// `reach2` of the triangle, i.e. processes it too. Such a neighbour is within the polygon's
    /// radius of the triangle (a point on the shared edge is as far from both sites), so the
    /// exact distance is needed only for polygons nearly as large as the reach.
    fn leads_to_processing(&self, polygon: &Polygon, tri: &[Vec3; 3], reach2: f64) -> bool {
        if polygon.radius2() < reach2 * (1.0 - 1e-9) {
            return true;
        }
        polygon.bisector_labels().all(|j| {
            let pj = self.cells.sites[j as usize].as_dvec3();
            distance2_to_triangle(pj, tri) <= reach2
        })
    }

    /// Shares triangle `t` out among every site within 2, 4, 8, … times the reach until the
    /// polygons are proven to tile it; returns the polygons of the sites the first pass did not
    /// process.
    fn redo(&self, t: u32, scratch: &mut Scratch) -> Vec<Piece> {
        let cells = self.cells;
        let tri = &self.triangles[t as usize];
        let Some(frame) = Frame::new(tri) else {
            return Vec::new();
        };
        let lo = tri[0].min(tri[1]).min(tri[2]).as_dvec3();
        let hi = tri[0].max(tri[1]).max(tri[2]).as_dvec3();
        let mut reach2 = self.reach2;
        loop {
            reach2 *= 4.0;
            let reach = reach2.sqrt();
            let (a, b) = (cells.coords(lo - reach), cells.coords(hi + reach));
            let volume: f64 = (0..3).map(|k| (b[k] - a[k] + 1) as f64).product();
            let mut near: Vec<u32> = Vec::new();
            if volume >= cells.len() as f64 {
                near.extend(0..cells.sites.len() as u32);
            } else {
                for x in a[0]..=b[0] {
                    for y in a[1]..=b[1] {
                        for z in a[2]..=b[2] {
                            if let Some(c) = cells.find([x, y, z]) {
                                near.extend(cells.sites_of(c).map(|i| i as u32));
                            }
                        }
                    }
                }
            }
            let everyone_near = near.len() == cells.sites.len();
            near.retain(|&s| {
                distance2_to_triangle(cells.sites[s as usize].as_dvec3(), tri) <= reach2
            });
            let everyone = everyone_near && near.len() == cells.sites.len();
            let mut found = Vec::new();
            let (mut touched, mut complete) = (false, true);
            for &s in &near {
                let ps = cells.sites[s as usize].as_dvec3();
                if self.clip_wide(s as usize, ps, &frame, 0.0, scratch) != Outcome::Done {
                    continue;
                }
                let (area, c) = scratch.polygon.moment();
                touched |= area > 0.0;
                complete &= self.leads_to_processing(&scratch.polygon, tri, reach2);
                if distance2_to_triangle(ps, tri) > self.reach2 && area > 0.0 {
                    found.push(Piece {
                        site: s,
                        triangle: t,
                        area,
                        centroid: frame.point(c.x, c.y),
                    });
                }
            }
            if (touched && complete) || everyone || !reach2.is_finite() {
                return found;
            }
        }
    }

    /// Each sorted site's centroid moved to the nearest point of the triangles with area in
    /// the patches registered to its grid cell (which hold every triangle within the reach of
    /// its sites), ties to the lowest triangle index; in sorted order.
    fn centroids_on_surface(&self, sums: &[CellSum]) -> Vec<SurfacePoint> {
        let cells = self.cells;
        (0..cells.len())
            .into_par_iter()
            .flat_map_iter(|c| {
                cells.sites_of(c).map(move |s| {
                    let p = sums[s].1.as_dvec3();
                    let mut best = (f64::INFINITY, u32::MAX, [1.0, 0.0, 0.0], p);
                    // The nearest of a patch's triangles to `p`, if nearer than `best` or as
                    // near with a lower index; a box farther than `best` is skipped.
                    let visit = |patch: std::ops::Range<u32>, best: &mut Best| {
                        for t in patch {
                            if !self.live[t as usize] {
                                continue;
                            }
                            let tri = &self.triangles[t as usize];
                            if box_distance2_below(p, tri) > best.0 {
                                continue;
                            }
                            let w = nearest_on_triangle(p, tri);
                            let q = tri[0].as_dvec3() * w[0]
                                + tri[1].as_dvec3() * w[1]
                                + tri[2].as_dvec3() * w[2];
                            let d2 = p.distance_squared(q);
                            if d2 < best.0 || (d2 == best.0 && t < best.1) {
                                *best = (d2, t, w, q);
                            }
                        }
                    };
                    // First the patch whose box is nearest, in the run whose box is: its
                    // distance then skips nearly every other patch. Visiting it again could
                    // not change `best`, so it is not.
                    let box_to = |[lo, hi]: &[Vec3; 2]| box_distance2_below_all(p, *lo, *hi);
                    let nearest_run = cells
                        .patch_runs(c)
                        .min_by(|a, b| box_to(a.1).total_cmp(&box_to(b.1)));
                    let first = nearest_run.and_then(|(run, _)| {
                        let q = run.iter().min_by(|&&a, &&b| {
                            let [a, b] = [a, b].map(|q| box_to(cells.patch(q as usize).1));
                            a.total_cmp(&b)
                        })?;
                        visit(cells.patch(*q as usize).0, &mut best);
                        Some(*q)
                    });
                    for (run, bounds) in cells.patch_runs(c) {
                        if box_to(bounds) > best.0 {
                            continue;
                        }
                        for &q in run {
                            let (patch, bounds) = cells.patch(q as usize);
                            if Some(q) == first || patch.len() > 1 && box_to(bounds) > best.0 {
                                continue;
                            }
                            visit(patch, &mut best);
                        }
                    }
                    match best {
                        (_, u32::MAX, ..) => SurfacePoint {
                            position: cells.sites[s],
                            triangle: u32::MAX,
                            bary: Vec2::ZERO,
                        },
                        (_, triangle, w, q) => SurfacePoint {
                            position: q.as_vec3(),
                            triangle,
                            bary: Vec2::new(w[1] as f32, w[2] as f32),
                        },
                    }
                })
            })
            .collect()
    }

    /// Divides the area of sites at exactly the same position by their number (each computed
    /// the same whole cell). Coincident sites share a grid cell.
    fn share_coincident(&self, areas: &mut [CellSum]) {
        let cells = self.cells;
        for c in 0..cells.len() {
            let range = cells.sites_of(c);
            for s in range.clone() {
                let same = range
                    .clone()
                    .filter(|&j| cells.sites[j] == cells.sites[s])
                    .count();
                areas[s].0 /= same as f32;
            }
        }
    }
}
