//! A mutable straight-sided tet mesh with vertex → tet incidence: what the local
//! operations of the linear stage edit.

use super::objective::ElementQuality;
use crate::geom::vec3::P3;
use crate::optimize::Boundary;

/// Marker of a deleted tet slot.
pub(super) const DEAD: [u32; 4] = [u32::MAX; 4];

/// Tets (positive corner order) with cached qualities and vertex stars.
#[derive(Clone)]
pub(super) struct LinMesh<'a> {
    /// Point positions (surface nodes first; only interior ones ever change).
    pub pts: Vec<P3>,
    /// Tets; deleted slots hold [`DEAD`].
    pub tets: Vec<[u32; 4]>,
    /// Cached quality of each live tet.
    pub q: Vec<f64>,
    /// Tets incident to each point.
    pub vt: Vec<Vec<u32>>,
    /// The fixed boundary.
    pub bnd: &'a Boundary,
    /// The element quality measure.
    pub eq: ElementQuality,
    /// Per point: its star changed since it was last smoothed to a standstill.
    pub dirty: Vec<bool>,
    /// Per point: the [`LinMesh::clock`] value of the last change in its star.
    pub changed: Vec<u64>,
    /// Counts changes (tets added or removed, vertices moved).
    pub clock: u64,
    /// Per point: the [`LinMesh::clock`] value when a sampled search last failed to
    /// move it (0: never). The search is a function of the star's corners and of the
    /// score, so while [`LinMesh::changed`] is older it fails again (see
    /// [`LinMesh::search_futile`]).
    searched: Vec<u64>,
    /// Deleted slots, reused by [`LinMesh::add`] (last freed first).
    free: Vec<u32>,
    /// Score tets by [`LinMesh::sliver_score`] instead of the element quality (the
    /// sliver passes); every cached quality must be measured again when it changes
    /// ([`LinMesh::set_sliver_mode`]).
    sliver_mode: bool,
    /// Boundary edges (smaller id, larger id) that [`LinMesh::sliver_score`] takes
    /// straight: those the straightening after the high-order stage will put back on
    /// their chords (see [`super::LinearParams::chords`]).
    pub chorded: rustc_hash::FxHashSet<(u32, u32)>,
}

impl<'a> LinMesh<'a> {
    /// Build from the front's output.
    #[cfg(test)]
    pub fn new(pts: Vec<P3>, tets: Vec<[u32; 4]>, bnd: &'a Boundary, eq: ElementQuality) -> Self {
        Self::with_known(pts, tets, None, bnd, eq)
    }

    /// Build from the front's output. `known[i]`, when given and not NaN, is tet `i`'s
    /// corner quality (1 − skewness, as [`ElementQuality`] scores a tet with fewer than
    /// two boundary vertices); it is used for such tets instead of measuring again.
    pub fn with_known(
        pts: Vec<P3>,
        tets: Vec<[u32; 4]>,
        known: Option<&[f64]>,
        bnd: &'a Boundary,
        eq: ElementQuality,
    ) -> Self {
        // Each star allocated once at its final size (about 20 tets; grown push by push,
        // most were reallocated three times).
        let mut deg = vec![0u32; pts.len()];
        for t in &tets {
            for &v in t {
                deg[v as usize] += 1;
            }
        }
        let mut vt: Vec<Vec<u32>> = deg
            .iter()
            .map(|&d| Vec::with_capacity(d as usize))
            .collect();
        for (i, t) in tets.iter().enumerate() {
            for &v in t {
                vt[v as usize].push(i as u32);
            }
        }
        let mut m = LinMesh {
            pts,
            q: vec![0.0; tets.len()],
            tets,
            vt,
            bnd,
            eq,
            dirty: vec![true; 0],
            changed: Vec::new(),
            clock: 1,
            searched: Vec::new(),
            free: Vec::new(),
            sliver_mode: false,
            chorded: Default::default(),
        };
        m.dirty = vec![true; m.pts.len()];
        m.changed = vec![1; m.pts.len()];
        for i in 0..m.tets.len() {
            let v = m.tets[i];
            let k = known.and_then(|k| k.get(i)).copied().unwrap_or(f64::NAN);
            m.q[i] = if !k.is_nan() && v.iter().filter(|&&x| bnd.is_fixed(x)).count() < 2 {
                k
            } else {
                m.quality(v)
            };
        }
        m
    }

    /// Corner positions of `v`.
    #[inline]
    pub fn corners(&self, v: [u32; 4]) -> [P3; 4] {
        v.map(|i| self.pts[i as usize])
    }

    /// Quality of the tet on `v` at the current positions.
    #[inline]
    pub fn quality(&self, v: [u32; 4]) -> f64 {
        self.quality_at(v, &self.corners(v))
    }

