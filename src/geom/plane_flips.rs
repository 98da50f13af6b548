//! Edge recovery inside a plane of mesh points by flips in that plane.
//!
//! CAD exports triangulate each planar facet as a fan of needles from one corner, far
//! from the Delaunay triangulation of the facet's points that the tetrahedralization
//! holds; each fan edge crosses many in-plane mesh edges, each exactly (the four points
//! coplanar). Splitting at those crossings puts rounded points a hair off the plane,
//! whose later pieces cross faces next to them and cut the segment into ever shorter
//! pieces (OpenSCAD-style CSG brackets: over a hundred points on one segment, and a fill
//! that could not be finished). Two triangulations of one planar point set are joined by
//! edge flips, and Lawson/Sloan's walk recovers a segment with them: flip any crossed
//! edge whose quadrilateral is strictly convex. In the tetrahedralization an in-plane
//! flip of edge xy to uw replaces the tets around xy, on each side of the plane, by the
//! edge-removal construction on that side's half of xy's ring (the 4-4 flip when each
//! side has one ring vertex).
//! Every decision is an exact orientation; no point is added.

use super::delaunay::{same_boundary, sorted2, Delaunay, FACES};
use super::predicates::{orient3d, projection_of, Proj};
use super::vec3::{dist2, tet_det, P3};
use rustc_hash::FxHashMap as HashMap;

/// In-plane flips one segment may take, per edge it crossed at first (plus as many):
/// in 3D a side of the plane can refuse a flip the plane would take, and two crossing
/// diagonals can then be flipped into each other while the queue's other edges wait. On
/// a CSG bracket's fans every recovery that succeeded took at most 2.2 per edge, and
/// the ones that cycled spent the whole time of the edge recovery with a budget of 4 per
/// edge squared.
const FLIPS_PER_CROSSING: usize = 4;

/// Most ring vertices on one side of a flipped edge (the polygon triangulated there).
const MAX_SIDE: usize = 16;

/// An in-plane flip ([`Delaunay::flip_in_plane`]) of edge xy to uw.
struct PlaneFlip {
    uw: [u32; 2],
    /// The tets around xy, to be replaced.
    around: Vec<u32>,
    /// Their vertices (to undo the flip).
    old: Vec<[u32; 4]>,
    new: Vec<[u32; 4]>,
}

/// The plane a segment lies in, with a projection in which its orientations are exact.
#[derive(Clone, Copy)]
struct InPlane {
    a: u32,
    b: u32,
    /// A third point of the plane, off line ab.
    c: u32,
    proj: Proj,
}

impl InPlane {
    /// Whether mesh edge uw (in the plane) crosses the segment properly: each segment's
    /// ends strictly on either side of the other's line.
    fn crosses(self, dt: &Delaunay, u: u32, w: u32) -> bool {
        let o = |p: u32, q: u32, r: u32| self.proj.orient2d(dt.p(p), dt.p(q), dt.p(r));
        o(self.a, self.b, u) * o(self.a, self.b, w) < 0 && o(u, w, self.a) * o(u, w, self.b) < 0
    }
}

impl Delaunay {
    /// Make segment ab an edge by flips in a plane of mesh points through it, where the
    /// segment leaves `a` across an edge in that plane (four points exactly coplanar)
    /// and crosses only edges in it: the crossed edges are flipped, any strictly convex
    /// one first (Sloan's queue), until none is left. True when ab is an edge. False,
    /// with every flip undone, when the segment leaves the plane's faces, a crossed edge
    /// is fixed, or the crossed edges left cannot be flipped: the flips that did not
    /// recover the segment would only change the tets the other ways then start from.
    pub(crate) fn recover_in_plane(&mut self, a: u32, b: u32) -> bool {
        if self.has_edge(a, b) {
            return true;
        }
        let Some((plane, crossed)) = self.plane_crossings(a, b) else {
            return false;
        };
        let budget = FLIPS_PER_CROSSING * (crossed.len() + 1);
        // A crossed edge that cannot be flipped yet, or whose flip still crosses the
        // segment, goes to the back; a full turn of the queue without a flip is stuck.
        let mut queue: std::collections::VecDeque<[u32; 2]> = crossed.into();
        let mut idle = 0;
        // Each flip's new tets and the old ones, to undo them, and the ids of the tets
        // they made (a later flip or undo makes a tet again under a new id).
        let mut undo: Vec<PlaneFlip> = Vec::new();
        let mut ids: HashMap<[u32; 4], u32> = HashMap::default();
        while let Some([x, y]) = queue.pop_front() {
            if idle > queue.len() || undo.len() >= budget {
                for f in undo.into_iter().rev() {
                    let at: Vec<u32> = f.new.iter().map(|t| ids[t]).collect();
                    let back = self.replace(&at, &f.old);
                    ids.extend(f.old.into_iter().zip(back));
                }
                return false;
            }
            match self.flip_in_plane(x, y, plane) {
                Some(f) => {
                    let [u, w] = f.uw;
                    let at = self.replace(&f.around, &f.new);
                    ids.extend(f.new.iter().copied().zip(at));
                    undo.push(f);
                    idle = 0;
                    if plane.crosses(self, u, w) {
                        queue.push_back([u, w]);
                    }
                }
                None => {
                    idle += 1;
                    queue.push_back([x, y]);
                }
            }
        }
        self.has_edge(a, b)
    }

