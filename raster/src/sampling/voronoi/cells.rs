//! The sites sorted into a sparse uniform grid, and for each occupied cell the triangles that
//! its sites may take area from.
//!
//! ```text
//! sites:       positions sorted by cell key (x-major), `order[k]` = input index of site k
//! cell_key:    [k0, k1, …]          occupied cells, ascending key
//! cell_start:  [0, 3, 7, …, N]      sites of cell c: cell_start[c] .. cell_start[c + 1]
//! slots:       open addressing, key → cell index (u32::MAX empty), 2× the cells
//! patch_start: [0, 16, 32, 33, …]   patch p: triangles patch_start[p] .. patch_start[p + 1]
//! patch_box:   [[lo, hi], …]        the box of each patch's triangles with area
//! list_start:  [0, 2, 5, …]         patches of cell c: patches[list_start[c] .. list_start[c + 1]],
//! patches:     [p, p, …]            ascending
//! run_start:   [0, 1, 3, …]         runs of cell c: run_boxes[run_start[c] .. run_start[c + 1]]
//! run_boxes:   [[lo, hi], …]        the box of each run of RUN entries of a cell's patches
//! ```
//!
//! A **patch** is a run of up to [`PATCH`] consecutive triangles whose box spans at most a
//! quarter of a cell, or a single larger triangle; the cells list patches rather than
//! triangles. A mesh's triangles that are close in index are mostly close in space, so on a
//! mesh much finer than the samples a patch holds nearly [`PATCH`] triangles, and the lists
//! are an order of magnitude shorter (3.3 M (cell, patch) pairs on a 7.8 M-triangle sphere
//! against 42.6 M (cell, triangle) pairs, whose registration took a third of the areas' time).
//! Where the triangles are as large as the sample spacing, patches are single triangles and
//! the lists are as before.
//!
//! About 23 bytes per site (12 position, 4 order, ~7 cells and slots), 28 per patch, 4 per
//! (cell, patch) pair and 24 per run of up to [`RUN`] pairs. While the pairs are sorted by cell
//! they are held twice.

use crate::parallel::sorted_by_key;
use glam::{DVec3, Vec3};
use rayon::prelude::*;

/// Bits per axis of a packed cell key. Coordinates are clamped to `0 .. 2²¹`; clamping is
/// monotone, so sites closer than a cell still fall in the same or adjacent cells.
const AXIS_BITS: u32 = 21;
const AXIS_MAX: i64 = (1 << AXIS_BITS) - 1;
const EMPTY: u32 = u32::MAX;
/// Triangles per parallel task when cutting them into patches. A multiple of [`PATCH`], and
/// fixed, so that the patches are the same for any thread count.
pub(super) const PATCH_CHUNK: usize = 4096;
/// Patches per parallel task when registering them with the cells.
const REGISTER_CHUNK: usize = 1024;
/// Most triangles in one patch: a site's or a centroid's search skips a patch whose box is
/// out of reach without looking at its triangles.
const PATCH: usize = 16;
/// Entries of a cell's patch list per bounding box: a search skips a run whose box is out of
/// reach without looking at its patches (where patches are single triangles, it would
/// otherwise test each triangle's box twice).
const RUN: usize = 16;
/// Largest extent of a patch of several triangles, in cells.
const PATCH_EXTENT: f64 = 0.25;

/// The grid (see the module documentation).
pub(super) struct Cells {
    origin: DVec3,
    /// Cell edge length.
    pub(super) size: f64,
    inv: f64,
    /// Site positions in cell order.
    pub(super) sites: Vec<Vec3>,
    /// Input index of each sorted site.
    pub(super) order: Vec<u32>,
    cell_key: Vec<u64>,
    cell_start: Vec<u32>,
    slots: Vec<u32>,
    shift: u32,
    /// Patch `p` is the triangles `patch_start[p]..patch_start[p + 1]`.
    patch_start: Vec<u32>,
    /// The bounding box (lower, upper corner) of each patch's triangles with area (empty if
    /// it has none).
    patch_box: Vec<[Vec3; 2]>,
    /// The patches of cell `c` are `patches[list_start[c]..list_start[c + 1]]`.
    list_start: Vec<u32>,
    patches: Vec<u32>,
    /// The bounding box of each run of [`RUN`] consecutive entries of a cell's patch list (a
    /// cell's last run may be shorter).
    run_boxes: Vec<[Vec3; 2]>,
    /// The runs of cell `c` are `run_boxes[run_start[c]..run_start[c + 1]]`.
    run_start: Vec<u32>,
}

