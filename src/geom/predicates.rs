//! Exact geometric predicates and the intersection tests built on them.
//!
//! Every topological decision in curvetet (orientation, point in tetrahedron, segment or
//! triangle crossing) goes through here. The signs come from Shewchuk's adaptive exact
//! predicates (`robust` crate), so they are right for all finite f64 inputs within the
//! range the surface checks admit; there is no epsilon anywhere in this file (the one
//! error bound, [`Plane`]'s, is Shewchuk's own filter: it only decides when the sign is
//! certain and defers to [`orient3d`] otherwise).
//!
//! Intersection tests take vertex *identities* (`u32` ids) besides coordinates, so that
//! elements sharing a vertex or an edge are judged by topology: touching at a shared
//! vertex or along a shared edge is not a conflict, touching anywhere else is.

use super::shape::TET_OUT_FACES;
use super::vec3::P3;
use robust::{Coord, Coord3D};

/// Sign (-1, 0, +1) of det[b-a, c-a, d-a]: +1 when `d` lies on the side the normal
/// (b-a)x(c-a) points to, i.e. when tet (a, b, c, d) is positive. Exact.
#[inline]
pub fn orient3d(a: P3, b: P3, c: P3, d: P3) -> i32 {
    // Shewchuk's orient3d is positive when d is *below* the plane (a, b, c seen
    // counterclockwise from above), the opposite of our convention: negate it.
    let v = robust::orient3d(c3(a), c3(b), c3(c), c3(d));
    if v < 0.0 {
        1
    } else if v > 0.0 {
        -1
    } else {
        0
    }
}

/// Shewchuk's error bound of the floating-point 3x3 orientation determinant relative to
/// its permanent ((7 + 56 eps) eps, eps = 2^-53, in `robust`'s `orient3d`), rounded up.
const O3D_ERR_BOUND: f64 = 8.0 * (f64::EPSILON / 2.0);

/// The oriented plane through `a`, `b`, `c`, prepared for many exact orientation tests:
/// [`Plane::orient`]`(d)` is [`orient3d`]`(a, b, c, d)`, decided by a few flops when the
/// floating-point determinant clears Shewchuk's error bound (the same filter `robust`
/// applies first) and by [`orient3d`] when it does not. The validity tests of the front
/// check every nearby front vertex against a candidate's four face planes: with the
/// normal and its error weights computed once per plane, each test costs a third of a
/// full `orient3d` call.
#[derive(Clone, Copy, Debug)]
pub struct Plane {
    p: [P3; 3],
    /// (b − a) × (c − a).
    n: P3,
    /// The permanent's weights: |u_j v_k| + |u_k v_j| per component of `n`.
    w: P3,
}

impl Plane {
    /// The plane through `a`, `b`, `c` (normal (b − a) × (c − a)).
    #[inline]
    pub fn new(a: P3, b: P3, c: P3) -> Plane {
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let prod = |i: usize, j: usize| (u[i] * v[j], u[j] * v[i]);
        let (x0, x1) = prod(1, 2);
        let (y0, y1) = prod(2, 0);
        let (z0, z1) = prod(0, 1);
        Plane {
            p: [a, b, c],
            n: [x0 - x1, y0 - y1, z0 - z1],
            w: [
                x0.abs() + x1.abs(),
                y0.abs() + y1.abs(),
                z0.abs() + z1.abs(),
            ],
        }
    }

    /// [`orient3d`]`(a, b, c, d)`, exact.
    #[inline]
    pub fn orient(&self, d: P3) -> i32 {
        self.filtered(d)
            .unwrap_or_else(|| orient3d(self.p[0], self.p[1], self.p[2], d))
    }

    /// The sign of [`Plane::orient`] when the floating-point determinant clears the error
    /// bound, else `None`.
    #[inline]
    fn filtered(&self, d: P3) -> Option<i32> {
        let a = self.p[0];
        let r = [d[0] - a[0], d[1] - a[1], d[2] - a[2]];
        let det = self.n[0] * r[0] + self.n[1] * r[1] + self.n[2] * r[2];
        let perm = self.w[0] * r[0].abs() + self.w[1] * r[1].abs() + self.w[2] * r[2].abs();
        let bound = O3D_ERR_BOUND * perm;
        if det > bound {
            Some(1)
        } else if det < -bound {
            Some(-1)
        } else {
            None
        }
    }
}

