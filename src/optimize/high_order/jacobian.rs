//! The 20 cubic Bernstein coefficients of det J of a 10-node tet (the same numbers as
//! [`crate::geom::bezier::jacobian_bezier`]) and the reverse-mode derivative of any
//! function of them with respect to the ten node positions.
//!
//! The Jacobian columns are linear in barycentric coordinates, `c_d(l) = Σ_j c_d[j] l_j`,
//! each `c_d[j]` a fixed integer combination of node positions ([`COLS`]); coefficient
//! `s` is the weighted sum of `det[c_0[i], c_1[j], c_2[k]]` over the ordered triples
//! with multiset `s`. So `∂b_s/∂c_0[i] = w_s Σ c_1[j] × c_2[k]` and cyclically, and the
//! node gradient follows from [`COLS`].

use crate::geom::bezier::BEZIER_INDEX;
use crate::geom::vec3::{cross, dot, sub, P3};

/// Column coefficient `c_d[j]` as (node, integer weight) terms, Gmsh node order (corners
/// 0..3, mids of (0,1), (1,2), (2,0), (3,0), (3,2), (3,1)); unused terms have weight 0.
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

/// Coefficient slot of the ordered triple (i, j, k) at index 16 i + 4 j + k.
const SLOT: [u8; 64] = {
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
};

/// 1 / (number of ordered triples of the slot's multiset).
const WEIGHT: [f64; 20] = {
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

/// The Jacobian columns and the cross products the coefficients and their derivatives
/// are made of, for one element.
pub(crate) struct JacTape {
    c: [[P3; 4]; 3],
    x12: [[P3; 4]; 4],
}

/// Coefficients of det J of `x` (in [`BEZIER_INDEX`] order) and the tape for
/// [`backprop`].
#[inline]
pub(crate) fn bezier_forward(x: &[P3; 10]) -> ([f64; 20], JacTape) {
    // Node positions relative to corner 0 (translation invariant, accurate far out).
    let y: [P3; 10] = std::array::from_fn(|i| sub(x[i], x[0]));
    let mut c = [[[0.0; 3]; 4]; 3];
    for d in 0..3 {
        for j in 0..4 {
            let mut v = [0.0; 3];
            for &(n, w) in &COLS[d][j] {
                if w != 0.0 && n != 0 {
                    for k in 0..3 {
                        v[k] += w * y[n][k];
                    }
                }
            }
            c[d][j] = v;
        }
    }
    let mut x12 = [[[0.0; 3]; 4]; 4];
    for j in 0..4 {
        for k in 0..4 {
            x12[j][k] = cross(c[1][j], c[2][k]);
        }
    }
    let mut b = [0.0; 20];
    for i in 0..4 {
        for j in 0..4 {
            for k in 0..4 {
                b[SLOT[16 * i + 4 * j + k] as usize] += dot(c[0][i], x12[j][k]);
            }
        }
    }
    for (v, w) in b.iter_mut().zip(WEIGHT.iter()) {
        *v *= w;
    }
    (b, JacTape { c, x12 })
}

/// Given `gb[s]` = ∂F/∂b_s, add ∂F/∂x_n to `gx[n]` for the ten nodes.
#[inline]
pub(crate) fn backprop(tape: &JacTape, gb: &[f64; 20], gx: &mut [P3; 10]) {
    let c = &tape.c;
    let mut gs = [0.0; 20];
    for s in 0..20 {
        gs[s] = gb[s] * WEIGHT[s];
    }
    let mut x20 = [[[0.0; 3]; 4]; 4]; // c2[k] x c0[i]
    let mut x01 = [[[0.0; 3]; 4]; 4]; // c0[i] x c1[j]
    for a in 0..4 {
        for b in 0..4 {
            x20[a][b] = cross(c[2][a], c[0][b]);
            x01[a][b] = cross(c[0][a], c[1][b]);
        }
    }
    let mut g = [[[0.0; 3]; 4]; 3];
    for i in 0..4 {
        for j in 0..4 {
            for k in 0..4 {
                let w = gs[SLOT[16 * i + 4 * j + k] as usize];
                if w == 0.0 {
                    continue;
                }
                for d in 0..3 {
                    g[0][i][d] += w * tape.x12[j][k][d];
                    g[1][j][d] += w * x20[k][i][d];
                    g[2][k][d] += w * x01[i][j][d];
                }
            }
        }
    }
    for d in 0..3 {
        for j in 0..4 {
            for &(n, w) in &COLS[d][j] {
                if w != 0.0 {
                    for k in 0..3 {
                        gx[n][k] += w * g[d][j][k];
                    }
                }
            }
        }
    }
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
                assert!((fd - gx[n][d]).abs() < 1e-7 * (1.0 + fd.abs()), "{n} {d}: {fd} vs {}", gx[n][d]);
            }
        }
    }
}
