//! Timing of the surface checks (run in release mode; the large cases are ignored):
//!
//!     cargo test --release --test surface_timing -- --ignored --nocapture
//!
//! Prints the time of `Surface::new` on the largest data surface (tube, 2292 triangles)
//! and on synthetic P2 icospheres of 82k, 328k and 1.3M triangles.

mod common;

use common::{icosphere, read_msh41, shared_data_dir};
use curvetet::Surface;
use std::time::Instant;

fn time_it(label: &str, nodes: Vec<[f64; 3]>, tris: Vec<[u32; 6]>) -> f64 {
    let n = tris.len();
    let t0 = Instant::now();
    let s = Surface::new(nodes, tris, vec![]).unwrap_or_else(|e| panic!("{label}: {e}"));
    let dt = t0.elapsed().as_secs_f64();
    assert!(s.warnings().is_empty());
    eprintln!(
        "{label}: {n} triangles, checks {:.3} s ({:.3} s per 1e5 triangles)",
        dt,
        dt * 1e5 / n as f64
    );
    dt
}

#[test]
fn small_icosphere_passes() {
    let (v, t) = icosphere(3);
    let s = Surface::new(v, t, vec![]).unwrap();
    assert_eq!(s.triangles().len(), 1280);
    assert!((s.volume() - 4.0 / 3.0 * std::f64::consts::PI).abs() < 1e-3);
}

#[test]
#[ignore = "timing; run in release with --ignored --nocapture"]
fn timing_tube_and_large_spheres() {
    if let Some(dir) = shared_data_dir() {
        let m = read_msh41(&dir.join("tube_p2.msh"));
        time_it("tube", m.nodes, m.tris);
    }
    for level in [6, 7, 8] {
        let (v, t) = icosphere(level);
        time_it(&format!("icosphere level {level}"), v, t);
    }
}
