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

/// CPU time (user + system) of the whole process so far, in seconds.
fn cpu_seconds() -> f64 {
    // SAFETY: getrusage only writes the struct we pass.
    let mut r: libc::rusage = unsafe { std::mem::zeroed() };
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut r) };
    let tv = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    tv(r.ru_utime) + tv(r.ru_stime)
}

/// Wall and CPU time of `Surface::new` (best of `reps`: the machine may be shared).
fn time_it(label: &str, nodes: Vec<[f64; 3]>, tris: Vec<[u32; 6]>, reps: usize) {
    let n = tris.len();
    let (mut wall, mut cpu) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..reps {
        let (nodes, tris) = (nodes.clone(), tris.clone());
        let (t0, c0) = (Instant::now(), cpu_seconds());
        let s = Surface::new(nodes, tris, vec![]).unwrap_or_else(|e| panic!("{label}: {e}"));
        let (dt, dc) = (t0.elapsed().as_secs_f64(), cpu_seconds() - c0);
        assert!(s.warnings().is_empty());
        drop(s);
        wall = wall.min(dt);
        cpu = cpu.min(dc);
    }
    eprintln!(
        "{label}: {n} triangles, checks {wall:.3} s wall, {cpu:.3} s CPU \
         ({:.3} s wall, {:.3} s CPU per 1e5 triangles; {} rayon threads)",
        wall * 1e5 / n as f64,
        cpu * 1e5 / n as f64,
        rayon::current_num_threads()
    );
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
        time_it("tube", m.nodes, m.tris, 20);
    }
    for (level, reps) in [(6, 5), (7, 3), (8, 1)] {
        let (v, t) = icosphere(level);
        time_it(&format!("icosphere level {level}"), v, t, reps);
    }
}
