//! P2 Lagrange shape functions (Gmsh node order) of the 6-node triangle and the 10-node
//! tetrahedron, their derivatives, and the maps they define.
//!
//! Triangle: corners 0, 1, 2 at (0,0), (1,0), (0,1); mid nodes of edges (0,1), (1,2), (2,0).
//! Tetrahedron: corners 0..3 at the origin and unit points; mid nodes of edges
//! (0,1), (1,2), (2,0), (3,0), (3,2), (3,1).

use super::vec3::{cross, P3};

/// Corner pairs of the three triangle edges, in mid-node order (nodes 3, 4, 5).
pub const TRI6_EDGES: [[usize; 2]; 3] = [[0, 1], [1, 2], [2, 0]];

/// Outward faces of a positive tet (v0, v1, v2, v3), by local vertex index, in the order
/// [opposite v3 (the base), opposite v2, opposite v0, opposite v1].
pub const TET_OUT_FACES: [[usize; 3]; 4] = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]];

/// Corner pairs of the six tetrahedron edges, in mid-node order (nodes 4..9).
pub const TET10_EDGES: [[usize; 2]; 6] = [[0, 1], [1, 2], [2, 0], [3, 0], [3, 2], [3, 1]];

/// Values of the six P2 triangle shape functions at (u, v).
#[inline]
pub fn tri6_shape(u: f64, v: f64) -> [f64; 6] {
    let l = [1.0 - u - v, u, v];
    [
        l[0] * (2.0 * l[0] - 1.0),
        l[1] * (2.0 * l[1] - 1.0),
        l[2] * (2.0 * l[2] - 1.0),
        4.0 * l[0] * l[1],
        4.0 * l[1] * l[2],
        4.0 * l[2] * l[0],
    ]
}

/// Derivatives (d/du, d/dv) of the six P2 triangle shape functions at (u, v).
#[inline]
pub fn tri6_grad(u: f64, v: f64) -> [[f64; 2]; 6] {
    let l0 = 1.0 - u - v;
    [
        [1.0 - 4.0 * l0, 1.0 - 4.0 * l0],
        [4.0 * u - 1.0, 0.0],
        [0.0, 4.0 * v - 1.0],
        [4.0 * (l0 - u), -4.0 * u],
        [4.0 * v, 4.0 * u],
        [-4.0 * v, 4.0 * (l0 - v)],
    ]
}

/// Point of the curved triangle at (u, v).
#[inline]
pub fn tri6_point(x: &[P3; 6], u: f64, v: f64) -> P3 {
    let n = tri6_shape(u, v);
    let mut p = [0.0; 3];
    for k in 0..6 {
        for d in 0..3 {
            p[d] += n[k] * x[k][d];
        }
    }
    p
}

/// Tangents (dx/du, dx/dv) of the curved triangle at (u, v).
#[inline]
pub fn tri6_tangents(x: &[P3; 6], u: f64, v: f64) -> (P3, P3) {
    let g = tri6_grad(u, v);
    let mut tu = [0.0; 3];
    let mut tv = [0.0; 3];
    for k in 0..6 {
        for d in 0..3 {
            tu[d] += g[k][0] * x[k][d];
            tv[d] += g[k][1] * x[k][d];
        }
    }
    (tu, tv)
}

/// Unnormalized normal dx/du x dx/dv of the curved triangle at (u, v); its length is
/// the area density (dA = |n| du dv).
#[inline]
pub fn tri6_normal(x: &[P3; 6], u: f64, v: f64) -> P3 {
    let (tu, tv) = tri6_tangents(x, u, v);
    cross(tu, tv)
}

/// Values of the ten P2 tetrahedron shape functions at reference point `xi`.
#[inline]
pub fn tet10_shape(xi: [f64; 3]) -> [f64; 10] {
    let l = [1.0 - xi[0] - xi[1] - xi[2], xi[0], xi[1], xi[2]];
    let mut n = [0.0; 10];
    for i in 0..4 {
        n[i] = l[i] * (2.0 * l[i] - 1.0);
    }
    for (k, [a, b]) in TET10_EDGES.iter().enumerate() {
        n[4 + k] = 4.0 * l[*a] * l[*b];
    }
    n
}

