//! Quadrature on the reference triangle and tetrahedron, and the areas and volumes of
//! curved (P2) elements and closed surfaces computed with it.
//!
//! Conventions: integrals are over the reference elements themselves, so the triangle
//! rule's weights sum to 1/2 (the reference triangle's area) and the tetrahedron rule's
//! to 1/6 (the reference tet's volume); `sum_q w_q f(p_q)` approximates `∫ f`.
//!
//! Sums over many elements use Neumaier's compensated summation ([`CompensatedSum`]), so
//! a closed surface's volume is accurate to ~1e-15 relative plus the per-element rounding,
//! independent of the number of triangles; contributions are taken about a point of the
//! surface, not the origin, so translating a model does not cost digits.

use super::bezier::{is_straight, LinearJacobian};
use super::shape::{tri6_normal, tri6_point};
use super::vec3::{det3, dot, norm, sub, tet_det, P3};

/// Dunavant's degree-6, 12-point rule on the reference triangle {u, v >= 0, u + v <= 1}
/// (D. A. Dunavant, "High degree efficient symmetrical Gaussian quadrature rules for the
/// triangle", IJNME 21, 1985, rule 6), as used by the paper for curved areas.
/// Rows are (u, v, weight); **weights sum to 1/2**. The constants were re-solved from the
/// moment equations to 40 digits and rounded to the nearest f64 (Dunavant's 15-digit table
/// agrees), so every monomial of degree <= 6 is integrated to f64 rounding.
pub const TRI_DUNAVANT6: [[f64; 3]; 12] = [
    [
        0.24928674517091043,
        0.24928674517091043,
        0.058393137863189684,
    ],
    [
        0.24928674517091043,
        0.5014265096581791,
        0.058393137863189684,
    ],
    [
        0.5014265096581791,
        0.24928674517091043,
        0.058393137863189684,
    ],
    [
        0.06308901449150223,
        0.06308901449150223,
        0.02542245318510341,
    ],
    [0.06308901449150223, 0.8738219710169955, 0.02542245318510341],
    [0.8738219710169955, 0.06308901449150223, 0.02542245318510341],
    [0.3103524510337844, 0.6365024991213987, 0.041425537809186785],
    [0.6365024991213987, 0.3103524510337844, 0.041425537809186785],
    [
        0.053145049844816945,
        0.6365024991213987,
        0.041425537809186785,
    ],
    [
        0.6365024991213987,
        0.053145049844816945,
        0.041425537809186785,
    ],
    [
        0.053145049844816945,
        0.3103524510337844,
        0.041425537809186785,
    ],
    [
        0.3103524510337844,
        0.053145049844816945,
        0.041425537809186785,
    ],
];

/// A 14-point, degree-5 rule with positive weights on the reference tetrahedron
/// (J. Walkington, "Quadrature on simplices of arbitrary dimension", CMU report 2000;
/// also tabulated in C. A. Felippa, *Advanced Finite Element Methods*, ch. 17): two
/// 4-point orbits (a, a, a, 1-3a) and one 6-point orbit (a, a, 1/2-a, 1/2-a).
/// Rows are (xi, eta, zeta, weight); **weights sum to 1/6**. Exact for quintics, so
/// for the cubic det J of a P2 tet with room to spare. Constants re-solved from the
/// moment equations to 40 digits and rounded to the nearest f64.
pub const TET_DEG5_14: [[f64; 4]; 14] = [
    [
        0.09273525031089122,
        0.09273525031089122,
        0.09273525031089122,
        0.012248840519393659,
    ],
    [
        0.7217942490673264,
        0.09273525031089122,
        0.09273525031089122,
        0.012248840519393659,
    ],
    [
        0.09273525031089122,
        0.7217942490673264,
        0.09273525031089122,
        0.012248840519393659,
    ],
    [
        0.09273525031089122,
        0.09273525031089122,
        0.7217942490673264,
        0.012248840519393659,
    ],
    [
        0.3108859192633006,
        0.3108859192633006,
        0.3108859192633006,
        0.018781320953002643,
    ],
    [
        0.06734224221009817,
        0.3108859192633006,
        0.3108859192633006,
        0.018781320953002643,
    ],
    [
        0.3108859192633006,
        0.06734224221009817,
        0.3108859192633006,
        0.018781320953002643,
    ],
    [
        0.3108859192633006,
        0.3108859192633006,
        0.06734224221009817,
        0.018781320953002643,
    ],
    [
        0.04550370412564965,
        0.45449629587435036,
        0.45449629587435036,
        0.007091003462846911,
    ],
    [
        0.45449629587435036,
        0.04550370412564965,
        0.45449629587435036,
        0.007091003462846911,
    ],
    [
        0.45449629587435036,
        0.45449629587435036,
        0.04550370412564965,
        0.007091003462846911,
    ],
    [
        0.04550370412564965,
        0.04550370412564965,
        0.45449629587435036,
        0.007091003462846911,
    ],
    [
        0.04550370412564965,
        0.45449629587435036,
        0.04550370412564965,
        0.007091003462846911,
    ],
    [
        0.45449629587435036,
        0.04550370412564965,
        0.04550370412564965,
        0.007091003462846911,
    ],
];

