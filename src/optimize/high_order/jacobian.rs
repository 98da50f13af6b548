//! The 20 cubic Bernstein coefficients of det J of a 10-node tet (the same numbers as
//! [`crate::geom::bezier::jacobian_bezier`]) and the reverse-mode derivative of any
//! function of them with respect to the ten node positions.
//!
//! The Jacobian columns are linear in barycentric coordinates, `c_d(l) = Σ_j c_d[j] l_j`,
//! each `c_d[j]` a fixed integer combination of node positions ([`COLS`]); coefficient
//! `s` is the weighted sum of `det[c_0[i], c_1[j], c_2[k]]` over the ordered triples
//! with multiset `s`. So `∂b_s/∂c_0[i] = w_s Σ c_1[j] × c_2[k]` and cyclically, and the
//! node gradient follows from [`COLS`].

// Index loops mirror the formulas (several arrays per index).
#![allow(clippy::needless_range_loop)]

use crate::geom::bezier::{SLOT_WEIGHT, TRIPLE_SLOT};
use crate::geom::vec3::{sub, P3};
use std::ops::{Add, AddAssign, Mul, Sub};

/// Column coefficient `c_d[j]` as (node, integer weight) terms, Gmsh node order (corners
/// 0..3, mids of (0,1), (1,2), (2,0), (3,0), (3,2), (3,1)); unused terms have weight 0.
/// The reference for the written-out [`columns`] and [`UPD`] (checked by the tests).
#[cfg_attr(not(test), allow(dead_code))]
const COLS: [[[(usize, f64); 4]; 4]; 3] = [
    [
        [(4, 4.0), (1, -1.0), (0, -3.0), (0, 0.0)],
        [(1, 3.0), (4, -4.0), (0, 1.0), (0, 0.0)],
        [(5, 4.0), (6, -4.0), (1, -1.0), (0, 1.0)],
        [(9, 4.0), (7, -4.0), (1, -1.0), (0, 1.0)],
    ],
    [
        [(6, 4.0), (2, -1.0), (0, -3.0), (0, 0.0)],
        [(5, 4.0), (4, -4.0), (2, -1.0), (0, 1.0)],
        [(2, 3.0), (6, -4.0), (0, 1.0), (0, 0.0)],
        [(8, 4.0), (7, -4.0), (2, -1.0), (0, 1.0)],
    ],
    [
        [(7, 4.0), (3, -1.0), (0, -3.0), (0, 0.0)],
        [(9, 4.0), (4, -4.0), (3, -1.0), (0, 1.0)],
        [(8, 4.0), (6, -4.0), (3, -1.0), (0, 1.0)],
        [(3, 3.0), (7, -4.0), (0, 1.0), (0, 0.0)],
    ],
];

/// The arithmetic the coefficient and gradient code needs: `f64` for one element, and
/// [`super::lanes`]' lane type for several at once, so that the formulas are written once
/// and every lane rounds exactly as the one-element code.
pub(super) trait Lane:
    Copy + Default + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + AddAssign
{
    /// `v` in every lane.
    fn splat(v: f64) -> Self;
}

impl Lane for f64 {
    #[inline(always)]
    fn splat(v: f64) -> f64 {
        v
    }
}

/// A vector of lanes.
pub(super) type V3<T> = [T; 3];

