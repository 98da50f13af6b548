//! Incremental Delaunay tetrahedralization (Bowyer–Watson) with exact predicates, the
//! kernel of the constrained fill that closes what the advancing front cannot.
//!
//! Points are inserted one at a time into a triangulation of a large enclosing tetrahedron:
//! the tet containing the point is found by a visibility walk (which terminates on a
//! Delaunay triangulation), the cavity of tets whose circumsphere strictly contains the
//! point is removed, and its boundary is connected to the point. Every decision is an
//! exact orient3d or insphere; the strict insphere test keeps every new tet's volume
//! positive even on cospherical input (the triangulation is then one of the Delaunay
//! ones). Neighbour links are kept so that later stages (boundary recovery by flips) can
//! work locally.

use super::predicates::orient3d;
use super::vec3::P3;
use rustc_hash::{FxHashMap as HashMap, FxHashSet as HashSet};
use std::cell::RefCell;

/// No tet (a hull face's outer neighbour).
pub(crate) const NONE: u32 = u32::MAX;

/// Local faces of a tet: face `k` is opposite vertex `k`, ordered so that its normal
/// (right hand) points out of a positively oriented tet.
pub(crate) const FACES: [[usize; 3]; 4] = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];

/// Insphere for a positively oriented tet (`orient3d(a, b, c, d) > 0`): > 0 when `e` is
/// strictly inside its circumsphere, 0 on it, < 0 outside.
pub(crate) fn insphere(a: P3, b: P3, c: P3, d: P3, e: P3) -> i32 {
    // Shewchuk's insphere assumes his orientation, the opposite of ours: negate.
    let v = robust::insphere(c3(a), c3(b), c3(c), c3(d), c3(e));
    if v < 0.0 {
        1
    } else if v > 0.0 {
        -1
    } else {
        0
    }
}

fn c3(p: P3) -> robust::Coord3D<f64> {
    robust::Coord3D {
        x: p[0],
        y: p[1],
        z: p[2],
    }
}

/// Relative 6 x volume (over the input's magnitude times the longest edge squared) above
/// which a tet is clearly not flat by construction ([`Delaunay::clearly_solid`]): about
/// a million units of roundoff.
const SOLID_MARGIN: f64 = 1e-10;

/// A Delaunay tetrahedralization of `pts` (the first `n` points, the input) plus four
/// enclosing points (ids `n..n + 4`).
#[derive(Clone)]
pub(crate) struct Delaunay {
    pub pts: Vec<P3>,
    /// Number of input points (the enclosing ones follow).
    pub n: usize,
    pub tets: Vec<[u32; 4]>,
    /// `adj[t][k]`: the tet across face `k` (opposite vertex `k`) of tet `t`, or [`NONE`].
    pub adj: Vec<[u32; 4]>,
    pub alive: Vec<bool>,
    /// A live tet containing each point (kept by every change; [`NONE`] before the point
    /// is in a tet).
    vt: Vec<u32>,
    /// Points added on an input edge: the edge (sorted ids).
    pub on_line: HashMap<u32, [u32; 2]>,
    /// Points added inside an input face: the face (sorted ids).
    pub on_face: HashMap<u32, [u32; 3]>,
    /// Input edge (sorted) -> the input faces (sorted) using it.
    pub edge_faces: HashMap<[u32; 2], Vec<[u32; 3]>>,
    /// Edges (sorted ids) that no flip may remove: recovered constraint edges.
    pub fixed_edges: HashSet<[u32; 2]>,
    /// Faces (sorted ids) that no flip may remove: recovered constraint faces.
    pub fixed_faces: HashSet<[u32; 3]>,
    last: u32,
    /// The largest absolute coordinate of the input points: the scale of the rounding
    /// of every point added on an input edge or face ([`Delaunay::clearly_solid`]).
    magnitude: f64,
    /// The tets [`Delaunay::walk_around`] has reached, reused from walk to walk (a hash
    /// set per walk cost more than the walk itself).
    walked: RefCell<Stamps>,
    /// Whether [`Delaunay::valid_new`] also refuses numerically flat tets (6 x volume
    /// below 1e-12 of the longest edge cubed): the constrained fill's recovery then
    /// makes none (`cdt_fill::Split::NoFlatTets`).
    pub refuse_flat: bool,
    /// The segment [`Delaunay::recover_edge_nm`] is bringing in: no flip made meanwhile
    /// may create a face or edge that it crosses ([`Delaunay::crosses_guard`]).
    guard: Option<[u32; 2]>,
}

/// Per-tet marks, each walk's with a new stamp: clearing them is one increment.
#[derive(Clone, Default)]
pub(crate) struct Stamps {
    stamp: u32,
    of: Vec<u32>,
}

impl Stamps {
    /// Start an empty set of tets with ids below `n`: a new stamp, so that the marks of
    /// the last set no longer count.
    pub(crate) fn clear_for(&mut self, n: usize) {
        if self.of.len() < n {
            self.of.resize(n, 0);
        }
        self.stamp = self.stamp.wrapping_add(1);
        if self.stamp == 0 {
            self.of.fill(0);
            self.stamp = 1;
        }
    }

    /// Mark tet `t` (below the `n` of [`Stamps::clear_for`]); true when it was not.
    pub(crate) fn insert(&mut self, t: u32) -> bool {
        let m = &mut self.of[t as usize];
        let new = *m != self.stamp;
        *m = self.stamp;
        new
    }

    /// Whether tet `t` is marked.
    pub(crate) fn contains(&self, t: u32) -> bool {
        self.of.get(t as usize) == Some(&self.stamp)
    }
}

impl Delaunay {
    /// The Delaunay tetrahedralization of `pts` (inserted in the given order; duplicates
    /// are skipped: they never appear in a tet).
    pub(crate) fn new(pts: &[P3]) -> Delaunay {
        let n = pts.len();
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in pts {
            for d in 0..3 {
                lo[d] = lo[d].min(p[d]);
                hi[d] = hi[d].max(p[d]);
            }
        }
        if n == 0 {
            lo = [0.0; 3];
            hi = [1.0; 3];
        }
        let c = [0, 1, 2].map(|d| 0.5 * (lo[d] + hi[d]));
        let r = (0..3).map(|d| hi[d] - lo[d]).fold(1e-300, f64::max) * 1e3;
        // A regular-ish tetrahedron far larger than the box (exact predicates make the
        // distance harmless).
        let far = [
            [c[0] + r, c[1] + r, c[2] + r],
            [c[0] + r, c[1] - r, c[2] - r],
            [c[0] - r, c[1] + r, c[2] - r],
            [c[0] - r, c[1] - r, c[2] + r],
        ];
        let mut all = pts.to_vec();
        all.extend_from_slice(&far);
        let s = n as u32;
        let mut t = [s, s + 1, s + 2, s + 3];
        if orient3d(
            all[t[0] as usize],
            all[t[1] as usize],
            all[t[2] as usize],
            all[t[3] as usize],
        ) < 0
        {
            t.swap(2, 3);
        }
        let mut vt = vec![NONE; all.len()];
        for &v in &t {
            vt[v as usize] = 0;
        }
        let mut dt = Delaunay {
            pts: all,
            n,
            tets: vec![t],
            adj: vec![[NONE; 4]],
            alive: vec![true],
            vt,
            on_line: HashMap::default(),
            on_face: HashMap::default(),
            edge_faces: HashMap::default(),
            fixed_edges: HashSet::default(),
            fixed_faces: HashSet::default(),
            last: 0,
            magnitude: pts.iter().flatten().fold(0.0, |m, x| m.max(x.abs())),
            walked: RefCell::default(),
            refuse_flat: false,
            guard: None,
        };
        for i in 0..n as u32 {
            dt.insert(i);
        }
        dt
    }

    pub(crate) fn p(&self, v: u32) -> P3 {
        self.pts[v as usize]
    }

    /// The tet containing point `q` (closed), by a visibility walk from the last tet made.
    fn locate(&self, q: P3) -> u32 {
        self.locate_from(self.last, q)
    }

