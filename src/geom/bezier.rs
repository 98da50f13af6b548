//! Bernstein (Bézier) form of the Jacobian determinant of the 10-node tetrahedron, and the
//! certified bounds built on it (Johnen, Remacle, Geuzaine, "Geometrical validity of
//! curvilinear finite elements", J. Comput. Phys. 233, 2013).
//!
//! det J of a P2 tet is a cubic polynomial on the reference tet. Written in the cubic
//! Bernstein basis its 20 coefficients bound it: min coefficient <= min det J and
//! max coefficient >= max det J, and the four corner coefficients *are* the values at the
//! corners. Restricting the polynomial to smaller sub-tets (red refinement) and
//! recomputing the coefficients there makes the bounds converge quadratically to the true
//! extrema, which decides validity (the sign of min det J) and tightens the scaled
//! Jacobian min J / max J.
//!
//! How the coefficients are computed (the most accurate route, no matrix inverse): each
//! column dx/dxi_d of the Jacobian matrix is a *linear* polynomial; in barycentric
//! coordinates l it is `sum_j c_d[j] l_j` ([`LinearJacobian`]). So
//! `det J(l) = sum_{i,j,k} l_i l_j l_k det[c_1[i], c_2[j], c_3[k]]`, and the Bernstein
//! coefficient of multi-index `a` is the average of `det[c_1[i], c_2[j], c_3[k]]` over the
//! ordered triples (i, j, k) whose multiset is `a` (64 small determinants). On a sub-tet
//! with barycentric vertices V_0..V_3 the columns are again linear, with coefficients
//! c_d(V_k): the same formula gives the coefficients of the restriction, computed from the
//! root columns directly (no error accumulates with depth: sub-tet vertices are exact
//! dyadic fractions).
//!
//! Rounding: all bounds are widened by a margin `tau` that covers the floating-point error
//! of the coefficients (see [`LinearJacobian::rounding_margin`]), so "certified" holds for the
//! exact polynomial defined by the f64 nodes, not only up to rounding.

use super::predicates::orient3d;
use super::shape::{tet10_det_jacobian, TET10_EDGES};
use super::vec3::{cross, det3, dot, mid, norm, sub, tet_det, P3};

/// Multi-indices (a_0, a_1, a_2, a_3), |a| = 3, of the 20 cubic Bernstein coefficients in
/// the order [`jacobian_bezier`] returns them: the 4 corners (0..4), then two per edge in
/// [`TET10_EDGES`] order, the one nearer the edge's first corner first (4..16), then the
/// 4 face centres, opposite corners 0, 1, 2, 3 (16..20). The coefficient's control point
/// (Greville point) is at barycentric coordinates a / 3.
pub const BEZIER_INDEX: [[u8; 4]; 20] = [
    [3, 0, 0, 0],
    [0, 3, 0, 0],
    [0, 0, 3, 0],
    [0, 0, 0, 3],
    [2, 1, 0, 0],
    [1, 2, 0, 0],
    [0, 2, 1, 0],
    [0, 1, 2, 0],
    [1, 0, 2, 0],
    [2, 0, 1, 0],
    [1, 0, 0, 2],
    [2, 0, 0, 1],
    [0, 0, 1, 2],
    [0, 0, 2, 1],
    [0, 1, 0, 2],
    [0, 2, 0, 1],
    [0, 1, 1, 1],
    [1, 0, 1, 1],
    [1, 1, 0, 1],
    [1, 1, 1, 0],
];

/// Coefficient slot of each ordered triple (i, j, k) (index 16 i + 4 j + k); the
/// reference for the hand-expanded [`coeffs_from_columns`] (checked in the tests), and
/// the table the optimizer's Jacobian and its derivative use.
pub(crate) const TRIPLE_SLOT: [u8; 64] = triple_slots();

const fn triple_slots() -> [u8; 64] {
    let mut out = [0u8; 64];
    let mut t = 0;
    while t < 64 {
        let mut a = [0u8; 4];
        a[t / 16] += 1;
        a[(t / 4) % 4] += 1;
        a[t % 4] += 1;
        let mut s = 0;
        while s < 20 {
            let b = BEZIER_INDEX[s];
            if b[0] == a[0] && b[1] == a[1] && b[2] == a[2] && b[3] == a[3] {
                out[t] = s as u8;
            }
            s += 1;
        }
        t += 1;
    }
    out
}

/// 1 / (number of ordered triples with the slot's multiset) = a! / 3!.
pub(crate) const SLOT_WEIGHT: [f64; 20] = {
    let mut w = [0.0; 20];
    let mut s = 0;
    while s < 20 {
        w[s] = if s < 4 {
            1.0
        } else if s < 16 {
            1.0 / 3.0
        } else {
            1.0 / 6.0
        };
        s += 1;
    }
    w
};

/// Greatest depth of red refinement used by the adaptive bounds (sub-tets of edge
/// 2^-10 of the reference tet's).
pub const MAX_DEPTH: u8 = 10;
/// Most sub-tets whose coefficients are computed for one element. Bounds the work: a
/// sub-tet costs about 0.3 us, so at most ~0.3 ms per element (the worst of 600000 random
/// curved tets needed 520 sub-tets for a 1e-3 scaled-Jacobian tolerance).
pub const MAX_SUBDOMAINS: u32 = 1024;
/// Most unsettled sub-tets kept at once (stack memory of the refinement).
const MAX_ACTIVE: usize = 128;

/// The Jacobian matrix of a P2 tet as a linear polynomial in barycentric coordinates:
/// column d (d = 0, 1, 2 for d/dxi, d/deta, d/dzeta) is `sum_j cols[d][j] * l_j` with
/// l = (1 - xi - eta - zeta, xi, eta, zeta).
///
/// The cheapest exact representation of dx/dxi; evaluating det J with it costs about a
/// third of [`tet10_det_jacobian`]. Built from node coordinates relative to corner 0, so
/// it is as accurate far from the origin as near it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinearJacobian {
    /// `cols[d][j]`: coefficient of `l_j` in column d.
    pub cols: [[P3; 4]; 3],
    /// Largest distance |x_i - x_0| of a node from corner 0; scales the rounding margin.
    pub extent: f64,
}

