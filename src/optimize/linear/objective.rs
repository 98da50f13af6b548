//! The element quality the linear stage maximizes (the minimum of, over the elements an
//! operation touches): 1 − equiangular skewness (paper eq. 2) of the corner tet, in
//! [0, 1], for a tet that is positive (exact) and, when it touches a curved boundary edge,
//! certified valid as a P2 element. A positive tet that is not P2-valid scores in
//! [−1, −0.5] by how far its Jacobian bound is from positive (so operations may improve
//! it but never create one); a non-positive tet, or one no placement of its interior mid
//! nodes can make valid, scores −∞.

use super::mesh::opposite_edge;
use crate::geom::bezier::{certify, fixed_coefficients_positive, jacobian_bounds, LinearJacobian};
use crate::geom::shape::TET10_EDGES;
use crate::geom::tet_quality::{
    dihedral_at_edge, dihedral_extremes, positive_and_not_flat, skewness_from_extremes,
    EQUIANGULAR_DIHEDRAL_DEG,
};
use crate::geom::vec3::P3;
use crate::optimize::dual::{dcross, ddot, dsub, D3, DP};
use crate::optimize::Boundary;

/// Weight of the straight-interior Bernstein ratio min b / max b of a curved tet with an
/// interior vertex in its quality (1: it counts as bad below 1 − the goal skewness, 0.4
/// by default; 2 gave screw 0.525 after the front's wedge floor, 1 gives 0.616, with
/// the other surfaces unchanged).
const CURVED_WEIGHT: f64 = 1.0;

/// Weight of the Bernstein ratio of a curved tet whose corners are all on the boundary
/// and which has at most one free (interior) edge: the high-order stage can barely change
/// its curved shape, so a poor ratio here counts as worse than the same skewness
/// elsewhere (trading such a tet for a sliver is right; the reverse made the hinge from
/// hinge_lin.off end at min J / max J 0.154 once the vertex search was added; with 0.6
/// every hinge variant and the screw are at least as good as without the search).
const PINNED_CURVED_WEIGHT: f64 = 0.6;

/// The quality measure of the linear stage (see the module docs).
#[derive(Clone, Copy, Debug, Default)]
pub struct ElementQuality;

impl ElementQuality {
    /// Quality of the tet on vertex ids `v` with corner positions `c` (`pts` gives the
    /// boundary mid nodes).
    #[inline]
    pub fn eval(&self, bnd: &Boundary, pts: &[P3], v: [u32; 4], c: &[P3; 4]) -> f64 {
        self.eval_above(bnd, pts, v, c, f64::NEG_INFINITY)
    }

    /// [`ElementQuality::eval`] when it is above `floor`; otherwise some value ≤ `floor`
    /// (the corner skewness alone already decides it: every score is at most 1 − skewness,
    /// so the curved part, the costly one, is skipped).
    #[inline]
    pub fn eval_above(
        &self,
        bnd: &Boundary,
        pts: &[P3],
        v: [u32; 4],
        c: &[P3; 4],
        floor: f64,
    ) -> f64 {
        self.eval_above_with(bnd, pts, v, c, floor, |_| false)
    }

    /// [`ElementQuality::eval_above`] with the boundary edges for which `on_chord` is
    /// true taken straight ([`Boundary::tet10_with`]).
    #[inline]
    pub fn eval_above_with(
        &self,
        bnd: &Boundary,
        pts: &[P3],
        v: [u32; 4],
        c: &[P3; 4],
        floor: f64,
        on_chord: impl Fn((u32, u32)) -> bool,
    ) -> f64 {
        self.eval_and_min_dihedral(bnd, pts, v, c, floor, on_chord)
            .0
    }

