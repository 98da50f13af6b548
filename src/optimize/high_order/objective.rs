//! The objective of one patch: for every element with a free node and every Bernstein
//! coefficient `b_s` of its det J, the measure `m_s = b_s / N(mean(b))` (1 for every
//! coefficient of a straight-sided tet; the certified min J / max J is at least
//! min m / max m) enters Gmsh's log-barrier function
//! `f(m) = (m − 1)² + ln²((m − ε) / (1 − ε))`, +∞ for m ≤ ε, with ε below the current
//! minimum (moved up between runs by the caller).
//!
//! `N(μ) = (μ + sqrt(μ² + δ²)) / 2` is the mean μ itself for a sound element (δ is 5% of
//! the element's initial straight-sided det J) and stays positive for a badly tangled
//! one whose mean is ≤ 0, so the barrier can start from any state.
//!
//! Variables: each free vertex's position, and for each free mid node its offset from
//! its edge's midpoint (so a mid node follows its moving corners).

// Index loops mirror the formulas (several arrays per index).
#![allow(clippy::needless_range_loop)]

use super::jacobian::bezier_forward;
use super::lanes::{self, L};
use crate::geom::bezier::scaled_jacobian_certified;
use crate::geom::tet_quality::DEFAULT_SJ_REL_TOL;
use crate::geom::vec3::{mid, P3};
use rayon::prelude::*;

/// No variable.
pub(super) const FIXED: u32 = u32::MAX;

/// One element of a patch: the fixed node positions and, per node, its variable.
#[derive(Clone, Debug)]
pub(super) struct PatchElem {
    /// Positions of the fixed nodes (free ones are ignored).
    pub x: [P3; 10],
    /// Variable of each node ([`FIXED`] when fixed); corners 0..4 are positions, mids
    /// 4..10 offsets from their edge midpoint.
    pub var: [u32; 10],
    /// δ of the normalization (see the module docs).
    pub delta: f64,
}

impl PatchElem {
    /// An element with nodes `x` and variables `var`.
    pub fn new(x: [P3; 10], var: [u32; 10]) -> PatchElem {
        PatchElem {
            x,
            var,
            delta: delta_of(&x),
        }
    }

    /// True when some node is a variable.
    pub fn has_var(&self) -> bool {
        self.var.iter().any(|&v| v != FIXED)
    }
}

/// δ of the normalization for nodes `x`.
fn delta_of(x: &[P3; 10]) -> f64 {
    let js = crate::geom::vec3::tet_det(x[0], x[1], x[2], x[3]).abs();
    if js > 0.0 {
        0.05 * js
    } else {
        let (b, _) = bezier_forward(x);
        0.05 * b.iter().fold(0.0f64, |a, v| a.max(v.abs()))
    }
}

/// The score the optimizer ranks elements by: the certified min J / max J of a
/// certified-valid element (in (0, 1]), else its smallest measure min b / N(mean b)
/// clamped to ≤ 0 (so every valid element ranks above every invalid one, and invalid
/// ones rank by how far the barrier has to push them).
///
/// When the unrefined Bernstein ratio min b / max b already reaches `enough`, that
/// ratio (a lower bound of min J / max J, up to rounding) is returned without the
/// subdivision that certifies the exact value: the optimizer only needs to know such an
/// element is good enough.
///
/// Scores the first `n` of the elements `xs` (the rest are ignored), their Bernstein
/// coefficients computed [`L`] at a time.
pub(super) fn score_block(xs: &[[P3; 10]; L], n: usize, enough: f64) -> [f64; L] {
    let bs = lanes::bezier_block(xs);
    std::array::from_fn(|l| {
        if l < n {
            score_with(&xs[l], &bs[l], enough)
        } else {
            f64::NAN
        }
    })
}

