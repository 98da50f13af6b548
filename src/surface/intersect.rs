//! Exact self-intersection checks, broad phase by a uniform grid (`surface/grid.rs`), so the
//! cost stays about O(n log n) for reasonable meshes.
//!
//! Both levels run in one pass ([`check_intersections`]) over the pairs of curved
//! triangles whose six-node bounding boxes overlap; a chord-level conflict anywhere is
//! reported before any curved-level one.
//!
//! **Chord level**: every pair of flat chord (corner) triangles whose bounding boxes
//! overlap is tested exactly (`flat_conflict`: exact early outs, a 2D path for coplanar
//! pairs, else the exact `triangle_triangle_conflict`; a test checks it agrees with the
//! latter): meeting at shared vertices or along a shared edge is fine, any other contact
//! (touching, crossing, coplanar overlap) is a
//! [`SelfIntersection`](SurfaceDefect::SelfIntersection), naming both triangles. Two
//! triangles with the same three corners coincide and are reported too.
//!
//! **Curved level**: each P2 triangle is split at its mid nodes into four flat
//! sub-triangles (c0 m01 m20, m01 c1 m12, m20 m12 c2, m01 m12 m20) and every overlapping
//! pair of sub-triangles (of the same or different triangles; shared nodes are judged by
//! id) is tested the same way. A conflict there is also an **error**
//! ([`SelfIntersection`](SurfaceDefect::SelfIntersection)), not a warning: the split is
//! the piecewise-flat surface through all six nodes of every curved triangle, so a
//! conflict means the boundary nodes themselves are entangled (typically a mid node pokes
//! through a nearby sheet). The mesher keeps every boundary node exactly and builds its
//! tets from them, so such an input cannot give a valid curved mesh; the final Jacobian
//! certification would fail later and less clearly. The split is a proxy of the curved
//! surface, not a proof either way: it can miss an intersection of the curved patches
//! between nodes (the final certification still catches that), and it could reject two
//! sheets that pass closer than their deviation from the split without touching (the six
//! benchmark surfaces, thin-walled LV and hinge included, pass). A sub-triangle whose
//! three nodes are exactly collinear cannot be tested and is reported as a
//! [`FoldedTriangle`](SurfaceDefect::FoldedTriangle) (such a split does not occur in a
//! sensible curved triangle).

use rayon::prelude::*;

use super::describe;
use super::grid::{bbox, overlap, Aabb, Grid};
use crate::error::{Error, Result, SurfaceDefect};
use crate::geom::predicates::{collinear, orient3d, projection_of, triangle_triangle_conflict};
use crate::geom::P3;

/// Node positions (0..6, Gmsh order) of the four flat sub-triangles of a P2 triangle,
/// oriented like the triangle.
pub const SUB_TRIANGLES: [[usize; 3]; 4] = [[0, 3, 5], [3, 1, 4], [5, 4, 2], [3, 4, 5]];

/// Do the flat triangles with node ids `a` and `b` meet anywhere other than at shared
/// vertices or a shared edge? Exact; identical id triples count as a conflict. Both
/// triangles must be non-degenerate.
///
/// Most pairs are settled by one to three orientation tests: if the vertices of `b` that
/// `a` lacks lie strictly on one side of `a`'s plane (or vice versa), `b` meets that plane
/// only in the shared vertex or edge, if at all. Coplanar pairs, common on the flat faces
/// of CAD models, take a 2D path (exact orientation signs in one coordinate projection)
/// rather than the general test, whose many exactly-zero 3D orientations are slow.
pub(crate) fn flat_conflict(nodes: &[P3], a: [u32; 3], b: [u32; 3]) -> bool {
    flat_conflict_at(
        a.map(|v| nodes[v as usize]),
        a,
        b.map(|v| nodes[v as usize]),
        b,
    )
}

