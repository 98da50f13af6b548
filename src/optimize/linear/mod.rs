//! Linear quality improvement of the straight-sided core, before P2 assembly.
//!
//! Worst element first: every tet whose quality (1 − equiangular skewness, see
//! `objective`) is below the goal is attacked in turn by edge removal on its edges, 2-3
//! flips on its faces, smoothing of its interior vertices, contraction of its edges
//! that have an interior end point, and insertion of a vertex on one of its interior
//! edges (longest first); an operation is kept only when it raises the minimum quality
//! of the tets it touches. Passes repeat while something improves. Tets still above
//! [`LinearParams::search_skewness`] then get a sampled search for their interior
//! vertices (the smoother's ascent stalls at kinks of the max-min), followed by passes
//! aimed at that threshold. The attempts over all passes are bounded by
//! [`LinearParams::max_attempts_per_tet`]; where a pass leaves more bad tets than it
//! found, later passes aim at the worst tets only ([`LinearParams::reach`]). Last, the
//! sliver rounds ([`LinearParams::sliver_passes`]); where they leave unforced slivers,
//! the stage runs a second time with multi-face removal in every pass
//! ([`improve_linear_known`]). Deterministic: the trial points of a vertex search, the
//! sliver rounds' runs two at a time, and on a whole fill the stage's two runs, go on
//! the threads of the rayon pool the stage is called in, with the same result on any
//! number.

mod contract;
mod flips;
mod insert;
mod mesh;
mod objective;
mod smooth;

use crate::geom::shape::TET10_EDGES;
use crate::geom::vec3::P3;
use crate::optimize::Boundary;
use contract::{contract, ContractScratch};
use flips::{flip23, remove_edge, remove_faces, FlipScratch};
use insert::{insert_in_cavity, split_edge, InsertScratch};
use mesh::LinMesh;
pub use objective::ElementQuality;
use smooth::{search_vertex, smooth_vertex, SmoothParams, SmoothScratch};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Tuning of the linear stage.
#[derive(Clone, Debug)]
pub struct LinearParams {
    /// Tets with equiangular skewness above this are worked on.
    pub goal_skewness: f64,
    /// Most passes over the bad tets.
    pub max_passes: usize,
    /// Smallest rise of the minimum quality that counts as an improvement.
    pub eps: f64,
    /// A tet still above this skewness after flips and smoothing gets a sampled search
    /// for better positions of its interior vertices (costly, and needed only where the
    /// smoother's ascent stalls: on the hinge it takes the worst tet from 0.961 to below
    /// 0.8).
    pub search_skewness: f64,
    /// Attempts at bad tets over all passes, per tet of the input, at most (the sampled
    /// searches are not counted). The six benchmark surfaces make 0.06-0.5, so the bound
    /// changes nothing there. On a surface of anisotropic triangles the boundary forces
    /// thousands of tets to be poor; each pass's splits and moves then leave more poor
    /// tets than before, and the passes do not settle. Measured with
    /// `scripts/aniso-torus.py` surfaces, without → with the bound: 30 × 54, this stage
    /// 4.2 → 3.1 s (the front: 0.65 s), max skewness 0.773 → 0.774; 12 × 27
    /// `--no-shift`, 1.07 → 0.49 s, min J / max J 0.691 → 0.715, skewness 0.835 →
    /// 0.843. A bound of 1 cut more time but let the latter's skewness reach 0.896. The
    /// worst tets come first in every pass, so the attempts cut are those at the least
    /// bad tets.
    pub max_attempts_per_tet: f64,
    /// When a pass leaves more tets below the goal than there were when the passes
    /// started, the goal is out of reach: the boundary forces those tets to be poor (a
    /// surface of anisotropic triangles), and splitting and moving only spreads the
    /// poor shape. The remaining passes then go only after the tets within this of the
    /// worst quality (as the high-order stage's [`reach`](super::HighOrderParams::reach)
    /// does), which is what the largest skewness depends on. None of the six benchmark
    /// surfaces gets there (their first pass fixes 23-57 % of their bad tets), so it
    /// changes nothing on them. On the `scripts/aniso-torus.py` tori of 30-50 x 40-60
    /// where it does (eight of nine), the stage took 0.9-4.3 s and now takes 0.2-0.7 s,
    /// less than the front; the largest skewness stays within 0.72-0.80, but rises on
    /// some (40 x 50: 0.70 -> 0.78). A reach of 0.1 saved about half as much, with
    /// skewness about 0.02 lower.
    pub reach: f64,
    /// Refuse, in every pass, an edge split that lifts the minimum quality by making more
    /// slivers (a dihedral angle below [`crate::mesh::slivers::SLIVER_DEG`]) than it
    /// removes, unless it makes an invalid tet valid. Passes aimed at the worst tets only
    /// ([`LinearParams::reach`]) always refuse them. Off by default: on the hinge the
    /// splits it refuses are what lift its worst tet (certified min J / max J 0.43 ->
    /// 0.38 with it on). On for the whole fill ([`crate::front::FrontStats::whole_fill`]),
    /// whose tets next to the surface are poor and where the splits spread slivers
    /// inward: OpenSCAD's sign made 2,055 interior slivers without it, 1,182 with it.
    pub guard_slivers: bool,
    /// Last: passes and vertex searches aimed at the unforced slivers only (tets with a
    /// dihedral angle below [`crate::mesh::slivers::SLIVER_DEG`] that no needle or cap
    /// triangle at their corners forces; see [`Boundary::sliver_floor`]), scoring every
    /// other tet as good (a score of 1), so that the forced slivers beside them, worse
    /// by the element quality, no longer block every move. Up to this many passes in
    /// all, in rounds of eight each followed by vertex searches, while a round removes
    /// some, with a budget of their own (two attempts per tet of the input); 0: none;
    /// the mesh of the round that left the fewest is kept. The last rounds, where some
    /// are left, may trade stuck ones (every corner on the surface) for more, better
    /// ones (any ones in the runs whose cavities grow, the third and fourth). Where
    /// some are left, the rounds run again with edge splits that also search for their
    /// new vertex's position, from the start and from the end, and the run that leaves
    /// the fewest is kept. The rounds keep removing them slowly on large fills:
    /// OpenSCAD's example019 went from 14,106 to 4,352, 2,979, 2,280, 1,732, 1,415,
    /// 997, 946, 897 and 839 in ten rounds, then 845 (a cap of 40 passes stopped it at
    /// 1,415; the five rounds more took 8 s of its 63 s stage).
    pub sliver_passes: usize,
    /// The surface's boundary edges may go back on their chords (a surface curved from
    /// a linear one, `Surface::chords_allowed`): the straightening after the
    /// high-order stage then puts every curved boundary edge of a tet it cannot certify
    /// on its chord. The sliver passes take the curved boundary edges of the tets that
    /// are not valid as P2 elements when they start as those chords already, so that
    /// they lift such a tet's straight shape, which is what the mesh will keep, rather
    /// than leave it alone, as they do otherwise.
    pub chords: bool,
    /// After the passes and searches: passes aimed only at tets above this skewness
    /// (nearly flat), with a budget of their own (one attempt per tet of the input), up
    /// to [`LinearParams::max_passes`]. None: no such passes.
    pub flat_skewness: Option<f64>,
    /// Start the stage's second run ([`improve_linear_known`]) beside the first, on the
    /// pool's other threads, rather than after it where the first leaves unforced
    /// slivers; stopped as soon as the first leaves none. The same mesh either way. On
    /// for the whole fill, where most such runs are needed; off for the front's meshes
    /// (the 1M-tet torus would hold two meshes for nothing).
    pub side_by_side: bool,
}

impl Default for LinearParams {
    fn default() -> Self {
        LinearParams {
            goal_skewness: 0.6,
            max_passes: 8,
            eps: 1e-9,
            search_skewness: 0.8,
            max_attempts_per_tet: 2.0,
            reach: 0.05,
            guard_slivers: false,
            flat_skewness: None,
            sliver_passes: 120,
            chords: false,
            side_by_side: false,
        }
    }
}

