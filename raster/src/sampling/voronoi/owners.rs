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
//! **The search.** A corner's nearest site is searched among the sites of the 3×3×3 block of
//! grid cells around its triangle; the sites outside the block count by their distance to its
//! faces. For a patch of several small triangles (`cells.rs`), the block's sites are first
//! narrowed to the few that can be nearest to a point of the patch, once for the patch, and
//! its corners are searched among those: on a mesh much finer than the samples a corner
//! compares about ten sites instead of a hundred. Which triangles get an owner may depend on
//! the search (a lead near the margin), never the areas: an owned triangle gets the bits
//! clipping gives.
//!
//! ```text
//! owners: [u32; triangles]   sorted site index, or SHARED
//! ```

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use super::cells::{Cells, Occupancy, PATCH_CHUNK};

/// The owner of a triangle that is clipped: no single site holds it robustly.
pub(super) const SHARED: u32 = u32::MAX;
/// How much nearer (relative to the squared local scale: the reach plus the triangle's
/// longest edge) a corner's site must be than any other.
const ROBUST: f64 = 1e-9;
/// Beyond the distance that can hold a patch's nearest sites, a site is still a candidate
/// within this many grid cells more: a corner's lead over the sites left out is then at least
/// about this much (in distance), far above the margin.
const SLACK: f64 = 0.25;

/// The site (sorted index) in whose cell each triangle lies wholly, robustly, or [`SHARED`].
/// `live[t]` is false for triangles without area, which are [`SHARED`]. `cells` must hold
/// the triangles' patches ([`Cells::register_triangles`]).
///
/// The triangles of a patch of several are searched among the patch's candidates
/// ([`Block::search_patch`]); a triangle alone in its patch (larger than a quarter of a cell,
/// or beside one) among all the sites of the block of cells around its first corner
/// ([`Block::search_block`]).
pub(super) fn triangle_owners(
    cells: &Cells,
    triangles: &[[Vec3; 3]],
    live: &[bool],
    reach: f64,
) -> Vec<u32> {
    let mut owners = vec![SHARED; triangles.len()];
    // Patches do not cross these chunks, so each task owns its patches' triangles.
    owners
        .par_chunks_mut(PATCH_CHUNK)
        .enumerate()
        .for_each_init(Block::default, |block, (k, out)| {
            let first = k * PATCH_CHUNK;
            for p in cells.patches_within(first..first + out.len()) {
                let (range, &[lo, hi]) = cells.patch(p);
                let range = range.start as usize..range.end as usize;
                match Occupancy::of(range.clone(), live) {
                    Occupancy::Empty => continue,
                    Occupancy::Single(t) => block.search_block(cells, triangles[t][0].as_dvec3()),
                    Occupancy::Several => block.search_patch(cells, lo.as_dvec3(), hi.as_dvec3()),
                }
                for t in range.filter(|&t| live[t]) {
                    out[t - first] = block.owner(cells, &triangles[t], reach);
                }
            }
        });
    owners
}

/// The sites searched for the current triangles' corners, and what was found for the last
/// triangle's corners (consecutive triangles usually share corners).
#[derive(Default)]
struct Block {
    /// The block of cells around `home`, and its sites.
    home: Option<[i64; 3]>,
    sites: Vec<u32>,
    everyone: bool,
    /// The sites searched, with their positions.
    searched: Vec<(u32, DVec3)>,
    /// Where the sites not searched lie: outside the block of cells around `home`, or at
    /// least `beyond` from `centre`.
    bound: Bound,
    /// The last triangle's corners with their [`Block::nearest`].
    corners: Vec<(Vec3, Nearest)>,
}

/// What is known of the sites a [`Block`] does not search.
#[derive(Clone, Copy, Default)]
enum Bound {
    /// There are none.
    #[default]
    None,
    /// They lie outside the block of cells around `home`.
    Block,
    /// They lie at least `beyond` from `centre`.
    Ball { centre: DVec3, beyond: f64 },
}

/// A point's nearest site and by how much (squared distances) every other site is farther:
/// 0 where that cannot be shown.
#[derive(Clone, Copy)]
struct Nearest {
    site: u32,
    lead: f64,
}

