//! Shared helpers for the geometry unit tests (random well-shaped and curved tets,
//! reference-tet lattices, the unit cube's surface).

use super::shape::straight_tet10;
use super::vec3::{tet_det, P3};
use rand::rngs::StdRng;
use rand::Rng;

/// The (n+1)(n+2)(n+3)/6 points of the order-n lattice of the reference tet.
pub fn lattice(n: usize) -> Vec<[f64; 3]> {
    let mut out = Vec::new();
    for i in 0..=n {
        for j in 0..=n - i {
            for k in 0..=n - i - j {
                out.push([
                    i as f64 / n as f64,
                    j as f64 / n as f64,
                    k as f64 / n as f64,
                ]);
            }
        }
    }
    out
}

/// A uniformly random point of the reference tet.
pub fn random_ref_point(rng: &mut StdRng) -> [f64; 3] {
    loop {
        let p: [f64; 3] = [rng.random(), rng.random(), rng.random()];
        if p[0] + p[1] + p[2] <= 1.0 {
            return p;
        }
    }
}

/// Corners of a random well-shaped positive tet (edge ~2.8, det > 0.5), near the origin.
pub fn random_corners(rng: &mut StdRng) -> [P3; 4] {
    // A regular tet, randomly stretched, rotated (via random linear map close to
    // identity) and translated: well shaped, positive.
    let reg = [
        [1.0, 1.0, 1.0],
        [1.0, -1.0, -1.0],
        [-1.0, 1.0, -1.0],
        [-1.0, -1.0, 1.0],
    ];
    loop {
        let mut a = [[0.0; 3]; 3];
        for (r, row) in a.iter_mut().enumerate() {
            for (c, v) in row.iter_mut().enumerate() {
                *v = if r == c { 1.0 } else { 0.0 } + rng.random_range(-0.4..0.4);
            }
        }
        let t = [
            rng.random_range(-2.0..2.0),
            rng.random_range(-2.0..2.0),
            rng.random_range(-2.0..2.0),
        ];
        let mut c = [[0.0; 3]; 4];
        for (k, p) in reg.iter().enumerate() {
            for r in 0..3 {
                c[k][r] = t[r] + a[r][0] * p[0] + a[r][1] * p[1] + a[r][2] * p[2];
            }
        }
        // reg is negatively oriented; swap to make it positive.
        c.swap(0, 1);
        if tet_det(c[0], c[1], c[2], c[3]) > 0.5 {
            return c;
        }
    }
}

/// A random curved P2 tet: [`random_corners`] with mid nodes moved by up to `amp` per
/// coordinate (amp > 0). Large amp gives invalid (tangled) elements.
pub fn random_curved(rng: &mut StdRng, amp: f64) -> [P3; 10] {
    let mut x = straight_tet10(random_corners(rng));
    for p in x.iter_mut().skip(4) {
        for v in p.iter_mut() {
            *v += rng.random_range(-amp..amp);
        }
    }
    x
}

/// The unit cube's corners (bit 0: x, bit 1: y, bit 2: z) and its 12 outward triangles.
pub fn unit_cube() -> (Vec<P3>, Vec<[u32; 3]>) {
    let pts = (0..8u32)
        .map(|i| [i & 1, (i >> 1) & 1, (i >> 2) & 1].map(f64::from))
        .collect();
    // Outward quads split into triangles.
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let faces = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    (pts, faces)
}
