//! Benchmark (not a test): curvetet's quality on the paper's surfaces beside the paper's
//! and Gmsh's (docs/benchmarks.md, "Quality against the paper and Gmsh").
//!
//! `cargo run --release --example quality_table [DATA_DIR] [SURFACE...]`
//!
//! For every benchmark surface (tests/data by default) it
//! meshes with the default options and prints the certified min of min J / max J next to
//! the paper's and Gmsh's, the max equiangular skewness, the counts above 0.85 and 0.9,
//! the dihedral angle range and the time of each stage; the raw front mesh (optimization
//! off) is measured too, for the before/after columns.

use curvetet::{generate, io, Options};
use std::path::PathBuf;

/// (surface, paper, Gmsh P2, Gmsh optimized with the boundary fixed, target): the paper's
/// values, Gmsh's on the same geometry, and the project's targets; `None` where the paper
/// has no value.
const ROWS: [(&str, Option<f64>, f64, f64, f64); 6] = [
    ("sphere", None, 0.762, 0.762, 0.80),
    ("torus", Some(0.681), 0.544, 0.544, 0.75),
    ("tube", Some(0.618), 0.671, 0.671, 0.75),
    ("lv", Some(0.156), 0.433, 0.641, 0.70),
    ("screw", Some(0.278), 0.008, 0.011, 0.45),
    ("hinge", Some(0.173), -0.236, 0.137, 0.35),
];

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (dir, names): (PathBuf, Vec<String>) = match args.first() {
        Some(d) if std::path::Path::new(d).is_dir() => (d.into(), args[1..].to_vec()),
        _ => (
            PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data"),
            args.clone(),
        ),
    };
    println!(
        "| surface | paper | Gmsh P2 | Gmsh opt. | target | curvetet raw → optimized (certified) | max skew raw → opt. | > 0.85 | > 0.9 | dihedral (°) | tets | front s | linear s | high-order s | total s |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for (name, paper, gmsh, gmsh_opt, target) in ROWS {
        if !names.is_empty() && !names.iter().any(|n| n == name) {
            continue;
        }
        let path = dir.join(format!("{name}_p2.msh"));
        let paper = paper.map_or("–".to_string(), |v| format!("{v:.3}"));
        let head = format!("| {name} | {paper} | {gmsh:.3} | {gmsh_opt:.3} | ≥ {target:.2} |");
        let surface = match io::read_surface(&path) {
            Ok(s) => s,
            Err(e) => {
                println!("{head} cannot read {}: {e} |", path.display());
                continue;
            }
        };
        // Timed as `curvetet mesh` runs: each worker on its own CPU.
        let opts = Options::default().with_pin_threads(true);
        let raw = generate(&surface, &opts.clone().with_optimize(false));
        let g = match generate(&surface, &opts) {
            Ok(g) => g,
            Err(e) => {
                let msg = e.to_string();
                println!("{head} failed: {} |", &msg[..msg.len().min(100)]);
                continue;
            }
        };
        let (raw_sj, raw_skew) = match &raw {
            Ok(r) => (
                format!("{:.3}", r.report.quality.scaled_jacobian_certified.min),
                format!("{:.3}", r.report.quality.skewness.max),
            ),
            Err(_) => ("–".into(), "–".into()),
        };
        let q = &g.report.quality;
        let t = &g.times;
        let total = t.size_field + t.front + t.assemble + t.optimize + t.certify + t.report;
        let met = if q.scaled_jacobian_certified.min >= target && q.skewness.max <= 0.85 {
            "✓"
        } else {
            "✗"
        };
        println!(
            "{head} {raw_sj} → **{:.3}** {met} | {raw_skew} → {:.3} | {} | {} | {:.1}..{:.1} | {} | {:.3} | {:.3} | {:.3} | {:.3} |",
            q.scaled_jacobian_certified.min,
            q.skewness.max,
            g.report.skew_above_085,
            g.report.skew_above_09,
            q.min_dihedral.min,
            q.max_dihedral.max,
            g.report.num_tets,
            t.front,
            g.optimize.time_linear,
            g.optimize.time_high_order,
            total
        );
    }
}