fn pack(c: [i64; 3]) -> u64 {
    ((c[0] as u64) << (2 * AXIS_BITS)) | ((c[1] as u64) << AXIS_BITS) | c[2] as u64
}

fn unpack(k: u64) -> [i64; 3] {
    let m = AXIS_MAX as u64;
    [
        (k >> (2 * AXIS_BITS)) as i64,
        ((k >> AXIS_BITS) & m) as i64,
        (k & m) as i64,
    ]
}

impl Cells {
    /// Sorts the finite ones of `sites` into cells of edge `size` (`order` then maps sorted
    /// sites to input indices).
    pub(super) fn new(sites: &[Vec3], size: f64) -> Cells {
        let origin = sites
            .iter()
            .filter(|p| p.is_finite())
            .fold(Vec3::splat(f32::INFINITY), |m, &p| m.min(p))
            .as_dvec3();
        let mut cells = Cells {
            origin,
            size,
            inv: 1.0 / size.max(f64::MIN_POSITIVE),
            sites: Vec::new(),
            order: Vec::new(),
            cell_key: Vec::new(),
            cell_start: Vec::new(),
            slots: Vec::new(),
            shift: 0,
            patch_start: Vec::new(),
            patch_box: Vec::new(),
            list_start: Vec::new(),
            patches: Vec::new(),
            run_boxes: Vec::new(),
            run_start: Vec::new(),
        };
        // Non-finite sites get a key above every cell's and are cut off after the sort.
        let mut keyed = sorted_by_key(sites.len(), |i| {
            let p = sites[i];
            if p.is_finite() {
                pack(cells.coords(p.as_dvec3()))
            } else {
                u64::MAX
            }
        });
        keyed.truncate(keyed.partition_point(|&(k, _)| k != u64::MAX));
        for (k, &(key, _)) in keyed.iter().enumerate() {
            if cells.cell_key.last() != Some(&key) {
                cells.cell_key.push(key);
                cells.cell_start.push(k as u32);
            }
        }
        cells.cell_start.push(keyed.len() as u32);
        // The order first and the keys dropped before the positions are gathered: the peak is
        // 20 bytes per site, not 32.
        cells.order = keyed.iter().map(|&(_, i)| i).collect();
        drop(keyed);
        cells.sites = cells.order.iter().map(|&i| sites[i as usize]).collect();
        let bits = (cells.cell_key.len() * 2)
            .max(2)
            .next_power_of_two()
            .trailing_zeros();
        cells.slots = vec![EMPTY; 1 << bits];
        cells.shift = 64 - bits;
        let mask = cells.slots.len() - 1;
        for (c, &key) in cells.cell_key.iter().enumerate() {
            let mut s = cells.slot(key);
            while cells.slots[s] != EMPTY {
                s = (s + 1) & mask;
            }
            cells.slots[s] = c as u32;
        }
        cells
    }

    /// Number of occupied cells.
    pub(super) fn len(&self) -> usize {
        self.cell_key.len()
    }

    /// Clamped cell coordinates of a point.
    pub(super) fn coords(&self, p: DVec3) -> [i64; 3] {
        let c = |x: f64, o: f64| ((x - o) * self.inv).floor().clamp(0.0, AXIS_MAX as f64) as i64;
        [
            c(p.x, self.origin.x),
            c(p.y, self.origin.y),
            c(p.z, self.origin.z),
        ]
    }

    /// Coordinates of occupied cell `c`.
    pub(super) fn cell_coords(&self, c: usize) -> [i64; 3] {
        unpack(self.cell_key[c])
    }

