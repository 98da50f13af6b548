//! Mesh a surface held in memory: arrays in, arrays out (no files).
//!
//! `cargo run --release --example from_arrays`
//!
//! The unit cube as 12 linear triangles, tagged by face; [`Surface::from_linear`] adds
//! one mid node per edge (its cube edges are sharp features, so it stays a cube), and the
//! P2 mesh comes back as arrays of nodes and 10-node tetrahedra. A surface that already
//! has 6-node triangles goes through [`Surface::new`] instead.

use curvetet::{generate, Options, Surface};

fn main() -> curvetet::Result<()> {
    // Vertex i is at (x, y, z) = (i & 1, (i >> 1) & 1, (i >> 2) & 1).
    let nodes: Vec<[f64; 3]> = (0..8)
        .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64])
        .collect();
    // Two triangles per face, counter-clockwise seen from outside.
    #[rustfmt::skip]
    let triangles: Vec<[u32; 3]> = vec![
        [0, 2, 3], [0, 3, 1], // z = 0
        [4, 5, 7], [4, 7, 6], // z = 1
        [0, 1, 5], [0, 5, 4], // y = 0
        [2, 6, 7], [2, 7, 3], // y = 1
        [0, 4, 6], [0, 6, 2], // x = 0
        [1, 3, 7], [1, 7, 5], // x = 1
    ];
    // One tag per triangle: the face's number, kept on the boundary of the output.
    let tags: Vec<i32> = (1..=6).flat_map(|f| [f, f]).collect();

    // Edges whose triangles meet at more than 40 degrees are features (kept sharp).
    let surface = Surface::from_linear(nodes, triangles, tags, 40.0)?;
    let out = generate(&surface, &Options::default())?;

    let mesh = &out.mesh; // the surface's nodes first, same indices, then interior ones
    println!(
        "{} nodes, {} tetrahedra (10 nodes each), {} boundary triangles",
        mesh.nodes.len(),
        mesh.tets.len(),
        mesh.boundary.len()
    );
    println!(
        "volume {:.12} (the cube's is 1), certified min scaled Jacobian {:.3}",
        out.report.volume_curved, out.report.quality.scaled_jacobian_certified.min
    );
    let first = mesh.tets[0];
    println!(
        "first tetrahedron: corners {:?}, mid nodes {:?}",
        &first[..4],
        &first[4..]
    );
    Ok(())
}