    /// Quality of the tet on `v` with corners at `c`.
    #[inline]
    pub fn quality_at(&self, v: [u32; 4], c: &[P3; 4]) -> f64 {
        self.quality_above(v, c, f64::NEG_INFINITY)
    }

    /// [`LinMesh::quality`] when it is above `floor`, else some value ≤ `floor`.
    #[inline]
    pub fn quality_of_above(&self, v: [u32; 4], floor: f64) -> f64 {
        self.quality_above(v, &self.corners(v), floor)
    }

    /// [`LinMesh::quality_at`] when it is above `floor`, else some value ≤ `floor`.
    #[inline]
    pub fn quality_above(&self, v: [u32; 4], c: &[P3; 4], floor: f64) -> f64 {
        if self.sliver_mode {
            return self.sliver_score(v, c, floor);
        }
        self.eq.eval_above(self.bnd, &self.pts, v, c, floor)
    }

    /// The sliver passes' score of the tet on `v` with corners at `c`: for a tet the
    /// element quality scores positive, its smallest dihedral angle over the least the
    /// sliver census allows there ([`Boundary::tet_sliver_floor`]), at most 1, so that
    /// below 1 exactly where the census counts an unforced sliver; otherwise (an
    /// inverted, flat or P2-invalid tet) the element quality's score, ≤ 0. Every tet that
    /// is not an unforced sliver scores 1: the forced slivers next to needle triangles,
    /// far worse by the element quality, no longer block the moves that lift an unforced
    /// one beside them. The boundary edges in [`LinMesh::chorded`] are taken straight.
    /// When the score is ≤ `floor` the value may be any such one.
    pub fn sliver_score(&self, v: [u32; 4], c: &[P3; 4], floor: f64) -> f64 {
        let (q, lo) =
            self.eq
                .eval_and_min_dihedral(self.bnd, &self.pts, v, c, floor.min(0.0), |e| {
                    self.chorded.contains(&e)
                });
        if q <= 0.0 {
            return q;
        }
        (lo / self.bnd.tet_sliver_floor(v)).min(1.0)
    }

    /// Score tets by [`LinMesh::sliver_score`] (`on`) or by the element quality from now
    /// on; every cached quality is measured again.
    pub fn set_sliver_mode(&mut self, on: bool) {
        self.sliver_mode = on;
        // Smoothed to a standstill, or searched in vain, under the other measure is not
        // under this one.
        self.dirty.iter_mut().for_each(|d| *d = true);
        self.searched.clear();
        for i in 0..self.tets.len() {
            if self.alive(i as u32) {
                self.q[i] = self.quality(self.tets[i]);
            }
        }
    }

    /// Whether tet `t` is exempt from the minimum an operation must raise: in the sliver
    /// passes, a tet that is not valid as a P2 element however its interior mid nodes are
    /// placed (scored in [−1, −0.5]). The straightening after the high-order stage makes
    /// such tets valid. A vertex move may not make one worse, and the flips, contractions
    /// and splits leave them alone: counted in the minimum, they would let an operation
    /// that lifts one a little make unforced slivers, or block every move of their
    /// corners that lifts an unforced sliver beside them.
    #[inline]
    pub fn exempt(&self, t: u32) -> bool {
        let q = self.q[t as usize];
        self.sliver_mode && q < 0.0 && q > f64::NEG_INFINITY
    }

    /// Whether an edge split that replaces tets scoring `old` by tets scoring `new`
    /// makes more unforced slivers than it removes: in the sliver passes, more tets
    /// scoring below 1. Lifting the minimum alone let the passes split one sliver into
    /// several better ones, pass after pass. (Asked of the splits and cavity insertions
    /// only, and not where the slivers they replace are all stuck, see
    /// `insert::only_stuck_slivers`: refusing flips, contractions and vertex moves that
    /// make more left more slivers in the end.)
    pub fn more_unforced(
        &self,
        old: impl IntoIterator<Item = f64>,
        new: impl IntoIterator<Item = f64>,
    ) -> bool {
        let below = |q: &f64| *q < 1.0;
        self.sliver_mode
            && new.into_iter().filter(below).count() > old.into_iter().filter(below).count()
    }

    /// Whether tets are scored by [`LinMesh::sliver_score`].
    #[inline]
    pub fn sliver_mode(&self) -> bool {
        self.sliver_mode
    }

