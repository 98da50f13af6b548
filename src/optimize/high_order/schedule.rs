//! Running one round's patches in parallel without waiting colour by colour.
//!
//! Patches are coloured so that patches of one colour share no active element. Run
//! colour by colour, a patch of colour c starts from the mesh as the patches of colours
//! below c left it; but it reads only the nodes and scores of its own active elements,
//! and only patches sharing one of those elements write them (a node a patch moves lies
//! in that patch's active elements only). So a patch can start as soon as the patches of
//! lower colour it shares an active element with are done — it then reads exactly what
//! the colour-by-colour order gives it, and the result is the same, bit for bit, for any
//! thread count and timing. What changes is the waiting: a long patch no longer holds
//! back the unrelated patches of the next colour (on the hinge, two workers finished
//! 13% sooner in a replay of its rounds' measured patch costs; four, 29% sooner).

use super::lbfgs::Lbfgs;
use super::patch::Patch;
use super::{prepare, run_patch, PatchResult, RoundPrm};
use crate::geom::vec3::P3;
use crate::mesh::TetMesh;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, PoisonError, RwLock};

/// What a round did.
#[derive(Default)]
pub(super) struct RoundDone {
    /// Patches whose result was kept.
    pub improved: usize,
    /// Element evaluations of the objective.
    pub work: u64,
}

/// For each patch, the patches of lower colour sharing an active element with it.
fn dependencies(patches: &[Patch], colours: &[u32], n_elems: usize) -> Vec<Vec<u32>> {
    // Element -> patches containing it, compressed rows.
    let mut off = vec![0u32; n_elems + 1];
    for p in patches {
        for &e in &p.elems {
            off[e as usize + 1] += 1;
        }
    }
    for i in 0..n_elems {
        off[i + 1] += off[i];
    }
    let mut fill = off.clone();
    let mut owners = vec![0u32; off[n_elems] as usize];
    for (i, p) in patches.iter().enumerate() {
        for &e in &p.elems {
            owners[fill[e as usize] as usize] = i as u32;
            fill[e as usize] += 1;
        }
    }
    let mut seen = vec![u32::MAX; patches.len()];
    patches
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let mut deps = Vec::new();
            for &e in &p.elems {
                for &j in &owners[off[e as usize] as usize..off[e as usize + 1] as usize] {
                    if colours[j as usize] < colours[i] && seen[j as usize] != i as u32 {
                        seen[j as usize] = i as u32;
                        deps.push(j);
                    }
                }
            }
            deps
        })
        .collect()
}

/// The mesh state the patches read and write. Patches read it under the read lock (in
/// parallel: no running patch writes what a starting one reads) and write their results
/// under the write lock.
struct State<'m> {
    nodes: &'m mut [P3],
    sj: &'m mut [f64],
}

/// The round's bookkeeping.
struct Progress {
    /// Dependencies of each patch not yet done.
    pending: Vec<u32>,
    done: RoundDone,
}

/// What every task of a round sees.
struct Round<'a, 'm> {
    tets: &'a [[u32; 10]],
    patches: &'a [Patch],
    dependents: Vec<Vec<u32>>,
    prm: &'a RoundPrm<'a>,
    state: RwLock<State<'m>>,
    progress: Mutex<Progress>,
    /// Patches spawned and not yet done (running or queued).
    live: AtomicUsize,
}

/// Optimize `patches` (coloured by `colours`) on the current rayon pool, writing kept
/// results into `mesh` and `sj`.
pub(super) fn run_round(
    mesh: &mut TetMesh,
    patches: &[Patch],
    colours: &[u32],
    sj: &mut [f64],
    prm: &RoundPrm,
) -> RoundDone {
    let deps = dependencies(patches, colours, sj.len());
    let mut dependents = vec![Vec::new(); patches.len()];
    for (i, d) in deps.iter().enumerate() {
        for &j in d {
            dependents[j as usize].push(i as u32);
        }
    }
    let pending: Vec<u32> = deps.iter().map(|d| d.len() as u32).collect();
    let TetMesh { nodes, tets, .. } = mesh;
    // Patches without dependencies start at once.
    let ready: Vec<usize> = (0..patches.len()).filter(|&i| pending[i] == 0).collect();
    let round = Round {
        tets,
        patches,
        dependents,
        prm,
        state: RwLock::new(State { nodes, sj }),
        progress: Mutex::new(Progress {
            pending,
            done: RoundDone::default(),
        }),
        live: AtomicUsize::new(0),
    };
    rayon::scope(|s| {
        for i in ready {
            spawn(s, &round, i);
        }
    });
    round
        .progress
        .into_inner()
        .unwrap_or_else(PoisonError::into_inner)
        .done
}

/// Run patch `i` as a task of scope `s` (its dependencies are done); when it is done,
/// write its result and start the patches that were waiting only for it.
fn spawn<'s, 'a: 's, 'm: 's>(s: &rayon::Scope<'s>, round: &'s Round<'a, 'm>, i: usize) {
    round.live.fetch_add(1, Ordering::SeqCst);
    s.spawn(move |s| {
        let job = {
            let st = round.state.read().unwrap_or_else(PoisonError::into_inner);
            prepare(round.tets, st.nodes, &round.patches[i], st.sj, round.prm)
        };
        let mut lb = Lbfgs::default();
        // Alone: no other patch is running or waiting to run, and none can start before
        // this one is done (only a finished patch releases others).
        let lone = || round.live.load(Ordering::SeqCst) == 1;
        let (result, work) = run_patch(job, round.prm, &mut lb, &lone);
        for k in finish(round, i, result, work) {
            spawn(s, round, k);
        }
        // After the released patches count as live, so that none runs alone too early.
        round.live.fetch_sub(1, Ordering::SeqCst);
    });
}

