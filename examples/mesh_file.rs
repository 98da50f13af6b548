//! Mesh a surface file and write the tetrahedral mesh: the library's main path.
//!
//! `cargo run --release --example mesh_file [INPUT] [OUTPUT]`
//!
//! INPUT is a closed surface: 6-node triangles (.msh, .vtu, .vtk, .mesh) are used as they
//! are, 3-node triangles (also .stl, .off, .obj, .ply) are curved first. Default:
//! tests/data/sphere_p2.msh. OUTPUT's extension picks the format (.msh, .vtu, .vtk,
//! .mesh); default: sphere_tets.msh in the temporary directory. The file is written whole
//! or not at all.

use curvetet::{generate, read_any_surface, write_mesh, CurveOptions, Options, WriteOptions};
use std::path::PathBuf;
use std::process::ExitCode;

fn main() -> ExitCode {
    let mut args = std::env::args_os().skip(1);
    let input = args.next().map(PathBuf::from).unwrap_or_else(|| {
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/sphere_p2.msh")
    });
    let output = args
        .next()
        .map(PathBuf::from)
        .unwrap_or_else(|| std::env::temp_dir().join("sphere_tets.msh"));
    match run(&input, &output) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // Every error names the file and line, element or option concerned.
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(input: &std::path::Path, output: &std::path::Path) -> curvetet::Result<()> {
    // Read and check the surface (a linear one is curved with the default options).
    let surface = read_any_surface(input, &CurveOptions::default())?;
    for w in surface.warnings() {
        eprintln!("warning: {w}");
    }
    // Front, optimization and certification, with the paper's settings.
    let out = generate(&surface, &Options::default())?;
    let r = &out.report;
    println!(
        "{}: {} tets, {} nodes; certified min scaled Jacobian {:.3}, max skewness {:.3}",
        input.display(),
        r.num_tets,
        r.num_nodes,
        r.quality.scaled_jacobian_certified.min,
        r.quality.skewness.max,
    );
    println!(
        "volume {:.6} (surface encloses {:.6})",
        r.volume_curved,
        surface.volume()
    );
    write_mesh(output, &out.mesh, &WriteOptions::default())?;
    println!("wrote {}", output.display());
    Ok(())
}