/// Gradients (d/dxi, d/deta, d/dzeta) of the ten P2 tetrahedron shape functions.
#[inline]
pub fn tet10_grad(xi: [f64; 3]) -> [[f64; 3]; 10] {
    let l = [1.0 - xi[0] - xi[1] - xi[2], xi[0], xi[1], xi[2]];
    // d(lambda_i)/d(xi_d)
    const DL: [[f64; 3]; 4] = [
        [-1.0, -1.0, -1.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let mut g = [[0.0; 3]; 10];
    for i in 0..4 {
        for d in 0..3 {
            g[i][d] = (4.0 * l[i] - 1.0) * DL[i][d];
        }
    }
    for (k, [a, b]) in TET10_EDGES.iter().enumerate() {
        for d in 0..3 {
            g[4 + k][d] = 4.0 * (l[*a] * DL[*b][d] + l[*b] * DL[*a][d]);
        }
    }
    g
}

/// The Jacobian matrix dx/dxi (rows: x, y, z; columns: xi, eta, zeta) at `xi`.
#[inline]
pub fn tet10_jacobian_matrix(x: &[P3; 10], xi: [f64; 3]) -> [[f64; 3]; 3] {
    let g = tet10_grad(xi);
    let mut j = [[0.0; 3]; 3];
    for k in 0..10 {
        for r in 0..3 {
            for c in 0..3 {
                j[r][c] += x[k][r] * g[k][c];
            }
        }
    }
    j
}

/// det(dx/dxi) at `xi`: six times the local volume ratio; equal to det[v1-v0, v2-v0,
/// v3-v0] everywhere for a straight-sided tet.
#[inline]
pub fn tet10_det_jacobian(x: &[P3; 10], xi: [f64; 3]) -> f64 {
    let j = tet10_jacobian_matrix(x, xi);
    j[0][0] * (j[1][1] * j[2][2] - j[1][2] * j[2][1])
        - j[0][1] * (j[1][0] * j[2][2] - j[1][2] * j[2][0])
        + j[0][2] * (j[1][0] * j[2][1] - j[1][1] * j[2][0])
}

/// Point of the curved tet at `xi`.
#[inline]
pub fn tet10_point(x: &[P3; 10], xi: [f64; 3]) -> P3 {
    let n = tet10_shape(xi);
    let mut p = [0.0; 3];
    for k in 0..10 {
        for d in 0..3 {
            p[d] += n[k] * x[k][d];
        }
    }
    p
}

/// The ten nodes of the straight-sided P2 tet on corners `c` (mid nodes at edge midpoints).
pub fn straight_tet10(c: [P3; 4]) -> [P3; 10] {
    let mut x = [[0.0; 3]; 10];
    x[..4].copy_from_slice(&c);
    for (k, [a, b]) in TET10_EDGES.iter().enumerate() {
        x[4 + k] = super::vec3::mid(c[*a], c[*b]);
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    fn finite_diff_ok(f: impl Fn(f64, f64, f64) -> f64, g: [f64; 3], p: [f64; 3]) {
        let h = 1e-6;
        for d in 0..3 {
            let mut a = p;
            let mut b = p;
            a[d] -= h;
            b[d] += h;
            let fd = (f(b[0], b[1], b[2]) - f(a[0], a[1], a[2])) / (2.0 * h);
            assert!((fd - g[d]).abs() < 1e-6, "d{d}: fd {fd} vs {}", g[d]);
        }
    }

    #[test]
    fn tri6_partition_of_unity_and_nodality() {
        let pts = [
            [0.0, 0.0],
            [1.0, 0.0],
            [0.0, 1.0],
            [0.5, 0.0],
            [0.5, 0.5],
            [0.0, 0.5],
        ];
        for (i, p) in pts.iter().enumerate() {
            let n = tri6_shape(p[0], p[1]);
            for (j, v) in n.iter().enumerate() {
                assert!((v - if i == j { 1.0 } else { 0.0 }).abs() < 1e-15);
            }
        }
        let g = tri6_grad(0.2, 0.3);
        let s: [f64; 2] = g.iter().fold([0.0, 0.0], |a, x| [a[0] + x[0], a[1] + x[1]]);
        assert!(s[0].abs() < 1e-14 && s[1].abs() < 1e-14);
        for (k, gk) in g.iter().enumerate() {
            finite_diff_ok(
                |u, v, _| tri6_shape(u, v)[k],
                [gk[0], gk[1], 0.0],
                [0.2, 0.3, 0.0],
            );
        }
    }

    #[test]
    fn tet10_partition_nodality_and_gradients() {
        let corners = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ];
        let ref_nodes = straight_tet10(corners);
        for (i, p) in ref_nodes.iter().enumerate() {
            let n = tet10_shape(*p);
            for (j, v) in n.iter().enumerate() {
                assert!(
                    (v - if i == j { 1.0 } else { 0.0 }).abs() < 1e-15,
                    "node {i} fn {j}"
                );
            }
        }
        let p = [0.15, 0.2, 0.3];
        let g = tet10_grad(p);
        for (k, gk) in g.iter().enumerate() {
            finite_diff_ok(|a, b, c| tet10_shape([a, b, c])[k], *gk, p);
        }
    }

    #[test]
    fn straight_tet_has_constant_jacobian() {
        let c = [
            [0.1, 0.2, 0.3],
            [1.3, 0.1, 0.2],
            [0.2, 1.1, 0.1],
            [0.3, 0.4, 0.9],
        ];
        let x = straight_tet10(c);
        let d0 = super::super::vec3::tet_det(c[0], c[1], c[2], c[3]);
        for p in [
            [0.0, 0.0, 0.0],
            [0.25, 0.25, 0.25],
            [0.1, 0.7, 0.1],
            [0.0, 0.0, 1.0],
        ] {
            assert!((tet10_det_jacobian(&x, p) - d0).abs() < 1e-13);
        }
    }
}
