//! High-order node optimization of the assembled P2 mesh.
//!
//! Seeds are the elements whose certified min J / max J is below a threshold, worst
//! first. Around each a patch is built (`patch`); patches are coloured so that those of
//! one colour share no active element, and each patch is optimized once the patches of
//! lower colours it shares an element with are done (`schedule`: in parallel, and the
//! same result as colour by colour), by a sequence of L-BFGS runs on the log-barrier
//! objective (`objective`) with the barrier moved up to just below the current minimum
//! after each run (Gmsh's moving barrier; it starts from any state, including invalid
//! elements), each variable measured in its node's local edge length. A patch that runs
//! alone (the rest of its round waiting for it) has its elements evaluated by every
//! thread. A patch's result is kept only when the certified minimum min J / max J of
//! its active elements rose (and, if vertices moved, their skewness stayed within
//! bounds); the output does not depend on the thread count. Surface nodes are never
//! variables.

mod jacobian;
mod lanes;
mod lbfgs;
mod objective;
mod patch;
mod schedule;

use crate::geom::predicates::orient3d;
use crate::geom::tet_quality::{dihedral_extremes, skewness_from_extremes};
use crate::geom::vec3::{dist, mid, P3};
use crate::mesh::report::tet_nodes;
use crate::mesh::TetMesh;
use crate::optimize::Boundary;
use lanes::L;
use lbfgs::Lbfgs;
use objective::{nodes, Objective, PatchElem, FIXED};
use patch::{colour, Marks, NodeElems, Patch};
use rayon::prelude::*;

/// How the rounds of one kind run: the part of [`HighOrderParams`] that differs between
/// staged and direct rounds.
#[derive(Clone, Debug, PartialEq)]
pub struct RoundTuning {
    /// Vertex-neighbour rings around a seed in its patch (round r uses
    /// `min(layers + r, max_layers)`).
    pub layers: usize,
    /// Rounds of (seed, patch, optimize).
    pub rounds: usize,
    /// L-BFGS iterations per barrier.
    pub iterations: usize,
    /// Barrier updates per patch.
    pub barrier_updates: usize,
    /// An L-BFGS run stops once every element of its patch is this far above the
    /// threshold (so that the neighbours' later patches do not push them straight back
    /// below it).
    pub stop_slack: f64,
}

/// Tuning of the high-order stage.
///
/// Where some element starts below [`reach_below`](Self::reach_below) (the screw, the
/// hinge), the rounds are staged ([`staged`](Self::staged), aiming at most
/// [`reach`](Self::reach) above the worst element); elsewhere they aim at the threshold
/// directly ([`direct`](Self::direct)). The staged defaults spend the effort on the worst
/// elements: two rounds of two-layer patches with 8 L-BFGS iterations per barrier, and
/// more (up to [`max_rounds`](Self::max_rounds)) while each round lifts the worst element
/// to its aim.
/// Against [`HighOrderParams::thorough`] (five rounds of one-layer patches, 6
/// iterations, reach 0.2: the defaults until 2026-11-24), measured on the screw: 15k
/// element evaluations instead of 50k, certified min J / max J 0.630 instead of 0.626,
/// but 204 elements left below the threshold instead of 78 (mean 0.891 instead of
/// 0.924); on the hinge the same minimum (0.436), 125k evaluations instead of 282k, max
/// skewness 0.831 instead of 0.812. `examples/benchmarks/optimize_tradeoff.rs` measures both.
#[derive(Clone, Debug)]
pub struct HighOrderParams {
    /// Elements with certified min J / max J below this seed patches.
    pub threshold: f64,
    /// Each staged round aims at most this far above the current worst element (the
    /// round's threshold is min(threshold, max(worst, 0) + reach)): effort goes to the
    /// worst first, and to every invalid element while some are left.
    pub reach: f64,
    /// When the worst element is at least this good at the start, the rounds are direct:
    /// every round aims at the threshold (staging only pays where some element is poor).
    pub reach_below: f64,
    /// The rounds where some element starts below [`reach_below`](Self::reach_below).
    pub staged: RoundTuning,
    /// The rounds elsewhere: where every element is already fair, two barrier updates
    /// suffice (with a stop slack of 0.01, 14-21% less work than three on the sphere,
    /// torus, tube and lv, the same certified minimum to three decimals).
    pub direct: RoundTuning,
    /// Largest patch layers in any round (see [`RoundTuning::layers`]).
    pub max_layers: usize,
    /// Staged rounds go on past [`RoundTuning::rounds`], up to this many, while some
    /// element is not valid (an untangling needs every round it can get) or the last
    /// round lifted the worst element to its aim (then [`reach`](Self::reach), not the
    /// optimizer, held it back: `scripts/aniso-torus.py 12 27 --no-shift` starting at
    /// 0.17 ended at 0.47 after two rounds, 0.72 after four; the demo torus of 16 x 30 at
    /// 0.57 and 0.85; the screw and the hinge fall short of their second round's aim and
    /// stop there). Direct rounds make exactly their `rounds`.
    pub max_rounds: usize,
    /// Let interior vertices move too (their edges' mid nodes follow them).
    pub move_vertices: bool,
    /// Vertices move only in a patch whose min J / max J after moving the mid nodes is
    /// still below this (moving them costs more and rarely helps a patch that is nearly
    /// good enough), until a round improves nothing: later rounds move them in every
    /// patch below the threshold.
    pub vertices_below: f64,
    /// Largest corner skewness moving vertices may create (a patch already worse may
    /// not get worse).
    pub max_skewness: f64,
    /// The larger skewness allowed in a patch whose min J / max J is below
    /// [`HighOrderParams::rescue_below`]: corner shape traded for curved validity where
    /// the curved quality is poor.
    pub max_skewness_rescue: f64,
    /// See [`HighOrderParams::max_skewness_rescue`].
    pub rescue_below: f64,
}

