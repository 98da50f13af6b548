//! Exact sign of a sum of products of three f64 values (a Kulisch-style fixed-point
//! accumulator). Used for the sign of a shell's enclosed volume, sum of det[a, b, c] over
//! its triangles, which decides the shell's orientation without any tolerance.
//!
//! Every finite f64 is m * 2^e with an integer m < 2^53 and e >= -1074, so a product of
//! three is an integer (< 2^159) times 2^(e1+e2+e3), e1+e2+e3 >= -3222. The accumulator
//! is a two's-complement integer in units of 2^-3222, wide enough (6656 bits) for any
//! finite inputs and up to 2^40 terms: each term is added exactly, so the sign is exact.

/// Exponent offset: bit 0 of the accumulator is 2^-3222.
const BIAS: i32 = 3 * 1074;
const LIMBS: usize = 104;

/// An exact accumulator of signed triple products.
#[derive(Clone)]
pub(crate) struct ExactSum {
    limbs: [u64; LIMBS],
}

/// (mantissa, exponent, negative) with value = ±mantissa * 2^exponent.
#[inline]
fn split(x: f64) -> (u64, i32, bool) {
    let bits = x.to_bits();
    let neg = bits >> 63 == 1;
    let exp = ((bits >> 52) & 0x7ff) as i32;
    let frac = bits & ((1u64 << 52) - 1);
    if exp == 0 {
        (frac, -1074, neg)
    } else {
        (frac | (1u64 << 52), exp - 1075, neg)
    }
}

impl ExactSum {
    /// Zero.
    pub fn new() -> ExactSum {
        ExactSum { limbs: [0; LIMBS] }
    }

    /// Adds `x * y * z` exactly (or subtracts it when `negate`). Inputs must be finite.
    pub fn add_product(&mut self, x: f64, y: f64, z: f64, negate: bool) {
        let (m1, e1, s1) = split(x);
        let (m2, e2, s2) = split(y);
        let (m3, e3, s3) = split(z);
        if m1 == 0 || m2 == 0 || m3 == 0 {
            return;
        }
        let neg = s1 ^ s2 ^ s3 ^ negate;
        let p12 = m1 as u128 * m2 as u128; // < 2^106
        let lo = (p12 as u64) as u128 * m3 as u128;
        let hi = ((p12 >> 64) as u64) as u128 * m3 as u128;
        // 192-bit product r = lo + hi * 2^64.
        let r0 = lo as u64;
        let mid = (lo >> 64) + (hi & 0xffff_ffff_ffff_ffff);
        let r1 = mid as u64;
        let r2 = ((hi >> 64) + (mid >> 64)) as u64;
        let pos = e1 + e2 + e3 + BIAS;
        debug_assert!(pos >= 0);
        let (q, s) = ((pos / 64) as usize, (pos % 64) as u32);
        let w = if s == 0 {
            [r0, r1, r2, 0]
        } else {
            [
                r0 << s,
                (r1 << s) | (r0 >> (64 - s)),
                (r2 << s) | (r1 >> (64 - s)),
                r2 >> (64 - s),
            ]
        };
        if neg {
            self.sub_at(q, w);
        } else {
            self.add_at(q, w);
        }
    }

    fn add_at(&mut self, q: usize, w: [u64; 4]) {
        let mut carry = false;
        let mut i = q;
        for wk in w {
            if i >= LIMBS {
                return;
            }
            let (a, c1) = self.limbs[i].overflowing_add(wk);
            let (a, c2) = a.overflowing_add(carry as u64);
            self.limbs[i] = a;
            carry = c1 || c2;
            i += 1;
        }
        while carry && i < LIMBS {
            let (a, c) = self.limbs[i].overflowing_add(1);
            self.limbs[i] = a;
            carry = c;
            i += 1;
        }
    }

