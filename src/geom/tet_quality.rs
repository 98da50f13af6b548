//! Element quality metrics (paper sections 2.5-2.6) and the summaries a quality report is
//! made of.
//!
//! - Dihedral angles and equiangular skewness (paper eq. 2) from the four corners, as the
//!   paper does for its straight-sided candidates.
//! - Scaled Jacobian min det J / max det J (paper eq. 3): sampled on a lattice, for
//!   comparison with the paper and Gmsh, and as a certified lower bound ([`super::bezier`]).
//!
//! The per-element functions allocate nothing; [`Histogram`] and [`QualitySummary`] are
//! the aggregate side (one allocation per histogram).

use serde::Serialize;

use super::bezier::{
    is_straight, scaled_jacobian_certified, straight_scaled_jacobian, LinearJacobian,
};
use super::quadrature::CompensatedSum;
use super::shape::TET10_EDGES;
use super::vec3::{add, cross, det3, dot, norm, scale, sub, P3};

/// The dihedral angle of the regular tetrahedron, acos(1/3) in degrees (70.5288°):
/// theta_e of the equiangular skewness.
pub const EQUIANGULAR_DIHEDRAL_DEG: f64 = 70.52877936550931;

/// Relative tolerance [`tet_quality`] asks of the certified scaled Jacobian.
pub const DEFAULT_SJ_REL_TOL: f64 = 1e-3;

/// Order of the lattice [`scaled_jacobian_sampled`] samples (84 points, corners included).
pub const SAMPLE_ORDER: usize = 6;

/// Smallest 6 x volume / (longest edge)^3 of a tet the front and the linear stage make:
/// below it a tet is flatter than f64 resolves relative to its size ([`numerically_flat`]).
pub const MIN_RELATIVE_VOLUME: f64 = 1e-12;

/// Is the straight tet `c` numerically flat: 6 x its volume at most
/// [`MIN_RELATIVE_VOLUME`] times its longest edge cubed? Such a tet can be positive by
/// the exact predicate, but its Jacobian cannot be certified.
#[inline]
pub fn numerically_flat(c: &[P3; 4]) -> bool {
    let (det, flat_below, _) = flatness(c);
    det <= flat_below
}

/// The floating-point 6 x volume of the tet `c`, the [`numerically_flat`] threshold
/// [`MIN_RELATIVE_VOLUME`] l³ it is compared with, and l² (l the longest edge).
#[inline]
fn flatness(c: &[P3; 4]) -> (f64, f64, f64) {
    let l2 = TET10_EDGES
        .iter()
        .map(|&[i, j]| super::vec3::dist2(c[i], c[j]))
        .fold(0.0, f64::max);
    let det = super::vec3::tet_det(c[0], c[1], c[2], c[3]);
    (det, MIN_RELATIVE_VOLUME * l2 * l2.sqrt(), l2)
}

/// Whether the straight tet `c` is positive (exact [`orient3d`](super::predicates::orient3d))
/// and not [`numerically_flat`], mostly without the exact predicate (the linear stage
/// asks this of every tet it scores).
///
/// Why f64 decides it: a tet that is not numerically flat has a floating-point
/// determinant above [`MIN_RELATIVE_VOLUME`] l³ (l its longest edge), while that
/// determinant, a dot and a cross product of the three rounded edge vectors from `c[0]`,
/// is off by at most about 10 eps times its permanent, itself at most 6 l³: 7e-15 l³,
/// so the tet is positive exactly; and a numerically flat one is rejected whatever its
/// sign. Where that error bound does not hold (edges so short or long that the products
/// could underflow or overflow, or NaN), the predicate decides as before.
#[inline]
pub fn positive_and_not_flat(c: &[P3; 4]) -> bool {
    let (det, flat_below, l2) = flatness(c);
    let not_flat = det > flat_below;
    if (1e-140..=1e140).contains(&l2) {
        return not_flat;
    }
    super::predicates::orient3d(c[0], c[1], c[2], c[3]) > 0 && not_flat
}