    /// The in-plane edges segment ab crosses, in order from `a`, and the plane: None
    /// unless it leaves `a` across an edge coplanar with it and every crossing after is
    /// one too (through the in-plane triangles that edge's ring holds), ending at `b`.
    fn plane_crossings(&self, a: u32, b: u32) -> Option<(InPlane, Vec<[u32; 2]>)> {
        let (pa, pb) = (self.p(a), self.p(b));
        let (t, k) = self.leaving(a, b)?;
        let tv = self.tets[t as usize];
        let f = FACES[k].map(|j| tv[j]);
        let zero: Vec<usize> = (0..3)
            .filter(|&e| orient3d(pa, pb, self.p(f[e]), self.p(f[(e + 1) % 3])) == 0)
            .collect();
        let &[e] = zero.as_slice() else {
            return None;
        };
        let (mut x, mut y) = (f[e], f[(e + 1) % 3]);
        let (proj, _) = projection_of(pa, pb, self.p(x))?;
        let plane = InPlane { a, b, c: x, proj };
        let side = |v: u32| proj.orient2d(pa, pb, self.p(v));
        if side(x) * side(y) >= 0 {
            return None;
        }
        let mut prev = a;
        let mut crossed = vec![[x, y]];
        for _ in 0..self.tets.len() {
            let w = match self.in_plane_ring(x, y, plane)? {
                [p, w] | [w, p] if p == prev => w,
                _ => return None,
            };
            if w == b {
                return Some((plane, crossed));
            }
            match side(w) {
                0 => return None, // a mesh point on the segment
                s if s == side(x) => {
                    prev = x;
                    x = w;
                }
                _ => {
                    prev = y;
                    y = w;
                }
            }
            crossed.push([x, y]);
        }
        None
    }

    /// The two ring vertices of edge xy in `plane`, one on each side of it; None unless
    /// there are exactly two so.
    fn in_plane_ring(&self, x: u32, y: u32, plane: InPlane) -> Option<[u32; 2]> {
        let ring = self.edge_ring(x, y, &self.around_edge(x, y))?;
        let on = self.coplanar_in(&ring, plane);
        let &[i, j] = on.as_slice() else {
            return None;
        };
        let (px, py) = (self.p(x), self.p(y));
        let s = |v: u32| plane.proj.orient2d(px, py, self.p(v));
        (s(ring[i]) * s(ring[j]) < 0).then_some([ring[i], ring[j]])
    }

    /// Positions in `ring` of its points on `plane`.
    fn coplanar_in(&self, ring: &[u32], plane: InPlane) -> Vec<usize> {
        let (pa, pb, pc) = (self.p(plane.a), self.p(plane.b), self.p(plane.c));
        (0..ring.len())
            .filter(|&i| orient3d(pa, pb, pc, self.p(ring[i])) == 0)
            .collect()
    }