    fn sub_at(&mut self, q: usize, w: [u64; 4]) {
        let mut borrow = false;
        let mut i = q;
        for wk in w {
            if i >= LIMBS {
                return;
            }
            let (a, b1) = self.limbs[i].overflowing_sub(wk);
            let (a, b2) = a.overflowing_sub(borrow as u64);
            self.limbs[i] = a;
            borrow = b1 || b2;
            i += 1;
        }
        while borrow && i < LIMBS {
            let (a, b) = self.limbs[i].overflowing_sub(1);
            self.limbs[i] = a;
            borrow = b;
            i += 1;
        }
    }

    /// Adds det[a, b, c] = a . (b x c) exactly.
    pub fn add_det3(&mut self, a: [f64; 3], b: [f64; 3], c: [f64; 3]) {
        self.add_product(a[0], b[1], c[2], false);
        self.add_product(a[0], b[2], c[1], true);
        self.add_product(a[1], b[2], c[0], false);
        self.add_product(a[1], b[0], c[2], true);
        self.add_product(a[2], b[0], c[1], false);
        self.add_product(a[2], b[1], c[0], true);
    }

    /// The exact sign of the sum: -1, 0 or +1.
    pub fn sign(&self) -> i32 {
        if self.limbs[LIMBS - 1] >> 63 == 1 {
            -1
        } else if self.limbs.iter().any(|&l| l != 0) {
            1
        } else {
            0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn signs_of_simple_sums() {
        let mut s = ExactSum::new();
        assert_eq!(s.sign(), 0);
        s.add_product(2.0, 3.0, 4.0, false);
        assert_eq!(s.sign(), 1);
        s.add_product(-2.0, 3.0, 4.0, false);
        assert_eq!(s.sign(), 0);
        s.add_product(1.0, 1.0, f64::from_bits(1), true); // minus the smallest subnormal
        assert_eq!(s.sign(), -1);
        s.add_product(1e300, 1e300, 1e-300, false);
        assert_eq!(s.sign(), 1);
        s.add_product(1e300, 1e300, 1e-300, true);
        assert_eq!(s.sign(), -1);
    }

    #[test]
    fn cancellation_that_floats_miss() {
        // 1e20 + 1 - 1e20 is 0 in f64 but 1 exactly.
        let mut s = ExactSum::new();
        s.add_product(1e10, 1e10, 1.0, false);
        s.add_product(1.0, 1.0, 1.0, false);
        s.add_product(1e10, 1e10, 1.0, true);
        assert_eq!(s.sign(), 1);
        // (0.1 * 0.1 * 0.1) - (0.1 * 0.1 * 0.1) == 0 exactly, in any order.
        let mut s = ExactSum::new();
        s.add_product(0.1, 0.1, 0.1, false);
        s.add_product(0.1, 0.1, 0.1, true);
        assert_eq!(s.sign(), 0);
        // 0.1*0.3*0.7 vs 0.3*0.7*0.1: the same real number, so zero exactly.
        let mut s = ExactSum::new();
        s.add_product(0.1, 0.3, 0.7, false);
        s.add_product(0.3, 0.7, 0.1, true);
        assert_eq!(s.sign(), 0);
    }

    #[test]
    fn det3_matches_integer_determinant() {
        let mut s = ExactSum::new();
        s.add_det3([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
        assert_eq!(s.sign(), 1);
        let mut s = ExactSum::new();
        s.add_det3([0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]);
        assert_eq!(s.sign(), -1);
        // Singular: third row = first + second, with awkward decimals.
        let a = [0.1, 0.2, 0.3];
        let b = [0.7, 0.11, 0.13];
        let mut s = ExactSum::new();
        s.add_det3(a, b, [0.8, 0.31, 0.43]);
        // 0.1+0.7 etc. are not exact in f64, so the sign is whatever it truly is; compare
        // with the negated copy for antisymmetry.
        let mut t = ExactSum::new();
        t.add_det3(b, a, [0.8, 0.31, 0.43]);
        assert_eq!(s.sign(), -t.sign());
    }
}