/// The outward face planes of the positive tetrahedron `x` (faces in
/// [`TET_OUT_FACES`] order), for testing many points against it.
#[inline]
pub fn tet_face_planes(x: &[P3; 4]) -> [Plane; 4] {
    TET_OUT_FACES.map(|g| Plane::new(x[g[0]], x[g[1]], x[g[2]]))
}

/// True when `p` lies in the closed tetrahedron whose outward face planes are `planes`
/// ([`tet_face_planes`]): on the inner side of, or on, every one.
#[inline]
pub fn in_closed_tet(planes: &[Plane; 4], p: P3) -> bool {
    planes.iter().all(|pl| pl.orient(p) <= 0)
}

#[inline]
fn c3(p: P3) -> Coord3D<f64> {
    Coord3D {
        x: p[0],
        y: p[1],
        z: p[2],
    }
}

/// A projection of a plane onto two coordinate axes.
#[derive(Clone, Copy, Debug)]
pub struct Proj {
    i: usize,
    j: usize,
}

impl Proj {
    #[inline]
    fn p(self, a: P3) -> Coord<f64> {
        Coord {
            x: a[self.i],
            y: a[self.j],
        }
    }
    /// Sign of the 2D orientation of (a, b, c) in this projection. Exact.
    #[inline]
    pub fn orient2d(self, a: P3, b: P3, c: P3) -> i32 {
        sign(robust::orient2d(self.p(a), self.p(b), self.p(c)))
    }
}

#[inline]
fn sign(v: f64) -> i32 {
    if v > 0.0 {
        1
    } else if v < 0.0 {
        -1
    } else {
        0
    }
}

/// A coordinate projection in which triangle (a, b, c) is not degenerate, and the sign of
/// its orientation there. `None` when the triangle is degenerate (collinear corners).
/// For points coplanar with the triangle, the projection is an affine bijection of the
/// plane, so every 2D orientation sign in it is exact (up to the returned global sign).
pub fn projection_of(a: P3, b: P3, c: P3) -> Option<(Proj, i32)> {
    let mut best: Option<(Proj, i32, f64)> = None;
    for (i, j) in [(0, 1), (1, 2), (2, 0)] {
        let pr = Proj { i, j };
        let v = robust::orient2d(pr.p(a), pr.p(b), pr.p(c));
        // (`Option::is_none_or` needs Rust 1.82; the crate's MSRV is 1.81.)
        if v != 0.0 && best.map_or(true, |b| v.abs() > b.2) {
            best = Some((pr, sign(v), v.abs()));
        }
    }
    best.map(|(p, s, _)| (p, s))
}

/// True when the three points are collinear (exactly).
pub fn collinear(a: P3, b: P3, c: P3) -> bool {
    projection_of(a, b, c).is_none()
}

/// True when `p` lies in the closed tetrahedron (a, b, c, d), which must be positive.
#[inline]
pub fn point_in_closed_tet(p: P3, a: P3, b: P3, c: P3, d: P3) -> bool {
    in_closed_tet(&tet_face_planes(&[a, b, c, d]), p)
}

/// Closed 2D segment-segment intersection (including collinear overlap), in projection `pr`.
fn seg_seg_2d(pr: Proj, p: P3, q: P3, a: P3, b: P3) -> bool {
    let o1 = pr.orient2d(p, q, a);
    let o2 = pr.orient2d(p, q, b);
    let o3 = pr.orient2d(a, b, p);
    let o4 = pr.orient2d(a, b, q);
    if o1 * o2 < 0 && o3 * o4 < 0 {
        return true;
    }
    (o1 == 0 && on_seg_2d(pr, p, q, a))
        || (o2 == 0 && on_seg_2d(pr, p, q, b))
        || (o3 == 0 && on_seg_2d(pr, a, b, p))
        || (o4 == 0 && on_seg_2d(pr, a, b, q))
}