    /// [`Delaunay::locate`] walking from tet `start` (in a region that is not convex, the
    /// walk can stop at the boundary: start near `q`).
    pub(crate) fn locate_from(&self, start: u32, q: P3) -> u32 {
        let mut t = start;
        if !self.alive[t as usize] {
            t = self.alive.iter().position(|&a| a).unwrap_or(0) as u32;
        }
        // Bounded for safety; a walk in a Delaunay triangulation terminates, but one in a
        // triangulation flips and insertions have made non-Delaunay can cycle.
        let bound = 4 * self.tets.len() + 16;
        // Past WALK_WATCH steps, each tet visited with its step: the next tet depends
        // only on the current one, so a walk back at a tet cycles until the bound.
        // The scan below then starts at once (the whole fill's lifts on OpenSCAD's
        // example020 walked 69 million steps, 30 cycles), and where it finds nothing,
        // the answer is the tet the walk would have been at by the bound.
        let mut seen: HashMap<u32, usize> = HashMap::default();
        let mut path: Vec<u32> = Vec::new();
        for step in 0..bound {
            if step >= WALK_WATCH {
                if let Some(&j) = seen.get(&t) {
                    // Steps j.. repeat with period step - j; path holds WALK_WATCH...
                    t = path[j + (bound - j) % (step - j) - WALK_WATCH];
                    break;
                }
                seen.insert(t, step);
                path.push(t);
            }
            let tv = self.tets[t as usize];
            let mut moved = false;
            for (k, f) in FACES.iter().enumerate() {
                let (a, b, c) = (self.p(tv[f[0]]), self.p(tv[f[1]]), self.p(tv[f[2]]));
                // q strictly outside face k (on the side its outward normal points to).
                if orient3d(a, b, c, q) > 0 {
                    let nb = self.adj[t as usize][k];
                    if nb != NONE {
                        t = nb;
                        moved = true;
                        break;
                    }
                }
            }
            if !moved {
                return t;
            }
        }
        // A cycling walk: a scan.
        (0..self.tets.len() as u32)
            .find(|&t| {
                self.alive[t as usize] && {
                    let tv = self.tets[t as usize];
                    FACES.iter().all(|f| {
                        orient3d(self.p(tv[f[0]]), self.p(tv[f[1]]), self.p(tv[f[2]]), q) <= 0
                    })
                }
            })
            .unwrap_or(t)
    }

    fn in_sphere(&self, t: u32, q: P3) -> i32 {
        let v = self.tets[t as usize];
        insphere(self.p(v[0]), self.p(v[1]), self.p(v[2]), self.p(v[3]), q)
    }

    /// Insert input point `i`. False if it coincides with a point already there.
    pub(crate) fn insert(&mut self, i: u32) -> bool {
        let q = self.p(i);
        let start = self.locate(q);
        if self.tets[start as usize].iter().any(|&v| self.p(v) == q) {
            return false;
        }
        // The cavity: tets whose circumsphere strictly contains q, grown from `start`
        // (which contains q, so its sphere does unless q is on it: then it is still
        // removed, as q lies in it).
        let mut cavity = vec![start];
        let mut in_cav: HashMap<u32, ()> = HashMap::default();
        in_cav.insert(start, ());
        let mut k = 0;
        while k < cavity.len() {
            let t = cavity[k];
            k += 1;
            for j in 0..4 {
                let nb = self.adj[t as usize][j];
                if nb != NONE && !in_cav.contains_key(&nb) && self.in_sphere(nb, q) > 0 {
                    in_cav.insert(nb, ());
                    cavity.push(nb);
                }
            }
        }
        // The cavity's boundary faces joined to q: each face's normal points out of its
        // tet and q is inside the cavity, so (f0, f2, f1, q) is positive.
        let mut new = Vec::new();
        for &t in &cavity {
            let tv = self.tets[t as usize];
            for (j, f) in FACES.iter().enumerate() {
                let nb = self.adj[t as usize][j];
                if nb == NONE || !in_cav.contains_key(&nb) {
                    new.push([tv[f[0]], tv[f[2]], tv[f[1]], i]);
                }
            }
        }
        self.replace(&cavity, &new);
        true
    }

    /// Live tets whose four vertices are all input points.
    #[cfg(test)]
    pub(crate) fn interior_tets(&self) -> impl Iterator<Item = [u32; 4]> + '_ {
        let n = self.n as u32;
        (0..self.tets.len())
            .filter(move |&t| self.alive[t] && self.tets[t].iter().all(|&v| v < n))
            .map(move |t| self.tets[t])
    }
}

pub(crate) fn sorted2(a: u32, b: u32) -> [u32; 2] {
    if a < b {
        [a, b]
    } else {
        [b, a]
    }
}

/// Steps a point location walk takes before it watches for a cycle
/// ([`Delaunay::locate_from`]); walks are a few dozen steps.
const WALK_WATCH: usize = 64;

pub(crate) fn sorted3(mut f: [u32; 3]) -> [u32; 3] {
    f.sort_unstable();
    f
}

impl Delaunay {
    /// Replace live tets `old` by tets `new` (each positively oriented) covering the same
    /// region, relinking neighbours. Returns the new tets' ids. A new face that matches
    /// no outer face of `old` gets no neighbour (the fill's boundary changes that way when
    /// it moves a Steiner point off a constraint face).
    pub(crate) fn replace(&mut self, old: &[u32], new: &[[u32; 4]]) -> Vec<u32> {
        let mut outer: HashMap<[u32; 3], (u32, usize)> = HashMap::default();
        let olds: HashSet<u32> = old.iter().copied().collect();
        for &t in old {
            let v = self.tets[t as usize];
            for (k, f) in FACES.iter().enumerate() {
                let nb = self.adj[t as usize][k];
                if nb != NONE && olds.contains(&nb) {
                    continue;
                }
                let key = sorted3(f.map(|j| v[j]));
                let back = if nb == NONE {
                    usize::MAX
                } else {
                    (0..4)
                        .find(|&m| self.adj[nb as usize][m] == t)
                        .unwrap_or(usize::MAX)
                };
                outer.insert(key, (nb, back));
            }
            self.alive[t as usize] = false;
        }
        let mut inner: HashMap<[u32; 3], (u32, usize)> = HashMap::default();
        let mut ids = Vec::with_capacity(new.len());
        for &v in new {
            let nt = self.tets.len() as u32;
            self.tets.push(v);
            self.adj.push([NONE; 4]);
            self.alive.push(true);
            for (k, f) in FACES.iter().enumerate() {
                let key = sorted3(f.map(|j| v[j]));
                if let Some((nb, back)) = outer.remove(&key) {
                    self.adj[nt as usize][k] = nb;
                    if nb != NONE && back != usize::MAX {
                        self.adj[nb as usize][back] = nt;
                    }
                } else if let Some((ot, ok)) = inner.remove(&key) {
                    self.adj[nt as usize][k] = ot;
                    self.adj[ot as usize][ok] = nt;
                } else {
                    inner.insert(key, (nt, k));
                }
            }
            ids.push(nt);
        }
        for &t in &ids {
            for v in self.tets[t as usize] {
                self.vt[v as usize] = t;
            }
        }
        self.last = *ids.last().unwrap_or(&self.last);
        ids
    }

    /// A tet a change may create: positive, and not flat by construction: its points
    /// (an added point standing for the input edge or face it was put on) all on one
    /// plane of input points, exactly, so that only rounding makes it positive.
    pub(crate) fn valid_new(&self, t: [u32; 4]) -> bool {
        if self.refuse_flat && super::tet_quality::numerically_flat(&t.map(|v| self.p(v))) {
            return false;
        }
        self.positive(t)
            && (self.clearly_solid(t) || !self.flat_by_construction(t))
            && (self.clearly_solid(t)
                || !FACES
                    .iter()
                    .any(|f| self.collinear_by_construction(f.map(|j| t[j]))))
    }

    /// Whether tet `t` is far too thick for rounding to make it look so: then neither it
    /// nor a face of it is flat by construction, and the exact tests (most of an
    /// insertion's time where many added points crowd a segment) are skipped. An added
    /// point is computed from input points (a point on a segment, interpolated; a
    /// segment's crossing with a plane), within a small multiple of the unit roundoff of
    /// [`Delaunay::magnitude`] of where it stands for; a tet whose points all stand on one
    /// plane of input points, or a face on one line, so has 6 x volume at most a few
    /// units of roundoff times the magnitude times its longest edge squared.
    /// [`SOLID_MARGIN`] is a million times that.
    fn clearly_solid(&self, t: [u32; 4]) -> bool {
        let (det, margin) = self.det_and_margin(t);
        det > margin
    }

