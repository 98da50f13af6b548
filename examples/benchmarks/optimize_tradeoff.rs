//! Experiment (not a test): how the optimizer's time against the front's trades with the
//! quality it reaches, on one surface (the screw by default), over a grid of the linear
//! and high-order stages' public parameters (around both the default and the thorough
//! high-order tuning). Every row is a full run of both stages on the same front mesh;
//! times are medians of `--runs` runs (default 5).
//!
//! `cargo run --release --example optimize_tradeoff [SURFACE] [--runs N]`
//!
//! It prints each setting's optimize/front time ratio, certified min J / max J and max
//! skewness, then the settings that meet all three of: ratio ≤ 1, certified min at
//! least `--floor` (default 0.62, the test suite's screw floor) and max skewness at most
//! `--max-skew` (default 0.68, the test suite's screw ceiling); and the Pareto front of
//! ratio against certified min: the evidence behind the high-order stage's default
//! tuning and the figures in docs/benchmarks.md.

use curvetet::front::run_front;
use curvetet::generate::size_field;
use curvetet::mesh::build::assemble;
use curvetet::mesh::report::{uncertified, QualityReport};
use curvetet::optimize::{
    improve_linear_known, optimize_high_order, Boundary, HighOrderParams, LinearParams, RoundTuning,
};
use curvetet::{io, Options};
use std::path::PathBuf;
use std::time::Instant;

/// One setting of both stages.
#[derive(Clone)]
struct Setting {
    name: String,
    linear: Option<LinearParams>,
    high: HighOrderParams,
}

/// The measured outcome of a setting.
struct Row {
    name: String,
    linear_s: f64,
    high_s: f64,
    ratio: f64,
    min_sj: f64,
    max_skew: f64,
    valid: bool,
}