/// Neumaier's compensated sum: the error is ~2 ulp of the result plus O(n u^2) of the
/// sum of magnitudes, instead of O(n u) for a plain loop. Cheap (a few flops per term).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CompensatedSum {
    sum: f64,
    comp: f64,
}

impl CompensatedSum {
    /// An empty sum (0).
    #[inline]
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds one term.
    #[inline]
    pub fn add(&mut self, v: f64) {
        let t = self.sum + v;
        if self.sum.abs() >= v.abs() {
            self.comp += (self.sum - t) + v;
        } else {
            self.comp += (v - t) + self.sum;
        }
        self.sum = t;
    }

    /// Adds another partial sum (for combining per-thread partial sums).
    #[inline]
    pub fn merge(&mut self, other: &CompensatedSum) {
        self.add(other.sum);
        self.comp += other.comp;
    }

    /// The current value of the sum.
    #[inline]
    pub fn value(&self) -> f64 {
        self.sum + self.comp
    }
}

impl std::iter::FromIterator<f64> for CompensatedSum {
    fn from_iter<I: IntoIterator<Item = f64>>(iter: I) -> Self {
        let mut s = CompensatedSum::new();
        for v in iter {
            s.add(v);
        }
        s
    }
}

/// Area of the curved 6-node triangle `x` (Gmsh order): the integral of |dx/du x dx/dv|
/// by [`TRI_DUNAVANT6`]. The integrand is not a polynomial, so this is approximate for
/// curved triangles (exact for flat ones); on a P2 sphere the total area converges at
/// the geometric order h^4, i.e. the quadrature error is not what limits it.
#[inline]
pub fn tri6_area(x: &[P3; 6]) -> f64 {
    let mut a = 0.0;
    for q in &TRI_DUNAVANT6 {
        a += q[2] * norm(tri6_normal(x, q[0], q[1]));
    }
    a
}

/// (1/3) ∫ x · n dA over the curved triangle `x` (n the unit normal by the right-hand
/// rule): its contribution to the volume enclosed by a closed surface (divergence
/// theorem). The integrand x · (x_u × x_v) has degree 4, so the rule is exact.
#[inline]
pub fn tri6_volume_contribution(x: &[P3; 6]) -> f64 {
    let mut s = 0.0;
    for q in &TRI_DUNAVANT6 {
        s += q[2] * dot(tri6_point(x, q[0], q[1]), tri6_normal(x, q[0], q[1]));
    }
    s / 3.0
}

/// Fetches the six nodes of a P2 triangle relative to `origin`; None if an index is out
/// of range.
#[inline]
fn gather6(nodes: &[P3], t: &[u32; 6], origin: P3) -> Option<[P3; 6]> {
    let mut x = [[0.0; 3]; 6];
    for (xi, &i) in x.iter_mut().zip(t.iter()) {
        *xi = sub(*nodes.get(i as usize)?, origin);
    }
    Some(x)
}

/// Volume enclosed by the closed curved surface `tris` (6-node triangles indexing
/// `nodes`, Gmsh order): positive when the triangles are oriented outward. Exact up to
/// rounding for P2 geometry. Returns NaN if an index is out of range; 0 for no triangles.
pub fn enclosed_volume(nodes: &[P3], tris: &[[u32; 6]]) -> f64 {
    let Some(origin) = surface_origin(nodes, tris.first().map(|t| t[0])) else {
        return if tris.is_empty() { 0.0 } else { f64::NAN };
    };
    let mut s = CompensatedSum::new();
    for t in tris {
        match gather6(nodes, t, origin) {
            Some(x) => s.add(tri6_volume_contribution(&x)),
            None => return f64::NAN,
        }
    }
    s.value()
}

/// Total area of the curved triangles `tris` (see [`tri6_area`]). NaN if an index is out
/// of range.
pub fn surface_area(nodes: &[P3], tris: &[[u32; 6]]) -> f64 {
    let mut s = CompensatedSum::new();
    for t in tris {
        match gather6(nodes, t, [0.0; 3]) {
            Some(x) => s.add(tri6_area(&x)),
            None => return f64::NAN,
        }
    }
    s.value()
}

