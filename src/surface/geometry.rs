//! Per-triangle geometric checks: degenerate chord triangles (exact) and folded curved
//! triangles (normal sampling on a lattice).
//!
//! **Degenerate**: the three corners are exactly collinear (exact predicate) →
//! [`DegenerateTriangle`](SurfaceDefect::DegenerateTriangle). A chord triangle that is not
//! exactly degenerate but whose normal underflows in f64 even in local, rescaled
//! coordinates is reported the same way (no metric check can be made on it).
//!
//! **Folded**: on the order-6 lattice (the 28 points (i/6, j/6), i + j <= 6, corners and
//! edges included) the curved normal `tri6_normal` must have a positive dot product with
//! the chord triangle's normal (the tangents are evaluated in closed form; a test checks
//! them against `tri6_normal`); the smallest cosine between them is the triangle's
//! "n.cos". Any cosine <= 0 (including a vanishing curved normal) →
//! [`FoldedTriangle`](SurfaceDefect::FoldedTriangle), naming the triangle, the minimum
//! cosine and where it occurs. This is a sampled, metric check (as in the data README),
//! not a certificate; the sub-triangle intersection test adds a conservative one.

use rayon::prelude::*;

use super::describe;
use crate::error::{Error, Result, SurfaceDefect};
use crate::geom::predicates::collinear;
use crate::geom::vec3::{cross, dist, dot, mid, norm, scale, sub};
use crate::geom::P3;

/// Lattice order of the fold check.
pub const FOLD_LATTICE_ORDER: usize = 6;

/// Exactly collinear corners.
pub fn check_degenerate(nodes: &[P3], tris: &[[u32; 6]]) -> Result<()> {
    let bad = tris.par_iter().position_first(|tri| {
        let [a, b, c] = [0, 1, 2].map(|k| nodes[tri[k] as usize]);
        collinear(a, b, c)
    });
    if let Some(t) = bad {
        return Err(Error::surface(
            SurfaceDefect::DegenerateTriangle,
            format!(
                "{} has zero area: its corners are collinear",
                describe::tri(t, &tris[t])
            ),
        ));
    }
    Ok(())
}

/// The six nodes of triangle `tri`.
#[inline]
pub(crate) fn tri_nodes(nodes: &[P3], tri: &[u32; 6]) -> [P3; 6] {
    tri.map(|v| nodes[v as usize])
}

/// Result of sampling one curved triangle's normal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum NormalSample {
    /// Minimum cosine between curved and chord normals, and the lattice point (u, v)
    /// (in sixths) where it occurs.
    MinCos(f64, [u8; 2]),
    /// The chord normal cannot be computed in f64 (area underflows).
    ChordUnderflow,
}

/// The minimum over the order-6 lattice of cos(curved normal, chord normal) of the
/// curved triangle with nodes `x` (Gmsh order). Works in local coordinates scaled to
/// unit size, so tiny or huge triangles neither underflow nor overflow.
pub fn min_normal_cosine_of(x: &[P3; 6]) -> NormalSample {
    let mut s = 0.0f64;
    for p in &x[1..] {
        for d in 0..3 {
            s = s.max((p[d] - x[0][d]).abs());
        }
    }
    if s == 0.0 || !s.is_finite() {
        return NormalSample::ChordUnderflow;
    }
    let inv = 1.0 / s;
    let y: [P3; 6] = x.map(|p| scale(sub(p, x[0]), inv));
    let nc = cross(y[1], y[2]);
    let lc = norm(nc);
    if lc == 0.0 || !lc.is_finite() {
        return NormalSample::ChordUnderflow;
    }
    let nc = scale(nc, 1.0 / lc);
    // The tangents are affine in (u, v): x_u = tu0 + u tuu + v tuv, x_v = tv0 + u tuv + v tvv
    // (from the Gmsh-order P2 shape functions), so each lattice point costs two affine
    // evaluations and a cross product.
    let (x0, x1, x2, m01, m12, m20) = (y[0], y[1], y[2], y[3], y[4], y[5]);
    let comb = |c: [f64; 6]| -> P3 {
        [0, 1, 2].map(|d| {
            c[0] * x0[d]
                + c[1] * x1[d]
                + c[2] * x2[d]
                + c[3] * m01[d]
                + c[4] * m12[d]
                + c[5] * m20[d]
        })
    };
    let tu0 = comb([-3.0, -1.0, 0.0, 4.0, 0.0, 0.0]);
    let tv0 = comb([-3.0, 0.0, -1.0, 0.0, 0.0, 4.0]);
    let tuu = comb([4.0, 4.0, 0.0, -8.0, 0.0, 0.0]);
    let tvv = comb([4.0, 0.0, 4.0, 0.0, 0.0, -8.0]);
    let tuv = comb([4.0, 0.0, 0.0, -4.0, 4.0, -4.0]);
    let mut best = (f64::INFINITY, [0u8; 2]);
    let q = FOLD_LATTICE_ORDER;
    for i in 0..=q {
        let u = i as f64 / q as f64;
        for j in 0..=(q - i) {
            let v = j as f64 / q as f64;
            let xu = [0, 1, 2].map(|d| tu0[d] + u * tuu[d] + v * tuv[d]);
            let xv = [0, 1, 2].map(|d| tv0[d] + u * tuv[d] + v * tvv[d]);
            let n = cross(xu, xv);
            let l = norm(n);
            let c = if l > 0.0 && l.is_finite() {
                dot(n, nc) / l
            } else {
                0.0
            };
            let c = if c.is_finite() { c } else { 0.0 };
            if c < best.0 {
                best = (c, [i as u8, j as u8]);
            }
        }
    }
    NormalSample::MinCos(best.0, best.1)
}