impl HighOrderParams {
    /// More staged rounds: five rounds of one-layer patches, 6 iterations per barrier,
    /// reach 0.2 (see [`HighOrderParams`]). Two to three times the staged rounds' work
    /// for a better distribution above the worst element; surfaces whose worst
    /// element starts at [`reach_below`](Self::reach_below) or better are unaffected
    /// (their rounds are [`direct`](Self::direct)).
    pub fn thorough() -> Self {
        let d = HighOrderParams::default();
        HighOrderParams {
            reach: 0.2,
            staged: RoundTuning {
                layers: 1,
                rounds: 5,
                iterations: 6,
                stop_slack: 0.03,
                ..d.staged.clone()
            },
            ..d
        }
    }
}

impl Default for HighOrderParams {
    fn default() -> Self {
        HighOrderParams {
            threshold: 0.85,
            reach: 0.15,
            reach_below: 0.35,
            staged: RoundTuning {
                layers: 2,
                rounds: 2,
                iterations: 8,
                barrier_updates: 3,
                stop_slack: 0.05,
            },
            direct: RoundTuning {
                layers: 1,
                rounds: 5,
                iterations: 6,
                barrier_updates: 2,
                stop_slack: 0.01,
            },
            max_layers: 2,
            max_rounds: 5,
            move_vertices: true,
            vertices_below: 0.7,
            max_skewness: 0.7,
            max_skewness_rescue: 0.8,
            rescue_below: 0.5,
        }
    }
}

/// What one round runs with: the stage's settings, the tuning of this mesh's kind of
/// round, and the round's own threshold and vertex rule.
struct RoundPrm<'p> {
    stage: &'p HighOrderParams,
    tune: &'p RoundTuning,
    /// This round's threshold (see [`HighOrderParams::reach`]).
    threshold: f64,
    /// This round's [`HighOrderParams::vertices_below`].
    vertices_below: f64,
    /// The boundary, for the sliver floors ([`Boundary::tet_sliver_floor`]).
    bnd: &'p Boundary,
}

/// What the high-order stage did.
#[derive(Debug, Clone, Default, serde::Serialize)]
#[non_exhaustive]
pub struct HighOrderStats {
    /// Certified min of min J / max J over the mesh, before and after.
    pub min_scaled_jacobian: [f64; 2],
    /// Elements not certified valid, before and after.
    pub invalid: [usize; 2],
    /// Elements below the threshold, before and after.
    pub below_threshold: [usize; 2],
    /// Rounds made.
    pub rounds: usize,
    /// Patches optimized.
    pub patches: usize,
    /// Patches whose result was kept.
    pub patches_improved: usize,
    /// Elements whose certified min J / max J rose.
    pub elements_improved: usize,
    /// Active elements summed over the patches.
    pub patch_elements: u64,
    /// Element evaluations of the objective (with gradient): the work done.
    pub element_evaluations: u64,
}

/// The optimizer's scores (see [`objective::score_block`]) of the elements `ts` into `out`
/// ([`L`] at a time, in parallel).
fn element_scores(mesh: &TetMesh, ts: &[u32], enough: f64, out: &mut [f64]) {
    out.par_chunks_mut(L)
        .zip(ts.par_chunks(L))
        .for_each(|(o, t)| {
            let xs = std::array::from_fn(|l| tet_nodes(mesh, t[l.min(t.len() - 1)] as usize));
            o.copy_from_slice(&objective::score_block(&xs, t.len(), enough)[..t.len()]);
        });
}

/// Optimize the free nodes of `mesh` (every node at index >= `bnd.n_surf`). Runs on the
/// current rayon pool; the result is the same for any number of threads.
pub fn optimize_high_order(
    mesh: &mut TetMesh,
    bnd: &Boundary,
    prm: &HighOrderParams,
) -> HighOrderStats {
    optimize_seeded(mesh, bnd, prm, None)
}