    /// In the sliver passes, whether the tet on corners `v` scoring `q` is an unforced
    /// sliver as the sliver census will count it (a corner dihedral angle below the
    /// tet's floor, [`Boundary::tet_sliver_floor`]): a score in (0, 1) says so; a score
    /// ≤ 0 (inverted, flat or not valid as a P2 element) leaves it to the corners'
    /// angles, since the straightening after the high-order stage makes a P2-invalid tet
    /// valid without moving a corner.
    pub fn unforced(&self, v: [u32; 4], q: f64) -> bool {
        q < 1.0
            && (q > 0.0 || {
                crate::geom::tet_quality::dihedral_extremes(&self.corners(v)).0
                    < self.bnd.tet_sliver_floor(v)
            })
    }

    /// The vertices sharing a tet with `v`, sorted.
    pub fn neighbours(&self, v: u32) -> Vec<u32> {
        let mut around: Vec<u32> = self.vt[v as usize]
            .iter()
            .flat_map(|&t| self.tets[t as usize])
            .filter(|&x| x != v)
            .collect();
        around.sort_unstable();
        around.dedup();
        around
    }

    /// True for a live tet slot.
    #[inline]
    pub fn alive(&self, t: u32) -> bool {
        self.tets[t as usize][0] != u32::MAX
    }

    /// Insert a tet with known quality; returns its slot.
    pub fn add(&mut self, v: [u32; 4], q: f64) -> u32 {
        self.clock += 1;
        let t = if let Some(t) = self.free.pop() {
            self.tets[t as usize] = v;
            self.q[t as usize] = q;
            t
        } else {
            self.tets.push(v);
            self.q.push(q);
            (self.tets.len() - 1) as u32
        };
        for &x in &v {
            self.vt[x as usize].push(t);
            self.dirty[x as usize] = true;
            self.changed[x as usize] = self.clock;
        }
        t
    }

    /// Delete tet `t`.
    pub fn remove(&mut self, t: u32) {
        self.clock += 1;
        let v = self.tets[t as usize];
        for &x in &v {
            self.dirty[x as usize] = true;
            self.changed[x as usize] = self.clock;
            let s = &mut self.vt[x as usize];
            if let Some(i) = s.iter().position(|&y| y == t) {
                s.swap_remove(i);
            }
        }
        self.tets[t as usize] = DEAD;
        self.q[t as usize] = f64::INFINITY;
        self.free.push(t);
    }

    /// Whether a sampled search for `v` failed since anything in its star last changed
    /// (corners, tets, or the score): it would fail again.
    pub fn search_futile(&self, v: u32) -> bool {
        let s = self.searched.get(v as usize).copied().unwrap_or(0);
        s != 0 && self.changed[v as usize] < s
    }

    /// Record that a sampled search failed to move `v`.
    pub fn search_failed(&mut self, v: u32) {
        if self.searched.len() <= v as usize {
            self.searched.resize(self.pts.len(), 0);
        }
        self.clock += 1;
        self.searched[v as usize] = self.clock;
    }

    /// Mark every corner of the star of `v` dirty (after `v` moved).
    pub fn touch_star(&mut self, v: u32) {
        self.clock += 1;
        for i in 0..self.vt[v as usize].len() {
            let t = self.vt[v as usize][i];
            for x in self.tets[t as usize] {
                self.dirty[x as usize] = true;
                self.changed[x as usize] = self.clock;
            }
        }
    }

    /// The live tets containing both `a` and `b`, appended to `out` (cleared first).
    pub fn edge_tets(&self, a: u32, b: u32, out: &mut Vec<u32>) {
        out.clear();
        for &t in &self.vt[a as usize] {
            if self.tets[t as usize].contains(&b) {
                out.push(t);
            }
        }
    }

    /// The tet other than `t` that has face `f`, if any.
    pub fn across(&self, t: u32, f: [u32; 3]) -> Option<u32> {
        self.vt[f[0] as usize].iter().copied().find(|&s| {
            s != t && {
                let x = &self.tets[s as usize];
                x.contains(&f[1]) && x.contains(&f[2])
            }
        })
    }

    /// The live tets and the points in use, compacted in slot order.
    pub fn into_parts(self) -> (Vec<P3>, Vec<[u32; 4]>) {
        let tets = self.tets.into_iter().filter(|t| t[0] != u32::MAX).collect();
        (self.pts, tets)
    }
}

/// The two corners of `t` other than `a` and `b`, ordered so that (a, b, u, v) is an even
/// permutation of `t` (so positive when `t` is).
#[inline]
pub(super) fn opposite_edge(t: [u32; 4], a: u32, b: u32) -> (u32, u32) {
    let ia = t.iter().position(|&x| x == a).unwrap_or(0);
    let ib = t.iter().position(|&x| x == b).unwrap_or(1);
    let mut rest = [0usize; 2];
    let mut k = 0;
    for i in 0..4 {
        if i != ia && i != ib {
            rest[k] = i;
            k += 1;
        }
    }
    let p = [ia, ib, rest[0], rest[1]];
    let mut inv = 0;
    for i in 0..4 {
        for j in i + 1..4 {
            if p[i] > p[j] {
                inv += 1;
            }
        }
    }
    if inv % 2 == 0 {
        (t[rest[0]], t[rest[1]])
    } else {
        (t[rest[1]], t[rest[0]])
    }
}