    /// [`Delaunay::clearly_solid`] for a tet of either orientation: 6 x volume that far
    /// from 0 on either side, so not flat by construction either.
    fn clearly_thick(&self, t: [u32; 4]) -> bool {
        let (det, margin) = self.det_and_margin(t);
        det.abs() > margin
    }

    /// Tet `t`'s 6 x signed volume and the least [`Delaunay::clearly_solid`] asks of it.
    fn det_and_margin(&self, t: [u32; 4]) -> (f64, f64) {
        let p = t.map(|v| self.p(v));
        let l2 = (0..4)
            .flat_map(|i| (i + 1..4).map(move |j| (i, j)))
            .map(|(i, j)| super::vec3::dist2(p[i], p[j]))
            .fold(0.0, f64::max);
        // A face's area is at least 6V / (2 x its opposite height) >= 6V / (2 sqrt(l2)).
        let det = super::vec3::tet_det(p[0], p[1], p[2], p[3]);
        (det, 2.0 * SOLID_MARGIN * self.magnitude.max(l2.sqrt()) * l2)
    }

    /// The input points an added point stands for (itself for an input point), for
    /// every point of `vs`, sorted; and whether any of `vs` is an added point.
    fn supports(&self, vs: &[u32]) -> (Vec<u32>, bool) {
        // Only points after the input and the four far points can be added ones: most
        // tets tested have none, and skip the lookups.
        if vs.iter().all(|&v| (v as usize) < self.n + 4) {
            return (Vec::new(), false);
        }
        let mut sup: Vec<u32> = Vec::with_capacity(3 * vs.len());
        let mut added = false;
        for &v in vs {
            if let Some(e) = self.on_line.get(&v) {
                sup.extend_from_slice(e);
                added = true;
            } else if let Some(f) = self.on_face.get(&v) {
                sup.extend_from_slice(f);
                added = true;
            } else {
                sup.push(v);
            }
        }
        sup.sort_unstable();
        sup.dedup();
        (sup, added)
    }

    /// Three points on one line by construction (added points on one input edge with
    /// its ends), whatever their rounded positions say.
    pub(crate) fn collinear_by_construction(&self, t: [u32; 3]) -> bool {
        let (sup, added) = self.supports(&t);
        if !added {
            return false;
        }
        let p: Vec<P3> = sup.iter().map(|&v| self.p(v)).collect();
        (1..p.len())
            .all(|i| (i + 1..p.len()).all(|j| super::predicates::collinear(p[0], p[i], p[j])))
    }

    fn flat_by_construction(&self, t: [u32; 4]) -> bool {
        let (sup, added) = self.supports(&t);
        if !added {
            return false;
        }
        let p: Vec<P3> = sup.iter().map(|&v| self.p(v)).collect();
        // Three points not on a line, then every other point on their plane.
        let base = (1..p.len()).find_map(|i| {
            (i + 1..p.len())
                .find(|&j| !super::predicates::collinear(p[0], p[i], p[j]))
                .map(|j| (i, j))
        });
        let Some((i, j)) = base else {
            return true; // all on one line
        };
        p.iter().all(|&x| orient3d(p[0], p[i], p[j], x) == 0)
    }

    pub(crate) fn positive(&self, t: [u32; 4]) -> bool {
        orient3d(self.p(t[0]), self.p(t[1]), self.p(t[2]), self.p(t[3])) > 0
    }

    /// 2-3 flip of tet `t` and its neighbour across face `k`: the edge between their
    /// apexes replaces the face. False (nothing changed) unless the union is convex there.
    pub(crate) fn flip23(&mut self, t: u32, k: usize) -> bool {
        let u = self.adj[t as usize][k];
        if u == NONE {
            return false;
        }
        let tv = self.tets[t as usize];
        if self.fixed_faces.contains(&sorted3(FACES[k].map(|j| tv[j]))) {
            return false;
        }
        let a = tv[k];
        let f = FACES[k].map(|j| tv[j]); // outward from t: (p, q, r)
        let uv = self.tets[u as usize];
        let Some(&b) = uv.iter().find(|x| !f.contains(x)) else {
            return false;
        };
        // New tets (p, q, a, b)... each (edge of f, a, b) with positive orientation.
        let new = [[f[0], f[1], a, b], [f[1], f[2], a, b], [f[2], f[0], a, b]];
        if !new.iter().all(|&n| self.valid_new(n)) {
            return false;
        }
        if f.iter().any(|&c| self.crosses_guard([a, b, c], &[[a, b]])) {
            return false;
        }
        self.replace(&[t, u], &new);
        true
    }

    /// 3-2 flip of the edge (a, b) when exactly three live tets share it: the triangle of
    /// their other vertices replaces the edge. False unless that is valid.
    pub(crate) fn flip32(&mut self, a: u32, b: u32, around: &[u32]) -> bool {
        if around.len() != 3 || self.fixed_edges.contains(&sorted2(a, b)) {
            return false;
        }
        let mut others: Vec<u32> = Vec::new();
        for &t in around {
            for &x in &self.tets[t as usize] {
                if x != a && x != b && !others.contains(&x) {
                    others.push(x);
                }
            }
        }
        if others.len() != 3 {
            return false;
        }
        let (p, q, r) = (others[0], others[1], others[2]);
        let mut t1 = [p, q, r, a];
        let mut t2 = [p, q, r, b];
        if !self.positive(t1) {
            t1.swap(0, 1);
        }
        if !self.positive(t2) {
            t2.swap(0, 1);
        }
        if !self.valid_new(t1) || !self.valid_new(t2) || self.crosses_guard([p, q, r], &[]) {
            return false;
        }
        // a and b on opposite sides of (p, q, r) (else the two tets overlap).
        if orient3d(self.p(p), self.p(q), self.p(r), self.p(a))
            == orient3d(self.p(p), self.p(q), self.p(r), self.p(b))
        {
            return false;
        }
        self.replace(around, &[t1, t2]);
        true
    }

    /// The ring of edge (x, y): the other vertices of the `around` tets (those sharing
    /// the edge), in order around it, each consecutive pair (and the last with the first)
    /// the other edge of one tet. None when the tets do not close up into one ring.
    pub(crate) fn edge_ring(&self, x: u32, y: u32, around: &[u32]) -> Option<Vec<u32>> {
        let n = around.len();
        // Each tet contributes the ring edge of its two other vertices; chain them.
        let mut links: Vec<[u32; 2]> = Vec::with_capacity(n);
        for &t in around {
            let o: Vec<u32> = self.tets[t as usize]
                .iter()
                .copied()
                .filter(|&v| v != x && v != y)
                .collect();
            if o.len() != 2 {
                return None;
            }
            links.push([o[0], o[1]]);
        }
        let mut ring = vec![links.first()?[0], links[0][1]];
        let mut used = vec![false; n];
        used[0] = true;
        while ring.len() < n {
            let last = *ring.last()?;
            let j = (0..n).find(|&j| !used[j] && links[j].contains(&last))?;
            used[j] = true;
            let next = if links[j][0] == last {
                links[j][1]
            } else {
                links[j][0]
            };
            ring.push(next);
        }
        // The ring closes back to its start.
        let j = (0..n).find(|&j| !used[j])?;
        (links[j].contains(&ring[0]) && links[j].contains(&ring[n - 1])).then_some(ring)
    }

    /// The tet of edge (x, y)'s star holding ring vertex r, and its local index of the
    /// vertex opposite face (x, y, r).
    fn star_face(&self, around: &[u32], x: u32, y: u32, r: u32) -> Option<(u32, usize)> {
        around.iter().find_map(|&t| {
            let tv = self.tets[t as usize];
            if !self.alive[t as usize] || !tv.contains(&r) {
                return None;
            }
            (0..4)
                .find(|&k| ![x, y, r].contains(&tv[k]))
                .map(|k| (t, k))
        })
    }