/// Largest distance of a mid node from its edge's midpoint, in edge lengths. A circular
/// arc of a whole half turn has its mid node half an edge length off (0.5): real curved
/// surfaces stay far below; beyond 1 the node belongs to no sensible edge.
pub const MAX_MID_OFFSET: f64 = 1.0;

/// Every mid node within [`MAX_MID_OFFSET`] edge lengths of its edge's midpoint.
pub fn check_mid_offsets(nodes: &[P3], tris: &[[u32; 6]]) -> Result<()> {
    let bad = tris.par_iter().enumerate().find_map_first(|(t, tri)| {
        (0..3).find_map(|k| {
            let (a, b, m) = (
                nodes[tri[k] as usize],
                nodes[tri[(k + 1) % 3] as usize],
                nodes[tri[3 + k] as usize],
            );
            let len = dist(a, b);
            let off = dist(m, mid(a, b));
            (off > MAX_MID_OFFSET * len).then_some((t, k, off / len))
        })
    });
    if let Some((t, k, r)) = bad {
        let tri = &tris[t];
        return Err(Error::surface(
            SurfaceDefect::MidNodeMismatch,
            format!(
                "{}: mid node {} of edge ({}, {}) lies {r:.3e} edge lengths from the edge's \
                 midpoint (at most {MAX_MID_OFFSET}): it is not a mid node of that edge",
                describe::tri(t, tri),
                tri[3 + k],
                tri[k],
                tri[(k + 1) % 3]
            ),
        ));
    }
    Ok(())
}

/// No folded curved triangle: every lattice cosine > 0.
pub fn check_folded(nodes: &[P3], tris: &[[u32; 6]]) -> Result<()> {
    let bad = tris
        .par_iter()
        .enumerate()
        .map(|(t, tri)| (t, min_normal_cosine_of(&tri_nodes(nodes, tri))))
        .find_first(|(_, s)| match s {
            NormalSample::MinCos(c, _) => *c <= 0.0,
            NormalSample::ChordUnderflow => true,
        });
    match bad {
        None => Ok(()),
        Some((t, NormalSample::ChordUnderflow)) => Err(Error::surface(
            SurfaceDefect::DegenerateTriangle,
            format!(
                "{} is degenerate in f64: its corners are not exactly collinear but its \
                 normal underflows even in rescaled local coordinates",
                describe::tri(t, &tris[t])
            ),
        )),
        Some((t, NormalSample::MinCos(c, [i, j]))) => Err(Error::surface(
            SurfaceDefect::FoldedTriangle,
            format!(
                "{} is folded: min cos(curved normal, chord normal) = {c:.4} <= 0 at \
                 (u, v) = ({i}/6, {j}/6) (mid nodes {}, {}, {}: one is likely pushed \
                 through)",
                describe::tri(t, &tris[t]),
                tris[t][3],
                tris[t][4],
                tris[t][5]
            ),
        )),
    }
}

/// Minimum lattice cosine over all triangles (the data README's "min n.cos").
pub fn min_normal_cosine(nodes: &[P3], tris: &[[u32; 6]]) -> f64 {
    tris.par_iter()
        .map(|tri| match min_normal_cosine_of(&tri_nodes(nodes, tri)) {
            NormalSample::MinCos(c, _) => c,
            NormalSample::ChordUnderflow => 0.0,
        })
        .reduce(|| f64::INFINITY, f64::min)
}

/// Boundary triangles whose corner triangle has a larger aspect ratio than this are
/// poorly shaped for the advancing front (the hinge, which meshes, has two just above
/// 10 among 1,960; raw marching-cubes surfaces, which do not, have hundreds up to
/// 50-1,000).
pub const POOR_ASPECT_RATIO: f64 = 10.0;

/// Aspect ratio of the triangle (a, b, c): longest edge × perimeter / (4√3 area), 1 for
/// the equilateral triangle, +∞ for a degenerate one.
pub fn aspect_ratio(a: P3, b: P3, c: P3) -> f64 {
    use crate::geom::vec3::{dist, tri_area};
    let e = [dist(a, b), dist(b, c), dist(c, a)];
    let area = tri_area(a, b, c);
    let r = e[0].max(e[1]).max(e[2]) * (e[0] + e[1] + e[2]) / (4.0 * 3f64.sqrt() * area);
    if r.is_nan() {
        f64::INFINITY
    } else {
        r
    }
}