    /// The flip of in-plane edge xy to the other diagonal uw of its in-plane quadrilateral
    /// x-u-y-w, when that is strictly convex and xy is not fixed: the tets around xy on
    /// each side of the plane are to be replaced by [`Delaunay::side_tets`]. None when a
    /// side has no valid tets.
    fn flip_in_plane(&self, x: u32, y: u32, plane: InPlane) -> Option<PlaneFlip> {
        if self.fixed_edges.contains(&sorted2(x, y)) {
            return None;
        }
        let around = self.around_edge(x, y);
        let ring = self.edge_ring(x, y, &around)?;
        let on = self.coplanar_in(&ring, plane);
        let &[iu, iw] = on.as_slice() else {
            return None;
        };
        let (u, w) = (ring[iu], ring[iw]);
        let o = |p: u32, q: u32, r: u32| plane.proj.orient2d(self.p(p), self.p(q), self.p(r));
        if o(x, y, u) * o(x, y, w) >= 0 || o(u, w, x) * o(u, w, y) >= 0 {
            return None;
        }
        // The two sides' chains of ring vertices from u to w.
        let n = ring.len();
        let side = |from: usize, to: usize| -> Vec<u32> {
            let len = (to + n - from) % n;
            (0..=len).map(|k| ring[(from + k) % n]).collect()
        };
        let sides = [side(iu, iw), side(iw, iu)];
        if sides.iter().any(|c| c.len() < 3 || c.len() > MAX_SIDE + 2) {
            return None;
        }
        let old: Vec<[u32; 4]> = around.iter().map(|&t| self.tets[t as usize]).collect();
        let mut new = Vec::with_capacity(2 * n);
        for c in &sides {
            new.extend(self.side_tets(c, x, y)?);
        }
        if !same_boundary(&old, &new) {
            return None;
        }
        Some(PlaneFlip {
            uw: [u, w],
            around,
            old,
            new,
        })
    }

    /// The new tets on one side of in-plane edge xy flipped to uw, for that side's chain
    /// `c` = u, A1, ..., w of ring vertices: a triangulation T of the polygon c (closed
    /// by uw) joined to x and to y, whose boundary is the side's faces (x | y, Ai, Ai+1)
    /// and the new in-plane faces (u, w, x), (u, w, y) (the edge-removal construction on
    /// half a ring). T is the one whose tets' least shape is largest (dynamic programming
    /// over the polygon's triangulations, as Shewchuk's edge removal); None when no T
    /// has every tet valid (x and y on opposite sides of each triangle).
    fn side_tets(&self, c: &[u32], x: u32, y: u32) -> Option<Vec<[u32; 4]>> {
        let m = c.len();
        // The two tets on triangle (c[i], c[k], c[j]), if valid, and their least shape.
        let pair = |i: usize, k: usize, j: usize| -> Option<([[u32; 4]; 2], f64)> {
            let (pa, pb, pc) = (self.p(c[i]), self.p(c[k]), self.p(c[j]));
            if orient3d(pa, pb, pc, self.p(x)) != -orient3d(pa, pb, pc, self.p(y)) {
                return None;
            }
            let mut out = [[0; 4]; 2];
            let mut q = f64::INFINITY;
            for (o, top) in out.iter_mut().zip([x, y]) {
                let mut t = [c[i], c[k], c[j], top];
                if !self.positive(t) {
                    t.swap(0, 1);
                }
                if !self.valid_new(t) {
                    return None;
                }
                q = q.min(shape(t.map(|v| self.p(v))));
                *o = t;
            }
            Some((out, q))
        };
        // best[i][j]: for the sub-polygon c[i..=j], the largest least shape and the
        // apex k of its triangle on (i, j).
        let mut best = vec![vec![(f64::NEG_INFINITY, usize::MAX); m]; m];
        for i in 0..m - 1 {
            best[i][i + 1] = (f64::INFINITY, usize::MAX);
        }
        for len in 2..m {
            for i in 0..m - len {
                let j = i + len;
                for k in i + 1..j {
                    let q = best[i][k].0.min(best[k][j].0);
                    if q <= best[i][j].0 {
                        continue;
                    }
                    if let Some((_, qt)) = pair(i, k, j) {
                        if q.min(qt) > best[i][j].0 {
                            best[i][j] = (q.min(qt), k);
                        }
                    }
                }
            }
        }
        if best[0][m - 1].1 == usize::MAX {
            return None;
        }
        let mut tets = Vec::with_capacity(2 * (m - 2));
        let mut todo = vec![(0, m - 1)];
        while let Some((i, j)) = todo.pop() {
            let k = best[i][j].1;
            if k == usize::MAX {
                continue;
            }
            tets.extend(pair(i, k, j)?.0);
            todo.push((i, k));
            todo.push((k, j));
        }
        Some(tets)
    }
}

