//! Throughput of the readers and writers on about a million P2 tets. A measurement, not
//! a timed test: run it with
//! `cargo test --release --test io_perf -- --ignored --nocapture`.

use std::time::Instant;

use curvetet::io::{self, Format, MshVersion, WriteOptions};
use curvetet::TetMesh;

/// A P2 mesh of an n x n x n grid of cubes, six (Kuhn) tets per cube, mid nodes on the
/// doubled grid, with its boundary triangles.
fn grid_mesh(n: usize) -> TetMesh {
    let m = 2 * n + 1;
    let id = |x: usize, y: usize, z: usize| (x + m * (y + m * z)) as u32;
    let mut nodes = Vec::with_capacity(m * m * m);
    for z in 0..m {
        for y in 0..m {
            for x in 0..m {
                let h = 0.5 / n as f64;
                nodes.push([x as f64 * h, y as f64 * h * 1.1, z as f64 * h * 0.9]);
            }
        }
    }
    // Kuhn subdivision: paths from corner 000 to 111 through the 6 permutations.
    let perms = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    let edges = curvetet::geom::shape::TET10_EDGES;
    let mut tets = Vec::with_capacity(6 * n * n * n);
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                for p in perms {
                    let mut c = [[2 * x, 2 * y, 2 * z]; 4];
                    for k in 0..3 {
                        c[k + 1] = c[k];
                        c[k + 1][p[k]] += 2;
                    }
                    let mut t = [0u32; 10];
                    for k in 0..4 {
                        t[k] = id(c[k][0], c[k][1], c[k][2]);
                    }
                    for (k, [a, b]) in edges.iter().enumerate() {
                        let q: [usize; 3] = std::array::from_fn(|d| (c[*a][d] + c[*b][d]) / 2);
                        t[4 + k] = id(q[0], q[1], q[2]);
                    }
                    tets.push(t);
                }
            }
        }
    }
    // Boundary: the z = 0 face only (enough to exercise the triangle paths).
    let mut boundary = Vec::new();
    for y in 0..n {
        for x in 0..n {
            let (a, b) = (2 * x, 2 * y);
            boundary.push([
                id(a, b, 0),
                id(a, b + 2, 0),
                id(a + 2, b + 2, 0),
                id(a, b + 1, 0),
                id(a + 1, b + 2, 0),
                id(a + 1, b + 1, 0),
            ]);
            boundary.push([
                id(a, b, 0),
                id(a + 2, b + 2, 0),
                id(a + 2, b, 0),
                id(a + 1, b + 1, 0),
                id(a + 2, b + 1, 0),
                id(a + 1, b, 0),
            ]);
        }
    }
    let boundary_tags = (0..boundary.len()).map(|i| 1 + (i % 2) as i32).collect();
    TetMesh {
        nodes,
        tets,
        boundary,
        boundary_tags,
        groups: Default::default(),
        tet_regions: Vec::new(),
    }
}

#[test]
#[ignore = "throughput measurement; run in release with --ignored --nocapture"]
fn million_tets_throughput() {
    let t = Instant::now();
    let mesh = grid_mesh(55);
    println!(
        "built {} nodes, {} tets, {} triangles in {:.2?}",
        mesh.nodes.len(),
        mesh.tets.len(),
        mesh.boundary.len(),
        t.elapsed()
    );
    let dir = std::env::temp_dir().join("curvetet_io_perf");
    std::fs::create_dir_all(&dir).unwrap();
    let variants = [
        ("msh41.msh", MshVersion::V41, false),
        ("msh41b.msh", MshVersion::V41, true),
        ("msh22.msh", MshVersion::V22, false),
        ("msh22b.msh", MshVersion::V22, true),
        ("a.vtu", MshVersion::V41, false),
        ("b.vtu", MshVersion::V41, true),
        ("a.vtk", MshVersion::V41, false),
        ("a.mesh", MshVersion::V41, false),
    ];
    let only = std::env::var("CURVETET_PERF_ONLY").ok();
    for (file, v, binary) in variants {
        if only.as_deref().is_some_and(|o| o != file) {
            continue;
        }
        let path = dir.join(file);
        let opts = WriteOptions::default()
            .with_msh_version(v)
            .with_binary(binary);
        let t = Instant::now();
        io::write_mesh(&path, &mesh, &opts).unwrap();
        let tw = t.elapsed();
        let size = std::fs::metadata(&path).unwrap().len();
        let t = Instant::now();
        let back = io::read(&path).unwrap();
        let tr = t.elapsed();
        assert_eq!(back.tet10.len(), mesh.tets.len());
        assert_eq!(back.tet10[12345], mesh.tets[12345]);
        println!(
            "{file:12} {:?}: write {tw:.2?}, read {tr:.2?}, {:.0} MB",
            Format::from_path(&path).unwrap(),
            size as f64 / 1e6
        );
        std::fs::remove_file(&path).unwrap();
    }
}
