//! Triangles that lie wholly in one site's cell, found before any clipping.
//!
//! A Voronoi cell is convex, so a triangle whose three corners are nearest to the same site
//! lies in that site's cell: the site takes the whole triangle, and every other site within
//! reach of it takes nothing. On a mesh finer than the samples that is most triangles, and
//! each is processed by about four sites; clipping it against each of them (the first pass's
//! main cost) is then needed only for the triangles a cell boundary crosses.
//!
//! The owner is recorded only where the answer is **robust**: each corner is nearer to its
//! site than to every other by more than [`ROBUST`] of the local scale squared, far above the
//! rounding of the clipping's half-plane tests (about 1e-14 of it, `clip.rs`). Then clipping
//! would keep every corner of the triangle for its owner and cut every corner away for any
//! other site (the tests are affine along the triangle, so its corners decide), and taking
//! the shortcut gives the very bits clipping gives. A tie (coincident sites, a corner on a
//! bisector), a corner outside the block of cells searched, or corners with different sites
//! leave the triangle [`SHARED`]: it is clipped as before.
//!
//! ```text
//! owners: [u32; triangles]   sorted site index, or SHARED
//! ```

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use super::cells::Cells;

/// The owner of a triangle that is clipped: no single site holds it robustly.
pub(super) const SHARED: u32 = u32::MAX;
/// How much nearer (relative to the squared local scale: the reach plus the triangle's
/// longest edge) a corner's site must be than any other.
const ROBUST: f64 = 1e-9;
/// Triangles per parallel task (fixed, so the result is the same for any thread count).
const CHUNK: usize = 4096;

/// The site (sorted index) in whose cell each triangle lies wholly, robustly, or [`SHARED`].
/// `live[t]` is false for triangles without area, which are [`SHARED`].
pub(super) fn triangle_owners(
    cells: &Cells,
    triangles: &[[Vec3; 3]],
    live: &[bool],
    reach: f64,
) -> Vec<u32> {
    let mut owners = vec![SHARED; triangles.len()];
    owners
        .par_chunks_mut(CHUNK)
        .enumerate()
        .for_each_init(Block::default, |block, (k, out)| {
            let first = k * CHUNK;
            for (i, owner) in out.iter_mut().enumerate() {
                let t = first + i;
                if live[t] {
                    *owner = block.owner(cells, &triangles[t], reach);
                }
            }
        });
    owners
}

/// The sites of the block of cells around the last triangle's first corner, and what was
/// found for the last triangle's corners (consecutive triangles usually share cells and
/// corners).
#[derive(Default)]
struct Block {
    home: Option<[i64; 3]>,
    sites: Vec<u32>,
    everyone: bool,
    /// The last triangle's corners with their [`Block::nearest`], found in this block.
    corners: Vec<(Vec3, Nearest)>,
}

/// A point's nearest site and by how much (squared distances) every other site is farther:
/// 0 where that cannot be shown.
#[derive(Clone, Copy)]
struct Nearest {
    site: u32,
    lead: f64,
}

impl Block {
    /// The robust owner of `tri`, or [`SHARED`].
    fn owner(&mut self, cells: &Cells, tri: &[Vec3; 3], reach: f64) -> u32 {
        let home = cells.coords(tri[0].as_dvec3());
        if self.home != Some(home) {
            self.home = Some(home);
            self.sites.clear();
            cells.gather(home, 1, &mut self.sites);
            self.everyone = self.sites.len() == cells.sites.len();
            self.corners.clear();
        }
        let longest = (0..3)
            .map(|k| tri[k].as_dvec3().distance(tri[(k + 1) % 3].as_dvec3()))
            .fold(0.0, f64::max);
        let scale = reach + longest;
        let margin = ROBUST * scale * scale;
        let found = tri.map(|corner| match self.corners.iter().find(|c| c.0 == corner) {
            Some(&(_, nearest)) => nearest,
            None => self.nearest(cells, corner.as_dvec3(), home),
        });
        self.corners.clear();
        self.corners.extend(tri.iter().copied().zip(found));
        let site = found[0].site;
        let robust = found.iter().all(|n| n.site == site && n.lead > margin);
        if robust { site } else { SHARED }
    }