/// [`score_block`]'s score of one element `x` given its Bernstein coefficients `b`.
fn score_with(x: &[P3; 10], b: &[f64; 20], enough: f64) -> f64 {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for &v in b {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo > 0.0 && lo >= enough * hi {
        return lo / hi;
    }
    let s = scaled_jacobian_certified(x, DEFAULT_SJ_REL_TOL);
    if s > 0.0 {
        return s;
    }
    let m = min_measure(b, delta_of(x));
    if m.is_nan() {
        f64::NEG_INFINITY
    } else {
        m.min(0.0)
    }
}

/// (ln x, 1 / x) for a positive normal `x`, branch-free, with a single division (absolute
/// error of ln below 1e-13): x = 2^e m with m in [√½, √2), ln m = 2 atanh((m − 1)/(m + 1))
/// by its series to the 15th power. Several times faster than the libm calls in the
/// objective's inner loop, where it is evaluated twenty times per element; tested against
/// `f64::ln`.
#[inline(always)]
pub(super) fn ln_and_recip(x: f64) -> (f64, f64) {
    const LN2: f64 = std::f64::consts::LN_2;
    // 2^52 + biased exponent, as a float: the exponent without an int → float
    // conversion (which SSE2 lacks for 64-bit lanes), so that loops over this vectorize.
    const EXP_BIAS: f64 = 4_503_599_627_370_496.0 + 1023.0;
    let bits = x.to_bits();
    let e = f64::from_bits(((bits >> 52) & 0x7ff) | 0x4330_0000_0000_0000) - EXP_BIAS;
    let m = f64::from_bits((bits & 0x000f_ffff_ffff_ffff) | 0x3ff0_0000_0000_0000);
    let big = m > std::f64::consts::SQRT_2;
    let m = if big { 0.5 * m } else { m };
    let e = if big { e + 1.0 } else { e };
    // 1 / (x (m + 1)) gives both s = (m − 1)/(m + 1) = (m − 1) x q and 1/x = (m + 1) q.
    let q = 1.0 / (x * (m + 1.0));
    let s = (m - 1.0) * x * q;
    let z = s * s;
    let p = 1.0
        + z * (1.0 / 3.0
            + z * (1.0 / 5.0
                + z * (1.0 / 7.0
                    + z * (1.0 / 9.0 + z * (1.0 / 11.0 + z * (1.0 / 13.0 + z * (1.0 / 15.0)))))));
    (e * LN2 + 2.0 * s * p, (m + 1.0) * q)
}

/// The normalization N(μ) and its derivative.
#[inline(always)]
pub(super) fn norm_of_mean(mu: f64, delta: f64) -> (f64, f64) {
    let r = (mu * mu + delta * delta).sqrt();
    (
        0.5 * (mu + r),
        0.5 * (1.0 + if r > 0.0 { mu / r } else { 0.0 }),
    )
}

/// The elements of a patch and the barrier.
pub(super) struct Objective<'a> {
    /// The patch's elements that have a free node.
    pub elems: &'a [PatchElem],
    /// Barrier ε: the objective is +∞ where some measure is ≤ ε.
    pub eps: f64,
    /// Smallest min b / max b of the last point [`Objective::eval`] saw (computed on the
    /// way, for stopping as soon as a target is reached).
    pub last_ratio: std::cell::Cell<f64>,
    /// Per-block results of a parallel [`Objective::eval`], reused across calls.
    pub outs: std::cell::RefCell<Vec<lanes::BlockOut>>,
    /// Whether this patch is the only one of its round still running, so that the other
    /// threads are idle and may evaluate parts of it (asked at every evaluation).
    pub lone: &'a dyn Fn() -> bool,
}

/// The nodes of `e` for variables `v`.
#[inline]
pub(super) fn nodes(e: &PatchElem, v: &[f64]) -> [P3; 10] {
    let mut x = e.x;
    for k in 0..4 {
        let i = e.var[k];
        if i != FIXED {
            let i = 3 * i as usize;
            x[k] = [v[i], v[i + 1], v[i + 2]];
        }
    }
    for (k, [a, b]) in crate::geom::shape::TET10_EDGES.iter().enumerate() {
        let i = e.var[4 + k];
        if i != FIXED {
            let i = 3 * i as usize;
            let m = mid(x[*a], x[*b]);
            x[4 + k] = [m[0] + v[i], m[1] + v[i + 1], m[2] + v[i + 2]];
        }
    }
    x
}

/// The nodes of the elements of `chunk` (at most [`L`]) for variables `v` into `xs`; a
/// short chunk repeats its last element in the spare lanes.
#[inline]
pub(super) fn gather(chunk: &[PatchElem], v: &[f64], xs: &mut [[P3; 10]; L]) {
    for (l, x) in xs.iter_mut().enumerate() {
        *x = nodes(&chunk[l.min(chunk.len() - 1)], v);
    }
}

