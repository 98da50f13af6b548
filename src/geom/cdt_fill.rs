//! The constrained fill: a tetrahedralization of the region a closed triangle surface
//! encloses, with every surface triangle kept exactly as a face and every added point
//! strictly inside. The advancing front hands it what it cannot close.
//!
//! 1. Delaunay tetrahedralization of the surface's vertices ([`Delaunay`]).
//! 2. Edge recovery: flips first (with [`Split::NoFlatTets`], flips in the plane of
//!    coplanar surface points before them, `plane_flips`, and no numerically flat tet
//!    made, the starting ones flipped out); where they cannot, a Steiner
//!    point where the segment leaves the tet at its current end (a face split, or an edge
//!    split when it crosses an edge), walking to the other end; or ([`Split::Halving`]) one inside the piece at
//!    the projection of the vertex that encroaches on it most (TetGen's reference
//!    point), else halfway. Recovered pieces are fixed: no flip removes them.
//! 3. Face recovery: every mesh edge that crosses a triangle's interior is split at the
//!    crossing (each split removes one crossing edge and adds none), until the triangle is
//!    a union of mesh faces.
//! 4. The enclosed tets by parity across the constraint faces; the rest are dropped.
//! 5. Every Steiner point is then moved off the surface (TetGen's `-Y`): its star's
//!    constraint faces are retriangulated without it (a best-shaped triangulation in
//!    the triangle's plane, exact 2D orientations) and it is placed along the inward normal where every
//!    tet of its new star is positive. Where no point is (a nearly flat tet of the star
//!    at the point: every inward step inverts it), the star grows through the faces a
//!    point just inside does not see, until it sees them all ([`Cdt::grown_star`]). A
//!    point that only a tiny step would move off waits for the last round: its
//!    neighbours may move off meanwhile, which it would pin to the surface. The surface
//!    triangles come back exactly.
//! 6. Points off the surface that numerically flat tets use are contracted into a
//!    neighbour where that leaves fewer of them ([`Cdt::contract_flat`]): Steiner points
//!    moved off a long segment one at a time stay almost on its line, and the tets
//!    between them are flatter than the later stages can certify or repair. After halving
//!    ([`Split::Halving`]), so are the Steiner points of tets with a dihedral angle below
//!    [`SLIVER_CONTRACT_DEG`] where that raises their star's smallest angle
//!    ([`Cdt::contract_slivers`]): halving leaves many points just off the surface, whose
//!    slivers the linear stage could not lift.
//!
//! Every topological decision is an exact orient3d/orient2d; the Steiner coordinates are
//! rounded, which the final checks cover: the boundary faces must be the input triangles
//! and every tet positive, or the fill reports what went wrong.

use super::delaunay::{closes_up, sorted2, sorted3, Delaunay, FACES, NONE};
use super::predicates::{orient3d, projection_of};
use super::tet_quality::{dihedral_extremes, numerically_flat};
use super::vec3::{axpy, centroid3, dist, dot, norm, sub, tet_det, tri_normal, P3};
use rustc_hash::{FxHashMap as HashMap, FxHashSet as HashSet};
use std::collections::BTreeMap;

/// A filled region: the input points then the new interior points, and positive tets.
pub(crate) struct Filled {
    pub pts: Vec<P3>,
    pub tets: Vec<[u32; 4]>,
    /// Steiner points moved off the surface with a grown cavity ([`Cdt::grown_star`]);
    /// the tests show that path runs by it.
    #[cfg_attr(not(test), allow(dead_code))]
    pub grown: usize,
    /// Steiner points left at a tiny step off the surface ([`TINY_STEP`]) that the fill
    /// keeps: no grown cavity was seen from a larger one, and no contraction removed
    /// them ([`Cdt::contract_slivers`]).
    #[cfg_attr(not(test), allow(dead_code))]
    pub tiny: usize,
}

/// Where a fill's time went, stage by stage (seconds; 0 for a stage not reached), and
/// the Steiner points edge and face recovery added.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Stages {
    pub delaunay: f64,
    pub edges: f64,
    pub faces: f64,
    pub steiner_removal: f64,
    pub steiner_points: usize,
    /// Segments missing from the Delaunay tetrahedralization that the recursive flip
    /// pass brought in ([`Split::FlipsThenHalving`] only).
    pub flipped_segments: usize,
    /// Contractions, lifts and the result, after the Steiner points moved.
    pub finish: f64,
    /// Steiner points that only the last round's larger cavities could move off the
    /// surface ([`GROW_LIMIT_LAST`]), or that stayed on it.
    pub wide_cavity_points: usize,
    /// Where edge or face recovery could not go on (for the error): the point a
    /// segment's recovery had reached, or the centroid of the triangle not recovered.
    pub stuck_near: Option<P3>,
}

/// Tetrahedralize the region bounded by `faces` (indices into `pts`, each oriented with the
/// region on its positive side: `orient3d(a, b, c, x) > 0` for `x` inside). The result's
/// boundary faces are exactly `faces`; new points are strictly inside. Err names the
/// stage that could not go on (a degenerate or self-intersecting surface, or a rounded
/// Steiner point that would invert a tet). `stages` gets the time of each stage reached.
pub(crate) fn fill(
    pts: &[P3],
    faces: &[[u32; 3]],
    split: Split,
    height: Option<&dyn Fn(P3) -> f64>,
    patience: Patience,
    stages: &mut Stages,
) -> Result<Filled, &'static str> {
    let clock = std::time::Instant::now();
    let dt = Delaunay::new(pts);
    stages.delaunay = clock.elapsed().as_secs_f64();
    fill_from(dt, faces, split, height, patience, stages)
}

/// The Delaunay tetrahedralization [`fill`] starts from, for [`fill_from`]: tries with
/// other ways on the same points build it once.
pub(crate) fn delaunay(pts: &[P3]) -> Delaunay {
    let mut dt = Delaunay::new(pts);
    // (Each try of the whole fill starts from a copy.)
    dt.compact();
    dt
}

/// [`fill`] from the Delaunay tetrahedralization of its points ([`delaunay`]);
/// `stages.delaunay` is left as it is.
pub(crate) fn fill_from(
    dt: Delaunay,
    faces: &[[u32; 3]],
    split: Split,
    height: Option<&dyn Fn(P3) -> f64>,
    patience: Patience,
    stages: &mut Stages,
) -> Result<Filled, &'static str> {
    let mut clock = std::time::Instant::now();
    let mut lap = || {
        let t = clock.elapsed().as_secs_f64();
        clock = std::time::Instant::now();
        t
    };
    let n = dt.n;
    let mut c = Cdt::new(dt, faces, split, patience)?;
    if split == Split::NoFlatTets {
        c.flip_flat_tets();
        c.dt.refuse_flat = true;
    }
    let r = c.recover_edges();
    stages.edges = lap();
    stages.flipped_segments = c.flipped_segments;
    stages.stuck_near = c.stuck_near;
    stages.steiner_points = c.dt.pts.len() - n - 4;
    r?;
    let r = (0..faces.len()).try_for_each(|i| {
        c.recover_face(i).inspect_err(|_| {
            let p = faces[i].map(|v| c.dt.p(v));
            c.stuck_near = Some(centroid3(p[0], p[1], p[2]));
        })
    });
    stages.faces = lap();
    stages.steiner_points = c.dt.pts.len() - n - 4;
    stages.stuck_near = c.stuck_near;
    r?;
    c.dt.refuse_flat = false;
    c.keep_enclosed()?;
    let r = c.remove_steiner_points();
    stages.steiner_removal = lap();
    stages.wide_cavity_points = c.wide_cavity_points;
    r?;
    c.contract_flat();
    if matches!(split, Split::Halving | Split::FlipsThenHalving) {
        c.contract_slivers();
    }
    if let Some(h) = height {
        c.lift_flat_tets(h);
    }
    let r = c.result();
    stages.finish = lap();
    r
}

/// A tet on a surface face with a dihedral angle below this (degrees) gets a point above
/// the face ([`Cdt::lift_flat_tets`]). Measured on OpenSCAD's example002 through the
/// whole fill and the linear stage: with no lifting 11 tets stay invalid as P2 elements;
/// lifting where the apex is within a quarter edge of the face's plane, 8; below 10°,
/// 10; below 20°, none.
const LIFT_BELOW_DEG: f64 = 20.0;

/// Tets below this smallest dihedral angle (degrees) with a Steiner point off the surface
/// get [`Cdt::contract_slivers`].
const SLIVER_CONTRACT_DEG: f64 = 5.0;

/// Rounds of [`Cdt::contract_flat`].
const CONTRACT_ROUNDS: usize = 8;

/// Highest link level of [`Split::FlipsThenHalving`]'s flip pass. TetGen's rounds go to
/// level 22 on drilled2; here the stall rule ([`DEEP_FLIP_STALL`]) ends the pass at
/// level 8 there. Going on to level 40 brought 39 more of drilled2's segments in, but
/// left an unseen four-hole sphere (offset holes) that meshes this way unmeshed.
const DEEP_FLIP_LEVELS: u32 = 11;

/// [`Delaunay::flipnm`] calls per segment and level in that pass: a segment that comes
/// in takes at most a few hundred (on drilled2), a failing search all it is given.
const DEEP_FLIP_BUDGET: usize = 1_000;

/// That pass stops raising the level once a level brings in fewer than 1 in this many
/// of the segments still missing (each level costs about the same, whatever it brings).
const DEEP_FLIP_STALL: usize = 20;

/// Rounds of [`Cdt::lift_flat_tets`].
const LIFT_ROUNDS: usize = 2;

/// Where edge recovery puts a Steiner point when flips cannot bring a segment piece in.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(crate) enum Split {
    /// [`Split::Halving`], after a pass of recursive flips ([`Delaunay::recover_edge_nm`])
    /// over every segment missing from the Delaunay tetrahedralization, the link level
    /// raised from 0 while it brings segments in ([`Cdt::deep_flips`]). TetGen recovers
    /// CAD booleans' segments this way (on a sphere drilled by two rotated holes,
    /// `scripts/csg-parts.py drilled2`, all 625 missing ones, with 13 Steiner points
    /// inside), where the greedy flips of the other ways recover 81 and leave over a
    /// thousand Steiner points on the surface among nearly coplanar chains; this pass
    /// brings about 500 in, and halving then fills. Slow (tens of seconds there), so
    /// the whole fill's last try only.
    FlipsThenHalving,
    /// Where the piece leaves the tet at its current end: one point per crossed face at
    /// most, but a rounded point on a face (the other ways follow where that inverts a
    /// tet).
    AtCrossing,
    /// Inside the piece by Bowyer-Watson, at the projection of the vertex that encroaches
    /// on it most, else halfway ([`Cdt::reference_fraction`]): points off the faces,
    /// where crossings pile up next to nearly flat tets (a second try on CAD parts).
    Halving,
    /// [`Split::AtCrossing`], after flips in the plane of coplanar surface points where a
    /// piece crosses only edges in it ([`Delaunay::recover_in_plane`]), and with no
    /// numerically flat tet anywhere in the recovery: those of the starting Delaunay
    /// tetrahedralization are flipped out first ([`Cdt::flip_flat_tets`]), and no flip,
    /// split or insertion of the recovery makes one (`Delaunay::refuse_flat`). A CAD
    /// facet's fan of needles then comes in without points a hair off its plane, and a
    /// segment crossing a set of points coplanar only within rounding (the meridian of a
    /// revolved surface at 180 degrees, whose Delaunay tets there are flat) crosses
    /// it once, through a face, not through flat tets whose crossings fall within
    /// rounding of each other. The whole fill's first try (on a CSG bracket and on aniso
    /// tori of 12 segments the other two failed).
    NoFlatTets,
}

