//! Euclidean distances used by metric (not topological) decisions: how close a point is
//! to a triangle. Floating point; the exact predicates decide every topological question.

use super::vec3::*;

/// Squared distance from `p` to the closed triangle (a, b, c) (Ericson, Real-Time
/// Collision Detection, 5.1.5: closest point by Voronoi regions).
pub fn point_triangle_dist2(p: P3, a: P3, b: P3, c: P3) -> f64 {
    let ab = sub(b, a);
    let ac = sub(c, a);
    let ap = sub(p, a);
    let d1 = dot(ab, ap);
    let d2 = dot(ac, ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return norm2(ap);
    }
    let bp = sub(p, b);
    let d3 = dot(ab, bp);
    let d4 = dot(ac, bp);
    if d3 >= 0.0 && d4 <= d3 {
        return norm2(bp);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return dist2(p, axpy(a, v, ab));
    }
    let cp = sub(p, c);
    let d5 = dot(ab, cp);
    let d6 = dot(ac, cp);
    if d6 >= 0.0 && d5 <= d6 {
        return norm2(cp);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return dist2(p, axpy(a, w, ac));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return dist2(p, axpy(b, w, sub(c, b)));
    }
    let denom = 1.0 / (va + vb + vc);
    let v = vb * denom;
    let w = vc * denom;
    dist2(p, add(a, add(scale(ab, v), scale(ac, w))))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regions() {
        let (a, b, c) = ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        assert_eq!(point_triangle_dist2([0.2, 0.2, 2.0], a, b, c), 4.0);
        assert_eq!(point_triangle_dist2([-1.0, -1.0, 0.0], a, b, c), 2.0);
        assert_eq!(point_triangle_dist2([0.5, -2.0, 0.0], a, b, c), 4.0);
        assert!((point_triangle_dist2([1.0, 1.0, 0.0], a, b, c) - 0.5).abs() < 1e-15);
        assert_eq!(point_triangle_dist2([3.0, 0.0, 0.0], a, b, c), 4.0);
        // Against brute force sampling.
        let p = [0.7, 0.9, 0.3];
        let mut best = f64::INFINITY;
        for i in 0..=200 {
            for j in 0..=200 - i {
                let q = [i as f64 / 200.0, j as f64 / 200.0, 0.0];
                best = best.min(dist2(p, q));
            }
        }
        let d = point_triangle_dist2(p, a, b, c);
        assert!(d <= best + 1e-12 && d > best - 1e-4);
    }
}