impl LinearJacobian {
    /// The linear Jacobian of the 10-node tet `x` (Gmsh order).
    #[inline]
    pub fn new(x: &[P3; 10]) -> Self {
        let mut y = [[0.0; 3]; 10];
        let mut e2 = 0.0;
        for i in 1..10 {
            y[i] = sub(x[i], x[0]);
            let n2 = dot(y[i], y[i]);
            // (A plain comparison, not f64::max: cheaper, and NaN input is caught later.)
            if n2 > e2 {
                e2 = n2;
            }
        }
        let extent = e2.sqrt();
        // Mid node (relative to x0) of the edge {a, b}.
        let m = |a: usize, b: usize| -> P3 {
            match (a.min(b), a.max(b)) {
                (0, 1) => y[4],
                (1, 2) => y[5],
                (0, 2) => y[6],
                (0, 3) => y[7],
                (2, 3) => y[8],
                _ => y[9], // (1, 3)
            }
        };
        let mut cols = [[[0.0; 3]; 4]; 3];
        for d in 1..4 {
            let yd = y[d];
            let m0d = m(0, d);
            let col = &mut cols[d - 1];
            for k in 0..3 {
                // At corner 0: 4 m_0d - 3 y_0 - y_d, with y_0 = 0.
                col[0][k] = 4.0 * m0d[k] - yd[k];
                // At corner d: 3 y_d + y_0 - 4 m_0d.
                col[d][k] = 3.0 * yd[k] - 4.0 * m0d[k];
            }
            for (j, cj) in col.iter_mut().enumerate().skip(1) {
                if j == d {
                    continue;
                }
                let mjd = m(j, d);
                let m0j = m(0, j);
                for k in 0..3 {
                    // Elsewhere: 4 (m_jd - m_0j) - (y_d - y_0).
                    cj[k] = 4.0 * (mjd[k] - m0j[k]) - yd[k];
                }
            }
        }
        LinearJacobian { cols, extent }
    }

    /// The three columns of dx/dxi at barycentric point `l`.
    #[inline]
    pub fn columns_at(&self, l: [f64; 4]) -> [P3; 3] {
        let mut out = [[0.0; 3]; 3];
        for (o, c) in out.iter_mut().zip(self.cols.iter()) {
            for k in 0..3 {
                o[k] = c[0][k] * l[0] + c[1][k] * l[1] + c[2][k] * l[2] + c[3][k] * l[3];
            }
        }
        out
    }

    /// det J at barycentric point `l`.
    #[inline]
    pub fn det_bary(&self, l: [f64; 4]) -> f64 {
        let [a, b, c] = self.columns_at(l);
        det3(a, b, c)
    }

    /// det J at reference point `xi` = (xi, eta, zeta).
    #[inline]
    pub fn det(&self, xi: [f64; 3]) -> f64 {
        self.det_bary(bary(xi))
    }

    /// The 20 Bernstein coefficients of det J on the whole reference tet.
    #[inline]
    pub fn bezier(&self) -> [f64; 20] {
        coeffs_from_columns(&self.cols)
    }

    /// The 20 Bernstein coefficients of det J restricted to the sub-tet whose vertices
    /// have reference coordinates `v` (det J of the *parent* map, not of the composed one).
    #[inline]
    pub fn bezier_on(&self, v: &[[f64; 3]; 4]) -> [f64; 20] {
        let mut c = [[[0.0; 3]; 4]; 3];
        for (k, vk) in v.iter().enumerate() {
            let cols = self.columns_at(bary(*vk));
            for d in 0..3 {
                c[d][k] = cols[d];
            }
        }
        coeffs_from_columns(&c)
    }

    /// A bound on the floating-point error of any coefficient this module computes (on
    /// the root or on a sub-tet), relative to the exact polynomial of the f64 nodes.
    ///
    /// With u = 2^-53, R = [`extent`](Self::extent) and C_d = max_j |cols[d][j]|: the node
    /// offsets carry error <= uR, so the columns carry <= ~26uR per component (<= 45uR in
    /// norm; sub-tet columns are convex combinations, adding <= 4u C_d). A determinant then
    /// carries <= 45uR (C_1C_2 + C_1C_3 + C_2C_3) from its inputs and, with its own
    /// arithmetic and the averaging, <= ~20u C_1C_2C_3. The margin is about 1.5-3 times
    /// that: 128uR (C_1C_2 + C_1C_3 + C_2C_3) + 32u C_1C_2C_3.
    pub fn rounding_margin(&self) -> f64 {
        let u = f64::EPSILON * 0.5;
        let mut c = [0.0f64; 3];
        for (cd, col) in c.iter_mut().zip(self.cols.iter()) {
            for v in col {
                // (A plain comparison, not f64::max: cheaper; a NaN is skipped either way.)
                let n2 = dot(*v, *v);
                if n2 > *cd {
                    *cd = n2;
                }
            }
            *cd = cd.sqrt();
        }
        32.0 * u * c[0] * c[1] * c[2]
            + 128.0 * u * self.extent * (c[0] * c[1] + c[0] * c[2] + c[1] * c[2])
    }
}

/// Barycentric coordinates (1 - xi - eta - zeta, xi, eta, zeta) of a reference point.
#[inline]
pub fn bary(xi: [f64; 3]) -> [f64; 4] {
    [1.0 - xi[0] - xi[1] - xi[2], xi[0], xi[1], xi[2]]
}

/// Bernstein coefficients of the cubic det[c_0(l), c_1(l), c_2(l)] for linear columns:
/// coefficient `a` is the mean of det[c_0[i], c_1[j], c_2[k]] over the ordered triples
/// (i, j, k) with multiset `a` (written out, so every index is a constant).
#[inline]
fn coeffs_from_columns(c: &[[P3; 4]; 3]) -> [f64; 20] {
    const THIRD: f64 = 1.0 / 3.0;
    const SIXTH: f64 = 1.0 / 6.0;
    let mut x = [[0.0; 3]; 16];
    for j in 0..4 {
        for k in 0..4 {
            x[4 * j + k] = cross(c[1][j], c[2][k]);
        }
    }
    let d = |i: usize, j: usize, k: usize| dot(c[0][i], x[4 * j + k]);
    [
        d(0, 0, 0),
        d(1, 1, 1),
        d(2, 2, 2),
        d(3, 3, 3),
        (d(0, 0, 1) + d(0, 1, 0) + d(1, 0, 0)) * THIRD,
        (d(0, 1, 1) + d(1, 0, 1) + d(1, 1, 0)) * THIRD,
        (d(1, 1, 2) + d(1, 2, 1) + d(2, 1, 1)) * THIRD,
        (d(1, 2, 2) + d(2, 1, 2) + d(2, 2, 1)) * THIRD,
        (d(0, 2, 2) + d(2, 0, 2) + d(2, 2, 0)) * THIRD,
        (d(0, 0, 2) + d(0, 2, 0) + d(2, 0, 0)) * THIRD,
        (d(0, 3, 3) + d(3, 0, 3) + d(3, 3, 0)) * THIRD,
        (d(0, 0, 3) + d(0, 3, 0) + d(3, 0, 0)) * THIRD,
        (d(2, 3, 3) + d(3, 2, 3) + d(3, 3, 2)) * THIRD,
        (d(2, 2, 3) + d(2, 3, 2) + d(3, 2, 2)) * THIRD,
        (d(1, 3, 3) + d(3, 1, 3) + d(3, 3, 1)) * THIRD,
        (d(1, 1, 3) + d(1, 3, 1) + d(3, 1, 1)) * THIRD,
        (d(1, 2, 3) + d(1, 3, 2) + d(2, 1, 3) + d(2, 3, 1) + d(3, 1, 2) + d(3, 2, 1)) * SIXTH,
        (d(0, 2, 3) + d(0, 3, 2) + d(2, 0, 3) + d(2, 3, 0) + d(3, 0, 2) + d(3, 2, 0)) * SIXTH,
        (d(0, 1, 3) + d(0, 3, 1) + d(1, 0, 3) + d(1, 3, 0) + d(3, 0, 1) + d(3, 1, 0)) * SIXTH,
        (d(0, 1, 2) + d(0, 2, 1) + d(1, 0, 2) + d(1, 2, 0) + d(2, 0, 1) + d(2, 1, 0)) * SIXTH,
    ]
}