/// [`optimize_high_order`] again after the nodes `moved` moved (a mesh it optimized
/// before): only the elements containing one of them seed patches. Elsewhere the mesh is
/// as the last run left it, and optimizing it again would repeat that run's work for
/// little or nothing.
pub(crate) fn reoptimize_high_order_near(
    mesh: &mut TetMesh,
    bnd: &Boundary,
    prm: &HighOrderParams,
    moved: &[u32],
) -> HighOrderStats {
    optimize_seeded(mesh, bnd, prm, Some(moved))
}

/// [`optimize_high_order`], with patches seeded only by elements containing a node of
/// `near` where given.
fn optimize_seeded(
    mesh: &mut TetMesh,
    bnd: &Boundary,
    prm: &HighOrderParams,
    near: Option<&[u32]>,
) -> HighOrderStats {
    let mut st = HighOrderStats::default();
    let ne = mesh.tets.len();
    let all: Vec<u32> = (0..ne as u32).collect();
    let mut sj = vec![0.0; ne];
    element_scores(mesh, &all, prm.threshold, &mut sj);
    let sj_start = sj.clone();
    let census = |sj: &[f64]| {
        let min = sj.iter().copied().fold(f64::INFINITY, f64::min);
        let invalid = sj.iter().filter(|&&v| v.is_nan() || v <= 0.0).count();
        let below = sj.iter().filter(|&&v| v < prm.threshold).count();
        (min, invalid, below)
    };
    let (m0, i0, b0) = census(&sj);
    st.min_scaled_jacobian[0] = if ne == 0 { 1.0 } else { m0 };
    st.invalid[0] = i0;
    st.below_threshold[0] = b0;
    let adj = NodeElems::new(mesh);
    // Elements that may seed a patch.
    let seeding: Vec<bool> = match near {
        None => vec![true; ne],
        Some(nodes) => {
            let mut m = vec![false; ne];
            for &n in nodes {
                for &e in adj.of(n) {
                    m[e as usize] = true;
                }
            }
            m
        }
    };
    let mut marks = Marks::new(ne, mesh.nodes.len());
    let direct = m0 >= prm.reach_below;
    // Set once a round improved nothing with vertices held back: from then on vertices
    // may move in every patch below the threshold.
    let mut escalate = false;
    // This mesh's kind of rounds, staged or direct, resolved once.
    let (tune, max_rounds) = if direct {
        (&prm.direct, prm.direct.rounds)
    } else {
        (&prm.staged, prm.max_rounds.max(prm.staged.rounds))
    };
    // The last round's aim; reaching it means the reach, not the optimizer, held the
    // worst element back, so another round can lift it further.
    let mut aim = f64::INFINITY;
    for round in 0..max_rounds {
        let (worst, invalid, _) = census(&sj);
        if round >= tune.rounds && worst < aim && invalid == 0 {
            break;
        }
        let rp = RoundPrm {
            stage: prm,
            tune,
            bnd,
            vertices_below: if escalate {
                prm.threshold
            } else {
                prm.vertices_below
            },
            threshold: if direct {
                prm.threshold
            } else {
                prm.threshold.min(worst.max(0.0) + prm.reach)
            },
        };
        let mut seeds: Vec<u32> = (0..ne as u32)
            .filter(|&t| seeding[t as usize] && sj[t as usize] < rp.threshold)
            .collect();
        if seeds.is_empty() {
            break;
        }
        st.rounds += 1;
        seeds.sort_by(|&a, &b| sj[a as usize].total_cmp(&sj[b as usize]).then(a.cmp(&b)));
        // One patch per seed not already inside an earlier patch of this round.
        let mut covered = vec![false; ne];
        let mut patches: Vec<Patch> = Vec::new();
        for &s in &seeds {
            if covered[s as usize] {
                continue;
            }
            let p = patch::build(
                mesh,
                &adj,
                bnd.n_surf,
                s,
                (tune.layers + round).min(prm.max_layers.max(tune.layers)),
                prm.move_vertices,
                &mut marks,
            );
            if p.free.is_empty() {
                continue;
            }
            // Seeds all of whose non-surface nodes are free here are covered.
            for &e in &p.elems {
                let all_free = mesh.tets[e as usize].iter().all(|&n| {
                    (n as usize) < bnd.n_surf
                        || p.free.binary_search(&n).is_ok()
                        || (!prm.move_vertices && adj.is_vertex[n as usize])
                });
                if all_free {
                    covered[e as usize] = true;
                }
            }
            patches.push(p);
        }
        let colours = colour(&patches, ne);
        let done = schedule::run_round(mesh, &patches, &colours, &mut sj, &rp);
        st.patches += patches.len();
        st.patch_elements += patches.iter().map(|p| p.elems.len() as u64).sum::<u64>();
        st.element_evaluations += done.work;
        st.patches_improved += done.improved;
        aim = rp.threshold;
        if done.improved == 0 {
            if escalate || rp.vertices_below >= rp.threshold || !prm.move_vertices {
                break;
            }
            escalate = true;
        }
    }
    // Exact scores where a round stored a cheaper lower bound below the threshold.
    let redo: Vec<u32> = (0..ne as u32)
        .filter(|&t| sj[t as usize] < prm.threshold && sj[t as usize] != sj_start[t as usize])
        .collect();
    let mut exact = vec![0.0; redo.len()];
    element_scores(mesh, &redo, prm.threshold, &mut exact);
    for (&t, v) in redo.iter().zip(exact) {
        sj[t as usize] = v;
    }
    let (m1, i1, b1) = census(&sj);
    st.min_scaled_jacobian[1] = if ne == 0 { 1.0 } else { m1 };
    st.invalid[1] = i1;
    st.below_threshold[1] = b1;
    st.elements_improved = sj.iter().zip(&sj_start).filter(|(a, b)| a > b).count();
    st
}