/// For `x` collinear with segment (p, q): is it within the closed segment? Exact
/// (comparisons of input coordinates only).
#[inline]
fn on_seg_2d(pr: Proj, p: P3, q: P3, x: P3) -> bool {
    let (pi, qi, xi) = (p[pr.i], q[pr.i], x[pr.i]);
    let (pj, qj, xj) = (p[pr.j], q[pr.j], x[pr.j]);
    xi >= pi.min(qi) && xi <= pi.max(qi) && xj >= pj.min(qj) && xj <= pj.max(qj)
}

/// Closed 2D point-in-triangle for coplanar points, given the triangle's projection sign.
#[inline]
fn point_in_tri_2d(pr: Proj, s: i32, x: P3, a: P3, b: P3, c: P3) -> bool {
    s * pr.orient2d(a, b, x) >= 0 && s * pr.orient2d(b, c, x) >= 0 && s * pr.orient2d(c, a, x) >= 0
}

/// Does the closed segment (p, q) meet the closed triangle (a, b, c)? No shared-vertex
/// logic: any contact counts. The triangle must not be degenerate; `side(x)` is
/// [`orient3d`]`(a, b, c, x)` (a [`Plane`]'s, say).
fn segment_meets_triangle(p: P3, q: P3, a: P3, b: P3, c: P3, side: impl Fn(P3) -> i32) -> bool {
    let sp = side(p);
    let sq = side(q);
    if sp * sq > 0 {
        return false;
    }
    if sp == 0 && sq == 0 {
        let Some((pr, s)) = projection_of(a, b, c) else {
            return false;
        };
        return point_in_tri_2d(pr, s, p, a, b, c)
            || point_in_tri_2d(pr, s, q, a, b, c)
            || seg_seg_2d(pr, p, q, a, b)
            || seg_seg_2d(pr, p, q, b, c)
            || seg_seg_2d(pr, p, q, c, a);
    }
    // The segment crosses or touches the plane: the line must pass through the triangle.
    let o1 = orient3d(p, q, a, b);
    let o2 = orient3d(p, q, b, c);
    let o3 = orient3d(p, q, c, a);
    (o1 >= 0 && o2 >= 0 && o3 >= 0) || (o1 <= 0 && o2 <= 0 && o3 <= 0)
}

/// Does segment `s` (ids `sid`) meet triangle `t` (ids `tid`) anywhere other than at the
/// vertices and edge they share? Exact. Points with equal ids are taken to be equal.
pub fn segment_triangle_conflict(s: [P3; 2], sid: [u32; 2], t: [P3; 3], tid: [u32; 3]) -> bool {
    segment_triangle_conflict_by(s, sid, t, tid, |x| orient3d(t[0], t[1], t[2], x))
}

/// [`segment_triangle_conflict`] with the triangle's plane test `side(x)` =
/// [`orient3d`]`(t[0], t[1], t[2], x)` given (a [`Plane`]'s, say).
pub fn segment_triangle_conflict_by(
    s: [P3; 2],
    sid: [u32; 2],
    t: [P3; 3],
    tid: [u32; 3],
    side: impl Fn(P3) -> i32,
) -> bool {
    let in_t = |id: u32| tid.iter().position(|&x| x == id);
    match (in_t(sid[0]), in_t(sid[1])) {
        (Some(_), Some(_)) => false, // the segment is an edge of the triangle
        (Some(j), None) => shared_vertex_conflict(t, j, side(s[1]), s[1]),
        (None, Some(j)) => shared_vertex_conflict(t, j, side(s[0]), s[0]),
        (None, None) => segment_meets_triangle(s[0], s[1], t[0], t[1], t[2], side),
    }
}

/// Segment from triangle vertex `t[j]` to `q` (on side `side_q` of the triangle's plane):
/// does it enter the closed triangle beyond `t[j]`? Only possible when `q` is coplanar
/// and inside the closed angle at `t[j]`.
fn shared_vertex_conflict(t: [P3; 3], j: usize, side_q: i32, q: P3) -> bool {
    if side_q != 0 {
        return false;
    }
    let v = t[j];
    let x = t[(j + 1) % 3];
    let y = t[(j + 2) % 3];
    let Some((pr, s)) = projection_of(v, x, y) else {
        return false;
    };
    s * pr.orient2d(v, x, q) >= 0 && s * pr.orient2d(v, q, y) >= 0
}