/// Surfaces whose median corner-triangle aspect ratio ([`TriangleShape::median`]) exceeds
/// this are made of elongated triangles, on which the advancing front may not close:
/// long boundary edges next to short ones. Tori from `scripts/aniso-torus.py`: 12-25 ×
/// 27-54 with median 3.5-4.0 left the front stuck (one, 12 × 27 `--no-shift` at 4.3,
/// meshed); 30 × 60 (3.4) closed only on the fourth front attempt, after 15 s (75-81 s
/// before [`crate::front::MAX_REPAIRS_WITHOUT_PROGRESS`] cut the failed attempts short),
/// and 30 × 50 on the second, after 21 s; 25-50 × 30-60 otherwise, median 1.8-3.1, meshed
/// on the first. The six benchmark surfaces have 1.03-1.21.
pub const ELONGATED_MEDIAN_ASPECT_RATIO: f64 = 3.3;

/// The corner triangles' aspect ratios ([`aspect_ratio`]) summed up for the front.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleShape {
    /// Triangles above [`POOR_ASPECT_RATIO`].
    pub poor: usize,
    /// The largest aspect ratio (0 for no triangle).
    pub worst: f64,
    /// The median aspect ratio (1 for no triangle); see [`ELONGATED_MEDIAN_ASPECT_RATIO`].
    pub median: f64,
}

impl TriangleShape {
    /// Most triangles elongated: the median above [`ELONGATED_MEDIAN_ASPECT_RATIO`].
    pub fn elongated(&self) -> bool {
        self.median > ELONGATED_MEDIAN_ASPECT_RATIO
    }
}

/// The [`TriangleShape`] of the corner triangles of `tris`, in one pass over them.
pub fn triangle_shape(nodes: &[P3], tris: &[[u32; 6]]) -> TriangleShape {
    let mut r: Vec<f64> = tris
        .iter()
        .map(|t| {
            aspect_ratio(
                nodes[t[0] as usize],
                nodes[t[1] as usize],
                nodes[t[2] as usize],
            )
        })
        .collect();
    let poor = r.iter().filter(|&&x| x > POOR_ASPECT_RATIO).count();
    let worst = r.iter().copied().fold(0.0f64, f64::max);
    let median = if r.is_empty() {
        1.0
    } else {
        let k = r.len() / 2;
        *r.select_nth_unstable_by(k, f64::total_cmp).1
    };
    TriangleShape {
        poor,
        worst,
        median,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::shape::tri6_normal;

    /// The closed-form tangents agree with `tri6_normal` (the reference shape functions).
    #[test]
    fn lattice_normals_match_shape_functions() {
        let x: [P3; 6] = [
            [0.0, 0.0, 0.0],
            [1.0, 0.1, 0.0],
            [0.2, 1.0, 0.1],
            [0.5, -0.1, 0.2],
            [0.7, 0.6, 0.3],
            [0.0, 0.5, -0.2],
        ];
        let nc = crate::geom::vec3::normalize(cross(x[1], x[2]));
        let mut want = f64::INFINITY;
        for i in 0..=6 {
            for j in 0..=(6 - i) {
                let n = tri6_normal(&x, i as f64 / 6.0, j as f64 / 6.0);
                want = want.min(dot(n, nc) / norm(n));
            }
        }
        let NormalSample::MinCos(got, _) = min_normal_cosine_of(&x) else {
            panic!("no sample");
        };
        assert!((got - want).abs() < 1e-12, "{got} vs {want}");
        assert!(got < 0.99);
    }

    /// Of three triangles' aspect ratios, the median is the middle one and the worst the
    /// largest; the equilateral triangle's is 1.
    #[test]
    fn triangle_shape_has_the_median_and_the_worst() {
        let h = 3f64.sqrt() / 2.0;
        // Equilateral; isosceles of base 1 and height 0.2 and 0.05 (aspect ratio grows as
        // the height shrinks).
        let nodes: Vec<P3> = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.5, h, 0.0],
            [0.5, 0.2, 0.0],
            [0.5, 0.05, 0.0],
        ];
        let tri = |c: u32| [0, 1, c, 0, 0, 0];
        let eq = aspect_ratio(nodes[0], nodes[1], nodes[2]);
        assert!((eq - 1.0).abs() < 1e-12, "{eq}");
        let mid = aspect_ratio(nodes[0], nodes[1], nodes[3]);
        let thin = aspect_ratio(nodes[0], nodes[1], nodes[4]);
        assert!(1.0 < mid && mid < thin, "{mid} {thin}");
        let tris = [tri(4), tri(2), tri(3)];
        let shape = |tris: &[[u32; 6]]| triangle_shape(&nodes, tris);
        let s = shape(&tris);
        assert_eq!((s.median, s.worst), (mid, thin));
        // Only the thinnest is above 10.
        assert!(
            thin > POOR_ASPECT_RATIO && mid < POOR_ASPECT_RATIO,
            "{mid} {thin}"
        );
        assert_eq!(s.poor, 1);
        assert_eq!(shape(&tris[1..2]).median, eq);
        let none = shape(&[]);
        assert_eq!((none.poor, none.worst, none.median), (0, 0.0, 1.0));
    }
}