/// Smallest measure of `b` (min b / N(mean b)).
#[inline]
pub(super) fn min_measure(b: &[f64; 20], delta: f64) -> f64 {
    let mean: f64 = b.iter().sum::<f64>() / 20.0;
    let (n, _) = norm_of_mean(mean, delta);
    if n.is_nan() || n <= 0.0 {
        return f64::NEG_INFINITY;
    }
    b.iter().fold(f64::INFINITY, |a, &v| a.min(v)) / n
}

impl Objective<'_> {
    /// Smallest measure over the patch at `v`, and the smallest uncertified-but-safe
    /// ratio min b / max b (a lower bound of every element's min J / max J when positive).
    /// In parallel parts when the patch runs alone, as [`Objective::eval`].
    pub fn min_measure(&self, v: &[f64]) -> (f64, f64) {
        // (min measure, min ratio) of the elements `elems`.
        let part = |elems: &[PatchElem]| {
            let mut lo = f64::INFINITY;
            let mut ratio = f64::INFINITY;
            let mut xs = [[[0.0; 3]; 10]; L];
            for chunk in elems.chunks(L) {
                gather(chunk, v, &mut xs);
                let bs = lanes::bezier_block(&xs);
                for (e, b) in chunk.iter().zip(&bs) {
                    lo = lo.min(min_measure(b, e.delta));
                    let (mut bmin, mut bmax) = (f64::INFINITY, f64::NEG_INFINITY);
                    for &x in b {
                        bmin = bmin.min(x);
                        bmax = bmax.max(x);
                    }
                    ratio = ratio.min(if bmax > 0.0 { bmin / bmax } else { -1.0 });
                }
            }
            (lo, ratio)
        };
        match part_len(self.elems.len(), self.lone) {
            // Minima: the same whatever the split.
            Some(per) => self.elems.par_chunks(per).map(part).reduce(
                || (f64::INFINITY, f64::INFINITY),
                |a, b| (a.0.min(b.0), a.1.min(b.1)),
            ),
            None => part(self.elems),
        }
    }

    /// Objective at `v`, gradient into `g`. Elements go through [`lanes::eval_block`]
    /// [`L`] at a time (bit-identical to one at a time; tested). A patch running alone
    /// has its blocks evaluated in parallel parts ([`part_len`]); their sums and
    /// gradients are still added in element order, so the result does not depend on the
    /// split or the thread count.
    pub fn eval(&self, v: &[f64], g: &mut [f64]) -> f64 {
        g.iter_mut().for_each(|x| *x = 0.0);
        let eps = self.eps;
        let lden = (1.0 - eps).ln();
        let mut total = 0.0;
        let mut ratio = f64::INFINITY;
        self.last_ratio.set(f64::NEG_INFINITY);
        if let Some(per) = part_len(self.elems.len(), self.lone) {
            let mut outs = self.outs.borrow_mut();
            outs.resize_with(self.elems.len().div_ceil(L), Default::default);
            outs.par_chunks_mut(per / L)
                .zip(self.elems.par_chunks(per))
                .for_each(|(outs, elems)| {
                    for (out, chunk) in outs.iter_mut().zip(elems.chunks(L)) {
                        eval_chunk(chunk, v, eps, lden, out);
                    }
                });
            for (out, chunk) in outs.iter().zip(self.elems.chunks(L)) {
                if !add_chunk(chunk, out, g, &mut total, &mut ratio) {
                    return f64::INFINITY;
                }
            }
        } else {
            let mut out = lanes::BlockOut::default();
            for chunk in self.elems.chunks(L) {
                eval_chunk(chunk, v, eps, lden, &mut out);
                if !add_chunk(chunk, &out, g, &mut total, &mut ratio) {
                    return f64::INFINITY;
                }
            }
        }
        self.last_ratio.set(ratio);
        total
    }
}

/// How many elements (a multiple of [`L`]) each part gets when the evaluation of `n`
/// elements is split across the current rayon pool, or `None` to evaluate them in one
/// piece: one part per thread, each of at least [`PART_ELEMS`] elements (below that, the
/// hand-off costs more than it saves), and only for a patch running alone (`lone()`): a
/// thread waiting for its part to come back steals other work, and another patch would
/// hold it far longer. The results never depend on the split.
pub(super) fn part_len(n: usize, lone: &dyn Fn() -> bool) -> Option<usize> {
    if !lone() {
        return None;
    }
    let parts = (n / PART_ELEMS).min(rayon::current_num_threads());
    (parts > 1).then(|| n.div_ceil(L).div_ceil(parts) * L)
}