/// The table-driven version of [`coeffs_from_columns`], for the tests.
#[cfg(test)]
fn coeffs_by_table(c: &[[P3; 4]; 3]) -> [f64; 20] {
    let mut b = [0.0; 20];
    for i in 0..4 {
        for j in 0..4 {
            for k in 0..4 {
                b[TRIPLE_SLOT[16 * i + 4 * j + k] as usize] += det3(c[0][i], c[1][j], c[2][k]);
            }
        }
    }
    for (v, w) in b.iter_mut().zip(SLOT_WEIGHT.iter()) {
        *v *= w;
    }
    b
}

/// True when every mid node is bit-for-bit the midpoint of its edge's corners (as
/// [`super::shape::straight_tet10`] builds them): then det J is the constant
/// det[v1-v0, v2-v0, v3-v0] and all bounds are exact.
#[inline]
pub fn is_straight(x: &[P3; 10]) -> bool {
    TET10_EDGES
        .iter()
        .enumerate()
        .all(|(k, [a, b])| x[4 + k] == mid(x[*a], x[*b]))
}

/// The 20 Bernstein coefficients of det J of the 10-node tet `x`, in [`BEZIER_INDEX`]
/// order. For a straight-sided tet (see [`is_straight`]) they are all exactly
/// det[v1-v0, v2-v0, v3-v0] = 6 * volume.
#[inline]
pub fn jacobian_bezier(x: &[P3; 10]) -> [f64; 20] {
    if is_straight(x) {
        return [tet_det(x[0], x[1], x[2], x[3]); 20];
    }
    LinearJacobian::new(x).bezier()
}

/// Value at reference point `xi` of the cubic with Bernstein coefficients `b`
/// ([`BEZIER_INDEX`] order).
#[inline]
pub fn bezier_eval(b: &[f64; 20], xi: [f64; 3]) -> f64 {
    let l = bary(xi);
    let mut s = 0.0;
    for (k, a) in BEZIER_INDEX.iter().enumerate() {
        let mut t = b[k]
            * if k < 4 {
                1.0
            } else if k < 16 {
                3.0
            } else {
                6.0
            };
        for (li, ai) in l.iter().zip(a.iter()) {
            for _ in 0..*ai {
                t *= li;
            }
        }
        s += t;
    }
    s
}

/// The verdict on the sign of det J over a whole element.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Certificate {
    /// det J > 0 everywhere, proved: `min_lower` > 0 is a certified lower bound on min det J.
    Valid {
        /// Certified lower bound on min det J.
        min_lower: f64,
    },
    /// det J is <= 0 somewhere: at reference point `point` (xi, eta, zeta),
    /// [`tet10_det_jacobian`] gives `value` <= 0.
    Invalid {
        /// Reference coordinates of the witness point.
        point: [f64; 3],
        /// det J there (<= 0).
        value: f64,
    },
    /// Neither could be shown within the work limits: min det J is within rounding of 0,
    /// or the input is not finite. Callers must treat it as invalid.
    Undecided {
        /// Best certified lower bound found (<= 0, or NaN for non-finite input).
        min_lower: f64,
    },
}

impl Certificate {
    /// True only for a proved-valid element.
    #[inline]
    pub fn is_valid(&self) -> bool {
        matches!(self, Certificate::Valid { .. })
    }
}

/// Certified bounds on the extrema of det J over an element.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JacobianBounds {
    /// Certified lower bound on min det J.
    pub min_lower: f64,
    /// An actual value of det J (so >= min det J), the smallest one seen.
    pub min_upper: f64,
    /// Reference point where `min_upper` was found.
    pub min_point: [f64; 3],
    /// An actual value of det J (so <= max det J), the largest one seen.
    pub max_lower: f64,
    /// Certified upper bound on max det J.
    pub max_upper: f64,
    /// How many sub-tets were evaluated (0 when the element's own coefficients sufficed).
    pub subdomains: u32,
    /// True when the work limits stopped the refinement before the tolerance was met
    /// (the bounds are still valid, only looser).
    pub exhausted: bool,
}

impl JacobianBounds {
    /// Certified lower bound on the scaled Jacobian min J / max J: min_lower / max_upper
    /// when min_lower > 0; a non-positive bound min_lower / max_lower when not. By
    /// convention -1 when no positive value of det J was seen (a fully inverted element)
    /// and NaN for non-finite input.
    pub fn scaled_lower(&self) -> f64 {
        if self.min_lower.is_nan() || self.max_upper.is_nan() || self.max_lower.is_nan() {
            return f64::NAN;
        }
        if self.min_lower > 0.0 {
            self.min_lower / self.max_upper
        } else if self.max_lower > 0.0 {
            (self.min_lower / self.max_lower).min(0.0)
        } else if self.min_upper < 0.0 {
            -1.0
        } else {
            0.0
        }
    }

    /// An upper bound on min J / max J from actual values (min_upper / max_lower); with
    /// [`scaled_lower`](Self::scaled_lower) it brackets the true scaled Jacobian of a
    /// valid element.
    pub fn scaled_upper(&self) -> f64 {
        if self.max_lower > 0.0 {
            self.min_upper / self.max_lower
        } else if self.min_upper < 0.0 {
            -1.0
        } else {
            0.0
        }
    }
}

/// Can moving the free mid nodes (`free_mid[k]` for edge `TET10_EDGES[k]`; corners fixed)
/// possibly make a tet valid whose det J has the Bernstein coefficients `b` (rounding
/// margin `tau`, see [`LinearJacobian::rounding_margin`])? False when a coefficient that
/// none of them affects is not above `tau`: the column coefficients at corner j depend
/// only on the mid nodes of the edges at j, so a coefficient whose multi-index touches
/// only corners with every incident edge fixed keeps its value whatever the free nodes do
/// (a corner coefficient is det J at that corner). A necessary condition; the linear
/// optimization stage asks it of the P2-invalid tets it would create.
pub fn fixed_coefficients_positive(b: &[f64; 20], tau: f64, free_mid: [bool; 6]) -> bool {
    let mut corner_fixed = [true; 4];
    for (k, [e0, e1]) in TET10_EDGES.iter().enumerate() {
        if free_mid[k] {
            corner_fixed[*e0] = false;
            corner_fixed[*e1] = false;
        }
    }
    BEZIER_INDEX.iter().zip(b.iter()).all(|(a, &v)| {
        let fixed = (0..4).all(|j| a[j] == 0 || corner_fixed[j]);
        !fixed || v > tau
    })
}