    /// [`ElementQuality::eval_above_with`] and the tet's smallest dihedral angle
    /// (degrees; NaN where the quality is −∞ without it), measured once for both (the
    /// sliver passes' score needs both).
    #[inline]
    pub(crate) fn eval_and_min_dihedral(
        &self,
        bnd: &Boundary,
        pts: &[P3],
        v: [u32; 4],
        c: &[P3; 4],
        floor: f64,
        on_chord: impl Fn((u32, u32)) -> bool,
    ) -> (f64, f64) {
        // A numerically flat tet scores as an inverted one: its Jacobian cannot be
        // certified, so the stage never makes one and works to remove those it is given.
        if !positive_and_not_flat(c) {
            return (f64::NEG_INFINITY, f64::NAN);
        }
        let (lo, hi) = dihedral_extremes(c);
        // (The shape's score, with early returns.)
        let q = (|| {
            let s = skewness_from_extremes(lo, hi);
            if !s.is_finite() {
                return f64::NEG_INFINITY;
            }
            if 1.0 - s <= floor {
                return 1.0 - s;
            }
            let nb = v.iter().filter(|&&x| bnd.is_fixed(x)).count();
            if nb >= 2 {
                let (x, curved) = bnd.tet10_with(pts, v, c, on_chord);
                if !curved {
                    return 1.0 - s;
                }
                // The Bernstein coefficients settle almost every tet at once (certify would
                // compute the same ones first); only the undecided go through `certify`.
                let lj = LinearJacobian::new(&x);
                let b = lj.bezier();
                let (blo, bhi) = b
                    .iter()
                    .fold((f64::INFINITY, 0.0f64), |(l, h), &v| (l.min(v), h.max(v)));
                let tau = lj.rounding_margin();
                let valid = (blo > tau && blo.is_finite()) || certify(&x).is_valid();
                // Edges the high-order stage may curve (not boundary edges).
                let free_mid = || TET10_EDGES.map(|[i, j]| bnd.edge_mid(v[i], v[j]).is_none());
                if !valid {
                    // Invalid whatever the high-order stage does with the interior mid
                    // nodes (a coefficient only boundary nodes set is not positive): as bad
                    // as an inverted tet, so no operation creates one.
                    if !fixed_coefficients_positive(&b, tau, free_mid()) {
                        return f64::NEG_INFINITY;
                    }
                    // How far det J is from positive, in (-1, 0]: min_lower over |min_lower| +
                    // |max_upper|, which keeps falling as the element gets more inverted (the
                    // scaled Jacobian's bound is -1 for every fully inverted element, a
                    // plateau on which no operation could show progress: on OpenSCAD's
                    // example021 the whole fill left such tets that the passes never moved).
                    let jb = jacobian_bounds(&x, 1e-2);
                    let r = jb.min_lower / (jb.min_lower.abs() + jb.max_upper.abs());
                    let r = if r.is_nan() { -1.0 } else { r.clamp(-1.0, 0.0) };
                    return -1.0 + 0.5 * (1.0 + r);
                }
                let ratio = blo / bhi;
                if nb == 4 {
                    // No interior vertex: the high-order stage can move few nodes of this
                    // tet, so its curved shape counts here (unrefined Bernstein ratio).
                    let free = free_mid().iter().filter(|&&f| f).count();
                    let k = if free <= 1 { PINNED_CURVED_WEIGHT } else { 1.0 };
                    return (1.0 - s).min(k * ratio);
                }
                // A curved tet barely valid with straight interior edges blocks every move
                // of its corners: count it as bad, so it is worked on first.
                return (1.0 - s).min(CURVED_WEIGHT * ratio);
            }
            1.0 - s
        })();
        (q, lo)
    }
}

/// Slack of [`ruled_out`]: far above the rounding of a bound or a minimum (about
/// 1e-15), so an operation that could succeed is never ruled out.
const BOUND_MARGIN: f64 = 1e-9;

/// An upper bound on the minimum quality of tets that replace the tets `ts` around the
/// edge (a, b) by cutting each, (a, b, u, v), along its edge (u, v) opposite (a, b): as an
/// edge split does (the new vertex lies on every cutting plane) and an edge removal does
/// (each ring edge (u, v) is an edge of one triangle of the ring's triangulation, whose
/// two new tets, one on a's side and one on b's, cut the old tet along it). The dihedral
/// angles of the two positive tets of a cut add up, at (u, v), to the old tet's there, so
/// one of them has at most half of it; and a tet's quality is at most θmin / θe
/// (1 − equiangular skewness, paper eq. 2; a curved part only lowers it). A non-positive
/// tet scores −∞, below any bound.
pub(super) fn cut_bound(pts: &[P3], tets: &[[u32; 4]], a: u32, b: u32, ts: &[u32]) -> f64 {
    let (pa, pb) = (pts[a as usize], pts[b as usize]);
    ts.iter()
        .map(|&t| {
            let (u, v) = opposite_edge(tets[t as usize], a, b);
            dihedral_at_edge(pts[u as usize], pts[v as usize], pa, pb)
                / (2.0 * EQUIANGULAR_DIHEDRAL_DEG)
        })
        .fold(f64::INFINITY, f64::min)
}

/// Whether `bound` (a [`cut_bound`]) rules out a minimum above `to_beat`.
pub(super) fn ruled_out(bound: f64, to_beat: f64) -> bool {
    bound + BOUND_MARGIN <= to_beat
}