/// See [`part_len`].
const PART_ELEMS: usize = 32;

/// [`lanes::eval_block`] on the elements of `chunk` (at most [`L`]) at `v`, with the
/// gradient of each free mid node's offset passed on to its edge's corners.
#[inline]
fn eval_chunk(chunk: &[PatchElem], v: &[f64], eps: f64, lden: f64, out: &mut lanes::BlockOut) {
    let mut xs = [[[0.0; 3]; 10]; L];
    gather(chunk, v, &mut xs);
    let delta = std::array::from_fn(|l| chunk[l.min(chunk.len() - 1)].delta);
    lanes::eval_block(&xs, delta, eps, lden, out);
    for (e, gx) in chunk.iter().zip(out.gx.iter_mut()) {
        follow_corners(e, gx);
    }
}

/// Add the results `out` of `chunk` to the objective `total`, its gradient `g` and the
/// smallest `ratio`, element by element; false (the rest not added) at the first element
/// outside the barrier.
#[inline]
fn add_chunk(
    chunk: &[PatchElem],
    out: &lanes::BlockOut,
    g: &mut [f64],
    total: &mut f64,
    ratio: &mut f64,
) -> bool {
    for (l, e) in chunk.iter().enumerate() {
        *ratio = ratio.min(out.ratio[l]);
        if !out.ok[l] {
            return false;
        }
        *total += out.part[l];
        scatter(e, &out.gx[l], g);
    }
    true
}

/// Mid nodes follow their corners (x_m = (x_a + x_b)/2 + offset): the gradient of a free
/// mid node's offset also moves its edge's corners.
#[inline]
fn follow_corners(e: &PatchElem, gx: &mut [P3; 10]) {
    for (k, [a, b]) in crate::geom::shape::TET10_EDGES.iter().enumerate() {
        if e.var[4 + k] != FIXED {
            let gm = gx[4 + k];
            for d in 0..3 {
                gx[*a][d] += 0.5 * gm[d];
                gx[*b][d] += 0.5 * gm[d];
            }
        }
    }
}

