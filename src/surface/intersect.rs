//! Exact self-intersection checks, broad phase by a uniform grid ([`super::grid`]), so the
//! cost stays about O(n log n) for reasonable meshes.
//!
//! Both levels run in one pass ([`check_intersections`]) over the pairs of curved
//! triangles whose six-node bounding boxes overlap; a chord-level conflict anywhere is
//! reported before any curved-level one.
//!
//! **Chord level**: every pair of flat chord (corner) triangles whose
//! bounding boxes overlap is tested with the exact `triangle_triangle_conflict`: meeting
//! at shared vertices or along a shared edge is fine, any other contact (touching,
//! crossing, coplanar overlap) is a
//! [`SelfIntersection`](SurfaceDefect::SelfIntersection), naming both triangles. Two
//! triangles with the same three corners coincide and are reported too.
//!
//! **Curved level**: each P2 triangle is split at its mid nodes into
//! four flat sub-triangles (c0 m01 m20, m01 c1 m12, m20 m12 c2, m01 m12 m20) and every
//! overlapping pair of sub-triangles (of the same or different triangles; shared nodes
//! are judged by id) is tested the same way. A conflict there is also an **error**
//! ([`SelfIntersection`](SurfaceDefect::SelfIntersection)), not a warning: the
//! sub-triangles pass through all six nodes of each curved triangle, so a conflict means
//! some boundary node (in practice a mid node) sits on the wrong side of another part of
//! the surface. The mesher keeps every boundary node exactly and builds its tets from
//! them, so such an input cannot give a valid curved mesh (the final certification would
//! fail, later and less clearly). The split is a conservative proxy, not a proof: it
//! can miss an intersection of the curved patches between nodes, which the final
//! Jacobian certification still catches. A sub-triangle whose three nodes are exactly
//! collinear cannot be tested and is reported as a
//! [`FoldedTriangle`](SurfaceDefect::FoldedTriangle) (such a split does not occur in a
//! sensible curved triangle).

use rayon::prelude::*;

use super::describe;
use super::grid::{bbox, overlap, Aabb, Grid};
use crate::error::{Error, Result, SurfaceDefect};
use crate::geom::predicates::{collinear, orient3d, triangle_triangle_conflict};
use crate::geom::P3;

/// Node positions (0..6, Gmsh order) of the four flat sub-triangles of a P2 triangle,
/// oriented like the triangle.
pub const SUB_TRIANGLES: [[usize; 3]; 4] = [[0, 3, 5], [3, 1, 4], [5, 4, 2], [3, 4, 5]];

/// Do the flat triangles with node ids `a` and `b` meet anywhere other than at shared
/// vertices or a shared edge? Exact; identical id triples count as a conflict.
pub(crate) fn flat_conflict(nodes: &[P3], a: [u32; 3], b: [u32; 3]) -> bool {
    let shared = a.iter().filter(|v| b.contains(v)).count();
    if shared == 3 {
        return true;
    }
    let pa = a.map(|v| nodes[v as usize]);
    let pb = b.map(|v| nodes[v as usize]);
    // Exact early out: if the vertices of one triangle that the other lacks lie strictly
    // on one side of the other's plane, the first meets that plane only in the shared
    // vertex or edge (or not at all), so the two meet only there. For a smooth surface
    // this settles almost every pair with one to three orientation tests.
    if strictly_one_side(pa, a, pb, b) || strictly_one_side(pb, b, pa, a) {
        return false;
    }
    triangle_triangle_conflict(pa, a, pb, b)
}

/// Are the vertices of `q` whose ids are not in `pid` all strictly on one side of the
/// plane of `p`?
#[inline]
fn strictly_one_side(p: [P3; 3], pid: [u32; 3], q: [P3; 3], qid: [u32; 3]) -> bool {
    let mut side = 0;
    for k in 0..3 {
        if pid.contains(&qid[k]) {
            continue;
        }
        let s = orient3d(p[0], p[1], p[2], q[k]);
        if s == 0 || (side != 0 && s != side) {
            return false;
        }
        side = s;
    }
    side != 0
}

fn corners(tri: &[u32; 6]) -> [u32; 3] {
    [tri[0], tri[1], tri[2]]
}

/// Node ids of sub-triangle `s` (= 4 * triangle + k).
fn sub_ids(tris: &[[u32; 6]], s: u32) -> [u32; 3] {
    let t = &tris[(s / 4) as usize];
    SUB_TRIANGLES[(s % 4) as usize].map(|k| t[k])
}

fn pts(nodes: &[P3], ids: [u32; 3]) -> [P3; 3] {
    ids.map(|v| nodes[v as usize])
}

/// The least conflicting pairs found so far: chord triangles, and sub-triangles.
#[derive(Default, Clone, Copy)]
struct Hits {
    chord: Option<(u32, u32)>,
    sub: Option<(u32, u32)>,
}

fn min_opt(a: Option<(u32, u32)>, b: Option<(u32, u32)>) -> Option<(u32, u32)> {
    match (a, b) {
        (Some(x), Some(y)) => Some(x.min(y)),
        (x, None) => x,
        (None, y) => y,
    }
}

