//! The supersampled visibility buffer: per sub-sample the nearest depth and the id of the
//! triangle seen there (layout drawn on [`VisibilityBuffer`]), and the span depth test.

use glam::{Mat4, Vec3, Vec4};
use rayon::prelude::*;

use super::clip::clip_and_project;
use super::error::RasterError;
use super::fixed::{Grid, MAX_GRID_AXIS};
use super::scan::scan_triangle_rows;
use crate::memory::{self, OutOfMemory};
use crate::output::Region;

/// The triangle id of an empty sub-sample.
pub const EMPTY: u32 = u32::MAX;

/// Most sub-samples a buffer may hold (2^28: 2 GiB of depth and ids).
pub const MAX_SUBSAMPLES: u64 = 1 << 28;

/// Largest supported `aa` (sub-samples per pixel axis).
pub const MAX_AA: u32 = 8;

/// A supersampled depth + triangle-id buffer.
///
/// # Layout
///
/// The `aa × aa` sub-samples of every pixel form one big row-major **sub-sample grid** of
/// `cols = width·aa` by `rows = height·aa` entries, stored as two parallel arrays (depth and
/// triangle id, structure of arrays). Sub-sample `(i, j)` of pixel `(x, y)` sits at pixel-space
/// position `(x + (i + ½)/aa, y + (j + ½)/aa)` and at index
/// `(y·aa + j)·cols + x·aa + i`:
///
/// ```text
///  aa = 2, width = 3                 index in depths() / triangles()
///            pixel 0   pixel 1   pixel 2
///  row 0   │ i0   i1 │ i0   i1 │ i0   i1 │     0  1 │  2  3 │  4  5      (pixel row 0, j = 0)
///  row 1   │ i0   i1 │ i0   i1 │ i0   i1 │     6  7 │  8  9 │ 10 11      (pixel row 0, j = 1)
///  row 2   │  ...                               12 13 │ ...             (pixel row 1, j = 0)
/// ```
///
/// The scan converter fills horizontal runs of this grid, so a span is one contiguous slice of
/// each array; resolving a pixel reads `aa` short runs.
///
/// A buffer made by [`VisibilityBuffer::new_window`] holds only a **window** of the image's
/// pixels (a tile and the pixels its shading reads): the arrays are the sub-sample grid of
/// the window alone, `window.width()·aa` entries a row, while triangles are still projected
/// and scanned on the whole image's grid and their spans cut to the window. Every sub-sample
/// of the window gets the bits the whole image's buffer has there, and a tile of a large
/// image needs the memory of the tile, not of the image.
///
/// Depth is NDC `z = z_clip / w_clip` in [0, 1] (glam's `perspective_rh`), smaller is nearer,
/// interpolated affinely in screen space (NDC depth is affine in screen space, which is why
/// z-buffers store it). An empty sub-sample has depth `+∞` and id [`EMPTY`]. The depth test is a
/// strict `<`: on equal depth the triangle drawn first stays, so results depend only on the
/// drawing order, never on timing.
#[derive(Clone, Debug)]
pub struct VisibilityBuffer {
    width: u32,
    height: u32,
    aa: u32,
    /// The whole image's sub-sample grid, on which triangles are scanned.
    grid: Grid,
    /// The pixels held: the whole image unless made by [`VisibilityBuffer::new_window`].
    window: Region,
    /// Sub-samples per row of the arrays: `window.width()·aa`.
    held_cols: usize,
    /// For a window smaller than the image, its NDC bounds grown by [`CULL_MARGIN`]:
    /// `[x_min, x_max, y_min, y_max]`.
    window_ndc: Option<[f64; 4]>,
    /// NDC depth per sub-sample, `+∞` when empty.
    depth: Vec<f32>,
    /// Triangle id per sub-sample, [`EMPTY`] when empty.
    triangle: Vec<u32>,
    /// Indices `j·aa + i` of a pixel's sub-samples, nearest to the pixel centre first (ties in
    /// index order); used by `resolve` to pick representatives.
    pub(super) centre_order: Vec<u8>,
}