/// Outward (for a positive tet) normals of the faces opposite corners 0, 1, 2, 3.
#[inline]
fn face_normals(c: &[P3; 4]) -> [P3; 4] {
    let n = |a: usize, b: usize, d: usize| cross(sub(c[b], c[a]), sub(c[d], c[a]));
    [n(1, 2, 3), n(0, 3, 2), n(0, 1, 3), n(0, 2, 1)]
}

/// For each edge in [`TET10_EDGES`] order, (s, c) with atan2(s, c) the interior dihedral
/// angle: s = |n_a x n_b| >= 0 and c = -n_a . n_b for the outward normals of the two faces
/// through the edge (the interior angle is pi minus the angle between them).
#[inline]
fn dihedral_sc(c: &[P3; 4]) -> [(f64, f64); 6] {
    let n = face_normals(c);
    let mut out = [(0.0, 0.0); 6];
    for (o, [a, b]) in out.iter_mut().zip(TET10_EDGES.iter()) {
        // The two faces through edge (a, b) are those opposite the other two corners.
        let mut other = [0usize; 2];
        let mut k = 0;
        for v in 0..4 {
            if v != *a && v != *b {
                other[k] = v;
                k += 1;
            }
        }
        let (p, q) = (n[other[0]], n[other[1]]);
        // `+ 0.0` turns -0 into +0, so a degenerate face gives atan2(0, 0) = 0, not 180°.
        *o = (norm(cross(p, q)), -dot(p, q) + 0.0);
    }
    out
}

/// Interior dihedral angles in degrees of the tet with corners `c`, at its six edges in
/// [`TET10_EDGES`] order ((0,1), (1,2), (2,0), (3,0), (3,2), (3,1)). Computed with atan2,
/// so accurate near 0° and 180° too; 0 at an edge next to a degenerate (zero-area) face.
/// Independent of the tet's orientation.
#[inline]
pub fn dihedral_angles(c: &[P3; 4]) -> [f64; 6] {
    let sc = dihedral_sc(c);
    let mut out = [0.0; 6];
    for (o, (s, cs)) in out.iter_mut().zip(sc.iter()) {
        *o = s.atan2(*cs).to_degrees();
    }
    out
}

/// The smallest and largest of [`dihedral_angles`] (degrees), with two atan2 instead of
/// six: the angles are ordered by the sign of s_a c_b - c_a s_b = k sin(theta_a -
/// theta_b), k > 0. Angles equal to within rounding may be picked either way.
#[inline]
pub fn dihedral_extremes(c: &[P3; 4]) -> (f64, f64) {
    let sc = dihedral_sc(c);
    let (mut lo, mut hi) = (0, 0);
    for (i, (s, cs)) in sc.iter().enumerate() {
        if s.is_nan() || cs.is_nan() {
            return (f64::NAN, f64::NAN);
        }
        // theta_i < theta_lo ?
        if s * sc[lo].1 - cs * sc[lo].0 < 0.0 {
            lo = i;
        }
        if s * sc[hi].1 - cs * sc[hi].0 > 0.0 {
            hi = i;
        }
    }
    (
        sc[lo].0.atan2(sc[lo].1).to_degrees(),
        sc[hi].0.atan2(sc[hi].1).to_degrees(),
    )
}

/// The interior dihedral angle (degrees) at edge (u, v) of the tet (u, v, a, b): the
/// angle between the half-planes bounded by the line uv through `a` and through `b`, in
/// [0, 180], whatever the tet's orientation. One atan2, for callers that need one edge.
#[inline]
pub fn dihedral_at_edge(u: P3, v: P3, a: P3, b: P3) -> f64 {
    let e = sub(v, u);
    // e x w turns w's component across e by 90 degrees about e: the angle between the
    // normals is the angle between the half-planes.
    let (na, nb) = (cross(e, sub(a, u)), cross(e, sub(b, u)));
    norm(cross(na, nb)).atan2(dot(na, nb) + 0.0).to_degrees()
}