impl LinearParams {
    /// For a whole fill's tets ([`crate::front::FrontStats::whole_fill`]): splits guarded
    /// ([`LinearParams::guard_slivers`]), then passes aimed at the nearly flat tets only
    /// ([`LinearParams::flat_skewness`] 0.95, a minimum dihedral angle below about 3.5°).
    /// A fill starts far worse than a front's mesh (most of its tets are below the goal):
    /// the default attempt budget runs out on tets that are merely poor and leaves nearly
    /// flat ones, which then fail P2 certification. More passes and attempts for every
    /// poor tet also removed them, at twice to three times this stage's time (the
    /// commit history has the figures).
    pub fn for_whole_fill() -> Self {
        LinearParams {
            guard_slivers: true,
            flat_skewness: Some(0.95),
            side_by_side: true,
            ..LinearParams::default()
        }
    }
}

/// What the linear stage did.
#[derive(Debug, Clone, Default, serde::Serialize)]
#[non_exhaustive]
pub struct LinearStats {
    /// Tets before and after.
    pub tets: [usize; 2],
    /// Largest equiangular skewness before and after.
    pub max_skewness: [f64; 2],
    /// Tets with skewness above the goal, before and after.
    pub bad: [usize; 2],
    /// Passes made.
    pub passes: usize,
    /// Attempts at bad tets in the passes (see [`LinearParams::max_attempts_per_tet`]).
    pub attempts: usize,
    /// 2-3 flips applied.
    pub flips23: usize,
    /// Edge removals applied (3-2, 4-4, n-to-(2n-4)).
    pub edge_removals: usize,
    /// Multi-face removals applied (of two faces or more: one is a 2-3 flip, tried first).
    pub face_removals: usize,
    /// The run kept made multi-face removals in every pass (see
    /// [`improve_linear_known`]).
    pub face_removal: bool,
    /// Edge contractions applied.
    pub contractions: usize,
    /// Vertex smoothings that moved a vertex.
    pub smoothings: usize,
    /// Sampled vertex searches that moved a vertex.
    pub searches: usize,
    /// Interior vertices inserted (edge splits kept).
    pub insertions: usize,
    /// Passes aimed at the tets within [`LinearParams::reach`] of the worst only (the
    /// goal was out of reach).
    pub reach_passes: usize,
    /// Where the stage's time went.
    pub seconds: LinearSeconds,
}

/// Wall-clock seconds of each part of the linear stage, in the order they run (see the
/// module docs), so that a report shows which part a slow mesh spends its time in.
#[derive(Debug, Clone, Default, serde::Serialize)]
#[non_exhaustive]
pub struct LinearSeconds {
    /// The first passes, aimed at [`LinearParams::goal_skewness`].
    pub passes: f64,
    /// The sampled vertex searches and the passes after each, aimed at
    /// [`LinearParams::search_skewness`].
    pub searches: f64,
    /// The passes aimed at nearly flat tets ([`LinearParams::flat_skewness`]).
    pub flat: f64,
    /// The rounds aimed at the unforced slivers ([`LinearParams::sliver_passes`]).
    pub slivers: f64,
    /// The other run of the stage, whose mesh was not kept ([`improve_linear_known`]).
    pub other_run: f64,
}

/// In the sliver passes: the unforced slivers left, as the sliver census will count
/// them ([`LinMesh::unforced`]; not every tet scored below 1, which counts P2-invalid
/// tets the straightening makes valid, and chose runs that left more slivers).
fn unforced_left(m: &LinMesh) -> usize {
    unforced_tets(m).count()
}

/// The slots of the live tets [`LinMesh::unforced`] counts.
fn unforced_tets<'m>(m: &'m LinMesh) -> impl Iterator<Item = usize> + 'm {
    (0..m.tets.len()).filter(|&t| m.alive(t as u32) && m.unforced(m.tets[t], m.q[t]))
}

/// Worst quality and the count of tets below `goal`.
fn census(m: &LinMesh, goal: f64) -> (f64, usize) {
    let mut worst = f64::INFINITY;
    let mut bad = 0;
    for (t, &q) in m.q.iter().enumerate() {
        if m.alive(t as u32) {
            worst = worst.min(q);
            if q < goal {
                bad += 1;
            }
        }
    }
    (worst, bad)
}

#[derive(Default)]
struct Scratch {
    flip: FlipScratch,
    contract: ContractScratch,
    smooth: SmoothScratch,
    smooth_prm: SmoothParams,
    insert: InsertScratch,
    /// Whether [`improve_tet`] also tries [`insert_in_cavity`] (the sliver passes' last
    /// rounds).
    cavities: bool,
    /// Whether [`improve_tet`] also tries [`remove_faces`].
    face_removal: bool,
    /// Any of these set: the run's result is no longer wanted, and its passes, searches
    /// and rounds end.
    stops: Vec<Arc<AtomicBool>>,
}

impl Scratch {
    /// Whether one of [`Scratch::stops`] is set.
    fn stopped(&self) -> bool {
        self.stops.iter().any(|s| s.load(Ordering::Relaxed))
    }
}

/// Improve the straight-sided tets `tets` on `pts` (surface nodes first, as the front
/// makes them) without touching the boundary `bnd`. Returns the new points (interior
/// ones may have moved; points no tet uses any more are left in place), the new tets
/// (positive) and what was done.
pub fn improve_linear(
    pts: Vec<P3>,
    tets: Vec<[u32; 4]>,
    bnd: &Boundary,
    prm: &LinearParams,
) -> (Vec<P3>, Vec<[u32; 4]>, LinearStats) {
    improve_linear_known(pts, tets, None, bnd, prm)
}

/// [`improve_linear`] given the corner quality of each tet where it is known
/// ([`crate::front::FrontOutput::quality`]: NaN where not), so that the stage does not
/// measure every tet again (on the 1M-tet torus that was about 0.1 s). The result is the
/// same.
///
/// Where the stage leaves unforced slivers ([`LinearParams::sliver_passes`]), it runs
/// again from the same tets with multi-face removal (Shewchuk's) after the 2-3
/// flips in every pass (in the sliver rounds, only in their fourth run, as the first
/// time), and the run that leaves fewer is kept, the first on a tie. Each run takes a
/// path of its own, and neither is the better one on every part (CHANGELOG has the
/// counts). Side by side ([`LinearParams::side_by_side`], the whole fill's), on two
/// threads, the second run costs little wall time where the first leaves some, and
/// stops where it leaves none; the meshes are those of one run after the other, at the
/// cost of a third more memory at the peak.
pub fn improve_linear_known(
    pts: Vec<P3>,
    tets: Vec<[u32; 4]>,
    known: Option<&[f64]>,
    bnd: &Boundary,
    prm: &LinearParams,
) -> (Vec<P3>, Vec<[u32; 4]>, LinearStats) {
    if prm.sliver_passes == 0 {
        return linear_run(pts, tets, known, bnd, prm, false, Vec::new()).0;
    }
    let ((first, left), second) = if prm.side_by_side {
        let stop = Arc::new(AtomicBool::new(false));
        let (p2, t2) = (pts.clone(), tets.clone());
        let (first, second) = rayon::join(
            || {
                let r = linear_run(pts, tets, known, bnd, prm, false, Vec::new());
                if r.1 == 0 {
                    stop.store(true, Ordering::Relaxed);
                }
                r
            },
            || linear_run(p2, t2, known, bnd, prm, true, vec![stop.clone()]),
        );
        (first, Ok(second))
    } else {
        let first = linear_run(
            pts.clone(),
            tets.clone(),
            known,
            bnd,
            prm,
            false,
            Vec::new(),
        );
        (first, Err((pts, tets)))
    };
    if left == 0 {
        return first;
    }
    // (Err: not run yet, its input.)
    let (mut second, fewer) = match second {
        Ok(s) => s,
        Err((pts, tets)) => linear_run(pts, tets, known, bnd, prm, true, Vec::new()),
    };
    let (mut kept, other) = if fewer < left {
        (second, first.2.seconds)
    } else {
        let other = std::mem::take(&mut second.2.seconds);
        (first, other)
    };
    let o = &other;
    kept.2.seconds.other_run = o.passes + o.searches + o.flat + o.slivers;
    kept
}

