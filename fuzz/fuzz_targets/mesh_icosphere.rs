//! Meshes small fuzzed closed surfaces: a P2 icosphere (20 or 80 triangles) whose nodes the
//! bytes move (corners radially and tangentially, mid nodes off their edges), optionally a
//! fuzzed size/alpha. Whatever `generate` returns must be a conforming, certified mesh of
//! that surface, or a clean error (`MeshingFailed`); `InvalidMesh` (the bug guard fired)
//! and panics are failures.
#![no_main]
use curvetet::mesh::check::check_conformity;
use curvetet::mesh::quality::uncertified;
use curvetet::surface::demo::icosphere;
use curvetet::{generate, Error, Options, SizeMode, Surface};
use libfuzzer_sys::fuzz_target;

fn signed(b: u8) -> f64 {
    (b as f64 - 128.0) / 128.0
}

fuzz_target!(|data: &[u8]| {
    let Some((&mode, d)) = data.split_first() else {
        return;
    };
    let (mut nodes, tris) = icosphere(u32::from(mode & 1));
    let amp = [0.05, 0.15, 0.3, 0.6][(mode as usize >> 1) & 3];
    for (p, c) in nodes.iter_mut().zip(d.chunks_exact(3)) {
        for k in 0..3 {
            p[k] += amp * signed(c[k]);
        }
    }
    let surface = match Surface::new(nodes, tris, vec![]) {
        Ok(s) => s,
        Err(e) => return curvetet_fuzz::check_error(&e),
    };
    let mut opts = Options {
        threads: 1,
        optimize: mode & 8 != 0,
        ..Options::default()
    };
    match (mode >> 4) & 3 {
        0 => opts.size = SizeMode::Graded,
        1 => opts.size = SizeMode::Uniform,
        2 => opts.size = SizeMode::Fixed(0.3 + 0.5 * signed(*d.last().unwrap_or(&200)).abs()),
        _ => opts.alpha = 1.0 + signed(*d.last().unwrap_or(&128)).abs(),
    }
    match generate(&surface, &opts) {
        Ok(g) => {
            let conf = check_conformity(&g.mesh).expect("generate returned a non-conforming mesh");
            assert_eq!(conf.boundary_faces, surface.triangles().len());
            let bad = uncertified(&g.mesh);
            assert!(bad.is_empty(), "generate returned uncertified elements {bad:?}");
            assert_eq!(g.mesh.boundary.len(), surface.triangles().len());
        }
        Err(Error::MeshingFailed { .. }) => {}
        Err(e) => panic!("generate failed: {e}"),
    }
});