    /// Distance from `p` (in the cell at coordinates `c`) to the boundary of the block of cells
    /// within `k` of `c`: every site closer than that to `p` is in [`Cells::gather`]'s block.
    pub(super) fn block_margin(&self, p: DVec3, c: [i64; 3], k: i64) -> f64 {
        // Never below the guaranteed k cells (rounding in the box).
        self.to_block_faces(p, c, k).max(k as f64 * self.size)
    }

    /// How far `p` lies inside the block of cells within `k` cells of `c` (per axis): every
    /// site outside the block is at least this far from `p`. Unlike [`Cells::block_margin`],
    /// `p` need not lie in cell `c`, and the distance is negative for a point outside the
    /// block. (No site's coordinate is clamped: the cells are at least 1/2²⁰ of the extent.)
    pub(super) fn inside_block(&self, p: DVec3, c: [i64; 3], k: i64) -> f64 {
        // Less the rounding of the block's faces.
        self.to_block_faces(p, c, k) - 1e-9 * self.size
    }

    /// The signed distance from `p` to the nearest face of the block of cells within `k` of
    /// `c`, as computed (positive inside).
    fn to_block_faces(&self, p: DVec3, c: [i64; 3], k: i64) -> f64 {
        (0..3).fold(f64::INFINITY, |m, a| {
            let lo = self.origin[a] + (c[a] - k) as f64 * self.size;
            let hi = self.origin[a] + (c[a] + k + 1) as f64 * self.size;
            m.min(p[a] - lo).min(hi - p[a])
        })
    }

    /// Sorted site range of occupied cell `c`.
    pub(super) fn sites_of(&self, c: usize) -> std::ops::Range<usize> {
        self.cell_start[c] as usize..self.cell_start[c + 1] as usize
    }

    /// Patch `p`: its range of triangles and the bounding box of those with area.
    pub(super) fn patch(&self, p: usize) -> (std::ops::Range<u32>, &[Vec3; 2]) {
        (
            self.patch_start[p]..self.patch_start[p + 1],
            &self.patch_box[p],
        )
    }

    /// The patches whose triangles lie in `triangles` (a range that starts and ends at patch
    /// boundaries, such as a multiple of [`PATCH_CHUNK`]).
    pub(super) fn patches_within(
        &self,
        triangles: std::ops::Range<usize>,
    ) -> std::ops::Range<usize> {
        let starts = &self.patch_start[..self.patch_start.len() - 1];
        let at = |t: usize| starts.partition_point(|&s| (s as usize) < t);
        at(triangles.start)..at(triangles.end)
    }

    /// The patches registered with occupied cell `c`, ascending, in runs of up to [`RUN`],
    /// each with the bounding box of its patches' boxes.
    pub(super) fn patch_runs(&self, c: usize) -> impl Iterator<Item = (&[u32], &[Vec3; 2])> {
        let list = &self.patches[self.list_start[c] as usize..self.list_start[c + 1] as usize];
        let boxes = &self.run_boxes[self.run_start[c] as usize..self.run_start[c + 1] as usize];
        list.chunks(RUN).zip(boxes)
    }

    fn slot(&self, key: u64) -> usize {
        (key.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> self.shift) as usize
    }

    /// The occupied cell at clamped coordinates `c`, if any.
    pub(super) fn find(&self, c: [i64; 3]) -> Option<usize> {
        if c.iter().any(|&x| !(0..=AXIS_MAX).contains(&x)) {
            return None;
        }
        let key = pack(c);
        let mask = self.slots.len() - 1;
        let mut s = self.slot(key);
        loop {
            let cell = self.slots[s];
            if cell == EMPTY {
                return None;
            }
            if self.cell_key[cell as usize] == key {
                return Some(cell as usize);
            }
            s = (s + 1) & mask;
        }
    }