/// The outcome of a patch whose optimization is kept.
struct PatchResult {
    /// New position of each free node (patch order).
    positions: Vec<P3>,
    /// New certified min J / max J of each active element (patch order).
    sj: Vec<f64>,
}

/// Run the moving-barrier sequence on `elems` from `v` (updated in place), L-BFGS working
/// on the variables divided by their length scales `scale` ([`length_scales`]).
/// Returns the number of element evaluations of the objective.
fn run_barrier(
    elems: &[PatchElem],
    v: &mut [f64],
    scale: &[f64],
    prm: &RoundPrm,
    lb: &mut Lbfgs,
    lone: &dyn Fn() -> bool,
) -> u64 {
    let mut obj = Objective {
        elems,
        eps: 0.0,
        last_ratio: Default::default(),
        outs: Default::default(),
        lone,
    };
    let (mut mmin, ratio) = obj.min_measure(v);
    let mut evals = 0u64;
    if !mmin.is_finite() || mmin >= 1.0 || ratio >= prm.threshold {
        return 0;
    }
    let mut u: Vec<f64> = v.iter().zip(scale).map(|(x, s)| x / s).collect();
    let unused = unused_vars(elems, v.len() / 3);
    let start = v.to_vec();
    for _ in 0..prm.tune.barrier_updates {
        obj.eps = if mmin == 0.0 {
            -0.1
        } else {
            mmin - 0.1 * mmin.abs()
        };
        let last = &obj.last_ratio;
        let obj = &obj;
        let mut f = |u: &[f64], g: &mut [f64]| {
            evals += elems.len() as u64;
            unscale(u, scale, v);
            let val = obj.eval(v, g);
            for (g, s) in g.iter_mut().zip(scale) {
                *g *= s;
            }
            val
        };
        let target = prm.threshold + prm.tune.stop_slack;
        let mut reached = || last.get() >= target;
        lb.minimize(
            &mut u,
            &mut f,
            prm.tune.iterations,
            FIRST_STEP,
            &mut reached,
        );
        // (The last evaluation may have been a rejected trial point.)
        unscale(&u, scale, v);
        for &i in &unused {
            v[3 * i..3 * i + 3].copy_from_slice(&start[3 * i..3 * i + 3]);
        }
        let (new, ratio) = obj.min_measure(v);
        let stagnated = (new - mmin).abs() < 0.01 * mmin.abs().max(1e-3);
        mmin = new;
        if stagnated || ratio >= prm.threshold {
            break;
        }
    }
    evals
}

/// The variables (of `n`) no element of `elems` uses. [`run_barrier`] puts them back as
/// they were: [`unscale`] brings each back as (x / s) * s, which can be an ulp off, and a
/// vertex the mid-node stage leaves fixed that way can invert a nearly flat corner tet
/// that stage never checks (OpenSCAD's children.stl: two, after the whole fill).
fn unused_vars(elems: &[PatchElem], n: usize) -> Vec<usize> {
    let mut used = vec![false; n];
    for e in elems {
        for &i in e.var.iter().filter(|&&i| i != FIXED) {
            used[i as usize] = true;
        }
    }
    (0..n).filter(|&i| !used[i]).collect()
}

/// The variables `v` of the scaled variables `u` (`v = u * scale`).
#[inline]
fn unscale(u: &[f64], scale: &[f64], v: &mut [f64]) {
    for ((x, u), s) in v.iter_mut().zip(u).zip(scale) {
        *x = u * s;
    }
}

/// Length of the first L-BFGS step of a barrier run, in units of the variables' length
/// scales.
const FIRST_STEP: f64 = 0.02;