    /// The site nearest to `p` among the block's, and its lead over every other site,
    /// counting those outside the block. (Tried on a 2 M-triangle sphere, no gain: the block's
    /// positions converted once per block; four independent branch-free running pairs merged
    /// at the end instead of this one branchy pass.)
    fn nearest(&self, cells: &Cells, p: DVec3, home: [i64; 3]) -> Nearest {
        let (mut site, mut first, mut second) = (SHARED, f64::INFINITY, f64::INFINITY);
        for &j in &self.sites {
            let d2 = p.distance_squared(cells.sites[j as usize].as_dvec3());
            if d2 < first {
                (site, first, second) = (j, d2, first);
            } else if d2 < second {
                second = d2;
            }
        }
        if !self.everyone {
            // Every site outside the block is at least this far.
            let inside = cells.inside_block(p, home, 1);
            second = if inside > 0.0 {
                second.min(inside * inside)
            } else {
                first
            };
        }
        let lead = second - first;
        Nearest {
            site,
            lead: if lead > 0.0 && site != SHARED {
                lead
            } else {
                0.0
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raster::testutil::Rng;

    /// Brute force: the site nearest to each corner over all sites, with the same margin.
    fn brute_owner(sites: &[Vec3], tri: &[Vec3; 3], margin: f64) -> Option<usize> {
        let nearest = |p: Vec3| {
            let mut d: Vec<(f64, usize)> = sites
                .iter()
                .enumerate()
                .map(|(j, s)| (p.as_dvec3().distance_squared(s.as_dvec3()), j))
                .collect();
            d.sort_by(|a, b| a.0.total_cmp(&b.0));
            (d.len() < 2 || d[1].0 - d[0].0 > margin).then_some(d[0].1)
        };
        let [a, b, c] = tri.map(nearest);
        (a.is_some() && a == b && b == c).then(|| a.unwrap())
    }

    #[test]
    fn owners_agree_with_every_site_searched() {
        let mut rng = Rng::new(7);
        let sites: Vec<Vec3> = (0..400)
            .map(|_| {
                Vec3::new(
                    rng.f32_in(0.0, 1.0),
                    rng.f32_in(0.0, 1.0),
                    rng.f32_in(0.0, 0.02),
                )
            })
            .collect();
        let cells = Cells::new(&sites, 0.1);
        let mut triangles = Vec::new();
        for _ in 0..3000 {
            let p = Vec3::new(rng.f32_in(0.0, 1.0), rng.f32_in(0.0, 1.0), 0.0);
            let e = rng.f32_in(0.0, 0.03);
            // Consecutive triangles share corners, as in a mesh.
            triangles.push([p, p + Vec3::new(e, 0.0, 0.0), p + Vec3::new(0.0, e, 0.0)]);
            triangles.push([
                p + Vec3::new(e, 0.0, 0.0),
                p + Vec3::new(e, e, 0.0),
                p + Vec3::new(0.0, e, 0.0),
            ]);
        }
        // Outside every block of cells.
        triangles.push([
            Vec3::splat(5.0),
            Vec3::new(5.1, 5.0, 5.0),
            Vec3::new(5.0, 5.1, 5.0),
        ]);
        let mut live = vec![true; triangles.len()];
        live[0] = false;
        let reach = 0.05;
        let owners = triangle_owners(&cells, &triangles, &live, reach);
        let (mut whole, mut missed) = (0, 0);
        for (tri, &owner) in triangles.iter().zip(&owners) {
            let longest = (0..3)
                .map(|k| tri[k].as_dvec3().distance(tri[(k + 1) % 3].as_dvec3()))
                .fold(0.0, f64::max);
            let margin = ROBUST * (reach + longest) * (reach + longest);
            let brute = brute_owner(&cells.sites, tri, margin);
            if owner == SHARED {
                missed += brute.is_some() as usize;
            } else {
                whole += 1;
                assert_eq!(brute, Some(owner as usize), "{tri:?}");
            }
        }
        // Only corners near the block's faces are missed.
        assert!(
            whole > 2500 && missed < whole / 100,
            "{whole} whole, {missed} missed"
        );
        assert_eq!(owners[0], SHARED, "no area");
        assert_eq!(owners[owners.len() - 1], SHARED, "outside every block");
    }

    #[test]
    fn ties_and_crossed_bisectors_are_shared() {
        let sites = [Vec3::ZERO, Vec3::X, Vec3::X];
        let cells = Cells::new(&sites, 0.25);
        let near = |p: Vec3| [p, p + Vec3::Y * 0.1, p + Vec3::Z * 0.1];
        let triangles = [
            near(Vec3::new(0.1, 0.0, 0.0)),
            near(Vec3::new(0.5, 0.2, 0.0)),
            [
                Vec3::new(0.4, 0.0, 0.0),
                Vec3::new(0.6, 0.0, 0.0),
                Vec3::new(0.4, 0.1, 0.0),
            ],
            near(Vec3::new(0.9, 0.0, 0.0)),
        ];
        let owners = triangle_owners(&cells, &triangles, &[true; 4], 0.5);
        let origin = cells.sites.iter().position(|&s| s == Vec3::ZERO).unwrap() as u32;
        // Near the site at the origin; a corner on the bisector; across the bisector; near the
        // two coincident sites.
        assert_eq!(owners, [origin, SHARED, SHARED, SHARED]);
    }
}
