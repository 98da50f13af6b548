//! Enclosed volumes of the curved and the chord surface (divergence theorem).
//!
//! V = 1/3 ∮ x · n dA. For a P2 triangle x(u, v) is quadratic and the unnormalised normal
//! x_u × x_v is quadratic, so the integrand is a degree-4 polynomial: the 6-point
//! degree-4 rule below (Dunavant) integrates it exactly up to rounding. Coordinates are
//! taken relative to the bounding-box centre to limit cancellation.
//!
//! The rule lives here because the surface needs only this one; when `geom` grows a
//! quadrature module, this should use it.

use crate::geom::shape::{tri6_normal, tri6_point};
use crate::geom::vec3::{dot, sub};
use crate::geom::P3;

/// Dunavant's degree-4 rule on the reference triangle: (barycentric a, weight), each
/// point (a, a, 1 - 2a) in its three permutations; weights sum to 1.
const DUNAVANT4: [(f64, f64); 2] = [
    (0.445_948_490_915_964_9, 0.223_381_589_678_011_47),
    (0.091_576_213_509_770_74, 0.109_951_743_655_321_87),
];

fn centre(nodes: &[P3]) -> P3 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in nodes {
        for d in 0..3 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    if nodes.is_empty() {
        return [0.0; 3];
    }
    [0, 1, 2].map(|d| 0.5 * (lo[d] + hi[d]))
}

/// Volume enclosed by the curved P2 triangles (positive when outward).
pub fn curved_volume(nodes: &[P3], tris: &[[u32; 6]]) -> f64 {
    let o = centre(nodes);
    let mut v = 0.0;
    for tri in tris {
        let x: [P3; 6] = tri.map(|k| sub(nodes[k as usize], o));
        let mut s = 0.0;
        for &(a, w) in &DUNAVANT4 {
            let b = 1.0 - 2.0 * a;
            for (u, vv) in [(a, a), (a, b), (b, a)] {
                s += w * dot(tri6_point(&x, u, vv), tri6_normal(&x, u, vv));
            }
        }
        // Reference triangle area 1/2; V = 1/3 sum.
        v += 0.5 * s;
    }
    v / 3.0
}