fn settings() -> Vec<Setting> {
    let mut out = Vec::new();
    let lin = |passes: usize, attempts: f64| LinearParams {
        max_passes: passes,
        max_attempts_per_tet: attempts,
        ..LinearParams::default()
    };
    let linears: Vec<(String, Option<LinearParams>)> = vec![
        ("lin default".into(), Some(LinearParams::default())),
        ("lin passes 4".into(), Some(lin(4, 2.0))),
        ("lin passes 2".into(), Some(lin(2, 2.0))),
        ("lin attempts 0.1".into(), Some(lin(8, 0.1))),
        ("no linear".into(), None),
    ];
    let bases = [
        ("high-order default", HighOrderParams::default()),
        ("high-order thorough", HighOrderParams::thorough()),
    ];
    for (ln, l) in &linears {
        for (bn, base) in &bases {
            for rounds in [5, 4, 3, 2, 1] {
                for reach in [0.1, 0.15, 0.2] {
                    for iterations in [6, 8] {
                        // The staged rounds' tuning (the screw's worst element starts
                        // poor: its rounds are staged).
                        let high = HighOrderParams {
                            reach,
                            staged: RoundTuning {
                                rounds,
                                iterations,
                                ..base.staged.clone()
                            },
                            ..base.clone()
                        };
                        out.push(Setting {
                            name: format!(
                                "{ln}; {bn} with rounds {rounds} reach {reach} iterations {iterations}"
                            ),
                            linear: l.clone(),
                            high,
                        });
                    }
                }
            }
        }
    }
    out
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/screw_p2.msh");
    let (mut runs, mut floor, mut max_skew) = (5usize, 0.62f64, 0.68f64);
    let mut i = 0;
    while i < args.len() {
        let value = |i: usize| args.get(i + 1).and_then(|v| v.parse::<f64>().ok());
        match args[i].as_str() {
            "--runs" => runs = value(i).map_or(runs, |v| v.max(1.0) as usize),
            "--floor" => floor = value(i).unwrap_or(floor),
            "--max-skew" => max_skew = value(i).unwrap_or(max_skew),
            p => {
                path = PathBuf::from(p);
                i += 1;
                continue;
            }
        }
        i += 2;
    }
    let surface = match io::read_any_surface(&path, &Default::default()) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("cannot read {}: {e}", path.display());
            std::process::exit(2);
        }
    };
    let opts = Options::default();
    // As `curvetet mesh` runs it: the high-order stage inside the pool (all cores, each
    // worker on its own CPU).
    let pool = match curvetet::threads::pool(opts.threads, true) {
        Ok(p) => p,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(1);
        }
    };
    let size = size_field(&surface, &opts);
    let bnd = Boundary::new(surface.nodes().len(), surface.triangles());
    let front = |progress: &mut dyn FnMut(f64, &str) -> bool| {
        run_front(
            surface.nodes(),
            surface.triangles(),
            &opts,
            &size,
            0,
            progress,
        )
    };
    let mut front_times = Vec::new();
    let mut out = None;
    for _ in 0..runs {
        let t = Instant::now();
        match front(&mut |_, _| false) {
            Ok(f) => out = Some(f),
            Err(e) => {
                eprintln!("the front failed: {e}");
                std::process::exit(5);
            }
        }
        front_times.push(t.elapsed().as_secs_f64());
    }
    let f = out.expect("runs >= 1");
    let front_s = median(&mut front_times);
    println!(
        "{}: {} tets from the front in {:.2} ms (median of {runs})",
        path.display(),
        f.tets.len(),
        front_s * 1e3
    );
    let mut rows = Vec::new();
    for s in settings() {
        let (mut lt, mut ht) = (Vec::new(), Vec::new());
        let mut last = None;
        for _ in 0..runs {
            let t = Instant::now();
            let (pts, tets) = match &s.linear {
                Some(p) => {
                    let (pts, tets, _) = improve_linear_known(
                        f.pts.clone(),
                        f.tets.clone(),
                        Some(&f.quality),
                        &bnd,
                        p,
                    );
                    (pts, tets)
                }
                None => (f.pts.clone(), f.tets.clone()),
            };
            lt.push(t.elapsed().as_secs_f64());
            let mut mesh = assemble(
                &pts,
                &tets,
                surface.nodes().len(),
                surface.triangles(),
                surface.tags(),
            );
            let t = Instant::now();
            let st = pool.install(|| optimize_high_order(&mut mesh, &bnd, &s.high));
            ht.push(t.elapsed().as_secs_f64());
            last = Some((mesh, st));
        }
        let (mesh, st) = last.expect("runs >= 1");
        let report = QualityReport::with_invalid(&mesh, 0);
        let (linear_s, high_s) = (median(&mut lt), median(&mut ht));
        rows.push(Row {
            name: s.name,
            linear_s,
            high_s,
            ratio: (linear_s + high_s) / front_s,
            min_sj: st.min_scaled_jacobian[1],
            max_skew: report.quality.skewness.max,
            valid: uncertified(&mesh).is_empty(),
        });
    }
    println!("| setting | linear ms | high-order ms | optimize/front | certified min J/max J | max skewness | all certified |");
    println!("|---|---|---|---|---|---|---|");
    for r in &rows {
        println!(
            "| {} | {:.2} | {:.2} | {:.2} | {:.3} | {:.3} | {} |",
            r.name,
            r.linear_s * 1e3,
            r.high_s * 1e3,
            r.ratio,
            r.min_sj,
            r.max_skew,
            if r.valid { "yes" } else { "NO" }
        );
    }
    let meets = |r: &Row| r.valid && r.ratio <= 1.0 && r.min_sj >= floor && r.max_skew <= max_skew;
    let ok: Vec<&Row> = rows.iter().filter(|r| meets(r)).collect();
    println!(
        "\nsettings with ratio <= 1, certified min >= {floor} and max skewness <= {max_skew}: {}",
        ok.len()
    );
    for r in ok {
        println!(
            "  {} (ratio {:.2}, min {:.3}, skewness {:.3})",
            r.name, r.ratio, r.min_sj, r.max_skew
        );
    }
    // Pareto front: no other valid setting is both faster and better.
    let mut front_rows: Vec<&Row> = rows
        .iter()
        .filter(|r| {
            r.valid
                && !rows.iter().any(|o| {
                    o.valid
                        && o.ratio <= r.ratio
                        && o.min_sj >= r.min_sj
                        && (o.ratio < r.ratio || o.min_sj > r.min_sj)
                })
        })
        .collect();
    front_rows.sort_by(|a, b| a.ratio.total_cmp(&b.ratio));
    println!("\nPareto front (optimize/front ratio against certified min J/max J):");
    for r in front_rows {
        println!(
            "  ratio {:.2}: min {:.3}, skewness {:.3} ({})",
            r.ratio, r.min_sj, r.max_skew, r.name
        );
    }
}