/// Both intersection checks of the module docs, in one pass over the pairs of curved
/// triangles whose six-node bounding boxes overlap (they contain the chord triangle and
/// the four sub-triangles). Reports, in this order: a chord-level conflict (the least
/// pair of triangles), a degenerate sub-triangle, a sub-triangle conflict. Triangles
/// must be non-degenerate.
pub fn check_intersections(nodes: &[P3], tris: &[[u32; 6]]) -> Result<()> {
    let n_sub = 4 * tris.len() as u32;
    let degenerate: Vec<bool> = (0..n_sub)
        .into_par_iter()
        .map(|s| {
            let [a, b, c] = pts(nodes, sub_ids(tris, s));
            collinear(a, b, c)
        })
        .collect();
    let boxes: Vec<Aabb> = tris
        .par_iter()
        .map(|t| bbox(t.map(|v| nodes[v as usize])))
        .collect();
    let grid = Grid::build(&boxes);
    let visit = |h: &mut Hits, i: u32, j: u32| {
        let (ti, tj) = (&tris[i as usize], &tris[j as usize]);
        if h.chord.is_none_or_after((i, j)) {
            let (ci, cj) = (corners(ti), corners(tj));
            if overlap(&bbox(pts(nodes, ci)), &bbox(pts(nodes, cj))) && flat_conflict(nodes, ci, cj)
            {
                h.chord = Some((i, j));
            }
        }
        if h.chord.is_some() {
            return; // a chord conflict anywhere is reported before any curved one
        }
        let sub_boxes = |t: u32| {
            let x = tris[t as usize].map(|v| nodes[v as usize]);
            SUB_TRIANGLES.map(|k| bbox(k.map(|q| x[q])))
        };
        let (bi, bj) = (sub_boxes(i), sub_boxes(j));
        for ki in 0..4u32 {
            let si = 4 * i + ki;
            if degenerate[si as usize] {
                continue;
            }
            for kj in 0..4u32 {
                let sj = 4 * j + kj;
                if degenerate[sj as usize]
                    || !h.sub.is_none_or_after((si, sj))
                    || !overlap(&bi[ki as usize], &bj[kj as usize])
                {
                    continue;
                }
                if flat_conflict(nodes, sub_ids(tris, si), sub_ids(tris, sj)) {
                    h.sub = Some((si, sj));
                }
            }
        }
    };
    let merge = |a: Hits, b: Hits| Hits {
        chord: min_opt(a.chord, b.chord),
        sub: min_opt(a.sub, b.sub),
    };
    let hits = grid.fold_pairs(&boxes, Hits::default, visit, merge);

    if let Some((i, j)) = hits.chord {
        let (i, j) = (i as usize, j as usize);
        return Err(Error::surface(
            SurfaceDefect::SelfIntersection,
            format!(
                "{} and {} intersect: their chord triangles meet away from shared vertices \
                 and edges (touching, crossing or overlapping)",
                describe::tri(i, &tris[i]),
                describe::tri(j, &tris[j])
            ),
        ));
    }
    if let Some(s) = degenerate.iter().position(|&d| d) {
        let t = s / 4;
        let id = sub_ids(tris, s as u32);
        return Err(Error::surface(
            SurfaceDefect::FoldedTriangle,
            format!(
                "{}: the flat sub-triangle (nodes {}, {}, {}) of its corner/mid-node split \
                 is degenerate (collinear nodes), so the curved triangle is degenerate or \
                 cannot be certified embedded",
                describe::tri(t, &tris[t]),
                id[0],
                id[1],
                id[2]
            ),
        ));
    }
    // Pairs of sub-triangles of the same triangle.
    let own = (0..tris.len() as u32).into_par_iter().find_map_first(|t| {
        for k in 0..4 {
            for l in k + 1..4 {
                let (si, sj) = (4 * t + k, 4 * t + l);
                if flat_conflict(nodes, sub_ids(tris, si), sub_ids(tris, sj)) {
                    return Some((si, sj));
                }
            }
        }
        None
    });
    if let Some((i, j)) = min_opt(hits.sub, own) {
        let (ti, tj) = ((i / 4) as usize, (j / 4) as usize);
        let (si, sj) = (sub_ids(tris, i), sub_ids(tris, j));
        let what = if ti == tj {
            format!("{} intersects itself", describe::tri(ti, &tris[ti]))
        } else {
            format!(
                "curved {} and {} intersect",
                describe::tri(ti, &tris[ti]),
                describe::tri(tj, &tris[tj])
            )
        };
        return Err(Error::surface(
            SurfaceDefect::SelfIntersection,
            format!(
                "{what}: flat sub-triangles (nodes {}, {}, {}) and (nodes {}, {}, {}) of their \
                 corner/mid-node splits meet, though the chord triangles do not (a mid node \
                 likely pokes through a nearby part of the surface)",
                si[0], si[1], si[2], sj[0], sj[1], sj[2]
            ),
        ));
    }
    Ok(())
}

/// `None`, or a pair after `p` (so `p` would be a new minimum).
trait NoneOrAfter {
    fn is_none_or_after(&self, p: (u32, u32)) -> bool;
}

impl NoneOrAfter for Option<(u32, u32)> {
    #[inline]
    fn is_none_or_after(&self, p: (u32, u32)) -> bool {
        match self {
            None => true,
            Some(c) => p < *c,
        }
    }
}