/// For each variable of `elems` (`n_free` free nodes, three coordinates each), the mean
/// edge length of the elements at its node. The objective is scale-free (it measures
/// J / J_straight), so its derivative with respect to a node scales as 1 / the local
/// length: divided by these scales, the variables of small and large elements have
/// gradients of one size, which suits L-BFGS's single initial curvature. On the six
/// benchmark surfaces it made the high-order stage's results as good or better (the
/// screw 0.616 -> 0.626 min J / max J, the hinge 414 -> 367 elements below the
/// threshold) with 5-10% less work.
fn length_scales(elems: &[PatchElem], n_free: usize) -> Vec<f64> {
    let mut sum = vec![0.0; n_free];
    let mut count = vec![0u32; n_free];
    for e in elems {
        let l = crate::geom::shape::TET10_EDGES
            .iter()
            .map(|&[a, b]| dist(e.x[a], e.x[b]))
            .sum::<f64>()
            / 6.0;
        for &i in &e.var {
            if i != FIXED {
                sum[i as usize] += l;
                count[i as usize] += 1;
            }
        }
    }
    let mut scale = vec![0.0; 3 * n_free];
    for (i, (s, c)) in sum.iter().zip(&count).enumerate() {
        let l = if *c > 0 && *s > 0.0 {
            s / *c as f64
        } else {
            1.0
        };
        scale[3 * i..3 * i + 3].fill(l);
    }
    scale
}

/// Scores of `elems` at `v`, their minimum and (when `with_skew`, else 0) the largest
/// corner skewness. In parallel parts when the patch runs `lone` (see
/// [`objective::part_len`]); the result is the same.
fn evaluate(
    elems: &[PatchElem],
    v: &[f64],
    enough: f64,
    with_skew: bool,
    out: &mut Vec<f64>,
    lone: &dyn Fn() -> bool,
) -> (f64, f64) {
    // Score and corner skewness of each element of `elems` into `o`.
    let score = |elems: &[PatchElem], o: &mut [(f64, f64)]| {
        let mut xs = [[[0.0; 3]; 10]; L];
        for (chunk, o) in elems.chunks(L).zip(o.chunks_mut(L)) {
            objective::gather(chunk, v, &mut xs);
            let sc = objective::score_block(&xs, chunk.len(), enough);
            for ((xe, &s), o) in xs.iter().zip(&sc).zip(o.iter_mut()) {
                // An inverted corner tet counts as the worst skewness: the final check
                // wants every corner tet positive, whatever the curved Jacobian says.
                let k = if !with_skew {
                    0.0
                } else if orient3d(xe[0], xe[1], xe[2], xe[3]) > 0 {
                    skew(xe)
                } else {
                    f64::INFINITY
                };
                *o = (s, k);
            }
        }
    };
    let mut res = vec![(0.0, 0.0); elems.len()];
    match objective::part_len(elems.len(), lone) {
        Some(per) => res
            .par_chunks_mut(per)
            .zip(elems.par_chunks(per))
            .for_each(|(o, e)| score(e, o)),
        None => score(elems, &mut res),
    }
    out.clear();
    out.extend(res.iter().map(|r| r.0));
    let lo = res.iter().fold(f64::INFINITY, |a, r| a.min(r.0));
    let sk = res.iter().fold(0.0f64, |a, r| a.max(r.1));
    (lo, sk)
}

/// What a patch starts from, read from the mesh once every patch it depends on is done
/// (see [`schedule`]).
struct PatchJob {
    /// The active elements with their fixed nodes and variables.
    elems: Vec<PatchElem>,
    /// Smallest score of the active elements before.
    before_min: f64,
    /// Their total shortfall below the threshold before.
    before_def: f64,
    /// Initial variables.
    v: Vec<f64>,
    /// Number of free nodes.
    n_free: usize,
    /// Each element's sliver floor ([`Boundary::tet_sliver_floor`]).
    floors: Vec<f64>,
}

/// The inputs of patch `p` at node positions `x` and element scores `sj`.
fn prepare(tets: &[[u32; 10]], x: &[P3], p: &Patch, sj: &[f64], prm: &RoundPrm) -> PatchJob {
    let var_of = |n: u32| -> u32 { p.free.binary_search(&n).map_or(FIXED, |i| i as u32) };
    let mut elems = Vec::with_capacity(p.elems.len());
    let mut before_min = f64::INFINITY;
    let mut before_def = 0.0;
    for &e in &p.elems {
        let t = &tets[e as usize];
        let xe: [P3; 10] = std::array::from_fn(|k| x[t[k] as usize]);
        before_min = before_min.min(sj[e as usize]);
        before_def += (prm.threshold - sj[e as usize]).max(0.0);
        elems.push(PatchElem::new(xe, t.map(var_of)));
    }
    let floors = p
        .elems
        .iter()
        .map(|&e| {
            let t = &tets[e as usize];
            prm.bnd.tet_sliver_floor([t[0], t[1], t[2], t[3]])
        })
        .collect();
    // Initial variables: vertex positions, mid offsets from their edge midpoints.
    let mut v = vec![0.0; 3 * p.free.len()];
    for el in &elems {
        for k in 0..10 {
            let i = el.var[k];
            if i == FIXED {
                continue;
            }
            let val = if k < 4 {
                el.x[k]
            } else {
                let [a, b] = crate::geom::shape::TET10_EDGES[k - 4];
                let m = mid(el.x[a], el.x[b]);
                [el.x[k][0] - m[0], el.x[k][1] - m[1], el.x[k][2] - m[2]]
            };
            let i = 3 * i as usize;
            v[i..i + 3].copy_from_slice(&val);
        }
    }
    PatchJob {
        elems,
        before_min,
        before_def,
        v,
        n_free: p.free.len(),
        floors,
    }
}

