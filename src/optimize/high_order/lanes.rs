//! The objective's per-element work ([`super::objective`]) for [`L`] elements at once,
//! one element per SIMD lane: the Bernstein coefficients of det J, the barrier terms and
//! the reverse-mode gradient, written as lane-wise arithmetic that the compiler turns
//! into vector instructions (AVX2 where the CPU has it, chosen at run time; SSE2
//! otherwise). Every lane performs exactly the operations of the one-element code in the
//! same order (no fused multiply-add), so results are bit-identical to it on any CPU
//! (tested): only the speed depends on the machine.
//!
//! Hand-written rather than taken from a SIMD crate: the ones on stable Rust pick their
//! instruction set at compile time, while a portable binary has to choose at run time.

// Index loops mirror the formulas (several arrays per index).
#![allow(clippy::needless_range_loop)]

use super::objective::ln_and_recip;
use crate::geom::bezier::{SLOT_WEIGHT, TRIPLE_SLOT};
use crate::geom::vec3::P3;
use std::ops::{Add, AddAssign, Mul, Sub};

/// Elements per block.
pub(super) const L: usize = 4;

/// One value per lane.
#[derive(Clone, Copy, Debug, Default)]
struct F([f64; L]);

impl F {
    #[inline(always)]
    fn splat(v: f64) -> F {
        F([v; L])
    }
    #[inline(always)]
    fn map(self, f: impl Fn(f64) -> f64) -> F {
        F(self.0.map(f))
    }
    #[inline(always)]
    fn zip(self, o: F, f: impl Fn(f64, f64) -> f64) -> F {
        let mut r = [0.0; L];
        for l in 0..L {
            r[l] = f(self.0[l], o.0[l]);
        }
        F(r)
    }
}

impl Add for F {
    type Output = F;
    #[inline(always)]
    fn add(self, o: F) -> F {
        self.zip(o, |a, b| a + b)
    }
}
impl Sub for F {
    type Output = F;
    #[inline(always)]
    fn sub(self, o: F) -> F {
        self.zip(o, |a, b| a - b)
    }
}
impl Mul for F {
    type Output = F;
    #[inline(always)]
    fn mul(self, o: F) -> F {
        self.zip(o, |a, b| a * b)
    }
}
impl AddAssign for F {
    #[inline(always)]
    fn add_assign(&mut self, o: F) {
        *self = *self + o;
    }
}

type V3 = [F; 3];

#[inline(always)]
fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[inline(always)]
fn dot(a: V3, b: V3) -> F {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The lane-wise [`ln_and_recip`] (a loop the compiler vectorizes: it is branch-free).
#[inline(always)]
fn ln_and_recip_lanes(x: F) -> (F, F) {
    let mut ln = [0.0; L];
    let mut rc = [0.0; L];
    for l in 0..L {
        (ln[l], rc[l]) = ln_and_recip(x.0[l]);
    }
    (F(ln), F(rc))
}

/// Per-lane results of [`eval_block`].
#[derive(Default)]
pub(super) struct BlockOut {
    /// Barrier sum of each element.
    pub part: [f64; L],
    /// min b / max b of each element (−1 when max b ≤ 0).
    pub ratio: [f64; L],
    /// Whether the element is inside the barrier (else the objective is +∞).
    pub ok: [bool; L],
    /// ∂(part)/∂(node position) of each element, before mid nodes follow corners.
    pub gx: [[P3; 10]; L],
}

/// Barrier terms and node gradients of the elements `x` (lane `l`: nodes `x[l]`,
/// normalization δ `delta[l]`) for barrier `eps` (`lden` = ln(1 − eps)). Picks the
/// widest instruction set the CPU has; the result does not depend on it.
#[inline]
pub(super) fn eval_block(
    x: &[[P3; 10]; L],
    delta: [f64; L],
    eps: f64,
    lden: f64,
    out: &mut BlockOut,
) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2 (checked just above).
            return unsafe { eval_block_avx2(x, delta, eps, lden, out) };
        }
    }
    eval_block_body(x, delta, eps, lden, out)
}

/// [`eval_block_body`] compiled for AVX2 (no FMA: lanes must round as the scalar code).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn eval_block_avx2(
    x: &[[P3; 10]; L],
    delta: [f64; L],
    eps: f64,
    lden: f64,
    out: &mut BlockOut,
) {
    eval_block_body(x, delta, eps, lden, out)
}