    /// The edges of face k of tet t (other than `skip`) whose tet in the face's 2-3 flip
    /// would not be valid ([`Delaunay::valid_new`]): the reflex edges that block the flip.
    fn blocking_edges(&self, t: u32, k: usize, skip: [u32; 2]) -> Vec<[u32; 2]> {
        let tv = self.tets[t as usize];
        let u = self.adj[t as usize][k];
        if u == NONE {
            return Vec::new();
        }
        let f = FACES[k].map(|j| tv[j]);
        let Some(&b) = self.tets[u as usize].iter().find(|v| !f.contains(v)) else {
            return Vec::new();
        };
        (0..3)
            .map(|i| [f[i], f[(i + 1) % 3]])
            .filter(|e| sorted2(e[0], e[1]) != sorted2(skip[0], skip[1]))
            .filter(|e| !self.valid_new([e[0], e[1], tv[k], b]))
            .collect()
    }

    /// Whether the guarded segment ([`Delaunay::guard`]) crosses face `f` through its
    /// interior, or one of its edges listed in `new` through the edge's interior: a face
    /// and edges a flip would create. A segment in the face's plane is not judged.
    fn crosses_guard(&self, f: [u32; 3], new: &[[u32; 2]]) -> bool {
        let Some([s, t]) = self.guard else {
            return false;
        };
        let [p, q, r] = f.map(|v| self.p(v));
        let (ps, pt) = (self.p(s), self.p(t));
        if orient3d(p, q, r, ps) == orient3d(p, q, r, pt) {
            return false; // one side, or in the plane
        }
        // The segment meets the plane at one point: where, relative to the edges.
        let o = [
            orient3d(ps, pt, p, q),
            orient3d(ps, pt, q, r),
            orient3d(ps, pt, r, p),
        ];
        if o.contains(&1) && o.contains(&-1) {
            return false;
        }
        match o.iter().filter(|&&x| x == 0).count() {
            0 => true,
            1 => {
                let k = o.iter().position(|&x| x == 0).unwrap_or(0);
                let e = sorted2(f[k], f[(k + 1) % 3]);
                new.iter().any(|n| sorted2(n[0], n[1]) == e)
            }
            _ => false, // through a vertex
        }
    }

    /// Whether the fan from `ring[apex]` that [`Delaunay::remove_edge`] would make for edge
    /// (x, y) has a face the guarded segment crosses ([`Delaunay::crosses_guard`]): a
    /// fan triangle, or a diagonal's triangle with x or y; the diagonals from the apex
    /// are new edges, the ring's edges are not.
    fn fan_crosses_guard(&self, ring: &[u32], apex: usize, x: u32, y: u32) -> bool {
        let n = ring.len();
        let a = ring[apex];
        (1..n - 1).any(|k| {
            let (b, c) = (ring[(apex + k) % n], ring[(apex + k + 1) % n]);
            let (ab_new, ac_new) = (k > 1, k < n - 2);
            let diag = match (ab_new, ac_new) {
                (true, true) => &[[a, b], [a, c]][..],
                (true, false) => &[[a, b]][..],
                (false, true) => &[[a, c]][..],
                (false, false) => &[][..],
            };
            self.crosses_guard([a, b, c], diag)
                || (ab_new
                    && [x, y]
                        .iter()
                        .any(|&z| self.crosses_guard([a, b, z], &[[a, b]])))
        })
    }