/// Optimize one prepared patch; `None` when nothing improved.
///
/// Stage A moves the free mid nodes only (the straight-sided shape is kept); when that
/// leaves the patch below the threshold and vertices may move, stage B continues from
/// A's result with the free vertices too, kept only if their corner skewness stays
/// within [`HighOrderParams::max_skewness`] ([`HighOrderParams::max_skewness_rescue`]
/// for a poor patch), or below the patch's previous worst.
fn run_patch(
    job: PatchJob,
    prm: &RoundPrm,
    lb: &mut Lbfgs,
    lone: &dyn Fn() -> bool,
) -> (Option<PatchResult>, u64) {
    let PatchJob {
        elems,
        before_min,
        before_def,
        mut v,
        n_free,
        floors,
    } = job;
    // Stage A: mid nodes only.
    let mids: Vec<PatchElem> = elems
        .iter()
        .map(|e| {
            let mut e = e.clone();
            e.var[..4].iter_mut().for_each(|x| *x = FIXED);
            e
        })
        .filter(PatchElem::has_var)
        .collect();
    let v0 = v.clone();
    let scale = length_scales(&elems, n_free);
    let mut work = 0;
    if !mids.is_empty() {
        work += run_barrier(&mids, &mut v, &scale, prm, lb, lone);
    }
    let mut scores = Vec::with_capacity(elems.len());
    let deficit = |s: &[f64]| s.iter().map(|&x| (prm.threshold - x).max(0.0)).sum::<f64>();
    // Better: a higher minimum, or the same minimum (to 1e-6: an element the patch cannot
    // lift still moves a little) and clearly less total shortfall below the threshold,
    // so improving a patch's other bad elements counts too.
    let better = |m: f64, d: f64, bm: f64, bd: f64| m > bm || (m >= bm - 1e-6 && d < bd - 1e-4);
    // Corners did not move: no skewness to check.
    let (mut best_min, _) = evaluate(&elems, &v, prm.threshold, false, &mut scores, lone);
    let mut best_def = deficit(&scores);
    let mut best: Option<(Vec<f64>, Vec<f64>)> = None;
    if v != v0 && better(best_min, best_def, before_min, before_def) {
        best = Some((v.clone(), scores.clone()));
    } else {
        best_min = before_min;
        best_def = before_def;
        v.copy_from_slice(&v0);
    }
    // Stage B: vertices too.
    let has_vertex = elems.iter().any(|e| e.var[..4].iter().any(|&i| i != FIXED));
    if prm.stage.move_vertices && has_vertex && best_min < prm.threshold.min(prm.vertices_below) {
        let vb = v.clone();
        work += run_barrier(&elems, &mut v, &scale, prm, lb, lone);
        if v != vb {
            let (lo, sk) = evaluate(&elems, &v, prm.threshold, true, &mut scores, lone);
            let stage = prm.stage;
            let cap = if before_min < stage.rescue_below {
                stage.max_skewness_rescue
            } else {
                stage.max_skewness
            };
            // Corner skewness before (`x` of a patch element holds its starting nodes).
            let before_skew = elems.iter().map(|e| skew(&e.x)).fold(0.0f64, f64::max);
            // Unforced slivers (a dihedral angle below the element's sliver floor)
            // before and after: moving vertices may not make more.
            let unforced =
                |x: [P3; 10], f: &f64| dihedral_extremes(&[x[0], x[1], x[2], x[3]]).0 < *f;
            let before_unforced = elems.iter().zip(&floors).filter(|(e, f)| unforced(e.x, f));
            let after_unforced = elems
                .iter()
                .zip(&floors)
                .filter(|(e, f)| unforced(nodes(e, &v), f));
            if better(lo, deficit(&scores), best_min, best_def)
                && sk <= before_skew.max(cap)
                && after_unforced.count() <= before_unforced.count()
            {
                best = Some((v.clone(), scores.clone()));
            }
        }
    }
    let Some((v, sj_new)) = best else {
        return (None, work);
    };
    // Final free node positions.
    let mut pos = vec![[0.0; 3]; n_free];
    let mut done = vec![false; n_free];
    for el in &elems {
        let xe = nodes(el, &v);
        for (&i, &xk) in el.var.iter().zip(xe.iter()) {
            if i != FIXED && !done[i as usize] {
                pos[i as usize] = xk;
                done[i as usize] = true;
            }
        }
    }
    (
        Some(PatchResult {
            positions: pos,
            sj: sj_new,
        }),
        work,
    )
}

