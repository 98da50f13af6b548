//! The target size field: target edge length at any point.
//!
//! Uniform (the paper's, eq. 1) or graded from the boundary: each surface vertex gets
//! a local size ([`corner_sizes`]: the mean length of its edges, or on a surface of
//! elongated triangles the edge of the equilateral triangle of their mean area), limited
//! along the surface so neighbours differ by at most the gradation rate, and the field
//! at a point x is `min_i (h_i + g |x - x_i|)` over the nearest surface vertices,
//! capped at the largest boundary size. So the interior never gets coarser than the
//! coarsest boundary triangle and sizes change by at most a factor (1 + g) per element.
//!
//! Deep inside, where every vertex is so far that even the smallest boundary size plus
//! g times the distance reaches the cap, the field is the cap whichever vertices are
//! nearest. [`SizeField::at_near`] takes a lower bound of that distance (the front
//! passes one from each face to the faces it creates: the distance to the nearest
//! vertex is 1-Lipschitz) and skips the k-nearest query there, with the same value bit
//! for bit.

use crate::geom::vec3::{dist, tri_area, P3};
use crate::options::SizeFrom;
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use std::num::NonZero;

/// Target edge length as a function of position.
// One per run: the size of the graded variant does not matter.
#[allow(clippy::large_enum_variant)]
pub enum SizeField {
    /// The same edge length everywhere.
    Uniform(f64),
    /// Graded from the boundary vertices.
    Graded {
        /// Surface corner positions.
        pts: Vec<P3>,
        /// Gradation-limited size at each of them.
        h: Vec<f64>,
        /// Growth rate.
        g: f64,
        /// Cap: the largest boundary size.
        hmax: f64,
        /// Nearest-vertex search over `pts`.
        tree: ImmutableKdTree<f64, 3>,
        /// Smallest of `h`.
        hmin: f64,
        /// What the local sizes were measured from ([`SizeFrom::Edges`] or
        /// [`SizeFrom::Areas`]).
        from: SizeFrom,
    },
}

/// [`SizeFrom::Auto`] measures sizes from areas when the median over the surface
/// vertices of (area size / edge size) is below this. It is 1 on equilateral triangles;
/// 0.99-1.00 on the six benchmark surfaces; 0.76-0.83 on the anisotropic tori
/// (`scripts/aniso-torus.py` 40-50 x 54) that leave the front stuck with edge sizes and
/// mesh at once with area sizes; 0.85-0.88 on tori that mesh either way.
pub const AREAS_BELOW: f64 = 0.9;

/// The local size at each surface corner `pts[i]` given the corner edges and triangles,
/// measured as `from` says, and what it was measured from (`Auto` resolved). A corner on
/// no edge gets +∞ (no size).
pub fn corner_sizes(
    pts: &[P3],
    edges: &[[u32; 2]],
    tris: &[[u32; 3]],
    from: SizeFrom,
) -> (Vec<f64>, SizeFrom) {
    let n = pts.len();
    let mean = |sum: &[f64], cnt: &[u32]| -> Vec<f64> {
        (0..n)
            .map(|i| {
                if cnt[i] > 0 {
                    sum[i] / cnt[i] as f64
                } else {
                    f64::INFINITY
                }
            })
            .collect()
    };
    let (mut sum, mut cnt) = (vec![0.0f64; n], vec![0u32; n]);
    for &[a, b] in edges {
        let l = dist(pts[a as usize], pts[b as usize]);
        for v in [a, b] {
            sum[v as usize] += l;
            cnt[v as usize] += 1;
        }
    }
    let by_edges = mean(&sum, &cnt);
    if from == SizeFrom::Edges {
        return (by_edges, SizeFrom::Edges);
    }
    let (mut sum, mut cnt) = (vec![0.0f64; n], vec![0u32; n]);
    for t in tris {
        let p = t.map(|v| pts[v as usize]);
        let area = tri_area(p[0], p[1], p[2]);
        for &v in t {
            sum[v as usize] += area;
            cnt[v as usize] += 1;
        }
    }
    let by_areas: Vec<f64> = mean(&sum, &cnt)
        .into_iter()
        .map(|a| {
            if a.is_finite() {
                regular_edge_from_area(a)
            } else {
                a
            }
        })
        .collect();
    if from == SizeFrom::Areas {
        return (by_areas, SizeFrom::Areas);
    }
    let mut ratios: Vec<f64> = by_areas
        .iter()
        .zip(&by_edges)
        .filter(|(a, e)| a.is_finite() && e.is_finite() && **e > 0.0)
        .map(|(a, e)| a / e)
        .collect();
    if ratios.is_empty() {
        return (by_edges, SizeFrom::Edges);
    }
    let mid = ratios.len() / 2;
    let (_, median, _) = ratios.select_nth_unstable_by(mid, f64::total_cmp);
    if *median < AREAS_BELOW {
        (by_areas, SizeFrom::Areas)
    } else {
        (by_edges, SizeFrom::Edges)
    }
}