    /// Remove edge (x, y) by a sequence of flips (after Si's flipnm): 3-2 when three tets
    /// share it; else shrink its star by 2-3 flips of its faces; where those are blocked
    /// by reflex link edges, remove those first, `level` levels deep. `anc` holds the
    /// stars of the edges being removed above this one: no flip here touches their tets
    /// but the two this edge's star shares with its parent's. True when the edge is gone.
    pub(crate) fn flipnm(
        &mut self,
        x: u32,
        y: u32,
        level: u32,
        budget: &mut usize,
        anc: &mut Vec<u32>,
    ) -> bool {
        if self.fixed_edges.contains(&sorted2(x, y)) {
            return false;
        }
        let base = anc.len();
        let r = 'star: loop {
            anc.truncate(base);
            if *budget == 0 {
                break false;
            }
            *budget -= 1;
            let around = self.around_edge(x, y);
            if around.is_empty() {
                break true;
            }
            if around.iter().filter(|t| anc[..base].contains(t)).count() > 2 {
                break false;
            }
            if self.flip32(x, y, &around) || self.remove_edge(x, y, &around) {
                break true;
            }
            let Some(ring) = self.edge_ring(x, y, &around) else {
                break false;
            };
            if ring.len() > 3 {
                for &r in &ring {
                    if let Some((t, k)) = self.star_face(&around, x, y, r) {
                        let u = self.adj[t as usize][k];
                        if anc[..base].contains(&t) || anc[..base].contains(&u) {
                            continue;
                        }
                        if self.flip23(t, k) {
                            continue 'star;
                        }
                    }
                }
            }
            if level == 0 {
                break false;
            }
            anc.extend_from_slice(&around);
            for &r in &ring {
                let Some((t, k)) = self.star_face(&around, x, y, r) else {
                    continue;
                };
                if let Some(e) = self.blocking_edges(t, k, [x, y]).first() {
                    if self.flipnm(e[0], e[1], level - 1, budget, anc) {
                        continue 'star;
                    }
                }
            }
            break false;
        };
        anc.truncate(base);
        r
    }

    /// Recover edge (a, b) by flips at link level `level` (see [`Delaunay::flipnm`]): the
    /// face it crosses first from a is 2-3 flipped, or the reflex edge that blocks that
    /// flip removed; stuck there, the same from b; stuck at both ends, any face it
    /// crosses further in. `budget` bounds the [`Delaunay::flipnm`] calls. True when the
    /// edge is there (the flips made on the way are kept either way). Meanwhile no flip
    /// but that of a crossed face itself makes a face or edge the segment crosses
    /// ([`Delaunay::crosses_guard`], TetGen's flip eligibility check): each flip from an
    /// end takes a crossing away and none adds one, so the flips cannot undo each other
    /// (without that check, most of the search went round in circles until its budget was
    /// spent).
    pub(crate) fn recover_edge_nm(
        &mut self,
        a0: u32,
        b0: u32,
        level: u32,
        budget: &mut usize,
    ) -> bool {
        self.guard = Some([a0, b0]);
        let r = self.recover_edge_guarded(a0, b0, level, budget);
        self.guard = None;
        r
    }

    /// [`Delaunay::recover_edge_nm`] with the guard set.
    fn recover_edge_guarded(&mut self, a0: u32, b0: u32, level: u32, budget: &mut usize) -> bool {
        let mut stuck_from = [false; 2];
        let (mut a, mut b) = (a0, b0);
        loop {
            if stuck_from[0] && stuck_from[1] {
                // Both ends stuck: any face the segment crosses further in.
                let crossed = self.crossed_faces(a0, b0);
                let mut moved = false;
                for (t, k) in crossed {
                    if self.alive[t as usize] && self.clear_face(t, k, [a0, b0], level, budget) {
                        moved = true;
                        break;
                    }
                }
                if !moved || *budget == 0 {
                    return false;
                }
                stuck_from = [false; 2];
                continue;
            }
            if self.has_edge(a, b) {
                return true;
            }
            if *budget == 0 {
                return false;
            }
            let Some((t, k)) = self.leaving(a, b) else {
                stuck_from[(a != a0) as usize] = true;
                std::mem::swap(&mut a, &mut b);
                continue;
            };
            if !self.clear_face(t, k, [a, b], level, budget) {
                stuck_from[(a != a0) as usize] = true;
                std::mem::swap(&mut a, &mut b);
                continue;
            }
            stuck_from = [false; 2];
        }
    }

    /// Take face k of tet t out of segment `seg`'s way: a 2-3 flip, else [`Delaunay::flipnm`]
    /// on the reflex edges that block it (on each of its edges where none is reflex).
    fn clear_face(
        &mut self,
        t: u32,
        k: usize,
        seg: [u32; 2],
        level: u32,
        budget: &mut usize,
    ) -> bool {
        // The crossed face itself may go whatever its new faces meet (as TetGen's
        // removefacebyflips).
        let guard = self.guard.take();
        let flipped = self.flip23(t, k);
        self.guard = guard;
        if flipped {
            return true;
        }
        let mut blocked = self.blocking_edges(t, k, seg);
        if blocked.is_empty() {
            let f = FACES[k].map(|j| self.tets[t as usize][j]);
            blocked = (0..3).map(|i| [f[i], f[(i + 1) % 3]]).collect();
        }
        blocked
            .into_iter()
            .any(|e| self.flipnm(e[0], e[1], level, budget, &mut Vec::new()))
    }

    /// Edge removal (n-to-2n-4 flip): replace the `around` tets sharing edge (x, y) by
    /// tets on a fan triangulation of their ring of other vertices, joined to x and to y,
    /// trying a fan from each ring vertex. False (nothing changed) if none is valid.
    pub(crate) fn remove_edge(&mut self, x: u32, y: u32, around: &[u32]) -> bool {
        let n = around.len();
        if !(3..=10).contains(&n) || self.fixed_edges.contains(&sorted2(x, y)) {
            return false;
        }
        let Some(ring) = self.edge_ring(x, y, around) else {
            return false;
        };
        'fans: for apex in 0..n {
            let mut new = Vec::with_capacity(2 * (n - 2));
            for k in 1..n - 1 {
                let a = ring[apex];
                let b = ring[(apex + k) % n];
                let c = ring[(apex + k + 1) % n];
                // x and y on opposite sides of each fan triangle: the cheap test first,
                // before the construction lookups of `valid_new` (edge recovery on CAD
                // parts spends most of its time here).
                let (pa, pb, pc) = (self.p(a), self.p(b), self.p(c));
                if orient3d(pa, pb, pc, self.p(x)) != -orient3d(pa, pb, pc, self.p(y)) {
                    continue 'fans;
                }
                for top in [x, y] {
                    let mut t = [a, b, c, top];
                    if !self.positive(t) {
                        t.swap(0, 1);
                    }
                    if !self.valid_new(t) {
                        continue 'fans;
                    }
                    new.push(t);
                }
            }
            if self.guard.is_some() && self.fan_crosses_guard(&ring, apex, x, y) {
                continue 'fans;
            }
            // Positive tets with the old tets' boundary tile their region exactly (a fan
            // triangle turned against the others would make an overlap; a volume
            // comparison misses one between nearly flat tets).
            let old: Vec<[u32; 4]> = around.iter().map(|&t| self.tets[t as usize]).collect();
            if same_boundary(&old, &new) {
                self.replace(around, &new);
                return true;
            }
        }
        false
    }

    /// Live tets containing vertex `v`: a walk across the faces through `v` from the tet
    /// [`Delaunay::vt`] keeps for it.
    pub(crate) fn star(&self, v: u32) -> Vec<u32> {
        let t0 = self.vt.get(v as usize).copied().unwrap_or(NONE);
        if t0 == NONE || !self.alive[t0 as usize] || !self.tets[t0 as usize].contains(&v) {
            // Not expected (every change keeps `vt`); a scan is always right.
            return (0..self.tets.len() as u32)
                .filter(|&t| self.alive[t as usize] && self.tets[t as usize].contains(&v))
                .collect();
        }
        self.walk_around(v, t0, |_| true)
    }

    /// The marks [`Delaunay::walk_around`] uses, for a caller's own set of tets; no walk
    /// may run while they are held (it would panic).
    pub(crate) fn tet_marks(&self) -> std::cell::RefMut<'_, Stamps> {
        self.walked.borrow_mut()
    }

    /// The tets containing vertex `v` reached from `t0` across faces through `v`, entering
    /// only tets `keep` accepts. Linear in the star's size: a cospherical ring (a
    /// cylinder's cap of many facets) gives a point thousands of tets.
    pub(crate) fn walk_around(&self, v: u32, t0: u32, keep: impl Fn(u32) -> bool) -> Vec<u32> {
        let mut out = Vec::with_capacity(64);
        out.push(t0);
        let mut seen = self.walked.borrow_mut();
        seen.clear_for(self.tets.len());
        seen.insert(t0);
        let mut k = 0;
        while k < out.len() {
            let t = out[k];
            k += 1;
            let tv = self.tets[t as usize];
            for (j, &w) in tv.iter().enumerate() {
                if w == v {
                    continue;
                }
                let nb = self.adj[t as usize][j];
                if nb != NONE && keep(nb) && seen.insert(nb) {
                    out.push(nb);
                }
            }
        }
        out
    }

    /// Drop the dead tets' slots, keeping the live tets in their order (so that every
    /// walk, scan and choice by id afterwards goes as it would have without): ids are
    /// never reused, and after the constrained fill's recovery and the outside's removal
    /// nine slots in ten were dead (OpenSCAD's CSG-modules: 1.32M for 114k live tets),
    /// which every scan over the tets then paid for. Faces across from a dead tet become
    /// [`NONE`].
    pub(crate) fn compact(&mut self) {
        let mut new_id = vec![NONE; self.tets.len()];
        let mut n = 0u32;
        for (id, &alive) in new_id.iter_mut().zip(&self.alive) {
            if alive {
                *id = n;
                n += 1;
            }
        }
        let map = |t: u32| if t == NONE { NONE } else { new_id[t as usize] };
        let mut w = 0;
        for t in 0..self.tets.len() {
            if self.alive[t] {
                self.tets[w] = self.tets[t];
                self.adj[w] = self.adj[t].map(map);
                w += 1;
            }
        }
        self.tets.truncate(w);
        self.adj.truncate(w);
        self.alive = vec![true; w];
        for t in self.vt.iter_mut() {
            *t = map(*t);
        }
        // (The walks' start: any live tet where the last made is gone.)
        self.last = Some(map(self.last)).filter(|&t| t != NONE).unwrap_or(0);
        *self.walked.borrow_mut() = Stamps::default();
    }

    /// Rebuild the point-to-tet map from the live tets (after tets are dropped).
    pub(crate) fn rebuild_vt(&mut self) {
        self.vt = vec![NONE; self.pts.len()];
        for t in 0..self.tets.len() {
            if self.alive[t] {
                for v in self.tets[t] {
                    self.vt[v as usize] = t as u32;
                }
            }
        }
    }

    /// Drop the last added point (in no tet).
    pub(crate) fn pop_point(&mut self) {
        self.pts.pop();
        self.vt.pop();
    }

    /// The id the next added point gets.
    pub(crate) fn next_id(&self) -> u32 {
        self.pts.len() as u32
    }

    /// A new point (not yet in any tet).
    pub(crate) fn add_point(&mut self, p: P3) -> u32 {
        self.pts.push(p);
        self.vt.push(NONE);
        (self.pts.len() - 1) as u32
    }

    /// Is (a, b) an edge of a live tet?
    pub(crate) fn has_edge(&self, a: u32, b: u32) -> bool {
        self.star(a)
            .iter()
            .any(|&t| self.tets[t as usize].contains(&b))
    }

    /// The live tets around edge (x, y).
    pub(crate) fn around_edge(&self, x: u32, y: u32) -> Vec<u32> {
        self.star(x)
            .into_iter()
            .filter(|&t| self.tets[t as usize].contains(&y))
            .collect()
    }

    /// Replace each tet of `old` by copies with one of its vertices in `which` replaced by
    /// the new point `p` (a split of those tets at `p`). Unless every new tet is positive,
    /// nothing changes and Err lists the old tets that would give a non-positive one (a
    /// rounded point next to a nearly flat tet).
    fn split_at(&mut self, old: &[u32], which: &[Vec<u32>], p: P3) -> Result<u32, Vec<u32>> {
        let s = self.add_point(p);
        let mut new = Vec::new();
        let mut bad = Vec::new();
        for (&t, w) in old.iter().zip(which) {
            let tv = self.tets[t as usize];
            for &x in w {
                let nt = tv.map(|v| if v == x { s } else { v });
                if self.valid_new(nt) {
                    new.push(nt);
                } else if !bad.contains(&t) {
                    bad.push(t);
                }
            }
        }
        if !bad.is_empty() {
            self.pts.pop();
            self.vt.pop();
            return Err(bad);
        }
        self.replace(old, &new);
        Ok(s)
    }

    /// Insert a new point at `p` by Bowyer–Watson in a triangulation that may no longer be
    /// Delaunay. The cavity is the tets whose circumsphere holds `p`, grown from the tet
    /// holding it without crossing a fixed face, then shrunk (tets not holding `p` taken
    /// out) until `p` sees every face of it, no fixed edge and no point is inside it.
    /// Unlike a face or edge split next to a nearly flat tet, every tet around a point
    /// near an edge is in the cavity, so no new tet is thin there. None (nothing changed)
    /// if the tets holding `p` themselves are in the way, or a new tet would be one
    /// [`Delaunay::valid_new`] refuses.
    pub(crate) fn insert_point(&mut self, p: P3) -> Option<u32> {
        self.insert_point_in(self.locate(p), p)
    }

    /// [`Delaunay::insert_point`] where tet `start` holds `p`.
    pub(crate) fn insert_point_in(&mut self, start: u32, p: P3) -> Option<u32> {
        self.insert_point_taking(start, p, None)
    }

    /// [`Delaunay::insert_point_in`], with tet `take` in the cavity whatever the sphere
    /// test says: it and the tets behind each cavity face of theirs that `p` does not see
    /// join the cavity (a tet can go), or nothing changes. For a nearly flat tet whose
    /// corners are nearly cocircular, a point above it can be outside its circumsphere.
    pub(crate) fn insert_point_taking(
        &mut self,
        start: u32,
        p: P3,
        take: Option<u32>,
    ) -> Option<u32> {
        let tv = self.tets[start as usize];
        if take.is_some_and(|t| !self.alive[t as usize]) {
            return None;
        }
        if !self.alive[start as usize] || tv.iter().any(|&v| self.p(v) == p) {
            return None;
        }
        let fixed_face = |dt: &Delaunay, t: u32, j: usize| {
            dt.fixed_faces
                .contains(&sorted3(FACES[j].map(|i| dt.tets[t as usize][i])))
        };
        // The point, known to the flatness tests from here on.
        let s = self.add_point(p);
        // The new tet on face j of t, and whether p is on that face: exactly, or by
        // construction (the support points of both on one plane).
        let new_tet = |dt: &Delaunay, t: u32, j: usize| {
            let tv = dt.tets[t as usize];
            let f = FACES[j];
            [tv[f[0]], tv[f[2]], tv[f[1]], s]
        };
        let on_face = |dt: &Delaunay, t: u32, j: usize| {
            let n = new_tet(dt, t, j);
            orient3d(dt.p(n[0]), dt.p(n[1]), dt.p(n[2]), p) == 0
                || (!dt.clearly_thick(n) && dt.flat_by_construction(n))
        };
        let holds = |dt: &Delaunay, t: u32| {
            (0..4).all(|j| dt.positive(new_tet(dt, t, j)) || on_face(dt, t, j))
        };
        let mut cav = vec![start];
        // (Sized for a typical cavity, so that the sets rarely grow: their rehashing
        // showed in profiles of the fill.)
        let mut in_cav: HashSet<u32> = HashSet::with_capacity_and_hasher(64, Default::default());
        in_cav.insert(start);
        // `take` and the tets it brings in through faces p does not see.
        let mut forced: HashSet<u32> = HashSet::default();
        if let Some(t) = take {
            forced.insert(t);
            if in_cav.insert(t) {
                cav.push(t);
            }
        }
        let mut k = 0;
        while k < cav.len() {
            let t = cav[k];
            k += 1;
            let mut holds_p = None;
            for j in 0..4 {
                let nb = self.adj[t as usize][j];
                if nb == NONE || in_cav.contains(&nb) || fixed_face(self, t, j) {
                    continue;
                }
                // Every tet holding p, and those the sphere test takes.
                let holds_p = *holds_p.get_or_insert_with(|| holds(self, t));
                let unseen = forced.contains(&t) && !self.valid_new(new_tet(self, t, j));
                if unseen {
                    forced.insert(nb);
                }
                if unseen || (holds_p && on_face(self, t, j)) || self.in_sphere(nb, p) > 0 {
                    in_cav.insert(nb);
                    cav.push(nb);
                }
            }
        }
        let fail = |dt: &mut Delaunay| {
            dt.pop_point();
            None
        };
        loop {
            let mut out: Vec<u32> = Vec::new();
            let mut bound_edges: HashSet<[u32; 2]> =
                HashSet::with_capacity_and_hasher(4 * cav.len() + 8, Default::default());
            let mut bound_pts: HashSet<u32> =
                HashSet::with_capacity_and_hasher(2 * cav.len() + 8, Default::default());
            for &t in &cav {
                for j in 0..4 {
                    let nb = self.adj[t as usize][j];
                    if nb != NONE && in_cav.contains(&nb) {
                        if fixed_face(self, t, j) {
                            out.push(t);
                        }
                        continue;
                    }
                    let n = new_tet(self, t, j);
                    if !self.valid_new(n) {
                        out.push(t);
                    }
                    for e in 0..3 {
                        bound_edges.insert(sorted2(n[e], n[(e + 1) % 3]));
                    }
                    bound_pts.extend(&n[..3]);
                }
            }
            if out.is_empty() {
                for &t in &cav {
                    let tv = self.tets[t as usize];
                    let inner_edge = (0..4).any(|a| {
                        (a + 1..4).any(|b| {
                            let e = sorted2(tv[a], tv[b]);
                            self.fixed_edges.contains(&e) && !bound_edges.contains(&e)
                        })
                    });
                    if inner_edge || tv.iter().any(|v| !bound_pts.contains(v)) {
                        out.push(t);
                    }
                }
            }
            if out.is_empty() {
                break;
            }
            let mut removed = false;
            for t in out {
                // A tet holding p cannot go, nor can `take`.
                if in_cav.contains(&t) && !holds(self, t) && Some(t) != take {
                    in_cav.remove(&t);
                    removed = true;
                }
            }
            if !removed {
                return fail(self);
            }
            cav.retain(|t| in_cav.contains(t));
        }
        let mut new = Vec::new();
        for &t in &cav {
            for j in 0..4 {
                let nb = self.adj[t as usize][j];
                if nb == NONE || !in_cav.contains(&nb) {
                    new.push(new_tet(self, t, j));
                }
            }
        }
        // The cavity's faces must close up (every edge on two of them, once each way):
        // in a tetrahedralization that is no longer Delaunay (after recovery and
        // relocation), the sphere test can take a cavity pinched at an edge, whose new
        // tets would leave a face without a neighbour.
        if !closes_up(new.iter().map(|t| [t[0], t[1], t[2]])) {
            return fail(self);
        }
        self.replace(&cav, &new);
        Some(s)
    }

    /// Split face `k` of tet `t` (and the tet behind it) at `p`, 2 tets to 6.
    pub(crate) fn split_face(&mut self, t: u32, k: usize, p: P3) -> Result<u32, Vec<u32>> {
        let u = self.adj[t as usize][k];
        let f = FACES[k].map(|j| self.tets[t as usize][j]);
        if u == NONE || self.fixed_faces.contains(&sorted3(f)) {
            return Err(Vec::new());
        }
        let w = f.to_vec();
        self.split_at(&[t, u], &[w.clone(), w], p)
    }

    /// Split edge (x, y) at `p`: each tet around it becomes two.
    pub(crate) fn split_edge(&mut self, x: u32, y: u32, p: P3) -> Result<u32, Vec<u32>> {
        if self.fixed_edges.contains(&sorted2(x, y)) {
            return Err(Vec::new());
        }
        let around = self.around_edge(x, y);
        if around.is_empty() {
            return Err(Vec::new());
        }
        let which = vec![vec![x, y]; around.len()];
        self.split_at(&around, &which, p)
    }

    /// Change the tets `bad` (nearly flat ones, in the way of a split) by any valid flip
    /// that keeps the fixed edges and faces. True if something changed.
    pub(crate) fn flip_away(&mut self, bad: &[u32]) -> bool {
        for &t in bad {
            if !self.alive[t as usize] {
                continue;
            }
            for k in 0..4 {
                if self.flip23(t, k) {
                    return true;
                }
            }
            let tv = self.tets[t as usize];
            for i in 0..4 {
                for j in i + 1..4 {
                    let (x, y) = (tv[i], tv[j]);
                    let around = self.around_edge(x, y);
                    if self.flip32(x, y, &around) || self.remove_edge(x, y, &around) {
                        return true;
                    }
                }
            }
        }
        false
    }

    /// The tet at `a` that segment ab leaves `a` through, and its face opposite `a` (b is
    /// on the inner side of, or on, each of the tet's faces through `a`).
    pub(crate) fn leaving(&self, a: u32, b: u32) -> Option<(u32, usize)> {
        let pb = self.p(b);
        self.star(a).iter().find_map(|&t| {
            let v = self.tets[t as usize];
            let k = v.iter().position(|&x| x == a)?;
            let ok = FACES.iter().enumerate().all(|(j, f)| {
                j == k || orient3d(self.p(v[f[0]]), self.p(v[f[1]]), self.p(v[f[2]]), pb) <= 0
            });
            ok.then_some((t, k))
        })
    }

    /// The faces segment ab crosses, walking from a's tet toward b: (tet, local face) in
    /// order. Stops early (returns what it has) where the segment meets an edge or a
    /// vertex (a degenerate crossing).
    pub(crate) fn crossed_faces(&self, a: u32, b: u32) -> Vec<(u32, usize)> {
        let (pa, pb) = (self.p(a), self.p(b));
        let Some((mut t, mut k)) = self.leaving(a, b) else {
            return Vec::new();
        };
        let mut out = Vec::new();
        for _ in 0..self.tets.len() {
            out.push((t, k));
            let nb = self.adj[t as usize][k];
            if nb == NONE || self.tets[nb as usize].contains(&b) {
                break;
            }
            // The exit face of nb: crossed strictly by ab, not the entry face.
            let entry = (0..4).find(|&m| self.adj[nb as usize][m] == t).unwrap_or(4);
            let v = self.tets[nb as usize];
            let next = (0..4).find(|&m| {
                if m == entry {
                    return false;
                }
                let f = FACES[m].map(|j| self.p(v[j]));
                let o = [
                    orient3d(pa, pb, f[0], f[1]),
                    orient3d(pa, pb, f[1], f[2]),
                    orient3d(pa, pb, f[2], f[0]),
                ];
                (o.iter().all(|&x| x > 0) || o.iter().all(|&x| x < 0))
                    && orient3d(f[0], f[1], f[2], pb) > 0
            });
            let Some(m) = next else {
                break;
            };
            t = nb;
            k = m;
        }
        out
    }

    /// [`Delaunay::recover_edge`] trying every face and edge segment ab crosses, not only
    /// the first: 2-3 flips of crossed faces, then removal of their edges.
    pub(crate) fn recover_edge_any(&mut self, a: u32, b: u32, budget: usize) -> bool {
        'outer: for _ in 0..budget {
            if self.has_edge(a, b) {
                return true;
            }
            let crossed = self.crossed_faces(a, b);
            for &(t, k) in &crossed {
                if self.alive[t as usize] && self.flip23(t, k) {
                    continue 'outer;
                }
            }
            for &(t, k) in &crossed {
                if !self.alive[t as usize] {
                    continue;
                }
                let v = self.tets[t as usize];
                let f = FACES[k].map(|j| v[j]);
                for e in 0..3 {
                    let (x, y) = (f[e], f[(e + 1) % 3]);
                    if [x, y].contains(&a) || [x, y].contains(&b) {
                        continue;
                    }
                    let around = self.around_edge(x, y);
                    if self.remove_edge(x, y, &around) {
                        continue 'outer;
                    }
                }
            }
            return false;
        }
        false
    }

    /// Try to make edge (a, b) appear by flips of what segment ab crosses next to `a`
    /// (greedy; at most `budget` flips). True when the edge is there.
    pub(crate) fn recover_edge(&mut self, a: u32, b: u32, budget: usize) -> bool {
        for _ in 0..budget {
            if self.has_edge(a, b) {
                return true;
            }
            let Some((t, k)) = self.leaving(a, b) else {
                return false;
            };
            if self.flip23(t, k) {
                continue;
            }
            // Not convex across that face: try 3-2 flips and edge removals on its edges.
            let v = self.tets[t as usize];
            let f = FACES[k].map(|j| v[j]);
            let flipped = (0..3).any(|e| {
                let (x, y) = (f[e], f[(e + 1) % 3]);
                let around = self.around_edge(x, y);
                self.flip32(x, y, &around) || self.remove_edge(x, y, &around)
            });
            if !flipped {
                return false;
            }
        }
        false
    }
}