impl LinearStats {
    /// Attempts at bad tets so far per tet of the input (the unit of
    /// [`LinearParams::max_attempts_per_tet`]).
    fn attempts_per_tet(&self) -> f64 {
        self.attempts as f64 / self.tets[0].max(1) as f64
    }
}

/// The points, tets and stats of [`improve_linear_known`].
type Improved = (Vec<P3>, Vec<[u32; 4]>, LinearStats);

/// One run of the linear stage ([`improve_linear_known`]), with multi-face removal in
/// every pass (`face_removal`) or only in the sliver rounds' fourth run; also returns
/// the unforced slivers it leaves (0 without sliver passes).
fn linear_run(
    pts: Vec<P3>,
    tets: Vec<[u32; 4]>,
    known: Option<&[f64]>,
    bnd: &Boundary,
    prm: &LinearParams,
    face_removal: bool,
    stops: Vec<Arc<AtomicBool>>,
) -> (Improved, usize) {
    let goal = 1.0 - prm.goal_skewness;
    let mut m = LinMesh::with_known(pts, tets, known, bnd, ElementQuality);
    let mut st = LinearStats::default();
    let (w0, b0) = census(&m, goal);
    st.tets[0] = m.tets.len();
    st.max_skewness[0] = 1.0 - w0;
    st.bad[0] = b0;
    let mut sc = Scratch {
        flip: FlipScratch::default(),
        contract: ContractScratch::default(),
        smooth: SmoothScratch::default(),
        smooth_prm: SmoothParams::default(),
        insert: InsertScratch::default(),
        cavities: false,
        face_removal,
        stops,
    };
    let mut order: Vec<(f64, u32, [u32; 4])> = Vec::new();
    // Clock at which each tet slot last resisted every operation (0: never); it is not
    // tried again until something in its corners' stars changes.
    let mut failed: Vec<u64> = Vec::new();
    let mut clock = std::time::Instant::now();
    // Seconds since the last call (or since the stage started).
    let mut lap = || {
        let now = std::time::Instant::now();
        let s = now.duration_since(clock).as_secs_f64();
        clock = now;
        s
    };
    run_passes(&mut m, prm, &mut sc, &mut st, &mut order, &mut failed);
    st.seconds.passes = lap();
    // Where the passes left very poor tets: sampled vertex searches, then passes aimed at
    // the search's threshold only (aiming at the goal again costs 2-3x the first passes'
    // time on the hinge for no gain). Meshes the passes alone make good enough are not
    // touched.
    let after_search = LinearParams {
        goal_skewness: prm.search_skewness,
        ..prm.clone()
    };
    for _ in 0..2 {
        if !search_worst(&mut m, prm, &mut sc, &mut st, &mut order) {
            break;
        }
        run_passes(
            &mut m,
            &after_search,
            &mut sc,
            &mut st,
            &mut order,
            &mut failed,
        );
    }
    st.seconds.searches = lap();
    if let Some(flat) = prm.flat_skewness {
        let spent = st.attempts_per_tet();
        let flat = LinearParams {
            goal_skewness: flat,
            max_attempts_per_tet: spent + 1.0,
            ..prm.clone()
        };
        run_passes(&mut m, &flat, &mut sc, &mut st, &mut order, &mut failed);
    }
    st.seconds.flat = lap();
    let left = if prm.sliver_passes > 0 {
        unforced_sliver_passes(&mut m, prm, &mut sc, &mut st, &mut order)
    } else {
        0
    };
    st.seconds.slivers = lap();
    st.face_removal = face_removal;
    let (w1, b1) = census(&m, goal);
    let (pts, tets) = m.into_parts();
    st.tets[1] = tets.len();
    st.max_skewness[1] = 1.0 - w1;
    st.bad[1] = b1;
    ((pts, tets, st), left)
}

/// The passes and searches of [`LinearParams::sliver_passes`]: the element quality
/// gives way to [`LinMesh::sliver_score`], below 1 on the unforced slivers only, and the
/// passes and searches aim at those (every tet below 1), with a budget of two attempts
/// per tet of the input on top of what was spent. Where the rounds stall, the last ones
/// also try [`insert_in_cavity`].
///
/// Where some are left, the rounds run again with every edge split whose smoothed new
/// vertex falls short searching for its position too
/// ([`InsertScratch::search`](insert::InsertScratch)): once from the mesh the plain
/// rounds started from, and once from where they ended; the mesh with the fewest
/// unforced slivers is kept, the earlier run's on a tie. A split of a sliver's interior
/// edge starts its new vertex on the sliver's nearly flat plane, where the smoother's
/// ascent often cannot leave; the search finds a position off it. Run alone, the
/// searching rounds take another path, which ends with more on some parts, and neither
/// searching run is the better one everywhere; with all three, no part ends with more
/// than the plain rounds leave. The third run's cavity insertions may also grow their
/// cavities ([`InsertScratch::grow`](insert::InsertScratch)): on a cluster of flat tets
/// whose corners are all on the boundary, the cavity of a tet and two rings of its
/// neighbours is often seen whole from none of its centroids (allowed in the other runs
/// too, growing leaves more on some parts). Where some are still left, a fourth run,
/// again from the start, without the searches, adds multi-face removal
/// ([`remove_faces`]) to the grown cavities: it takes a path of its own, which ends with
/// fewer on some parts and more on others (also when tried in every run), so it too is
/// kept only where it leaves the fewest. Last, where some are left in the mesh kept,
/// [`contract_leftovers`] merges their interior corners into a neighbour wherever that
/// leaves fewer. (CHANGELOG has the counts behind each of these choices.)
///
/// The runs go two at a time on the pool's threads ([`speculate`]): the plain one beside
/// the searching one from the start, the one from where the plain run ended beside the
/// fourth. The mesh is the one they make one after the other, in less wall time and
/// more memory at the peak.
fn unforced_sliver_passes(
    m: &mut LinMesh,
    prm: &LinearParams,
    sc: &mut Scratch,
    st: &mut LinearStats,
    order: &mut Vec<(f64, u32, [u32; 4])>,
) -> usize {
    if prm.chords {
        m.chorded = doomed_edges(m);
    }
    m.set_sliver_mode(true);
    let every_pass = std::mem::replace(&mut sc.face_removal, false);
    if unforced_left(m) > 0 {
        let start = (m.clone(), st.clone());
        // Each later run needs the earlier ones only to know whether it runs at all:
        // two at a time, the second stopped early where the first leaves none.
        let (plain, fresh) = speculate(
            m,
            st,
            sc,
            order,
            start.clone(),
            |s| s.insert.search = true,
            prm,
        );
        if plain > 0 {
            let (f, fresh) = fresh.expect("not stopped: the plain run left some");
            // The searching runs' result with fewer than the plain run, if any (on a
            // tie, the earlier run's).
            let mut kept = None;
            if f < plain {
                kept = Some((f, fresh));
            }
            let fewest = kept.as_ref().map_or(plain, |k| k.0);
            if fewest > 0 {
                let mut chained = (m.clone(), st.clone());
                sc.insert.search = true;
                sc.insert.grow = true;
                let (c, fourth) = speculate(
                    &mut chained.0,
                    &mut chained.1,
                    sc,
                    order,
                    start,
                    |s| {
                        s.face_removal = true;
                        s.insert.grow = true;
                    },
                    prm,
                );
                sc.insert.search = false;
                sc.insert.grow = false;
                if c < fewest {
                    kept = Some((c, chained));
                }
                let fewest = kept.as_ref().map_or(plain, |k| k.0);
                if fewest > 0 {
                    let (c, fourth) = fourth.expect("not stopped: the third run left some");
                    if c < fewest {
                        kept = Some((c, fourth));
                    }
                }
            }
            if let Some((_, (mesh, stats))) = kept {
                *m = mesh;
                *st = stats;
            }
        }
    }
    sc.face_removal = every_pass;
    if unforced_left(m) > 0 {
        contract_leftovers(m, prm.chords, &mut sc.contract);
    }
    let left = unforced_left(m);
    m.chorded.clear();
    m.set_sliver_mode(false);
    left
}

