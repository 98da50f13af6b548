//! Exact validity of a candidate tetrahedron against the active front (paper 2.5).
//!
//! A candidate T = (a, b, c, p) on front face (a, b, c) is valid when it lies in the
//! closure of the unmeshed region: p strictly on the inner side of (a, b, c), no front
//! vertex in closed T (other than T's own), no new edge of T crossing a front face and no
//! front edge crossing a new face of T (shared vertices and edges excepted, decided by
//! ids), and any front face with T's three vertices being exactly a new face of T with the
//! opposite orientation (it then closes). Every decision is an exact predicate.
//!
//! The same pass measures the paper's edge-face angle: for each front face F sharing an
//! edge with T, the angle of the unmeshed wedge left between F and T. A thin wedge would
//! force a sliver later.

use super::grid::Aabb;
use crate::geom::distance::point_triangle_dist2;
use crate::geom::predicates::{
    in_closed_tet, orient3d, segment_triangle_conflict_by, tet_face_planes, Plane,
};
use crate::geom::vec3::*;

pub use crate::geom::shape::TET_OUT_FACES;

/// Why a candidate is not valid (for diagnostics; the front face involved, if any).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Conflict {
    /// The apex is not strictly on the inner side of the base face.
    NotPositive,
    /// Flatter than f64 resolves (see [`MIN_RELATIVE_VOLUME`]).
    Degenerate,
    /// A new point too close to this unrelated front face.
    ApexNearFace([u32; 3]),
    /// A vertex of this front face too close to a new face.
    VertexNearNewFace([u32; 3]),
    /// This front face has the base face's vertices.
    CopyOfBase([u32; 3]),
    /// This front face is a new face of T with the same orientation.
    SameOrientation([u32; 3]),
    /// A vertex of this front face lies in T.
    VertexInside([u32; 3]),
    /// A new edge of T crosses this front face.
    NewEdgeCrosses([u32; 3]),
    /// An edge of this front face crosses a new face of T.
    EdgeCrossesNewFace([u32; 3]),
}

/// The outcome of a validity test.
#[derive(Clone, Copy, Debug)]
pub struct Verdict {
    /// Smallest unmeshed wedge angle (degrees) between T and a front face sharing an edge
    /// with it; 360 when there is none.
    pub min_gap_deg: f64,
    /// The same, against boundary (input) faces only.
    pub min_gap_boundary_deg: f64,
    /// Tets that will have to close the thin wedges T leaves against front faces (front
    /// face + T's vertex across the wedge); the caller checks they can exist.
    pub closings: [[u32; 4]; 6],
    /// Number of entries in `closings`.
    pub num_closings: usize,
    /// Whether each closing's front face is a boundary face.
    pub closing_on_boundary: [bool; 6],
}

pub use crate::geom::tet_quality::MIN_RELATIVE_VOLUME;

/// Id the caller gives a candidate's apex when it is a new point.
pub const NEW_POINT: u32 = u32::MAX - 1;

/// Wedges thinner than this (degrees) are checked for a valid closing tet.
pub const LOOKAHEAD_GAP_DEG: f64 = 35.0;

/// One front face as the validity test sees it.
#[derive(Clone, Copy)]
pub struct FaceRef {
    /// Vertex ids, oriented with the normal into the unmeshed region.
    pub v: [u32; 3],
    /// Is it an input (boundary) face?
    pub boundary: bool,
}