fn surface_origin(nodes: &[P3], first: Option<u32>) -> Option<P3> {
    nodes.get(first? as usize).copied()
}

/// Volume enclosed by the flat triangles on the first three indices of each entry of
/// `tris` (pass `[u32; 3]` triangles, or `[u32; 6]` P2 triangles to use their chords):
/// sum of det[a, b, c] / 6 about a surface point. Positive for outward orientation. NaN if
/// an index is out of range (or an entry has fewer than 3 indices); 0 for no triangles.
pub fn enclosed_volume_linear<T: AsRef<[u32]>>(nodes: &[P3], tris: &[T]) -> f64 {
    let first = tris.first().and_then(|t| t.as_ref().first().copied());
    let Some(origin) = surface_origin(nodes, first) else {
        return if tris.is_empty() { 0.0 } else { f64::NAN };
    };
    let mut s = CompensatedSum::new();
    for t in tris {
        let t = t.as_ref();
        if t.len() < 3 {
            return f64::NAN;
        }
        let mut p = [[0.0; 3]; 3];
        for k in 0..3 {
            match nodes.get(t[k] as usize) {
                Some(n) => p[k] = sub(*n, origin),
                None => return f64::NAN,
            }
        }
        s.add(det3(p[0], p[1], p[2]) / 6.0);
    }
    s.value()
}

/// Volume of the curved 10-node tet `x` (Gmsh order): ∫ det J over the reference tet by
/// [`TET_DEG5_14`]. det J is a cubic, so this is exact up to rounding; negative for an
/// inverted element. For a straight-sided tet it equals det[v1-v0, v2-v0, v3-v0] / 6.
#[inline]
pub fn tet10_volume(x: &[P3; 10]) -> f64 {
    if is_straight(x) {
        return tet_det(x[0], x[1], x[2], x[3]) / 6.0;
    }
    let lj = LinearJacobian::new(x);
    let mut v = 0.0;
    for q in &TET_DEG5_14 {
        v += q[3] * lj.det([q[0], q[1], q[2]]);
    }
    v
}