#[inline(always)]
fn cross<T: Lane>(a: V3<T>, b: V3<T>) -> V3<T> {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[inline(always)]
fn dot<T: Lane>(a: V3<T>, b: V3<T>) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The Jacobian columns of one element (what [`backprop`] needs).
pub(crate) struct JacTape {
    c: [[P3; 4]; 3],
}

/// Coefficients of det J of `x` (in [`crate::geom::bezier::BEZIER_INDEX`] order) and the tape for
/// [`backprop`].
#[inline]
pub(crate) fn bezier_forward(x: &[P3; 10]) -> ([f64; 20], JacTape) {
    // Node positions relative to corner 0 (translation invariant, accurate far out).
    let y: [P3; 10] = std::array::from_fn(|i| sub(x[i], x[0]));
    let (b, c) = coefficients(&y);
    (b, JacTape { c })
}

/// Given `gb[s]` = ∂F/∂b_s, add ∂F/∂x_n to `gx[n]` for the ten nodes. The objective
/// runs it on lanes ([`super::lanes`]); this one-element form is its reference in the
/// tests.
#[cfg_attr(not(test), allow(dead_code))]
#[inline]
pub(crate) fn backprop(tape: &JacTape, gb: &[f64; 20], gx: &mut [P3; 10]) {
    let gs: [f64; 20] = std::array::from_fn(|s| gb[s] * SLOT_WEIGHT[s]);
    let upd = node_gradient(&tape.c, &gs);
    for (o, u) in gx.iter_mut().zip(upd.iter()) {
        for k in 0..3 {
            o[k] += u[k];
        }
    }
}

/// The weighted coefficients b_s of det J from node positions `y` relative to corner 0,
/// and the columns `c`.
#[inline(always)]
pub(super) fn coefficients<T: Lane>(y: &[V3<T>; 10]) -> ([T; 20], [[V3<T>; 4]; 3]) {
    let c = columns(y);
    let mut x12 = [[[T::default(); 3]; 4]; 4];
    for j in 0..4 {
        for k in 0..4 {
            x12[j][k] = cross(c[1][j], c[2][k]);
        }
    }
    let mut b = [T::default(); 20];
    for i in 0..4 {
        for j in 0..4 {
            for k in 0..4 {
                b[TRIPLE_SLOT[16 * i + 4 * j + k] as usize] += dot(c[0][i], x12[j][k]);
            }
        }
    }
    for s in 0..20 {
        b[s] = b[s] * T::splat(SLOT_WEIGHT[s]);
    }
    (b, c)
}

/// ∂F/∂x_n for the ten nodes from `gs[s]` = w_s ∂F/∂b_s and the columns `c`.
#[inline(always)]
pub(super) fn node_gradient<T: Lane>(c: &[[V3<T>; 4]; 3], gs: &[T; 20]) -> [V3<T>; 10] {
    // Reverse mode through the forward pass: b_s = w_s Σ c_0[i] · X_jk with
    // X_jk = c_1[j] × c_2[k]. With W_ijk = gs[slot(i, j, k)]:
    // ∂F/∂c_0[i] = Σ_jk W_ijk X_jk, ∂F/∂X_jk = Σ_i W_ijk c_0[i] =: Y_jk, and through the
    // cross product ∂F/∂c_1[j] = Σ_k c_2[k] × Y_jk, ∂F/∂c_2[k] = Σ_j Y_jk × c_1[j]
    // (a third fewer operations than contracting each column's weights separately).
    let mut g = [[[T::default(); 3]; 4]; 3];
    for j in 0..4 {
        for k in 0..4 {
            let x = cross(c[1][j], c[2][k]);
            let mut y = [T::default(); 3];
            for i in 0..4 {
                let wt = gs[TRIPLE_SLOT[16 * i + 4 * j + k] as usize];
                for d in 0..3 {
                    g[0][i][d] += wt * x[d];
                    y[d] += wt * c[0][i][d];
                }
            }
            let a = cross(c[2][k], y);
            let b = cross(y, c[1][j]);
            for d in 0..3 {
                g[1][j][d] += a[d];
                g[2][k][d] += b[d];
            }
        }
    }
    // ∂F/∂x_n = Σ_t UPD[n][t] g[t / 4][t % 4], one call per row so that each unrolls
    // with its zero terms dropped at compile time.
    let lin = |w: [f64; 12]| -> V3<T> {
        let mut o = [T::default(); 3];
        for (t, &wt) in w.iter().enumerate() {
            if wt != 0.0 {
                let gv = g[t / 4][t % 4];
                for k in 0..3 {
                    o[k] += T::splat(wt) * gv[k];
                }
            }
        }
        o
    };
    [
        lin(UPD[0]),
        lin(UPD[1]),
        lin(UPD[2]),
        lin(UPD[3]),
        lin(UPD[4]),
        lin(UPD[5]),
        lin(UPD[6]),
        lin(UPD[7]),
        lin(UPD[8]),
        lin(UPD[9]),
    ]
}

/// ∂F/∂x_n = Σ_t `UPD[n][t] g[t / 4][t % 4]` ([`COLS`] transposed; checked by the tests).
const UPD: [[f64; 12]; 10] = [
    [-3., 1., 1., 1., -3., 1., 1., 1., -3., 1., 1., 1.],
    [-1., 3., -1., -1., 0., 0., 0., 0., 0., 0., 0., 0.],
    [0., 0., 0., 0., -1., -1., 3., -1., 0., 0., 0., 0.],
    [0., 0., 0., 0., 0., 0., 0., 0., -1., -1., -1., 3.],
    [4., -4., 0., 0., 0., -4., 0., 0., 0., -4., 0., 0.],
    [0., 0., 4., 0., 0., 4., 0., 0., 0., 0., 0., 0.],
    [0., 0., -4., 0., 4., 0., -4., 0., 0., 0., -4., 0.],
    [0., 0., 0., -4., 0., 0., 0., -4., 4., 0., 0., -4.],
    [0., 0., 0., 0., 0., 0., 0., 4., 0., 0., 4., 0.],
    [0., 0., 0., 4., 0., 0., 0., 0., 0., 4., 0., 0.],
];

/// The Jacobian columns `c[d][j]` from node positions relative to corner 0 ([`COLS`]
/// written out without its zero terms; `y[0]` = 0).
#[inline(always)]
fn columns<T: Lane>(y: &[V3<T>; 10]) -> [[V3<T>; 4]; 3] {
    let f = |t: &[(usize, f64)]| -> V3<T> {
        let mut v = [T::default(); 3];
        for &(n, w) in t {
            for k in 0..3 {
                v[k] += T::splat(w) * y[n][k];
            }
        }
        v
    };
    [
        [
            f(&[(4, 4.0), (1, -1.0)]),
            f(&[(1, 3.0), (4, -4.0)]),
            f(&[(5, 4.0), (6, -4.0), (1, -1.0)]),
            f(&[(9, 4.0), (7, -4.0), (1, -1.0)]),
        ],
        [
            f(&[(6, 4.0), (2, -1.0)]),
            f(&[(5, 4.0), (4, -4.0), (2, -1.0)]),
            f(&[(2, 3.0), (6, -4.0)]),
            f(&[(8, 4.0), (7, -4.0), (2, -1.0)]),
        ],
        [
            f(&[(7, 4.0), (3, -1.0)]),
            f(&[(9, 4.0), (4, -4.0), (3, -1.0)]),
            f(&[(8, 4.0), (6, -4.0), (3, -1.0)]),
            f(&[(3, 3.0), (7, -4.0)]),
        ],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::bezier::LinearJacobian;

    fn sample() -> [P3; 10] {
        let c = [
            [0.1, 0.0, 0.2],
            [1.0, 0.1, 0.0],
            [0.2, 0.9, 0.1],
            [0.3, 0.2, 0.8],
        ];
        let mut x = crate::geom::shape::straight_tet10(c);
        let bumps = [
            [0.03, -0.02, 0.05],
            [-0.04, 0.01, 0.02],
            [0.02, 0.06, -0.01],
            [0.0, -0.05, 0.03],
            [0.05, 0.01, -0.04],
            [-0.02, 0.03, 0.01],
        ];
        for (k, b) in bumps.iter().enumerate() {
            for d in 0..3 {
                x[4 + k][d] += b[d];
            }
        }
        x
    }

    #[test]
    fn written_out_tables_match_cols() {
        let x = sample();
        let y: [P3; 10] = std::array::from_fn(|i| sub(x[i], x[0]));
        let c = columns(&y);
        for d in 0..3 {
            for j in 0..4 {
                let mut v = [0.0; 3];
                for &(n, w) in &COLS[d][j] {
                    for k in 0..3 {
                        v[k] += w * y[n][k];
                    }
                }
                for k in 0..3 {
                    assert!((v[k] - c[d][j][k]).abs() < 1e-14);
                }
            }
        }
    }

    #[test]
    fn upd_is_cols_transposed() {
        for n in 0..10 {
            for t in 0..12 {
                let w: f64 = COLS[t / 4][t % 4]
                    .iter()
                    .filter(|&&(m, _)| m == n)
                    .map(|&(_, w)| w)
                    .sum();
                assert_eq!(UPD[n][t], w, "node {n}, column {t}");
            }
        }
    }

    #[test]
    fn coefficients_match_geom_bezier() {
        let x = sample();
        let (b, _) = bezier_forward(&x);
        let r = LinearJacobian::new(&x).bezier();
        for s in 0..20 {
            assert!((b[s] - r[s]).abs() < 1e-13, "{s}: {} vs {}", b[s], r[s]);
        }
    }

    #[test]
    fn gradient_matches_finite_differences() {
        let x = sample();
        // F = Σ_s a_s b_s^2 with arbitrary weights.
        let a: [f64; 20] = std::array::from_fn(|s| 0.3 + 0.1 * s as f64);
        let f = |x: &[P3; 10]| -> f64 {
            let (b, _) = bezier_forward(x);
            (0..20).map(|s| a[s] * b[s] * b[s]).sum()
        };
        let (b, tape) = bezier_forward(&x);
        let gb: [f64; 20] = std::array::from_fn(|s| 2.0 * a[s] * b[s]);
        let mut gx = [[0.0; 3]; 10];
        backprop(&tape, &gb, &mut gx);
        for n in 0..10 {
            for d in 0..3 {
                let h = 1e-6;
                let mut xp = x;
                xp[n][d] += h;
                let mut xm = x;
                xm[n][d] -= h;
                let fd = (f(&xp) - f(&xm)) / (2.0 * h);
                assert!(
                    (fd - gx[n][d]).abs() < 1e-7 * (1.0 + fd.abs()),
                    "{n} {d}: {fd} vs {}",
                    gx[n][d]
                );
            }
        }
    }
}
