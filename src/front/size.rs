//! The target size field: target edge length at any point.
//!
//! Uniform (the paper's, eq. 1) or graded from the boundary: each surface vertex gets
//! the mean length of its edges, limited along the surface so neighbours differ by at
//! most the gradation rate, and the field at a point x is
//! `min_i (h_i + g |x - x_i|)` over the nearest surface vertices, capped at the largest
//! boundary size. So the interior never gets coarser than the coarsest boundary triangle
//! and sizes change by at most a factor (1 + g) per element.

use crate::geom::vec3::{dist, P3};
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use std::num::NonZero;

/// Target edge length as a function of position.
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
    },
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
    /// The graded field of a surface given by its corner positions and corner edges.
    pub fn graded(corner_pts: Vec<P3>, edges: &[[u32; 2]], g: f64) -> SizeField {
        let n = corner_pts.len();
        let mut sum = vec![0.0f64; n];
        let mut cnt = vec![0u32; n];
        for &[a, b] in edges {
            let l = dist(corner_pts[a as usize], corner_pts[b as usize]);
            for v in [a, b] {
                sum[v as usize] += l;
                cnt[v as usize] += 1;
            }
        }
        let mut h: Vec<f64> = (0..n)
            .map(|i| {
                if cnt[i] > 0 {
                    sum[i] / cnt[i] as f64
                } else {
                    f64::INFINITY
                }
            })
            .collect();
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
        SizeField::Graded {
            pts,
            h,
            g,
            hmax,
            tree,
        }
    }

    /// Target edge length at `x`.
    pub fn at(&self, x: P3) -> f64 {
        match self {
            SizeField::Uniform(l) => *l,
            SizeField::Graded {
                pts,
                h,
                g,
                hmax,
                tree,
            } => {
                let k = NonZero::new(8usize.min(pts.len()).max(1)).unwrap();
                let near = tree
                    .query(&x)
                    .nearest_n::<SquaredEuclidean<f64>>(k)
                    .execute();
                let mut best = *hmax;
                for r in near {
                    let i = r.item as usize;
                    best = best.min(h[i] + g * r.distance.sqrt());
                }
                best
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