/// How long the fill keeps moving Steiner points off the surface when many stay on it.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(crate) enum Patience {
    /// Every round, grown cavities included: no other way follows.
    Exhaustive,
    /// Give up once more than [`GIVE_UP_STUCK`] plus [`GIVE_UP_PER_MILLE`] per mille of the
    /// points have stayed on the surface in the first round: the caller has another way
    /// ([`Split::Halving`]) that is cheaper than the search. Fills that close leave almost
    /// none after the first round; where many stay, the later rounds (grown cavities
    /// included) did not close the fill either, after far longer (CHANGELOG has the
    /// corpus figures).
    GiveUpEarly,
    /// [`Patience::Exhaustive`], then one more round with far larger cavities
    /// ([`GROW_LIMIT_LAST`]) for the points still on the surface: the last way there is.
    /// Where another way follows, that way makes a better fill (on OpenSCAD's animation,
    /// halving without the points outside closed this way left 32 elements that could
    /// not be certified; with them it needs no such round).
    LastResort,
}

/// Stuck points in the first round that [`Patience::GiveUpEarly`] accepts, plus ...
const GIVE_UP_STUCK: usize = 16;

/// ... this many per thousand Steiner points.
const GIVE_UP_PER_MILLE: usize = 10;

/// With [`Split::Halving`], a piece of a segment shorter than `2^-this` of the segment
/// that crosses a mesh edge exactly is split at that crossing, not halved again. Where
/// the segment is one diagonal of a planar quad of surface points and the mesh has the
/// other, every midpoint (rounded off the segment's line) leaves a piece crossing that
/// edge: on OpenSCAD's CSG-modules halving put 61 points within 1e-4 of the crossing on
/// a 4.4 long segment, and two of them could then not be moved off the surface.
const HALVING_DEPTH: i32 = 10;

/// A segment piece is split at its encroaching vertex's projection only where that lies
/// at least this fraction of the piece from either end ([`Cdt::reference_fraction`]);
/// TetGen's value: nearer an end, the new piece would be short next to that end.
const REFERENCE_MARGIN: f64 = 0.2;

/// Rounds of [`Cdt::flip_flat_tets`] (on aniso tori of 12 segments: 106 flat tets, 16
/// after the first round, 2 after the second, which no flip removes).
const FLAT_FLIP_ROUNDS: usize = 4;

/// Flips tried per segment or face to clear nearly flat tets out of a split's way.
const MAX_UNBLOCK: usize = 64;

/// Most tets a Steiner point's cavity grows to ([`Cdt::grown_star`]).
const GROW_LIMIT: usize = 400;

/// Most tets a cavity grows to in a last round for the Steiner points that no cavity
/// within [`GROW_LIMIT`] moves off the surface. On OpenSCAD's GEB one point on an edge
/// between two coplanar facets, crowded by the points of nearby recovered segments, stayed
/// (its star 80 tets), and the fill failed without this round; since segments stop
/// being halved near an edge they cross ([`HALVING_DEPTH`]), that point is not made.
/// Only fills that would fail reach this round, and only with [`Patience::LastResort`].
const GROW_LIMIT_LAST: usize = 4_000;

/// Step lengths tried for a grown cavity's point: `reach / 2^k` for k in 2..this.
const GROW_STEPS: i32 = 40;

/// A Steiner point placed nearer than `span / 2^this` to the planes of the input faces
/// it was on (`span`: its farthest star vertex) tries a grown cavity seen from higher up
/// ([`Cdt::move_off`]): relative to the star's long edges it is still on the surface.
const TINY_STEP: i32 = 10;

/// Rounds over the Steiner points not yet moved off the surface.
const MOVE_ROUNDS: usize = 4;

/// Link tets whose centroid directions a Steiner point's move tries. A point in a
/// cospherical ring (a cylinder's cap of many facets) has thousands of link tets, and each
/// direction costs dozens of steps per try; a typical star has fewer than this.
const MAX_LINK_DIRS: usize = 32;

struct Cdt<'a> {
    dt: Delaunay,
    faces: &'a [[u32; 3]],
    /// Per sorted input edge: its chain of mesh vertices from `key[0]` to `key[1]`.
    chains: HashMap<[u32; 2], Vec<u32>>,
    /// Per input face: the Steiner points inside it.
    inner: Vec<Vec<u32>>,
    /// Sorted constraint sub-face -> its input face.
    parent: HashMap<[u32; 3], usize>,
    split: Split,
    patience: Patience,
    /// Steiner points moved off with a grown cavity.
    grown: usize,
    /// Steiner points left at a tiny step.
    tiny: Vec<u32>,
    /// Whether [`Cdt::move_off`] may grow a cavity (the last rounds only).
    grow: bool,
    /// Most tets a grown cavity may have ([`GROW_LIMIT`], then [`GROW_LIMIT_LAST`]).
    grow_limit: usize,
    /// Points that reached the round with [`GROW_LIMIT_LAST`].
    wide_cavity_points: usize,
    /// [`Stages::flipped_segments`].
    flipped_segments: usize,
    /// Whether [`Cdt::move_off`] leaves a point that only a tiny step would move off
    /// the surface on it, for a later round (every round of
    /// [`Cdt::remove_steiner_points`] but the last).
    defer_tiny: bool,
    /// Points deferred so in the current round ([`Cdt::move_round`]).
    deferred: usize,
    /// Where recovery stopped ([`Stages::stuck_near`]).
    stuck_near: Option<P3>,
}

impl<'a> Cdt<'a> {
    fn new(
        dt: Delaunay,
        faces: &'a [[u32; 3]],
        split: Split,
        patience: Patience,
    ) -> Result<Cdt<'a>, &'static str> {
        let n = dt.n;
        if faces.iter().flatten().any(|&v| v as usize >= n) {
            return Err("a face refers to a missing point");
        }
        let used: HashSet<u32> = faces.iter().flatten().copied().collect();
        if used.iter().any(|&v| dt.star(v).is_empty()) {
            return Err("two surface points coincide");
        }
        let mut dt = dt;
        for f in faces {
            for k in 0..3 {
                dt.edge_faces
                    .entry(sorted2(f[k], f[(k + 1) % 3]))
                    .or_default()
                    .push(sorted3(*f));
            }
        }
        Ok(Cdt {
            dt,
            faces,
            chains: HashMap::default(),
            inner: vec![Vec::new(); faces.len()],
            parent: HashMap::default(),
            split,
            patience,
            grown: 0,
            tiny: Vec::new(),
            grow: false,
            grow_limit: GROW_LIMIT,
            wide_cavity_points: 0,
            flipped_segments: 0,
            defer_tiny: true,
            deferred: 0,
            stuck_near: None,
        })
    }

    /// Flip the numerically flat tets out of the starting tetrahedralization, by flips
    /// that make none ([`Split::NoFlatTets`]), a few rounds while some go.
    fn flip_flat_tets(&mut self) {
        let flat = |dt: &Delaunay, t: u32| {
            dt.alive[t as usize] && numerically_flat(&dt.tets[t as usize].map(|v| dt.p(v)))
        };
        self.dt.refuse_flat = true;
        for _ in 0..FLAT_FLIP_ROUNDS {
            let list: Vec<u32> = (0..self.dt.tets.len() as u32)
                .filter(|&t| flat(&self.dt, t))
                .collect();
            let mut flipped = false;
            for t in list {
                if flat(&self.dt, t) && self.dt.flip_away(&[t]) {
                    flipped = true;
                }
            }
            if !flipped {
                break;
            }
        }
        self.dt.refuse_flat = false;
    }