    /// Appends the sorted indices of the sites in the cells within `k` cells of `c` (per axis),
    /// in key order; if that block would visit more cells than are occupied, every site. Every
    /// site closer than `k · size` to a point of cell `c` is included.
    pub(super) fn gather(&self, c: [i64; 3], k: i64, out: &mut Vec<u32>) {
        let side = (2 * k + 1) as f64;
        if side * side * side >= self.len() as f64 {
            out.extend(0..self.sites.len() as u32);
            return;
        }
        for x in c[0] - k..=c[0] + k {
            for y in c[1] - k..=c[1] + k {
                for z in c[2] - k..=c[2] + k {
                    if let Some(cell) = self.find([x, y, z]) {
                        out.extend(self.sites_of(cell).map(|i| i as u32));
                    }
                }
            }
        }
    }

    /// Registers with every occupied cell the triangles that come within `reach` (≤ the cell
    /// size) of a point of the cell, and perhaps a few more, by patches (see the module
    /// documentation). A patch of several triangles goes to the occupied cells its box, grown
    /// by `reach`, overlaps. A single triangle is cut into pieces no larger than a cell
    /// (recursive longest-edge bisection), and each piece goes to the occupied cells its box,
    /// grown by `reach`, overlaps near its plane. `live[t]` is false for triangles without
    /// area, which no cell gets for themselves (they may lie in a patch with others).
    pub(super) fn register_triangles(
        &mut self,
        triangles: &[[Vec3; 3]],
        live: &[bool],
        reach: f64,
    ) {
        self.register_in_chunks(triangles, live, reach, REGISTER_CHUNK);
    }

    /// [`Cells::register_triangles`], `chunk` patches per parallel task (the lists are the
    /// same for every `chunk`).
    fn register_in_chunks(
        &mut self,
        triangles: &[[Vec3; 3]],
        live: &[bool],
        reach: f64,
        chunk: usize,
    ) {
        let extent = (PATCH_EXTENT * self.size) as f32;
        let parts: Vec<(Vec<u32>, Vec<[Vec3; 2]>)> = triangles
            .par_chunks(PATCH_CHUNK)
            .enumerate()
            .map(|(k, part)| {
                let first = k * PATCH_CHUNK;
                cut_into_patches(part, &live[first..first + part.len()], first, extent)
            })
            .collect();
        let mut starts = Vec::with_capacity(triangles.len() / PATCH + parts.len() + 1);
        let mut boxes = Vec::with_capacity(starts.capacity());
        for (s, b) in parts {
            starts.extend(s);
            boxes.extend(b);
        }
        starts.push(triangles.len() as u32);
        // Per chunk of patches, their cells one after the other and how many each has: no
        // allocation per patch (a list each took a quarter of the pass on 2 M triangles).
        let chunks: Vec<(Vec<u32>, Vec<u32>)> = boxes
            .par_chunks(chunk.max(1))
            .enumerate()
            .map(|(k, part)| {
                let (mut cells, mut counts) = (Vec::new(), Vec::with_capacity(part.len()));
                let (mut own, mut stack) = (Vec::new(), Vec::new());
                for (i, &[lo, hi]) in part.iter().enumerate() {
                    let p = k * chunk.max(1) + i;
                    let range = starts[p] as usize..starts[p + 1] as usize;
                    own.clear();
                    match Occupancy::of(range, live) {
                        Occupancy::Empty => {}
                        Occupancy::Single(t) => {
                            self.cells_near(&triangles[t], reach, &mut own, &mut stack)
                        }
                        Occupancy::Several => self.cells_in_box(
                            lo.as_dvec3(),
                            hi.as_dvec3(),
                            reach,
                            |_| true,
                            &mut own,
                        ),
                    }
                    own.sort_unstable();
                    own.dedup();
                    cells.extend_from_slice(&own);
                    counts.push(own.len() as u32);
                }
                (cells, counts)
            })
            .collect();
        let lists = || {
            chunks.iter().flat_map(|(cells, counts)| {
                counts.iter().scan(0usize, move |at, &n| {
                    let list = &cells[*at..*at + n as usize];
                    *at += n as usize;
                    Some(list)
                })
            })
        };
        // Counting sort by cell; patches are visited in index order, so each cell's list
        // comes out ascending.
        let mut start = vec![0u32; self.len() + 1];
        for list in lists() {
            for &c in list {
                start[c as usize + 1] += 1;
            }
        }
        for c in 0..self.len() {
            start[c + 1] += start[c];
        }
        let mut patches = vec![0u32; start[self.len()] as usize];
        let mut next = start.clone();
        for (p, list) in lists().enumerate() {
            for &c in list {
                patches[next[c as usize] as usize] = p as u32;
                next[c as usize] += 1;
            }
        }
        let mut runs = Vec::new();
        let mut run_start = Vec::with_capacity(self.len() + 1);
        run_start.push(0);
        for c in 0..self.len() {
            let end = start[c + 1] as usize;
            runs.extend(
                (start[c] as usize..end)
                    .step_by(RUN)
                    .map(|a| a..end.min(a + RUN)),
            );
            run_start.push(runs.len() as u32);
        }
        self.run_boxes = runs
            .into_par_iter()
            .map(|run| {
                patches[run]
                    .iter()
                    .fold([Vec3::INFINITY, Vec3::NEG_INFINITY], |[lo, hi], &p| {
                        let [a, b] = boxes[p as usize];
                        [lo.min(a), hi.max(b)]
                    })
            })
            .collect();
        self.run_start = run_start;
        self.patch_start = starts;
        self.patch_box = boxes;
        self.patches = patches;
        self.list_start = start;
    }