/// Whether tets `a` and `b` have the same boundary as oriented triangles (faces shared
/// inside a set, once each way, cancel). Positive tets with the boundary of a region tile
/// it: the winding number they add up to at a point is the boundary's, so 1 inside and 0
/// outside, and a point covered twice or not at all would change it.
pub(crate) fn same_boundary(a: &[[u32; 4]], b: &[[u32; 4]]) -> bool {
    // Each oriented face, rotated to start at its smallest vertex, with +1 for set `a`
    // and -1 for set `b`; a face's reverse counts against it.
    let mut faces: Vec<([u32; 3], i32)> = Vec::with_capacity(4 * (a.len() + b.len()));
    for (set, w) in [(a, 1), (b, -1)] {
        for t in set {
            for f in FACES {
                let g = f.map(|j| t[j]);
                let r = (0..3).min_by_key(|&k| g[k]).unwrap_or(0);
                let g = [g[r], g[(r + 1) % 3], g[(r + 2) % 3]];
                // The reverse, also starting at the smallest vertex.
                let rev = [g[0], g[2], g[1]];
                if g[1] < g[2] {
                    faces.push((g, w));
                } else {
                    faces.push((rev, -w));
                }
            }
        }
    }
    faces.sort_unstable();
    faces
        .chunk_by(|x, y| x.0 == y.0)
        .all(|run| run.iter().map(|x| x.1).sum::<i32>() == 0)
}

