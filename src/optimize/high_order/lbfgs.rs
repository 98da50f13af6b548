//! A small limited-memory BFGS minimizer with a backtracking (Armijo) line search that
//! treats a non-finite objective as "outside the barrier" and shrinks the step. Written
//! here rather than taken from a crate: the patches are tiny, the objective is +∞ outside
//! its barrier (which general-purpose line searches mishandle), and the buffers are
//! reused across patches.

// Index loops mirror the formulas (several arrays per index).
#![allow(clippy::needless_range_loop)]

/// Work buffers, reusable across calls.
#[derive(Default)]
pub(crate) struct Lbfgs {
    s: Vec<Vec<f64>>,
    y: Vec<Vec<f64>>,
    rho: Vec<f64>,
    alpha: Vec<f64>,
    g: Vec<f64>,
    d: Vec<f64>,
    xn: Vec<f64>,
    gn: Vec<f64>,
}

/// How many correction pairs are kept.
const MEMORY: usize = 6;

impl Lbfgs {
    /// Minimize `f` (value, writing the gradient into its second argument) from `x` for at
    /// most `max_iter` iterations, or until `stop()` says so after an accepted step (the
    /// last point `f` saw is then `x`); the first step moves by at most `first_step`.
    /// Returns the final value (`x` holds the minimizer found).
    pub fn minimize(
        &mut self,
        x: &mut [f64],
        f: &mut impl FnMut(&[f64], &mut [f64]) -> f64,
        max_iter: usize,
        first_step: f64,
        stop: &mut impl FnMut() -> bool,
    ) -> f64 {
        let n = x.len();
        self.g.resize(n, 0.0);
        self.d.resize(n, 0.0);
        self.xn.resize(n, 0.0);
        self.gn.resize(n, 0.0);
        for v in [&mut self.s, &mut self.y] {
            v.resize_with(MEMORY, Vec::new);
            for b in v.iter_mut() {
                b.resize(n, 0.0);
            }
        }
        self.rho.resize(MEMORY, 0.0);
        self.alpha.resize(MEMORY, 0.0);
        let mut fx = f(x, &mut self.g);
        if !fx.is_finite() {
            return fx;
        }
        let mut stored = 0usize; // pairs in use
        let mut head = 0usize; // next slot to write
        for _ in 0..max_iter {
            // Direction: two-loop recursion.
            self.d.copy_from_slice(&self.g);
            for back in 0..stored {
                let k = (head + MEMORY - 1 - back) % MEMORY;
                let a = self.rho[k] * dot(&self.s[k], &self.d);
                self.alpha[k] = a;
                axpy(&mut self.d, -a, &self.y[k]);
            }
            if stored > 0 {
                let k = (head + MEMORY - 1) % MEMORY;
                let gamma = dot(&self.s[k], &self.y[k]) / dot(&self.y[k], &self.y[k]);
                for v in self.d.iter_mut() {
                    *v *= gamma;
                }
            } else {
                let gn = dot(&self.g, &self.g).sqrt();
                if gn == 0.0 {
                    break;
                }
                let sc = first_step / gn;
                for v in self.d.iter_mut() {
                    *v *= sc;
                }
            }
            for fwd in 0..stored {
                let k = (head + MEMORY - stored + fwd) % MEMORY;
                let b = self.rho[k] * dot(&self.y[k], &self.d);
                axpy(&mut self.d, self.alpha[k] - b, &self.s[k]);
            }
            for v in self.d.iter_mut() {
                *v = -*v;
            }
            let mut slope = dot(&self.g, &self.d);
            if slope.is_nan() || slope >= 0.0 {
                // Not a descent direction: restart from the scaled gradient.
                stored = 0;
                let gn = dot(&self.g, &self.g).sqrt();
                if gn == 0.0 {
                    break;
                }
                let sc = first_step / gn;
                for (d, g) in self.d.iter_mut().zip(&self.g) {
                    *d = -g * sc;
                }
                slope = dot(&self.g, &self.d);
            }
            // Backtracking line search.
            let mut step = 1.0;
            let mut fnew = f64::INFINITY;
            let mut ok = false;
            for _ in 0..40 {
                for i in 0..n {
                    self.xn[i] = x[i] + step * self.d[i];
                }
                fnew = f(&self.xn, &mut self.gn);
                if fnew.is_finite() && fnew <= fx + 1e-4 * step * slope {
                    ok = true;
                    break;
                }
                step *= if fnew.is_finite() { 0.5 } else { 0.25 };
            }
            if !ok {
                break;
            }
            // Update the history.
            let k = head;
            let mut sy = 0.0;
            for i in 0..n {
                self.s[k][i] = self.xn[i] - x[i];
                self.y[k][i] = self.gn[i] - self.g[i];
                sy += self.s[k][i] * self.y[k][i];
            }
            if sy > 1e-300 {
                self.rho[k] = 1.0 / sy;
                head = (head + 1) % MEMORY;
                stored = (stored + 1).min(MEMORY);
            }
            x.copy_from_slice(&self.xn);
            self.g.copy_from_slice(&self.gn);
            let done = (fx - fnew).abs() <= 1e-12 * fx.abs().max(1e-300);
            fx = fnew;
            if done || stop() {
                break;
            }
        }
        fx
    }
}

#[inline]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[inline]
fn axpy(y: &mut [f64], a: f64, x: &[f64]) {
    for (yi, xi) in y.iter_mut().zip(x) {
        *yi += a * xi;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn minimizes_rosenbrock() {
        let mut x = vec![-1.2, 1.0];
        let mut f = |x: &[f64], g: &mut [f64]| {
            let (a, b) = (x[0], x[1]);
            g[0] = -2.0 * (1.0 - a) - 400.0 * a * (b - a * a);
            g[1] = 200.0 * (b - a * a);
            (1.0 - a).powi(2) + 100.0 * (b - a * a).powi(2)
        };
        let v = Lbfgs::default().minimize(&mut x, &mut f, 200, 0.1, &mut || false);
        assert!(v < 1e-10, "{v} at {x:?}");
    }

    #[test]
    fn respects_a_barrier() {
        // min (x - 2)^2 - ln(1 - x) stays below x = 1.
        let mut x = vec![0.0];
        let mut f = |x: &[f64], g: &mut [f64]| {
            if x[0] >= 1.0 {
                return f64::INFINITY;
            }
            g[0] = 2.0 * (x[0] - 2.0) + 1.0 / (1.0 - x[0]);
            (x[0] - 2.0).powi(2) - (1.0 - x[0]).ln()
        };
        Lbfgs::default().minimize(&mut x, &mut f, 100, 1.0, &mut || false);
        let exact = (3.0 - 3.0f64.sqrt()) / 2.0; // the root of 2x^2 - 6x + 3 below 1
        assert!((x[0] - exact).abs() < 1e-6, "{} vs {exact}", x[0]);
    }
}