/// Equiangular skewness of the corner tet.
#[inline]
fn skew(x: &[P3; 10]) -> f64 {
    let (lo, hi) = dihedral_extremes(&[x[0], x[1], x[2], x[3]]);
    skewness_from_extremes(lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::report::uncertified;
    use crate::optimize::testmesh::cube;

    /// A free (interior, non-corner) mid node of `m` near the cube's centre.
    fn central_mid(m: &TetMesh, n_surf: usize) -> u32 {
        let adj = NodeElems::new(m);
        let mut best = (f64::INFINITY, 0u32);
        for n in n_surf..m.nodes.len() {
            if adj.is_vertex[n] {
                continue;
            }
            let d = dist(m.nodes[n], [0.5, 0.5, 0.5]);
            if d < best.0 {
                best = (d, n as u32);
            }
        }
        best.1
    }

    #[test]
    fn length_scales_are_the_mean_edge_of_the_elements_at_a_node() {
        let unit = crate::geom::shape::straight_tet10([
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ]);
        let twice = unit.map(|p| p.map(|c| 2.0 * c));
        // Edges 1, 1, 1, √2, √2, √2 (and twice those).
        let unit_mean = (3.0 + 3.0 * 2f64.sqrt()) / 6.0;
        // Variable 0 (a mid node) in both elements, variable 1 (a corner) in the second.
        let mut va = [FIXED; 10];
        va[4] = 0;
        let mut vb = [FIXED; 10];
        vb[5] = 0;
        vb[3] = 1;
        let elems = [PatchElem::new(unit, va), PatchElem::new(twice, vb)];
        let s = length_scales(&elems, 2);
        assert_eq!(s.len(), 6);
        for d in 0..3 {
            // Mean of the two elements' means; the second's alone.
            assert!((s[d] - 1.5 * unit_mean).abs() < 1e-15, "{s:?}");
            assert!((s[3 + d] - 2.0 * unit_mean).abs() < 1e-15, "{s:?}");
        }
    }

    /// A barrier run gives back the variables its elements do not use bit for bit, as
    /// stage A (mid nodes only) leaves the patch's vertex variables: scaled and unscaled,
    /// (x / s) * s can be an ulp off x, and an ulp was enough to invert a nearly flat
    /// corner tet (OpenSCAD's children.stl, through the whole fill).
    #[test]
    fn a_barrier_gives_back_unused_variables_exactly() {
        // Variable 0: mid node 4's offset; variable 1: corner 3, used by the full element
        // only (it sets variable 1's length scale, as in a patch).
        let mut va = [FIXED; 10];
        va[4] = 0;
        let mut vfull = va;
        vfull[3] = 1;
        // A corner whose coordinates do not all survive the round trip through the scale.
        let (x, scale) = (0..1000)
            .map(|k| {
                let x = crate::geom::shape::straight_tet10([
                    [0.0, 0.0, 0.0],
                    [1.0, 0.0, 0.0],
                    [0.0, 1.0, 0.0],
                    [0.1, 0.2, 0.7 + 0.001 * f64::from(k)],
                ]);
                (x, length_scales(&[PatchElem::new(x, vfull)], 2))
            })
            .find(|(x, s)| (0..3).any(|d| x[3][d] / s[3 + d] * s[3 + d] != x[3][d]))
            .expect("some corner makes a lossy round trip");
        // Mid node 4 pushed far off its edge: a poor element for the barrier to improve.
        let offset = [0.0, 0.45, 0.3];
        let mut xm = x;
        xm[4] = [0, 1, 2].map(|d| xm[4][d] + offset[d]);
        let mids = [PatchElem::new(xm, va)];
        let mut v: Vec<f64> = offset.iter().chain(&x[3]).copied().collect();
        let before = v.clone();
        let d = HighOrderParams::default();
        let nb = Boundary::new(0, &[]);
        let prm = RoundPrm {
            stage: &d,
            tune: &d.staged,
            threshold: d.threshold,
            vertices_below: d.vertices_below,
            bnd: &nb,
        };
        let work = run_barrier(&mids, &mut v, &scale, &prm, &mut Lbfgs::default(), &|| true);
        assert!(work > 0 && v[..3] != before[..3], "the barrier did not run");
        assert_eq!(
            v[3..].iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
            before[3..].iter().map(|x| x.to_bits()).collect::<Vec<_>>()
        );
    }

    /// The cube of `cube(3, 0.05)` with its central mid node pushed out far enough to
    /// leave invalid elements.
    fn tangled_cube() -> (crate::optimize::testmesh::CubeMesh, TetMesh) {
        let c = cube(3, 0.05);
        let mut m = c.p2();
        let n = central_mid(&m, c.n_surf) as usize;
        m.nodes[n][0] += 0.25;
        m.nodes[n][1] -= 0.15;
        assert!(
            !uncertified(&m).is_empty(),
            "the test needs invalid elements"
        );
        (c, m)
    }

    #[test]
    fn untangles_an_invalid_patch_and_keeps_the_boundary() {
        let (c, mut m) = tangled_cube();
        let bnd = c.boundary();
        let surf_before = m.nodes[..c.n_surf].to_vec();
        let st = optimize_high_order(&mut m, &bnd, &HighOrderParams::default());
        assert!(uncertified(&m).is_empty(), "{st:?}");
        assert_eq!(st.invalid[1], 0);
        assert!(st.invalid[0] > 0);
        assert!(st.min_scaled_jacobian[1] > 0.5, "{st:?}");
        // Surface nodes bit-identical.
        for (a, b) in surf_before.iter().zip(&m.nodes[..c.n_surf]) {
            assert_eq!(a.map(f64::to_bits), b.map(f64::to_bits));
        }
    }

    #[test]
    fn rounds_go_on_while_an_element_is_invalid() {
        let (c, m) = tangled_cube();
        let bnd = c.boundary();
        // The tangle starts poor (below reach_below): the staged rounds apply. With none
        // planned, only invalid elements keep rounds going, and they stop once all are
        // valid.
        let d = HighOrderParams::default();
        let only_invalid = HighOrderParams {
            staged: RoundTuning {
                rounds: 0,
                ..d.staged.clone()
            },
            ..d.clone()
        };
        let mut a = m.clone();
        let st = optimize_high_order(&mut a, &bnd, &only_invalid);
        assert!(
            st.min_scaled_jacobian[0] < only_invalid.reach_below,
            "{st:?}"
        );
        assert!(
            st.rounds >= 1 && st.rounds <= only_invalid.max_rounds,
            "{st:?}"
        );
        assert!(uncertified(&a).is_empty(), "{st:?}");
        // Without the extension nothing runs.
        let none = HighOrderParams {
            max_rounds: 0,
            ..only_invalid.clone()
        };
        let mut b = m.clone();
        let st = optimize_high_order(&mut b, &bnd, &none);
        assert_eq!(st.rounds, 0);
        assert!(!uncertified(&b).is_empty());
    }

    #[test]
    fn optimizing_again_near_moved_nodes_leaves_the_rest_alone() {
        let c = cube(6, 0.08);
        let bnd = c.boundary();
        let base = c.p2_perturbed(3, 0.04);
        let prm = HighOrderParams::default();
        // The interior mid node nearest a corner of the cube: patches around its elements
        // (two layers) stay within half the cube.
        let adj = NodeElems::new(&base);
        let near = (c.n_surf..base.nodes.len())
            .filter(|&n| !adj.is_vertex[n])
            .min_by(|&a, &b| {
                dist(base.nodes[a], [0.0; 3]).total_cmp(&dist(base.nodes[b], [0.0; 3]))
            })
            .unwrap() as u32;
        // Nodes in the far corner octant of the cube that moved.
        let far_moved = |m: &TetMesh| {
            (0..m.nodes.len())
                .filter(|&n| base.nodes[n].iter().all(|&x| x > 0.6))
                .filter(|&n| m.nodes[n].map(f64::to_bits) != base.nodes[n].map(f64::to_bits))
                .count()
        };
        let mut a = base.clone();
        let st = reoptimize_high_order_near(&mut a, &bnd, &prm, &[near]);
        assert!(st.patches_improved > 0, "{st:?}");
        assert_ne!(a.nodes[near as usize], base.nodes[near as usize]);
        assert_eq!(far_moved(&a), 0);
        // Everywhere, the far nodes move too.
        let mut b = base.clone();
        optimize_high_order(&mut b, &bnd, &prm);
        assert!(far_moved(&b) > 0);
    }

    #[test]
    fn same_result_for_one_two_and_four_threads() {
        let c = cube(4, 0.08);
        let bnd = c.boundary();
        let base = c.p2_perturbed(7, 0.04);
        let mut out: Vec<(Vec<P3>, String)> = Vec::new();
        for threads in [1, 2, 4] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut m = base.clone();
            let st =
                pool.install(|| optimize_high_order(&mut m, &bnd, &HighOrderParams::default()));
            assert!(st.patches > 1, "{st:?}");
            out.push((m.nodes, format!("{st:?}")));
        }
        for o in &out[1..] {
            assert_eq!(o.1, out[0].1);
            assert!(o
                .0
                .iter()
                .zip(&out[0].0)
                .all(|(a, b)| a.map(f64::to_bits) == b.map(f64::to_bits)));
        }
    }
}
