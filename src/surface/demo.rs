//! The built-in example: a P2 torus surface built analytically, every node (corners and
//! mid nodes) exactly on the torus, for the demo and the benchmarks.

use crate::geom::P3;
use std::f64::consts::PI;

/// Triangulated torus with major radius `big_r`, minor radius `r`, `nu` corners around
/// the axis (z) and `nv` rings around the tube (`nv` is rounded up to even); outward
/// 6-node triangles (Gmsh order). Alternate rings are shifted by half a step, so the
/// triangles are close to equilateral; mid nodes sit at the parametric midpoints, on
/// the torus.
pub fn torus(nu: usize, nv: usize, big_r: f64, r: f64) -> (Vec<P3>, Vec<[u32; 6]>) {
    use std::collections::HashMap;
    let nu = nu.max(3);
    let nv = nv.max(4).div_ceil(2) * 2;
    // Parametric position (u in corner steps, v in ring steps) -> point; periodic.
    let x = |u: f64, v: f64| -> P3 {
        let (su, cu) = (2.0 * PI * u / nu as f64).sin_cos();
        let (sv, cv) = (2.0 * PI * v / nv as f64).sin_cos();
        [(big_r + r * cv) * cu, (big_r + r * cv) * su, r * sv]
    };
    let shift = |j: usize| if j % 2 == 1 { 0.5 } else { 0.0 };
    let corner = |i: usize, j: usize| ((j % nv) * nu + (i % nu)) as u32;
    let mut nodes: Vec<P3> = Vec::with_capacity(4 * nu * nv);
    for j in 0..nv {
        for i in 0..nu {
            nodes.push(x(i as f64 + shift(j), j as f64));
        }
    }
    let mut mids: HashMap<(u32, u32), u32> = HashMap::new();
    let mut tris = Vec::with_capacity(2 * nu * nv);
    // Each corner given as (id, u, v) in unwrapped parameters.
    let mut tri = |c: [(u32, f64, f64); 3], nodes: &mut Vec<P3>| {
        let mut t = [c[0].0, c[1].0, c[2].0, 0, 0, 0];
        for (k, (a, b)) in [(0, 1), (1, 2), (2, 0)].into_iter().enumerate() {
            let key = (c[a].0.min(c[b].0), c[a].0.max(c[b].0));
            t[3 + k] = *mids.entry(key).or_insert_with(|| {
                nodes.push(x(0.5 * (c[a].1 + c[b].1), 0.5 * (c[a].2 + c[b].2)));
                (nodes.len() - 1) as u32
            });
        }
        tris.push(t);
    };
    for j in 0..nv {
        let (v0, v1) = (j as f64, (j + 1) as f64);
        for i in 0..nu {
            let p = |ii: usize, jj: usize, vv: f64| (corner(ii, jj), ii as f64 + shift(jj), vv);
            if j % 2 == 0 {
                // Ring j at u = i, ring j+1 at u = i + 1/2.
                tri([p(i, j, v0), p(i + 1, j, v0), p(i, j + 1, v1)], &mut nodes);
                tri(
                    [p(i + 1, j, v0), p(i + 1, j + 1, v1), p(i, j + 1, v1)],
                    &mut nodes,
                );
            } else {
                // Ring j at u = i + 1/2, ring j+1 at u = i.
                tri(
                    [p(i, j, v0), p(i + 1, j, v0), p(i + 1, j + 1, v1)],
                    &mut nodes,
                );
                tri(
                    [p(i, j, v0), p(i + 1, j + 1, v1), p(i, j + 1, v1)],
                    &mut nodes,
                );
            }
        }
    }
    (nodes, tris)
}

