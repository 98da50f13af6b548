//! The command-line tool as a user runs it: `check` accepts the data surfaces (with the
//! README's V_p2) and rejects every bad-input file with its specific defect and exit code;
//! `demo` writes a surface `check` accepts and a mesh `check` certifies; `mesh` writes a
//! mesh `check` certifies, draws the quality histograms (`--plot`) and skips optimization
//! with `--no-optimize`; bad options are clear errors.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

fn bin() -> &'static str {
    env!("CARGO_BIN_EXE_curvetet")
}

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn run(args: &[&str]) -> Output {
    Command::new(bin())
        .args(args)
        .output()
        .expect("curvetet runs")
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("curvetet-cli-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

#[test]
fn check_accepts_data_surfaces_with_readme_volumes() {
    for (name, v_p2) in [
        ("sphere", 4.188659268),
        ("torus", 2.417959847),
        ("tube", 4.71240098),
        ("lv", 3234.7592),
        ("screw", 3787.149008),
        ("hinge", 6336.122621),
    ] {
        let out = run(&[
            "check",
            data(&format!("{name}_p2.msh")).to_str().unwrap(),
            "--json",
        ]);
        assert!(
            out.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let v = j["enclosed_volume"].as_f64().unwrap();
        // The README gives V_p2 to ~10 significant digits.
        assert!(
            (v - v_p2).abs() <= 2e-9 * v_p2.abs().max(1.0),
            "{name}: {v} vs {v_p2}"
        );
        // Triangle shape: only the hinge has triangles of aspect ratio above 10 (two,
        // the worst 10.8).
        let shape = &j["triangle_shape"];
        let poor = shape["poorly_shaped"].as_u64().unwrap();
        let worst = shape["worst_aspect_ratio"].as_f64().unwrap();
        if name == "hinge" {
            assert!(
                poor == 2 && (10.7..10.9).contains(&worst),
                "{name}: {shape}"
            );
        } else {
            assert!(poor == 0 && (1.0..10.0).contains(&worst), "{name}: {shape}");
        }
    }
    // A raw marching-cubes surface: many poorly shaped triangles, and the warning.
    let out = run(&["check", data("mc_blob.off").to_str().unwrap(), "--json"]);
    assert!(out.status.success());
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(j["triangle_shape"]["poorly_shaped"], 101);
    assert!(String::from_utf8_lossy(&out.stderr).contains("aspect ratio above 10"));
}

#[test]
fn check_rejects_each_bad_file_with_its_defect() {
    let list = std::fs::read_to_string(data("bad/EXPECTED.txt")).unwrap();
    let mut n = 0;
    for line in list
        .lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with('#'))
    {
        let mut it = line.split_whitespace();
        let (file, kind) = (it.next().unwrap(), it.next().unwrap());
        let path = data(&format!("bad/{file}"));
        let t = Instant::now();
        let out = run(&["check", path.to_str().unwrap()]);
        assert!(t.elapsed() < Duration::from_secs(10), "{file}: too slow");
        let code = out
            .status
            .code()
            .expect("exit code, not a signal (no crash)");
        let err = String::from_utf8_lossy(&out.stderr);
        // Surface defects exit 4; defects visible in the file text itself are parse errors (3).
        assert!(code == 4 || code == 3, "{file}: exit {code}: {err}");
        if code == 4 {
            assert!(err.contains(kind), "{file}: expected {kind}, got: {err}");
        }
        n += 1;
    }
    assert!(n >= 30, "corpus has {n} files");
}

#[test]
fn demo_and_mesh_write_files_check_certifies() {
    let surf = tmp("demo_surface.msh");
    let out = run(&["demo", "--surface-only", "-o", surf.to_str().unwrap()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(run(&["check", surf.to_str().unwrap()]).status.success());

    let vol = tmp("demo_volume.msh");
    let out = run(&["demo", "-q", "-o", vol.to_str().unwrap()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = run(&["check", vol.to_str().unwrap(), "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(j["valid"], true);
    assert_eq!(j["report"]["num_invalid"], 0);

    let m = tmp("sphere.vtu");
    let report = tmp("sphere.json");
    let out = run(&[
        "mesh",
        data("sphere_p2.msh").to_str().unwrap(),
        "-o",
        m.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
        "-q",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(run(&["check", m.to_str().unwrap()]).status.success());
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert!(r["report"]["num_tets"].as_u64().unwrap() > 1000);
    // Near-equilateral triangles: auto sizes from edges.
    assert_eq!(r["size_from"], "edges");
}

/// `curvetet mesh INPUT -o NAME.msh --report NAME.json -q EXTRA...`, which must succeed;
/// the report.
fn mesh_report(input: &Path, name: &str, extra: &[&str]) -> serde_json::Value {
    let m = tmp(&format!("{name}.msh"));
    let report = tmp(&format!("{name}.json"));
    let mut args = vec![
        "mesh",
        input.to_str().unwrap(),
        "-o",
        m.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
        "-q",
    ];
    args.extend_from_slice(extra);
    let out = run(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap()
}

/// `--size-from areas` is taken and reported and changes the mesh; a uniform size has no
/// `size_from`, and the two do not combine.
#[test]
fn size_from_is_an_option_and_in_the_report() {
    let screw = data("screw_p2.msh");
    let mesh = |extra: &[&str], name: &str| {
        let mut args = vec!["--no-optimize"];
        args.extend_from_slice(extra);
        mesh_report(&screw, name, &args)
    };
    let edges = mesh(&[], "screw_edges");
    let areas = mesh(&["--size-from", "areas"], "screw_areas");
    assert_eq!(edges["size_from"], "edges");
    assert_eq!(areas["size_from"], "areas");
    // The screw's area sizes are within a few percent of its edge sizes: another mesh.
    assert_ne!(areas["report"]["num_tets"], serde_json::Value::Null);
    assert_ne!(areas["front"]["steps"], edges["front"]["steps"]);
    let uniform = mesh(&["--uniform-size"], "screw_uniform");
    assert!(uniform["size_from"].is_null());
    let out = run(&[
        "mesh",
        data("screw_p2.msh").to_str().unwrap(),
        "-o",
        tmp("x.msh").to_str().unwrap(),
        "--uniform-size",
        "--size-from",
        "areas",
    ]);
    assert_eq!(out.status.code(), Some(2), "clap refuses the combination");
}

/// A uniform `--size` far above the boundary's edges (the unit sphere's mean edge is about
/// 0.2) is clamped to twice the mean edge, with a warning, and the report gives the size
/// used; a size below that is used as given.
#[test]
fn a_size_the_boundary_cannot_support_is_clamped_and_said() {
    let s = data("sphere_p2.msh");
    let o = tmp("sphere_size1.msh");
    let report = tmp("sphere_size1.json");
    let out = run(&[
        "mesh",
        s.to_str().unwrap(),
        "-o",
        o.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
        "-q",
        "--size",
        "1",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("--size 1 is more than the boundary supports"),
        "{err}"
    );
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    let used = r["size"].as_f64().unwrap();
    assert!(used > 0.3 && used < 0.5, "{used}");
    let r = mesh_report(&s, "sphere_size03", &["--size", "0.3"]);
    assert_eq!(r["size"].as_f64(), Some(0.3));
}

#[test]
fn bad_options_and_missing_files_fail_clearly() {
    let s = data("sphere_p2.msh");
    let o = tmp("x.msh");
    let out = run(&[
        "mesh",
        s.to_str().unwrap(),
        "-o",
        o.to_str().unwrap(),
        "--alpha",
        "0",
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("alpha"));
    let out = run(&[
        "mesh",
        s.to_str().unwrap(),
        "-o",
        o.to_str().unwrap(),
        "--size",
        "NaN",
    ]);
    assert_eq!(out.status.code(), Some(1));
    let out = run(&[
        "check",
        Path::new("/nonexistent/surface.msh").to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("/nonexistent/surface.msh"));
}

#[test]
fn mesh_plots_the_two_histograms_and_optimization_can_be_turned_off() {
    let s = data("sphere_p2.msh");
    let mesh_with = |name: &str, extra: &[&str]| mesh_report(&s, name, extra);
    let svg = tmp("quality.svg");
    let opt = mesh_with("opt", &["--plot", svg.to_str().unwrap()]);
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.starts_with("<svg") && text.trim_end().ends_with("</svg>"));
    assert!(text.contains("Scaled Jacobian min J / max J"));
    assert!(text.contains("Equiangular skewness"));
    // Bars in both panels: at least one filled rectangle per histogram bin drawn.
    assert!(text.matches("<rect").count() > 10, "{text}");

    let raw = mesh_with("raw", &["--no-optimize"]);
    assert!(opt["times"]["optimize"].as_f64().unwrap() > 0.0);
    assert!(opt["optimize"]["linear"]["passes"].as_u64().unwrap() > 0);
    assert_eq!(raw["times"]["optimize"].as_f64(), Some(0.0));
    assert_eq!(raw["optimize"]["linear"]["passes"].as_u64(), Some(0));
    let sj = |v: &serde_json::Value| {
        v["report"]["quality"]["scaled_jacobian_certified"]["min"]
            .as_f64()
            .unwrap()
    };
    let skew = |v: &serde_json::Value| v["report"]["quality"]["skewness"]["max"].as_f64().unwrap();
    assert!(sj(&opt) > sj(&raw), "{} vs {}", sj(&opt), sj(&raw));
    assert!(skew(&opt) < skew(&raw), "{} vs {}", skew(&opt), skew(&raw));
    assert!(sj(&opt) >= 0.8 && skew(&opt) <= 0.85);
}