/// Test candidate `t` (ids, with positions `tp`; `t[0..3]` is the base face as stored on the
/// front, `t[3]` the apex) against the front faces `near` (excluding the base face).
/// Returns the first conflict found, if any. `min_dist` > 0 also rejects a new point (apex id
/// [`NEW_POINT`]) that would come closer than that to an unrelated front face.
pub fn check(
    t: [u32; 4],
    tp: [P3; 4],
    near: &[FaceRef],
    pos: impl Fn(u32) -> P3,
    min_dist: f64,
) -> Result<Verdict, Conflict> {
    if orient3d(tp[0], tp[1], tp[2], tp[3]) <= 0 {
        return Err(Conflict::NotPositive);
    }
    // Numerically degenerate (flatter than f64 resolves relative to its size): its
    // Jacobian could not be certified, so it is never created.
    if crate::geom::tet_quality::numerically_flat(&tp) {
        return Err(Conflict::Degenerate);
    }
    // T's outward face planes: every nearby front vertex is tested against them.
    let planes = tet_face_planes(&tp);
    let tb = Aabb::of(&tp);
    let tb_far = Aabb {
        lo: [
            tb.lo[0] - min_dist,
            tb.lo[1] - min_dist,
            tb.lo[2] - min_dist,
        ],
        hi: [
            tb.hi[0] + min_dist,
            tb.hi[1] + min_dist,
            tb.hi[2] + min_dist,
        ],
    };
    let min_d2 = min_dist * min_dist;
    let mut min_gap = 360.0f64;
    let mut min_gap_b = 360.0f64;
    let mut closings = [[0u32; 4]; 6];
    let mut num_closings = 0;
    let mut closing_on_boundary = [false; 6];
    for f in near {
        let fv = f.v;
        let fp = [pos(fv[0]), pos(fv[1]), pos(fv[2])];
        let fb = Aabb::of(&fp);
        if !fb.overlaps(&tb_far) {
            continue;
        }
        let in_t = |id: u32| t.iter().position(|&x| x == id);
        let loc = [in_t(fv[0]), in_t(fv[1]), in_t(fv[2])];
        let shared = loc.iter().filter(|x| x.is_some()).count();
        if shared == 0 && min_d2 > 0.0 {
            // Proximity: an unrelated front face must not come close to T's apex, nor
            // its vertices close to T's new faces (a narrow gap would be left).
            // (Box distances first: most faces are ruled out without the exact distance.)
            if fb.dist2(tp[3]) < min_d2 && point_triangle_dist2(tp[3], fp[0], fp[1], fp[2]) < min_d2
            {
                return Err(Conflict::ApexNearFace(fv));
            }
            for q in fp {
                if tb.dist2(q) >= min_d2 {
                    continue;
                }
                for g in &TET_OUT_FACES[1..] {
                    if point_triangle_dist2(q, tp[g[0]], tp[g[1]], tp[g[2]]) < min_d2 {
                        return Err(Conflict::VertexNearNewFace(fv));
                    }
                }
            }
        }
        if !fb.overlaps(&tb) {
            continue;
        }
        if shared == 3 {
            // F has T's three vertices: it must be a new face of T, oppositely oriented.
            let l = [loc[0].unwrap(), loc[1].unwrap(), loc[2].unwrap()];
            if !l.contains(&3) {
                return Err(Conflict::CopyOfBase(fv)); // a second copy of the base face
            }
            // Outward new faces of T are (0,1,3), (1,2,3), (2,0,3); F must be a cyclic
            // rotation of one of them reversed, i.e. a rotation of (1,0,3), (2,1,3), (0,2,3).
            let rot = |a: [usize; 3]| [a, [a[1], a[2], a[0]], [a[2], a[0], a[1]]];
            let ok = [[1, 0, 3], [2, 1, 3], [0, 2, 3]]
                .iter()
                .any(|g| rot(*g).contains(&l));
            if !ok {
                return Err(Conflict::SameOrientation(fv));
            }
            continue;
        }
        if shared == 2 {
            // Unmeshed wedge between F and T at their shared edge.
            let (e0, e1, fo) = match loc {
                [Some(a), Some(b), None] => (a, b, fp[2]),
                [None, Some(a), Some(b)] => (a, b, fp[0]),
                [Some(b), None, Some(a)] => (a, b, fp[1]),
                _ => (0, 1, fp[0]), // unreachable: exactly two are shared
            };
            let (g, k) = wedge_gap_deg(tp, e0, e1, fo, tri_normal(fp[0], fp[1], fp[2]));
            min_gap = min_gap.min(g);
            let is_base_face = k != 3 && e0 != 3 && e1 != 3;
            if g < LOOKAHEAD_GAP_DEG && !is_base_face && num_closings < closings.len() {
                closings[num_closings] = [fv[0], fv[1], fv[2], t[k]];
                closing_on_boundary[num_closings] = f.boundary;
                num_closings += 1;
            }
            if f.boundary {
                min_gap_b = min_gap_b.min(g);
            }
        }
        if separated(&t, &planes, &fv, &fp) {
            continue;
        }
        // Front vertices inside closed T.
        for k in 0..3 {
            if loc[k].is_none() && in_closed_tet(&planes, fp[k]) {
                return Err(Conflict::VertexInside(fv));
            }
        }
        // New edges of T against F.
        let fplane = Plane::new(fp[0], fp[1], fp[2]);
        for i in 0..3 {
            if segment_triangle_conflict_by([tp[i], tp[3]], [t[i], t[3]], fp, fv, |x| {
                fplane.orient(x)
            }) {
                return Err(Conflict::NewEdgeCrosses(fv));
            }
        }
        // Edges of F against the new faces of T.
        for k in 0..3 {
            let (i, j) = (k, (k + 1) % 3);
            let (ei, ej) = (fv[i], fv[j]);
            if loc[i].is_some() && loc[j].is_some() {
                continue; // an edge of T itself
            }
            for (g, pl) in TET_OUT_FACES.iter().zip(&planes).skip(1) {
                let gid = [t[g[0]], t[g[1]], t[g[2]]];
                let gp = [tp[g[0]], tp[g[1]], tp[g[2]]];
                if segment_triangle_conflict_by([fp[i], fp[j]], [ei, ej], gp, gid, |x| pl.orient(x))
                {
                    return Err(Conflict::EdgeCrossesNewFace(fv));
                }
            }
        }
    }
    Ok(Verdict {
        min_gap_deg: min_gap,
        min_gap_boundary_deg: min_gap_b,
        closings,
        num_closings,
        closing_on_boundary,
    })
}