/// Segment counts giving near-equilateral triangles with about `n_tris` triangles on the
/// torus (R, r).
pub fn torus_resolution(n_tris: usize, big_r: f64, r: f64) -> (usize, usize) {
    // Equilateral triangles: ring spacing (2 pi r / nv) = sqrt(3)/2 of the corner spacing
    // (2 pi R / nu) on the tube's mean circle.
    let ratio = big_r / r * 3f64.sqrt() / 2.0; // nu / nv
    let nv = ((((n_tris as f64 / (2.0 * ratio)).sqrt() / 2.0).round() as usize) * 2).max(4);
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
    let unit = crate::geom::vec3::normalize;
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

/// Two regions: an icosphere of radius `inner` inside one of radius `outer` (both at
/// `level`, [`icosphere`]): the inner sphere is the interface between the ball and the
/// shell around it. The inner sphere's triangles come first, each sphere outward.
pub fn nested_spheres(level: u32, inner: f64, outer: f64) -> (Vec<P3>, Vec<[u32; 6]>) {
    let (v, t) = icosphere(level);
    let n = v.len() as u32;
    let mut nodes: Vec<P3> = v.iter().map(|p| p.map(|x| x * inner)).collect();
    nodes.extend(v.iter().map(|p| p.map(|x| x * outer)));
    let mut tris = t.clone();
    tris.extend(t.iter().map(|x| x.map(|i| i + n)));
    (nodes, tris)
}

/// Two regions: the boxes [0, 1] x [0, 1] x [0, 1] and [1, 2] x [0, 1] x [0, 1], each face
/// split into `n` x `n` squares of two flat P2 triangles (mid nodes at edge midpoints);
/// the shared square x = 1 appears once. Every triangle faces out of the box it was made
/// for (the shared square: out of the first box).
pub fn split_box(n: usize) -> (Vec<P3>, Vec<[u32; 6]>) {
    use std::collections::HashMap;
    let n = n.max(1);
    // Nodes on a lattice of spacing 1 / (2n), keyed by integer coordinates.
    let mut ids: HashMap<[i64; 3], u32> = HashMap::new();
    let mut nodes: Vec<P3> = Vec::new();
    let h = 1.0 / (2 * n) as f64;
    let mut node = |k: [i64; 3]| {
        *ids.entry(k).or_insert_with(|| {
            nodes.push(k.map(|x| x as f64 * h));
            nodes.len() as u32 - 1
        })
    };
    let mut tris: Vec<[u32; 6]> = Vec::new();
    let mut seen = std::collections::HashSet::new();
    let m = 2 * n as i64;
    for x0 in [0i64, m] {
        // The six faces: (axis, at, outward sign).
        for (axis, at, sign) in [
            (0, x0, -1),
            (0, x0 + m, 1),
            (1, 0, -1),
            (1, m, 1),
            (2, 0, -1),
            (2, m, 1),
        ] {
            let (u, w) = ((axis + 1) % 3, (axis + 2) % 3);
            let base = |a: i64, b: i64| {
                let mut k = [0i64; 3];
                k[axis] = at;
                k[u] = a + if u == 0 { x0 } else { 0 };
                k[w] = b + if w == 0 { x0 } else { 0 };
                k
            };
            for i in 0..n as i64 {
                for j in 0..n as i64 {
                    let (a, b) = (2 * i, 2 * j);
                    let c = [
                        base(a, b),
                        base(a + 2, b),
                        base(a + 2, b + 2),
                        base(a, b + 2),
                    ];
                    for q in [[0, 1, 2], [0, 2, 3]] {
                        // Counterclockwise in (u, w) faces +axis.
                        let mut k = q.map(|i| c[i]);
                        if sign < 0 {
                            k.swap(1, 2);
                        }
                        let mid = |p: [i64; 3], r: [i64; 3]| {
                            [(p[0] + r[0]) / 2, (p[1] + r[1]) / 2, (p[2] + r[2]) / 2]
                        };
                        let mut key = k;
                        key.sort_unstable();
                        if !seen.insert(key) {
                            continue;
                        }
                        tris.push([
                            node(k[0]),
                            node(k[1]),
                            node(k[2]),
                            node(mid(k[0], k[1])),
                            node(mid(k[1], k[2])),
                            node(mid(k[2], k[0])),
                        ]);
                    }
                }
            }
        }
    }
    (nodes, tris)
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
