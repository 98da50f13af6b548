//! Exact self-intersection checks, broad phase by a uniform grid ([`super::grid`]), so the
//! cost stays about O(n log n) for reasonable meshes.
//!
//! **Chord level** ([`check_chords`]): every pair of flat chord (corner) triangles whose
//! bounding boxes overlap is tested with the exact `triangle_triangle_conflict`: meeting
//! at shared vertices or along a shared edge is fine, any other contact (touching,
//! crossing, coplanar overlap) is a
//! [`SelfIntersection`](SurfaceDefect::SelfIntersection), naming both triangles. Two
//! triangles with the same three corners coincide and are reported too.
//!
//! **Curved level** ([`check_curved`]): each P2 triangle is split at its mid nodes into
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

use super::describe;
use super::grid::{bbox, Aabb, Grid};
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
    if shared == 0 {
        // Exact early outs: one triangle strictly on one side of the other's plane.
        let s = pb.map(|q| orient3d(pa[0], pa[1], pa[2], q));
        if s.iter().all(|&x| x > 0) || s.iter().all(|&x| x < 0) {
            return false;
        }
        let s = pa.map(|q| orient3d(pb[0], pb[1], pb[2], q));
        if s.iter().all(|&x| x > 0) || s.iter().all(|&x| x < 0) {
            return false;
        }
    }
    triangle_triangle_conflict(pa, a, pb, b)
}

fn corners(tri: &[u32; 6]) -> [u32; 3] {
    [tri[0], tri[1], tri[2]]
}

/// Chord triangles do not meet except at shared vertices and edges. Triangles must be
/// non-degenerate.
pub fn check_chords(nodes: &[P3], tris: &[[u32; 6]]) -> Result<()> {
    let boxes: Vec<Aabb> = tris
        .iter()
        .map(|t| bbox(corners(t).map(|v| nodes[v as usize])))
        .collect();
    let grid = Grid::build(&boxes);
    let hit = grid.min_conflict(&boxes, |i, j| {
        flat_conflict(
            nodes,
            corners(&tris[i as usize]),
            corners(&tris[j as usize]),
        )
    });
    if let Some((i, j)) = hit {
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
    Ok(())
}

/// Node ids of sub-triangle `s` (= 4 * triangle + k).
fn sub_ids(tris: &[[u32; 6]], s: u32) -> [u32; 3] {
    let t = &tris[(s / 4) as usize];
    SUB_TRIANGLES[(s % 4) as usize].map(|k| t[k])
}

/// The four flat sub-triangles of every curved triangle do not meet except at shared
/// nodes and edges (see the module docs). Chord triangles must have passed.
pub fn check_curved(nodes: &[P3], tris: &[[u32; 6]]) -> Result<()> {
    let n_sub = 4 * tris.len();
    for s in 0..n_sub as u32 {
        let id = sub_ids(tris, s);
        let [a, b, c] = id.map(|v| nodes[v as usize]);
        if collinear(a, b, c) {
            let t = (s / 4) as usize;
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
    }
    let boxes: Vec<Aabb> = (0..n_sub as u32)
        .map(|s| bbox(sub_ids(tris, s).map(|v| nodes[v as usize])))
        .collect();
    let grid = Grid::build(&boxes);
    let hit = grid.min_conflict(&boxes, |i, j| {
        flat_conflict(nodes, sub_ids(tris, i), sub_ids(tris, j))
    });
    if let Some((i, j)) = hit {
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