/// Is F strictly outside one of T's face planes (`planes`, outward; touching only at T's
/// own vertices on that face)? Cheap early exit for most nearby faces.
fn separated(t: &[u32; 4], planes: &[Plane; 4], fv: &[u32; 3], fp: &[P3; 3]) -> bool {
    'faces: for (face, pl) in TET_OUT_FACES.iter().zip(planes) {
        for k in 0..3 {
            if face.iter().any(|&i| t[i] == fv[k]) {
                continue;
            }
            if pl.orient(fp[k]) <= 0 {
                continue 'faces;
            }
        }
        return true;
    }
    false
}

/// Angle (degrees) swept from front face F's half-plane at edge (tp[e0], tp[e1]), turning
/// towards F's normal `nf`, until the first face of T containing that edge, and the T
/// vertex (local index) of that face opposite the edge.
fn wedge_gap_deg(tp: [P3; 4], e0: usize, e1: usize, f_other: P3, nf: P3) -> (f64, usize) {
    let u = tp[e0];
    let t = normalize(sub(tp[e1], u));
    let perp = |x: P3| {
        let d = sub(x, u);
        sub(d, scale(t, dot(d, t)))
    };
    let e1v = normalize(perp(f_other));
    let e2v = normalize(sub(nf, scale(t, dot(nf, t))));
    let mut best = 360.0f64;
    let mut best_k = 0;
    for (k, &q) in tp.iter().enumerate() {
        if k == e0 || k == e1 {
            continue;
        }
        let x = perp(q);
        let mut ang = dot(x, e2v).atan2(dot(x, e1v)).to_degrees();
        if ang < 0.0 {
            ang += 360.0;
        }
        if ang < best {
            best = ang;
            best_k = k;
        }
    }
    (best, best_k)
}