/// Do triangles `a` and `b` meet anywhere other than at shared vertices or a shared edge?
/// Exact. Identical triangles (three shared ids) are reported as not conflicting; callers
/// that care must compare ids themselves.
pub fn triangle_triangle_conflict(a: [P3; 3], aid: [u32; 3], b: [P3; 3], bid: [u32; 3]) -> bool {
    for k in 0..3 {
        let (i, j) = (k, (k + 1) % 3);
        if segment_triangle_conflict([a[i], a[j]], [aid[i], aid[j]], b, bid) {
            return true;
        }
        if segment_triangle_conflict([b[i], b[j]], [bid[i], bid[j]], a, aid) {
            return true;
        }
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    const O: P3 = [0.0, 0.0, 0.0];
    const X: P3 = [1.0, 0.0, 0.0];
    const Y: P3 = [0.0, 1.0, 0.0];
    const Z: P3 = [0.0, 0.0, 1.0];

    #[test]
    fn orient3d_sign_matches_positive_unit_tet() {
        // det[X-O, Y-O, Z-O] = 1 > 0: the unit tet (O, X, Y, Z) is positive.
        assert_eq!(orient3d(O, X, Y, Z), 1);
        assert_eq!(orient3d(O, Y, X, Z), -1);
        assert_eq!(orient3d(O, X, Y, [0.3, 0.3, 0.0]), 0);
        assert_eq!(crate::geom::vec3::tet_det(O, X, Y, Z), 1.0);
    }

    #[test]
    fn orient3d_exact_where_naive_float_fails() {
        // Points on the plane z = x*1e-?: a near-degenerate configuration where the naive
        // determinant has the wrong sign or zero. Construct d exactly coplanar with
        // a, b, c (all on the plane x + y + z = 1 with dyadic coordinates) and then
        // nudge by one ulp.
        let a = [0.1, 0.2, 0.7];
        let b = [0.5, 0.25, 0.25];
        let c = [1e-17, 1.0, 0.0];
        // d = a + t (b - a) with t = 2^-30, computed; check naive vs exact consistency
        // by perturbing the last bit in z.
        let mut exact_zero_or_pos = 0;
        let mut naive_wrong = 0;
        for k in 0..2000 {
            let t = (k as f64) * 1e-3;
            let d = [
                a[0] + t * (c[0] - a[0]),
                a[1] + t * (c[1] - a[1]),
                a[2] + t * (c[2] - a[2]),
            ];
            let s = orient3d(a, b, c, d);
            let naive = crate::geom::vec3::tet_det(a, b, c, d);
            // Exact sign is antisymmetric under swapping two points: a cheap self-check.
            assert_eq!(s, -orient3d(b, a, c, d));
            assert_eq!(s, orient3d(b, c, a, d));
            if s >= 0 {
                exact_zero_or_pos += 1;
            }
            if (naive > 0.0) as i32 - (naive < 0.0) as i32 != s {
                naive_wrong += 1;
            }
        }
        assert!(exact_zero_or_pos > 0);
        // The naive determinant disagrees with the exact sign on many of these
        // nearly-collinear points (this is why the predicates exist).
        assert!(naive_wrong > 0, "expected naive float to fail somewhere");
    }

    #[test]
    fn exact_orientation_consistency_on_grid() {
        // Classic test: points on a fine grid near a line, orientation must be consistent
        // under cyclic permutation and never contradict itself.
        let p = [0.5, 0.5, 0.0];
        let q = [12.0, 12.0, 0.0];
        let r = [24.0, 24.0, 0.0];
        let w = [0.0, 0.0, 1.0];
        for i in 0..64 {
            for j in 0..64 {
                let pp = [
                    p[0] + i as f64 * f64::EPSILON,
                    p[1] + j as f64 * f64::EPSILON,
                    0.0,
                ];
                let s = orient3d(pp, q, r, w);
                assert_eq!(s, orient3d(q, r, pp, w));
                assert_eq!(s, -orient3d(q, pp, r, w));
                // Exactly collinear when i == j (pp on the line y = x).
                if i == j {
                    assert_eq!(s, 0);
                }
            }
        }
    }

    #[test]
    fn plane_orient_is_orient3d() {
        use rand::{Rng, SeedableRng};
        // Random points, points nudged off exactly coplanar ones by a few ulps (where the
        // filter must defer to the exact predicate), and exactly coplanar ones.
        let mut rng = rand::rngs::StdRng::seed_from_u64(5);
        let mut r3 = |s: f64| -> P3 { std::array::from_fn(|_| s * rng.random_range(-1.0..1.0)) };
        let (mut n, mut zero, mut deferred, mut random_deferred) = (0, 0, 0, 0);
        for scale in [1e-3, 1.0, 1e3] {
            for _ in 0..200 {
                let (a, b, c) = (r3(scale), r3(scale), r3(scale));
                let pl = Plane::new(a, b, c);
                let mut pts: Vec<P3> = (0..20).map(|_| r3(scale)).collect();
                for k in 0..20 {
                    // On segment ab (coplanar up to rounding of the construction), and
                    // that point moved by k ulps in z.
                    let t = k as f64 / 20.0;
                    let mut d: P3 = std::array::from_fn(|i| a[i] + t * (b[i] - a[i]));
                    pts.push(d);
                    for _ in 0..k % 4 {
                        d[2] = d[2].next_up();
                    }
                    pts.push(d);
                }
                pts.extend([a, b, c]);
                for (i, d) in pts.into_iter().enumerate() {
                    let exact = orient3d(a, b, c, d);
                    assert_eq!(pl.orient(d), exact, "{a:?} {b:?} {c:?} {d:?}");
                    n += 1;
                    zero += usize::from(exact == 0);
                    let defer = pl.filtered(d).is_none();
                    deferred += usize::from(defer);
                    random_deferred += usize::from(defer && i < 20);
                }
            }
        }
        // Every exact zero was deferred (else the filter could not have matched it), and
        // so were some of the nudged points, but almost no random one.
        assert!(zero > 1000 && deferred > zero, "{n} {zero} {deferred}");
        assert!(random_deferred * 1000 < n, "{n} {random_deferred}");
    }

    #[test]
    fn point_in_tet() {
        assert!(point_in_closed_tet([0.1, 0.1, 0.1], O, X, Y, Z));
        assert!(point_in_closed_tet(O, O, X, Y, Z));
        assert!(point_in_closed_tet([0.5, 0.5, 0.0], O, X, Y, Z));
        assert!(!point_in_closed_tet([0.5, 0.5, 0.1], O, X, Y, Z));
        assert!(!point_in_closed_tet([-1e-300, 0.1, 0.1], O, X, Y, Z));
    }

    #[test]
    fn segment_triangle_cases() {
        let t = [O, X, Y];
        let tid = [0, 1, 2];
        // Crossing through the interior.
        assert!(segment_triangle_conflict(
            [[0.2, 0.2, -1.0], [0.2, 0.2, 1.0]],
            [10, 11],
            t,
            tid
        ));
        // Missing.
        assert!(!segment_triangle_conflict(
            [[0.8, 0.8, -1.0], [0.8, 0.8, 1.0]],
            [10, 11],
            t,
            tid
        ));
        // Touching an edge: a conflict (no shared vertex).
        assert!(segment_triangle_conflict(
            [[0.5, 0.5, -1.0], [0.5, 0.5, 1.0]],
            [10, 11],
            t,
            tid
        ));
        // Shared vertex, not coplanar: fine.
        assert!(!segment_triangle_conflict(
            [O, [0.2, 0.2, 1.0]],
            [0, 11],
            t,
            tid
        ));
        // Shared vertex, coplanar, inside the angle: conflict.
        assert!(segment_triangle_conflict(
            [O, [0.2, 0.2, 0.0]],
            [0, 11],
            t,
            tid
        ));
        // Shared vertex, coplanar, outside the angle: fine.
        assert!(!segment_triangle_conflict(
            [O, [-0.2, 0.2, 0.0]],
            [0, 11],
            t,
            tid
        ));
        // Shared vertex, collinear overlap with an edge: conflict.
        assert!(segment_triangle_conflict(
            [O, [2.0, 0.0, 0.0]],
            [0, 11],
            t,
            tid
        ));
        // An edge of the triangle: fine.
        assert!(!segment_triangle_conflict([O, X], [0, 1], t, tid));
        // Coplanar, disjoint ids, crossing the triangle: conflict.
        assert!(segment_triangle_conflict(
            [[-1.0, 0.3, 0.0], [2.0, 0.3, 0.0]],
            [10, 11],
            t,
            tid
        ));
        // Coplanar, disjoint: fine.
        assert!(!segment_triangle_conflict(
            [[-1.0, 3.0, 0.0], [2.0, 3.0, 0.0]],
            [10, 11],
            t,
            tid
        ));
        // Endpoint touching the interior from above: conflict.
        assert!(segment_triangle_conflict(
            [[0.2, 0.2, 0.0], [0.2, 0.2, 1.0]],
            [10, 11],
            t,
            tid
        ));
    }

    #[test]
    fn segment_triangle_near_degenerate() {
        // Segment passing one ulp beside a triangle's edge: the exact predicate must tell
        // inside from outside.
        let t = [O, X, Y];
        let tid = [0, 1, 2];
        // One ulp beside the edge x + y = 1 (at x = 0.5): outside, then inside.
        let up = f64::from_bits(0.5f64.to_bits() + 1);
        let down = f64::from_bits(0.5f64.to_bits() - 1);
        assert!(!segment_triangle_conflict(
            [[up, 0.5, -1.0], [up, 0.5, 1.0]],
            [7, 8],
            t,
            tid
        ));
        assert!(segment_triangle_conflict(
            [[down, 0.5, -1.0], [down, 0.5, 1.0]],
            [7, 8],
            t,
            tid
        ));
        // On the edge exactly: touching counts.
        assert!(segment_triangle_conflict(
            [[0.5, 0.5, -1.0], [0.5, 0.5, 1.0]],
            [7, 8],
            t,
            tid
        ));
    }

    #[test]
    fn triangle_triangle_cases() {
        let a = [O, X, Y];
        let aid = [0, 1, 2];
        // Shares edge (O, X), folded up: fine.
        assert!(!triangle_triangle_conflict(
            a,
            aid,
            [O, X, [0.3, 0.0, 1.0]],
            [0, 1, 3]
        ));
        // Shares edge, coplanar on the same side: overlap.
        assert!(triangle_triangle_conflict(
            a,
            aid,
            [X, O, [0.3, 0.4, 0.0]],
            [1, 0, 3]
        ));
        // Shares edge, coplanar on the other side: fine.
        assert!(!triangle_triangle_conflict(
            a,
            aid,
            [X, O, [0.3, -0.4, 0.0]],
            [1, 0, 3]
        ));
        // Piercing without shared vertices.
        assert!(triangle_triangle_conflict(
            a,
            aid,
            [[0.2, 0.2, -1.0], [0.3, 0.2, 1.0], [0.2, 0.3, 1.0]],
            [5, 6, 7]
        ));
        // Disjoint.
        assert!(!triangle_triangle_conflict(
            a,
            aid,
            [[2.0, 2.0, -1.0], [3.0, 2.0, 1.0], [2.0, 3.0, 1.0]],
            [5, 6, 7]
        ));
        // Shares one vertex, the other triangle cuts through a's interior along a line from O.
        assert!(triangle_triangle_conflict(
            a,
            aid,
            [O, [0.5, 0.5, -1.0], [0.5, 0.5, 1.0]],
            [0, 5, 6]
        ));
        // Coplanar, one inside the other, no shared ids.
        assert!(triangle_triangle_conflict(
            a,
            aid,
            [[0.1, 0.1, 0.0], [0.2, 0.1, 0.0], [0.1, 0.2, 0.0]],
            [5, 6, 7]
        ));
    }
}
