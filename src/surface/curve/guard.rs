//! The guards: no curved triangle folds, and curving creates no self-intersection. Where
//! either fails, edges go back to their straight (chord midpoint) position one by one,
//! until the surface is clean.
//!
//! **Fold guard**: every triangle's minimum cosine between curved and chord normals on the
//! order-6 lattice ([`min_normal_cosine_of`], the surface check's own sampling) must be at
//! least `min_cos` (> 0). A triangle below it gets its most bent curved edge (largest
//! mid-node offset over edge length) straightened; its neighbours across that edge are
//! checked again.
//!
//! **Intersection guard**: the surface check's sub-triangle test, run on every pair of
//! triangles whose six-node boxes overlap and within each triangle (exact, see
//! `surface::intersect`). Every curved edge whose mid node belongs to a conflicting
//! sub-triangle is straightened. The chord triangles were checked before curving, so with
//! every edge straight nothing can conflict but rounding of the chord midpoints.
//!
//! The intersection scan costs as much as the surface check's own, so it runs only when
//! that check (`Surface::new`) reports an intersection; then both guards repeat until the
//! check passes or neither guard changes anything (each round straightens at least one
//! curved edge, so this ends).

use rayon::prelude::*;

use crate::geom::predicates::collinear;
use crate::geom::vec3::{dist, norm, sub};
use crate::geom::P3;
use crate::surface::geometry::{min_normal_cosine_of, tri_nodes, NormalSample};
use crate::surface::grid::{bbox, overlap, Aabb, Grid};
use crate::surface::intersect::{flat_conflict_at, SUB_TRIANGLES};

/// What the guards did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct GuardCounts {
    /// Edges straightened because a triangle would fold (or bend past `min_cos`).
    pub fold: usize,
    /// Edges straightened because sub-triangles would intersect.
    pub intersection: usize,
}

/// What the guards work on: the node positions (mid nodes are moved) and the edges. An
/// edge is curved when its mid node is not at its chord midpoint.
pub(crate) struct Edges<'a> {
    pub nodes: &'a mut [P3],
    pub tris: &'a [[u32; 6]],
    /// Per edge: its two corner nodes and its two triangles.
    pub ends: &'a [([u32; 2], [u32; 2])],
    /// Number of input vertices: edge e has mid node `n_input + e`.
    pub n_input: usize,
}

impl Edges<'_> {
    fn edge_of(&self, node: u32) -> Option<usize> {
        (node as usize).checked_sub(self.n_input)
    }

    fn straight(&self, e: usize) -> P3 {
        let [a, b] = self.ends[e].0;
        crate::geom::vec3::mid(self.nodes[a as usize], self.nodes[b as usize])
    }

    fn is_curved(&self, e: usize) -> bool {
        self.nodes[self.n_input + e] != self.straight(e)
    }

    fn straighten(&mut self, e: usize) {
        let s = self.straight(e);
        self.nodes[self.n_input + e] = s;
    }

    /// Offset of edge e's mid node from its chord midpoint, over its length.
    fn bend(&self, e: usize) -> f64 {
        let [a, b] = self.ends[e].0;
        let l = dist(self.nodes[a as usize], self.nodes[b as usize]);
        norm(sub(self.nodes[self.n_input + e], self.straight(e))) / l
    }
}

fn bad_fold(nodes: &[P3], tri: &[u32; 6], min_cos: f64) -> bool {
    match min_normal_cosine_of(&tri_nodes(nodes, tri)) {
        NormalSample::MinCos(c, _) => c.is_nan() || c < min_cos,
        NormalSample::ChordUnderflow => false, // a chord property: reported by the checks
    }
}