/// How far det J of a straight-sided 10-node tet ([`is_straight`]) can be from its corner
/// determinant, computed in f64: each mid node is its edge's midpoint rounded to f64
/// (at most u·M off per coordinate, M the largest corner coordinate, u = 2^-53), which
/// moves the Jacobian's columns by at most 8u·M per component anywhere in the element,
/// and the determinant's own rounding. With C_d = |x_d − x_0|: the same form as
/// [`LinearJacobian::rounding_margin`], with M for the extent,
/// 128u·M·(C_1C_2 + C_1C_3 + C_2C_3) + 32u·C_1C_2C_3, several times the bound.
fn straight_margin(x: &[P3; 10]) -> f64 {
    let u = f64::EPSILON * 0.5;
    let m = x[..4]
        .iter()
        .flat_map(|p| p.iter())
        .fold(0.0f64, |a, &v| a.max(v.abs()));
    let c = [1, 2, 3].map(|d| norm(sub(x[d], x[0])));
    32.0 * u * c[0] * c[1] * c[2] + 128.0 * u * m * (c[0] * c[1] + c[0] * c[2] + c[1] * c[2])
}

/// The corner determinant of a straight-sided tet and its [`straight_margin`], when the
/// determinant is farther than that from 0 (or not finite): det J is then that constant
/// to within the margin. None for a curved tet or a nearly flat straight one.
fn straight_decided(x: &[P3; 10]) -> Option<(f64, f64)> {
    if !is_straight(x) {
        return None;
    }
    let d = tet_det(x[0], x[1], x[2], x[3]);
    let margin = straight_margin(x);
    (d.abs() > margin || !d.is_finite()).then_some((d, margin))
}

/// Proves or disproves det J > 0 on the whole element: one set of Bernstein coefficients
/// decides almost every element; inconclusive ones (some coefficient <= 0 while the
/// sampled values are positive) are resolved by adaptive red refinement, up to
/// [`MAX_DEPTH`] levels and [`MAX_SUBDOMAINS`] sub-tets. Allocation-free.
pub fn certify(x: &[P3; 10]) -> Certificate {
    if is_straight(x) {
        // det J is the corner determinant up to the rounding of the mid nodes to the
        // nearest f64 of their edges' midpoints (`straight_margin`): above that it is
        // certified here; a positive tet below it (nearly flat) goes through the
        // Bernstein coefficients of its actual nodes, like a curved one.
        let d = tet_det(x[0], x[1], x[2], x[3]);
        if orient3d(x[0], x[1], x[2], x[3]) <= 0 {
            let p = [0.25; 3];
            let v = tet10_det_jacobian(x, p);
            if v <= 0.0 {
                return Certificate::Invalid { point: p, value: v };
            }
            return Certificate::Undecided {
                min_lower: if d.is_nan() { d } else { d.min(0.0) },
            };
        }
        let margin = straight_margin(x);
        if d > margin {
            return Certificate::Valid {
                min_lower: d - margin,
            };
        }
    }
    let lj = LinearJacobian::new(x);
    let tau = lj.rounding_margin();
    let b = lj.bezier();
    let mut lo = f64::INFINITY;
    for &v in &b {
        if v.is_nan() {
            return Certificate::Undecided {
                min_lower: f64::NAN,
            };
        }
        lo = lo.min(v);
    }
    if lo > tau && tau.is_finite() {
        return Certificate::Valid {
            min_lower: lo - tau,
        };
    }
    let mut r = Refiner::new(x, &lj, tau, Goal::Sign);
    r.run(b);
    if let Some((point, value)) = r.witness {
        return Certificate::Invalid { point, value };
    }
    let min_lower = r.settled_min - tau;
    if r.exhausted || min_lower.is_nan() || min_lower <= 0.0 {
        Certificate::Undecided {
            min_lower: if min_lower.is_nan() {
                min_lower
            } else {
                min_lower.min(0.0)
            },
        }
    } else {
        Certificate::Valid { min_lower }
    }
}

/// Certified bounds on min and max det J, refined adaptively until the scaled Jacobian
/// they imply is known to relative tolerance `rel_tol` (scaled_lower >= scaled_upper *
/// (1 - rel_tol), roughly), or the work limits are hit (bounds stay valid, just looser).
/// For an element found invalid the refinement stops at once.
pub fn jacobian_bounds(x: &[P3; 10], rel_tol: f64) -> JacobianBounds {
    if let Some((d, margin)) = straight_decided(x) {
        return JacobianBounds {
            min_lower: d - margin,
            min_upper: d,
            min_point: [0.0; 3],
            max_lower: d,
            max_upper: d + margin,
            subdomains: 0,
            exhausted: false,
        };
    }
    let lj = LinearJacobian::new(x);
    let tau = lj.rounding_margin();
    let b = lj.bezier();
    if b.iter().any(|v| v.is_nan()) || tau.is_nan() {
        return JacobianBounds {
            min_lower: f64::NAN,
            min_upper: f64::NAN,
            min_point: [0.0; 3],
            max_lower: f64::NAN,
            max_upper: f64::NAN,
            subdomains: 0,
            exhausted: true,
        };
    }
    let mut r = Refiner::new(x, &lj, tau, Goal::Ratio(rel_tol.max(0.0)));
    r.run(b);
    JacobianBounds {
        min_lower: r.settled_min - tau,
        min_upper: r.m_hi,
        min_point: r.m_hi_point,
        max_lower: r.big_lo,
        max_upper: r.settled_max + tau,
        subdomains: r.evals,
        exhausted: r.exhausted,
    }
}

/// A certified lower bound on the scaled Jacobian min det J / max det J of `x`, tightened
/// by subdivision to relative tolerance `rel_tol` (1e-3 is a good default; smaller costs
/// more). Always <= the true value; <= 0 when the element is (or may be) invalid; exactly
/// 1.0 for a straight-sided tet that is not nearly flat (free fast path; a tet thinner
/// than the rounding of its mid nodes to f64 takes the general path). See
/// [`JacobianBounds::scaled_lower`] for the conventions on inverted elements.
pub fn scaled_jacobian_certified(x: &[P3; 10], rel_tol: f64) -> f64 {
    if straight_decided(x).is_some() {
        return straight_scaled_jacobian(x);
    }
    jacobian_bounds(x, rel_tol).scaled_lower()
}

/// Scaled Jacobian of a straight-sided tet (det J constant): 1, -1 (inverted) or 0 (flat)
/// by the exact sign of the corner determinant; NaN for non-finite corners.
pub(crate) fn straight_scaled_jacobian(x: &[P3; 10]) -> f64 {
    if x[..4].iter().any(|p| p.iter().any(|v| !v.is_finite())) {
        return f64::NAN;
    }
    match orient3d(x[0], x[1], x[2], x[3]) {
        1 => 1.0,
        -1 => -1.0,
        _ => 0.0,
    }
}

// ---------------------------------------------------------------------------------------
// Adaptive refinement.

const ROOT: [[f64; 3]; 4] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
];

/// Bey's red refinement of a tet (v0..v3): 4 corner children and 4 from the inner
/// octahedron split along the diagonal m02-m13. Entries are indices into
/// [v0, v1, v2, v3, m01, m02, m03, m12, m13, m23]. Recursively it produces only three
/// similarity classes of tets (J. Bey, Computing 55, 1995), so bounds keep converging.
const RED_CHILDREN: [[usize; 4]; 8] = [
    [0, 4, 5, 6],
    [4, 1, 7, 8],
    [5, 7, 2, 9],
    [6, 8, 9, 3],
    [4, 5, 6, 8],
    [4, 5, 7, 8],
    [5, 6, 8, 9],
    [5, 7, 8, 9],
];