/// Edge length of the regular tetrahedron whose faces have area `a`.
pub fn regular_edge_from_area(a: f64) -> f64 {
    (4.0 * a / 3f64.sqrt()).sqrt()
}

/// Height of the regular tetrahedron with edge `l`: sqrt(2/3) l.
pub fn regular_height(l: f64) -> f64 {
    (2.0f64 / 3.0).sqrt() * l
}

impl SizeField {
    /// The graded field of a surface given by its corner positions and corner edges, the
    /// local sizes measured from edges.
    pub fn graded(corner_pts: Vec<P3>, edges: &[[u32; 2]], g: f64) -> SizeField {
        let (h, from) = corner_sizes(&corner_pts, edges, &[], SizeFrom::Edges);
        SizeField::graded_from(corner_pts, h, from, edges, g)
    }

    /// The graded field of local sizes `h` at the corners `corner_pts` (measured from
    /// `from`; +∞ where none), limited along the corner edges by the growth rate `g`.
    pub fn graded_from(
        corner_pts: Vec<P3>,
        mut h: Vec<f64>,
        from: SizeFrom,
        edges: &[[u32; 2]],
        g: f64,
    ) -> SizeField {
        let n = corner_pts.len();
        // Gradation limit along the surface: relax h_j <= h_i + g |x_i - x_j| over edges
        // until nothing changes (a few sweeps; each sweep is O(edges)). Bounded.
        for _ in 0..64 {
            let mut changed = false;
            for &[a, b] in edges {
                let (a, b) = (a as usize, b as usize);
                let l = dist(corner_pts[a], corner_pts[b]);
                if h[b] > h[a] + g * l {
                    h[b] = h[a] + g * l;
                    changed = true;
                }
                if h[a] > h[b] + g * l {
                    h[a] = h[b] + g * l;
                    changed = true;
                }
            }
            if !changed {
                break;
            }
        }
        let hmax = h
            .iter()
            .cloned()
            .filter(|x| x.is_finite())
            .fold(0.0, f64::max);
        let keep: Vec<usize> = (0..n).filter(|&i| h[i].is_finite()).collect();
        let pts: Vec<P3> = keep.iter().map(|&i| corner_pts[i]).collect();
        let h: Vec<f64> = keep.iter().map(|&i| h[i]).collect();
        let tree = ImmutableKdTree::new_from_slice(&pts).expect("kd-tree of surface vertices");
        let hmin = h.iter().cloned().fold(f64::INFINITY, f64::min);
        SizeField::Graded {
            pts,
            h,
            g,
            hmax,
            tree,
            hmin,
            from,
        }
    }

    /// What the local sizes of a graded field were measured from (`None` when uniform).
    pub fn measured_from(&self) -> Option<SizeFrom> {
        match self {
            SizeField::Uniform(_) => None,
            SizeField::Graded { from, .. } => Some(*from),
        }
    }

    /// Target edge length at `x`.
    pub fn at(&self, x: P3) -> f64 {
        self.at_near(x, 0.0).0
    }

    /// Target edge length at `x`, given `floor`, a lower bound of the distance from `x`
    /// to the nearest surface vertex (0 when nothing is known); also returns such a
    /// bound (the distance itself, less a margin for rounding, when it was computed).
    pub fn at_near(&self, x: P3, floor: f64) -> (f64, f64) {
        match self {
            SizeField::Uniform(l) => (*l, 0.0),
            SizeField::Graded {
                pts,
                h,
                g,
                hmax,
                tree,
                hmin,
                ..
            } => {
                // Every term of the minimum below is at least hmin + g * (distance to
                // the nearest vertex), rounding being monotone: when that reaches the
                // cap, the value is the cap.
                if *hmin + *g * floor >= *hmax {
                    return (*hmax, floor);
                }
                let k = NonZero::new(8usize.min(pts.len()).max(1)).unwrap();
                let near = tree
                    .query(&x)
                    .nearest_n::<SquaredEuclidean<f64>>(k)
                    .execute();
                let mut best = *hmax;
                let mut nearest = f64::INFINITY;
                for r in near {
                    let i = r.item as usize;
                    let d = r.distance.sqrt();
                    nearest = nearest.min(d);
                    best = best.min(h[i] + g * d);
                }
                (best, (nearest * (1.0 - 1e-9)).max(0.0))
            }
        }
    }