/// Equiangular skewness from the smallest and largest dihedral angles (degrees): paper
/// eq. 2, max[(θmax − θe)/(180 − θe), (θe − θmin)/θe].
#[inline]
pub fn skewness_from_extremes(min_deg: f64, max_deg: f64) -> f64 {
    let te = EQUIANGULAR_DIHEDRAL_DEG;
    if min_deg.is_nan() || max_deg.is_nan() {
        return f64::NAN;
    }
    ((max_deg - te) / (180.0 - te)).max((te - min_deg) / te)
}

/// Equiangular skewness, paper eq. 2: max[(θmax − θe)/(180 − θe), (θe − θmin)/θe] over
/// the six dihedral angles (degrees), θe = [`EQUIANGULAR_DIHEDRAL_DEG`]. 0 for the regular
/// tet, → 1 for slivers, needles and caps. NaN angles give NaN.
#[inline]
pub fn equiangular_skewness(angles: &[f64; 6]) -> f64 {
    let (mut lo, mut hi) = (angles[0], angles[0]);
    for &a in angles {
        if a.is_nan() {
            return f64::NAN;
        }
        lo = lo.min(a);
        hi = hi.max(a);
    }
    skewness_from_extremes(lo, hi)
}

/// Scaled Jacobian min det J / max det J over the order-[`SAMPLE_ORDER`] lattice of the
/// reference tet (84 points, corners included): what the paper and Gmsh-style tools
/// report. An *estimate* (the true minimum can be lower between samples); use
/// [`scaled_jacobian_certified`] for a guaranteed bound. Exactly 1 for a straight-sided
/// tet; -1 by convention when no sample is positive and some is negative, 0 when the
/// largest is 0.
pub fn scaled_jacobian_sampled(x: &[P3; 10]) -> f64 {
    if is_straight(x) {
        return straight_scaled_jacobian(x);
    }
    // Columns of dx/dxi are linear: walk the lattice adding constant steps (9 adds and
    // one 3x3 determinant per point).
    let c = LinearJacobian::new(x).cols;
    let n = SAMPLE_ORDER;
    let h = 1.0 / n as f64;
    let mut step = [[[0.0; 3]; 3]; 3]; // step[axis][column]
    for (axis, st) in step.iter_mut().enumerate() {
        for (d, s) in st.iter_mut().enumerate() {
            *s = scale(sub(c[d][axis + 1], c[d][0]), h);
        }
    }
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for i in 0..=n {
        for j in 0..=n - i {
            let mut col = [[0.0; 3]; 3];
            for (d, cd) in col.iter_mut().enumerate() {
                *cd = add(
                    c[d][0],
                    add(scale(step[0][d], i as f64), scale(step[1][d], j as f64)),
                );
            }
            for _ in 0..=n - i - j {
                let v = det3(col[0], col[1], col[2]);
                if v.is_nan() {
                    return f64::NAN;
                }
                lo = lo.min(v);
                hi = hi.max(v);
                for (cd, st) in col.iter_mut().zip(step[2].iter()) {
                    *cd = add(*cd, *st);
                }
            }
        }
    }
    if hi > 0.0 {
        lo / hi
    } else if lo < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// All quality measures of one P2 tet.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct TetQuality {
    /// min J / max J on the sample lattice ([`scaled_jacobian_sampled`]).
    pub scaled_jacobian: f64,
    /// Certified lower bound on min J / max J ([`scaled_jacobian_certified`] at
    /// [`DEFAULT_SJ_REL_TOL`]).
    pub scaled_jacobian_certified: f64,
    /// Equiangular skewness of the corner tet (paper eq. 2).
    pub skewness: f64,
    /// Smallest dihedral angle of the corner tet, degrees.
    pub min_dihedral: f64,
    /// Largest dihedral angle of the corner tet, degrees.
    pub max_dihedral: f64,
}

/// Every quality measure of the 10-node tet `x` (Gmsh order). Dihedral angles and
/// skewness use the four corners only, as the paper does.
pub fn tet_quality(x: &[P3; 10]) -> TetQuality {
    let (lo, hi) = dihedral_extremes(&[x[0], x[1], x[2], x[3]]);
    TetQuality {
        scaled_jacobian: scaled_jacobian_sampled(x),
        scaled_jacobian_certified: scaled_jacobian_certified(x, DEFAULT_SJ_REL_TOL),
        skewness: skewness_from_extremes(lo, hi),
        min_dihedral: lo,
        max_dihedral: hi,
    }
}

