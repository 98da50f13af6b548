//! Mixed-scale benchmark of the surface checks (issue 29): a 327,680-triangle P2 sphere of
//! radius 1e-3 inside a 12-triangle cube of side 1000, against the sphere alone.
//!
//!     cargo bench --bench mixed_scale
//!
//! With one uniform broad-phase grid sized from the mean triangle, the few huge cube
//! triangles made every small triangle share one cell and the check quadratic; with a
//! grid per size level the two take about as long. Prints both times and their ratio
//! (best of three runs each). Timing only; nothing is asserted (the pair sets are tested
//! against brute force in the unit tests).

use curvetet::surface::demo::icosphere;
use curvetet::Surface;
use std::time::Instant;

type P3 = [f64; 3];

/// The sphere: `icosphere(7)` scaled to radius 1e-3, oriented inward (a cavity in the
/// cube), so the two shells make one valid body.
fn sphere() -> (Vec<P3>, Vec<[u32; 6]>) {
    let (nodes, tris) = icosphere(7);
    let nodes = nodes.iter().map(|p| p.map(|x| 1e-3 * x)).collect();
    let tris = tris
        .iter()
        .map(|t| [t[0], t[2], t[1], t[5], t[4], t[3]])
        .collect();
    (nodes, tris)
}

/// A P2 cube of side 1000 centred at the origin, outward, appended to `nodes`.
fn add_cube(nodes: &mut Vec<P3>, tris: &mut Vec<[u32; 6]>) {
    use std::collections::HashMap;
    let base = nodes.len() as u32;
    for k in 0..8 {
        let c = |b: u32| if k & b != 0 { 500.0 } else { -500.0 };
        nodes.push([c(1), c(2), c(4)]);
    }
    // Each face as two outward triangles (corner bits: x = 1, y = 2, z = 4).
    let quads: [[u32; 4]; 6] = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
    let mut m = |nodes: &mut Vec<P3>, a: u32, b: u32| -> u32 {
        *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
            let (p, q) = (nodes[a as usize], nodes[b as usize]);
            nodes.push([0, 1, 2].map(|d| 0.5 * (p[d] + q[d])));
            nodes.len() as u32 - 1
        })
    };
    for q in quads {
        for [a, b, c] in [[q[0], q[1], q[2]], [q[0], q[2], q[3]]] {
            let [a, b, c] = [a + base, b + base, c + base];
            let t = [a, b, c, m(nodes, a, b), m(nodes, b, c), m(nodes, c, a)];
            tris.push(t);
        }
    }
}

/// Best of three wall times of the surface checks on (nodes, tris), in seconds.
fn time_checks(nodes: &[P3], tris: &[[u32; 6]]) -> f64 {
    (0..3)
        .map(|_| {
            let (n, t) = (nodes.to_vec(), tris.to_vec());
            let s = Instant::now();
            let r = Surface::new(n, t, vec![]);
            let e = s.elapsed().as_secs_f64();
            if let Err(err) = r {
                panic!("the benchmark surface should pass the checks: {err}");
            }
            e
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    let (nodes, tris) = sphere();
    let alone = time_checks(&nodes, &tris);
    let (mut nodes2, mut tris2) = (nodes, tris);
    add_cube(&mut nodes2, &mut tris2);
    let mixed = time_checks(&nodes2, &tris2);
    println!(
        "surface checks, {} triangles: sphere alone {alone:.2} s, sphere in a cube of side \
         1000 ({} triangles) {mixed:.2} s, ratio {:.2}",
        tris2.len() - 12,
        tris2.len(),
        mixed / alone
    );
}