/// Whether oriented triangles close up: every edge on two of them, once each way (the
/// faces of a cavity, seen from the point that fills it).
pub(crate) fn closes_up(tris: impl Iterator<Item = [u32; 3]>) -> bool {
    let mut edges: HashMap<[u32; 2], i32> = HashMap::default();
    for f in tris {
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            *edges.entry(sorted2(a, b)).or_insert(0) += if a < b { 1 } else { -1 };
        }
    }
    edges.values().all(|&c| c == 0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rng(seed: &mut u64) -> f64 {
        *seed ^= *seed << 13;
        *seed ^= *seed >> 7;
        *seed ^= *seed << 17;
        (*seed >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A point of the unit cube from `seed` (three [`rng`] draws).
    fn point(seed: &mut u64) -> P3 {
        [rng(seed), rng(seed), rng(seed)]
    }

    #[test]
    fn stamps_start_each_set_empty_even_when_the_stamp_wraps() {
        let mut m = Stamps::default();
        m.clear_for(4);
        assert!(m.insert(2) && !m.insert(2));
        assert!(m.contains(2) && !m.contains(1) && !m.contains(9));
        m.clear_for(6);
        assert!(!m.contains(2));
        assert!(m.insert(5));
        // The stamp wraps: marks of every earlier set are cleared, not taken as current.
        m.stamp = u32::MAX;
        m.of[3] = 1;
        m.clear_for(6);
        assert_eq!(m.stamp, 1);
        assert!(!m.contains(3) && !m.contains(5));
    }

    fn check_delaunay(dt: &Delaunay) {
        let live: Vec<usize> = (0..dt.tets.len()).filter(|&t| dt.alive[t]).collect();
        for &t in &live {
            let v = dt.tets[t];
            let p = v.map(|x| dt.pts[x as usize]);
            assert!(orient3d(p[0], p[1], p[2], p[3]) > 0, "tet {t} not positive");
            // Empty circumsphere against every point.
            for (i, &q) in dt.pts.iter().enumerate() {
                if v.contains(&(i as u32)) {
                    continue;
                }
                assert!(
                    insphere(p[0], p[1], p[2], p[3], q) <= 0,
                    "point {i} in tet {t}'s sphere"
                );
            }
            // Links are mutual and across the same face.
            for (k, fk) in FACES.iter().enumerate() {
                let nb = dt.adj[t][k];
                if nb == NONE {
                    continue;
                }
                assert!(dt.alive[nb as usize]);
                let mut f: Vec<u32> = fk.iter().map(|&j| v[j]).collect();
                f.sort_unstable();
                let w = dt.tets[nb as usize];
                assert!(f.iter().all(|x| w.contains(x)));
                assert!(dt.adj[nb as usize].contains(&(t as u32)));
            }
        }
        // The tets fill the enclosing tet: volumes add up.
        let vol = |v: [u32; 4]| {
            let p = v.map(|x| dt.pts[x as usize]);
            crate::geom::vec3::tet_det(p[0], p[1], p[2], p[3])
        };
        let total: f64 = live.iter().map(|&t| vol(dt.tets[t])).sum();
        let n = dt.n as u32;
        let outer = vol([n, n + 1, n + 2, n + 3]).abs();
        assert!((total - outer).abs() <= 1e-9 * outer, "{total} vs {outer}");
    }

    #[test]
    fn insphere_sign_matches_our_orientation() {
        let a = [0.0, 0.0, 0.0];
        let b = [1.0, 0.0, 0.0];
        let c = [0.0, 1.0, 0.0];
        let d = [0.0, 0.0, 1.0];
        assert!(orient3d(a, b, c, d) > 0);
        assert_eq!(insphere(a, b, c, d, [0.2, 0.2, 0.2]), 1);
        assert_eq!(insphere(a, b, c, d, [5.0, 5.0, 5.0]), -1);
        assert_eq!(insphere(a, b, c, d, [1.0, 1.0, 0.0]), 0);
    }

    /// The segment from (0, 0, -1) to (0, 0, 1) against faces in the plane z = 0: through
    /// the interior it crosses; through an edge's interior only if that edge is new;
    /// through a vertex, beside the face or in its plane, not.
    #[test]
    fn a_guarded_segment_crosses_new_faces_and_edges_only() {
        let pts = [
            [0.0, 0.0, -1.0], // 0, 1: the segment
            [0.0, 0.0, 1.0],
            [-1.0, -1.0, 0.0], // 2, 3, 4: around the origin
            [1.0, -1.0, 0.0],
            [0.0, 1.0, 0.0],
            [-1.0, 0.0, 0.0], // 5, 6: an edge through the origin
            [1.0, 0.0, 0.0],
            [0.0, 0.0, 0.0],  // 7: the origin
            [3.0, 3.0, 0.0],  // 8
            [0.0, 0.0, -0.5], // 9: on the segment, below the plane
        ];
        let mut dt = Delaunay::new(&pts);
        assert!(!dt.crosses_guard([2, 3, 4], &[]), "no guard, no crossing");
        dt.guard = Some([0, 1]);
        assert!(dt.crosses_guard([2, 3, 4], &[]));
        assert!(dt.crosses_guard([5, 6, 4], &[[6, 5]]));
        assert!(!dt.crosses_guard([5, 6, 4], &[[6, 4], [4, 5]]));
        assert!(!dt.crosses_guard([7, 3, 4], &[[7, 3], [3, 4], [4, 7]]));
        assert!(!dt.crosses_guard([3, 4, 8], &[[3, 4], [4, 8], [8, 3]]));
        assert!(!dt.crosses_guard([0, 9, 3], &[[0, 9], [9, 3], [3, 0]]));
        dt.guard = Some([0, 9]);
        assert!(
            !dt.crosses_guard([2, 3, 4], &[]),
            "the segment ends before the plane"
        );
        dt.guard = Some([0, 7]);
        assert!(
            !dt.crosses_guard([7, 3, 4], &[[7, 3]]),
            "ends at the face's vertex"
        );
    }

    #[test]
    fn random_points_give_an_empty_sphere_triangulation() {
        let mut s = 0x9e3779b97f4a7c15u64;
        let pts: Vec<P3> = (0..200).map(|_| point(&mut s)).collect();
        let dt = Delaunay::new(&pts);
        check_delaunay(&dt);
        assert!(dt.interior_tets().count() > 200);
    }

    /// A 2-3 flip's tets have its two tets' boundary; a tet turned over, or one more
    /// tet on top (an overlap), does not.
    #[test]
    fn same_boundary_compares_oriented_faces() {
        let old = [[0, 1, 2, 3], [0, 2, 1, 4]];
        let new = [[0, 2, 3, 4], [2, 1, 3, 4], [1, 0, 3, 4]];
        assert!(same_boundary(&old, &new));
        assert!(same_boundary(&new, &old));
        assert!(!same_boundary(
            &old,
            &[[0, 2, 3, 4], [1, 2, 3, 4], [1, 0, 3, 4]]
        ));
        assert!(!same_boundary(&old, &[new[0], new[1], new[2], new[0]]));
        assert!(!same_boundary(&old, &new[..2]));
    }

    /// Points inserted one by one into a Delaunay triangulation keep it Delaunay; with
    /// fixed edges, they keep those edges, every tet positive and the volume.
    #[test]
    fn inserted_points_keep_the_triangulation_and_its_fixed_edges() {
        let mut s = 0x2545f4914f6cdd1du64;
        let pts: Vec<P3> = (0..150).map(|_| point(&mut s)).collect();
        let volume = |dt: &Delaunay| -> f64 {
            (0..dt.tets.len())
                .filter(|&t| dt.alive[t])
                .map(|t| {
                    let p = dt.tets[t].map(|v| dt.pts[v as usize]);
                    crate::geom::vec3::tet_det(p[0], p[1], p[2], p[3])
                })
                .sum()
        };
        let mut dt = Delaunay::new(&pts);
        for _ in 0..60 {
            let q = point(&mut s);
            assert!(dt.insert_point(q).is_some());
        }
        check_delaunay(&dt);
        let mut dt = Delaunay::new(&pts);
        let v0 = volume(&dt);
        let fixed: Vec<[u32; 2]> = (0..40u32)
            .filter_map(|a| (a + 1..150).find(|&b| dt.has_edge(a, b)).map(|b| [a, b]))
            .collect();
        dt.fixed_edges.extend(fixed.iter().copied());
        let mut added = 0;
        for _ in 0..200 {
            let q = point(&mut s);
            added += usize::from(dt.insert_point(q).is_some());
        }
        assert!(added > 150, "{added} of 200 inserted");
        for e in &fixed {
            assert!(dt.has_edge(e[0], e[1]), "fixed edge {e:?} lost");
        }
        for t in (0..dt.tets.len()).filter(|&t| dt.alive[t]) {
            assert!(dt.positive(dt.tets[t]), "tet {t}");
        }
        assert!((volume(&dt) - v0).abs() <= 1e-9 * v0);
    }

    /// Compacting drops every dead slot, keeps the live tets in their order with their
    /// links, and the insertions after it make the same tets (renumbered) as without.
    #[test]
    fn compacting_keeps_the_live_tets_in_order_and_what_follows() {
        let mut s = 0x51f15e5u64;
        let pts: Vec<P3> = (0..120).map(|_| point(&mut s)).collect();
        let live = |dt: &Delaunay| -> Vec<[u32; 4]> {
            (0..dt.tets.len())
                .filter(|&t| dt.alive[t])
                .map(|t| dt.tets[t])
                .collect()
        };
        let plain = Delaunay::new(&pts);
        let mut packed = plain.clone();
        packed.compact();
        assert!(plain.alive.iter().any(|a| !a), "nothing to drop");
        assert_eq!(packed.tets.len(), live(&plain).len());
        assert!(packed.alive.iter().all(|&a| a));
        assert_eq!(live(&packed), live(&plain));
        check_delaunay(&packed);
        for v in 0..pts.len() as u32 {
            let star = packed.star(v);
            assert!(!star.is_empty() && star.iter().all(|&t| packed.tets[t as usize].contains(&v)));
            assert_eq!(star.len(), plain.star(v).len(), "point {v}");
        }
        let mut plain = plain;
        for _ in 0..40 {
            let q = point(&mut s);
            assert_eq!(
                plain.insert_point(q).is_some(),
                packed.insert_point(q).is_some()
            );
            assert_eq!(live(&packed), live(&plain));
        }
        check_delaunay(&packed);
    }

    #[test]
    fn grid_points_cospherical_and_duplicates() {
        // A 4 x 4 x 4 lattice: every cube's 8 corners are cospherical.
        let mut pts = Vec::new();
        for i in 0..4 {
            for j in 0..4 {
                for k in 0..4 {
                    pts.push([i as f64, j as f64, k as f64]);
                }
            }
        }
        pts.push([1.0, 1.0, 1.0]);
        let dt = Delaunay::new(&pts);
        check_delaunay(&dt);
        // The lattice's 27 cubes, each of volume 1, are covered.
        let vol: f64 = dt
            .interior_tets()
            .map(|v| {
                let p = v.map(|x| dt.pts[x as usize]);
                crate::geom::vec3::tet_det(p[0], p[1], p[2], p[3]) / 6.0
            })
            .sum();
        assert!((vol - 27.0).abs() < 1e-9, "{vol}");
        assert!(dt.interior_tets().all(|t| !t.contains(&64)));
    }
}