/// Counts of values in `bins` equal-width bins over [lo, hi] (hi itself goes to the last
/// bin), plus values below, above, and NaN.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Histogram {
    /// Lower end of the first bin.
    pub lo: f64,
    /// Upper end of the last bin.
    pub hi: f64,
    /// Count per bin; bin i covers [lo + i w, lo + (i+1) w), w = (hi - lo) / bins.
    pub counts: Vec<u64>,
    /// Values < lo.
    pub below: u64,
    /// Values > hi.
    pub above: u64,
    /// NaN values.
    pub nan: u64,
}

impl Histogram {
    /// An empty histogram of `bins` bins (at least 1) over [lo, hi].
    pub fn new(lo: f64, hi: f64, bins: usize) -> Self {
        Histogram {
            lo,
            hi,
            counts: vec![0; bins.max(1)],
            below: 0,
            above: 0,
            nan: 0,
        }
    }

    /// Counts one value.
    #[inline]
    pub fn add(&mut self, v: f64) {
        self.add_n(v, 1);
    }

    /// Counts `n` copies of a value.
    #[inline]
    pub fn add_n(&mut self, v: f64, n: u64) {
        if v.is_nan() {
            self.nan += n;
        } else if v < self.lo {
            self.below += n;
        } else if v > self.hi {
            self.above += n;
        } else {
            let len = self.counts.len();
            // `as usize` saturates (NaN from a zero-width range -> bin 0).
            let i = (((v - self.lo) / (self.hi - self.lo)) * len as f64) as usize;
            self.counts[i.min(len - 1)] += n;
        }
    }

    /// Adds the counts of `other`. With the same range and bins this is exact; otherwise
    /// `other`'s bins are re-binned by their centres.
    pub fn merge(&mut self, other: &Histogram) {
        if other.counts.len() == self.counts.len() && other.lo == self.lo && other.hi == self.hi {
            for (a, b) in self.counts.iter_mut().zip(other.counts.iter()) {
                *a += b;
            }
            self.below += other.below;
            self.above += other.above;
        } else {
            let w = (other.hi - other.lo) / other.counts.len() as f64;
            for (i, &c) in other.counts.iter().enumerate() {
                self.add_n(other.lo + (i as f64 + 0.5) * w, c);
            }
            self.add_n(f64::NEG_INFINITY, other.below);
            self.add_n(f64::INFINITY, other.above);
        }
        self.nan += other.nan;
    }

    /// Number of values counted (including below/above/NaN).
    pub fn total(&self) -> u64 {
        self.counts.iter().sum::<u64>() + self.below + self.above + self.nan
    }

    /// Fraction of counted values strictly greater than `t` at bin resolution (bins
    /// entirely above t, plus `above`): "0.3% of elements have skewness > 0.9".
    pub fn fraction_above(&self, t: f64) -> f64 {
        let total = self.total();
        if total == 0 {
            return 0.0;
        }
        let w = (self.hi - self.lo) / self.counts.len() as f64;
        let mut n = self.above;
        for (i, &c) in self.counts.iter().enumerate() {
            if self.lo + i as f64 * w >= t {
                n += c;
            }
        }
        n as f64 / total as f64
    }
}

/// min / max / mean and a histogram of one quality measure over a mesh. NaN values are
/// counted in the histogram only.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct QualitySummary {
    /// Number of (non-NaN) values.
    pub count: u64,
    /// Smallest value (+inf when empty).
    pub min: f64,
    /// Largest value (-inf when empty).
    pub max: f64,
    /// Mean value (NaN when empty).
    pub mean: f64,
    /// Distribution of the values.
    pub histogram: Histogram,
    #[serde(skip)]
    sum: CompensatedSum,
}