impl Block {
    /// Gathers the sites of the block of cells around `home`, unless they are those of the last
    /// block; returns whether it did.
    fn gather(&mut self, cells: &Cells, home: [i64; 3]) -> bool {
        if self.home == Some(home) {
            return false;
        }
        self.home = Some(home);
        self.sites.clear();
        cells.gather(home, 1, &mut self.sites);
        self.everyone = self.sites.len() == cells.sites.len();
        true
    }

    /// Searches every site of the block of cells around the cell of `corner`.
    fn search_block(&mut self, cells: &Cells, corner: DVec3) {
        let home = cells.coords(corner);
        if !self.gather(cells, home) && matches!(self.bound, Bound::Block | Bound::None) {
            return;
        }
        self.searched.clear();
        let position = |j: u32| (j, cells.sites[j as usize].as_dvec3());
        self.searched
            .extend(self.sites.iter().map(|&j| position(j)));
        self.bound = if self.everyone {
            Bound::None
        } else {
            Bound::Block
        };
        self.corners.clear();
    }

    /// Searches the candidates of the patch with box `lo..hi`: with `d` the distance from its
    /// centre to the nearest site and `ρ` the box's half diagonal, a point of the patch lies
    /// within `d + ρ` of that site, so its nearest site lies within `d + 2ρ` of the centre.
    /// The candidates are the sites of the block of cells around the centre within that
    /// distance and [`SLACK`] cells more.
    fn search_patch(&mut self, cells: &Cells, lo: DVec3, hi: DVec3) {
        let centre = (lo + hi) * 0.5;
        let home = cells.coords(centre);
        self.gather(cells, home);
        self.searched.clear();
        self.corners.clear();
        let position = |j: u32| cells.sites[j as usize].as_dvec3();
        let nearest = self
            .sites
            .iter()
            .map(|&j| centre.distance_squared(position(j)))
            .fold(f64::INFINITY, f64::min);
        let radius = (hi - lo).length() * 0.5;
        let within = nearest.sqrt() + 2.0 * radius + SLACK * cells.size;
        let mut beyond = if self.everyone {
            f64::INFINITY
        } else {
            cells.inside_block(centre, home, 1)
        };
        // The radius keeps the others a slack away from every point of the patch; the bound
        // is kept exact all the same.
        for &j in &self.sites {
            let d = centre.distance(position(j));
            if d <= within {
                self.searched.push((j, position(j)));
            } else {
                beyond = beyond.min(d);
            }
        }
        self.bound = Bound::Ball { centre, beyond };
    }

    /// The robust owner of `tri` among the sites searched, or [`SHARED`].
    fn owner(&mut self, cells: &Cells, tri: &[Vec3; 3], reach: f64) -> u32 {
        let longest = (0..3)
            .map(|k| tri[k].as_dvec3().distance(tri[(k + 1) % 3].as_dvec3()))
            .fold(0.0, f64::max);
        let scale = reach + longest;
        let margin = ROBUST * scale * scale;
        let found = tri.map(|corner| match self.corners.iter().find(|c| c.0 == corner) {
            Some(&(_, nearest)) => nearest,
            None => self.nearest(cells, corner.as_dvec3()),
        });
        self.corners.clear();
        self.corners.extend(tri.iter().copied().zip(found));
        let site = found[0].site;
        let robust = found.iter().all(|n| n.site == site && n.lead > margin);
        if robust { site } else { SHARED }
    }

