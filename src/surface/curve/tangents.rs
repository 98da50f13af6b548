//! Tangents of the feature curves at their vertices.
//!
//! The feature edges form a graph. At a vertex with exactly two feature edges, to p and to
//! q, that do not turn by more than the feature angle, the curve is smooth and its tangent
//! is that of the circle through p, v, q:
//! T ∝ |q - v| (v - p)/|v - p| + |v - p| (q - v)/|q - v| (exact for points on a circle,
//! whatever their spacing; along a straight line it is the line's direction). Every other
//! feature vertex (an end of a feature line, a junction of three or more, or a kink) is a
//! *corner*: it has no tangent.

use crate::geom::vec3::{dot, norm, normalize, scale, sub};
use crate::geom::P3;
use crate::surface::topology::SurfaceEdge;

/// A smooth feature vertex: its neighbours along the curve and its unit tangent (from
/// `prev` towards `next`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct CurvePoint {
    pub prev: u32,
    pub next: u32,
    pub tangent: P3,
}

/// Per vertex (corners of the input), its curve point if it is a smooth feature vertex.
pub(crate) fn feature_tangents(
    nodes: &[P3],
    n_input: usize,
    edges: &[SurfaceEdge],
    feature: &[bool],
    cos_feature: f64,
) -> Vec<Option<CurvePoint>> {
    // Up to two feature neighbours per vertex, and the feature degree.
    let mut nb = vec![[u32::MAX; 2]; n_input];
    let mut deg = vec![0u32; n_input];
    for (e, se) in edges.iter().enumerate() {
        if !feature[e] {
            continue;
        }
        let [a, b] = se.nodes;
        for (v, w) in [(a, b), (b, a)] {
            let k = deg[v as usize] as usize;
            if k < 2 {
                nb[v as usize][k] = w;
            }
            deg[v as usize] += 1;
        }
    }
    (0..n_input)
        .map(|v| {
            if deg[v] != 2 {
                return None;
            }
            let [p, q] = nb[v];
            let x = nodes[v];
            let (e1, e2) = (sub(x, nodes[p as usize]), sub(nodes[q as usize], x));
            let (l1, l2) = (norm(e1), norm(e2));
            if l1.is_nan()
                || l2.is_nan()
                || l1 <= 0.0
                || l2 <= 0.0
                || dot(e1, e2) < cos_feature * l1 * l2
            {
                return None; // a kink
            }
            let t: P3 = [0, 1, 2].map(|d| l2 / l1 * e1[d] + l1 / l2 * e2[d]);
            let t = normalize(t);
            if !t.iter().all(|c| c.is_finite()) || norm(t) == 0.0 {
                return None;
            }
            Some(CurvePoint {
                prev: p,
                next: q,
                tangent: t,
            })
        })
        .collect()
}

/// The tangent at curve point `c` oriented towards its neighbour `toward` (`None` if
/// `toward` is not one of its neighbours).
pub(crate) fn oriented(c: &CurvePoint, toward: u32) -> Option<P3> {
    if toward == c.next {
        Some(c.tangent)
    } else if toward == c.prev {
        Some(scale(c.tangent, -1.0))
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Three points on a circle at uneven spacing: the tangent is the circle's.
    #[test]
    fn three_point_tangent_is_exact_on_a_circle() {
        let on = |a: f64| [2.0 * a.cos(), 2.0 * a.sin(), 1.0];
        let nodes = vec![on(0.0), on(0.3), on(0.5)];
        let edges = [
            SurfaceEdge {
                nodes: [0, 1],
                mid: 0,
                tris: [0, 0],
            },
            SurfaceEdge {
                nodes: [1, 2],
                mid: 0,
                tris: [0, 0],
            },
        ];
        let t = feature_tangents(&nodes, 3, &edges, &[true, true], 0.5);
        let c = t[1].expect("a smooth curve point");
        let want = [-(0.3f64.sin()), 0.3f64.cos(), 0.0];
        let got = oriented(&c, 2).unwrap();
        for d in 0..3 {
            assert!((got[d] - want[d]).abs() < 1e-14, "{got:?} vs {want:?}");
        }
        assert!(t[0].is_none() && t[2].is_none());
    }
}
