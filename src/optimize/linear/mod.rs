//! Linear quality improvement of the straight-sided core, before P2 assembly.
//!
//! Worst element first: every tet whose quality (1 − equiangular skewness, see
//! [`quality`]) is below the goal is attacked in turn by edge removal on its edges, 2-3
//! flips on its faces, smoothing of its interior vertices and contraction of its edges
//! that have an interior end point; an operation is kept only when it raises the minimum
//! quality of the tets it touches. Passes repeat while something improves. Sequential and
//! deterministic.

mod contract;
mod flips;
mod mesh;
mod quality;
mod smooth;

use crate::geom::shape::TET10_EDGES;
use crate::geom::vec3::P3;
use crate::optimize::Boundary;
use contract::{contract, ContractScratch};
use flips::{flip23, remove_edge, FlipScratch};
use mesh::LinMesh;
pub use quality::ElementQuality;
use smooth::{smooth_vertex, SmoothParams, SmoothScratch};

/// Tuning of the linear stage.
#[derive(Clone, Debug)]
pub struct LinearParams {
    /// Tets with equiangular skewness above this are worked on.
    pub goal_skewness: f64,
    /// Most passes over the bad tets.
    pub max_passes: usize,
    /// Smallest rise of the minimum quality that counts as an improvement.
    pub eps: f64,
}

impl Default for LinearParams {
    fn default() -> Self {
        LinearParams {
            goal_skewness: 0.6,
            max_passes: 8,
            eps: 1e-9,
        }
    }
}

/// What the linear stage did.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct LinearStats {
    /// Tets before and after.
    pub tets: [usize; 2],
    /// Largest equiangular skewness before and after.
    pub max_skewness: [f64; 2],
    /// Tets with skewness above the goal, before and after.
    pub bad: [usize; 2],
    /// Passes made.
    pub passes: usize,
    /// 2-3 flips applied.
    pub flips23: usize,
    /// Edge removals applied (3-2, 4-4, n-to-(2n-4)).
    pub edge_removals: usize,
    /// Edge contractions applied.
    pub contractions: usize,
    /// Vertex smoothings that moved a vertex.
    pub smoothings: usize,
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

struct Scratch {
    flip: FlipScratch,
    contract: ContractScratch,
    smooth: SmoothScratch,
    smooth_prm: SmoothParams,
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
    let goal = 1.0 - prm.goal_skewness;
    let mut m = LinMesh::new(pts, tets, bnd, ElementQuality);
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
    };
    let mut order: Vec<(f64, u32, [u32; 4])> = Vec::new();
    for _ in 0..prm.max_passes {
        st.passes += 1;
        order.clear();
        for (t, &q) in m.q.iter().enumerate() {
            if q < goal && m.alive(t as u32) {
                order.push((q, t as u32, m.tets[t]));
            }
        }
        order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let mut changed = 0;
        for &(_, t, tv) in &order {
            if m.tets[t as usize] != tv || m.q[t as usize] >= goal {
                continue;
            }
            if improve_tet(&mut m, t, prm.eps, &mut sc, &mut st) {
                changed += 1;
            }
        }
        if changed == 0 {
            break;
        }
    }
    let (w1, b1) = census(&m, goal);
    let (pts, tets) = m.into_parts();
    st.tets[1] = tets.len();
    st.max_skewness[1] = 1.0 - w1;
    st.bad[1] = b1;
    (pts, tets, st)
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
    moved
}