impl QualitySummary {
    /// An empty summary whose histogram has `bins` bins over [lo, hi].
    pub fn new(lo: f64, hi: f64, bins: usize) -> Self {
        QualitySummary {
            count: 0,
            min: f64::INFINITY,
            max: f64::NEG_INFINITY,
            mean: f64::NAN,
            histogram: Histogram::new(lo, hi, bins),
            sum: CompensatedSum::new(),
        }
    }

    /// A summary of `values`.
    pub fn from_values(
        values: impl IntoIterator<Item = f64>,
        lo: f64,
        hi: f64,
        bins: usize,
    ) -> Self {
        let mut s = QualitySummary::new(lo, hi, bins);
        for v in values {
            s.add(v);
        }
        s
    }

    /// Adds one value.
    #[inline]
    pub fn add(&mut self, v: f64) {
        self.histogram.add(v);
        if v.is_nan() {
            return;
        }
        self.count += 1;
        self.min = self.min.min(v);
        self.max = self.max.max(v);
        self.sum.add(v);
        self.mean = self.sum.value() / self.count as f64;
    }

    /// Adds another summary (for per-thread partial summaries; merge in a fixed order
    /// for bit-reproducible means).
    pub fn merge(&mut self, other: &QualitySummary) {
        self.histogram.merge(&other.histogram);
        self.count += other.count;
        self.min = self.min.min(other.min);
        self.max = self.max.max(other.max);
        self.sum.merge(&other.sum);
        self.mean = if self.count > 0 {
            self.sum.value() / self.count as f64
        } else {
            f64::NAN
        };
    }
}

/// Summaries of every measure of [`TetQuality`] over a mesh, with the report's bins:
/// scaled Jacobians and skewness over [0, 1] in 20 bins, dihedral angles over [0, 180]
/// in 36 bins.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct TetQualitySummary {
    /// Sampled scaled Jacobian.
    pub scaled_jacobian: QualitySummary,
    /// Certified lower bound of the scaled Jacobian.
    pub scaled_jacobian_certified: QualitySummary,
    /// Equiangular skewness.
    pub skewness: QualitySummary,
    /// Smallest dihedral angle per element, degrees.
    pub min_dihedral: QualitySummary,
    /// Largest dihedral angle per element, degrees.
    pub max_dihedral: QualitySummary,
}

impl Default for TetQualitySummary {
    fn default() -> Self {
        Self::new()
    }
}

impl TetQualitySummary {
    /// Empty summaries.
    pub fn new() -> Self {
        TetQualitySummary {
            scaled_jacobian: QualitySummary::new(0.0, 1.0, 20),
            scaled_jacobian_certified: QualitySummary::new(0.0, 1.0, 20),
            skewness: QualitySummary::new(0.0, 1.0, 20),
            min_dihedral: QualitySummary::new(0.0, 180.0, 36),
            max_dihedral: QualitySummary::new(0.0, 180.0, 36),
        }
    }

    /// Adds one element's measures.
    pub fn add(&mut self, q: &TetQuality) {
        self.scaled_jacobian.add(q.scaled_jacobian);
        self.scaled_jacobian_certified
            .add(q.scaled_jacobian_certified);
        self.skewness.add(q.skewness);
        self.min_dihedral.add(q.min_dihedral);
        self.max_dihedral.add(q.max_dihedral);
    }

    /// Adds another summary.
    pub fn merge(&mut self, o: &TetQualitySummary) {
        self.scaled_jacobian.merge(&o.scaled_jacobian);
        self.scaled_jacobian_certified
            .merge(&o.scaled_jacobian_certified);
        self.skewness.merge(&o.skewness);
        self.min_dihedral.merge(&o.min_dihedral);
        self.max_dihedral.merge(&o.max_dihedral);
    }
}

#[cfg(test)]
mod tests {
    use super::super::bezier::jacobian_bounds;
    use super::super::shape::{straight_tet10, tet10_det_jacobian};
    use super::super::testutil::{lattice, random_corners, random_curved};
    use super::*;
    use rand::rngs::StdRng;
    use rand::SeedableRng;