    /// For a walk over the occupied cells in key order: the index of the first occupied cell
    /// with key ≥ that of coordinates `c` (clamped into the grid), from a cursor that only moves
    /// forward (`from`).
    pub(super) fn seek(&self, c: [i64; 3], from: usize) -> usize {
        let key = pack(c.map(|x| x.clamp(0, AXIS_MAX)));
        let mut k = from;
        // Short hops are the rule (the next column is close); far ones binary-search.
        let mut step = 1;
        while k + step < self.len() && self.cell_key[k + step] < key {
            k += step;
            step *= 2;
        }
        k + self.cell_key[k..self.len().min(k + step + 1)].partition_point(|&x| x < key)
    }

    /// The sorted site range of the occupied cells from index `first` on whose keys are at most
    /// that of coordinates `last` (the cells of one z column, from a [`Cells::seek`] cursor).
    pub(super) fn column_sites(&self, first: usize, last: [i64; 3]) -> (u32, u32) {
        let key = pack(last.map(|x| x.clamp(0, AXIS_MAX)));
        let mut end = first;
        while end < self.len() && self.cell_key[end] <= key {
            end += 1;
        }
        (self.cell_start[first], self.cell_start[end])
    }

    /// The occupied cells that the box `lo..hi`, grown by `reach`, overlaps and whose centre
    /// `keep` accepts.
    fn cells_in_box(
        &self,
        lo: DVec3,
        hi: DVec3,
        reach: f64,
        keep: impl Fn(DVec3) -> bool,
        out: &mut Vec<u32>,
    ) {
        let (a, b) = (self.coords(lo - reach), self.coords(hi + reach));
        for x in a[0]..=b[0] {
            for y in a[1]..=b[1] {
                for z in a[2]..=b[2] {
                    let centre =
                        self.origin + (DVec3::new(x as f64, y as f64, z as f64) + 0.5) * self.size;
                    if !keep(centre) {
                        continue;
                    }
                    if let Some(c) = self.find([x, y, z]) {
                        out.push(c as u32);
                    }
                }
            }
        }
    }