impl VisibilityBuffer {
    /// An empty buffer of `width × height` pixels with `aa × aa` sub-samples per pixel.
    ///
    /// Sizes are validated before anything is allocated, and allocation failure is reported
    /// rather than aborting.
    pub fn new(width: u32, height: u32, aa: u32) -> Result<Self, RasterError> {
        Self::new_window(width, height, aa, Region::full(width, height))
    }

    /// An empty buffer of a `width × height` image with `aa × aa` sub-samples per pixel that
    /// holds only the pixels of `window` (see the layout above). The limit of
    /// [`MAX_SUBSAMPLES`] applies to the window, the one per axis to the image.
    pub fn new_window(
        width: u32,
        height: u32,
        aa: u32,
        window: Region,
    ) -> Result<Self, RasterError> {
        if width == 0 || height == 0 {
            return Err(RasterError::EmptyImage { width, height });
        }
        if !(1..=MAX_AA).contains(&aa) {
            return Err(RasterError::InvalidAa { aa });
        }
        if window.check_within(width, height).is_err() {
            return Err(RasterError::WindowOutside {
                window,
                width,
                height,
            });
        }
        let (cols, rows) = (
            u64::from(width) * u64::from(aa),
            u64::from(height) * u64::from(aa),
        );
        let axis = u64::from(MAX_GRID_AXIS);
        if cols > axis || rows > axis {
            return Err(RasterError::TooLarge { width, height, aa });
        }
        let (held_cols, held_rows) = (
            u64::from(window.width()) * u64::from(aa),
            u64::from(window.height()) * u64::from(aa),
        );
        if held_cols * held_rows > MAX_SUBSAMPLES {
            return Err(RasterError::TooLarge {
                width: window.width(),
                height: window.height(),
                aa,
            });
        }
        let len = (held_cols * held_rows) as usize; // ≤ 2^28
        // A refusal names the whole buffer: depth and ids, 8 bytes per sub-sample.
        let whole = |e: OutOfMemory| {
            RasterError::OutOfMemory(OutOfMemory {
                bytes: held_cols * held_rows * 8,
                ..e
            })
        };
        let depth = memory::filled(len, f32::INFINITY, memory::VISIBILITY).map_err(whole)?;
        let triangle = memory::filled(len, EMPTY, memory::VISIBILITY).map_err(whole)?;

        // Squared distance to the pixel centre in units of (1 / 2aa)²: (2i + 1 − aa)² + (…)².
        let dist = |s: u32| {
            let (i, j) = ((s % aa) as i32, (s / aa) as i32);
            let a = aa as i32;
            (2 * i + 1 - a).pow(2) + (2 * j + 1 - a).pow(2)
        };
        let mut centre_order: Vec<u8> = (0..aa * aa).map(|s| s as u8).collect();
        centre_order.sort_by_key(|&s| (dist(u32::from(s)), s));

        Ok(Self {
            width,
            height,
            aa,
            grid: Grid {
                cols: cols as u32,
                rows: rows as u32,
            },
            window,
            held_cols: held_cols as usize,
            window_ndc: (!window.is_full(width, height)).then(|| {
                // Sub-sample column c is at NDC x = 2c/cols − 1, row r at y = 1 − 2r/rows.
                let (cols, rows, m) = (cols as f64, rows as f64, CULL_MARGIN);
                let aa = f64::from(aa);
                let x = |c: f64| 2.0 * c / cols - 1.0;
                let y = |r: f64| 1.0 - 2.0 * r / rows;
                [
                    x(f64::from(window.x0) * aa - m),
                    x(f64::from(window.x1) * aa + m),
                    y(f64::from(window.y1) * aa + m),
                    y(f64::from(window.y0) * aa - m),
                ]
            }),
            depth,
            triangle,
            centre_order,
        })
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Sub-samples per pixel axis.
    pub fn aa(&self) -> u32 {
        self.aa
    }

    /// `(cols, rows)` of the image's sub-sample grid: `(width·aa, height·aa)`.
    pub fn grid_size(&self) -> (u32, u32) {
        (self.grid.cols, self.grid.rows)
    }

    /// The pixels the buffer holds (the whole image unless made by
    /// [`VisibilityBuffer::new_window`]).
    pub fn window(&self) -> Region {
        self.window
    }

    /// Depth per sub-sample, row-major over the window's sub-sample grid (the image's for a
    /// buffer of the whole image; see the layout above).
    pub fn depths(&self) -> &[f32] {
        &self.depth
    }

    /// Triangle id per sub-sample ([`EMPTY`] where nothing was drawn), same layout as
    /// [`depths`](Self::depths).
    pub fn triangles(&self) -> &[u32] {
        &self.triangle
    }

    /// Indices `j·aa + i` of a pixel's sub-samples, nearest to the pixel centre first (ties in
    /// index order): the order in which [`resolve`](Self::resolve) picks representatives.
    pub fn centre_order(&self) -> &[u8] {
        &self.centre_order
    }

    /// `(triangle id, depth)` of sub-sample `(i, j)` of pixel `(x, y)`; `None` when out of
    /// range or empty. A pixel of the image outside the window is a caller's error (debug
    /// builds assert); it reads as empty.
    pub fn sample(&self, x: u32, y: u32, i: u32, j: u32) -> Option<(u32, f32)> {
        if !self.holds(x, y) || i >= self.aa || j >= self.aa {
            return None;
        }
        let idx = self.index(x, y, i, j);
        let id = self.triangle[idx];
        (id != EMPTY).then(|| (id, self.depth[idx]))
    }

    /// True when pixel `(x, y)` lies in the window; asserts (debug builds) that a pixel of the
    /// image is not read outside it, which would give a tile other bits than the whole image.
    #[inline]
    pub(super) fn holds(&self, x: u32, y: u32) -> bool {
        let held = self.window.contains(x, y);
        debug_assert!(
            held || x >= self.width || y >= self.height,
            "pixel ({x}, {y}) read outside the visibility window {}",
            self.window
        );
        held
    }

    /// Index of sub-sample `(i, j)` of pixel `(x, y)` (arguments in range, the pixel in the
    /// window).
    #[inline]
    pub(super) fn index(&self, x: u32, y: u32, i: u32, j: u32) -> usize {
        let w = &self.window;
        ((y - w.y0) * self.aa + j) as usize * self.held_cols + ((x - w.x0) * self.aa + i) as usize
    }

    /// Empties every sub-sample.
    pub fn clear(&mut self) {
        self.depth.fill(f32::INFINITY);
        self.triangle.fill(EMPTY);
    }

    /// Rasterises one clip-space triangle with id `id` (either winding; no culling).
    ///
    /// The triangle is clipped to the view frustum, so parts behind the near plane or outside
    /// the image are dropped; input containing NaN or infinity draws nothing, as does
    /// `id == EMPTY`. Each covered sub-sample (top-left fill rule) whose interpolated depth is
    /// strictly less than the stored one takes this triangle's depth and id.
    pub fn rasterize_triangle(&mut self, id: u32, clip: [Vec4; 3]) {
        if id == EMPTY || self.misses_window(&clip) {
            return;
        }
        let poly = clip_and_project(clip, self.grid);
        let plane = poly.depth;
        let w = &self.window;
        let (first_col, end_col) = (w.x0 * self.aa, w.x1 * self.aa);
        let rows = w.y0 * self.aa..w.y1 * self.aa;
        let cols = self.held_cols;
        let (depth, triangle) = (&mut self.depth, &mut self.triangle);
        for tri in poly.triangles() {
            scan_triangle_rows(tri, self.grid, rows.clone(), |row, c0, c1| {
                // The span cut to the window; its depths still count from the span's start
                // (`z0` at c0), as the whole image's do.
                let (a, b) = (c0.max(first_col), c1.min(end_col));
                if a >= b {
                    return;
                }
                let at = (row - rows.start) as usize * cols;
                let range = at + (a - first_col) as usize..at + (b - first_col) as usize;
                let (z0, dz) = plane.span(row, c0);
                let skipped = (a - c0) as f32;
                depth_test_span(
                    &mut depth[range.clone()],
                    &mut triangle[range],
                    z0,
                    dz,
                    skipped,
                    id,
                );
            });
        }
    }

    /// True when the triangle certainly covers no sub-sample of a window smaller than the image:
    /// its three clip-space corners lie beyond one and the same edge of the window, grown by
    /// [`CULL_MARGIN`] sub-samples, e.g. x < e·w for the left edge at NDC x = e. The inequality
    /// is linear in clip space, so it holds over the whole triangle, and every visible point
    /// (w > 0) projects beyond the edge, corners behind the eye included. Tiles of large scenes
    /// would otherwise clip and project every triangle of the image; the margin keeps the test
    /// clear of rounding.
    fn misses_window(&self, clip: &[Vec4; 3]) -> bool {
        let Some([x_min, x_max, y_min, y_max]) = self.window_ndc else {
            return false;
        };
        let all = |beyond: fn(&Vec4, f64) -> bool, edge: f64| clip.iter().all(|v| beyond(v, edge));
        all(|v, e| f64::from(v.x) < e * f64::from(v.w), x_min)
            || all(|v, e| f64::from(v.x) > e * f64::from(v.w), x_max)
            || all(|v, e| f64::from(v.y) < e * f64::from(v.w), y_min)
            || all(|v, e| f64::from(v.y) > e * f64::from(v.w), y_max)
    }

    /// Rasterises an indexed mesh: triangle `k` gets id `first_id + k` and its corners are
    /// `view_proj · (position, 1)`.
    ///
    /// Triangles with an out-of-range index are skipped (and keep their id slot); drawing stops
    /// before an id would reach [`EMPTY`].
    ///
    /// A mesh of at least 65 536 triangles a thread is drawn on the rayon threads, each taking
    /// a contiguous run of triangles into a buffer of its own (the first thread into this one),
    /// the runs' buffers then merged in id order. The buffer is the one-threaded draw's, bit for
    /// bit: a sub-sample keeps the first triangle in id order at the least depth drawn there,
    /// whether one thread finds it or the merge does (a later run's depth replaces an earlier
    /// one's only where strictly less, as within a run). The extra buffers take at most 256 MB
    /// (8 bytes a sub-sample each); a larger image is drawn in fewer runs.
    pub fn rasterize_mesh(
        &mut self,
        view_proj: Mat4,
        positions: &[Vec3],
        triangles: &[[u32; 3]],
        first_id: u32,
    ) {
        let runs = rayon::current_num_threads()
            .min(triangles.len() / PARALLEL_MIN_TRIANGLES)
            .min(self.runs_within(PARALLEL_MAX_BYTES));
        self.draw_in_runs(view_proj, positions, triangles, first_id, runs);
    }

    /// [`VisibilityBuffer::rasterize_mesh`] in `runs` contiguous runs of triangles (one thread
    /// each at most; fewer than two draw on this thread).
    fn draw_in_runs(
        &mut self,
        view_proj: Mat4,
        positions: &[Vec3],
        triangles: &[[u32; 3]],
        first_id: u32,
        runs: usize,
    ) {
        if runs < 2 || triangles.is_empty() {
            self.draw_run(view_proj, positions, triangles, first_id, 0);
            return;
        }
        // The other runs' buffers; if one cannot be had, the mesh is drawn on one thread.
        let Ok(mut others) = (1..runs)
            .map(|_| VisibilityBuffer::new_window(self.width, self.height, self.aa, self.window))
            .collect::<Result<Vec<_>, _>>()
        else {
            self.draw_run(view_proj, positions, triangles, first_id, 0);
            return;
        };
        let per_run = triangles.len().div_ceil(runs);
        {
            let mut buffers: Vec<&mut VisibilityBuffer> = Vec::with_capacity(runs);
            buffers.push(&mut *self);
            buffers.extend(others.iter_mut());
            buffers
                .par_iter_mut()
                .zip(triangles.par_chunks(per_run))
                .enumerate()
                .for_each(|(run, (buffer, chunk))| {
                    buffer.draw_run(view_proj, positions, chunk, first_id, run * per_run);
                });
        }
        for later in &others {
            self.merge_later(later);
        }
    }

    /// How many runs [`VisibilityBuffer::rasterize_mesh`] may draw at once when the buffers of
    /// all but the first take at most `bytes`.
    fn runs_within(&self, bytes: u64) -> usize {
        let per_buffer = (self.depth.len() as u64 * 8).max(1);
        (bytes / per_buffer)
            .saturating_add(1)
            .min(usize::MAX as u64) as usize
    }

    /// Draws `triangles`, the mesh's from index `offset` on (ids `first_id + offset + k`).
    fn draw_run(
        &mut self,
        view_proj: Mat4,
        positions: &[Vec3],
        triangles: &[[u32; 3]],
        first_id: u32,
        offset: usize,
    ) {
        for (k, tri) in triangles.iter().enumerate() {
            let Some(id) = u32::try_from(offset + k)
                .ok()
                .and_then(|k| first_id.checked_add(k))
            else {
                return;
            };
            let corner = |i: u32| positions.get(i as usize).map(|p| view_proj * p.extend(1.0));
            if let (Some(a), Some(b), Some(c)) = (corner(tri[0]), corner(tri[1]), corner(tri[2])) {
                self.rasterize_triangle(id, [a, b, c]);
            }
        }
    }

    /// Takes `later`'s sub-samples where they are strictly nearer: `later` holds triangles
    /// drawn after every one of this buffer's (the same image and window).
    fn merge_later(&mut self, later: &VisibilityBuffer) {
        let pairs = self.depth.iter_mut().zip(&mut self.triangle);
        for ((depth, id), (&later_depth, &later_id)) in
            pairs.zip(later.depth.iter().zip(&later.triangle))
        {
            if later_depth < *depth {
                *depth = later_depth;
                *id = later_id;
            }
        }
    }
}

/// How far beyond a window's edge, in sub-samples, a triangle's corners must lie for the
/// triangle to be skipped without clipping ([`VisibilityBuffer::misses_window`]): far more
/// than the rounding of the projection and of the snap to 1/256 sub-sample.
const CULL_MARGIN: f64 = 2.0;

/// Meshes with at least this many triangles per thread are drawn in parallel (below it, the
/// extra buffers cost more than the threads save).
const PARALLEL_MIN_TRIANGLES: usize = 1 << 16;
/// Most bytes the extra buffers of a parallel draw may take (8 bytes a sub-sample each).
const PARALLEL_MAX_BYTES: u64 = 256 << 20;

/// Lanes per chunk of [`depth_test_span`]: eight `f32` fill one AVX register or two SSE ones.
const LANES: usize = 8;

/// Depth-tests one span: its sub-sample `k` gets depth `clamp(z0 + (first + k)·dz, 0, 1)` and
/// takes `id` where that is strictly less than the stored depth (`first` > 0: the span's
/// first `first` sub-samples lie outside the buffer's window).
///
/// The span is processed in chunks of [`LANES`] whose results are computed into local arrays
/// and written back unconditionally, so the compiler vectorises the compare-and-select (a plain
/// `if z < d { … }` loop compiles to a branch per sub-sample; measured on the `large_triangles`
/// bench: ≈ 690 M sub-samples/s plain, ≈ 900 M/s chunked). `k` is carried as an `f32`, exact
/// because spans are shorter than 2^24, so every lane computes exactly what a scalar loop would.
#[inline]
fn depth_test_span(depths: &mut [f32], ids: &mut [u32], z0: f32, dz: f32, first: f32, id: u32) {
    let depth_at = |k: f32| (z0 + dz * k).clamp(0.0, 1.0);
    let mut d_chunks = depths.chunks_exact_mut(LANES);
    let mut t_chunks = ids.chunks_exact_mut(LANES);
    let mut base = first;
    for (d, t) in (&mut d_chunks).zip(&mut t_chunks) {
        let mut new_d = [0.0f32; LANES];
        let mut new_t = [0u32; LANES];
        for l in 0..LANES {
            let z = depth_at(base + l as f32);
            let nearer = z < d[l];
            new_d[l] = if nearer { z } else { d[l] };
            new_t[l] = if nearer { id } else { t[l] };
        }
        d.copy_from_slice(&new_d);
        t.copy_from_slice(&new_t);
        base += LANES as f32;
    }
    let tail = d_chunks
        .into_remainder()
        .iter_mut()
        .zip(t_chunks.into_remainder());
    for (d, t) in tail {
        let z = depth_at(base);
        if z < *d {
            *d = z;
            *t = id;
        }
        base += 1.0;
    }
}

#[cfg(test)]
mod tests;