    /// The smallest size anywhere (used to size search structures).
    pub fn min_size(&self) -> f64 {
        match self {
            SizeField::Uniform(l) => *l,
            SizeField::Graded { h, .. } => h.iter().cloned().fold(f64::INFINITY, f64::min),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// A strip of `n` quads split into triangles, `w` by `hgt` each: corners, edges and
    /// triangles.
    fn strip(n: usize, w: f64, hgt: f64) -> (Vec<P3>, Vec<[u32; 2]>, Vec<[u32; 3]>) {
        let mut pts = Vec::new();
        for i in 0..=n {
            pts.push([i as f64 * w, 0.0, 0.0]);
            pts.push([i as f64 * w, hgt, 0.0]);
        }
        let (mut edges, mut tris) = (Vec::new(), Vec::new());
        for i in 0..n as u32 {
            let (a, b, c, d) = (2 * i, 2 * i + 2, 2 * i + 3, 2 * i + 1);
            tris.push([a, b, c]);
            tris.push([a, c, d]);
            edges.extend([[a, b], [b, c], [c, a], [c, d], [d, a]]);
        }
        edges.push([0, 1]);
        (pts, edges, tris)
    }

    #[test]
    fn auto_sizes_from_areas_only_on_elongated_triangles() {
        // Near-equilateral triangles (1 x 0.9 halves): edges.
        let (p, e, t) = strip(20, 1.0, 0.9);
        let (h, from) = corner_sizes(&p, &e, &t, SizeFrom::Auto);
        assert_eq!(from, SizeFrom::Edges);
        assert_eq!(h, corner_sizes(&p, &e, &t, SizeFrom::Edges).0);
        // Halves of 1 x 0.3 rectangles: areas, and an interior corner's size is the
        // equilateral edge of its triangles' mean area (every triangle has area 0.15).
        let (p, e, t) = strip(20, 1.0, 0.3);
        let (h, from) = corner_sizes(&p, &e, &t, SizeFrom::Auto);
        assert_eq!(from, SizeFrom::Areas);
        let want = regular_edge_from_area(0.15);
        assert!((h[10] - want).abs() < 1e-12 * want, "{} vs {want}", h[10]);
        let (he, _) = corner_sizes(&p, &e, &t, SizeFrom::Edges);
        assert!(h[10] < 0.9 * he[10], "areas {} edges {}", h[10], he[10]);
        // Forced either way.
        assert_eq!(corner_sizes(&p, &e, &t, SizeFrom::Edges).1, SizeFrom::Edges);
        let (p, e, t) = strip(20, 1.0, 0.9);
        assert_eq!(corner_sizes(&p, &e, &t, SizeFrom::Areas).1, SizeFrom::Areas);
    }

    /// A graded field on random points of the unit sphere.
    fn sphere_field(rng: &mut rand::rngs::StdRng) -> (SizeField, Vec<P3>) {
        let mut pts = Vec::new();
        while pts.len() < 400 {
            let p: P3 = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
            let r = dist(p, [0.0; 3]);
            if r > 0.1 && r <= 1.0 {
                pts.push(p.map(|x| x / r));
            }
        }
        // Edges to each point's two nearest neighbours: their lengths set the sizes.
        let mut edges: Vec<[u32; 2]> = Vec::new();
        for (i, &p) in pts.iter().enumerate() {
            let mut by: Vec<(f64, usize)> = (0..pts.len())
                .filter(|&j| j != i)
                .map(|j| (dist(p, pts[j]), j))
                .collect();
            by.sort_by(|a, b| a.0.total_cmp(&b.0));
            for &(_, j) in &by[..2] {
                edges.push([i as u32, j as u32]);
            }
        }
        let f = SizeField::graded(pts.clone(), &edges, 0.2);
        (f, pts)
    }

    #[test]
    fn at_near_is_at_given_a_true_distance_floor() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(3);
        let (f, pts) = sphere_field(&mut rng);
        let SizeField::Graded { hmin, hmax, g, .. } = &f else {
            unreachable!()
        };
        let depth = (hmax - hmin) / g;
        assert!(depth < 0.9, "the test needs points deep enough: {depth}");
        let (mut skipped, mut queried) = (0, 0);
        for _ in 0..4000 {
            let x: P3 = std::array::from_fn(|_| rng.random_range(-0.35..0.35));
            let nearest = pts
                .iter()
                .map(|&p| dist(p, x))
                .fold(f64::INFINITY, f64::min);
            let exact = f.at(x);
            // Any floor at most the true distance gives the same value, bit for bit.
            for floor in [0.0, 0.5 * nearest, 0.999 * nearest] {
                let (v, bound) = f.at_near(x, floor);
                assert_eq!(v.to_bits(), exact.to_bits(), "{x:?} floor {floor}");
                assert!(bound <= nearest, "{bound} > {nearest}");
                if hmin + g * floor >= *hmax {
                    skipped += 1;
                    assert_eq!(v, *hmax);
                } else {
                    queried += 1;
                    // A computed bound is the distance itself, less the margin.
                    assert!(bound >= 0.999_999 * nearest, "{bound} vs {nearest}");
                }
            }
        }
        assert!(skipped > 100 && queried > 100, "{skipped} {queried}");
    }
}
