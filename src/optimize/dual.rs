//! Forward-mode dual numbers with a 3-component gradient: the exact derivative of a
//! quality measure with respect to the position of one vertex, for the smoother.

use std::ops::{Add, Mul, Neg, Sub};

/// A value and its gradient with respect to a point in R^3.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct D3 {
    /// Value.
    pub v: f64,
    /// Gradient.
    pub g: [f64; 3],
}

impl D3 {
    /// A constant.
    #[inline]
    pub fn c(v: f64) -> D3 {
        D3 { v, g: [0.0; 3] }
    }

    /// The `k`-th coordinate of the variable point, with value `v`.
    #[inline]
    pub fn var(v: f64, k: usize) -> D3 {
        let mut g = [0.0; 3];
        g[k] = 1.0;
        D3 { v, g }
    }

    /// Multiplication by a constant.
    #[inline]
    pub fn scale(self, s: f64) -> D3 {
        D3 {
            v: self.v * s,
            g: [self.g[0] * s, self.g[1] * s, self.g[2] * s],
        }
    }

    /// Square root (derivative undefined at 0: returns a zero gradient there).
    #[inline]
    pub fn sqrt(self) -> D3 {
        let r = self.v.sqrt();
        let k = if r > 0.0 { 0.5 / r } else { 0.0 };
        D3 {
            v: r,
            g: [self.g[0] * k, self.g[1] * k, self.g[2] * k],
        }
    }

    /// atan2(self, x).
    #[inline]
    pub fn atan2(self, x: D3) -> D3 {
        let (s, c) = (self.v, x.v);
        let r2 = s * s + c * c;
        let k = if r2 > 0.0 { 1.0 / r2 } else { 0.0 };
        D3 {
            v: s.atan2(c),
            g: std::array::from_fn(|i| (c * self.g[i] - s * x.g[i]) * k),
        }
    }
}

impl Add for D3 {
    type Output = D3;
    #[inline]
    fn add(self, o: D3) -> D3 {
        D3 {
            v: self.v + o.v,
            g: [self.g[0] + o.g[0], self.g[1] + o.g[1], self.g[2] + o.g[2]],
        }
    }
}

impl Sub for D3 {
    type Output = D3;
    #[inline]
    fn sub(self, o: D3) -> D3 {
        D3 {
            v: self.v - o.v,
            g: [self.g[0] - o.g[0], self.g[1] - o.g[1], self.g[2] - o.g[2]],
        }
    }
}

#[allow(clippy::suspicious_arithmetic_impl)] // the product rule adds
impl Mul for D3 {
    type Output = D3;
    #[inline]
    fn mul(self, o: D3) -> D3 {
        D3 {
            v: self.v * o.v,
            g: std::array::from_fn(|i| self.g[i] * o.v + self.v * o.g[i]),
        }
    }
}

impl Neg for D3 {
    type Output = D3;
    #[inline]
    fn neg(self) -> D3 {
        D3 {
            v: -self.v,
            g: [-self.g[0], -self.g[1], -self.g[2]],
        }
    }
}

/// A point whose coordinates are dual numbers.
pub(crate) type DP = [D3; 3];

#[inline]
pub(crate) fn dsub(a: DP, b: DP) -> DP {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline]
pub(crate) fn dcross(a: DP, b: DP) -> DP {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[inline]
pub(crate) fn ddot(a: DP, b: DP) -> D3 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn derivatives_match_finite_differences() {
        // f(p) = atan2(|p x a|, p . b) + sqrt(p . p)
        let a = [D3::c(0.3), D3::c(-1.2), D3::c(0.7)];
        let b = [D3::c(1.1), D3::c(0.4), D3::c(-0.2)];
        let f = |p: [f64; 3]| -> D3 {
            let x = [D3::var(p[0], 0), D3::var(p[1], 1), D3::var(p[2], 2)];
            let c = dcross(x, a);
            ddot(c, c).sqrt().atan2(ddot(x, b)) + ddot(x, x).sqrt() - (-x[0]).scale(2.0)
        };
        let p = [0.4, 0.9, -0.3];
        let d = f(p);
        for k in 0..3 {
            let h = 1e-6;
            let mut q = p;
            q[k] += h;
            let mut r = p;
            r[k] -= h;
            let fd = (f(q).v - f(r).v) / (2.0 * h);
            assert!((fd - d.g[k]).abs() < 1e-8, "{k}: {fd} vs {}", d.g[k]);
        }
    }
}
