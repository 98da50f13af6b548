//! Where an edge's mid node goes, given what is known at its two ends.
//!
//! **Arc rule** ([`arc_mid`]): the edge is taken as a circular arc leaving `a` along
//! tangent `ta` and arriving at `b` along `tb`. With d the unit chord direction, the parts
//! of the tangents across the chord, u = t - (t·d) d, say which way and how much it bends:
//! for a circle, u_a = sin φ n and u_b = -sin φ n, with n the bulge direction and φ the
//! angle between tangent and chord. The mid node is the arc's midpoint, at height
//! (L/2) tan(φ/2) above the chord midpoint, with n sin φ estimated as (u_a - u_b)/2 (or
//! from one end only when the other has no tangent). Exact for points on a circle with
//! exact tangents: the rims of the tube, and great circles of a sphere.
//!
//! **Surface edges** take their end tangents from the vertex normals: the chord projected
//! into each end's tangent plane ([`tangent_from_normal`]); on a sphere that is the great
//! circle's tangent.
//!
//! **PN rule** ([`pn_mid`]): the midpoint of the cubic edge of a PN triangle (Vlachos et
//! al. 2001), m = (a + b)/2 - (w_ab N_a + w_ba N_b)/8 with w_ij = (p_j - p_i)·N_i. Kept for
//! comparison (see `CurveOptions::rule`): on the benchmark sphere and torus its volume
//! error is 4 to 5 times the arc rule's (numbers in the `curve` module docs).

use crate::geom::vec3::{add, dot, mid, norm, scale, sub};
use crate::geom::P3;

/// The part of `t` across the unit direction `d`.
#[inline]
fn across(t: P3, d: P3) -> P3 {
    sub(t, scale(d, dot(t, d)))
}

/// Mid node of the arc from `a` to `b` with unit end tangents along the travel a → b;
/// either may be unknown. Unknown at both ends, or no bend: the chord midpoint.
pub(crate) fn arc_mid(a: P3, b: P3, ta: Option<P3>, tb: Option<P3>) -> P3 {
    let m = mid(a, b);
    let chord = sub(b, a);
    let l = norm(chord);
    if l.is_nan() || l <= 0.0 {
        return m;
    }
    let d = scale(chord, 1.0 / l);
    let v = match (ta, tb) {
        (Some(ta), Some(tb)) => scale(sub(across(ta, d), across(tb, d)), 0.5),
        (Some(ta), None) => across(ta, d),
        (None, Some(tb)) => scale(across(tb, d), -1.0),
        (None, None) => return m,
    };
    let s = norm(v);
    if !s.is_finite() || s <= 0.0 {
        return m;
    }
    let phi = s.min(1.0).asin();
    let height = 0.5 * l * (0.5 * phi).tan();
    add(m, scale(v, height / s))
}

/// The unit tangent at a surface point with unit normal `n` in the direction of `chord`
/// (the chord projected into the tangent plane); `None` if the chord is along the normal.
pub(crate) fn tangent_from_normal(chord: P3, n: P3) -> Option<P3> {
    let t = sub(chord, scale(n, dot(chord, n)));
    let l = norm(t);
    (l > 0.0 && l.is_finite()).then(|| scale(t, 1.0 / l))
}

/// The PN-triangle edge midpoint (module docs).
pub(crate) fn pn_mid(a: P3, b: P3, na: P3, nb: P3) -> P3 {
    let d = sub(b, a);
    let (wab, wba) = (dot(d, na), -dot(d, nb));
    let m = mid(a, b);
    [0, 1, 2].map(|k| m[k] - (wab * na[k] + wba * nb[k]) / 8.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Arc rule on a great circle of the unit sphere: the mid node is on the sphere.
    #[test]
    fn arc_rule_is_exact_on_a_sphere() {
        let a = [1.0, 0.0, 0.0];
        let th: f64 = 0.7;
        let b = [th.cos(), th.sin() * 0.6, th.sin() * 0.8];
        let ta = tangent_from_normal(sub(b, a), a);
        let tb = tangent_from_normal(sub(b, a), b);
        let m = arc_mid(a, b, ta, tb);
        assert!((norm(m) - 1.0).abs() < 1e-15, "{}", norm(m));
        // The PN rule is close but not exact.
        let p = pn_mid(a, b, a, b);
        assert!((norm(p) - 1.0).abs() > 1e-4);
        // Straight when the ends' normals agree.
        let z = [0.0, 0.0, 1.0];
        let f = arc_mid(
            [0.0; 3],
            [1.0, 2.0, 0.0],
            tangent_from_normal([1.0, 2.0, 0.0], z),
            tangent_from_normal([1.0, 2.0, 0.0], z),
        );
        assert_eq!(f, [0.5, 1.0, 0.0]);
    }
}
