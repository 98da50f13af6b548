//! Tiny fixed-size vector helpers on `[f64; 3]`.
//!
//! Hand-written rather than nalgebra's `Vector3` in the hot loops: plain arrays keep the
//! front's data flat (`Vec<[f64; 3]>`) and these few inline functions compile to the same
//! code without conversions at every call.

/// A point or vector in 3D.
pub type P3 = [f64; 3];

/// a - b
#[inline]
pub fn sub(a: P3, b: P3) -> P3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
/// a + b
#[inline]
pub fn add(a: P3, b: P3) -> P3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
/// s * a
#[inline]
pub fn scale(a: P3, s: f64) -> P3 {
    [a[0] * s, a[1] * s, a[2] * s]
}
/// a + s * b
#[inline]
pub fn axpy(a: P3, s: f64, b: P3) -> P3 {
    [a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]]
}
/// a . b
#[inline]
pub fn dot(a: P3, b: P3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
/// a x b
#[inline]
pub fn cross(a: P3, b: P3) -> P3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
/// |a|
#[inline]
pub fn norm(a: P3) -> f64 {
    dot(a, a).sqrt()
}
/// |a|^2
#[inline]
pub fn norm2(a: P3) -> f64 {
    dot(a, a)
}
/// |a - b|
#[inline]
pub fn dist(a: P3, b: P3) -> f64 {
    norm(sub(a, b))
}
/// |a - b|^2
#[inline]
pub fn dist2(a: P3, b: P3) -> f64 {
    norm2(sub(a, b))
}
/// (a + b) / 2
#[inline]
pub fn mid(a: P3, b: P3) -> P3 {
    [
        0.5 * (a[0] + b[0]),
        0.5 * (a[1] + b[1]),
        0.5 * (a[2] + b[2]),
    ]
}
/// a / |a| (returns a unchanged when |a| == 0)
#[inline]
pub fn normalize(a: P3) -> P3 {
    let n = norm(a);
    if n > 0.0 {
        scale(a, 1.0 / n)
    } else {
        a
    }
}
/// det[a, b, c] (columns)
#[inline]
pub fn det3(a: P3, b: P3, c: P3) -> f64 {
    dot(a, cross(b, c))
}
/// Signed volume * 6 of tet (a, b, c, d): det[b-a, c-a, d-a] (floating point, not exact).
#[inline]
pub fn tet_det(a: P3, b: P3, c: P3, d: P3) -> f64 {
    det3(sub(b, a), sub(c, a), sub(d, a))
}
/// Unnormalized normal (b-a) x (c-a) of triangle (a, b, c).
#[inline]
pub fn tri_normal(a: P3, b: P3, c: P3) -> P3 {
    cross(sub(b, a), sub(c, a))
}
/// Area of the triangle (a, b, c).
#[inline]
pub fn tri_area(a: P3, b: P3, c: P3) -> f64 {
    0.5 * norm(tri_normal(a, b, c))
}
/// Centroid of a tet.
#[inline]
pub fn centroid4(c: &[P3; 4]) -> P3 {
    let [a, b, d, e] = *c;
    std::array::from_fn(|k| 0.25 * (a[k] + b[k] + d[k] + e[k]))
}

/// Centroid of a triangle.
#[inline]
pub fn centroid3(a: P3, b: P3, c: P3) -> P3 {
    let t = 1.0 / 3.0;
    [
        (a[0] + b[0] + c[0]) * t,
        (a[1] + b[1] + c[1]) * t,
        (a[2] + b[2] + c[2]) * t,
    ]
}
