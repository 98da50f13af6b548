//! Vertex insertion by edge split: a new interior vertex at the midpoint of an interior
//! edge (never a boundary edge, so no Steiner point on the boundary) splits each of the
//! edge's tets in two, then is smoothed. Kept only when the minimum quality of the edge's
//! tets rises; otherwise undone. It gives a tet whose corners are all on the boundary
//! (a sliver across a thin wall, say) a vertex that can move.

use super::mesh::{opposite_edge, LinMesh};
use super::smooth::{smooth_vertex, SmoothParams, SmoothScratch};
use crate::geom::vec3::mid;

/// Scratch buffers of the insertion.
#[derive(Default)]
pub(super) struct InsertScratch {
    ts: Vec<u32>,
    old: Vec<[u32; 4]>,
    /// Qualities of `old`, restored on undo.
    old_q: Vec<f64>,
    /// Qualities of the new tets, two per old tet.
    new_q: Vec<f64>,
    added: Vec<u32>,
}

/// Try splitting the interior edge (a, b); true when kept.
pub(super) fn split_edge(
    m: &mut LinMesh,
    a: u32,
    b: u32,
    eps: f64,
    prm: &SmoothParams,
    s: &mut InsertScratch,
    ss: &mut SmoothScratch,
) -> bool {
    if m.bnd.is_boundary_edge(a, b) {
        return false;
    }
    m.edge_tets(a, b, &mut s.ts);
    if s.ts.len() < 3 {
        return false;
    }
    let mut old_min = f64::INFINITY;
    s.old.clear();
    s.old_q.clear();
    for &t in &s.ts {
        old_min = old_min.min(m.q[t as usize]);
        s.old.push(m.tets[t as usize]);
        s.old_q.push(m.q[t as usize]);
    }
    let p = mid(m.pts[a as usize], m.pts[b as usize]);
    // The new tets (a, p, u, v) and (p, b, u, v) for each old (a, b, u, v); all must be
    // positive (exact) before anything changes.
    let np = m.pts.len() as u32;
    m.pts.push(p);
    m.vt.push(Vec::new());
    m.dirty.push(true);
    m.changed.push(m.clock);
    let mut ok = true;
    s.new_q.clear();
    for &t in &s.ts {
        let (u, v) = opposite_edge(m.tets[t as usize], a, b);
        for nt in [[a, np, u, v], [np, b, u, v]] {
            let q = m.quality(nt);
            ok &= q != f64::NEG_INFINITY;
            s.new_q.push(q);
        }
    }
    if !ok {
        m.pts.pop();
        m.vt.pop();
        m.dirty.pop();
        m.changed.pop();
        return false;
    }
    for i in 0..s.ts.len() {
        m.remove(s.ts[i]);
    }
    s.added.clear();
    // (The qualities measured above: nothing has moved since.)
    for i in 0..s.old.len() {
        let (u, v) = opposite_edge(s.old[i], a, b);
        for (j, nt) in [[a, np, u, v], [np, b, u, v]].into_iter().enumerate() {
            let id = m.add(nt, s.new_q[2 * i + j]);
            s.added.push(id);
        }
    }
    smooth_vertex(m, np, prm, ss);
    let new_min = m.vt[np as usize]
        .iter()
        .map(|&t| m.q[t as usize])
        .fold(f64::INFINITY, f64::min);
    if new_min > old_min + eps {
        return true;
    }
    // Undo: the new vertex stays as an unused point.
    for i in 0..s.added.len() {
        m.remove(s.added[i]);
    }
    // (Their corners are where they were: the new vertex is in none of them.)
    for i in 0..s.old.len() {
        m.add(s.old[i], s.old_q[i]);
    }
    false
}
