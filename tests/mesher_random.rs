//! Robustness of the mesher: the data surfaces under random rotations and scalings by
//! 1e-3 and 1e3, and randomly generated closed P2 surfaces (perturbed spheres and tori),
//! all checked independently (tests/common/meshcheck.rs).

#[path = "common/meshcheck.rs"]
mod meshcheck;

use curvetet::geom::P3;
use curvetet::{generate, io, Options, Surface};
use meshcheck::check_mesh;
use rand::{Rng, SeedableRng};
use std::path::PathBuf;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// A random rotation matrix (from a random unit quaternion).
fn rotation(rng: &mut impl Rng) -> [[f64; 3]; 3] {
    let (u1, u2, u3): (f64, f64, f64) = (rng.random(), rng.random(), rng.random());
    let tau = std::f64::consts::TAU;
    let q = [
        (1.0 - u1).sqrt() * (tau * u2).sin(),
        (1.0 - u1).sqrt() * (tau * u2).cos(),
        u1.sqrt() * (tau * u3).sin(),
        u1.sqrt() * (tau * u3).cos(),
    ];
    let (x, y, z, w) = (q[0], q[1], q[2], q[3]);
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - z * w),
            2.0 * (x * z + y * w),
        ],
        [
            2.0 * (x * y + z * w),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - x * w),
        ],
        [
            2.0 * (x * z - y * w),
            2.0 * (y * z + x * w),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

fn transform(nodes: &[P3], r: &[[f64; 3]; 3], s: f64) -> Vec<P3> {
    nodes
        .iter()
        .map(|p| std::array::from_fn(|i| s * (r[i][0] * p[0] + r[i][1] * p[1] + r[i][2] * p[2])))
        .collect()
}

#[test]
fn rotated_and_scaled_data_surfaces() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(7);
    for name in ["sphere", "torus", "tube", "lv", "screw", "hinge"] {
        let s = io::read_surface(&data(&format!("{name}_p2.msh"))).unwrap();
        for scale in [1e-3, 1.0, 1e3] {
            let r = rotation(&mut rng);
            let nodes = transform(s.nodes(), &r, scale);
            let t = Surface::new(nodes, s.triangles().to_vec(), s.tags().to_vec())
                .unwrap_or_else(|e| panic!("{name} x{scale}: rotated surface rejected: {e}"));
            let g = generate(&t, &Options::default())
                .unwrap_or_else(|e| panic!("{name} rotated, x{scale}: {e}"));
            check_mesh(&t, &g.mesh);
        }
    }
}

/// A perturbed P2 icosphere: radius 1 + amp * f(direction), every node on the surface.
fn bumpy_sphere(level: u32, amp: f64, k: [f64; 3], shift: P3) -> (Vec<P3>, Vec<[u32; 6]>) {
    let (nodes, tris) = curvetet::surface::demo::icosphere(level);
    let f = |p: P3| {
        let r = 1.0 + amp * ((k[0] * p[0]).sin() * (k[1] * p[1]).cos() + 0.5 * (k[2] * p[2]).sin());
        [
            r * p[0] + shift[0],
            r * p[1] + shift[1],
            r * p[2] + shift[2],
        ]
    };
    (nodes.into_iter().map(f).collect(), tris)
}

#[test]
fn fifty_random_closed_surfaces() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(2026);
    let mut done = 0;
    for i in 0..50 {
        let (nodes, tris) = if i % 2 == 0 {
            let level = 1 + (i / 2) % 3;
            let amp = rng.random_range(0.0..0.25);
            let k = [
                rng.random_range(1.0..4.0),
                rng.random_range(1.0..4.0),
                rng.random_range(1.0..4.0),
            ];
            let shift = [
                rng.random_range(-5.0..5.0),
                rng.random_range(-5.0..5.0),
                rng.random_range(-5.0..5.0),
            ];
            bumpy_sphere(level as u32, amp, k, shift)
        } else {
            let big_r = rng.random_range(1.0..2.0);
            let r = rng.random_range(0.2..0.6);
            let nv = rng.random_range(6..14);
            let nu = ((nv as f64) * big_r / r).round() as usize;
            let (nodes, tris) = curvetet::surface::demo::torus(nu, nv, big_r, r);
            let amp = rng.random_range(0.0..0.3) * r;
            let nodes = nodes
                .into_iter()
                .map(|p| {
                    let s = 1.0 + amp * (3.0 * p[2]).sin() * (2.0 * p[0]).cos();
                    [p[0] * s, p[1] * s, p[2]]
                })
                .collect();
            (nodes, tris)
        };
        let s = Surface::new(nodes, tris, vec![])
            .unwrap_or_else(|e| panic!("random surface {i} rejected: {e}"));
        let g =
            generate(&s, &Options::default()).unwrap_or_else(|e| panic!("random surface {i}: {e}"));
        check_mesh(&s, &g.mesh);
        done += 1;
    }
    assert_eq!(done, 50);
}