    /// The occupied cells near a triangle (see [`Cells::register_triangles`]).
    /// `stack` is scratch space.
    fn cells_near(
        &self,
        tri: &[Vec3; 3],
        reach: f64,
        out: &mut Vec<u32>,
        stack: &mut Vec<([DVec3; 3], u32)>,
    ) {
        stack.clear();
        stack.push((tri.map(|v| v.as_dvec3()), 0u32));
        while let Some((p, depth)) = stack.pop() {
            let lo = p[0].min(p[1]).min(p[2]);
            let hi = p[0].max(p[1]).max(p[2]);
            if (hi - lo).max_element() > self.size && depth < 48 {
                // Halve the longest edge: a sliver becomes shorter slivers (not ever more of
                // them, as a four-way split would), so the pieces grow with length, not length².
                let l = [0, 1, 2].map(|k| p[k].distance_squared(p[(k + 1) % 3]));
                let k = (0..3).fold(0, |b, k| if l[k] > l[b] { k } else { b });
                let (a, b, c) = (p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
                let m = (a + b) * 0.5;
                stack.push(([a, m, c], depth + 1));
                stack.push(([m, b, c], depth + 1));
                continue;
            }
            // Only cells within `reach` of the piece's plane can hold a site within `reach`.
            let normal = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero();
            let half_diagonal = 0.5 * 3f64.sqrt() * self.size;
            let near_plane = |centre: DVec3| {
                normal == DVec3::ZERO || (centre - p[0]).dot(normal).abs() <= reach + half_diagonal
            };
            self.cells_in_box(lo, hi, reach, near_plane, out);
        }
    }
}

/// Which of a patch's triangles have area (`live`): none, one, or several. A patch of several
/// is handled by its box; a triangle alone by itself (registration and owners alike).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Occupancy {
    /// No triangle with area.
    Empty,
    /// Exactly one, this one.
    Single(usize),
    /// Two or more.
    Several,
}

impl Occupancy {
    /// The occupancy of the triangles `range`.
    pub(super) fn of(range: std::ops::Range<usize>, live: &[bool]) -> Occupancy {
        let mut alive = range.filter(|&t| live[t]);
        match (alive.next(), alive.next()) {
            (None, _) => Occupancy::Empty,
            (Some(t), None) => Occupancy::Single(t),
            (Some(_), Some(_)) => Occupancy::Several,
        }
    }
}