/// Most rounds of [`contract_leftovers`] (a round that merges none ends them).
const LEFTOVER_ROUNDS: usize = 4;

/// After the sliver rounds, where unforced slivers are left: each interior corner `r`
/// of one is merged into the first of its neighbours for which that leaves fewer
/// unforced slivers in `r`'s star, the neighbour staying where it is
/// ([`contract::contract_fewer`]). The rounds' contractions must raise the minimum
/// score over both vertices' stars, which a single other sliver or P2-invalid tet
/// around the neighbour blocks, though those tets do not change; a vertex in a thin
/// pocket between needle faces (three slivers around it, its star of ten tets) is then
/// left where no move lifts them. Only the count decides here, and only a merge that
/// lowers it is made: the stage never ends with more.
fn contract_leftovers(m: &mut LinMesh, chords: bool, sc: &mut ContractScratch) {
    for _ in 0..LEFTOVER_ROUNDS {
        let slivers: Vec<[u32; 4]> = unforced_tets(m).map(|t| m.tets[t]).collect();
        let mut merged = false;
        for tv in slivers {
            for r in tv {
                if m.bnd.is_fixed(r) || m.vt[r as usize].is_empty() {
                    continue;
                }
                if m.neighbours(r)
                    .into_iter()
                    .any(|k| contract::contract_fewer(m, r, k, chords, sc))
                {
                    merged = true;
                }
            }
        }
        if !merged {
            break;
        }
    }
}