/// [`flat_conflict`] with the coordinates already gathered (`pa[k]` is node `a[k]`).
pub(crate) fn flat_conflict_at(pa: [P3; 3], a: [u32; 3], pb: [P3; 3], b: [u32; 3]) -> bool {
    let shared = a.iter().filter(|v| b.contains(v)).count();
    if shared == 3 {
        return true;
    }
    match side_of_plane(pa, a, pb, b) {
        Side::Strict => return false,
        Side::On => return coplanar_conflict(pa, a, pb, b, shared),
        Side::Mixed => {}
    }
    if side_of_plane(pb, b, pa, a) == Side::Strict {
        return false;
    }
    triangle_triangle_conflict(pa, a, pb, b)
}

/// Where the vertices of `q` that `p` lacks lie relative to `p`'s plane.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Side {
    /// All strictly on one side.
    Strict,
    /// All on the plane: the triangles are coplanar.
    On,
    /// Anything else.
    Mixed,
}

#[inline]
fn side_of_plane(p: [P3; 3], pid: [u32; 3], q: [P3; 3], qid: [u32; 3]) -> Side {
    let (mut pos, mut neg, mut zero) = (0, 0, 0);
    for k in 0..3 {
        if pid.contains(&qid[k]) {
            continue;
        }
        match orient3d_axis_shortcut(p[0], p[1], p[2], q[k]) {
            1 => pos += 1,
            -1 => neg += 1,
            _ => zero += 1,
        }
        if zero > 0 && (pos > 0 || neg > 0) {
            return Side::Mixed;
        }
    }
    if zero > 0 {
        Side::On
    } else if pos == 0 || neg == 0 {
        Side::Strict
    } else {
        Side::Mixed
    }
}

/// `orient3d`, answering 0 at once when the four points share a coordinate exactly (an
/// axis-aligned plane, common on CAD faces). The exact predicate would reach the same 0
/// only through its slow adaptive stages.
#[inline]
fn orient3d_axis_shortcut(a: P3, b: P3, c: P3, d: P3) -> i32 {
    if (0..3).any(|k| a[k] == b[k] && a[k] == c[k] && a[k] == d[k]) {
        return 0;
    }
    orient3d(a, b, c, d)
}

/// Conflict of two coplanar, non-degenerate triangles sharing `shared` (0..=2) vertex ids.
fn coplanar_conflict(pa: [P3; 3], a: [u32; 3], pb: [P3; 3], b: [u32; 3], shared: usize) -> bool {
    let Some((pr, _)) = projection_of(pa[0], pa[1], pa[2]) else {
        return triangle_triangle_conflict(pa, a, pb, b);
    };
    let o = |x: P3, y: P3, z: P3| pr.orient2d(x, y, z);
    let others = |p: [P3; 3], ids: [u32; 3], q: [u32; 3]| {
        let mut v = Vec::with_capacity(3);
        for k in 0..3 {
            if !q.contains(&ids[k]) {
                v.push(p[k]);
            }
        }
        v
    };
    match shared {
        2 => {
            // Shared edge (u, w): fine iff the third vertices are strictly on opposite
            // sides of it.
            let k = (0..3).find(|&k| !b.contains(&a[k])).unwrap_or(0);
            let (c, u, w) = (pa[k], pa[(k + 1) % 3], pa[(k + 2) % 3]);
            let d = others(pb, b, a)[0];
            o(u, w, c) * o(u, w, d) >= 0
        }
        1 => {
            // Shared vertex v: the triangles meet beyond v iff their angular sectors at v
            // do, i.e. iff a boundary ray of one lies in the other's closed sector.
            let k = (0..3).find(|&k| b.contains(&a[k])).unwrap_or(0);
            let v = pa[k];
            let (a1, a2) = (pa[(k + 1) % 3], pa[(k + 2) % 3]);
            let bo = others(pb, b, a);
            let (b1, b2) = (bo[0], bo[1]);
            let in_sector = |x: P3, y: P3, p: P3| {
                let s = o(v, x, y);
                s * o(v, x, p) >= 0 && s * o(v, p, y) >= 0
            };
            in_sector(a1, a2, b1)
                || in_sector(a1, a2, b2)
                || in_sector(b1, b2, a1)
                || in_sector(b1, b2, a2)
        }
        _ => {
            // No shared vertex: closed triangles meet iff two edges meet or a vertex of one
            // lies in the other.
            let inside = |t: [P3; 3], p: P3| {
                let s = o(t[0], t[1], t[2]);
                (0..3).all(|k| s * o(t[k], t[(k + 1) % 3], p) >= 0)
            };
            if pb.iter().any(|&p| inside(pa, p)) || pa.iter().any(|&p| inside(pb, p)) {
                return true;
            }
            (0..3).any(|i| {
                (0..3).any(|j| segments_meet(&o, pa[i], pa[(i + 1) % 3], pb[j], pb[(j + 1) % 3]))
            })
        }
    }
}