/// The twelve smooth pieces whose minimum is 1 − skewness: for each dihedral angle θ
/// (degrees), θ/θe and (180 − θ)/(180 − θe); with their gradients with respect to corner
/// `k` of `c`.
pub(super) fn skew_pieces(c: &[P3; 4], k: usize) -> [D3; 12] {
    let p: [DP; 4] = std::array::from_fn(|i| {
        std::array::from_fn(|d| {
            if i == k {
                D3::var(c[i][d], d)
            } else {
                D3::c(c[i][d])
            }
        })
    });
    // Outward normals of the faces opposite corners 0..3 (as in geom::tet_quality).
    let n = |a: usize, b: usize, d: usize| dcross(dsub(p[b], p[a]), dsub(p[d], p[a]));
    let normals = [n(1, 2, 3), n(0, 3, 2), n(0, 1, 3), n(0, 2, 1)];
    let te = EQUIANGULAR_DIHEDRAL_DEG;
    let mut out = [D3::c(0.0); 12];
    for (e, [a, b]) in crate::geom::shape::TET10_EDGES.iter().enumerate() {
        let mut other = [0usize; 2];
        let mut m = 0;
        for v in 0..4 {
            if v != *a && v != *b {
                other[m] = v;
                m += 1;
            }
        }
        let (na, nb) = (normals[other[0]], normals[other[1]]);
        let x = dcross(na, nb);
        let s = ddot(x, x).sqrt();
        let cs = -ddot(na, nb);
        let theta = s.atan2(cs).scale(180.0 / std::f64::consts::PI);
        out[2 * e] = theta.scale(1.0 / te);
        out[2 * e + 1] = (D3::c(180.0) - theta).scale(1.0 / (180.0 - te));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::tet_quality::{dihedral_angles, equiangular_skewness};

    /// A tet positive by the exact predicate but flatter than f64 resolves scores as an
    /// inverted one; a thin one that is not still has its (poor) quality.
    #[test]
    fn a_numerically_flat_tet_scores_as_an_inverted_one() {
        use crate::geom::predicates::orient3d;
        // No surface: every corner is free, so only the straight tet is scored.
        let bnd = crate::optimize::Boundary::new(0, &[]);
        let tet = |h: f64| -> [P3; 4] {
            [
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.3, 0.3, h],
            ]
        };
        let v = [0, 1, 2, 3];
        let flat = tet(1e-14);
        assert!(orient3d(flat[0], flat[1], flat[2], flat[3]) > 0);
        assert_eq!(ElementQuality.eval(&bnd, &[], v, &flat), f64::NEG_INFINITY);
        let thin = ElementQuality.eval(&bnd, &[], v, &tet(1e-6));
        assert!(thin.is_finite() && thin >= 0.0, "{thin}");
    }

    #[test]
    fn eval_above_agrees_with_eval_above_the_floor() {
        use rand::{Rng, SeedableRng};
        // A cube with a bulged (curved) boundary, corners moved at random: tets with
        // curved boundary faces, inverted and poor ones, against floors across [−1, 1].
        let c = crate::optimize::testmesh::cube(3, 0.08);
        let bnd = c.boundary();
        let mut rng = rand::rngs::StdRng::seed_from_u64(11);
        let (mut curved, mut cut) = (0, 0);
        for _ in 0..20 {
            for t in &c.tets {
                let x: [P3; 4] = std::array::from_fn(|i| {
                    let p = c.pts[t[i] as usize];
                    std::array::from_fn(|d| p[d] + rng.random_range(-0.12..0.12))
                });
                let q = ElementQuality.eval(&bnd, &c.pts, *t, &x);
                if t.iter().filter(|&&v| bnd.is_fixed(v)).count() >= 2 {
                    curved += 1;
                }
                for floor in [-1.0, -0.5, 0.0, 0.2, 0.4, 0.6, 0.8, 1.0] {
                    let a = ElementQuality.eval_above(&bnd, &c.pts, *t, &x, floor);
                    if q > floor {
                        assert_eq!(a.to_bits(), q.to_bits(), "{t:?} floor {floor}");
                    } else {
                        assert!(a <= floor, "{t:?} floor {floor}: {a} for {q}");
                        cut += usize::from(a != q);
                    }
                }
            }
        }
        assert!(curved > 100 && cut > 0, "{curved} {cut}");
    }

    #[test]
    fn pieces_give_one_minus_skewness_and_their_gradients() {
        let c = [
            [0.0, 0.0, 0.0],
            [1.0, 0.1, 0.0],
            [0.2, 0.9, 0.1],
            [0.3, 0.2, 0.7],
        ];
        let s = equiangular_skewness(&dihedral_angles(&c));
        for k in 0..4 {
            let p = skew_pieces(&c, k);
            let m = p.iter().map(|x| x.v).fold(f64::INFINITY, f64::min);
            assert!((m - (1.0 - s)).abs() < 1e-12);
            for (i, piece) in p.iter().enumerate() {
                for d in 0..3 {
                    let h = 1e-6;
                    let mut cp = c;
                    cp[k][d] += h;
                    let mut cm = c;
                    cm[k][d] -= h;
                    let fd = (skew_pieces(&cp, k)[i].v - skew_pieces(&cm, k)[i].v) / (2.0 * h);
                    assert!((fd - piece.g[d]).abs() < 1e-6, "{k} {i} {d}");
                }
            }
        }
    }
}