    /// The site searched nearest to `p`, and its lead over every other site, counting those
    /// not searched by their [`Bound`]. (Tried on a 2 M-triangle sphere, no gain: four
    /// independent branch-free running pairs merged at the end instead of this one branchy
    /// pass.)
    fn nearest(&self, cells: &Cells, p: DVec3) -> Nearest {
        let (mut site, mut first, mut second) = (SHARED, f64::INFINITY, f64::INFINITY);
        for &(j, q) in &self.searched {
            let d2 = p.distance_squared(q);
            if d2 < first {
                (site, first, second) = (j, d2, first);
            } else if d2 < second {
                second = d2;
            }
        }
        // Every site not searched is at least this far.
        let rest = match self.bound {
            Bound::None => f64::INFINITY,
            Bound::Block => cells.inside_block(p, self.home.unwrap_or_default(), 1),
            Bound::Ball { centre, beyond } => beyond - p.distance(centre),
        };
        second = if rest > 0.0 {
            second.min(rest * rest)
        } else {
            first
        };
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
        let mut cells = Cells::new(&sites, 0.1);
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
        cells.register_triangles(&triangles, &live, reach);
        // Both searches run: pairs small enough for one patch, and triangles alone.
        let sizes: Vec<usize> = cells
            .patches_within(0..triangles.len())
            .map(|p| cells.patch(p).0.len())
            .collect();
        let pairs = sizes.iter().filter(|&&n| n == 2).count();
        assert!(
            pairs > 500 && sizes.len() - pairs > 500,
            "{pairs} of {}",
            sizes.len()
        );
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
        // Triangles as large as a cell, each alone in its patch, then small ones, each twice
        // in a row: a patch of two.
        for (size, copies) in [(0.1, 1), (0.01, 2)] {
            let mut cells = Cells::new(&sites, 0.25);
            let near = |p: Vec3| [p, p + Vec3::Y * size, p + Vec3::Z * size];
            let triangles: Vec<[Vec3; 3]> = [
                near(Vec3::new(0.1, 0.0, 0.0)),
                near(Vec3::new(0.5, 0.2, 0.0)),
                [
                    Vec3::new(0.5 - size, 0.0, 0.0),
                    Vec3::new(0.5 + size, 0.0, 0.0),
                    Vec3::new(0.5 - size, size, 0.0),
                ],
                near(Vec3::new(0.9, 0.0, 0.0)),
            ]
            .iter()
            .flat_map(|&t| std::iter::repeat_n(t, copies))
            .collect();
            let live = vec![true; triangles.len()];
            cells.register_triangles(&triangles, &live, 0.5);
            let patches = cells.patches_within(0..triangles.len()).len();
            assert_eq!(patches, 4, "size {size}");
            let owners = triangle_owners(&cells, &triangles, &live, 0.5);
            let origin = cells.sites.iter().position(|&s| s == Vec3::ZERO).unwrap() as u32;
            // Near the site at the origin; a corner on the bisector; across the bisector; near
            // the two coincident sites.
            let expected = [origin, SHARED, SHARED, SHARED].map(|o| [o; 2]);
            let expected: Vec<u32> = expected.iter().flat_map(|o| o[..copies].to_vec()).collect();
            assert_eq!(owners, expected, "size {size}");
        }
    }

    #[test]
    fn a_nearer_site_outside_the_block_keeps_a_triangle_shared() {
        // Cells of 0.1 from the origin. Around (0.34, 0.05), in cell (3, 0, 0), the block of
        // cells holds the site at (0.49, 0.19) but not the nearer one at (0.34, 0.21), in cell
        // (3, 2, 0). Thirty far sites keep the block from being every site.
        let mut sites = vec![
            Vec3::ZERO,
            Vec3::new(0.49, 0.19, 0.0),
            Vec3::new(0.34, 0.21, 0.0),
        ];
        sites.extend((0..30).map(|i| Vec3::new(5.0 + i as f32, 5.0, 0.0)));
        let mut cells = Cells::new(&sites, 0.1);
        let p = Vec3::new(0.34, 0.05, 0.0);
        let near = |size: f32| [p, p + Vec3::X * size, p + Vec3::Y * size];
        // A patch of two small triangles, and a triangle too large for a patch of several.
        let triangles = [near(0.005), near(0.005), near(0.03)];
        let live = [true; 3];
        let reach = 0.05;
        cells.register_triangles(&triangles, &live, reach);
        assert_eq!(cells.patches_within(0..3).len(), 2);
        let owners = triangle_owners(&cells, &triangles, &live, reach);
        let nearer = cells.sites.iter().position(|&s| s == sites[2]).unwrap();
        for tri in &triangles {
            assert_eq!(brute_owner(&cells.sites, tri, 1e-9), Some(nearer));
        }
        assert_eq!(owners, [SHARED; 3]);
    }
}