/// Add the node gradient `gx` of `e` to its variables' entries of `g`.
#[inline]
fn scatter(e: &PatchElem, gx: &[P3; 10], g: &mut [f64]) {
    for n in 0..10 {
        let i = e.var[n];
        if i != FIXED {
            let i = 3 * i as usize;
            for d in 0..3 {
                g[i + d] += gx[n][d];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optimize::high_order::jacobian::backprop;

    #[test]
    fn fast_ln_matches_ln() {
        let mut x = 1e-300_f64;
        while x < 1e300 {
            for f in [1.0, 1.1, 1.3, 1.414, 1.4143, 1.7, 1.99] {
                let v = x * f;
                let b = v.ln();
                let (c, r) = ln_and_recip(v);
                assert!(
                    (c - b).abs() <= 1e-13 + 8.0 * f64::EPSILON * b.abs(),
                    "{v}: {c} vs {b}"
                );
                assert!((r * v - 1.0).abs() <= 4.0 * f64::EPSILON, "{v}: 1/x {r}");
            }
            x *= 7.3;
        }
    }

    /// A tet with one mid node (edge 0-1) off its edge.
    fn curved_tet() -> [P3; 10] {
        let c = [
            [0.0, 0.0, 0.0],
            [1.0, 0.1, 0.0],
            [0.2, 0.9, 0.1],
            [0.3, 0.2, 0.8],
        ];
        let mut x = crate::geom::shape::straight_tet10(c);
        x[4][2] += 0.05;
        x
    }

    #[test]
    #[ignore = "timing; run in release with --ignored --nocapture"]
    fn eval_cost() {
        let x = curved_tet();
        let mut elems = Vec::new();
        for _ in 0..100 {
            let var = [FIXED, FIXED, FIXED, 0, 1, 2, 3, 4, 5, 6];
            elems.push(PatchElem::new(x, var));
        }
        let obj = Objective {
            elems: &elems,
            eps: -0.5,
            last_ratio: Default::default(),
            outs: Default::default(),
            lone: &|| false,
        };
        let mut v = vec![0.01; 21];
        v[..3].copy_from_slice(&x[3]);
        let mut g = vec![0.0; 21];
        // The fastest of ten batches: the machines here are shared.
        let mut dt = f64::INFINITY;
        let mut s = 0.0;
        for _ in 0..10 {
            let t = std::time::Instant::now();
            for _ in 0..2000 {
                s += obj.eval(&v, &mut g);
            }
            dt = dt.min(t.elapsed().as_secs_f64());
        }
        println!("{:.1} ns per element eval ({s})", dt / 200000.0 * 1e9);
    }

    /// The objective one element at a time, as it was written before [`lanes`]: the
    /// reference the lane code must match bit for bit.
    fn eval_reference(obj: &Objective, v: &[f64], g: &mut [f64]) -> f64 {
        g.iter_mut().for_each(|x| *x = 0.0);
        let eps = obj.eps;
        let lden = (1.0 - eps).ln();
        let mut total = 0.0;
        for e in obj.elems {
            let x = nodes(e, v);
            let (b, tape) = bezier_forward(&x);
            let mean = b.iter().sum::<f64>() / 20.0;
            let (nrm, dn) = norm_of_mean(mean, e.delta);
            if nrm.is_nan() || nrm <= 0.0 {
                return f64::INFINITY;
            }
            let inv = 1.0 / nrm;
            let m: [f64; 20] = std::array::from_fn(|s| b[s] * inv);
            let lo = m.iter().fold(f64::INFINITY, |a, &x| a.min(x));
            if lo.is_nan() || lo <= eps {
                return f64::INFINITY;
            }
            let (mut part, mut dm_sum) = (0.0, 0.0);
            let mut df = [0.0; 20];
            for s in 0..20 {
                let (ln_r, inv_r) = ln_and_recip(m[s] - eps);
                let l = ln_r - lden;
                part += (m[s] - 1.0) * (m[s] - 1.0) + l * l;
                df[s] = 2.0 * ((m[s] - 1.0) + l * inv_r);
                dm_sum += df[s] * m[s];
            }
            total += part;
            let corr = dm_sum * dn / 20.0;
            let gb: [f64; 20] = std::array::from_fn(|s| (df[s] - corr) * inv);
            let mut gx = [[0.0; 3]; 10];
            backprop(&tape, &gb, &mut gx);
            follow_corners(e, &mut gx);
            scatter(e, &gx, g);
        }
        total
    }

    /// `n_el` copies of [`curved_tet`] with every node shaken by up to 0.03, sharing four
    /// variables (corner 3 and mids 6..9, so that the order in which their gradients are
    /// added matters to the last bit), and a point near the start for them.
    fn shaken_patch(rng: &mut impl rand::Rng, n_el: usize) -> (Vec<PatchElem>, Vec<f64>) {
        let base = curved_tet();
        let elems = (0..n_el)
            .map(|_| {
                let mut x = base;
                for c in x.iter_mut().flatten() {
                    *c += rng.random_range(-0.03..0.03);
                }
                let var = std::array::from_fn(|k| {
                    if k == 3 || k >= 6 {
                        (k % 4) as u32
                    } else {
                        FIXED
                    }
                });
                PatchElem::new(x, var)
            })
            .collect();
        let mut v: Vec<f64> = (0..12).map(|_| rng.random_range(-0.01..0.01)).collect();
        v[9..12].copy_from_slice(&base[3]);
        (elems, v)
    }

    #[test]
    fn lanes_match_one_element_at_a_time_bit_for_bit() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand::rngs::StdRng::seed_from_u64(11);
        for n_el in [1usize, 3, 4, 5, 9] {
            for _ in 0..20 {
                let (elems, v) = shaken_patch(&mut rng, n_el);
                let obj = Objective {
                    elems: &elems,
                    eps: rng.random_range(-0.5..0.1),
                    last_ratio: Default::default(),
                    outs: Default::default(),
                    lone: &|| false,
                };
                let (mut g1, mut g2) = (vec![0.0; 12], vec![0.0; 12]);
                let f1 = obj.eval(&v, &mut g1);
                let f2 = eval_reference(&obj, &v, &mut g2);
                assert_eq!(f1.to_bits(), f2.to_bits(), "{f1} vs {f2}");
                if f1.is_finite() {
                    for (a, b) in g1.iter().zip(&g2) {
                        assert_eq!(a.to_bits(), b.to_bits(), "{a} vs {b}");
                    }
                }
                // The portable body gives the same as the dispatched one.
                let xs: [[P3; 10]; L] = std::array::from_fn(|l| nodes(&elems[l % n_el], &v));
                let d = std::array::from_fn(|l| elems[l % n_el].delta);
                let (mut a, mut b) = (lanes::BlockOut::default(), lanes::BlockOut::default());
                let lden = (1.0 - obj.eps).ln();
                lanes::eval_block(&xs, d, obj.eps, lden, &mut a);
                lanes::eval_block_body(&xs, d, obj.eps, lden, &mut b);
                assert_eq!(a.part.map(f64::to_bits), b.part.map(f64::to_bits));
                assert_eq!(a.ratio.map(f64::to_bits), b.ratio.map(f64::to_bits));
                assert_eq!(a.ok, b.ok);
                let bz = lanes::bezier_block(&xs);
                assert_eq!(bz, lanes::bezier_block_body(&xs));
                for (l, b) in bz.iter().enumerate() {
                    assert_eq!(*b, bezier_forward(&xs[l]).0);
                }
                let bits = |o: &lanes::BlockOut| o.gx.map(|e| e.map(|p| p.map(f64::to_bits)));
                assert_eq!(bits(&a), bits(&b));
            }
        }
    }

    #[test]
    fn parallel_parts_give_the_serial_result_bit_for_bit() {
        use rand::SeedableRng;
        let mut rng = rand::rngs::StdRng::seed_from_u64(17);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        for (n_el, eps) in [(137usize, -10.0), (64, -10.0), (137, 0.97)] {
            // Elements sharing the four variables (so that the order in which gradients
            // are added matters to the last bit).
            let (elems, v) = shaken_patch(&mut rng, n_el);
            let run = |lone: bool| {
                pool.install(|| {
                    // Split in two for a lone patch only.
                    let per = part_len(n_el, &|| true).expect("split");
                    assert!(per % L == 0 && per < n_el && 2 * per >= n_el, "{per}");
                    assert_eq!(part_len(n_el, &|| false), None);
                    let yes = || lone;
                    let obj = Objective {
                        elems: &elems,
                        eps,
                        last_ratio: Default::default(),
                        outs: Default::default(),
                        lone: &yes,
                    };
                    let mut g = vec![0.0; 12];
                    let f = obj.eval(&v, &mut g);
                    (f, g, obj.last_ratio.get())
                })
            };
            let (f1, g1, r1) = run(false);
            let (f2, g2, r2) = run(true);
            assert_eq!(f1.to_bits(), f2.to_bits(), "{f1} vs {f2}");
            assert_eq!(f1.is_finite(), eps < 0.0, "{f1}");
            if f1.is_finite() {
                assert_eq!(r1.to_bits(), r2.to_bits());
                for (a, b) in g1.iter().zip(&g2) {
                    assert_eq!(a.to_bits(), b.to_bits(), "{a} vs {b}");
                }
            }
        }
    }

    #[test]
    fn gradient_matches_finite_differences() {
        let mut x = curved_tet();
        x[9][0] -= 0.04;
        // Corner 3 and mids 5 and 9 free; mid 9 sits on edge (3, 1).
        let e = PatchElem::new(
            x,
            [FIXED, FIXED, FIXED, 0, FIXED, 1, FIXED, FIXED, FIXED, 2],
        );
        let m5 = mid(x[1], x[2]);
        let m9 = mid(x[3], x[1]);
        let v0 = vec![
            x[3][0],
            x[3][1],
            x[3][2],
            x[5][0] - m5[0] + 0.02,
            x[5][1] - m5[1],
            x[5][2] - m5[2] - 0.01,
            x[9][0] - m9[0],
            x[9][1] - m9[1],
            x[9][2] - m9[2],
        ];
        let elems = [e];
        let obj = Objective {
            elems: &elems,
            eps: 0.2,
            last_ratio: Default::default(),
            outs: Default::default(),
            lone: &|| false,
        };
        let mut g = vec![0.0; 9];
        let f0 = obj.eval(&v0, &mut g);
        assert!(f0.is_finite() && f0 > 0.0);
        let mut scratch = vec![0.0; 9];
        for i in 0..9 {
            let h = 1e-7;
            let mut vp = v0.clone();
            vp[i] += h;
            let mut vm = v0.clone();
            vm[i] -= h;
            let fd = (obj.eval(&vp, &mut scratch) - obj.eval(&vm, &mut scratch)) / (2.0 * h);
            assert!(
                (fd - g[i]).abs() < 1e-5 * (1.0 + fd.abs()),
                "{i}: {fd} vs {}",
                g[i]
            );
        }
    }
}