/// Write patch `i`'s outcome; returns the patches it was the last dependency of.
fn finish(round: &Round, i: usize, result: Option<PatchResult>, work: u64) -> Vec<usize> {
    let p = &round.patches[i];
    let improved = result.is_some();
    if let Some(r) = result {
        let mut st = round.state.write().unwrap_or_else(PoisonError::into_inner);
        for (n, x) in p.free.iter().zip(r.positions) {
            st.nodes[*n as usize] = x;
        }
        for (e, v) in p.elems.iter().zip(r.sj) {
            st.sj[*e as usize] = v;
        }
    }
    // The results are written before any dependent is released.
    let mut pr = round
        .progress
        .lock()
        .unwrap_or_else(PoisonError::into_inner);
    pr.done.work += work;
    pr.done.improved += usize::from(improved);
    let mut ready = Vec::new();
    for &k in &round.dependents[i] {
        let k = k as usize;
        pr.pending[k] -= 1;
        if pr.pending[k] == 0 {
            ready.push(k);
        }
    }
    ready
}

#[cfg(test)]
mod tests {
    use super::super::patch::{self, colour, Marks, NodeElems};
    use super::*;
    use crate::optimize::testmesh::cube;

    /// The colour-by-colour order the scheduler must reproduce: each colour's patches
    /// read the state the lower colours left, results written in patch order.
    fn by_colour(
        mesh: &mut TetMesh,
        patches: &[Patch],
        colours: &[u32],
        sj: &mut [f64],
        prm: &RoundPrm,
    ) -> (usize, u64) {
        let (mut improved, mut work) = (0, 0);
        let ncol = colours.iter().copied().max().map_or(0, |c| c + 1);
        for c in 0..ncol {
            let batch: Vec<usize> = (0..patches.len()).filter(|&i| colours[i] == c).collect();
            let jobs: Vec<_> = batch
                .iter()
                .map(|&i| prepare(&mesh.tets, &mesh.nodes, &patches[i], sj, prm))
                .collect();
            for (&i, job) in batch.iter().zip(jobs) {
                let (r, w) = run_patch(job, prm, &mut Lbfgs::default(), &|| false);
                work += w;
                let Some(r) = r else { continue };
                improved += 1;
                for (n, x) in patches[i].free.iter().zip(r.positions) {
                    mesh.nodes[*n as usize] = x;
                }
                for (e, v) in patches[i].elems.iter().zip(r.sj) {
                    sj[*e as usize] = v;
                }
            }
        }
        (improved, work)
    }

    #[test]
    fn the_same_result_as_colour_by_colour_for_any_thread_count() {
        let c = cube(4, 0.08);
        let base = c.p2_perturbed(5, 0.05);
        let adj = NodeElems::new(&base);
        let stage = crate::optimize::HighOrderParams::default();
        let nb = crate::optimize::Boundary::new(0, &[]);
        let prm = RoundPrm {
            stage: &stage,
            tune: &stage.staged,
            threshold: stage.threshold,
            vertices_below: stage.vertices_below,
            bnd: &nb,
        };
        let ne = base.tets.len();
        let mut sj0 = vec![0.0; ne];
        let all: Vec<u32> = (0..ne as u32).collect();
        super::super::element_scores(&base, &all, prm.threshold, &mut sj0);
        // One patch (two layers) per element below the threshold: heavy overlap, so
        // several colours and many dependencies.
        let mut marks = Marks::new(ne, base.nodes.len());
        let patches: Vec<Patch> = (0..ne as u32)
            .filter(|&t| sj0[t as usize] < prm.threshold)
            .map(|t| patch::build(&base, &adj, c.n_surf, t, 2, true, &mut marks))
            .filter(|p| !p.free.is_empty())
            .collect();
        let colours = colour(&patches, ne);
        assert!(
            colours.iter().copied().max().unwrap_or(0) >= 3,
            "{colours:?}"
        );
        let (mut m_ref, mut sj_ref) = (base.clone(), sj0.clone());
        let (imp_ref, work_ref) = by_colour(&mut m_ref, &patches, &colours, &mut sj_ref, &prm);
        assert!(imp_ref > 1);
        for threads in [1, 2, 4, 4] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let (mut m, mut sj) = (base.clone(), sj0.clone());
            let done = pool.install(|| run_round(&mut m, &patches, &colours, &mut sj, &prm));
            assert_eq!((done.improved, done.work), (imp_ref, work_ref));
            assert!(m
                .nodes
                .iter()
                .zip(&m_ref.nodes)
                .all(|(a, b)| a.map(f64::to_bits) == b.map(f64::to_bits)));
            assert!(sj
                .iter()
                .zip(&sj_ref)
                .all(|(a, b)| a.to_bits() == b.to_bits()));
        }
    }

    fn patch(elems: &[u32]) -> Patch {
        Patch {
            elems: elems.to_vec(),
            free: vec![],
        }
    }

    #[test]
    fn a_patch_waits_for_the_lower_colours_it_overlaps_only() {
        // 0 and 1 overlap (element 2), 1 and 2 overlap (element 5), 0 and 2 do not.
        let ps = [patch(&[0, 1, 2]), patch(&[2, 3, 5]), patch(&[5, 6])];
        let deps = dependencies(&ps, &[0, 1, 0], 8);
        assert_eq!(deps, vec![vec![], vec![0, 2], vec![]]);
        // A lower colour later in patch order is still waited for.
        let deps = dependencies(&ps, &[1, 2, 0], 8);
        assert_eq!(deps, vec![vec![], vec![0, 2], vec![]]);
        let deps = dependencies(&ps, &[2, 0, 1], 8);
        assert_eq!(deps, vec![vec![1], vec![], vec![1]]);
    }
}