/// The 8 red-refinement children of the tet with reference vertices `v`.
#[inline]
pub fn red_children(v: &[[f64; 3]; 4]) -> [[[f64; 3]; 4]; 8] {
    let m = |a: usize, b: usize| -> [f64; 3] {
        [
            0.5 * (v[a][0] + v[b][0]),
            0.5 * (v[a][1] + v[b][1]),
            0.5 * (v[a][2] + v[b][2]),
        ]
    };
    let p = [
        v[0],
        v[1],
        v[2],
        v[3],
        m(0, 1),
        m(0, 2),
        m(0, 3),
        m(1, 2),
        m(1, 3),
        m(2, 3),
    ];
    let mut out = [[[0.0; 3]; 4]; 8];
    for (o, c) in out.iter_mut().zip(RED_CHILDREN.iter()) {
        for k in 0..4 {
            o[k] = p[c[k]];
        }
    }
    out
}

#[derive(Clone, Copy)]
enum Goal {
    /// Decide the sign of min det J.
    Sign,
    /// Tighten min/max to this relative tolerance.
    Ratio(f64),
}

#[derive(Clone, Copy)]
struct Leaf {
    v: [[f64; 3]; 4],
    min: f64,
    max: f64,
    depth: u8,
}

const EMPTY_LEAF: Leaf = Leaf {
    v: [[0.0; 3]; 4],
    min: 0.0,
    max: 0.0,
    depth: 0,
};

/// Per-pass thresholds of the settling test (see [`Refiner::need`]).
#[derive(Clone, Copy)]
struct Thresholds {
    min_at: f64,
    min_inv: f64,
    max_at: f64,
    max_inv: f64,
}

/// Best-first adaptive refinement: keeps a set of unsettled sub-tets, repeatedly splits
/// the one whose bounds are furthest from good enough, and folds settled sub-tets into
/// running bounds. The leaf storage lives on the stack of [`Refiner::run`] and is only
/// created when the root is not already settled.
struct Refiner<'a> {
    x: &'a [P3; 10],
    lj: &'a LinearJacobian,
    tau: f64,
    goal: Goal,
    /// Smallest actual det J value seen, and where.
    m_hi: f64,
    m_hi_point: [f64; 3],
    /// Largest actual det J value seen.
    big_lo: f64,
    /// min / max coefficient over settled leaves (all leaves once `run` returns).
    settled_min: f64,
    settled_max: f64,
    evals: u32,
    exhausted: bool,
    witness: Option<([f64; 3], f64)>,
}

impl<'a> Refiner<'a> {
    fn new(x: &'a [P3; 10], lj: &'a LinearJacobian, tau: f64, goal: Goal) -> Self {
        Refiner {
            x,
            lj,
            tau,
            goal,
            m_hi: f64::INFINITY,
            m_hi_point: [0.0; 3],
            big_lo: f64::NEG_INFINITY,
            settled_min: f64::INFINITY,
            settled_max: f64::NEG_INFINITY,
            evals: 0,
            exhausted: false,
            witness: None,
        }
    }

    /// Records an actual value of det J at reference point p.
    #[inline]
    fn saw(&mut self, p: [f64; 3], v: f64) {
        if v < self.m_hi {
            self.m_hi = v;
            self.m_hi_point = p;
        }
        if v > self.big_lo {
            self.big_lo = v;
        }
        if v <= 0.0 && self.witness.is_none() && matches!(self.goal, Goal::Sign) {
            // Confirm with the reference evaluation, so the witness is independent of
            // this module's arithmetic.
            let w = tet10_det_jacobian(self.x, p);
            if w <= 0.0 {
                self.witness = Some((p, w));
            }
        }
    }

    /// Builds a leaf from its coefficients, recording the actual values it exposes: the
    /// corner coefficients and det J at the control points of the extreme coefficients
    /// (within O(h^2) of them, which is what makes the stopping test converge).
    fn leaf(&mut self, v: [[f64; 3]; 4], b: &[f64; 20], depth: u8) -> Leaf {
        let (mut kmin, mut kmax) = (0, 0);
        for k in 1..20 {
            if b[k] < b[kmin] {
                kmin = k;
            }
            if b[k] > b[kmax] {
                kmax = k;
            }
        }
        for (k, vk) in v.iter().enumerate() {
            self.saw(*vk, b[k]);
        }
        for k in [kmin, kmax] {
            if k >= 4 {
                let a = BEZIER_INDEX[k];
                let mut p = [0.0; 3];
                for (vi, ai) in v.iter().zip(a.iter()) {
                    let s = f64::from(*ai) / 3.0;
                    for d in 0..3 {
                        p[d] += s * vi[d];
                    }
                }
                let val = self.lj.det(p);
                self.saw(p, val);
            }
        }
        Leaf {
            v,
            min: b[kmin],
            max: b[kmax],
            depth,
        }
    }

    fn thresholds(&self) -> Thresholds {
        match self.goal {
            Goal::Sign => Thresholds {
                min_at: self.tau,
                min_inv: 1.0,
                max_at: f64::INFINITY,
                max_inv: 0.0,
            },
            Goal::Ratio(tol) => {
                // Settled when min >= m_hi (1 - tol/2) and max <= big_lo (1 + tol/2):
                // then the ratio of the bounds is within ~tol of the ratio of values.
                let t = 0.5 * tol;
                let sm = self.m_hi.abs().max(self.tau);
                let sb = self.big_lo.abs().max(self.tau);
                Thresholds {
                    min_at: self.m_hi - t * sm,
                    min_inv: 1.0 / sm,
                    max_at: self.big_lo + t * sb,
                    max_inv: 1.0 / sb,
                }
            }
        }
    }

    /// How far (relative) this leaf is from settled (> 0), or None when it is settled.
    #[inline]
    fn need(th: &Thresholds, l: &Leaf) -> Option<f64> {
        let g = ((th.min_at - l.min) * th.min_inv).max((l.max - th.max_at) * th.max_inv);
        if g > 0.0 {
            Some(g)
        } else if g.is_nan() && (l.min.is_nan() || l.max.is_nan()) {
            Some(f64::INFINITY)
        } else {
            None
        }
    }

    fn done(&self) -> bool {
        match self.goal {
            Goal::Sign => self.witness.is_some(),
            // An element with a non-positive value is invalid; its scaled Jacobian is
            // not worth tightening.
            Goal::Ratio(_) => self.m_hi.is_nan() || self.m_hi <= 0.0,
        }
    }

    #[inline]
    fn settle(&mut self, l: &Leaf) {
        self.settled_min = self.settled_min.min(l.min);
        self.settled_max = self.settled_max.max(l.max);
    }