/// Cuts `part` (the triangles from index `first` on, `live` saying which have area) into
/// patches: runs of up to [`PATCH`] consecutive triangles whose box of the triangles with area
/// spans at most `extent`, a larger triangle alone. Returns each patch's first triangle and
/// box. Greedy from the first triangle, so the patches depend only on the triangles.
fn cut_into_patches(
    part: &[[Vec3; 3]],
    live: &[bool],
    first: usize,
    extent: f32,
) -> (Vec<u32>, Vec<[Vec3; 2]>) {
    let (mut starts, mut boxes) = (Vec::new(), Vec::new());
    let mut t = 0;
    while t < part.len() {
        let start = t;
        let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        let mut alive = 0;
        while t < part.len() && t - start < PATCH {
            if live[t] {
                let [a, b, c] = part[t];
                let (l, h) = (lo.min(a).min(b).min(c), hi.max(a).max(b).max(c));
                if alive > 0 && !((h - l).max_element() <= extent) {
                    break;
                }
                (lo, hi) = (l, h);
                alive += 1;
                if !((h - l).max_element() <= extent) {
                    // A large triangle stays alone.
                    t += 1;
                    break;
                }
            }
            t += 1;
        }
        starts.push((first + start) as u32);
        boxes.push([lo, hi]);
    }
    (starts, boxes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::shapes::icosphere;

    /// Distance from `p` to the axis-aligned box `[lo, lo + size]`.
    fn box_distance(p: DVec3, lo: DVec3, size: f64) -> f64 {
        (lo - p).max(p - (lo + size)).max(DVec3::ZERO).length()
    }

    #[test]
    fn triangles_register_alike_in_any_chunks_and_within_reach() {
        // 5120 small triangles, more than one chunk, and two larger than a cell; every 50th
        // has no area and registers nowhere.
        let mut tris = icosphere(4, Vec3::ZERO, 1.0);
        tris.insert(3000, [Vec3::new(-1.0, -1.0, 0.0), Vec3::X, Vec3::Y]);
        tris.push([
            Vec3::new(0.0, -1.2, -1.2),
            Vec3::new(0.0, 1.2, -1.2),
            Vec3::Z,
        ]);
        let live: Vec<bool> = (0..tris.len()).map(|t| t % 50 != 7).collect();
        for (t, tri) in tris.iter_mut().enumerate() {
            if !live[t] {
                *tri = [tri[0]; 3];
            }
        }
        let sites: Vec<Vec3> = tris
            .iter()
            .step_by(61)
            .map(|t| (t[0] + t[1] + t[2]) / 3.0)
            .collect();
        let (size, reach) = (0.5, 0.2);
        let register = |chunk: usize| {
            let mut cells = Cells::new(&sites, size);
            cells.register_in_chunks(&tris, &live, reach, chunk);
            cells
        };
        let cells = register(REGISTER_CHUNK);
        let lists = |cells: &Cells| -> Vec<Vec<std::ops::Range<u32>>> {
            (0..cells.len())
                .map(|c| {
                    let runs = cells.patch_runs(c);
                    runs.flat_map(|(run, _)| run.iter().map(|&p| cells.patch(p as usize).0))
                        .collect()
                })
                .collect()
        };
        let whole = lists(&register(usize::MAX));
        assert_eq!(lists(&cells), whole);
        for chunk in [1, 7, 100] {
            assert_eq!(lists(&register(chunk)), whole, "chunk {chunk}");
        }
        // The patches cut the triangles into consecutive runs within the chunks; each box is
        // that of the patch's triangles with area, and spans at most a quarter of a cell
        // unless the patch holds one of them.
        let starts = &cells.patch_start;
        assert_eq!(
            (starts[0], starts[starts.len() - 1]),
            (0, tris.len() as u32)
        );
        let mut several = 0;
        for (p, w) in starts.windows(2).enumerate() {
            let (a, b) = (w[0] as usize, w[1] as usize);
            assert!(a < b && b - a <= PATCH, "patch {p}: {a}..{b}");
            assert_eq!(
                a / PATCH_CHUNK,
                (b - 1) / PATCH_CHUNK,
                "patch {p} crosses a chunk"
            );
            let alive: Vec<usize> = (a..b).filter(|&t| live[t]).collect();
            let (lo, hi) =
                alive
                    .iter()
                    .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &t| {
                        let [x, y, z] = tris[t];
                        (lo.min(x).min(y).min(z), hi.max(x).max(y).max(z))
                    });
            assert_eq!(cells.patch_box[p], [lo, hi], "patch {p}");
            if alive.len() > 1 {
                several += 1;
                assert!((hi - lo).max_element() <= 0.25 * size as f32, "patch {p}");
            }
        }
        assert!(several > 100, "{several} patches of several triangles");
        assert!(
            (1..starts.len())
                .any(|p| starts[p] - starts[p - 1] == 1 && live[starts[p - 1] as usize])
        );
        // Each list ascends, holds no patch without a triangle with area, and covers every
        // triangle that comes within the reach of its cell (tested at points spread over the
        // triangle).
        let mut near = 0;
        for (c, list) in whole.iter().enumerate() {
            assert!(list.windows(2).all(|w| w[0].end <= w[1].start), "cell {c}");
            assert!(
                list.iter().all(|r| r.clone().any(|t| live[t as usize])),
                "cell {c}"
            );
            let lo =
                cells.origin + DVec3::from_array(cells.cell_coords(c).map(|x| x as f64)) * size;
            for (t, tri) in tris.iter().enumerate().filter(|&(t, _)| live[t]) {
                let [a, b, c3] = tri.map(|v| v.as_dvec3());
                let touches = (0..=8).any(|i| {
                    (0..=8 - i).any(|j| {
                        let (u, v) = (i as f64 / 8.0, j as f64 / 8.0);
                        let p = a + (b - a) * u + (c3 - a) * v;
                        box_distance(p, lo, size) < 0.999 * reach
                    })
                });
                if touches {
                    near += 1;
                    assert!(
                        list.iter().any(|r| r.contains(&(t as u32))),
                        "cell {c}, triangle {t}"
                    );
                }
            }
        }
        assert!(near > 1000, "{near} (cell, triangle) pairs within reach");
    }
}