/// The fold guard over all triangles; returns how many edges it straightened.
pub(crate) fn fold_guard(s: &mut Edges, min_cos: f64) -> usize {
    let mut count = 0;
    let mut todo: Vec<u32> = (0..s.tris.len() as u32).collect();
    while !todo.is_empty() {
        let bad: Vec<u32> = {
            let (nodes, tris) = (&*s.nodes, s.tris);
            todo.par_iter()
                .copied()
                .filter(|&t| bad_fold(nodes, &tris[t as usize], min_cos))
                .collect()
        };
        let mut next = Vec::new();
        for t in bad {
            let tri = s.tris[t as usize];
            let worst = tri[3..]
                .iter()
                .filter_map(|&m| s.edge_of(m))
                .filter(|&e| s.is_curved(e))
                .max_by(|&e, &f| s.bend(e).total_cmp(&s.bend(f)));
            if let Some(e) = worst {
                s.straighten(e);
                count += 1;
                next.extend(s.ends[e].1);
            }
        }
        next.sort_unstable();
        next.dedup();
        todo = next;
    }
    count
}

fn sub_ids(tri: &[u32; 6], k: usize) -> [u32; 3] {
    SUB_TRIANGLES[k].map(|q| tri[q])
}

/// The mid nodes of all conflicting (or degenerate) sub-triangles.
fn conflicting_mid_nodes(nodes: &[P3], tris: &[[u32; 6]], n_input: usize) -> Vec<u32> {
    let boxes: Vec<Aabb> = tris
        .par_iter()
        .map(|t| bbox(t.map(|v| nodes[v as usize])))
        .collect();
    let grid = Grid::build(&boxes);
    let mids = |ids: [u32; 3], out: &mut Vec<u32>| {
        out.extend(ids.iter().filter(|&&v| v as usize >= n_input));
    };
    let visit_pair = |out: &mut Vec<u32>, i: u32, j: u32| {
        let (ti, tj) = (&tris[i as usize], &tris[j as usize]);
        let (xi, xj) = (tri_nodes(nodes, ti), tri_nodes(nodes, tj));
        for (ki, ski) in SUB_TRIANGLES.iter().enumerate() {
            let a = sub_ids(ti, ki);
            let pa = ski.map(|q| xi[q]);
            for (kj, skj) in SUB_TRIANGLES.iter().enumerate() {
                let b = sub_ids(tj, kj);
                let pb = skj.map(|q| xj[q]);
                if overlap(&bbox(pa), &bbox(pb))
                    && !collinear(pa[0], pa[1], pa[2])
                    && !collinear(pb[0], pb[1], pb[2])
                    && flat_conflict_at(pa, a, pb, b)
                {
                    mids(a, out);
                    mids(b, out);
                }
            }
        }
    };
    let mut out = grid.fold_pairs(&boxes, Vec::new, visit_pair, |mut a, b| {
        a.extend(b);
        a
    });
    let own: Vec<u32> = tris
        .par_iter()
        .flat_map_iter(|t| {
            let x = tri_nodes(nodes, t);
            let mut o = Vec::new();
            for (k, sk) in SUB_TRIANGLES.iter().enumerate() {
                let pa = sk.map(|q| x[q]);
                if collinear(pa[0], pa[1], pa[2]) {
                    mids(sub_ids(t, k), &mut o);
                    continue;
                }
                for (l, sl) in SUB_TRIANGLES.iter().enumerate().skip(k + 1) {
                    let pb = sl.map(|q| x[q]);
                    if !collinear(pb[0], pb[1], pb[2])
                        && flat_conflict_at(pa, sub_ids(t, k), pb, sub_ids(t, l))
                    {
                        mids(sub_ids(t, k), &mut o);
                        mids(sub_ids(t, l), &mut o);
                    }
                }
            }
            o
        })
        .collect();
    out.extend(own);
    out.sort_unstable();
    out.dedup();
    out
}

/// The intersection guard's pass: straightens every curved edge whose mid node is in a
/// conflicting (or degenerate) sub-triangle; returns how many.
pub(crate) fn intersection_pass(s: &mut Edges) -> usize {
    let conflicting = conflicting_mid_nodes(s.nodes, s.tris, s.n_input);
    let mut changed = 0;
    for m in conflicting {
        if let Some(e) = s.edge_of(m) {
            if s.is_curved(e) {
                s.straighten(e);
                changed += 1;
            }
        }
    }
    changed
}