    fn recover_edges(&mut self) -> Result<(), &'static str> {
        let mut edges: Vec<[u32; 2]> = self
            .faces
            .iter()
            .flat_map(|f| (0..3).map(move |k| sorted2(f[k], f[(k + 1) % 3])))
            .collect();
        edges.sort_unstable();
        edges.dedup();
        // Those already there first: fixed, later flips keep them.
        for e in &edges {
            if self.dt.has_edge(e[0], e[1]) {
                self.dt.fixed_edges.insert(*e);
                self.chains.insert(*e, e.to_vec());
            }
        }
        if self.split == Split::FlipsThenHalving {
            self.deep_flips(&edges);
        }
        for e in &edges {
            if !self.chains.contains_key(e) {
                let chain = self.recover_segment(e[0], e[1])?;
                self.chains.insert(*e, chain);
            }
        }
        Ok(())
    }

    /// [`Split::FlipsThenHalving`]'s pass: each missing segment of `edges` by recursive
    /// flips, level by level; one that comes in is fixed. The flips of a segment that
    /// does not come in are kept: none made a face or edge that segment crosses, and
    /// the next level starts from where they left it (as TetGen's rounds do). The level
    /// rises while a level brings in at least 1 in [`DEEP_FLIP_STALL`] of the missing.
    fn deep_flips(&mut self, edges: &[[u32; 2]]) {
        let mut missing: Vec<[u32; 2]> = edges
            .iter()
            .copied()
            .filter(|e| !self.chains.contains_key(e))
            .collect();
        for level in 0..=DEEP_FLIP_LEVELS {
            let before = missing.len();
            missing.retain(|&e| {
                let mut budget = DEEP_FLIP_BUDGET;
                if !self.dt.recover_edge_nm(e[0], e[1], level, &mut budget) {
                    return true;
                }
                self.dt.fixed_edges.insert(e);
                self.chains.insert(e, e.to_vec());
                false
            });
            self.flipped_segments += before - missing.len();
            if missing.is_empty() || (before - missing.len()) * DEEP_FLIP_STALL < before {
                break;
            }
        }
    }

    /// Make segment ab a chain of mesh edges: flips, else a Steiner point where the
    /// segment leaves the tet at its current end.
    fn recover_segment(&mut self, a: u32, b: u32) -> Result<Vec<u32>, &'static str> {
        let mut chain = vec![a];
        let mut cur = a;
        // The chain's next points to reach, the last first: b, and any point inserted on
        // the segment that did not join the current end.
        let mut goals = vec![b];
        let mut flips = 0;
        for _ in 0..1_000_000 {
            let Some(&goal) = goals.last() else {
                return Ok(chain);
            };
            if (self.split == Split::NoFlatTets && self.dt.recover_in_plane(cur, goal))
                || self.dt.recover_edge(cur, goal, 32)
                || self.dt.recover_edge_any(cur, goal, 32)
            {
                chain.push(goal);
                self.dt.fixed_edges.insert(sorted2(cur, goal));
                cur = goal;
                goals.pop();
                continue;
            }
            // Halving, except for a piece that halving has already cut short and that
            // crosses a mesh edge exactly: split that edge at the crossing instead.
            let short = dist(self.dt.p(cur), self.dt.p(goal))
                < dist(self.dt.p(a), self.dt.p(b)) * 0.5f64.powi(HALVING_DEPTH);
            if matches!(self.split, Split::Halving | Split::FlipsThenHalving)
                && !(short && self.crosses_an_edge(cur, goal))
            {
                if let Some(s) = self.insert_between(a, b, cur, goal) {
                    goals.push(s);
                    continue;
                }
            }
            let Some((t, k)) = self.dt.leaving(cur, goal) else {
                // Rounded Steiner points can leave no tet that the straight piece
                // leaves cur through: a point between them on the segment instead.
                let s = self.insert_between(a, b, cur, goal).ok_or_else(|| {
                    self.stuck_at(cur, "no tet leaves a segment's end toward its other end")
                })?;
                goals.push(s);
                continue;
            };
            let tv = self.dt.tets[t as usize];
            let f = FACES[k].map(|j| tv[j]);
            let fp = f.map(|v| self.dt.p(v));
            let (pc, pb) = (self.dt.p(cur), self.dt.p(goal));
            let o = [0, 1, 2].map(|e| orient3d(pc, pb, fp[e], fp[(e + 1) % 3]));
            // The new point's edge, known to the flatness test before the split.
            let next = self.dt.next_id();
            self.dt.on_line.insert(next, sorted2(a, b));
            let zeros = o.iter().filter(|&&x| x == 0).count();
            let on_edge = o.iter().position(|&x| x == 0).unwrap_or(0);
            let p = match zeros {
                0 => segment_plane(pc, pb, fp),
                1 => segment_line(pc, pb, fp[on_edge], fp[(on_edge + 1) % 3]),
                _ => return Err(self.stuck_at(cur, "a surface edge passes through a vertex")),
            };
            let split = match zeros {
                0 => {
                    // Rounded next to an edge of the face, a face split inverts a tet:
                    // split the nearest edges instead.
                    self.dt.split_face(t, k, p).or_else(|mut bad| {
                        let mut es = [0, 1, 2];
                        es.sort_by(|&i, &j| {
                            let d = |e: usize| line_dist(p, fp[e], fp[(e + 1) % 3]);
                            d(i).total_cmp(&d(j))
                        });
                        for e in es {
                            let (x, y) = (f[e], f[(e + 1) % 3]);
                            let q = segment_line(pc, pb, fp[e], fp[(e + 1) % 3]);
                            match self.dt.split_edge(x, y, q) {
                                Ok(s) => return Ok(s),
                                Err(b) => bad.extend(b),
                            }
                        }
                        Err(bad)
                    })
                }
                _ => self.dt.split_edge(f[on_edge], f[(on_edge + 1) % 3], p),
            };
            let s = match split {
                Ok(s) => s,
                Err(bad) => {
                    // Nearly flat tets in the way: flip them and walk again...
                    flips += 1;
                    if flips <= MAX_UNBLOCK && self.dt.flip_away(&bad) {
                        self.dt.on_line.remove(&next);
                        continue;
                    }
                    // ...else insert the point by Bowyer-Watson, which takes every tet
                    // around a nearby edge into its cavity.
                    match self.dt.insert_point(p) {
                        Some(s) => s,
                        None => {
                            self.dt.on_line.remove(&next);
                            // ...else a point between cur and goal, away from the face
                            // whose crossing is too near other points.
                            self.insert_between(a, b, cur, goal).ok_or_else(|| {
                                self.stuck_at(
                                    cur,
                                    "a Steiner point on a surface edge would invert a tet",
                                )
                            })?
                        }
                    }
                }
            };
            if self.dt.has_edge(cur, s) {
                self.dt.fixed_edges.insert(sorted2(cur, s));
                chain.push(s);
                cur = s;
            } else {
                goals.push(s);
            }
        }
        Err(self.stuck_at(cur, "edge recovery did not end"))
    }

    /// Note that recovery stopped at vertex `v` ([`Stages::stuck_near`]); `why` back.
    fn stuck_at(&mut self, v: u32, why: &'static str) -> &'static str {
        self.stuck_near = Some(self.dt.p(v));
        why
    }

    /// Whether segment `cur`-`goal` leaves `cur` exactly through an edge of the face it
    /// leaves by (the segment and that edge coplanar and crossing, as the two diagonals
    /// of a planar quad are).
    fn crosses_an_edge(&self, cur: u32, goal: u32) -> bool {
        let Some((t, k)) = self.dt.leaving(cur, goal) else {
            return false;
        };
        let tv = self.dt.tets[t as usize];
        let fp = FACES[k].map(|j| self.dt.p(tv[j]));
        let (pc, pb) = (self.dt.p(cur), self.dt.p(goal));
        (0..3)
            .filter(|&e| orient3d(pc, pb, fp[e], fp[(e + 1) % 3]) == 0)
            .count()
            == 1
    }

    /// Insert a point of input edge ab strictly between its points `cur` and `goal`
    /// (where [`Cdt::reference_fraction`] says, else halfway, else a quarter from either),
    /// by Bowyer-Watson: a point off every face it is rounded near, where a split at the
    /// segment's crossing would invert a tet.
    fn insert_between(&mut self, a: u32, b: u32, cur: u32, goal: u32) -> Option<u32> {
        let (pa, pb) = (self.dt.p(a), self.dt.p(b));
        let ab = sub(pb, pa);
        let len2 = dot(ab, ab);
        let param = |v: u32| dot(sub(self.dt.p(v), pa), ab) / len2;
        let (t0, t1) = (param(cur), param(goal));
        let first = self.reference_fraction(cur, goal);
        let others = if first == 0.5 {
            &[0.25, 0.75][..]
        } else {
            &[0.5, 0.25, 0.75][..]
        };
        for f in std::iter::once(first).chain(others.iter().copied()) {
            let t = t0 + f * (t1 - t0);
            let p = axpy(pa, t, ab);
            if !(t > t0.min(t1) && t < t0.max(t1)) || p == self.dt.p(cur) || p == self.dt.p(goal) {
                continue;
            }
            let next = self.dt.next_id();
            self.dt.on_line.insert(next, sorted2(a, b));
            if let Some(s) = self.dt.insert_point(p) {
                return Some(s);
            }
            self.dt.on_line.remove(&next);
        }
        None
    }

    /// Where along piece cur-goal to split it: at the projection of the vertex that sees
    /// the piece under the widest angle among the tets it crosses (TetGen's reference
    /// point), when that angle is obtuse (the vertex is in the piece's diametral ball)
    /// and the projection falls in the middle three fifths ([`REFERENCE_MARGIN`]); else
    /// halfway. The encroaching vertex is then outside both pieces' diametral balls, so
    /// that it no longer keeps them out of the tetrahedralization; a midpoint may leave it
    /// inside one and need a split more (Si, TOMS 2015, §4.2). Measured on OpenSCAD's
    /// parts that need halving (Steiner points of the recovery, halving at midpoints →
    /// here): animation 4,633 → 3,179, children 1,654 → 1,380; the CHANGELOG has the
    /// effect on the meshes.
    fn reference_fraction(&self, cur: u32, goal: u32) -> f64 {
        let (pc, pg) = (self.dt.p(cur), self.dt.p(goal));
        let d = sub(pg, pc);
        let len2 = dot(d, d);
        let mut best = (0.0f64, 0.5);
        for (t, _) in self.dt.crossed_faces(cur, goal) {
            for v in self.dt.tets[t as usize] {
                if v == cur || v == goal {
                    continue;
                }
                let p = self.dt.p(v);
                let (u, w) = (sub(pc, p), sub(pg, p));
                // Encroaching: the angle at p is obtuse; the most negative cosine wins.
                let c = dot(u, w) / (norm(u) * norm(w));
                if c < best.0 {
                    best = (c, dot(sub(p, pc), d) / len2);
                }
            }
        }
        if (REFERENCE_MARGIN..=1.0 - REFERENCE_MARGIN).contains(&best.1) {
            best.1
        } else {
            0.5
        }
    }

    /// The chain of input edge (a, b), from a to b.
    fn chain(&self, a: u32, b: u32) -> Vec<u32> {
        let mut c = self.chains.get(&sorted2(a, b)).cloned().unwrap_or_default();
        if a > b {
            c.reverse();
        }
        c
    }

    /// Split every mesh edge crossing face `i`'s interior, then fix its sub-faces.
    fn recover_face(&mut self, i: usize) -> Result<(), &'static str> {
        let f = self.faces[i];
        let fp = f.map(|v| self.dt.p(v));
        let mut on: HashSet<u32> = HashSet::default();
        let mut rim: HashSet<[u32; 2]> = HashSet::default();
        for k in 0..3 {
            let ch = self.chain(f[k], f[(k + 1) % 3]);
            for w in ch.windows(2) {
                rim.insert(sorted2(w[0], w[1]));
            }
            on.extend(ch);
        }
        on.extend(self.inner[i].iter().copied());
        let side = |dt: &Delaunay, on: &HashSet<u32>, v: u32| {
            if on.contains(&v) {
                0
            } else {
                orient3d(fp[0], fp[1], fp[2], dt.p(v))
            }
        };
        let mut flips = 0;
        loop {
            let mut near: Vec<u32> = on.iter().flat_map(|&v| self.dt.star(v)).collect();
            near.sort_unstable();
            near.dedup();
            let mut crossing = None;
            'find: for &t in &near {
                let tv = self.dt.tets[t as usize];
                for a in 0..4 {
                    for b in a + 1..4 {
                        let (u, v) = (tv[a], tv[b]);
                        let (su, sv) = (side(&self.dt, &on, u), side(&self.dt, &on, v));
                        if su * sv >= 0 {
                            continue;
                        }
                        let (pu, pv) = (self.dt.p(u), self.dt.p(v));
                        let o = [0, 1, 2].map(|e| orient3d(pu, pv, fp[e], fp[(e + 1) % 3]));
                        if o.iter().all(|&x| x > 0) || o.iter().all(|&x| x < 0) {
                            crossing = Some((u, v));
                            break 'find;
                        }
                    }
                }
            }
            let Some((u, v)) = crossing else {
                // A nearly flat tet with all four points on the face (rounded Steiner
                // points): flip it away and look again.
                let flat: Vec<u32> = near
                    .iter()
                    .copied()
                    .filter(|&t| self.dt.tets[t as usize].iter().all(|v| on.contains(v)))
                    .collect();
                if flat.is_empty() {
                    break;
                }
                flips += 1;
                if flips <= MAX_UNBLOCK && self.dt.flip_away(&flat) {
                    continue;
                }
                return Err("a flat tet lies in a surface triangle");
            };
            let (pu, pv) = (self.dt.p(u), self.dt.p(v));
            let p = segment_plane(pu, pv, fp);
            let next = self.dt.next_id();
            self.dt.on_face.insert(next, sorted3(f));
            let s = match self.dt.split_edge(u, v, p) {
                Ok(s) => s,
                Err(bad) => {
                    flips += 1;
                    if flips <= MAX_UNBLOCK && self.dt.flip_away(&bad) {
                        self.dt.on_face.remove(&next);
                        continue;
                    }
                    match self.dt.insert_point(p) {
                        Some(s) => s,
                        None => {
                            self.dt.on_face.remove(&next);
                            return Err("a Steiner point in a surface triangle would invert a tet");
                        }
                    }
                }
            };
            on.insert(s);
            self.inner[i].push(s);
        }
        // The sub-faces: mesh faces on `on` points only; a disk with the rim as boundary.
        let mut near: Vec<u32> = on.iter().flat_map(|&v| self.dt.star(v)).collect();
        near.sort_unstable();
        near.dedup();
        let mut subs: HashSet<[u32; 3]> = HashSet::default();
        for &t in &near {
            let tv = self.dt.tets[t as usize];
            if tv.iter().all(|v| on.contains(v)) {
                return Err("a flat tet lies in a surface triangle");
            }
            for fk in FACES {
                let g = fk.map(|j| tv[j]);
                if g.iter().all(|v| on.contains(v)) {
                    subs.insert(sorted3(g));
                }
            }
        }
        let mut uses: HashMap<[u32; 2], u32> = HashMap::default();
        for g in &subs {
            for k in 0..3 {
                *uses.entry(sorted2(g[k], g[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        let disk = uses
            .iter()
            .all(|(e, &n)| n == if rim.contains(e) { 1 } else { 2 })
            && rim.iter().all(|e| uses.contains_key(e));
        if !disk {
            return Err("a surface triangle is not recovered as a disk of faces");
        }
        for g in subs {
            for k in 0..3 {
                self.dt.fixed_edges.insert(sorted2(g[k], g[(k + 1) % 3]));
            }
            self.dt.fixed_faces.insert(g);
            if self.parent.insert(g, i).is_some_and(|j| j != i) {
                return Err("two surface triangles share a recovered face");
            }
        }
        Ok(())
    }

    /// Keep the tets the constraint faces enclose (odd parity from the enclosing points),
    /// checking that each constraint face has the region on its positive side.
    fn keep_enclosed(&mut self) -> Result<(), &'static str> {
        let nt = self.dt.tets.len();
        let far = self.dt.n as u32..self.dt.n as u32 + 4;
        let start = (0..nt)
            .find(|&t| self.dt.alive[t] && self.dt.tets[t].iter().any(|v| far.contains(v)))
            .ok_or("no outer tet")?;
        let mut state = vec![0u8; nt]; // 0 unknown, 1 outside, 2 inside
        state[start] = 1;
        let mut stack = vec![start as u32];
        while let Some(t) = stack.pop() {
            let tv = self.dt.tets[t as usize];
            for (k, fk) in FACES.iter().enumerate() {
                let nb = self.dt.adj[t as usize][k];
                if nb == NONE {
                    continue;
                }
                let wall = self.dt.fixed_faces.contains(&sorted3(fk.map(|j| tv[j])));
                let s = state[t as usize];
                let want = if wall { 3 - s } else { s };
                match state[nb as usize] {
                    0 => {
                        state[nb as usize] = want;
                        stack.push(nb);
                    }
                    x if x != want => return Err("the surface does not enclose consistently"),
                    _ => {}
                }
            }
        }
        for (t, &st) in state.iter().enumerate() {
            if !self.dt.alive[t] || st != 2 {
                continue;
            }
            let tv = self.dt.tets[t];
            if tv.iter().any(|v| far.contains(v)) {
                return Err("the surface does not enclose the region");
            }
            for fk in FACES {
                let g = fk.map(|j| tv[j]);
                if self.parent.contains_key(&sorted3(g)) {
                    // The region must be on the face's positive side: its outward face
                    // (g) turns against the input face in the input face's plane.
                    let i = self.parent[&sorted3(g)];
                    let f = self.faces[i].map(|v| self.dt.p(v));
                    let (proj, sign) =
                        projection_of(f[0], f[1], f[2]).ok_or("degenerate triangle")?;
                    let gp = g.map(|v| self.dt.p(v));
                    // Or the tet's apex on the face's positive side: either test alone
                    // can be turned by rounded Steiner points (a thin sub-face, an apex
                    // nearly in the plane), a face that faces away fails both.
                    let apex = tv.iter().find(|v| !g.contains(v)).map(|&v| self.dt.p(v));
                    let above = apex.is_some_and(|d| orient3d(f[0], f[1], f[2], d) > 0);
                    if proj.orient2d(gp[0], gp[1], gp[2]) != -sign && !above {
                        return Err("a surface triangle faces away from the region");
                    }
                }
            }
        }
        for (alive, &st) in self.dt.alive.iter_mut().zip(&state) {
            if st != 2 {
                *alive = false;
            }
        }
        for t in 0..nt {
            if self.dt.alive[t] {
                for k in 0..4 {
                    let nb = self.dt.adj[t][k];
                    if nb != NONE && !self.dt.alive[nb as usize] {
                        self.dt.adj[t][k] = NONE;
                    }
                }
            }
        }
        self.dt.rebuild_vt();
        self.dt.compact();
        Ok(())
    }

    fn remove_steiner_points(&mut self) -> Result<(), &'static str> {
        let first = self.dt.n as u32 + 4;
        let last = self.dt.pts.len() as u32;
        // How many input faces use each input edge (2, or 4 where two pockets touch).
        let mut edge_faces: HashMap<[u32; 2], usize> = HashMap::default();
        for f in self.faces {
            for k in 0..3 {
                *edge_faces.entry(sorted2(f[k], f[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        let mut on_edge: HashMap<u32, usize> = HashMap::default();
        for (e, ch) in &self.chains {
            for &v in &ch[1..ch.len() - 1] {
                on_edge.insert(v, edge_faces.get(e).copied().unwrap_or(2));
            }
        }
        // Each point's pockets left to move it off (2 where two pockets touch at an edge).
        let mut left: Vec<(u32, usize)> = (first..last)
            .map(|s| (s, on_edge.get(&s).copied().unwrap_or(1)))
            .collect();
        // A point whose new star has no kernel yet may get one once its neighbours have
        // moved: a few rounds over those left. Then, for those still left, the same
        // with grown cavities ([`Cdt::grown_star`]): their search costs more, and a point
        // that would move in a later round does not pay it.
        let give_up = match self.patience {
            Patience::Exhaustive | Patience::LastResort => usize::MAX,
            Patience::GiveUpEarly => GIVE_UP_STUCK + left.len() * GIVE_UP_PER_MILLE / 1000,
        };
        let mut first_round = true;
        for grow in [false, true] {
            self.grow = grow;
            for _ in 0..MOVE_ROUNDS {
                if left.is_empty() {
                    break;
                }
                let stuck =
                    self.move_round(&left, if first_round { give_up } else { usize::MAX })?;
                first_round = false;
                let progress = stuck.len() < left.len();
                left = stuck;
                if !progress {
                    break;
                }
            }
        }
        // The points deferred at a tiny step (and any still stuck): one more round that
        // leaves them there where nothing better is found.
        self.defer_tiny = false;
        left = self.move_round(&left, usize::MAX)?;
        // The points still left: one round with far larger cavities, where no other way
        // follows.
        self.wide_cavity_points = left.len();
        if self.patience == Patience::LastResort {
            self.grow_limit = GROW_LIMIT_LAST;
            left = self.move_round(&left, usize::MAX)?;
        }
        if left.is_empty() {
            Ok(())
        } else {
            Err("no interior point sees a Steiner point's star")
        }
    }

    /// One round of [`Cdt::remove_one`] over the points `left` (each with its pockets);
    /// returns those still on the surface, or Err once more than `give_up` of them have
    /// stayed (points deferred at a tiny step not counted).
    fn move_round(
        &mut self,
        left: &[(u32, usize)],
        give_up: usize,
    ) -> Result<Vec<(u32, usize)>, &'static str> {
        let mut stuck = Vec::new();
        self.deferred = 0;
        for &(s, n) in left {
            let n = self.remove_one(s, n)?;
            if n > 0 {
                stuck.push((s, n));
                if stuck.len().saturating_sub(self.deferred) > give_up {
                    return Err("too many Steiner points stay on the surface");
                }
            }
        }
        Ok(stuck)
    }

    /// Move Steiner point `s` off the surface in each of its `pockets`; returns how many
    /// are left (its new star there has no kernel).
    fn remove_one(&mut self, s: u32, pockets: usize) -> Result<usize, &'static str> {
        let mut left = pockets;
        let mut seen: HashSet<u32> = HashSet::default();
        let mut failed = 0;
        while left > failed {
            let star = self.dt.star(s);
            let star = if star.iter().any(|t| seen.contains(t)) || star.is_empty() {
                // Another pocket at this point: its tets are not linked to the first.
                (0..self.dt.tets.len() as u32)
                    .filter(|&t| {
                        self.dt.alive[t as usize]
                            && self.dt.tets[t as usize].contains(&s)
                            && !seen.contains(&t)
                    })
                    .collect::<Vec<_>>()
            } else {
                star
            };
            if star.is_empty() {
                // Every pocket tried: those that failed are left for the next round.
                return Ok(if self.dt.star(s).is_empty() { 0 } else { left });
            }
            let mut comp = self.component(s, &star);
            let mut moved = None;
            // With grown cavities (the last rounds), the flips were already tried.
            let unblocks = if self.grow { 0 } else { MAX_UNBLOCK };
            for attempt in 0..=unblocks {
                if attempt > 0 {
                    let star = self.dt.star(s);
                    if star.is_empty() {
                        break;
                    }
                    comp = self.component(s, &star);
                }
                match self.move_off(s, &comp, attempt < unblocks)? {
                    Some(0) => continue,
                    Some(usize::MAX) => {
                        moved = self.move_off(s, &comp, false)?;
                        break;
                    }
                    g => {
                        moved = g;
                        break;
                    }
                }
            }
            seen.extend(comp.iter().copied());
            match moved {
                Some(g) => left = left.saturating_sub(g),
                None => failed += 1,
            }
        }
        Ok(left)
    }

    /// The tets of `star` (all containing `s`) linked to its first through faces at `s`.
    fn component(&self, s: u32, star: &[u32]) -> Vec<u32> {
        let set: HashSet<u32> = star.iter().copied().collect();
        self.dt.walk_around(s, star[0], |t| set.contains(&t))
    }

    /// Move Steiner point `s` off the surface within the tets `comp` around it. Returns
    /// how many surface triangles it was on there, or None (nothing changed) when no
    /// point sees its new star. With `unblock`, such a point makes it flip the link tets
    /// in the way instead and return 0 (or usize::MAX when no flip applies).
    fn move_off(
        &mut self,
        s: u32,
        comp: &[u32],
        unblock: bool,
    ) -> Result<Option<usize>, &'static str> {
        // The constraint faces at s, outward, grouped by input face: edges x -> y of
        // the faces (s, x, y).
        let mut groups: BTreeMap<usize, Vec<[u32; 2]>> = BTreeMap::new();
        let mut link: Vec<[u32; 4]> = Vec::new();
        for &t in comp {
            let tv = self.dt.tets[t as usize];
            let ks = tv.iter().position(|&v| v == s).ok_or("star")?;
            link.push(tv);
            for (k, fk) in FACES.iter().enumerate() {
                if k == ks || self.dt.adj[t as usize][k] != NONE {
                    continue;
                }
                let g = fk.map(|j| tv[j]);
                let i = *self
                    .parent
                    .get(&sorted3(g))
                    .ok_or("a boundary face that is no surface triangle")?;
                let r = (0..3).find(|&m| g[m] == s).unwrap_or(0);
                groups
                    .entry(i)
                    .or_default()
                    .push([g[(r + 1) % 3], g[(r + 2) % 3]]);
            }
        }
        if groups.is_empty() {
            return Err("a Steiner point inside the region"); // (never placed there)
        }
        let mut new_faces: Vec<([u32; 3], usize)> = Vec::new();
        let mut inward = [0.0; 3];
        for (&i, edges) in &groups {
            let f = self.faces[i].map(|v| self.dt.p(v));
            // The input face's positive side is the region's.
            let nrm = tri_normal(f[0], f[1], f[2]);
            let l = norm(nrm).max(f64::MIN_POSITIVE);
            inward = axpy(inward, 1.0 / l, nrm);
            let poly = polygon(edges).ok_or("the faces at a Steiner point are no fan")?;
            let (proj, sign) = projection_of(f[0], f[1], f[2]).ok_or("degenerate triangle")?;
            // Outward faces turn the other way from the input face.
            let tris = triangulate_polygon(
                &poly,
                |a, b, c| {
                    !self.dt.collinear_by_construction([a, b, c])
                        && proj.orient2d(self.dt.p(a), self.dt.p(b), self.dt.p(c)) == -sign
                },
                |a, b, c| tri_shape(self.dt.p(a), self.dt.p(b), self.dt.p(c)),
            )
            .ok_or("the faces at a Steiner point cannot be retriangulated")?;
            new_faces.extend(tris.into_iter().map(|t| (t, i)));
        }
        // How far a point is off the surface here: its distance to the nearest plane of
        // the input faces at `s`.
        let planes: Vec<[P3; 3]> = groups
            .keys()
            .map(|&i| self.faces[i].map(|v| self.dt.p(v)))
            .collect();
        let height = |p: P3| {
            planes
                .iter()
                .map(|f| {
                    let n = norm(tri_normal(f[0], f[1], f[2])).max(f64::MIN_POSITIVE);
                    tet_det(f[0], f[1], f[2], p).abs() / n
                })
                .fold(f64::INFINITY, f64::min)
        };
        let ps = self.dt.p(s);
        // The nearest and the farthest star vertex.
        let (reach, span) = link
            .iter()
            .flatten()
            .filter(|&&v| v != s)
            .map(|&v| dist(ps, self.dt.p(v)))
            .fold((f64::INFINITY, 0.0f64), |(lo, hi), d| {
                (lo.min(d), hi.max(d))
            });
        let centre = {
            let vs: Vec<P3> = link
                .iter()
                .flatten()
                .filter(|&&v| v != s)
                .map(|&v| self.dt.p(v))
                .collect();
            let k = vs.len().max(1) as f64;
            let c = vs.iter().fold([0.0; 3], |a, &p| axpy(a, 1.0 / k, p));
            sub(c, ps)
        };
        let q = self.dt.add_point(ps);
        let mut tets: Vec<[u32; 4]> = link
            .iter()
            .map(|tv| tv.map(|v| if v == s { q } else { v }))
            .collect();
        tets.extend(new_faces.iter().map(|(g, _)| [g[0], g[2], g[1], q]));
        // Candidate directions: the inward normal, toward the star's centre, toward each
        // link tet's centroid (at most [`MAX_LINK_DIRS`] of them, evenly spread).
        let mut dirs = vec![inward, centre];
        for tv in link
            .iter()
            .step_by(link.len().div_ceil(MAX_LINK_DIRS).max(1))
        {
            let c = tv
                .iter()
                .filter(|&&v| v != s)
                .fold([0.0; 3], |a, &v| axpy(a, 1.0 / 3.0, self.dt.p(v)));
            dirs.push(sub(c, ps));
        }
        // Best: the centre of the largest ball in the new star's kernel (each new tet
        // positive is one half-space for the point); else small steps along `dirs`.
        let walls = self.walls(&tets, q);
        // Whether every new tet is positive, testing first the one that failed last: a
        // step along a direction mostly fails on the same tet, so most candidates cost
        // one orientation test instead of one per tet (on OpenSCAD's example012 these
        // tests were three quarters of the whole run). The answer does not depend on the
        // order.
        let mut last_bad = 0;
        let mut all_positive = |dt: &Delaunay| {
            if !dt.positive(tets[last_bad]) {
                return false;
            }
            match tets.iter().position(|&t| !dt.positive(t)) {
                Some(i) => {
                    last_bad = i;
                    false
                }
                None => true,
            }
        };
        let mut placed = false;
        if let Some(c) = kernel_centre(&walls, ps) {
            self.dt.pts[q as usize] = c;
            placed = all_positive(&self.dt);
        }
        'dirs: for d in dirs {
            if placed {
                break;
            }
            let l = norm(d);
            if l.is_nan() || l <= 0.0 || !reach.is_finite() {
                continue;
            }
            for k in 1..60 {
                let p = axpy(ps, reach * 0.5f64.powi(k) / l, d);
                self.dt.pts[q as usize] = p;
                if all_positive(&self.dt) {
                    placed = true;
                    break 'dirs;
                }
            }
        }
        if !placed && unblock {
            // Flip the link tets the inward step inverts, and try again.
            let l = norm(inward);
            if l > 0.0 && reach.is_finite() {
                self.dt.pts[q as usize] = axpy(ps, reach * 1e-6 / l, inward);
            }
            let bad: Vec<u32> = comp
                .iter()
                .zip(&tets)
                .filter(|(_, &t)| !self.dt.positive(t))
                .map(|(&t, _)| t)
                .collect();
            self.dt.pop_point();
            return Ok(Some(if self.dt.flip_away(&bad) {
                0
            } else {
                usize::MAX
            }));
        }
        let mut cavity = comp.to_vec();
        // Only a point a tiny height off the surface (relative to the star's longest
        // reach, not the shortest: Steiner points on one segment crowd each other) sees
        // the star: kept there, it would leave nearly flat tets at the surface that the
        // linear stage cannot lift. The height, not the step: a kernel centre can lie
        // far along the surface and a hair above it. A grown cavity seen from higher up
        // is taken instead where there is one.
        let limit = span * 0.5f64.powi(TINY_STEP);
        let at_tiny_step = self.dt.pts[q as usize];
        let tiny = placed && height(at_tiny_step) < limit;
        if tiny || (!placed && !unblock && self.grow) {
            // No point sees the star itself (a tet of it is nearly flat at `s`, so every
            // inward step crosses its far face): a larger cavity that some point near
            // `s` sees.
            let faces: Vec<[u32; 4]> = tets[link.len()..].to_vec();
            let steps = if tiny {
                2..TINY_STEP + 1
            } else {
                2..GROW_STEPS
            };
            // The smallest such cavity over the candidate points.
            let mut best: Option<(P3, Vec<u32>, Vec<[u32; 4]>)> = None;
            let base = if tiny { span } else { reach };
            for d in [inward, centre] {
                let l = norm(d);
                if l.is_nan() || l <= 0.0 || !base.is_finite() || base <= 0.0 {
                    continue;
                }
                for k in steps.clone() {
                    let p = axpy(ps, base * 0.5f64.powi(k) / l, d);
                    self.dt.pts[q as usize] = p;
                    // Only a cavity smaller than the best so far can replace it: growing
                    // one stops past that size.
                    let most = best.as_ref().map_or(self.grow_limit, |b| b.1.len() - 1);
                    if let Some((cav, new)) = self.grown_star(s, q, comp, &faces, most) {
                        if best.as_ref().map_or(true, |b| cav.len() < b.1.len()) {
                            best = Some((p, cav, new));
                        }
                    }
                }
            }
            if let Some((p, cav, new)) = best {
                // The smallest cavity is seen from very near `s` (down to 2^-39 of the
                // reach), which leaves nearly flat tets at the surface; the centre of the
                // largest ball in the grown star's kernel is as far in as it can be.
                let p = kernel_centre(&self.walls(&new, q), p).unwrap_or(p);
                self.dt.pts[q as usize] = p;
                cavity = cav;
                tets = new;
                placed = true;
                self.grown += 1;
            } else if tiny {
                if self.defer_tiny {
                    // Left on the surface until the last round: its neighbours on the
                    // same face may move off meanwhile, and a point a tiny step off it
                    // would pin them to the surface too.
                    self.deferred += 1;
                    self.dt.pop_point();
                    return Ok(None);
                }
                self.dt.pts[q as usize] = at_tiny_step;
            }
        }
        if tiny && self.dt.pts[q as usize] == at_tiny_step && dist(at_tiny_step, ps) < limit {
            self.tiny.push(q);
        }
        if !placed {
            self.dt.pop_point();
            return Ok(None);
        }
        self.dt.replace(&cavity, &tets);
        for (g, i) in new_faces {
            for k in 0..3 {
                self.dt.fixed_edges.insert(sorted2(g[k], g[(k + 1) % 3]));
            }
            self.dt.fixed_faces.insert(sorted3(g));
            self.parent.insert(sorted3(g), i);
        }
        Ok(Some(groups.len()))
    }

    /// The faces of tets `tets` opposite their vertex `q`, turned so that `q` is on
    /// their positive side when the tet is positive: the walls of `q`'s star, as
    /// [`kernel_centre`] takes them.
    fn walls(&self, tets: &[[u32; 4]], q: u32) -> Vec<[P3; 3]> {
        tets.iter()
            .map(|t| {
                let f = opposite(t, q);
                [f[0], f[2], f[1]].map(|v| self.dt.p(v))
            })
            .collect()
    }

    /// The cavity that the new point `q` (at its current position) sees, grown from the
    /// tets `comp` around Steiner point `s`, and the tets joining `q` to its faces and to
    /// the retriangulated surface faces `faces` (as tets with `q`). Each cavity face `q`
    /// does not see strictly (positively) is crossed into the tet behind it, Bowyer-Watson
    /// fashion, until `q` sees them all: the cavity is then star-shaped from `q`, so the
    /// new tets fill it. None where the face to cross is a surface face, the tet behind it
    /// has `s` (another pocket), the cavity grows past `most` tets (at most
    /// [`Cdt::grow_limit`]), or `q` is not strictly inside `faces`; interior points the
    /// cavity swallows are dropped.
    fn grown_star(
        &self,
        s: u32,
        q: u32,
        comp: &[u32],
        faces: &[[u32; 4]],
        most: usize,
    ) -> Option<(Vec<u32>, Vec<[u32; 4]>)> {
        if !faces.iter().all(|&t| self.dt.positive(t)) {
            return None;
        }
        let mut cavity: Vec<u32> = comp.to_vec();
        // (Only orientation tests below: no star walk needs the marks meanwhile.)
        let mut inside = self.dt.tet_marks();
        inside.clear_for(self.dt.tets.len());
        for &t in &cavity {
            inside.insert(t);
        }
        // The faces at `s` are inside the star or are the surface faces `faces` replace.
        let at_s = |tv: [u32; 4], k: usize| tv[k] != s && tv.contains(&s);
        // Each face is tested when its tet joins; a face seen stays seen, or becomes
        // inner when the tet behind it joins later.
        let mut todo: Vec<(u32, usize)> = cavity
            .iter()
            .flat_map(|&t| (0..4).map(move |k| (t, k)))
            .collect();
        while let Some((t, k)) = todo.pop() {
            let tv = self.dt.tets[t as usize];
            let nb = self.dt.adj[t as usize][k];
            if at_s(tv, k) || (nb != NONE && inside.contains(nb)) {
                continue;
            }
            let mut nt = tv;
            nt[k] = q;
            if self.dt.positive(nt) {
                continue;
            }
            if nb == NONE || self.dt.tets[nb as usize].contains(&s) {
                return None;
            }
            inside.insert(nb);
            cavity.push(nb);
            if cavity.len() > most {
                return None;
            }
            todo.extend((0..4).map(|k| (nb, k)));
        }
        let mut new = Vec::new();
        for &t in &cavity {
            let tv = self.dt.tets[t as usize];
            for k in 0..4 {
                let nb = self.dt.adj[t as usize][k];
                if !at_s(tv, k) && (nb == NONE || !inside.contains(nb)) {
                    let mut nt = tv;
                    nt[k] = q;
                    new.push(nt);
                }
            }
        }
        // Interior points the cavity swallows are left out (in no tet; the result keeps
        // only the points tets use): every surface point has a surface face, which stays
        // a cavity face.
        new.extend_from_slice(faces);
        // The new tets tile the cavity when its boundary is a closed surface (every edge
        // on two faces, once each way) and they take its volume (a boundary pinched at a
        // vertex can wind twice around `q`).
        let vol = |t: &[u32; 4]| {
            let p = t.map(|v| self.dt.p(v));
            tet_det(p[0], p[1], p[2], p[3]).abs()
        };
        let (was, now): (f64, f64) = (
            cavity.iter().map(|&t| vol(&self.dt.tets[t as usize])).sum(),
            new.iter().map(vol).sum(),
        );
        let bases = new.iter().map(|t| opposite(t, q));
        let closed = closes_up(bases) && (was - now).abs() <= 1e-9 * was.max(now);
        closed.then_some((cavity, new))
    }

    /// Remove the points off the surface that numerically flat tets use, where joining one
    /// to a neighbour leaves fewer such tets (an edge contraction; every new tet positive
    /// and the star tiled exactly), a few rounds while some point goes.
    fn contract_flat(&mut self) {
        let surface: HashSet<u32> = self.faces.iter().flatten().copied().collect();
        let mut gone: HashSet<u32> = HashSet::default();
        for _ in 0..CONTRACT_ROUNDS {
            let flat: Vec<u32> = (0..self.dt.tets.len() as u32)
                .filter(|&t| {
                    self.dt.alive[t as usize]
                        && numerically_flat(&self.dt.tets[t as usize].map(|v| self.dt.p(v)))
                })
                .collect();
            let mut changed = 0;
            for t in flat {
                if !self.dt.alive[t as usize] {
                    continue;
                }
                let tv = self.dt.tets[t as usize];
                for q in tv {
                    if surface.contains(&q) || gone.contains(&q) {
                        continue;
                    }
                    if self.contract_point(q) {
                        gone.insert(q);
                        changed += 1;
                        break;
                    }
                }
            }
            if changed == 0 {
                break;
            }
        }
    }

    /// [`Cdt::contract_point_by`] for fewer numerically flat tets.
    fn contract_point(&mut self, q: u32) -> bool {
        self.contract_point_by(q, false)
    }

    /// Points off the surface added by the recovery (Steiner points) that a tet with a
    /// dihedral angle below [`SLIVER_CONTRACT_DEG`] uses: contracted into the neighbour
    /// that raises their star's smallest dihedral angle most, without more numerically
    /// flat tets; a few rounds while some point goes.
    fn contract_slivers(&mut self) {
        // Steiner points come after the input points and the four enclosing ones; none
        // is on the surface (every one has been moved off it).
        let first_steiner = self.dt.n as u32 + 4;
        for _ in 0..CONTRACT_ROUNDS {
            let mut cand: Vec<u32> = Vec::new();
            for t in 0..self.dt.tets.len() {
                let tv = self.dt.tets[t];
                if !self.dt.alive[t] || tv.iter().all(|&v| v < first_steiner) {
                    continue;
                }
                let c = tv.map(|v| self.dt.p(v));
                if numerically_flat(&c) || dihedral_extremes(&c).0 < SLIVER_CONTRACT_DEG {
                    cand.extend(tv.iter().copied().filter(|&v| v >= first_steiner));
                }
            }
            cand.sort_unstable();
            cand.dedup();
            let mut changed = 0;
            for q in cand {
                // (A point contracted earlier in the round has no star.)
                if !self.dt.star(q).is_empty() && self.contract_point_by(q, true) {
                    changed += 1;
                }
            }
            if changed == 0 {
                break;
            }
        }
    }

    /// Contract point `q` (off the surface) into the star neighbour that leaves the fewest
    /// numerically flat tets, then the largest smallest dihedral angle, where that leaves
    /// fewer flat tets than its star has or (`by_angle`) no more and a larger smallest
    /// angle; false (nothing changed) when none does.
    fn contract_point_by(&mut self, q: u32, by_angle: bool) -> bool {
        let star = self.dt.star(q);
        let old: Vec<[u32; 4]> = star.iter().map(|&t| self.dt.tets[t as usize]).collect();
        let shape = |dt: &Delaunay, tets: &[[u32; 4]]| {
            let mut flat = 0usize;
            let mut lo = f64::INFINITY;
            for t in tets {
                let c = t.map(|v| dt.p(v));
                if numerically_flat(&c) {
                    flat += 1;
                } else {
                    lo = lo.min(dihedral_extremes(&c).0);
                }
            }
            (flat, lo)
        };
        let (flat0, lo0) = shape(&self.dt, &old);
        // The star's outer faces.
        let outer: HashSet<[u32; 3]> = old.iter().map(|t| sorted3(opposite(t, q))).collect();
        let mut nbrs: Vec<u32> = old.iter().flatten().copied().filter(|&v| v != q).collect();
        nbrs.sort_unstable();
        nbrs.dedup();
        let mut best: Option<(usize, f64, Vec<[u32; 4]>)> = None;
        for w in nbrs {
            let new: Vec<[u32; 4]> = old
                .iter()
                .filter(|t| !t.contains(&w))
                .map(|t| t.map(|v| if v == q { w } else { v }))
                .collect();
            if new.is_empty() || !new.iter().all(|&t| self.dt.positive(t)) {
                continue;
            }
            let (flat, lo) = shape(&self.dt, &new);
            let worse = if by_angle {
                flat > flat0 || (flat == flat0 && lo <= lo0)
            } else {
                flat >= flat0
            };
            if worse || best.as_ref().is_some_and(|b| (flat, -lo) >= (b.0, -b.1)) {
                continue;
            }
            if self.tiles(&outer, q, &new) {
                best = Some((flat, lo, new));
            }
        }
        let Some((_, _, new)) = best else {
            return false;
        };
        self.dt.replace(&star, &new);
        true
    }

    /// Whether the positive tets `new` tile the star of `q` whose outer faces are
    /// `outer`: each face on two new tets, on opposite sides of it, or on one and an
    /// outer face, on the side `q` is (then the tets' boundary is the star's, and
    /// positive tets with that boundary cover it once).
    fn tiles(&self, outer: &HashSet<[u32; 3]>, q: u32, new: &[[u32; 4]]) -> bool {
        let mut apex: HashMap<[u32; 3], Vec<u32>> = HashMap::default();
        for t in new {
            for (k, fk) in FACES.iter().enumerate() {
                apex.entry(sorted3(fk.map(|j| t[j])))
                    .or_default()
                    .push(t[k]);
            }
        }
        let side = |f: &[u32; 3], x: u32| {
            let p = f.map(|v| self.dt.p(v));
            orient3d(p[0], p[1], p[2], self.dt.p(x))
        };
        let mut on_outer = 0;
        for (f, xs) in &apex {
            match (xs.as_slice(), outer.contains(f)) {
                ([x], true) => {
                    if side(f, *x) != side(f, q) {
                        return false;
                    }
                    on_outer += 1;
                }
                ([x, y], false) => {
                    if side(f, *x) * side(f, *y) >= 0 {
                        return false;
                    }
                }
                _ => return false,
            }
        }
        on_outer == outer.len()
    }

    /// Where a tet on a surface face is thin (a dihedral angle below [`LIFT_BELOW_DEG`]:
    /// two surface triangles at a shallow fold, or an apex on the surface elsewhere),
    /// insert a point above the face, at the height an equilateral
    /// tet on it would have, capped by `height` at the face's centroid, as a front would
    /// place it. The point goes in by [`Delaunay::insert_point`], whose cavity never
    /// crosses a surface face; it is skipped where it would not lie strictly inside the
    /// region or would crowd a vertex.
    fn lift_flat_tets(&mut self, height: &dyn Fn(P3) -> f64) {
        for _ in 0..LIFT_ROUNDS {
            // (tet, the point above its face, the height)
            let mut targets: Vec<(u32, P3, f64)> = Vec::new();
            for t in 0..self.dt.tets.len() {
                if !self.dt.alive[t] {
                    continue;
                }
                let tv = self.dt.tets[t];
                if !self.dt.adj[t].contains(&NONE) {
                    continue;
                }
                if dihedral_extremes(&tv.map(|v| self.dt.p(v))).0 >= LIFT_BELOW_DEG {
                    continue;
                }
                for (k, fk) in FACES.iter().enumerate() {
                    if self.dt.adj[t][k] != NONE {
                        continue;
                    }
                    let f = fk.map(|j| self.dt.p(tv[j]));
                    let n = tri_normal(f[0], f[1], f[2]);
                    let nn = norm(n);
                    if nn.is_nan() || nn <= 0.0 {
                        continue;
                    }
                    let n = n.map(|x| x / nn);
                    // Inward: the side the apex is on (the tet is positive).
                    let inward = if dot(n, sub(self.dt.p(tv[k]), f[0])) > 0.0 {
                        1.0
                    } else {
                        -1.0
                    };
                    let mean = (dist(f[0], f[1]) + dist(f[1], f[2]) + dist(f[2], f[0])) / 3.0;
                    let c = [0, 1, 2].map(|i| (f[0][i] + f[1][i] + f[2][i]) / 3.0);
                    // An equilateral tet's height: sqrt(2/3) of its edge.
                    let h = (0.8165 * mean).min(height(c));
                    if h.is_nan() || h <= 0.0 {
                        continue;
                    }
                    targets.push((t as u32, axpy(c, inward * h, n), h));
                }
            }
            let mut added = 0;
            for (t, p, h) in targets {
                if !self.dt.alive[t as usize] {
                    continue;
                }
                // The walk starts at the tet on the face, which p is above.
                let s = self.dt.locate_from(t, p);
                let sv = self.dt.tets[s as usize];
                let inside = self.dt.alive[s as usize]
                    && FACES.iter().enumerate().all(|(k, fk)| {
                        let g = fk.map(|j| self.dt.p(sv[j]));
                        let o = orient3d(g[0], g[1], g[2], p);
                        o < 0 || (o == 0 && self.dt.adj[s as usize][k] != NONE)
                    });
                let crowded = sv.iter().any(|&v| dist(self.dt.p(v), p) < 0.3 * h);
                if inside && !crowded && self.dt.insert_point_taking(s, p, Some(t)).is_some() {
                    added += 1;
                }
            }
            if added == 0 {
                break;
            }
        }
    }

    fn result(&self) -> Result<Filled, &'static str> {
        let n = self.dt.n;
        let first = n as u32 + 4;
        let mut map: HashMap<u32, u32> = HashMap::default();
        let mut pts: Vec<P3> = self.dt.pts[..n].to_vec();
        let mut tets = Vec::new();
        let mut bound: HashSet<[u32; 3]> = HashSet::default();
        for t in 0..self.dt.tets.len() {
            if !self.dt.alive[t] {
                continue;
            }
            let tv = self.dt.tets[t];
            if !self.dt.positive(tv) {
                return Err("a tet is not positive");
            }
            for (k, fk) in FACES.iter().enumerate() {
                if self.dt.adj[t][k] == NONE {
                    let g = fk.map(|j| tv[j]);
                    // Outward: the input face reversed, as a rotation-free key.
                    bound.insert(canon([g[0], g[2], g[1]]));
                }
            }
            let mut out = [0; 4];
            for (o, &v) in out.iter_mut().zip(&tv) {
                *o = if (v as usize) < n {
                    v
                } else if v >= first {
                    if self.dt.on_line.contains_key(&v) || self.dt.on_face.contains_key(&v) {
                        return Err("a Steiner point stayed on the surface");
                    }
                    *map.entry(v).or_insert_with(|| {
                        pts.push(self.dt.pts[v as usize]);
                        (pts.len() - 1) as u32
                    })
                } else {
                    return Err("an enclosing point in the region");
                };
            }
            tets.push(out);
        }
        let want: HashSet<[u32; 3]> = self.faces.iter().map(|&f| canon(f)).collect();
        if bound != want {
            return Err("the filled region's boundary is not the surface");
        }
        // Overlapping tets would show as more volume than the surface encloses.
        let vol = |t: &[u32; 4]| {
            let p = t.map(|v| pts[v as usize]);
            tet_det(p[0], p[1], p[2], p[3]).abs()
        };
        let filled: f64 = tets.iter().map(vol).sum();
        let enclosed: f64 = self
            .faces
            .iter()
            .map(|f| {
                let p = f.map(|v| pts[v as usize]);
                -super::vec3::det3(p[0], p[1], p[2])
            })
            .sum();
        if (filled - enclosed).abs() > 1e-9 * filled.max(enclosed.abs()) {
            return Err("the filled tets overlap");
        }
        Ok(Filled {
            pts,
            tets,
            grown: self.grown,
            tiny: self.tiny.iter().filter(|v| map.contains_key(v)).count(),
        })
    }
}

/// The face of tet `t` opposite its vertex `q` (the last face when `q` is not in it),
/// in [`FACES`] order.
fn opposite(t: &[u32; 4], q: u32) -> [u32; 3] {
    let j = t.iter().position(|&v| v == q).unwrap_or(3);
    FACES[j].map(|m| t[m])
}

/// A face with its smallest id first (same orientation).
fn canon(f: [u32; 3]) -> [u32; 3] {
    let r = (0..3).min_by_key(|&k| f[k]).unwrap_or(0);
    [f[r], f[(r + 1) % 3], f[(r + 2) % 3]]
}

/// Order directed edges x -> y into a polygon: a cycle, or a path closed by its chord
/// (from the path's end back to its start).
fn polygon(edges: &[[u32; 2]]) -> Option<Vec<u32>> {
    let next: HashMap<u32, u32> = edges.iter().map(|e| (e[0], e[1])).collect();
    if next.len() != edges.len() {
        return None;
    }
    let heads: HashSet<u32> = edges.iter().map(|e| e[1]).collect();
    let start = edges
        .iter()
        .map(|e| e[0])
        .find(|v| !heads.contains(v))
        .unwrap_or(edges[0][0]);
    let mut poly = vec![start];
    let mut v = start;
    while let Some(&w) = next.get(&v) {
        if w == start {
            break;
        }
        poly.push(w);
        if poly.len() > edges.len() + 1 {
            return None;
        }
        v = w;
    }
    let closed = next.get(&v) == Some(&start);
    (poly.len() == edges.len() + usize::from(!closed)).then_some(poly)
}

/// Triangulate a simple polygon (vertices in order, closed from the last to the first)
/// maximising the worst triangle's `shape`, by dynamic programming over its diagonals.
/// `ccw(a, b, c)` is the exact test that a triangle turns the polygon's way; a triangle
/// is allowed when it does and no other polygon vertex is in it (closed). The best worst
/// shape avoids joining runs of nearly collinear points (split edges) to each other.
fn triangulate_polygon(
    poly: &[u32],
    ccw: impl Fn(u32, u32, u32) -> bool,
    shape: impl Fn(u32, u32, u32) -> f64,
) -> Option<Vec<[u32; 3]>> {
    let n = poly.len();
    if n < 3 {
        return None;
    }
    let ok = |i: usize, k: usize, j: usize| {
        let (a, b, c) = (poly[i], poly[k], poly[j]);
        ccw(a, b, c)
            && poly
                .iter()
                .all(|&x| [a, b, c].contains(&x) || ccw(b, a, x) || ccw(c, b, x) || ccw(a, c, x))
    };
    // best[i][j]: the best worst shape of the sub-polygon i..=j (closed by i-j).
    let mut best = vec![vec![f64::NEG_INFINITY; n]; n];
    let mut pick = vec![vec![usize::MAX; n]; n];
    for i in 0..n - 1 {
        best[i][i + 1] = f64::INFINITY;
    }
    for len in 2..n {
        for i in 0..n - len {
            let j = i + len;
            for k in i + 1..j {
                if best[i][k] == f64::NEG_INFINITY || best[k][j] == f64::NEG_INFINITY {
                    continue;
                }
                if !ok(i, k, j) {
                    continue;
                }
                let q = best[i][k]
                    .min(best[k][j])
                    .min(shape(poly[i], poly[k], poly[j]));
                if q > best[i][j] {
                    best[i][j] = q;
                    pick[i][j] = k;
                }
            }
        }
    }
    if best[0][n - 1] == f64::NEG_INFINITY {
        return None;
    }
    let mut out = Vec::with_capacity(n - 2);
    let mut stack = vec![(0, n - 1)];
    while let Some((i, j)) = stack.pop() {
        if j <= i + 1 {
            continue;
        }
        let k = pick[i][j];
        out.push([poly[i], poly[k], poly[j]]);
        stack.push((i, k));
        stack.push((k, j));
    }
    Some(out)
}

/// A point strictly on the positive side of every triangle: the centre of the largest
/// ball in their half-spaces' intersection (a linear program, coordinates relative to
/// `o`), checked exactly.
fn kernel_centre(walls: &[[P3; 3]], o: P3) -> Option<P3> {
    use microlp::{ComparisonOp, OptimizationDirection, Problem};
    let mut pr = Problem::new(OptimizationDirection::Maximize);
    let inf = f64::INFINITY;
    let x = pr.add_var(0.0, (-inf, inf));
    let y = pr.add_var(0.0, (-inf, inf));
    let z = pr.add_var(0.0, (-inf, inf));
    let t = pr.add_var(1.0, (0.0, inf));
    for w in walls {
        let p = w.map(|v| sub(v, o));
        let n = tri_normal(p[0], p[1], p[2]);
        let l = norm(n);
        if l.is_nan() || l <= 0.0 {
            return None;
        }
        let n = [n[0] / l, n[1] / l, n[2] / l];
        // n . (q - p0) >= t
        pr.add_constraint(
            [(x, n[0]), (y, n[1]), (z, n[2]), (t, -1.0)],
            ComparisonOp::Ge,
            dot(n, p[0]),
        );
    }
    let sol = pr.solve().ok()?.into_solution().ok()?;
    if sol.var_value(t).is_nan() || sol.var_value(t) <= 0.0 {
        return None;
    }
    let q = [sol.var_value(x), sol.var_value(y), sol.var_value(z)];
    let q = [q[0] + o[0], q[1] + o[1], q[2] + o[2]];
    walls
        .iter()
        .all(|w| orient3d(w[0], w[1], w[2], q) > 0)
        .then_some(q)
}

/// Area over the sum of squared edge lengths (0 for a degenerate triangle).
fn tri_shape(a: P3, b: P3, c: P3) -> f64 {
    let l = super::vec3::dist2(a, b) + super::vec3::dist2(b, c) + super::vec3::dist2(c, a);
    norm(tri_normal(a, b, c)) / l.max(f64::MIN_POSITIVE)
}

/// Where segment ab meets the plane of `f` (rounded).
fn segment_plane(a: P3, b: P3, f: [P3; 3]) -> P3 {
    let da = tet_det(f[0], f[1], f[2], a);
    let db = tet_det(f[0], f[1], f[2], b);
    let t = if da == db { 0.5 } else { da / (da - db) };
    axpy(a, t.clamp(0.0, 1.0), sub(b, a))
}

/// Distance from `p` to the line through x and y.
fn line_dist(p: P3, x: P3, y: P3) -> f64 {
    let d = sub(y, x);
    norm(super::vec3::cross(d, sub(p, x))) / norm(d).max(f64::MIN_POSITIVE)
}

/// The point of edge xy closest to the line through a and b (rounded).
fn segment_line(a: P3, b: P3, x: P3, y: P3) -> P3 {
    let d1 = sub(b, a);
    let d2 = sub(y, x);
    let r = sub(a, x);
    let (aa, ee, bb) = (dot(d1, d1), dot(d2, d2), dot(d1, d2));
    let (cc, ff) = (dot(d1, r), dot(d2, r));
    let den = aa * ee - bb * bb;
    let t = if den.abs() > 0.0 {
        (aa * ff - bb * cc) / den
    } else {
        0.5
    };
    axpy(x, t.clamp(0.0, 1.0), d2)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::distance::point_triangle_dist2;

    /// Fill `faces` (outward, as surfaces are stored) and check the result: positive tets,
    /// boundary exactly the input, volume the enclosed one.
    fn fill_and_check(pts: &[P3], outward: &[[u32; 3]]) -> Result<Filled, String> {
        fill_and_check_with(pts, outward, Split::AtCrossing)
    }

    /// The triangles `outward` turned to face into the region, as the fill takes them.
    fn inward(outward: &[[u32; 3]]) -> Vec<[u32; 3]> {
        outward.iter().map(|f| [f[0], f[2], f[1]]).collect()
    }

    /// [`fill_and_check`] with Steiner points placed by `split`.
    fn fill_and_check_with(
        pts: &[P3],
        outward: &[[u32; 3]],
        split: Split,
    ) -> Result<Filled, String> {
        let faces = inward(outward);
        let mut stages = Stages::default();
        let r = fill(pts, &faces, split, None, Patience::Exhaustive, &mut stages)
            .map_err(|e| e.to_string())?;
        assert_eq!(&r.pts[..pts.len()], pts);
        let mut vol = 0.0;
        let mut uses: HashMap<[u32; 3], i32> = HashMap::default();
        for t in &r.tets {
            let p = t.map(|v| r.pts[v as usize]);
            assert!(orient3d(p[0], p[1], p[2], p[3]) > 0);
            vol += tet_det(p[0], p[1], p[2], p[3]) / 6.0;
            for fk in FACES {
                let g = fk.map(|j| t[j]);
                *uses.entry(canon(g)).or_insert(0) += 1;
                *uses.entry(canon([g[0], g[2], g[1]])).or_insert(0) -= 1;
            }
        }
        // Faces used once and not matched by an opposite use: the outward boundary.
        let bound: HashSet<[u32; 3]> = uses
            .iter()
            .filter(|(_, &n)| n == 1)
            .map(|(f, _)| *f)
            .collect();
        let want: HashSet<[u32; 3]> = outward.iter().map(|&f| canon(f)).collect();
        assert_eq!(bound, want);
        let enclosed: f64 = outward
            .iter()
            .map(|f| {
                super::super::vec3::det3(pts[f[0] as usize], pts[f[1] as usize], pts[f[2] as usize])
                    / 6.0
            })
            .sum();
        assert!(
            (vol - enclosed).abs() <= 1e-9 * enclosed.abs(),
            "{vol} vs {enclosed}"
        );
        Ok(r)
    }

    fn cube() -> (Vec<P3>, Vec<[u32; 3]>) {
        crate::geom::testutil::unit_cube()
    }

    #[test]
    fn a_cube_fills_with_its_own_vertices() {
        let (p, f) = cube();
        let r = fill_and_check(&p, &f).unwrap();
        assert!(r.tets.len() >= 5);
    }

    /// A segment whose diametral ball holds a ring of points around it (so that the
    /// Delaunay tetrahedralization crosses it) is split at their projection, 0.3 along
    /// it, not halfway: both pieces' balls are then empty of them.
    #[test]
    fn a_missing_segment_is_split_at_its_encroaching_vertex() {
        let (x, r) = (0.3, 0.05);
        let mut p = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]];
        for k in 0..5 {
            let a = (72.0 * k as f64).to_radians();
            p.push([x, r * a.cos(), r * a.sin()]);
        }
        let dt = delaunay(&p);
        assert!(!dt.has_edge(0, 1));
        let c = Cdt::new(dt, &[], Split::Halving, Patience::Exhaustive).unwrap();
        assert!((c.reference_fraction(0, 1) - x).abs() < 1e-12);
        assert!((c.reference_fraction(1, 0) - (1.0 - x)).abs() < 1e-12);
    }

    /// Schönhardt's twisted prism: no tetrahedralization without an added point.
    #[test]
    fn the_schoenhardt_prism_fills_with_an_interior_point() {
        let mut p = Vec::new();
        for (z, twist) in [(0.0, 0.0), (1.0, 0.5)] {
            for k in 0..3 {
                let a =
                    (k as f64 * 120.0f64 + if z > 0.0 { twist * 60.0 } else { 0.0 }).to_radians();
                p.push([a.cos(), a.sin(), z]);
            }
        }
        // Bottom (outward down), top (up), and each side quad split along the
        // reflex diagonal.
        let mut f = vec![[0, 2, 1], [3, 4, 5]];
        for k in 0..3 {
            let (a, b) = (k, (k + 1) % 3);
            let (c, d) = (3 + k, 3 + (k + 1) % 3);
            f.push([a, b, d]);
            f.push([a, d, c]);
        }
        let r = fill_and_check(&p, &f);
        // The twist makes one of the two diagonals reflex; try the other split if
        // this one is convex, the point is a fill that needs a Steiner point.
        let r = r.or_else(|_| {
            let mut g = vec![[0, 2, 1], [3, 4, 5]];
            for k in 0..3 {
                let (a, b) = (k, (k + 1) % 3);
                let (c, d) = (3 + k, 3 + (k + 1) % 3);
                g.push([a, b, c]);
                g.push([b, d, c]);
            }
            fill_and_check(&p, &g)
        });
        let r = r.unwrap();
        assert!(r.pts.len() > 6, "{} points", r.pts.len());
    }

    /// A fan around a removed point with a run of collinear points (a split edge): the
    /// triangulation joins the run to the far vertex, never to itself.
    #[test]
    fn polygon_runs_of_collinear_points_join_across() {
        let p: Vec<P3> = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [3.0, 0.0, 0.0],
            [1.5, 1.0, 0.0],
        ];
        let (proj, sign) = projection_of(p[0], p[3], p[4]).unwrap();
        let ccw = |a: u32, b: u32, c: u32| {
            proj.orient2d(p[a as usize], p[b as usize], p[c as usize]) == sign
        };
        let shape = |a: u32, b: u32, c: u32| tri_shape(p[a as usize], p[b as usize], p[c as usize]);
        // Starting anywhere on the cycle.
        for r in 0..5 {
            let poly: Vec<u32> = (0..5).map(|k| ((k + r) % 5) as u32).collect();
            let t = triangulate_polygon(&poly, ccw, shape).unwrap();
            assert_eq!(t.len(), 3);
            for x in &t {
                assert!(ccw(x[0], x[1], x[2]), "{x:?}");
                assert!(x.contains(&4), "{x:?} does not use the apex");
            }
        }
    }

    /// Whole CAD parts (OpenSCAD exports) filled from their vertices alone: the
    /// hardest use of the fill (coplanar faces, cospherical points everywhere).
    /// The corner points and outward triangles of `tests/data/openscad/NAME.stl`.
    fn openscad_corners(name: &str) -> (Vec<P3>, Vec<[u32; 3]>) {
        surface_corners(&format!("openscad/{name}.stl"))
    }

    /// The corner points and outward triangles of `tests/data/FILE`.
    fn surface_corners(file: &str) -> (Vec<P3>, Vec<[u32; 3]>) {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data")
            .join(file);
        let s = crate::io::read_any_surface(&path, &Default::default()).unwrap();
        let corners = s.corner_nodes();
        let local = |v: u32| corners.binary_search(&v).unwrap() as u32;
        let pts: Vec<P3> = corners.iter().map(|&c| s.nodes()[c as usize]).collect();
        let faces: Vec<[u32; 3]> = s
            .triangles()
            .iter()
            .map(|t| [local(t[0]), local(t[1]), local(t[2])])
            .collect();
        (pts, faces)
    }

    #[test]
    fn openscad_parts_fill_with_their_boundary_kept() {
        for name in ["LetterBlock", "example002", "example013", "example014"] {
            let (pts, faces) = openscad_corners(name);
            let r = fill_and_check(&pts, &faces).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(r.tets.len() >= faces.len() / 4, "{name}");
        }
    }

    /// OpenSCAD's example018, filled from its boundary points: moving the Steiner points
    /// off the surface, tiny steps taken at once, leaves a numerically flat tet whose
    /// vertices are not all on the surface; contracting one of them into a neighbour
    /// removes it, and the fill keeps its boundary and volume.
    #[test]
    fn contraction_removes_the_flat_tets_moving_off_leaves() {
        let (pts, outward) = openscad_corners("example018");
        let faces = inward(&outward);
        let mut c = Cdt::new(
            Delaunay::new(&pts),
            &faces,
            Split::AtCrossing,
            Patience::Exhaustive,
        )
        .unwrap();
        // Points that only a tiny step moves off placed there at once, not deferred to
        // the last round: the fill then leaves the flat tet (deferred, none).
        c.defer_tiny = false;
        c.recover_edges().unwrap();
        (0..faces.len())
            .try_for_each(|i| c.recover_face(i))
            .unwrap();
        c.keep_enclosed().unwrap();
        c.remove_steiner_points().unwrap();
        let flat = |c: &Cdt| {
            (0..c.dt.tets.len())
                .filter(|&t| c.dt.alive[t] && numerically_flat(&c.dt.tets[t].map(|v| c.dt.p(v))))
                .count()
        };
        assert!(
            flat(&c) > 0,
            "example018 no longer leaves a flat tet to contract"
        );
        c.contract_flat();
        assert_eq!(flat(&c), 0);
        let r = fill_and_check(&pts, &outward).unwrap();
        let flat_left = r
            .tets
            .iter()
            .filter(|t| numerically_flat(&t.map(|v| r.pts[v as usize])));
        assert_eq!(flat_left.count(), 0);
    }

    /// OpenSCAD's example005 (a CAD part of needle triangles), filled from its boundary
    /// points alone: some Steiner points have a nearly flat tet in their star, so every
    /// inward step inverts a tet of the star itself; only a grown cavity takes them off
    /// the surface (without [`Cdt::grown_star`] the fill fails there).
    #[test]
    fn a_star_no_point_sees_grows_into_a_cavity_one_does() {
        let (pts, faces) = openscad_corners("example005");
        let r = fill_and_check(&pts, &faces).unwrap_or_else(|e| panic!("example005: {e}"));
        assert!(r.grown > 0, "no cavity grown");
    }

    /// example005 again: 34 of its Steiner points are seen only from within 2^-10 of their
    /// star's span of where they were on the surface (steps down to 2^-48 of the nearest
    /// star vertex), where they would leave linearly flat tets; each gets a grown cavity
    /// seen from a larger step instead.
    #[test]
    fn no_steiner_point_stays_a_tiny_step_off_the_surface() {
        let (pts, faces) = openscad_corners("example005");
        let r = fill_and_check(&pts, &faces).unwrap_or_else(|e| panic!("example005: {e}"));
        assert_eq!(r.tiny, 0, "Steiner points left at a tiny step");
    }

    /// OpenSCAD's offset: 12 of its Steiner points had moved off the surface by a fair
    /// step, but along it: they ended within 1e-6 of the part's size of a surface triangle,
    /// where the linear stage cannot lift the flat tets they make. Measured by the height
    /// above the faces, each gets a grown cavity seen from higher up instead.
    #[test]
    fn no_steiner_point_moves_along_the_surface_instead_of_off_it() {
        let (pts, faces) = openscad_corners("offset");
        let r = fill_and_check(&pts, &faces).unwrap_or_else(|e| panic!("offset: {e}"));
        let (lo, hi) = pts.iter().fold(
            ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
            |(lo, hi), p| {
                (
                    std::array::from_fn(|d| lo[d].min(p[d])),
                    std::array::from_fn(|d| hi[d].max(p[d])),
                )
            },
        );
        let near = 1e-6 * dist(lo, hi);
        // Steiner points within `near` of a surface triangle.
        let hugging = r.pts[pts.len()..]
            .iter()
            .filter(|&&p| {
                faces.iter().any(|f| {
                    let a = f.map(|v| pts[v as usize]);
                    point_triangle_dist2(p, a[0], a[1], a[2]) < near * near
                })
            })
            .count();
        assert!(r.pts.len() > pts.len(), "offset needs Steiner points");
        assert_eq!(hugging, 0, "Steiner points hugging the surface");
    }

    /// An aniso torus of 12 segments around its axis (`tests/data/tori/aniso_12x44.off`):
    /// its meridian at 180 degrees is coplanar only within rounding, and the Delaunay
    /// tetrahedralization of its corners has over a hundred numerically flat tets there.
    /// At crossings, the fill fails (Steiner points within rounding of each other on a
    /// segment through them); flipped out first, and none made in the recovery, it
    /// closes, its boundary the input's.
    #[test]
    fn a_layer_coplanar_within_rounding_fills_without_flat_tets() {
        let (pts, outward) = surface_corners("tori/aniso_12x44.off");
        assert!(fill_and_check(&pts, &outward).is_err());
        let faces = inward(&outward);
        let mut c = Cdt::new(
            Delaunay::new(&pts),
            &faces,
            Split::NoFlatTets,
            Patience::Exhaustive,
        )
        .unwrap();
        let flat = |c: &Cdt| {
            (0..c.dt.tets.len())
                .filter(|&t| c.dt.alive[t] && numerically_flat(&c.dt.tets[t].map(|v| c.dt.p(v))))
                .count()
        };
        let before = flat(&c);
        c.flip_flat_tets();
        let after = flat(&c);
        assert!(before > 100 && after <= 2, "{before} -> {after} flat tets");
        let r = fill_and_check_with(&pts, &outward, Split::NoFlatTets).unwrap();
        assert!(r.tets.len() >= outward.len() / 4);
    }

    /// A fill that stops says where: on the aniso torus of 12 segments, at crossings, the
    /// point its edge recovery had reached, on that surface edge within rounding.
    #[test]
    fn a_failed_fill_says_where_recovery_stopped() {
        let (pts, outward) = surface_corners("tori/aniso_12x44.off");
        let mut stages = Stages::default();
        let faces = inward(&outward);
        let r = fill(
            &pts,
            &faces,
            Split::AtCrossing,
            None,
            Patience::Exhaustive,
            &mut stages,
        );
        assert!(r.is_err());
        let p = stages.stuck_near.expect("no place named");
        let on_an_edge = outward.iter().any(|f| {
            (0..3).any(|k| {
                let (a, b) = (pts[f[k] as usize], pts[f[(k + 1) % 3] as usize]);
                line_dist(p, a, b) < 1e-12 * dist(a, b)
                    && dot(sub(p, a), sub(b, a)) >= 0.0
                    && dot(sub(p, b), sub(a, b)) >= 0.0
            })
        });
        assert!(on_an_edge, "{p:?} is on no surface edge");
    }
}