/// A run of the sliver rounds on `m` with the scratch `sc` as it is, and, on another
/// thread of the pool, one from `other` with a fresh scratch that `set` configures; the
/// latter's count and mesh are returned unless the first run left no unforced sliver,
/// which stops it early (it would not run at all one after the other). Each run's
/// result is the one it has alone: on one thread, or any number, the same.
#[allow(clippy::type_complexity)]
fn speculate<'a>(
    m: &mut LinMesh<'a>,
    st: &mut LinearStats,
    sc: &mut Scratch,
    order: &mut Vec<(f64, u32, [u32; 4])>,
    other: (LinMesh<'a>, LinearStats),
    set: impl FnOnce(&mut Scratch) + Send,
    prm: &LinearParams,
) -> (usize, Option<(usize, (LinMesh<'a>, LinearStats))>) {
    let stop = Arc::new(AtomicBool::new(false));
    let smooth_prm = sc.smooth_prm;
    // The second run ends where the first leaves none, and where the run they are part
    // of is no longer wanted.
    let mut stops = sc.stops.clone();
    stops.push(stop.clone());
    let (first, second) = rayon::join(
        || {
            let n = sliver_rounds(m, prm, sc, st, order);
            if n == 0 {
                stop.store(true, Ordering::Relaxed);
            }
            n
        },
        || {
            let mut o = other;
            let mut s = Scratch {
                smooth_prm,
                stops,
                ..Default::default()
            };
            set(&mut s);
            let n = sliver_rounds(&mut o.0, prm, &mut s, &mut o.1, &mut Vec::new());
            (n, o)
        },
    );
    let second = (first > 0).then_some(second);
    (first, second)
}

/// The rounds of [`unforced_sliver_passes`] on `m` (in sliver mode, with some unforced
/// sliver); `m` ends as the round that left the fewest, and that count is returned.
/// Where [`Scratch::stops`] says so before they end, they end early: their result is
/// then not used.
fn sliver_rounds(
    m: &mut LinMesh,
    prm: &LinearParams,
    sc: &mut Scratch,
    st: &mut LinearStats,
    order: &mut Vec<(f64, u32, [u32; 4])>,
) -> usize {
    let spent = st.attempts_per_tet();
    // Goal and search threshold: a score of 1 (skewness 0 in the passes' terms);
    // no narrowing to the worst (a reach of 1 spans every score below the goal).
    let mut p = LinearParams {
        goal_skewness: 0.0,
        search_skewness: 0.0,
        max_attempts_per_tet: spent + 2.0,
        reach: 1.0,
        ..prm.clone()
    };
    // The clocks of the tets that resisted, by this score.
    let mut failed = Vec::new();
    // Rounds of passes, each followed by vertex searches, while a round removes some.
    let mut left = unforced_left(m);
    // The mesh with the fewest so far: a round's max-min moves can make new ones
    // elsewhere, and the round that ends the rounds often leaves more than the one
    // before it (OpenSCAD's example010: 25, then 36).
    let mut best = (left, m.clone());
    let mut passes = 0;
    // Once the rounds stop removing any, more rounds from the best mesh so far with
    // cavity insertions as a last resort: only then, so that the rounds before take
    // the same path as without them (they make some parts end with more). Where some
    // are left still, rounds from the best mesh again whose insertions may trade stuck
    // slivers for more ([`InsertScratch::trade_stuck`]), with a budget of their own,
    // kept only where they leave fewer.
    loop {
        let mut stalled = 0;
        while left > 0 && passes < prm.sliver_passes && !sc.stopped() {
            let round = LinearParams {
                max_passes: SLIVER_ROUND_PASSES.min(prm.sliver_passes - passes),
                ..p.clone()
            };
            let before = st.passes;
            run_passes(m, &round, sc, st, order, &mut failed);
            passes += (st.passes - before).max(1);
            if unforced_left(m) > 0 {
                search_worst(m, &p, sc, st, order);
            }
            let now = unforced_left(m);
            if now < best.0 {
                best = (now, m.clone());
            }
            // (A trading round may go on after one that removed none: a trade makes more
            // before the round after it lifts them.)
            stalled = if now >= left { stalled + 1 } else { 0 };
            if stalled > usize::from(sc.insert.trade_stuck) {
                break;
            }
            left = now;
        }
        if sc.insert.trade_stuck || best.0 == 0 || sc.stopped() {
            break;
        }
        let trade = sc.cavities || passes >= prm.sliver_passes;
        if unforced_left(m) > best.0 {
            *m = best.1.clone();
        }
        if trade {
            sc.insert.trade_stuck = true;
            passes = passes.min(prm.sliver_passes.saturating_sub(TRADE_PASSES));
            p.max_attempts_per_tet = st.attempts_per_tet() + 1.0;
        }
        sc.cavities = true;
        failed.clear();
        left = best.0;
    }
    sc.cavities = false;
    sc.insert.trade_stuck = false;
    if unforced_left(m) > best.0 {
        *m = best.1;
    }
    best.0
}

/// The boundary edges of the positive tets that the element quality scores as not
/// valid P2 elements (≤ 0): the straightening after the high-order stage puts them on
/// their chords unless something makes those tets valid first ([`LinearParams::chords`]).
/// (A straight one among them is its own chord: taking it as one changes nothing.)
fn doomed_edges(m: &LinMesh) -> rustc_hash::FxHashSet<(u32, u32)> {
    use crate::geom::tet_quality::positive_and_not_flat;
    let mut out = rustc_hash::FxHashSet::default();
    for (t, &q) in m.q.iter().enumerate() {
        if q > 0.0 || !m.alive(t as u32) {
            continue;
        }
        let tv = m.tets[t];
        let c = m.corners(tv);
        if !positive_and_not_flat(&c) {
            continue;
        }
        for [i, j] in TET10_EDGES {
            let (a, b) = (tv[i], tv[j]);
            if m.bnd.is_boundary_edge(a, b) {
                out.insert((a.min(b), a.max(b)));
            }
        }
    }
    out
}

/// Passes of [`sliver_rounds`]' last rounds, those that trade stuck slivers
/// ([`InsertScratch::trade_stuck`]), whatever the earlier rounds spent.
const TRADE_PASSES: usize = 32;

/// Most passes of a round of [`LinearParams::sliver_passes`] before its vertex searches.
const SLIVER_ROUND_PASSES: usize = 8;

/// Up to `prm.max_passes` passes over the tets below the goal, worst first.
fn run_passes(
    m: &mut LinMesh,
    prm: &LinearParams,
    sc: &mut Scratch,
    st: &mut LinearStats,
    order: &mut Vec<(f64, u32, [u32; 4])>,
    failed: &mut Vec<u64>,
) {
    let full_goal = 1.0 - prm.goal_skewness;
    let (mut worst, start_bad) = census(m, full_goal);
    let mut out_of_reach = false;
    for _ in 0..prm.max_passes {
        if !attempt_left(prm, st) || sc.stopped() {
            return;
        }
        st.passes += 1;
        sc.insert.sliver_guard = prm.guard_slivers || out_of_reach;
        let goal = if out_of_reach {
            st.reach_passes += 1;
            full_goal.min(worst + prm.reach)
        } else {
            full_goal
        };
        worst_first(m, goal, order);
        let mut changed = 0;
        for &(_, t, tv) in order.iter() {
            if m.tets[t as usize] != tv || m.q[t as usize] >= goal {
                continue;
            }
            let ti = t as usize;
            if ti < failed.len()
                && failed[ti] != 0
                && tv.iter().all(|&v| m.changed[v as usize] < failed[ti])
            {
                continue;
            }
            if !attempt_left(prm, st) || (st.attempts % 64 == 0 && sc.stopped()) {
                return;
            }
            st.attempts += 1;
            if improve_tet(m, t, prm.eps, sc, st) {
                changed += 1;
            } else if m.tets[ti] == tv {
                if failed.len() <= ti {
                    failed.resize(ti + 1, 0);
                }
                m.clock += 1;
                failed[ti] = m.clock;
            }
        }
        let (w, bad) = census(m, full_goal);
        worst = w;
        out_of_reach = out_of_reach || bad > start_bad;
        if changed == 0 {
            break;
        }
    }
}

/// Whether another attempt is within [`LinearParams::max_attempts_per_tet`].
fn attempt_left(prm: &LinearParams, st: &LinearStats) -> bool {
    st.attempts < (prm.max_attempts_per_tet * st.tets[0] as f64) as usize
}

/// Most tets per round whose vertices [`search_worst`] searches (the worst ones). Each
/// vertex search evaluates its star at 960 trial points; a front's mesh has few tets to
/// search, but the whole fill of a part with thin plates can have a third of its tets
/// there, and searching them all then takes most of the stage's time.
const SEARCH_MAX_TETS: usize = 1000;

/// Sampled searches ([`search_vertex`]) for the vertices of the tets above
/// `prm.search_skewness`, worst first (at most [`SEARCH_MAX_TETS`]); true when a vertex
/// moved.
fn search_worst(
    m: &mut LinMesh,
    prm: &LinearParams,
    sc: &mut Scratch,
    st: &mut LinearStats,
    order: &mut Vec<(f64, u32, [u32; 4])>,
) -> bool {
    let floor = 1.0 - prm.search_skewness;
    worst_first(m, floor, order);
    let mut moved = false;
    for &(_, t, tv) in order.iter().take(SEARCH_MAX_TETS) {
        if sc.stopped() {
            break;
        }
        for &v in &tv {
            if m.tets[t as usize] != tv || m.q[t as usize] >= floor || m.search_futile(v) {
                continue;
            }
            if search_vertex(m, v, &mut sc.smooth) {
                st.searches += 1;
                moved = true;
            } else {
                m.search_failed(v);
            }
        }
    }
    moved
}

/// The live tets of quality below `floor` with their corners, worst first (ties by
/// index: deterministic), into `order`.
fn worst_first(m: &LinMesh, floor: f64, order: &mut Vec<(f64, u32, [u32; 4])>) {
    order.clear();
    for (t, &q) in m.q.iter().enumerate() {
        if q < floor && m.alive(t as u32) {
            order.push((q, t as u32, m.tets[t]));
        }
    }
    order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
}

/// One attempt at the bad tet `t`; true when the mesh changed.
fn improve_tet(m: &mut LinMesh, t: u32, eps: f64, sc: &mut Scratch, st: &mut LinearStats) -> bool {
    let tv = m.tets[t as usize];
    for [i, j] in TET10_EDGES {
        if remove_edge(m, tv[i], tv[j], eps, &mut sc.flip) {
            st.edge_removals += 1;
            return true;
        }
    }
    for k in 0..4 {
        if flip23(m, t, k, eps) {
            st.flips23 += 1;
            return true;
        }
    }
    if sc.face_removal {
        for k in 0..4 {
            if remove_faces(m, t, k, eps, &mut sc.flip) {
                st.face_removals += 1;
                return true;
            }
        }
    }
    let q0 = m.q[t as usize];
    let mut moved = false;
    for &v in &tv {
        if smooth_vertex(m, v, &sc.smooth_prm, &mut sc.smooth) {
            st.smoothings += 1;
            moved = true;
        }
    }
    if moved && m.q[t as usize] > q0 {
        return true;
    }
    for [i, j] in TET10_EDGES {
        let (a, b) = (tv[i], tv[j]);
        if contract(m, a, b, eps, &mut sc.contract) || contract(m, b, a, eps, &mut sc.contract) {
            st.contractions += 1;
            return true;
        }
    }
    // Longest edges first.
    let mut edges = TET10_EDGES.map(|[i, j]| {
        let (a, b) = (tv[i], tv[j]);
        let l = crate::geom::vec3::dist2(m.pts[a as usize], m.pts[b as usize]);
        (l, a, b)
    });
    edges.sort_by(|x, y| y.0.total_cmp(&x.0).then((x.1, x.2).cmp(&(y.1, y.2))));
    for (_, a, b) in edges {
        if split_edge(m, a, b, eps, &sc.smooth_prm, &mut sc.insert, &mut sc.smooth) {
            st.insertions += 1;
            return true;
        }
    }
    if sc.cavities && insert_in_cavity(m, tv, eps, &sc.smooth_prm, &mut sc.insert, &mut sc.smooth) {
        st.insertions += 1;
        return true;
    }
    moved
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::predicates::orient3d;
    use crate::optimize::testmesh::cube;
    use rand::{Rng, SeedableRng};
    use std::collections::HashMap;

    /// Three tets around the edge (a, b) = (3, 4) of a bipyramid on an equilateral
    /// triangle of side 1, apexes at heights ±h; every vertex fixed.
    fn bipyramid(h: f64) -> (Vec<P3>, Vec<[u32; 4]>) {
        let s3 = 3f64.sqrt();
        let pts = vec![
            [1.0 / s3, 0.0, 0.0],
            [-0.5 / s3, 0.5, 0.0],
            [-0.5 / s3, -0.5, 0.0],
            [0.0, 0.0, h],
            [0.0, 0.0, -h],
        ];
        let mut tets = Vec::new();
        for i in 0..3u32 {
            let mut t = [3, 4, i, (i + 1) % 3];
            let x = t.map(|v| pts[v as usize]);
            if orient3d(x[0], x[1], x[2], x[3]) < 0 {
                t.swap(2, 3);
            }
            tets.push(t);
        }
        (pts, tets)
    }

    fn min_q(m: &LinMesh) -> f64 {
        (0..m.tets.len() as u32)
            .filter(|&t| m.alive(t))
            .map(|t| m.q[t as usize])
            .fold(f64::INFINITY, f64::min)
    }

    fn all_positive(pts: &[P3], tets: &[[u32; 4]]) -> bool {
        tets.iter().all(|t| {
            let x = t.map(|v| pts[v as usize]);
            orient3d(x[0], x[1], x[2], x[3]) > 0
        })
    }

    #[test]
    fn edge_removal_turns_a_tall_bipyramid_into_two_good_tets() {
        let (pts, tets) = bipyramid(0.8);
        let bnd = Boundary::new(5, &[]);
        let mut m = LinMesh::new(pts, tets, &bnd, ElementQuality);
        let before = min_q(&m);
        assert!(before < 0.4, "skewness {}", 1.0 - before);
        assert!(remove_edge(&mut m, 3, 4, 1e-9, &mut FlipScratch::default()));
        let (pts, tets) = m.into_parts();
        assert_eq!(tets.len(), 2);
        assert!(all_positive(&pts, &tets));
        let m = LinMesh::new(pts, tets, &bnd, ElementQuality);
        assert!(min_q(&m) > 0.99, "skewness {}", 1.0 - min_q(&m));
    }

    #[test]
    fn flip23_turns_a_flat_bipyramid_into_three_tets() {
        let (pts, three) = bipyramid(0.1);
        let bnd = Boundary::new(5, &[]);
        let m3 = LinMesh::new(pts.clone(), three, &bnd, ElementQuality);
        let q3 = min_q(&m3);
        // The same bipyramid as two flat tets sharing the triangle.
        let mut two = vec![[0, 1, 2, 3], [0, 2, 1, 4]];
        for t in two.iter_mut() {
            let x = t.map(|v| pts[v as usize]);
            if orient3d(x[0], x[1], x[2], x[3]) < 0 {
                t.swap(0, 1);
            }
        }
        let mut m = LinMesh::new(pts, two, &bnd, ElementQuality);
        let q2 = min_q(&m);
        assert!(q3 > q2);
        let k = m.tets[0].iter().position(|&v| v >= 3).unwrap();
        assert!(flip23(&mut m, 0, k, 1e-9));
        assert!((min_q(&m) - q3).abs() < 1e-12);
        let (pts, tets) = m.into_parts();
        assert_eq!(tets.len(), 3);
        assert!(all_positive(&pts, &tets));
        // A flip that would not improve is refused.
        let (pts, three) = bipyramid(0.8);
        let mut two = vec![[0, 1, 2, 3], [0, 2, 1, 4]];
        for t in two.iter_mut() {
            let x = t.map(|v| pts[v as usize]);
            if orient3d(x[0], x[1], x[2], x[3]) < 0 {
                t.swap(0, 1);
            }
        }
        drop(three);
        let mut m = LinMesh::new(pts, two, &bnd, ElementQuality);
        let k = m.tets[0].iter().position(|&v| v >= 3).unwrap();
        assert!(!flip23(&mut m, 0, k, 1e-9));
    }

    /// An icosahedron's vertices (0..12, fixed) around one interior vertex (12) at `p`.
    fn icosahedron_star(p: P3) -> (Vec<P3>, Vec<[u32; 4]>) {
        let g = (1.0 + 5f64.sqrt()) / 2.0;
        let mut pts: Vec<P3> = Vec::new();
        for (a, b) in [(1.0, g), (-1.0, g), (1.0, -g), (-1.0, -g)] {
            pts.push([0.0, a, b]);
            pts.push([a, b, 0.0]);
            pts.push([b, 0.0, a]);
        }
        pts.push(p);
        let c = 12u32;
        // Faces: triples of mutually adjacent vertices (edge length 2).
        let mut tets = Vec::new();
        for i in 0..12 {
            for j in i + 1..12 {
                for k in j + 1..12 {
                    let e = |a: usize, b: usize| {
                        (crate::geom::vec3::dist(pts[a], pts[b]) - 2.0).abs() < 1e-9
                    };
                    if e(i, j) && e(j, k) && e(i, k) {
                        let mut t = [i as u32, j as u32, k as u32, c];
                        let x = t.map(|v| pts[v as usize]);
                        if orient3d(x[0], x[1], x[2], x[3]) < 0 {
                            t.swap(0, 1);
                        }
                        tets.push(t);
                    }
                }
            }
        }
        (pts, tets)
    }

    #[test]
    fn search_lifts_a_far_off_centre_vertex_and_leaves_a_centred_one() {
        let bnd = Boundary::new(12, &[]);
        let (pts, tets) = icosahedron_star([0.9, 0.5, -0.3]);
        let fixed: Vec<P3> = pts[..12].to_vec();
        let mut m = LinMesh::new(pts, tets, &bnd, ElementQuality);
        let before = min_q(&m);
        let mut sc = SmoothScratch::default();
        for v in 0..12 {
            assert!(!search_vertex(&mut m, v, &mut sc));
        }
        assert!(search_vertex(&mut m, 12, &mut sc));
        let after = min_q(&m);
        assert!(after > before + 0.2, "{before} -> {after}");
        assert!(crate::geom::vec3::norm(m.pts[12]) < 0.2, "{:?}", m.pts[12]);
        for (a, b) in fixed.iter().zip(&m.pts[..12]) {
            assert_eq!(a.map(f64::to_bits), b.map(f64::to_bits));
        }
        for t in 0..m.tets.len() {
            assert_eq!(m.q[t], m.quality(m.tets[t]));
        }
        // At the centre nothing is better.
        let (pts, tets) = icosahedron_star([0.0; 3]);
        let mut m = LinMesh::new(pts, tets, &bnd, ElementQuality);
        assert!(!search_vertex(&mut m, 12, &mut sc));
        assert_eq!(m.pts[12], [0.0; 3]);
    }

    /// The sliver rounds count what the sliver census ([`crate::mesh::slivers::census`])
    /// will count on the assembled mesh: a tet of a cube bulged so far that its curved
    /// boundary makes it P2-invalid (scored ≤ 0) is no sliver by its corners' angles, and
    /// one whose corner moved almost onto its opposite face is.
    #[test]
    fn the_rounds_count_slivers_as_the_census_does() {
        let c = crate::optimize::testmesh::cube(3, 0.6);
        let bnd = c.boundary();
        let counts = |pts: Vec<P3>| {
            let tm = crate::mesh::build::assemble(&pts, &c.tets, c.n_surf, &c.tris, &[]);
            let mut m = LinMesh::new(pts, c.tets.clone(), &bnd, ElementQuality);
            m.set_sliver_mode(true);
            let census_unforced = crate::mesh::slivers::census(&tm).unforced;
            (unforced_left(&m), census_unforced, census(&m, 1.0).1)
        };
        let (left, unforced, below) = counts(c.pts.clone());
        assert!(below > 0, "no P2-invalid tet at this bulge");
        assert_eq!((left, unforced), (0, 0));
        // An interior vertex moved almost onto the opposite face of a tet in its star
        // (it stays inside that tet: every tet stays positive).
        let m = LinMesh::new(c.pts.clone(), c.tets.clone(), &bnd, ElementQuality);
        let v = c.n_surf;
        let t = m.vt[v][0];
        let f: Vec<u32> = m.tets[t as usize]
            .into_iter()
            .filter(|&x| x != v as u32)
            .collect();
        let mut pts = c.pts.clone();
        pts[v] = std::array::from_fn(|k| {
            let centroid = f.iter().map(|&x| c.pts[x as usize][k]).sum::<f64>() / 3.0;
            0.99 * centroid + 0.01 * c.pts[v][k]
        });
        let (left, unforced, below) = counts(pts);
        assert!(unforced > 0);
        assert_eq!(left, unforced);
        assert!(below > unforced);
    }

    /// An interior vertex moved almost onto a neighbour makes the tets on the edge
    /// between them unforced slivers; merging it into that neighbour takes them along,
    /// every tet left positive and the volume the same. Where no unforced sliver is left
    /// to remove, no merge is made.
    #[test]
    fn a_vertex_merged_into_a_neighbour_takes_its_slivers_along() {
        use crate::geom::vec3::tet_det;
        let c = crate::optimize::testmesh::cube(3, 0.0);
        let bnd = c.boundary();
        let pts0 = crate::optimize::testmesh::jittered(&c, 3, 0.1);
        let volume = |m: &LinMesh| -> f64 {
            (0..m.tets.len() as u32)
                .filter(|&t| m.alive(t))
                .map(|t| {
                    let p = m.corners(m.tets[t as usize]);
                    tet_det(p[0], p[1], p[2], p[3])
                })
                .sum()
        };
        let mut sc = ContractScratch::default();
        let mut m = LinMesh::new(pts0.clone(), c.tets.clone(), &bnd, ElementQuality);
        m.set_sliver_mode(true);
        assert_eq!(unforced_left(&m), 0);
        let pairs: Vec<(u32, u32)> = (0..m.pts.len() as u32)
            .filter(|&r| !bnd.is_fixed(r))
            .flat_map(|r| m.neighbours(r).into_iter().map(move |k| (r, k)))
            .collect();
        for &(r, k) in &pairs {
            assert!(!contract::contract_fewer(&mut m, r, k, false, &mut sc));
        }
        let mut merged = 0;
        for &(r, k) in &pairs {
            let mut pts = pts0.clone();
            pts[r as usize] =
                std::array::from_fn(|d| 0.98 * pts0[k as usize][d] + 0.02 * pts0[r as usize][d]);
            let mut m = LinMesh::new(pts, c.tets.clone(), &bnd, ElementQuality);
            m.set_sliver_mode(true);
            let before = unforced_left(&m);
            let v0 = volume(&m);
            if bnd.is_fixed(k) {
                // A boundary vertex is never merged away.
                assert!(!contract::contract_fewer(&mut m, k, r, false, &mut sc));
            }
            if !contract::contract_fewer(&mut m, r, k, false, &mut sc) {
                continue;
            }
            merged += 1;
            assert!(before > 0);
            assert!(unforced_left(&m) < before, "{r} {k}");
            assert!(m.vt[r as usize].is_empty());
            for t in (0..m.tets.len() as u32).filter(|&t| m.alive(t)) {
                let p = m.corners(m.tets[t as usize]);
                assert!(orient3d(p[0], p[1], p[2], p[3]) > 0);
            }
            assert!((volume(&m) - v0).abs() < 1e-12 * v0.abs());
        }
        assert!(merged > 0, "no merge among {} pairs", pairs.len());
    }

    /// On a curved boundary, a merge whose new tets include one that is not valid as a
    /// P2 element is refused, unless the boundary edges may be put on their chords
    /// (a surface curved from a linear one): then the straight tet is what counts.
    #[test]
    fn a_merge_may_leave_a_tet_for_the_straightening_only_where_chords_are_allowed() {
        let c = crate::optimize::testmesh::cube(3, 0.6);
        let bnd = c.boundary();
        let m0 = LinMesh::new(c.pts.clone(), c.tets.clone(), &bnd, ElementQuality);
        let mut sc = ContractScratch::default();
        let mut only_chords = 0;
        for r in (0..c.pts.len() as u32).filter(|&r| !bnd.is_fixed(r)) {
            for k in m0.neighbours(r).into_iter().filter(|&x| bnd.is_fixed(x)) {
                let mut pts = c.pts.clone();
                pts[r as usize] = std::array::from_fn(|d| {
                    0.97 * c.pts[k as usize][d] + 0.03 * c.pts[r as usize][d]
                });
                let fresh = || {
                    let mut m = LinMesh::new(pts.clone(), c.tets.clone(), &bnd, ElementQuality);
                    m.set_sliver_mode(true);
                    m
                };
                let (mut plain, mut chorded) = (fresh(), fresh());
                let before = unforced_left(&plain);
                let a = contract::contract_fewer(&mut plain, r, k, false, &mut sc);
                let b = contract::contract_fewer(&mut chorded, r, k, true, &mut sc);
                // Whatever chords allow, a merge leaves fewer, and every tet positive.
                for (m, applied) in [(&plain, a), (&chorded, b)] {
                    if applied {
                        assert!(unforced_left(m) < before);
                        for t in (0..m.tets.len() as u32).filter(|&t| m.alive(t)) {
                            assert!(crate::geom::tet_quality::positive_and_not_flat(
                                &m.corners(m.tets[t as usize])
                            ));
                        }
                    }
                }
                // Chords only allow more.
                assert!(!a || b, "{r} {k}");
                if b && !a {
                    only_chords += 1;
                    // What made the difference: a tet the merge made (on `k`, not in the
                    // mesh before it) that is not valid as a P2 element.
                    let old: std::collections::HashSet<[u32; 4]> =
                        plain.tets.iter().copied().collect();
                    let made_invalid = chorded.vt[k as usize]
                        .iter()
                        .filter(|&&t| !old.contains(&chorded.tets[t as usize]))
                        .any(|&t| chorded.q[t as usize] <= 0.0);
                    assert!(made_invalid, "{r} {k}");
                }
            }
        }
        assert!(only_chords > 0, "no merge that only chords allow");
    }

    /// A vertex whose search failed is not searched again until its star changes (the
    /// search would fail again: it depends on the star's corners and the score only).
    #[test]
    fn a_failed_search_waits_for_a_change_in_the_star() {
        let bnd = Boundary::new(12, &[]);
        let (pts, tets) = icosahedron_star([0.0; 3]);
        let mut m = LinMesh::new(pts, tets, &bnd, ElementQuality);
        let mut sc = Scratch::default();
        let mut st = LinearStats::default();
        // Every tet of the centred star counts as poor, and none can be lifted.
        let prm = LinearParams {
            search_skewness: 0.0,
            ..LinearParams::default()
        };
        let mut search = |m: &mut LinMesh| search_worst(m, &prm, &mut sc, &mut st, &mut Vec::new());
        assert!(!m.search_futile(12));
        assert!(!search(&mut m));
        assert!(m.search_futile(12));
        // A corner of its star moves: worth a search again.
        m.touch_star(0);
        assert!(!m.search_futile(12));
        assert!(!search(&mut m));
        assert!(m.search_futile(12));
        // The score changes: worth a search again.
        m.set_sliver_mode(true);
        assert!(!m.search_futile(12));
    }

    #[test]
    fn smoother_centres_a_vertex_and_never_moves_the_boundary() {
        let (pts, tets) = icosahedron_star([0.55, 0.3, -0.2]);
        let c = 12u32;
        assert_eq!(tets.len(), 20);
        let fixed: Vec<P3> = pts[..12].to_vec();
        let bnd = Boundary::new(12, &[]);
        let mut m = LinMesh::new(pts, tets, &bnd, ElementQuality);
        let before = min_q(&m);
        for v in 0..12 {
            assert!(!smooth_vertex(
                &mut m,
                v,
                &SmoothParams::default(),
                &mut SmoothScratch::default()
            ));
        }
        assert!(smooth_vertex(
            &mut m,
            c,
            &SmoothParams::default(),
            &mut SmoothScratch::default()
        ));
        let after = min_q(&m);
        assert!(after > before + 0.1, "{before} -> {after}");
        assert!(
            crate::geom::vec3::norm(m.pts[c as usize]) < 0.05,
            "{:?}",
            m.pts[c as usize]
        );
        for (a, b) in fixed.iter().zip(&m.pts[..12]) {
            assert_eq!(a.map(f64::to_bits), b.map(f64::to_bits));
        }
        // Cached qualities are the true ones.
        for t in 0..m.tets.len() {
            assert_eq!(m.q[t], m.quality(m.tets[t]));
        }
    }

    /// Faces of exactly one tet, as sorted triples.
    fn boundary_faces(tets: &[[u32; 4]]) -> Vec<[u32; 3]> {
        let mut count: HashMap<[u32; 3], u32> = HashMap::new();
        for t in tets {
            for k in 0..4 {
                let mut f = [0u32; 3];
                let mut n = 0;
                for (i, &v) in t.iter().enumerate() {
                    if i != k {
                        f[n] = v;
                        n += 1;
                    }
                }
                f.sort_unstable();
                *count.entry(f).or_insert(0) += 1;
            }
        }
        let mut out: Vec<[u32; 3]> = count
            .into_iter()
            .filter(|(_, c)| *c == 1)
            .map(|(f, _)| f)
            .collect();
        out.sort_unstable();
        out
    }

    /// The cube of [`cube`]`(4, 0.06)` with its interior vertices shaken (every tet
    /// positive), and the shaken points.
    fn shaken_cube() -> (crate::optimize::testmesh::CubeMesh, Vec<P3>) {
        let c = cube(4, 0.06);
        let mut rng = rand::rngs::StdRng::seed_from_u64(3);
        let mut pts = c.pts.clone();
        for v in c.n_surf..pts.len() {
            for _ in 0..20 {
                let old = pts[v];
                for x in pts[v].iter_mut() {
                    *x += rng.random_range(-0.09..0.09);
                }
                if all_positive(&pts, &c.tets) {
                    break;
                }
                pts[v] = old;
            }
        }
        (c, pts)
    }

    #[test]
    fn improve_linear_keeps_the_boundary_and_validity_and_raises_the_worst() {
        let (c, pts) = shaken_cube();
        let bnd = c.boundary();
        let m0 = LinMesh::new(pts.clone(), c.tets.clone(), &bnd, ElementQuality);
        let q0 = min_q(&m0);
        drop(m0);
        let (pts2, tets2, st) =
            improve_linear(pts.clone(), c.tets.clone(), &bnd, &LinearParams::default());
        assert!(st.max_skewness[1] < st.max_skewness[0], "{st:?}");
        assert!((st.max_skewness[0] - (1.0 - q0)).abs() < 1e-12);
        assert!(st.edge_removals + st.flips23 + st.smoothings + st.contractions > 0);
        // Boundary points bit-identical, boundary faces the same, every tet positive.
        for (a, b) in pts[..c.n_surf].iter().zip(&pts2[..c.n_surf]) {
            assert_eq!(a.map(f64::to_bits), b.map(f64::to_bits));
        }
        assert_eq!(boundary_faces(&c.tets), boundary_faces(&tets2));
        assert!(all_positive(&pts2, &tets2));
        // The P2 mesh is conforming, fills the cube and is certified valid.
        let mesh = crate::mesh::build::assemble(&pts2, &tets2, c.n_surf, &c.tris, &[]);
        let conf = crate::mesh::check::check_conformity(&mesh).unwrap();
        assert!((conf.volume_linear - 1.0).abs() < 1e-12);
        assert!(crate::mesh::report::uncertified(&mesh).is_empty());
        // Deterministic.
        let (pts3, tets3, _) = improve_linear(pts, c.tets.clone(), &bnd, &LinearParams::default());
        assert_eq!(tets2, tets3);
        assert!(pts2
            .iter()
            .zip(&pts3)
            .all(|(a, b)| a.map(f64::to_bits) == b.map(f64::to_bits)));
    }

    #[test]
    fn the_stage_times_each_of_its_parts() {
        let (c, pts) = shaken_cube();
        let bnd = c.boundary();
        // Every part runs: flat passes asked for, and a search threshold every poor tet
        // is above.
        let prm = LinearParams {
            flat_skewness: Some(0.3),
            search_skewness: 0.3,
            ..LinearParams::default()
        };
        let clock = std::time::Instant::now();
        let st = improve_linear(pts, c.tets.clone(), &bnd, &prm).2;
        let wall = clock.elapsed().as_secs_f64();
        let s = &st.seconds;
        let parts = [s.passes, s.searches, s.flat, s.slivers];
        assert!(st.passes > 0 && st.searches > 0, "{st:?}");
        assert!(parts.iter().all(|&x| x > 0.0), "{s:?}");
        assert!(parts.iter().sum::<f64>() <= wall, "{s:?} in {wall} s");
    }

    #[test]
    fn attempts_stay_within_their_bound() {
        let (c, pts) = shaken_cube();
        let bnd = c.boundary();
        let free = improve_linear(pts.clone(), c.tets.clone(), &bnd, &LinearParams::default()).2;
        let n = c.tets.len();
        assert!(free.attempts > 3, "{free:?}");
        assert!(free.attempts as f64 <= LinearParams::default().max_attempts_per_tet * n as f64);
        // A bound below what the unbounded run makes: exactly that many, and a valid,
        // improved mesh still.
        let bound = (free.attempts / 2) as f64 / n as f64;
        let prm = LinearParams {
            max_attempts_per_tet: bound,
            ..LinearParams::default()
        };
        let (pts2, tets2, st) = improve_linear(pts.clone(), c.tets.clone(), &bnd, &prm);
        assert_eq!(st.attempts, (bound * n as f64) as usize, "{st:?}");
        assert!(st.max_skewness[1] < st.max_skewness[0], "{st:?}");
        assert!(all_positive(&pts2, &tets2));
        // None allowed (no sampled search, and no sliver passes, which have a budget of
        // their own): the mesh is returned as it came.
        let prm = LinearParams {
            max_attempts_per_tet: 0.0,
            search_skewness: 1.0,
            sliver_passes: 0,
            ..LinearParams::default()
        };
        let (pts3, tets3, st) = improve_linear(pts.clone(), c.tets.clone(), &bnd, &prm);
        assert_eq!((st.attempts, st.passes), (0, 0));
        assert_eq!(tets3, c.tets);
        assert!(pts3
            .iter()
            .zip(&pts)
            .all(|(a, b)| a.map(f64::to_bits) == b.map(f64::to_bits)));
    }

    #[test]
    fn an_unreachable_goal_narrows_the_passes_to_the_worst() {
        let (c, pts) = shaken_cube();
        let bnd = c.boundary();
        // The default goal is within reach here: every pass aims at it.
        let st = improve_linear(pts.clone(), c.tets.clone(), &bnd, &LinearParams::default()).2;
        assert_eq!(st.reach_passes, 0, "{st:?}");
        // A goal almost no tet can meet (skewness 0.05): the first pass's splits leave
        // more tets below it than there were, so the later passes aim at the worst only.
        let unreachable = LinearParams {
            goal_skewness: 0.05,
            search_skewness: 1.0,
            ..LinearParams::default()
        };
        let wide = LinearParams {
            reach: f64::INFINITY,
            ..unreachable.clone()
        };
        let (pts_w, tets_w, st_w) = improve_linear(pts.clone(), c.tets.clone(), &bnd, &wide);
        let (pts_n, tets_n, st_n) = improve_linear(pts, c.tets.clone(), &bnd, &unreachable);
        assert!(st_n.tets[1] > st_n.tets[0], "{st_n:?}");
        assert!(
            st_n.reach_passes > 0 && st_n.reach_passes < st_n.passes,
            "{st_n:?}"
        );
        // An infinite reach keeps aiming at the full goal (the passes are counted all the
        // same): it makes many more attempts, here until their bound.
        assert!(st_w.reach_passes > 0, "{st_w:?}");
        assert!(2 * st_n.attempts < st_w.attempts, "{st_n:?} {st_w:?}");
        for (p, t, st) in [(&pts_n, &tets_n, &st_n), (&pts_w, &tets_w, &st_w)] {
            assert!(all_positive(p, t));
            assert_eq!(boundary_faces(&c.tets), boundary_faces(t));
            assert!(st.max_skewness[1] < st.max_skewness[0], "{st:?}");
        }
    }
}