    /// `positive_and_not_flat` is exactly "positive by the exact predicate and not
    /// numerically flat": on random tets, on tets flattened towards and past the
    /// threshold, inverted ones, and at scales where the predicate decides.
    #[test]
    fn positive_and_not_flat_is_the_predicate_and_the_flatness_test() {
        use crate::geom::predicates::orient3d;
        use rand::Rng;
        let mut rng = StdRng::seed_from_u64(17);
        let (mut yes, mut flat, mut neg) = (0, 0, 0);
        for i in 0..200_000 {
            let unit = [1.0, 1e-3, 1e5, 1e-80, 1e80][i % 5];
            let mut c: [P3; 4] =
                std::array::from_fn(|_| std::array::from_fn(|_| rng.random_range(-1.0..1.0)));
            // Flatten: the last corner onto the plane of the others, then off it by a
            // height across the threshold.
            if i % 3 != 0 {
                let n = cross(sub(c[1], c[0]), sub(c[2], c[0]));
                let nn = dot(n, n).sqrt();
                let h = dot(sub(c[3], c[0]), n) / nn;
                let off = [1e-9, 1e-11, 1e-12, 3e-13, 1e-14, 0.0][rng.random_range(0..6)];
                let off = off * if rng.random_bool(0.5) { 1.0 } else { -1.0 };
                c[3] = add(c[3], scale(n, (off - h) / nn));
            }
            let c = c.map(|p| p.map(|x| x * unit));
            let want = orient3d(c[0], c[1], c[2], c[3]) > 0 && !numerically_flat(&c);
            assert_eq!(positive_and_not_flat(&c), want, "{c:?}");
            if want {
                yes += 1;
            } else if orient3d(c[0], c[1], c[2], c[3]) > 0 {
                flat += 1;
            } else {
                neg += 1;
            }
        }
        assert!(
            yes > 1000 && flat > 1000 && neg > 1000,
            "{yes} {flat} {neg}"
        );
    }

    #[test]
    fn theta_e_is_acos_one_third() {
        assert!(((1.0f64 / 3.0).acos().to_degrees() - EQUIANGULAR_DIHEDRAL_DEG).abs() < 1e-13);
    }

    #[test]
    fn dihedral_at_edge_matches_dihedral_angles() {
        use rand::Rng;
        let mut rng = StdRng::seed_from_u64(5);
        for n in 0..400 {
            // Well-shaped tets, then any four points (either orientation, slivers too).
            let c = if n % 2 == 0 {
                random_corners(&mut rng)
            } else {
                std::array::from_fn(|_| std::array::from_fn(|_| rng.random_range(-1.0..1.0)))
            };
            let a = dihedral_angles(&c);
            for (k, [i, j]) in TET10_EDGES.iter().enumerate() {
                let o: Vec<usize> = (0..4).filter(|x| x != i && x != j).collect();
                for (x, y) in [(o[0], o[1]), (o[1], o[0])] {
                    let d = dihedral_at_edge(c[*i], c[*j], c[x], c[y]);
                    assert!((d - a[k]).abs() < 1e-9, "{d} {}", a[k]);
                    let d = dihedral_at_edge(c[*j], c[*i], c[x], c[y]);
                    assert!((d - a[k]).abs() < 1e-9, "{d} {}", a[k]);
                }
            }
        }
    }

    #[test]
    fn regular_tet_is_equiangular() {
        let c = [
            [1.0, 1.0, 1.0],
            [-1.0, -1.0, 1.0],
            [1.0, -1.0, -1.0],
            [-1.0, 1.0, -1.0],
        ];
        let a = dihedral_angles(&c);
        for v in a {
            assert!((v - EQUIANGULAR_DIHEDRAL_DEG).abs() < 1e-12, "{v}");
        }
        assert!(equiangular_skewness(&a) < 1e-13);
    }

