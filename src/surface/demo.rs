//! The built-in example: a P2 torus surface built analytically, every node (corners and
//! mid nodes) exactly on the torus, for the demo and the benchmarks.

use crate::geom::P3;
use std::f64::consts::PI;

/// Triangulated torus with major radius `big_r`, minor radius `r`, `nu` segments around
/// the axis (z) and `nv` around the tube; outward 6-node triangles (Gmsh order).
/// Mid nodes sit at the parametric midpoints, on the torus.
pub fn torus(nu: usize, nv: usize, big_r: f64, r: f64) -> (Vec<P3>, Vec<[u32; 6]>) {
    let (nu, nv) = (nu.max(3), nv.max(3));
    let x = |u: f64, v: f64| -> P3 {
        let (su, cu) = (2.0 * PI * u).sin_cos();
        let (sv, cv) = (2.0 * PI * v).sin_cos();
        [(big_r + r * cv) * cu, (big_r + r * cv) * su, r * sv]
    };
    // Node lattice at half steps: (2*nu) x (2*nv) points; even/even are corners.
    let (mu, mv) = (2 * nu, 2 * nv);
    let id = |a: usize, b: usize| ((a % mu) * mv + (b % mv)) as u32;
    let mut nodes = Vec::with_capacity(mu * mv);
    for a in 0..mu {
        for b in 0..mv {
            nodes.push(x(a as f64 / mu as f64, b as f64 / mv as f64));
        }
    }
    let mut tris = Vec::with_capacity(2 * nu * nv);
    for i in 0..nu {
        for j in 0..nv {
            let (a, b) = (2 * i, 2 * j);
            // Quad (a,b) (a+2,b) (a+2,b+2) (a,b+2), split along (a,b)-(a+2,b+2).
            tris.push([
                id(a, b),
                id(a + 2, b),
                id(a + 2, b + 2),
                id(a + 1, b),
                id(a + 2, b + 1),
                id(a + 1, b + 1),
            ]);
            tris.push([
                id(a, b),
                id(a + 2, b + 2),
                id(a, b + 2),
                id(a + 1, b + 1),
                id(a + 1, b + 2),
                id(a, b + 1),
            ]);
        }
    }
    // Drop lattice points that are no node of any triangle (odd/odd off the diagonals).
    let mut used = vec![false; nodes.len()];
    for t in &tris {
        for &v in t {
            used[v as usize] = true;
        }
    }
    let mut remap = vec![u32::MAX; nodes.len()];
    let mut kept = Vec::new();
    for (i, p) in nodes.iter().enumerate() {
        if used[i] {
            remap[i] = kept.len() as u32;
            kept.push(*p);
        }
    }
    for t in &mut tris {
        for v in t.iter_mut() {
            *v = remap[*v as usize];
        }
    }
    (kept, tris)
}

/// Segment counts giving near-equilateral triangles with about `n_tris` triangles on the
/// torus (R, r).
pub fn torus_resolution(n_tris: usize, big_r: f64, r: f64) -> (usize, usize) {
    let ratio = big_r / r; // nu / nv for square quads
    let nv = ((n_tris as f64 / (2.0 * ratio)).sqrt().round() as usize).max(3);
    let nu = ((nv as f64 * ratio).round() as usize).max(3);
    (nu, nv)
}

/// A closed P2 icosphere of radius 1: `20 * 4^level` triangles, mid nodes on the sphere.
pub fn icosphere(level: u32) -> (Vec<P3>, Vec<[u32; 6]>) {
    use std::collections::HashMap;
    let g = (1.0 + 5f64.sqrt()) / 2.0;
    let mut v: Vec<[f64; 3]> = vec![
        [-1.0, g, 0.0],
        [1.0, g, 0.0],
        [-1.0, -g, 0.0],
        [1.0, -g, 0.0],
        [0.0, -1.0, g],
        [0.0, 1.0, g],
        [0.0, -1.0, -g],
        [0.0, 1.0, -g],
        [g, 0.0, -1.0],
        [g, 0.0, 1.0],
        [-g, 0.0, -1.0],
        [-g, 0.0, 1.0],
    ];
    let mut f: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    let unit = |p: [f64; 3]| {
        let n = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        [p[0] / n, p[1] / n, p[2] / n]
    };
    for p in v.iter_mut() {
        *p = unit(*p);
    }
    let midpoint = |v: &mut Vec<[f64; 3]>, cache: &mut HashMap<(u32, u32), u32>, a: u32, b: u32| {
        let key = (a.min(b), a.max(b));
        *cache.entry(key).or_insert_with(|| {
            let (p, q) = (v[a as usize], v[b as usize]);
            v.push(unit([p[0] + q[0], p[1] + q[1], p[2] + q[2]]));
            v.len() as u32 - 1
        })
    };
    for _ in 0..level {
        let mut cache = HashMap::new();
        let mut nf = Vec::with_capacity(4 * f.len());
        for t in &f {
            let a = midpoint(&mut v, &mut cache, t[0], t[1]);
            let b = midpoint(&mut v, &mut cache, t[1], t[2]);
            let c = midpoint(&mut v, &mut cache, t[2], t[0]);
            nf.extend([[t[0], a, c], [t[1], b, a], [t[2], c, b], [a, b, c]]);
        }
        f = nf;
    }
    let mut cache = HashMap::new();
    let mut tris = Vec::with_capacity(f.len());
    for t in &f {
        let a = midpoint(&mut v, &mut cache, t[0], t[1]);
        let b = midpoint(&mut v, &mut cache, t[1], t[2]);
        let c = midpoint(&mut v, &mut cache, t[2], t[0]);
        tris.push([t[0], t[1], t[2], a, b, c]);
    }
    (v, tris)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn demo_torus_is_a_valid_surface_with_the_right_volume() {
        let (nodes, tris) = torus(36, 12, 1.0, 0.35);
        let s = crate::Surface::new(nodes, tris, vec![]).expect("demo torus passes the checks");
        let v = crate::geom::quadrature::enclosed_volume(s.nodes(), s.triangles());
        let exact = 2.0 * PI * PI * 1.0 * 0.35 * 0.35;
        assert!((v - exact).abs() / exact < 1e-3, "volume {v} vs {exact}");
        assert!(s.warnings().is_empty());
    }
}