    /// Refines until every leaf is settled, an answer is found, or the work limits are
    /// hit; afterwards `settled_min` / `settled_max` bound det J over the whole element.
    fn run(&mut self, root_coeffs: [f64; 20]) {
        let root = self.leaf(ROOT, &root_coeffs, 0);
        if self.done() || Self::need(&self.thresholds(), &root).is_none() {
            self.settle(&root);
            return;
        }
        let mut active = [EMPTY_LEAF; MAX_ACTIVE];
        active[0] = root;
        let mut n = 1;
        while !self.done() {
            // Settle what needs no more work; pick the neediest of the rest.
            let th = self.thresholds();
            let mut best: Option<(usize, f64)> = None;
            let mut i = 0;
            while i < n {
                let l = active[i];
                let g = match Self::need(&th, &l) {
                    Some(g) if l.depth < MAX_DEPTH => g,
                    other => {
                        // Settled, or cannot be refined (keep its valid, loose bounds).
                        self.exhausted |= other.is_some();
                        self.settle(&l);
                        n -= 1;
                        active[i] = active[n];
                        continue;
                    }
                };
                let better = match best {
                    None => true,
                    Some((_, bg)) => g > bg,
                };
                if better {
                    best = Some((i, g));
                }
                i += 1;
            }
            let Some((i, _)) = best else {
                break;
            };
            if n + 7 > MAX_ACTIVE || self.evals + 8 > MAX_SUBDOMAINS {
                self.exhausted = true;
                break;
            }
            let parent = active[i];
            for (c, kv) in red_children(&parent.v).iter().enumerate() {
                let b = self.lj.bezier_on(kv);
                self.evals += 1;
                let leaf = self.leaf(*kv, &b, parent.depth + 1);
                if c == 0 {
                    active[i] = leaf;
                } else {
                    active[n] = leaf;
                    n += 1;
                }
            }
        }
        for l in &active[..n] {
            self.settle(l);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::shape::{straight_tet10, tet10_det_jacobian};
    use super::super::testutil::{lattice, random_curved, random_ref_point};
    use super::*;
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};

    #[test]
    fn fixed_coefficients_decide_what_free_mid_nodes_cannot_fix() {
        let unit = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ];
        let fixed_ok = |x: &[P3; 10], free: [bool; 6]| {
            let lj = LinearJacobian::new(x);
            fixed_coefficients_positive(&lj.bezier(), lj.rounding_margin(), free)
        };
        let mut x = straight_tet10(unit);
        assert!(fixed_ok(&x, [false; 6]));
        // Mid node of edge 0-1 pulled back past corner 0: det J < 0 at corner 0.
        x[4] = [-0.5, 0.0, 0.0];
        assert!(!certify(&x).is_valid());
        assert!(jacobian_bezier(&x)[0] < 0.0);
        // Nothing free, or only edges away from corners 0 and 1 free: unfixable.
        assert!(!fixed_ok(&x, [false; 6]));
        assert!(!fixed_ok(&x, [false, false, false, false, true, false]));
        // Edge 0-1's own mid node free: every coefficient left fixed is positive.
        let mut free = [false; 6];
        free[0] = true;
        assert!(fixed_ok(&x, free));
        // Which is right: putting that mid node back makes the tet valid.
        x[4] = [0.5, 0.0, 0.0];
        assert!(certify(&x).is_valid());
    }

    #[test]
    fn bezier_index_table_is_consistent() {
        // Every multi-index of degree 3 exactly once; each ordered triple maps to its slot.
        let mut seen = [false; 20];
        for (s, a) in BEZIER_INDEX.iter().enumerate() {
            assert_eq!(a.iter().map(|v| *v as u32).sum::<u32>(), 3);
            for (t, b) in BEZIER_INDEX.iter().enumerate() {
                if t != s {
                    assert_ne!(a, b);
                }
            }
            seen[s] = true;
        }
        assert!(seen.iter().all(|s| *s));
        let mut counts = [0usize; 20];
        for t in TRIPLE_SLOT.iter() {
            counts[*t as usize] += 1;
        }
        for (s, c) in counts.iter().enumerate() {
            assert_eq!(*c as f64 * SLOT_WEIGHT[s], 1.0, "slot {s}");
        }
        // Edge slots follow TET10_EDGES: slot 4 + 2k has 2 at the edge's first corner.
        for (k, [a, b]) in TET10_EDGES.iter().enumerate() {
            assert_eq!(BEZIER_INDEX[4 + 2 * k][*a], 2);
            assert_eq!(BEZIER_INDEX[4 + 2 * k][*b], 1);
            assert_eq!(BEZIER_INDEX[5 + 2 * k][*a], 1);
            assert_eq!(BEZIER_INDEX[5 + 2 * k][*b], 2);
        }
    }

    /// A straight-sided tet one ulp thick, far from the origin: its mid nodes are its
    /// edges' midpoints rounded to f64, half its thickness off, so the P2 element those
    /// ten nodes define is inverted in places although its corner determinant is
    /// positive. Certification must not call it valid.
    #[test]
    fn a_straight_tet_thinner_than_its_mid_node_rounding_is_not_certified() {
        let x0: f64 = 1.0e6;
        let up = f64::from_bits(x0.to_bits() + 1);
        let x = straight_tet10([
            [x0, 0.0, 0.0],
            [x0, 1.0, 0.0],
            [x0, 0.0, 1.0],
            [up, 0.3, 0.3],
        ]);
        assert!(is_straight(&x));
        let corner = tet_det(x[0], x[1], x[2], x[3]);
        let x = if corner > 0.0 {
            x
        } else {
            straight_tet10([x[0], x[2], x[1], x[3]])
        };
        assert!(orient3d(x[0], x[1], x[2], x[3]) > 0);
        let mut rng = StdRng::seed_from_u64(3);
        let negative = (0..2000).any(|_| {
            let mut l: [f64; 4] = std::array::from_fn(|_| rng.random::<f64>());
            let s: f64 = l.iter().sum();
            l.iter_mut().for_each(|v| *v /= s);
            tet10_det_jacobian(&x, [l[1], l[2], l[3]]) < 0.0
        });
        assert!(negative, "the rounded mid nodes invert no sampled point");
        assert!(!certify(&x).is_valid(), "{:?}", certify(&x));
        assert!(scaled_jacobian_certified(&x, 1e-3) <= 0.0);
    }

    #[test]
    fn expanded_coefficients_match_the_table() {
        let mut rng = StdRng::seed_from_u64(8);
        for _ in 0..50 {
            let lj = LinearJacobian::new(&random_curved(&mut rng, 0.5));
            let a = coeffs_from_columns(&lj.cols);
            let b = coeffs_by_table(&lj.cols);
            for (u, v) in a.iter().zip(b.iter()) {
                assert!((u - v).abs() <= 1e-14 * u.abs().max(1.0), "{u} vs {v}");
            }
        }
    }