/// The face of `t` opposite corner `k`, ordered so that (f0, f1, f2, t[k]) is positive
/// when `t` is.
#[inline]
pub(super) fn face_opposite(t: [u32; 4], k: usize) -> [u32; 3] {
    match k {
        0 => [t[2], t[1], t[3]],
        1 => [t[0], t[2], t[3]],
        2 => [t[1], t[0], t[3]],
        _ => [t[0], t[1], t[2]],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::vec3::mid;

    fn parity(p: [u32; 4], t: [u32; 4]) -> bool {
        let idx = p.map(|x| t.iter().position(|&y| y == x).unwrap());
        let mut inv = 0;
        for i in 0..4 {
            for j in i + 1..4 {
                if idx[i] > idx[j] {
                    inv += 1;
                }
            }
        }
        inv % 2 == 0
    }

    /// The sliver score is 1 on a thin tet a needle at its corner forces (while the
    /// element quality calls it far worse than an interior sliver), below 1 on a sliver
    /// no needle forces, and is the element quality's on an inverted tet.
    #[test]
    fn the_sliver_score_is_below_one_on_unforced_slivers_only() {
        use crate::geom::predicates::orient3d;
        use crate::geom::tet_quality::dihedral_extremes;
        use crate::mesh::slivers::{smallest_angle_deg, SLIVER_DEG};
        // A needle triangle (smallest angle about 0.57 degrees) with its mid nodes at
        // the midpoints (straight), then interior points.
        let (a, b, c) = ([0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [10.0, 0.1, 0.0]);
        let mut pts = vec![a, b, c, mid(a, b), mid(b, c), mid(c, a)];
        let tris = [[0, 1, 2, 3, 4, 5]];
        let bnd = Boundary::new(6, &tris).with_sliver_floors(&pts, &tris);
        let needle = smallest_angle_deg([a, b, c]);
        assert!(needle < 1.0, "{needle}");
        assert_eq!(bnd.tet_sliver_floor([0, 6, 7, 8]), needle / 2.0);
        assert_eq!(bnd.tet_sliver_floor([1, 6, 7, 8]), needle / 2.0);
        assert_eq!(bnd.tet_sliver_floor([6, 7, 8, 9]), SLIVER_DEG);
        // 6: above the needle; 7..10: an interior sliver (a square's corners, one lifted
        // a little off their plane).
        pts.push([7.0, 0.05, 0.2]);
        pts.extend([
            [20.0, 0.0, 0.0],
            [21.0, 0.0, 0.0],
            [21.0, 1.0, 0.0],
            [20.0, 1.0, 0.15],
        ]);
        let positive = |mut t: [u32; 4]| {
            let x = t.map(|v| pts[v as usize]);
            if orient3d(x[0], x[1], x[2], x[3]) < 0 {
                t.swap(2, 3);
            }
            t
        };
        let forced = positive([0, 1, 2, 6]);
        let interior = positive([7, 8, 9, 10]);
        let mut inverted = interior;
        inverted.swap(0, 1);
        let m = LinMesh::new(pts.clone(), vec![forced, interior], &bnd, ElementQuality);
        let dmin = |t: [u32; 4]| dihedral_extremes(&m.corners(t)).0;
        let sliver = |t: [u32; 4]| m.sliver_score(t, &m.corners(t), f64::NEG_INFINITY);
        // The forced one: below 10 degrees but not below half the needle's angle.
        assert!(
            (needle / 2.0..SLIVER_DEG).contains(&dmin(forced)),
            "{}",
            dmin(forced)
        );
        assert!(
            (0.0..SLIVER_DEG).contains(&dmin(interior)),
            "{}",
            dmin(interior)
        );
        assert!(m.quality(forced) < m.quality(interior));
        assert_eq!(sliver(forced), 1.0);
        assert_eq!(sliver(interior), dmin(interior) / SLIVER_DEG);
        assert_eq!(sliver(inverted), f64::NEG_INFINITY);
    }

    #[test]
    fn orderings_are_even_permutations() {
        let t = [10, 11, 12, 13];
        for k in 0..4 {
            let f = face_opposite(t, k);
            assert!(parity([f[0], f[1], f[2], t[k]], t), "face {k}");
        }
        for a in 0..4 {
            for b in 0..4 {
                if a != b {
                    let (u, v) = opposite_edge(t, t[a], t[b]);
                    assert!(parity([t[a], t[b], u, v], t));
                }
            }
        }
    }
}