/// A tet's shape: 6 x volume over the cube of its root-mean-square edge length (up to a
/// constant, 1 for the regular tet), scale-free, 0 when flat.
fn shape(p: [P3; 4]) -> f64 {
    let mut l2 = 0.0;
    for i in 0..4 {
        for j in i + 1..4 {
            l2 += dist2(p[i], p[j]);
        }
    }
    let rms = (l2 / 6.0).sqrt();
    tet_det(p[0], p[1], p[2], p[3]) / (rms * rms * rms)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The points of [`a_planar_fan_is_recovered_by_flips_in_its_plane`]: a far apex
    /// (0), an arc of 12 points in the plane z = 0 bulging away from it (1..=12), and 5
    /// points above.
    fn fan_points() -> Vec<P3> {
        let mut pts: Vec<P3> = vec![[-80.0, 0.0, 0.0]];
        for k in 0..12 {
            let s = k as f64 / 11.0;
            pts.push([6.0 * (std::f64::consts::PI * s).sin(), 20.0 * s - 10.0, 0.0]);
        }
        for &(x, y) in &[
            (0.0, 0.0),
            (-10.0, 3.0),
            (-20.0, -1.0),
            (1.0, 8.0),
            (1.0, -7.0),
        ] {
            pts.push([x, y, 3.0]);
        }
        pts
    }

    /// The live tets, each rotated to start at its smallest vertex, sorted.
    fn live_tets(dt: &Delaunay) -> Vec<[u32; 4]> {
        let mut out: Vec<[u32; 4]> = (0..dt.tets.len())
            .filter(|&t| dt.alive[t])
            .map(|t| {
                let mut v = dt.tets[t];
                // Even permutations keep the orientation: two swaps bring the
                // smallest first.
                let m = (0..4).min_by_key(|&i| v[i]).unwrap_or(0);
                if m != 0 {
                    v.swap(0, m);
                    let (i, j) = [(2, 3), (1, 3), (1, 2)][m - 1];
                    v.swap(i, j);
                }
                // Then a cyclic turn of the other three (even) to put their smallest
                // second.
                let k = (1..4).min_by_key(|&i| v[i]).unwrap_or(1);
                v[1..].rotate_left(k - 1);
                v
            })
            .collect();
        out.sort_unstable();
        out
    }

    /// A fan of needles in the plane z = 0 (the triangulation CAD exporters write for a
    /// planar facet) from a far apex to an arc that bulges away from it, with points
    /// above: the Delaunay tetrahedralization holds the arc's own triangles there instead,
    /// each fan edge crosses some of their edges exactly, and in-plane flips recover
    /// every fan edge with no new point.
    #[test]
    fn a_planar_fan_is_recovered_by_flips_in_its_plane() {
        let pts = fan_points();
        let mut dt = Delaunay::new(&pts);
        let volume = |dt: &Delaunay| -> f64 {
            (0..dt.tets.len())
                .filter(|&t| dt.alive[t])
                .map(|t| {
                    let p = dt.tets[t].map(|v| dt.p(v));
                    tet_det(p[0], p[1], p[2], p[3])
                })
                .sum()
        };
        let before = volume(&dt);
        let missing: Vec<u32> = (1..13).filter(|&v| !dt.has_edge(0, v)).collect();
        assert!(
            missing.len() >= 3,
            "the Delaunay has the fan already: {missing:?}"
        );
        for v in 1..13 {
            assert!(dt.recover_in_plane(0, v), "fan edge 0-{v}");
            dt.fixed_edges.insert(sorted2(0, v));
        }
        assert!((1..13).all(|v| dt.has_edge(0, v)));
        assert_eq!(dt.pts.len(), pts.len() + 4, "no point added");
        let live: Vec<[u32; 4]> = (0..dt.tets.len())
            .filter(|&t| dt.alive[t])
            .map(|t| dt.tets[t])
            .collect();
        assert!(live.iter().all(|&t| dt.positive(t)));
        let after = volume(&dt);
        assert!(
            (after - before).abs() <= 1e-12 * before,
            "{after} vs {before}"
        );
    }

    /// Where a crossed edge may not be flipped (fixed: a recovered segment), the
    /// recovery stops, and the flips it made are undone: the same tets as before.
    #[test]
    fn a_stuck_recovery_in_a_plane_undoes_its_flips() {
        let mut dt = Delaunay::new(&fan_points());
        let (v, crossed) = (1..13)
            .find_map(|v| {
                let (_, c) = dt.plane_crossings(0, v)?;
                (c.len() >= 3).then_some((v, c))
            })
            .expect("a fan edge crossing three edges or more");
        let last = crossed[crossed.len() - 1];
        dt.fixed_edges.insert(sorted2(last[0], last[1]));
        let before = live_tets(&dt);
        assert!(!dt.recover_in_plane(0, v));
        assert_eq!(live_tets(&dt), before);
        // Unfixed, the same recovery goes through.
        dt.fixed_edges.clear();
        assert!(dt.recover_in_plane(0, v));
        assert_ne!(live_tets(&dt), before);
    }
}
