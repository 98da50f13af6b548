//! The objective's per-element work ([`super::objective`]) for [`L`] elements at once,
//! one element per SIMD lane: the Bernstein coefficients of det J and the reverse-mode
//! gradient (the formulas of [`jacobian`], generic over the lane type) and the barrier
//! terms, as lane-wise arithmetic that the compiler turns into vector instructions (AVX2
//! where the CPU has it, chosen at run time; SSE2 otherwise). Every lane performs exactly
//! the operations of the one-element code in the same order (no fused multiply-add), so
//! results are bit-identical to it on any CPU (tested): only the speed depends on the
//! machine.
//!
//! Hand-written rather than taken from a SIMD crate: the ones on stable Rust pick their
//! instruction set at compile time, while a portable binary has to choose at run time.

// Index loops mirror the formulas (several arrays per index).
#![allow(clippy::needless_range_loop)]

use super::jacobian::{self, Lane, V3};
use super::objective::{ln_and_recip, norm_of_mean};
use crate::geom::bezier::SLOT_WEIGHT;
use crate::geom::vec3::P3;
use std::ops::{Add, AddAssign, Mul, Sub};

/// Elements per block.
pub(super) const L: usize = 4;

/// One value per lane.
#[derive(Clone, Copy, Debug, Default)]
struct F([f64; L]);

impl Lane for F {
    #[inline(always)]
    fn splat(v: f64) -> F {
        F([v; L])
    }
}

impl F {
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
    let (mut nrm, mut dn) = (F::default(), F::default());
    for l in 0..L {
        (nrm.0[l], dn.0[l]) = norm_of_mean(mean.0[l], delta[l]);
    }
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
    let upd = jacobian::node_gradient(&c, &gs);
    for l in 0..L {
        for n in 0..10 {
            for k in 0..3 {
                out.gx[l][n][k] = 0.0 + upd[n][k].0[l];
            }
        }
    }
}

/// The Bernstein coefficients of det J of each lane's element and the Jacobian columns
/// ([`jacobian::coefficients`] on the nodes relative to corner 0, transposed to lanes).
#[inline(always)]
fn coefficients(x: &[[P3; 10]; L]) -> ([F; 20], [[V3<F>; 4]; 3]) {
    let mut y = [[F::default(); 3]; 10];
    for n in 0..10 {
        for d in 0..3 {
            for l in 0..L {
                y[n][d].0[l] = x[l][n][d] - x[l][0][d];
            }
        }
    }
    jacobian::coefficients(&y)
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