/// Closed coplanar segments (p, q) and (r, s) meet, given an exact 2D orientation `o` of
/// their plane's projection.
fn segments_meet(o: &impl Fn(P3, P3, P3) -> i32, p: P3, q: P3, r: P3, s: P3) -> bool {
    let (o1, o2, o3, o4) = (o(p, q, r), o(p, q, s), o(r, s, p), o(r, s, q));
    if o1 * o2 < 0 && o3 * o4 < 0 {
        return true;
    }
    // Collinear points: on the closed segment iff within its bounding box.
    let on = |x: P3, y: P3, z: P3| (0..3).all(|d| z[d] >= x[d].min(y[d]) && z[d] <= x[d].max(y[d]));
    (o1 == 0 && on(p, q, r))
        || (o2 == 0 && on(p, q, s))
        || (o3 == 0 && on(r, s, p))
        || (o4 == 0 && on(r, s, q))
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
    check_levels(nodes, tris, true)
}

/// The chord level of [`check_intersections`] only: the flat corner triangles, mid nodes
/// ignored. This is the self-intersection check of a *linear* surface (used before it is
/// curved, see `surface::curve`).
pub fn check_chord_intersections(nodes: &[P3], tris: &[[u32; 6]]) -> Result<()> {
    check_levels(nodes, tris, false)
}