#[cfg(test)]
mod tests {
    use super::super::shape::{straight_tet10, tet10_det_jacobian};
    use super::super::testutil::random_curved;
    use super::super::vec3::{add, mid, tet_det};
    use super::*;
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};
    use std::f64::consts::PI;

    fn fact(n: u32) -> f64 {
        (1..=n).map(f64::from).product()
    }

    #[test]
    fn triangle_rule_is_exact_to_degree_6() {
        let ws: f64 = TRI_DUNAVANT6.iter().map(|q| q[2]).sum();
        assert!((ws - 0.5).abs() < 1e-16);
        for i in 0..=6u32 {
            for j in 0..=6 - i {
                let exact = fact(i) * fact(j) / fact(i + j + 2);
                let got: f64 = TRI_DUNAVANT6
                    .iter()
                    .map(|q| q[2] * q[0].powi(i as i32) * q[1].powi(j as i32))
                    .sum();
                assert!((got - exact).abs() < 1e-16, "u^{i} v^{j}: {got} vs {exact}");
            }
        }
        assert!(TRI_DUNAVANT6
            .iter()
            .all(|q| q[2] > 0.0 && q[0] + q[1] < 1.0));
    }

    #[test]
    fn tet_rule_is_exact_to_degree_5_with_positive_weights() {
        let ws: f64 = TET_DEG5_14.iter().map(|q| q[3]).sum();
        assert!((ws - 1.0 / 6.0).abs() < 1e-16);
        assert!(TET_DEG5_14.iter().all(|q| q[3] > 0.0));
        for i in 0..=5u32 {
            for j in 0..=5 - i {
                for k in 0..=5 - i - j {
                    let exact = fact(i) * fact(j) * fact(k) / fact(i + j + k + 3);
                    let got: f64 = TET_DEG5_14
                        .iter()
                        .map(|q| {
                            q[3] * q[0].powi(i as i32) * q[1].powi(j as i32) * q[2].powi(k as i32)
                        })
                        .sum();
                    assert!((got - exact).abs() < 1e-17, "{i}{j}{k}: {got} vs {exact}");
                }
            }
        }
    }

    #[test]
    fn compensated_sum_beats_naive() {
        // 1 + 1e-16 * 1e6 - 1: naive loses it all.
        let mut s = CompensatedSum::new();
        s.add(1.0);
        for _ in 0..1_000_000 {
            s.add(1e-16);
        }
        s.add(-1.0);
        // The compensation term is itself a plain sum of 1e6 terms: ~1e-11 relative.
        assert!((s.value() - 1e-10).abs() < 1e-9 * 1e-10, "{}", s.value());
        let mut naive = 1.0;
        for _ in 0..1_000_000 {
            naive += 1e-16;
        }
        assert_eq!(naive - 1.0, 0.0);
        let mut a: CompensatedSum = [1e100, 1.0, -1e100].into_iter().collect();
        assert_eq!(a.value(), 1.0);
        a.merge(&[2.0, 1e-30].into_iter().collect());
        assert_eq!(a.value(), 3.0);
    }

    /// Gauss-Legendre nodes and weights on [0, 1] (Newton on P_n), for a collapsed
    /// (Duffy) tensor rule used as an independent high-order reference.
    fn gauss01(n: usize) -> Vec<(f64, f64)> {
        let mut out = Vec::new();
        for i in 0..n {
            let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 0.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            out.push((0.5 * (1.0 - x), 1.0 / ((1.0 - x * x) * dp * dp)));
        }
        out
    }

    /// ∫ f over the reference tet by an n^3-point collapsed Gauss rule.
    fn duffy(n: usize, f: impl Fn([f64; 3]) -> f64) -> f64 {
        let g = gauss01(n);
        let mut s = 0.0;
        for &(a, wa) in &g {
            for &(b, wb) in &g {
                for &(c, wc) in &g {
                    let xi = a;
                    let eta = (1.0 - a) * b;
                    let zeta = (1.0 - a) * (1.0 - b) * c;
                    s += wa * wb * wc * (1.0 - a) * (1.0 - a) * (1.0 - b) * f([xi, eta, zeta]);
                }
            }
        }
        s
    }

    #[test]
    fn tet10_volume_matches_high_order_quadrature() {
        assert!((duffy(6, |_| 1.0) - 1.0 / 6.0).abs() < 1e-15);
        let mut rng = StdRng::seed_from_u64(1);
        for _ in 0..200 {
            let x = random_curved(&mut rng, 0.5);
            let v = tet10_volume(&x);
            let reference = duffy(8, |p| tet10_det_jacobian(&x, p));
            assert!(
                (v - reference).abs() < 1e-13 * reference.abs().max(1.0),
                "{v} vs {reference}"
            );
            // The Bernstein coefficients' mean is the exact integral too.
            let b = super::super::bezier::jacobian_bezier(&x);
            let mean = b.iter().sum::<f64>() / 20.0 / 6.0;
            assert!((v - mean).abs() < 1e-13 * v.abs().max(1.0));
        }
        // Straight tets: corner determinant / 6.
        for _ in 0..100 {
            let c = [
                [rng.random(), rng.random(), rng.random()],
                [rng.random(), rng.random(), rng.random()],
                [rng.random(), rng.random(), rng.random()],
                [rng.random(), rng.random(), rng.random()],
            ];
            let d = tet_det(c[0], c[1], c[2], c[3]) / 6.0;
            let mut x = straight_tet10(c);
            assert_eq!(tet10_volume(&x), d);
            // Off the fast path (one mid node moved by an ulp) the rule agrees.
            x[7][1] = f64::from_bits(x[7][1].to_bits() + 1);
            assert!(
                (tet10_volume(&x) - d).abs() < 1e-15,
                "{} vs {d}",
                tet10_volume(&x)
            );
        }
    }

    #[test]
    fn flat_triangle_area_and_volume() {
        let a = [0.0, 0.0, 1.0];
        let b = [2.0, 0.0, 1.0];
        let c = [0.0, 3.0, 1.0];
        let x = [a, b, c, mid(a, b), mid(b, c), mid(c, a)];
        assert!((tri6_area(&x) - 3.0).abs() < 1e-14);
        // x · n = z * 1 over the plane z = 1: volume contribution area * 1 / 3.
        assert!((tri6_volume_contribution(&x) - 1.0).abs() < 1e-14);
    }

    /// The demo P2 icosphere (`level` 1-to-4 splits, every node on the unit sphere),
    /// translated by `shift`.
    fn p2_sphere(level: u32, shift: P3) -> (Vec<P3>, Vec<[u32; 6]>) {
        let (mut v, tris) = crate::surface::demo::icosphere(level);
        for p in v.iter_mut() {
            *p = add(*p, shift);
        }
        (v, tris)
    }

    #[test]
    fn p2_sphere_converges_at_fourth_order() {
        let va = 4.0 * PI / 3.0;
        let aa = 4.0 * PI;
        let mut prev: Option<(f64, f64, f64)> = None;
        let mut orders = Vec::new();
        for level in 1..=4 {
            let (nodes, tris) = p2_sphere(level, [0.0; 3]);
            let ev = (enclosed_volume(&nodes, &tris) - va).abs() / va;
            let ea = (surface_area(&nodes, &tris) - aa).abs() / aa;
            let el = (enclosed_volume_linear(&nodes, &tris) - va).abs() / va;
            if let Some((pv, pa, pl)) = prev {
                // h halves per level: observed order = log2(error ratio).
                orders.push(((pv / ev).log2(), (pa / ea).log2(), (pl / el).log2()));
            }
            prev = Some((ev, ea, el));
        }
        // Observed orders, levels 1->2, 2->3, 3->4: volume 3.94, 3.99, 4.00; area 3.91,
        // 3.98, 3.99; linear volume 1.90, 1.98, 1.99. Relative errors at level 4 (5120
        // triangles): volume 5.7e-7, area 3.8e-7, linear volume 2.2e-3.
        for (ov, oa, ol) in &orders {
            assert!(*ov > 3.7, "volume order {ov} ({orders:?})");
            assert!(*oa > 3.7, "area order {oa} ({orders:?})");
            assert!(*ol > 1.8 && *ol < 2.3, "linear order {ol} ({orders:?})");
        }
    }

    /// Exactly rounded sum (Shewchuk's partials, as Python's math.fsum).
    fn fsum(values: impl IntoIterator<Item = f64>) -> f64 {
        let mut partials: Vec<f64> = Vec::new();
        for mut x in values {
            let mut i = 0;
            for j in 0..partials.len() {
                let mut y = partials[j];
                if x.abs() < y.abs() {
                    std::mem::swap(&mut x, &mut y);
                }
                let hi = x + y;
                let lo = y - (hi - x);
                if lo != 0.0 {
                    partials[i] = lo;
                    i += 1;
                }
                x = hi;
            }
            partials.truncate(i);
            partials.push(x);
        }
        partials.iter().rev().fold(0.0, |a, b| a + b)
    }

    #[test]
    fn enclosed_volume_is_translation_and_order_invariant() {
        let (nodes, tris) = p2_sphere(6, [0.0; 3]); // 81920 triangles
        let v0 = enclosed_volume(&nodes, &tris);
        // The compensated sum is the exactly rounded sum of the same contributions to
        // within a few ulps.
        let o = nodes[tris[0][0] as usize];
        let exact = fsum(tris.iter().map(|t| {
            let mut x = [[0.0; 3]; 6];
            for k in 0..6 {
                x[k] = sub(nodes[t[k] as usize], o);
            }
            tri6_volume_contribution(&x)
        }));
        assert!(
            (v0 - exact).abs() <= 2.0 * f64::EPSILON * exact,
            "{v0} vs {exact}"
        );
        let (far, _) = p2_sphere(6, [1000.0, -2000.0, 500.0]);
        let v1 = enclosed_volume(&far, &tris);
        // Translating rounds the nodes by ~1e-13: the volume moves by about that much.
        assert!((v0 - v1).abs() < 1e-11 * v0, "{v0} vs {v1}");
        let mut rev = tris.clone();
        rev.reverse();
        let v2 = enclosed_volume(&nodes, &rev);
        assert!((v0 - v2).abs() < 4.0 * f64::EPSILON * v0, "{v0} vs {v2}");
        // Flipping the orientation negates it.
        let flipped: Vec<[u32; 6]> = tris
            .iter()
            .map(|t| [t[0], t[2], t[1], t[5], t[4], t[3]])
            .collect();
        assert!((enclosed_volume(&nodes, &flipped) + v0).abs() < 1e-14 * v0);
        // Linear version with [u32; 3] triangles equals the chord version.
        let lin: Vec<[u32; 3]> = tris.iter().map(|t| [t[0], t[1], t[2]]).collect();
        assert_eq!(
            enclosed_volume_linear(&nodes, &lin),
            enclosed_volume_linear(&nodes, &tris)
        );
        // Bad indices and empty input do not panic.
        assert!(enclosed_volume(&nodes, &[[0, 1, 2, 3, 4, u32::MAX]]).is_nan());
        assert!(enclosed_volume_linear(&nodes, &[[0u32, 1, u32::MAX]]).is_nan());
        assert_eq!(enclosed_volume(&nodes, &[]), 0.0);
        assert_eq!(enclosed_volume_linear::<[u32; 3]>(&nodes, &[]), 0.0);
    }
}