    #[test]
    fn right_corner_tet_hand_values() {
        let c = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ];
        let a = dihedral_angles(&c);
        // Edges at the right corner ((0,1), (2,0), (3,0)) are 90°; edges of the slanted
        // face ((1,2), (3,2), (3,1)) are acos(1/sqrt 3) = 54.7356°.
        let slant = 54.735610317245346;
        let want = [90.0, slant, 90.0, 90.0, slant, slant];
        for (g, w) in a.iter().zip(want.iter()) {
            assert!((g - w).abs() < 1e-12, "{a:?}");
        }
        let te = EQUIANGULAR_DIHEDRAL_DEG;
        let s = equiangular_skewness(&a);
        let want_s = ((90.0 - te) / (180.0 - te)).max((te - slant) / te);
        assert!((s - want_s).abs() < 1e-15);
        // Hand value: the 54.74° angles dominate, (70.5288 - 54.7356) / 70.5288 = 0.22393
        // (the 90° ones give only (90 - 70.5288) / 109.4712 = 0.17787).
        assert!((s - 0.223_925).abs() < 1e-5);
        // Orientation does not change the angles.
        let b = dihedral_angles(&[c[1], c[0], c[2], c[3]]);
        let mut sa = a;
        let mut sb = b;
        sa.sort_by(f64::total_cmp);
        sb.sort_by(f64::total_cmp);
        for (x, y) in sa.iter().zip(sb.iter()) {
            assert!((x - y).abs() < 1e-12);
        }
    }

    #[test]
    fn extremes_match_all_angles() {
        let mut rng = StdRng::seed_from_u64(4);
        for _ in 0..1000 {
            let c = random_corners(&mut rng);
            let x = straight_tet10(c);
            let a = dihedral_angles(&c);
            let lo = a.iter().cloned().fold(f64::INFINITY, f64::min);
            let hi = a.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
            let (elo, ehi) = dihedral_extremes(&c);
            assert!((elo - lo).abs() < 1e-12 && (ehi - hi).abs() < 1e-12);
            let q = tet_quality(&x);
            assert!((q.skewness - equiangular_skewness(&a)).abs() < 1e-14);
            // Angle sum identities hold loosely: each angle is in (0, 180).
            assert!(lo > 0.0 && hi < 180.0);
        }
        // Degenerate: a repeated corner gives 0 angles, not 180.
        let d = dihedral_angles(&[[0.0; 3], [0.0; 3], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
        assert!(d.iter().all(|v| v.is_finite()));
        assert_eq!(d[0], 0.0);
    }

    #[test]
    fn sampled_matches_direct_lattice_evaluation() {
        let mut rng = StdRng::seed_from_u64(6);
        let pts = lattice(SAMPLE_ORDER);
        assert_eq!(pts.len(), 84);
        for _ in 0..200 {
            let x = random_curved(&mut rng, 0.2);
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            for p in &pts {
                let v = tet10_det_jacobian(&x, *p);
                lo = lo.min(v);
                hi = hi.max(v);
            }
            let want = if hi > 0.0 { lo / hi } else { -1.0 };
            let got = scaled_jacobian_sampled(&x);
            assert!((got - want).abs() < 1e-12, "{got} vs {want}");
        }
    }

    #[test]
    fn sliver_skewness_near_one() {
        // Four nearly coplanar points on a square's corners, alternate heights.
        let e = 0.01;
        let c = [
            [0.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [1.0, 0.0, e],
            [0.0, 1.0, e],
        ];
        let a = dihedral_angles(&c);
        let lo = a.iter().cloned().fold(f64::INFINITY, f64::min);
        let hi = a.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        assert!(lo < 2.0 && hi > 178.0, "{a:?}");
        let s = equiangular_skewness(&a);
        assert!(s > 0.97 && s <= 1.0, "{s}");
        // Paper fig. 4: min dihedral 22° ↔ skewness ~0.68, 45° ↔ ~0.36 (when the
        // minimum dominates): (70.53 - 22) / 70.53 = 0.688, (70.53 - 45) / 70.53 = 0.362.
        let f = |m: f64| equiangular_skewness(&[m, 70.0, 70.0, 70.0, 70.0, 90.0]);
        assert!((f(22.0) - 0.688).abs() < 1e-3);
        assert!((f(45.0) - 0.362).abs() < 1e-3);
    }

    #[test]
    fn straight_tet_scaled_jacobian_is_exactly_one() {
        let c = [
            [0.1, 0.2, 0.3],
            [1.3, 0.1, 0.2],
            [0.2, 1.1, 0.1],
            [0.3, 0.4, 0.9],
        ];
        let x = straight_tet10(c);
        assert_eq!(scaled_jacobian_sampled(&x), 1.0);
        let q = tet_quality(&x);
        assert_eq!(q.scaled_jacobian, 1.0);
        assert_eq!(q.scaled_jacobian_certified, 1.0);
        assert!(q.min_dihedral > 0.0 && q.max_dihedral < 180.0);
    }

    #[test]
    fn sampled_sits_between_certified_and_dense() {
        let mut rng = StdRng::seed_from_u64(42);
        let dense = lattice(12);
        for _ in 0..300 {
            let x = random_curved(&mut rng, 0.3);
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            for p in &dense {
                let v = tet10_det_jacobian(&x, *p);
                lo = lo.min(v);
                hi = hi.max(v);
            }
            if lo <= 0.0 {
                continue;
            }
            let q = tet_quality(&x);
            let dense_sj = lo / hi;
            assert!(q.scaled_jacobian_certified <= dense_sj + 1e-12);
            // The order-6 lattice is a subset of the order-12 one: never lower.
            assert!(q.scaled_jacobian >= dense_sj - 1e-12);
            assert!(q.scaled_jacobian <= 1.0);
            let jb = jacobian_bounds(&x, DEFAULT_SJ_REL_TOL);
            assert!(
                q.scaled_jacobian_certified
                    >= jb.scaled_upper() * (1.0 - 2.0 * DEFAULT_SJ_REL_TOL) - 1e-12
            );
        }
    }

    #[test]
    fn histogram_and_summary() {
        let mut h = Histogram::new(0.0, 1.0, 4);
        for v in [-0.5, 0.0, 0.1, 0.25, 0.5, 0.99, 1.0, 1.5, f64::NAN] {
            h.add(v);
        }
        assert_eq!(h.counts, vec![2, 1, 1, 2]);
        assert_eq!((h.below, h.above, h.nan), (1, 1, 1));
        assert_eq!(h.total(), 9);
        let mut g = Histogram::new(0.0, 1.0, 4);
        g.add(0.3);
        g.merge(&h);
        assert_eq!(g.counts, vec![2, 2, 1, 2]);
        // A differently binned histogram merges by bin centres.
        let mut k = Histogram::new(0.0, 1.0, 2);
        k.merge(&h);
        assert_eq!(k.counts, vec![3, 3]);
        assert_eq!(k.total(), h.total());
        assert!((h.fraction_above(0.75) - 3.0 / 9.0).abs() < 1e-15);
        // Degenerate ranges do not panic.
        let mut z = Histogram::new(1.0, 1.0, 0);
        z.add(1.0);
        z.add(2.0);
        assert_eq!(z.total(), 2);

        let s = QualitySummary::from_values([0.5, 0.25, 1.0, f64::NAN], 0.0, 1.0, 10);
        assert_eq!(s.count, 3);
        assert_eq!((s.min, s.max), (0.25, 1.0));
        assert!((s.mean - 1.75 / 3.0).abs() < 1e-15);
        let mut t = QualitySummary::new(0.0, 1.0, 10);
        t.merge(&s);
        assert_eq!(t, s);
        let json = serde_json::to_string(&s).unwrap();
        assert!(json.contains("\"mean\"") && json.contains("\"counts\"") && !json.contains("sum"));

        let mut rng = StdRng::seed_from_u64(1);
        let mut all = TetQualitySummary::new();
        for _ in 0..50 {
            all.add(&tet_quality(&random_curved(&mut rng, 0.1)));
        }
        assert_eq!(all.skewness.count, 50);
        assert!(all.scaled_jacobian_certified.max <= 1.0);
        assert!(serde_json::to_string(&all).is_ok());
    }

    #[test]
    fn nan_input_does_not_panic() {
        let mut x = straight_tet10([
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ]);
        x[0][0] = f64::NAN;
        let q = tet_quality(&x);
        assert!(q.scaled_jacobian.is_nan() && q.skewness.is_nan());
    }
}