/// Both levels (`curved`) or the chord level only.
fn check_levels(nodes: &[P3], tris: &[[u32; 6]], curved: bool) -> Result<()> {
    let n_sub = if curved { 4 * tris.len() as u32 } else { 0 };
    let degenerate: Vec<bool> = (0..n_sub)
        .into_par_iter()
        .map(|s| {
            let [a, b, c] = pts(nodes, sub_ids(tris, s));
            collinear(a, b, c)
        })
        .collect();
    let boxes: Vec<Aabb> = tris
        .par_iter()
        .map(|t| {
            if curved {
                bbox(t.map(|v| nodes[v as usize]))
            } else {
                bbox([t[0], t[1], t[2]].map(|v| nodes[v as usize]))
            }
        })
        .collect();
    let grid = Grid::build(&boxes);
    let visit = |h: &mut Hits, i: u32, j: u32| {
        // Gather the twelve nodes once; every test below works on these copies.
        let (ti, tj) = (&tris[i as usize], &tris[j as usize]);
        let (xi, xj) = (ti.map(|v| nodes[v as usize]), tj.map(|v| nodes[v as usize]));
        let pick = |t: &[u32; 6], x: &[P3; 6], k: [usize; 3]| (k.map(|q| x[q]), k.map(|q| t[q]));
        if h.chord.is_none_or_after((i, j)) {
            let ((pa, a), (pb, b)) = (pick(ti, &xi, [0, 1, 2]), pick(tj, &xj, [0, 1, 2]));
            if overlap(&bbox(pa), &bbox(pb)) && flat_conflict_at(pa, a, pb, b) {
                h.chord = Some((i, j));
            }
        }
        if h.chord.is_some() || !curved {
            return; // a chord conflict anywhere is reported before any curved one
        }
        let bi = SUB_TRIANGLES.map(|k| bbox(k.map(|q| xi[q])));
        let bj = SUB_TRIANGLES.map(|k| bbox(k.map(|q| xj[q])));
        for (ki, ski) in SUB_TRIANGLES.iter().enumerate() {
            let si = 4 * i + ki as u32;
            if degenerate[si as usize] {
                continue;
            }
            let (pa, a) = pick(ti, &xi, *ski);
            for (kj, skj) in SUB_TRIANGLES.iter().enumerate() {
                let sj = 4 * j + kj as u32;
                if degenerate[sj as usize]
                    || !h.sub.is_none_or_after((si, sj))
                    || !overlap(&bi[ki], &bj[kj])
                {
                    continue;
                }
                let (pb, b) = pick(tj, &xj, *skj);
                if flat_conflict_at(pa, a, pb, b) {
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
    if !curved {
        return Ok(());
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

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{rngs::StdRng, Rng, SeedableRng};

    /// `flat_conflict` (with its early outs and coplanar 2D path) agrees with the general
    /// exact `triangle_triangle_conflict` on random triangles, coplanar ones on small
    /// integer lattices (axis-aligned and tilted planes) included, sharing 0, 1 or 2
    /// vertices.
    #[test]
    fn flat_conflict_matches_general_test() {
        let mut rng = StdRng::seed_from_u64(7);
        let planes: [(P3, P3, P3); 3] = [
            ([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
            ([0.0, 0.0, 3.0], [1.0, 2.0, 0.0], [0.0, 1.0, 1.0]),
            ([0.5, 0.25, 0.0], [0.5, 0.0, 1.0], [-1.0, 2.0, 3.0]),
        ];
        let mut counts = [0usize; 2];
        for it in 0..40_000 {
            let coplanar = it % 4 != 3;
            let (o, e1, e2) = planes[it % 3];
            let pt = |rng: &mut StdRng| -> P3 {
                if coplanar {
                    let (u, v) = (
                        rng.random_range(-3..=3) as f64,
                        rng.random_range(-3..=3) as f64,
                    );
                    [0, 1, 2].map(|d| o[d] + u * e1[d] + v * e2[d])
                } else {
                    [0, 1, 2].map(|_| rng.random_range(-3..=3) as f64 * 0.5)
                }
            };
            let mut nodes: Vec<P3> = (0..3).map(|_| pt(&mut rng)).collect();
            let shared = rng.random_range(0..=2usize);
            let mut b = [0u32; 3];
            let perm = [rng.random_range(0..3u32), 0, 0];
            for (k, bk) in b.iter_mut().enumerate() {
                if k < shared {
                    *bk = (perm[0] + k as u32) % 3;
                } else {
                    nodes.push(pt(&mut rng));
                    *bk = nodes.len() as u32 - 1;
                }
            }
            // Random order and orientation of b.
            if rng.random_bool(0.5) {
                b.swap(1, 2);
            }
            b.rotate_left(rng.random_range(0..3));
            let a = [0u32, 1, 2];
            // Equal coordinates under different ids are not allowed in a surface.
            let distinct =
                (0..nodes.len()).all(|i| (i + 1..nodes.len()).all(|j| nodes[i] != nodes[j]));
            let pa = a.map(|v| nodes[v as usize]);
            let pb = b.map(|v| nodes[v as usize]);
            if !distinct || collinear(pa[0], pa[1], pa[2]) || collinear(pb[0], pb[1], pb[2]) {
                continue;
            }
            let fast = flat_conflict(&nodes, a, b);
            let reference = triangle_triangle_conflict(pa, a, pb, b);
            assert_eq!(fast, reference, "a {pa:?} b {pb:?} ids {b:?}");
            counts[fast as usize] += 1;
        }
        assert!(counts[0] > 1000 && counts[1] > 1000, "{counts:?}");
    }
}