/// What [`eval_block`] computes; the operations of `Objective::eval`, `bezier_forward` and
/// `backprop` for one element, in their order, on every lane.
#[inline(always)]
pub(super) fn eval_block_body(
    x: &[[P3; 10]; L],
    delta: [f64; L],
    eps: f64,
    lden: f64,
    out: &mut BlockOut,
) {
    let (b, c) = coefficients(x);
    // Measures, barrier and ∂/∂b.
    let mut bmin = F::splat(f64::INFINITY);
    let mut bmax = F::splat(f64::NEG_INFINITY);
    for s in 0..20 {
        bmin = bmin.zip(b[s], f64::min);
        bmax = bmax.zip(b[s], f64::max);
    }
    let mut sum = F::splat(0.0);
    for s in 0..20 {
        sum += b[s];
    }
    let mean = sum.map(|v| v / 20.0);
    let dl = F(delta);
    let r = (mean * mean + dl * dl).map(f64::sqrt);
    let nrm = (mean + r).map(|v| 0.5 * v);
    let dn = mean.zip(r, |mu, r| 0.5 * (1.0 + if r > 0.0 { mu / r } else { 0.0 }));
    let inv = nrm.map(|v| 1.0 / v);
    let mut m = [F::default(); 20];
    let mut lo = F::splat(f64::INFINITY);
    for s in 0..20 {
        m[s] = b[s] * inv;
        lo = lo.zip(m[s], f64::min);
    }
    for l in 0..L {
        out.ratio[l] = if bmax.0[l] > 0.0 {
            bmin.0[l] / bmax.0[l]
        } else {
            -1.0
        };
        let n = nrm.0[l];
        let lw = lo.0[l];
        out.ok[l] = !(n.is_nan() || n <= 0.0 || lw.is_nan() || lw <= eps);
    }
    let e = F::splat(eps);
    let one = F::splat(1.0);
    let two = F::splat(2.0);
    let mut df = [F::default(); 20];
    let mut dm_sum = F::splat(0.0);
    let mut part = F::splat(0.0);
    for s in 0..20 {
        let (ln_r, inv_r) = ln_and_recip_lanes(m[s] - e);
        let lg = ln_r - F::splat(lden);
        part += (m[s] - one) * (m[s] - one) + lg * lg;
        let d = two * ((m[s] - one) + lg * inv_r);
        df[s] = d;
        dm_sum += d * m[s];
    }
    out.part = part.0;
    let corr = (dm_sum * dn).map(|v| v / 20.0);
    let mut gs = [F::default(); 20];
    for s in 0..20 {
        gs[s] = ((df[s] - corr) * inv) * F::splat(SLOT_WEIGHT[s]);
    }
    // Backprop (the contractions of `jacobian::backprop`).
    let mut g = [[[F::default(); 3]; 4]; 3];
    for i in 0..4 {
        let (mut a0, mut a1, mut a2) = ([F::default(); 3], [F::default(); 3], [F::default(); 3]);
        for j in 0..4 {
            let (mut u0, mut u1, mut u2) =
                ([F::default(); 3], [F::default(); 3], [F::default(); 3]);
            for k in 0..4 {
                let wt = gs[TRIPLE_SLOT[16 * i + 4 * j + k] as usize];
                for d in 0..3 {
                    u0[d] += wt * c[2][k][d];
                    u1[d] += wt * c[0][k][d];
                    u2[d] += wt * c[1][k][d];
                }
            }
            let x0 = cross(c[1][j], u0);
            let x1 = cross(c[2][j], u1);
            let x2 = cross(c[0][j], u2);
            for d in 0..3 {
                a0[d] += x0[d];
                a1[d] += x1[d];
                a2[d] += x2[d];
            }
        }
        g[0][i] = a0;
        g[1][i] = a1;
        g[2][i] = a2;
    }
    // Written out row by row so that the compiler unrolls each (a loop over the rows
    // kept the zero tests at run time).
    let lin = |w: [f64; 12]| -> V3 {
        let mut o = [F::default(); 3];
        for (t, &wt) in w.iter().enumerate() {
            if wt != 0.0 {
                let gv = g[t / 4][t % 4];
                for k in 0..3 {
                    o[k] += F::splat(wt) * gv[k];
                }
            }
        }
        o
    };
    let upd = [
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
    ];
    for l in 0..L {
        for n in 0..10 {
            for k in 0..3 {
                out.gx[l][n][k] = 0.0 + upd[n][k].0[l];
            }
        }
    }
}

/// The Bernstein coefficients of det J of each lane's element (`jacobian::bezier_forward`'s
/// operations) and the Jacobian columns.
#[inline(always)]
fn coefficients(x: &[[P3; 10]; L]) -> ([F; 20], [[V3; 4]; 3]) {
    // Nodes relative to corner 0, transposed to lanes.
    let mut y = [[F::default(); 3]; 10];
    for n in 0..10 {
        for d in 0..3 {
            for l in 0..L {
                y[n][d].0[l] = x[l][n][d] - x[l][0][d];
            }
        }
    }
    let c = columns(&y);
    let mut x12 = [[[F::default(); 3]; 4]; 4];
    for j in 0..4 {
        for k in 0..4 {
            x12[j][k] = cross(c[1][j], c[2][k]);
        }
    }
    let mut b = [F::default(); 20];
    for i in 0..4 {
        for j in 0..4 {
            for k in 0..4 {
                let s = TRIPLE_SLOT[16 * i + 4 * j + k] as usize;
                b[s] += dot(c[0][i], x12[j][k]);
            }
        }
    }
    for s in 0..20 {
        b[s] = b[s] * F::splat(SLOT_WEIGHT[s]);
    }
    (b, c)
}

/// [`coefficients`] alone, for the objective's minimum measure.
#[inline]
pub(super) fn bezier_block(x: &[[P3; 10]; L]) -> [[f64; 20]; L] {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2 (checked just above).
            return unsafe { bezier_block_avx2(x) };
        }
    }
    bezier_block_body(x)
}

/// [`bezier_block_body`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn bezier_block_avx2(x: &[[P3; 10]; L]) -> [[f64; 20]; L] {
    bezier_block_body(x)
}

#[inline(always)]
pub(super) fn bezier_block_body(x: &[[P3; 10]; L]) -> [[f64; 20]; L] {
    let (b, _) = coefficients(x);
    std::array::from_fn(|l| std::array::from_fn(|s| b[s].0[l]))
}

/// ∂F/∂x_n = Σ_t UPD[n][t] g[t / 4][t % 4] (the written-out `COLS` of `jacobian`).
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

/// The Jacobian columns (`jacobian::columns`, same terms in the same order).
#[inline(always)]
fn columns(y: &[V3; 10]) -> [[V3; 4]; 3] {
    let f = |t: &[(usize, f64)]| -> V3 {
        let mut v = [F::default(); 3];
        for &(n, w) in t {
            for k in 0..3 {
                v[k] += F::splat(w) * y[n][k];
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