    #[test]
    fn straight_tet_coefficients_are_six_volumes() {
        let c = [
            [0.1, 0.2, 0.3],
            [1.3, 0.1, 0.2],
            [0.2, 1.1, 0.1],
            [0.3, 0.4, 0.9],
        ];
        let x = straight_tet10(c);
        let d = tet_det(c[0], c[1], c[2], c[3]);
        assert!(is_straight(&x));
        assert_eq!(jacobian_bezier(&x), [d; 20]);
        assert_eq!(scaled_jacobian_certified(&x, 1e-3), 1.0);
        assert_eq!(
            certify(&x),
            Certificate::Valid {
                min_lower: d - straight_margin(&x)
            }
        );
        // The general path (no fast path) agrees to rounding.
        let b = LinearJacobian::new(&x).bezier();
        for v in b {
            assert!((v - d).abs() < 1e-14 * d.abs(), "{v} vs {d}");
        }
        // Inverted straight tet.
        let xi = straight_tet10([c[1], c[0], c[2], c[3]]);
        assert_eq!(scaled_jacobian_certified(&xi, 1e-3), -1.0);
        match certify(&xi) {
            Certificate::Invalid { point, value } => {
                assert!(value < 0.0);
                assert!(tet10_det_jacobian(&xi, point) <= 0.0);
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn bernstein_form_matches_direct_evaluation() {
        let mut rng = StdRng::seed_from_u64(7);
        for _ in 0..200 {
            let x = random_curved(&mut rng, 0.5);
            let b = jacobian_bezier(&x);
            let lj = LinearJacobian::new(&x);
            let scale = b.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            for _ in 0..20 {
                let xi = random_ref_point(&mut rng);
                let direct = tet10_det_jacobian(&x, xi);
                let bez = bezier_eval(&b, xi);
                let lin = lj.det(xi);
                assert!(
                    (direct - bez).abs() <= 1e-12 * scale,
                    "direct {direct} bezier {bez} scale {scale}"
                );
                assert!((direct - lin).abs() <= 1e-12 * scale);
            }
            // Corner coefficients are the corner values.
            for (k, p) in ROOT.iter().enumerate() {
                assert!((b[k] - tet10_det_jacobian(&x, *p)).abs() <= 1e-13 * scale);
            }
        }
    }

    #[test]
    fn red_children_tile_the_parent() {
        let kids = red_children(&ROOT);
        let vol = |v: &[[f64; 3]; 4]| tet_det(v[0], v[1], v[2], v[3]);
        let total: f64 = kids.iter().map(|k| vol(k).abs()).sum();
        assert!((total - 1.0).abs() < 1e-15);
        for k in &kids {
            assert!((vol(k).abs() - 0.125).abs() < 1e-15);
        }
        // Random points lie in at least one child; interior points in exactly one.
        let mut rng = StdRng::seed_from_u64(3);
        for _ in 0..2000 {
            let p: [f64; 3] = [rng.random(), rng.random(), rng.random()];
            if p[0] + p[1] + p[2] > 1.0 {
                continue;
            }
            let mut inside = 0;
            for k in &kids {
                // Barycentric coordinates of p in k.
                let d = vol(k);
                let l = [
                    tet_det(p, k[1], k[2], k[3]) / d,
                    tet_det(k[0], p, k[2], k[3]) / d,
                    tet_det(k[0], k[1], p, k[3]) / d,
                    tet_det(k[0], k[1], k[2], p) / d,
                ];
                if l.iter().all(|v| *v > -1e-12) {
                    inside += 1;
                }
            }
            assert!(inside >= 1);
        }
    }

    #[test]
    fn sub_tet_coefficients_match_restriction() {
        // Coefficients on a child, evaluated at a child-barycentric point, equal det J at
        // the corresponding parent point.
        let mut rng = StdRng::seed_from_u64(11);
        let x = random_curved(&mut rng, 0.4);
        let lj = LinearJacobian::new(&x);
        for kid in red_children(&ROOT).iter() {
            for g in red_children(kid).iter() {
                let b = lj.bezier_on(g);
                for _ in 0..10 {
                    let mu: [f64; 3] = [
                        rng.random::<f64>() / 3.0,
                        rng.random::<f64>() / 3.0,
                        rng.random::<f64>() / 3.0,
                    ];
                    let l = bary(mu);
                    let mut p = [0.0; 3];
                    for k in 0..4 {
                        for d in 0..3 {
                            p[d] += l[k] * g[k][d];
                        }
                    }
                    let want = tet10_det_jacobian(&x, p);
                    let got = bezier_eval(&b, mu);
                    assert!((want - got).abs() < 1e-12 * want.abs().max(1.0));
                }
            }
        }
    }

    /// The main claim: on ~1000 random curved tets the certified bounds enclose dense
    /// samples, and certify never lies.
    #[test]
    fn certified_bounds_enclose_dense_samples() {
        let mut rng = StdRng::seed_from_u64(2024);
        let pts = lattice(10);
        let (mut n_valid, mut n_invalid, mut n_undecided, mut n_refined) = (0, 0, 0, 0);
        for it in 0..1000 {
            // Amplitudes from gentle to tangled.
            let amp = [0.05, 0.2, 0.4, 0.7, 1.0][it % 5];
            let x = random_curved(&mut rng, amp);
            let b = jacobian_bezier(&x);
            let (mut smin, mut smax) = (f64::INFINITY, f64::NEG_INFINITY);
            for p in &pts {
                let v = tet10_det_jacobian(&x, *p);
                smin = smin.min(v);
                smax = smax.max(v);
            }
            let cmin = b.iter().cloned().fold(f64::INFINITY, f64::min);
            let cmax = b.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
            let slack = 1e-12 * smax.abs().max(smin.abs());
            assert!(
                cmin <= smin + slack,
                "coefficient min {cmin} > sample {smin}"
            );
            assert!(
                cmax >= smax - slack,
                "coefficient max {cmax} < sample {smax}"
            );

            let jb = jacobian_bounds(&x, 1e-3);
            assert!(
                jb.min_lower <= smin,
                "{it}: min_lower {} > {smin}",
                jb.min_lower
            );
            assert!(
                jb.max_upper >= smax,
                "{it}: max_upper {} < {smax}",
                jb.max_upper
            );
            assert!(jb.min_lower >= cmin - slack - 1e-9);
            if jb.subdomains > 0 {
                n_refined += 1;
            }
            let sj = jb.scaled_lower();
            if smin > 0.0 {
                assert!(sj <= smin / smax + 1e-12, "{it}: sj {sj} > {}", smin / smax);
                if sj > 0.0 && jb.min_upper > 0.0 {
                    // Tightened to the tolerance (unless the work limit stopped it).
                    let up = jb.scaled_upper();
                    assert!(sj >= up * (1.0 - 2e-3) || jb.subdomains >= MAX_SUBDOMAINS - 8);
                }
            } else {
                assert!(sj <= 0.0);
            }

            match certify(&x) {
                Certificate::Valid { min_lower } => {
                    n_valid += 1;
                    assert!(smin > 0.0, "{it}: certified valid but sample {smin} <= 0");
                    assert!(min_lower > 0.0 && min_lower <= smin);
                }
                Certificate::Invalid { point, value } => {
                    n_invalid += 1;
                    assert!(value <= 0.0);
                    assert!(point.iter().all(|v| *v >= 0.0) && point.iter().sum::<f64>() <= 1.0);
                    assert_eq!(tet10_det_jacobian(&x, point), value);
                }
                Certificate::Undecided { .. } => n_undecided += 1,
            }
        }
        // Observed (seed 2024): 571 valid, 429 invalid, 0 undecided; 190 needed
        // subdivision to reach the 1e-3 tolerance.
        assert!(n_valid > 200 && n_invalid > 100, "{n_valid} {n_invalid}");
        assert!(n_undecided <= 2, "undecided {n_undecided}");
        assert!(n_refined > 100);
    }

    #[test]
    fn inconclusive_coefficients_are_resolved_by_subdivision() {
        // Find curved tets whose root coefficients include a non-positive one while the
        // element is valid: certify must still say Valid (after subdividing).
        let mut rng = StdRng::seed_from_u64(99);
        let pts = lattice(12);
        let mut resolved = 0;
        for _ in 0..5000 {
            let x = random_curved(&mut rng, 0.6);
            let b = jacobian_bezier(&x);
            if b.iter().all(|v| *v > 0.0) {
                continue;
            }
            let smin = pts
                .iter()
                .map(|p| tet10_det_jacobian(&x, *p))
                .fold(f64::INFINITY, f64::min);
            if smin > 0.05 {
                assert!(certify(&x).is_valid(), "{x:?}");
                resolved += 1;
            }
        }
        // Observed (seed 99): 288 such cases, all certified valid.
        assert!(resolved >= 10, "only {resolved} inconclusive cases found");
    }

    #[test]
    fn interior_negative_region_is_found() {
        // Corners positive, but a mid node pushed through the opposite face: det J < 0
        // inside; the witness must be real.
        let mut x = straight_tet10(ROOT);
        x[4] = [0.5, 0.9, 0.9]; // mid node of edge (0,1) dragged far away
        let b = jacobian_bezier(&x);
        match certify(&x) {
            Certificate::Invalid { point, value } => {
                assert!(value <= 0.0 && tet10_det_jacobian(&x, point) <= 0.0);
            }
            other => panic!("expected invalid, got {other:?} (coeffs {b:?})"),
        }
        assert!(scaled_jacobian_certified(&x, 1e-3) <= 0.0);
    }

    #[test]
    fn straight_tets_use_the_exact_sign() {
        // Corners rounded onto a tilted plane: the float determinant's sign is noise,
        // the exact predicate's is not. Whatever either sign, det J is below the rounding
        // of the mid nodes ([`straight_margin`]): never certified, and a certified scaled
        // Jacobian of at most 0; found invalid only with a witness point.
        let mut rng = StdRng::seed_from_u64(12);
        let (a, u, v) = ([0.1, 0.2, 0.3], [0.7, 0.3, 0.11], [0.2, 0.9, 0.37]);
        let on_plane = |s: f64, t: f64| -> P3 {
            [
                a[0] + s * u[0] + t * v[0],
                a[1] + s * u[1] + t * v[1],
                a[2] + s * u[2] + t * v[2],
            ]
        };
        let mut disagreements = 0;
        for _ in 0..2000 {
            let mut c = [[0.0; 3]; 4];
            for p in c.iter_mut() {
                *p = on_plane(rng.random(), rng.random());
            }
            let x = straight_tet10(c);
            let o = orient3d(c[0], c[1], c[2], c[3]);
            let d = tet_det(c[0], c[1], c[2], c[3]);
            if (o > 0) != (d > 0.0) {
                disagreements += 1;
            }
            assert!(scaled_jacobian_certified(&x, 1e-3) <= 0.0);
            match certify(&x) {
                Certificate::Valid { .. } => panic!("{c:?} certified"),
                // The witness is a point where the ten nodes' det J is not positive.
                Certificate::Invalid { point, value } => {
                    assert!(value <= 0.0 && tet10_det_jacobian(&x, point) <= 0.0)
                }
                Certificate::Undecided { .. } => {}
            }
        }
        // Observed (seed 12): the float sign disagrees with the exact one in 167 of 2000.
        assert!(disagreements > 10, "{disagreements}");
        let c = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.25, 0.25, 0.0],
        ];
        let flat = straight_tet10(c);
        assert_eq!(scaled_jacobian_certified(&flat, 1e-3), 0.0);
        assert!(matches!(certify(&flat), Certificate::Invalid { .. }));
    }

    #[test]
    fn nan_and_degenerate_input_do_not_hang() {
        let mut x = straight_tet10(ROOT);
        x[5][1] = f64::NAN;
        assert!(matches!(certify(&x), Certificate::Undecided { .. }));
        assert!(scaled_jacobian_certified(&x, 1e-3).is_nan());
        let y = [[1.0; 3]; 10];
        assert!(!certify(&y).is_valid());
        assert_eq!(scaled_jacobian_certified(&y, 1e-3), 0.0);
        let mut z = straight_tet10(ROOT);
        z[6] = [f64::INFINITY, 0.0, 0.0];
        assert!(!certify(&z).is_valid());
        let _ = scaled_jacobian_certified(&z, 1e-3);
        // A flat curved tet (all nodes in a plane): det J == 0 everywhere.
        let mut f = straight_tet10([
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
        ]);
        f[4][0] += 0.1;
        assert!(!certify(&f).is_valid());
        assert!(scaled_jacobian_certified(&f, 1e-3) <= 0.0);
        // Zero tolerance terminates (work limits).
        let mut rng = StdRng::seed_from_u64(5);
        let x = random_curved(&mut rng, 0.3);
        let jb = jacobian_bounds(&x, 0.0);
        assert!(jb.subdomains <= MAX_SUBDOMAINS);
    }

    #[test]
    fn far_from_origin_is_as_accurate() {
        // Nodes on a 2^-20 grid, translated by 2^20: the translation is exact, so the
        // far element is the same polynomial, and samples taken near the origin are an
        // accurate reference for it.
        let mut rng = StdRng::seed_from_u64(17);
        let pts = lattice(8);
        let q = (2.0f64).powi(-20);
        let shift = [2f64.powi(20), -(2f64.powi(20)), 3.0 * 2f64.powi(19)];
        for _ in 0..300 {
            let mut x = random_curved(&mut rng, 0.3);
            for p in x.iter_mut() {
                for v in p.iter_mut() {
                    *v = (*v / q).round() * q;
                }
            }
            let mut y = x;
            for (p, px) in y.iter_mut().zip(x.iter()) {
                for d in 0..3 {
                    p[d] += shift[d];
                    assert_eq!(p[d] - shift[d], px[d], "translation must be exact");
                }
            }
            let bx = jacobian_bezier(&x);
            let by = jacobian_bezier(&y);
            let scale = bx.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            for (a, b) in bx.iter().zip(by.iter()) {
                assert!((a - b).abs() < 1e-13 * scale, "{a} {b}");
            }
            let (mut smin, mut smax) = (f64::INFINITY, f64::NEG_INFINITY);
            for p in &pts {
                let v = tet10_det_jacobian(&x, *p);
                smin = smin.min(v);
                smax = smax.max(v);
            }
            let jb = jacobian_bounds(&y, 1e-3);
            assert!(jb.min_lower <= smin && jb.max_upper >= smax);
            if let Certificate::Valid { min_lower } = certify(&y) {
                assert!(smin > 0.0 && min_lower <= smin);
            }
        }
    }
}
