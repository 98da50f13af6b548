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
        let out = run(&["check", path.to_str().unwrap(), "--strict"]);
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
        // Without --strict, unused nodes and orientation are repaired with a warning;
        // everything else is refused the same way.
        let lenient = run(&["check", path.to_str().unwrap()]);
        let lerr = String::from_utf8_lossy(&lenient.stderr);
        if code == 4 && (kind == "unused-node" || kind == "inconsistent-orientation") {
            assert!(lenient.status.success(), "{file}: {lerr}");
            assert!(lerr.contains("warning: "), "{file}: {lerr}");
        } else {
            assert_eq!(lenient.status.code(), Some(code), "{file}: {lerr}");
            if code == 4 {
                assert!(lerr.contains(kind), "{file}: expected {kind}, got: {lerr}");
            }
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
    assert_eq!(
        out.status.code(),
        Some(1),
        "clap refuses the combination (usage error)"
    );
}

/// `--gradation` is taken and reported: a faster growth inward gives the screw fewer tets;
/// 0 is refused with the option's name, and a uniform size does not combine with it.
#[test]
fn gradation_is_an_option_and_in_the_report() {
    let screw = data("screw_p2.msh");
    let slow = mesh_report(&screw, "screw_g02", &["--no-optimize"]);
    let fast = mesh_report(
        &screw,
        "screw_g08",
        &["--no-optimize", "--gradation", "0.8"],
    );
    assert_eq!(slow["options"]["gradation"], 0.2);
    assert_eq!(fast["options"]["gradation"], 0.8);
    let tets = |r: &serde_json::Value| r["report"]["num_tets"].as_u64().unwrap();
    assert!(
        tets(&fast) < tets(&slow),
        "{} vs {}",
        tets(&fast),
        tets(&slow)
    );
    let out_path = tmp("g.msh");
    let run_with = |extra: &[&str]| {
        let mut args = vec![
            "mesh",
            screw.to_str().unwrap(),
            "-o",
            out_path.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        run(&args)
    };
    let zero = run_with(&["--gradation", "0"]);
    assert_eq!(zero.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&zero.stderr).contains("gradation must be"));
    let both = run_with(&["--gradation", "0.5", "--size", "1"]);
    assert_eq!(both.status.code(), Some(1), "clap refuses the combination");
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

/// A fresh empty directory for one test.
fn scratch(name: &str) -> PathBuf {
    let d = tmp(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn names_in(d: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn an_output_that_is_the_input_or_another_output_is_refused() {
    let d = scratch("same");
    let input = d.join("in.msh");
    std::fs::copy(data("sphere_p2.msh"), &input).unwrap();
    let original = std::fs::read(&input).unwrap();
    let link = d.join("link.msh");
    std::os::unix::fs::symlink(&input, &link).unwrap();
    let out = d.join("out.msh");
    let svg = d.join("q.svg");
    let dotted = format!("{}/../same/in.msh", s(&d));
    let cases: Vec<Vec<&str>> = vec![
        vec!["mesh", s(&input), "-o", s(&input)],
        vec!["mesh", s(&input), "-o", s(&link)],
        vec!["mesh", s(&input), "-o", &dotted],
        vec!["mesh", s(&link), "-o", s(&input)],
        vec!["convert", s(&input), s(&input)],
        vec!["curve", s(&input), "-o", s(&link)],
        vec!["mesh", s(&input), "-o", s(&out), "--report", s(&input)],
        vec!["mesh", s(&input), "-o", s(&out), "--report", s(&out)],
        vec![
            "mesh",
            s(&input),
            "-o",
            s(&out),
            "--plot",
            s(&svg),
            "--report",
            s(&svg),
        ],
        vec!["check", s(&input), "--plot", s(&link)],
    ];
    for args in cases {
        let t = Instant::now();
        let o = run(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(
            err.contains("same file") || err.contains("is the input"),
            "{args:?}: {err}"
        );
        assert!(
            t.elapsed() < Duration::from_secs(1),
            "{args:?}: {:?}",
            t.elapsed()
        );
        assert_eq!(std::fs::read(&input).unwrap(), original, "{args:?}");
        assert_eq!(names_in(&d), ["in.msh", "link.msh"], "{args:?}");
    }
}

#[test]
fn bad_requests_fail_before_the_input_is_read() {
    // The input does not exist: had it been read first, every case would be an I/O
    // error naming it.
    let d = scratch("early");
    let input = d.join("missing.msh");
    let out = d.join("out.msh");
    let in_missing_dir = d.join("no/such/dir/out.msh");
    let (vtk, medit) = (format!("{}/x.vtk", s(&d)), format!("{}/x.mesh", s(&d)));
    let cases: Vec<(Vec<&str>, i32, &str)> = vec![
        (
            vec!["mesh", s(&input), "-o", s(&in_missing_dir)],
            2,
            "no/such/dir",
        ),
        (
            vec!["mesh", s(&input), "-o", "/proc/out.msh"],
            2,
            "cannot write in /proc",
        ),
        (vec!["convert", s(&input), "/proc/out.msh"], 2, "/proc"),
        (
            vec![
                "mesh",
                s(&input),
                "-o",
                s(&out),
                "--report",
                s(&in_missing_dir),
            ],
            2,
            "no/such",
        ),
        (vec!["mesh", s(&input), "-o", s(&d)], 1, "extension"),
        (vec!["mesh", s(&input), "-o", &vtk, "--binary"], 1, "binary"),
        (vec!["convert", s(&input), &medit, "--binary"], 1, "binary"),
        (
            vec!["mesh", s(&input), "-o", s(&out), "--size", "0"],
            1,
            "size",
        ),
        (
            vec!["mesh", s(&input), "-o", s(&out), "--size=-1"],
            1,
            "size",
        ),
        (
            vec!["mesh", s(&input), "-o", s(&out), "--size", "inf"],
            1,
            "size",
        ),
        (
            vec!["mesh", s(&input), "-o", s(&out), "--threads", "100000"],
            1,
            "at most",
        ),
        (
            vec!["mesh", s(&input), "-o", s(&out), "--threads", "99999"],
            1,
            "at most",
        ),
        (
            vec!["mesh", s(&input), "-o", s(&out), "--smooth", "4294967295"],
            1,
            "at most 1000",
        ),
        (
            vec!["curve", s(&input), "-o", s(&out), "--smooth", "1001"],
            1,
            "at most 1000",
        ),
        (
            vec!["demo", "-o", s(&out), "--threads", "100000"],
            1,
            "at most",
        ),
    ];
    for (args, code, what) in cases {
        let t = Instant::now();
        let o = run(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(code), "{args:?}: {err}");
        assert!(err.contains(what), "{args:?}: expected {what:?} in: {err}");
        assert!(!err.contains("missing.msh"), "{args:?}: {err}");
        assert!(
            t.elapsed() < Duration::from_secs(1),
            "{args:?}: {:?}",
            t.elapsed()
        );
    }
    assert!(names_in(&d).is_empty(), "{:?}", names_in(&d));
}

#[test]
fn devices_and_fifos_are_refused_at_once() {
    let d = scratch("devices");
    let zero = d.join("zero.msh");
    std::os::unix::fs::symlink("/dev/zero", &zero).unwrap();
    let fifo = d.join("fifo.stl");
    let c = std::ffi::CString::new(s(&fifo)).unwrap();
    // SAFETY: a NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    for p in [&zero, &fifo, &d.join("dir.msh")] {
        if p.ends_with("dir.msh") {
            std::fs::create_dir(p).unwrap();
        }
        let t = Instant::now();
        let o = run(&["check", s(p)]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{p:?}: {err}");
        assert!(
            err.contains("not a regular file") || err.contains("a directory"),
            "{err}"
        );
        assert!(
            t.elapsed() < Duration::from_secs(1),
            "{p:?}: {:?}",
            t.elapsed()
        );
    }
}

#[test]
fn a_closed_stdout_is_not_a_panic() {
    // A pipe whose reading end is closed before curvetet starts: every write to it fails
    // with EPIPE, as in `curvetet check X | head -1` once head has exited.
    let mut fds = [0; 2];
    // SAFETY: fds has room for the two descriptors.
    assert_eq!(unsafe { libc::pipe(fds.as_mut_ptr()) }, 0);
    // SAFETY: both descriptors are fresh and owned here.
    let (read_end, write_end) = unsafe {
        use std::os::fd::FromRawFd;
        (
            std::os::fd::OwnedFd::from_raw_fd(fds[0]),
            std::os::fd::OwnedFd::from_raw_fd(fds[1]),
        )
    };
    drop(read_end);
    for args in [vec!["check"], vec!["check", "--json"]] {
        let o = Command::new(bin())
            .args(&args)
            .arg(data("sphere_p2.msh"))
            .stdout(std::process::Stdio::from(write_end.try_clone().unwrap()))
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(0), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
}

#[test]
fn usage_errors_and_io_errors_have_distinct_documented_exit_codes() {
    let o = run(&["mesh", "--no-such-option"]);
    assert_eq!(o.status.code(), Some(1), "usage error");
    let o = run(&["frobnicate"]);
    assert_eq!(o.status.code(), Some(1), "unknown command");
    let o = run(&["check", "/nonexistent/surface.msh"]);
    assert_eq!(o.status.code(), Some(2), "I/O error");
    let o = run(&["--help"]);
    assert_eq!(o.status.code(), Some(0));
    let help = String::from_utf8_lossy(&o.stdout);
    for line in [
        "Exit codes:",
        "1  usage error",
        "2  I/O error",
        "3  malformed",
        "4  invalid surface",
        "5  meshing failed",
    ] {
        assert!(help.contains(line), "--help lacks {line:?}: {help}");
    }
}

/// `convert` under a file size limit of `limit` bytes, with SIGXFSZ either fatal (the
/// process is killed in the middle of a write) or ignored (the write fails with EFBIG,
/// as on a full disk).
fn convert_limited(input: &Path, output: &Path, limit: u64, kill: bool) -> Output {
    use std::os::unix::process::CommandExt;
    let mut c = Command::new(bin());
    c.arg("convert").arg(input).arg(output);
    // SAFETY: only async-signal-safe calls between fork and exec.
    unsafe {
        c.pre_exec(move || {
            let r = libc::rlimit {
                rlim_cur: limit,
                rlim_max: limit,
            };
            if libc::setrlimit(libc::RLIMIT_FSIZE, &r) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            let action = if kill { libc::SIG_DFL } else { libc::SIG_IGN };
            libc::signal(libc::SIGXFSZ, action);
            Ok(())
        });
    }
    c.output().unwrap()
}

#[test]
fn a_killed_or_failed_write_leaves_the_old_file_whole() {
    use std::os::unix::process::ExitStatusExt;
    let d = scratch("killed");
    let out = d.join("out.vtu");
    let old = b"the previous contents".to_vec();
    let input = data("lv_p2.msh");
    // The whole output, written without a limit elsewhere.
    let whole_path = tmp("killed-whole.vtu");
    assert!(run(&["convert", s(&input), s(&whole_path)])
        .status
        .success());
    let whole = std::fs::read(&whole_path).unwrap();
    assert!(whole.len() > 200_000);
    for limit in [4096, 65536, whole.len() as u64 / 2] {
        // Killed by SIGXFSZ in the middle of writing: the old file stays.
        std::fs::write(&out, &old).unwrap();
        let o = convert_limited(&input, &out, limit, true);
        assert_eq!(o.status.signal(), Some(libc::SIGXFSZ), "limit {limit}");
        assert_eq!(std::fs::read(&out).unwrap(), old, "limit {limit}: killed");
        // The write fails (as on a full disk): an I/O error, the old file stays, and the
        // temporary file is gone.
        for f in names_in(&d) {
            if f != "out.vtu" {
                std::fs::remove_file(d.join(f)).unwrap();
            }
        }
        let o = convert_limited(&input, &out, limit, false);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "limit {limit}: {err}");
        assert!(err.contains("out.vtu"), "{err}");
        assert_eq!(std::fs::read(&out).unwrap(), old, "limit {limit}: failed");
        assert_eq!(names_in(&d), ["out.vtu"], "limit {limit}");
    }
    // No old file: a failed write leaves none.
    std::fs::remove_file(&out).unwrap();
    let o = convert_limited(&input, &out, 65536, false);
    assert_eq!(o.status.code(), Some(2));
    assert!(names_in(&d).is_empty(), "{:?}", names_in(&d));
    // Within the limit: the whole file.
    let o = convert_limited(&input, &out, 2 * whole.len() as u64, false);
    assert!(o.status.success());
    assert_eq!(std::fs::read(&out).unwrap(), whole);
}

#[test]
fn concurrent_writers_of_one_path_leave_one_complete_file() {
    let d = scratch("concurrent");
    let out = d.join("out.vtu");
    let input = data("tube_p2.msh");
    let whole_path = tmp("concurrent-whole.vtu");
    assert!(run(&["convert", s(&input), s(&whole_path)])
        .status
        .success());
    let whole = std::fs::read(&whole_path).unwrap();
    for round in 0..3 {
        let children: Vec<_> = (0..4)
            .map(|_| {
                Command::new(bin())
                    .args(["convert", s(&input), s(&out)])
                    .stderr(std::process::Stdio::null())
                    .spawn()
                    .unwrap()
            })
            .collect();
        for mut c in children {
            assert!(c.wait().unwrap().success(), "round {round}");
        }
        assert!(
            std::fs::read(&out).unwrap() == whole,
            "round {round}: not the whole file"
        );
        assert_eq!(names_in(&d), ["out.vtu"], "round {round}");
    }
}

#[test]
fn a_convert_interrupted_while_writing_leaves_the_old_file_and_no_temporary() {
    use std::os::unix::process::ExitStatusExt;
    let d = scratch("sigterm");
    // A volume mesh of a few megabytes: its conversion writes for tens of milliseconds.
    let input = tmp("sigterm-big.msh");
    let o = run(&[
        "demo",
        "-q",
        "--triangles",
        "6000",
        "--no-optimize",
        "-o",
        s(&input),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let whole_path = tmp("sigterm-whole.vtu");
    assert!(run(&["convert", s(&input), s(&whole_path)])
        .status
        .success());
    let whole = std::fs::read(&whole_path).unwrap();
    let out = d.join("out.vtu");
    let old = b"the previous contents".to_vec();
    let mut caught = 0;
    for _ in 0..20 {
        std::fs::write(&out, &old).unwrap();
        let mut child = Command::new(bin())
            .args(["convert", s(&input), s(&out)])
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        // Wait for the temporary file to appear, then interrupt the write.
        let t = Instant::now();
        let writing = loop {
            if names_in(&d).iter().any(|n| n.starts_with(".out.vtu.")) {
                break true;
            }
            if child.try_wait().unwrap().is_some() || t.elapsed() > Duration::from_secs(10) {
                break false;
            }
        };
        if !writing {
            let _ = child.kill();
            child.wait().unwrap();
            continue;
        }
        // SAFETY: a signal to our own child.
        unsafe { libc::kill(child.id() as i32, libc::SIGTERM) };
        let status = child.wait().unwrap();
        if status.signal() != Some(libc::SIGTERM) {
            continue; // finished before the signal arrived
        }
        // Ended by the signal: the target is the old file, or the whole new one when the
        // signal came just after the rename; never anything else, and no temporary.
        let now = std::fs::read(&out).unwrap();
        assert!(now == old || now == whole, "the target is partial");
        assert_eq!(names_in(&d), ["out.vtu"], "a temporary file was left");
        caught += usize::from(now == old);
        if caught == 3 {
            break;
        }
    }
    assert!(caught > 0, "never caught a convert while it was writing");
}

/// Checks each file of a JSON list with meshio: it reads without warning, holds P2 tets
/// and triangles, the triangles' and tets' tags (cell array `key`) are the given sets, and
/// for .msh and .vtu files the physical names are the given (name, tag, dim) triples.
const MESHIO_GROUPS: &str = r#"
import json, sys, warnings
import numpy as np
import meshio
spec = json.loads(sys.argv[1])
for f in spec:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        m = meshio.read(f["path"])
    kinds = sorted({b.type for b in m.cells})
    assert kinds == ["tetra10", "triangle6"], (f["path"], kinds)
    tri, tet = set(), set()
    for b, d in zip(m.cells, m.cell_data[f["key"]]):
        vals = {int(x) for x in np.asarray(d).reshape(-1)}
        (tri if b.type == "triangle6" else tet).update(vals)
    assert sorted(tri) == f["tri"], (f["path"], sorted(tri), f["tri"])
    assert sorted(tet) == f["tet"], (f["path"], sorted(tet), f["tet"])
    if "names" in f:
        got = sorted([k] + [int(x) for x in np.asarray(v).reshape(-1)] for k, v in m.field_data.items())
        assert got == sorted(f["names"]), (f["path"], got, f["names"])
print("meshio ok", len(spec))
"#;

/// The linear surface of [`curvetet::surface::demo::split_box`] (two unit boxes sharing
/// the wall x = 1, given once) as an OFF file.
fn split_box_off(path: &Path, n: usize) {
    use std::collections::HashMap;
    use std::fmt::Write;
    let (nodes, tris) = curvetet::surface::demo::split_box(n);
    let mut ids = HashMap::new();
    let mut corners = Vec::new();
    let faces: Vec<[u32; 3]> = tris
        .iter()
        .map(|t| {
            [0, 1, 2].map(|k| {
                *ids.entry(t[k]).or_insert_with(|| {
                    corners.push(nodes[t[k] as usize]);
                    corners.len() as u32 - 1
                })
            })
        })
        .collect();
    let mut text = format!("OFF\n{} {} 0\n", corners.len(), faces.len());
    for p in &corners {
        writeln!(text, "{} {} {}", p[0], p[1], p[2]).unwrap();
    }
    for f in &faces {
        writeln!(text, "3 {} {} {}", f[0], f[1], f[2]).unwrap();
    }
    std::fs::write(path, text).unwrap();
}

/// Issue 30: a surface of two regions meshes through `curvetet mesh` into one conforming
/// mesh that `check` accepts and reports by region: a box split by a wall (found by its
/// junction edges) and a sphere inside a sphere (P2, `--nested-regions`); `check` on the
/// inputs reports their regions.
#[test]
fn mesh_and_check_two_region_surfaces() {
    let boxes = tmp("regions_box.off");
    split_box_off(&boxes, 2);
    let spheres = tmp("regions_spheres.msh");
    let (nodes, tris) = curvetet::surface::demo::nested_spheres(1, 0.5, 1.0);
    let ntris = tris.len();
    curvetet::io::write_surface(
        &spheres,
        &nodes,
        &tris,
        &vec![0; ntris],
        &Default::default(),
    )
    .unwrap();
    for (input, flags, interfaces) in [
        (&boxes, &[][..], 8),
        (&spheres, &["--nested-regions"][..], ntris / 2),
    ] {
        let mut args = vec!["check", input.to_str().unwrap()];
        args.extend_from_slice(flags);
        let out = run(&args);
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(out.status.success(), "{text}");
        assert!(text.contains("valid surface of 2 regions"), "{text}");
        let msh = tmp(&format!(
            "{}_out.msh",
            input.file_stem().unwrap().to_str().unwrap()
        ));
        let mut args = vec![
            "mesh",
            input.to_str().unwrap(),
            "-o",
            msh.to_str().unwrap(),
            "--threads",
            "1",
        ];
        args.extend_from_slice(flags);
        let out = run(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{err}");
        assert!(err.contains("2 regions: meshing each"), "{err}");
        let out = run(&["check", msh.to_str().unwrap(), "--json"]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(j["valid"], true);
        assert_eq!(j["conformity"]["interface_faces"], interfaces);
        let regions = j["regions"].as_array().unwrap();
        let got: Vec<(i64, &str)> = regions
            .iter()
            .map(|r| (r["tag"].as_i64().unwrap(), r["name"].as_str().unwrap()))
            .collect();
        assert_eq!(got, vec![(1, "region_1"), (2, "region_2")]);
        assert!(regions.iter().all(|r| r["tets"].as_u64().unwrap() > 0));
    }
    // Without --nested-regions, the inner sphere is a cavity: one region.
    let msh = tmp("regions_cavity_out.msh");
    let out = run(&[
        "mesh",
        spheres.to_str().unwrap(),
        "-o",
        msh.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    let raw = curvetet::io::read(&msh).unwrap();
    assert!(raw.tet10_tags.iter().all(|&t| t == 1));
}

/// A P2 sphere whose triangles are tagged 3 (z > 0, "inlet") and 7 ("wall"), in a
/// volume named "fluid" with tag 4: an MSH 2.2 file as Gmsh writes one with named
/// physical groups.
fn named_sphere(path: &Path) {
    use curvetet::io;
    let raw = io::read(&data("sphere_p2.msh")).unwrap();
    let tags: Vec<i32> = raw
        .tri6
        .iter()
        .map(|t| {
            let z: f64 = t[..3].iter().map(|&v| raw.nodes[v as usize][2]).sum();
            if z > 0.0 {
                3
            } else {
                7
            }
        })
        .collect();
    let opts = io::WriteOptions::default().with_msh_version(io::MshVersion::V22);
    io::write_surface(path, &raw.nodes, &raw.tri6, &tags, &opts).unwrap();
    let text = std::fs::read_to_string(path).unwrap();
    // The writer names nothing on a surface of tagged triangles: add the names.
    assert!(!text.contains("$PhysicalNames"));
    let names =
        "$PhysicalNames\n3\n2 3 \"inlet\"\n2 7 \"wall\"\n3 4 \"fluid\"\n$EndPhysicalNames\n";
    let text = text.replacen("$EndMeshFormat\n", &format!("$EndMeshFormat\n{names}"), 1);
    std::fs::write(path, text).unwrap();
}

/// Issue 30: every output of a tagged-and-named input, an untagged one, a body with a
/// cavity and two regions with an interface, in every format and encoding, is read by meshio without warning, with a
/// physical group for each boundary part and for the volume: the input's numbers and names
/// (.msh: physical names; .vtu: field data as meshio keeps them), or `boundary` 1 and
/// `volume` 1. curvetet reads the same numbers and names back, and Gmsh opens the .msh
/// files without a warning.
#[test]
fn groups_survive_every_output_format() {
    let named = tmp("named_sphere.msh");
    named_sphere(&named);
    let regions = tmp("groups_split_box.off");
    split_box_off(&regions, 2);
    // (name, input, triangle groups, volume groups, names)
    type Case = (
        &'static str,
        PathBuf,
        Vec<i32>,
        Vec<i32>,
        Vec<(&'static str, i32, u8)>,
    );
    let cases: Vec<Case> = vec![
        (
            "named",
            named,
            vec![3, 7],
            vec![4],
            vec![("inlet", 3, 2), ("wall", 7, 2), ("fluid", 4, 3)],
        ),
        (
            "untagged",
            data("sphere_lin.off"),
            vec![1],
            vec![1],
            vec![("boundary", 1, 2), ("volume", 1, 3)],
        ),
        (
            // A body with a cavity: two shells, one boundary group.
            "cavity",
            data("box_cavity_lin.off"),
            vec![1],
            vec![1],
            vec![("boundary", 1, 2), ("volume", 1, 3)],
        ),
        (
            // Two regions with an interface: two boxes sharing a wall.
            "regions",
            regions,
            vec![1, 2],
            vec![1, 2],
            vec![
                ("boundary", 1, 2),
                ("interface_1_2", 2, 2),
                ("region_1", 1, 3),
                ("region_2", 2, 3),
            ],
        ),
    ];
    let gmsh = Command::new("gmsh").arg("-version").output().is_ok();
    let mut spec = Vec::new();
    for (name, input, tri, vols, names) in &cases {
        let first = tmp(&format!("groups_{name}.msh"));
        let out = run(&[
            "mesh",
            input.to_str().unwrap(),
            "-o",
            first.to_str().unwrap(),
            "-q",
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let variants: [(&str, &[&str]); 7] = [
            ("41.msh", &[]),
            ("41b.msh", &["--binary"]),
            ("22.msh", &["--msh22"]),
            ("22b.msh", &["--msh22", "--binary"]),
            ("a.vtu", &[]),
            ("b.vtu", &["--binary"]),
            ("a.vtk", &[]),
        ];
        for (suffix, flags) in variants {
            let path = tmp(&format!("groups_{name}_{suffix}"));
            let mut args = vec!["convert", first.to_str().unwrap(), path.to_str().unwrap()];
            args.extend_from_slice(flags);
            let out = run(&args);
            assert!(
                out.status.success(),
                "{}",
                String::from_utf8_lossy(&out.stderr)
            );
            let msh = suffix.ends_with(".msh");
            let named = msh || suffix.ends_with(".vtu");
            // curvetet reads back the input's numbers (and, from .msh, names).
            let back = curvetet::io::read(&path).unwrap();
            let mut got: Vec<i32> = back.tri6_tags.clone();
            got.sort_unstable();
            got.dedup();
            assert_eq!(&got, tri, "{name} {suffix}");
            if named {
                assert_eq!(back.groups().volume_tag, vols[0], "{name} {suffix}");
                let mut got: Vec<(String, i32, u8)> = back
                    .physical_names
                    .iter()
                    .map(|n| (n.name.clone(), n.tag, n.dim))
                    .collect();
                got.sort();
                let mut want: Vec<(String, i32, u8)> = names
                    .iter()
                    .map(|&(n, t, d)| (n.to_string(), t, d))
                    .collect();
                want.sort();
                assert_eq!(got, want, "{name} {suffix}");
            }
            // Each tet is in its region (in .vtu/.vtk: the tets' tag, 0 for one region).
            let mut tets: Vec<i32> = back.tet10_tags.clone();
            tets.sort_unstable();
            tets.dedup();
            let tet_tags = if msh || vols.len() > 1 {
                vols.clone()
            } else {
                vec![0]
            };
            assert_eq!(tets, tet_tags, "{name} {suffix}");
            if msh && gmsh {
                let o = Command::new("gmsh")
                    .args([path.to_str().unwrap(), "-0", "-o"])
                    .arg(tmp(&format!("groups_{name}_{suffix}_gmsh.msh")))
                    .output()
                    .unwrap();
                let text = String::from_utf8_lossy(&o.stdout).to_string()
                    + &String::from_utf8_lossy(&o.stderr);
                assert!(o.status.success(), "gmsh {name} {suffix}: {text}");
                assert!(
                    !text.contains("Warning") && !text.contains("Error"),
                    "gmsh {name} {suffix}: {text}"
                );
            }
            let mut entry = serde_json::json!({
                "path": path.to_str().unwrap(),
                "key": if msh { "gmsh:physical" } else { "BoundaryTag" },
                "tri": tri,
                "tet": tet_tags,
            });
            if named {
                entry["names"] = serde_json::json!(names
                    .iter()
                    .map(|&(n, t, d)| serde_json::json!([n, t, d]))
                    .collect::<Vec<_>>());
            }
            spec.push(entry);
        }
    }
    let out = Command::new("python3")
        .args([
            "-c",
            MESHIO_GROUPS,
            &serde_json::Value::from(spec).to_string(),
        ])
        .output()
        .expect("python3 runs (scripts/install-deps installs meshio)");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.status.success(), "meshio failed:\n{text}");
    assert!(text.contains("meshio ok 28"), "{text}");
    assert!(
        !text.to_lowercase().contains("warn"),
        "meshio warned:\n{text}"
    );
}

/// A P2 sphere mesh split into two regions by the plane x = 0 (tets by centroid), as an
/// MSH 2.2 file: the outer triangles (tag 1), the interface triangles between the regions
/// (tag 9), the tets with region tags 1 and 2 (or all 1 with `one_region`). Returns the
/// number of interface triangles.
fn two_region_sphere(path: &Path, one_region: bool) -> usize {
    use std::collections::HashMap;
    use std::fmt::Write;
    let raw = curvetet::io::read(&data("sphere_p2.msh")).unwrap();
    let surface = curvetet::io::surface_from_raw(raw, "sphere").unwrap();
    let opts = curvetet::Options::default().with_optimize(false);
    let m = curvetet::generate(&surface, &opts).unwrap().mesh;
    let region: Vec<i32> = m
        .tets
        .iter()
        .map(|t| {
            let x: f64 = t[..4].iter().map(|&v| m.nodes[v as usize][0]).sum();
            if x > 0.0 || one_region {
                1
            } else {
                2
            }
        })
        .collect();
    let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
    const EDGES: [(usize, usize); 6] = [(0, 1), (1, 2), (2, 0), (3, 0), (3, 2), (3, 1)];
    for t in &m.tets {
        for (k, &(i, j)) in EDGES.iter().enumerate() {
            mid.insert((t[i].min(t[j]), t[i].max(t[j])), t[4 + k]);
        }
    }
    // Faces by sorted corners -> the tets holding them.
    let mut faces: HashMap<[u32; 3], Vec<usize>> = HashMap::new();
    for (ti, t) in m.tets.iter().enumerate() {
        for f in [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]] {
            let mut k = [t[f[0]], t[f[1]], t[f[2]]];
            k.sort_unstable();
            faces.entry(k).or_default().push(ti);
        }
    }
    let x_centroid = |t: usize| -> bool {
        let x: f64 = m.tets[t][..4].iter().map(|&v| m.nodes[v as usize][0]).sum();
        x > 0.0
    };
    let mut interface: Vec<[u32; 6]> = faces
        .iter()
        .filter(|(_, ts)| ts.len() == 2 && x_centroid(ts[0]) != x_centroid(ts[1]))
        .map(|(k, _)| {
            let e = |a: u32, b: u32| mid[&(a.min(b), a.max(b))];
            [
                k[0],
                k[1],
                k[2],
                e(k[0], k[1]),
                e(k[1], k[2]),
                e(k[2], k[0]),
            ]
        })
        .collect();
    interface.sort_unstable();
    let mut s = String::from("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n");
    writeln!(s, "{}", m.nodes.len()).unwrap();
    for (i, p) in m.nodes.iter().enumerate() {
        writeln!(s, "{} {:?} {:?} {:?}", i + 1, p[0], p[1], p[2]).unwrap();
    }
    let n = m.boundary.len() + interface.len() + m.tets.len();
    write!(s, "$EndNodes\n$Elements\n{n}\n").unwrap();
    let mut id = 0;
    let mut element = |s: &mut String, ty: u32, tag: i32, nodes: &[u32]| {
        id += 1;
        write!(s, "{id} {ty} 2 {tag} {tag}").unwrap();
        for v in nodes {
            write!(s, " {}", v + 1).unwrap();
        }
        s.push('\n');
    };
    for b in &m.boundary {
        element(&mut s, 9, 1, b);
    }
    for b in &interface {
        element(&mut s, 9, 9, b);
    }
    for (t, r) in m.tets.iter().zip(&region) {
        element(&mut s, 11, *r, t);
    }
    s.push_str("$EndElements\n");
    std::fs::write(path, s).unwrap();
    interface.len()
}

/// Issue 30: `check` accepts a conforming two-region mesh whose interface triangles are
/// listed with the boundary, reports the regions, and still refuses such triangles
/// inside one region (a cavity filled with tets would look the same).
#[test]
fn check_accepts_two_regions_with_their_interface() {
    let two = tmp("two_regions.msh");
    let k = two_region_sphere(&two, false);
    assert!(k > 50, "{k} interface triangles");
    let out = run(&["check", two.to_str().unwrap(), "--json"]);
    assert!(
        out.status.success(),
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(j["valid"], true);
    assert_eq!(j["conformity"]["interface_faces"], k);
    let regions: Vec<i64> = j["regions"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["tag"].as_i64().unwrap())
        .collect();
    assert_eq!(regions, vec![1, 2]);
    let text = run(&["check", two.to_str().unwrap()]);
    assert!(String::from_utf8_lossy(&text.stdout).contains(&format!("{k} interface triangles")));

    let one = tmp("one_region_interface.msh");
    two_region_sphere(&one, true);
    let out = run(&["check", one.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(6));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("is not a face of one tet"), "{err}");
}

/// Issue 30: the CLI's outputs carry what the other doors do. Its .vtu and .vtk meshes
/// have the per-tet `ScaledJacobian` and `EquiangularSkewness` cell arrays (as the VTK
/// filter's output; meshio reads them, and their extremes are the report's); its
/// `--report` has the crate version, the options used and per-stage times including
/// reading and writing.
#[test]
fn cli_vtu_has_quality_arrays_and_report_has_version_options_times() {
    let vtu = tmp("quality.vtu");
    let vtk = tmp("quality.vtk");
    let report = tmp("quality.json");
    let out = run(&[
        "mesh",
        data("sphere_lin.off").to_str().unwrap(),
        "-o",
        vtu.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
        "--alpha",
        "1.4",
        "-q",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(r["curvetet_version"], env!("CARGO_PKG_VERSION"));
    assert_eq!(r["options"]["alpha"], 1.4);
    assert_eq!(r["options"]["size"], "graded");
    assert_eq!(r["options"]["optimize"], true);
    assert_eq!(r["input"]["feature_angle"], 40.0);
    assert_eq!(r["input"]["strict"], false);
    assert_eq!(r["input"]["warnings"], serde_json::json!([]));
    assert!(r["input"]["path"]
        .as_str()
        .unwrap()
        .ends_with("sphere_lin.off"));
    for stage in [
        "read",
        "size_field",
        "front",
        "assemble",
        "optimize",
        "certify",
        "report",
        "write",
    ] {
        let t = r["times"][stage].as_f64().unwrap_or(-1.0);
        assert!(t > 0.0, "{stage}: {}", r["times"]);
    }
    let out = run(&["convert", vtu.to_str().unwrap(), vtk.to_str().unwrap()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let min_sj = r["report"]["quality"]["scaled_jacobian"]["min"]
        .as_f64()
        .unwrap();
    let max_skew = r["report"]["quality"]["skewness"]["max"].as_f64().unwrap();
    let ntets = r["report"]["num_tets"].as_u64().unwrap();
    let script = r#"
import sys, json
import numpy as np
import meshio
for path in sys.argv[1:]:
    m = meshio.read(path)
    sj = np.concatenate([d for b, d in zip(m.cells, m.cell_data["ScaledJacobian"]) if b.type == "tetra10"])
    sk = np.concatenate([d for b, d in zip(m.cells, m.cell_data["EquiangularSkewness"]) if b.type == "tetra10"])
    print(json.dumps([len(sj), float(sj.min()), float(sj.max()), float(sk.max())]))
"#;
    let out = Command::new("python3")
        .args(["-c", script, vtu.to_str().unwrap(), vtk.to_str().unwrap()])
        .output()
        .expect("python3 runs (scripts/install-deps installs meshio)");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 2, "{text}");
    for line in lines {
        let v: Vec<f64> = serde_json::from_str(line).unwrap();
        assert_eq!(v[0] as u64, ntets);
        // The .vtk holds 17 significant digits, as the .vtu.
        assert!(
            (v[1] - min_sj).abs() <= 1e-12 * min_sj,
            "{v:?} vs min SJ {min_sj}"
        );
        assert!(v[2] <= 1.0 + 1e-12, "{v:?}");
        assert!(
            (v[3] - max_skew).abs() <= 1e-12,
            "{v:?} vs max skewness {max_skew}"
        );
    }
}

/// Issue 30: the progress callback (and so the CLI's progress bar) reports an optimize
/// stage between the front and the certification, and none when optimization is off.
#[test]
fn progress_reports_the_optimize_stage() {
    let raw = curvetet::io::read(&data("sphere_p2.msh")).unwrap();
    let surface = curvetet::io::surface_from_raw(raw, "sphere").unwrap();
    for optimize in [true, false] {
        let opts = curvetet::Options::default().with_optimize(optimize);
        let mut stages: Vec<(String, f64)> = Vec::new();
        curvetet::generate_with_progress(&surface, &opts, &mut |f, s| {
            if stages.last().map(|x| x.0.as_str()) != Some(s) || s == "optimize" {
                stages.push((s.to_string(), f));
            }
            false
        })
        .unwrap();
        let names: Vec<&str> = stages.iter().map(|s| s.0.as_str()).collect();
        if optimize {
            assert_eq!(
                names,
                ["front", "optimize", "optimize", "certify"],
                "{stages:?}"
            );
            assert_eq!((stages[1].1, stages[2].1), (0.0, 0.5));
        } else {
            assert_eq!(names, ["front", "certify"], "{stages:?}");
        }
    }
}

/// Issue 30: a Gmsh model of two volumes (a box with a spherical inclusion, physical
/// volumes 7 "matrix" and 8 "inclusion") meshed in 2D by Gmsh (`-2 -order 2`) is meshed
/// by `curvetet mesh` into one conforming mesh with the two physical volumes, which
/// `check` accepts and meshio reads; Gmsh opens it without a warning.
#[test]
fn a_gmsh_surface_of_two_volumes_meshes_by_physical_volume() {
    let has_gmsh = Command::new("gmsh")
        .arg("-version")
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false);
    if !has_gmsh {
        if std::env::var_os("CURVETET_REQUIRE_TOOLS").is_some() {
            panic!("required tool missing: gmsh");
        }
        println!("note: gmsh not available; skipped (scripts/install-deps installs it)");
        return;
    }
    let geo = tmp("box_inclusion.geo");
    std::fs::write(
        &geo,
        "SetFactory(\"OpenCASCADE\");\nBox(1) = {0,0,0, 2,2,2};\nSphere(2) = {1,1,1, 0.5};\n\
         BooleanFragments{ Volume{1}; Delete; }{ Volume{2}; Delete; }\n\
         Physical Volume(\"matrix\", 7) = {3};\nPhysical Volume(\"inclusion\", 8) = {2};\n\
         Mesh.MeshSizeMax = 0.4;\n",
    )
    .unwrap();
    let surface = tmp("box_inclusion_surface.msh");
    let o = Command::new("gmsh")
        .arg(&geo)
        .args(["-2", "-order", "2", "-format", "msh41", "-save_all", "-o"])
        .arg(&surface)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = tmp("box_inclusion_volume.msh");
    let r = run(&[
        "mesh",
        surface.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--threads",
        "1",
    ]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(r.status.success(), "{err}");
    assert!(err.contains("2 regions"), "{err}");
    let r = run(&["check", out.to_str().unwrap(), "--json"]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let j: serde_json::Value = serde_json::from_slice(&r.stdout).unwrap();
    let got: Vec<(i64, &str)> = j["regions"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| (r["tag"].as_i64().unwrap(), r["name"].as_str().unwrap()))
        .collect();
    assert_eq!(got, vec![(7, "matrix"), (8, "inclusion")]);
    assert!(j["conformity"]["interface_faces"].as_u64().unwrap() > 0);
    let rel = j["volume_relative_difference"].as_f64().unwrap();
    assert!(rel <= 1e-10, "{rel}");
    // The inclusion's linear volume ...
    let back = curvetet::io::read(&out).unwrap();
    let inclusion: f64 = back
        .tet10
        .iter()
        .zip(&back.tet10_tags)
        .filter(|x| *x.1 == 8)
        .map(|(t, _)| {
            let p = |k: usize| back.nodes[t[k] as usize];
            curvetet::geom::vec3::tet_det(p(0), p(1), p(2), p(3)) / 6.0
        })
        .sum();
    // ... equals the volume its chord triangles (the boundary triangles on the sphere)
    // enclose.
    let on_sphere = |v: u32| {
        let p = back.nodes[v as usize];
        let d = ((p[0] - 1.0).powi(2) + (p[1] - 1.0).powi(2) + (p[2] - 1.0).powi(2)).sqrt();
        (d - 0.5).abs() < 1e-6
    };
    let sphere: Vec<[u32; 6]> = back
        .tri6
        .iter()
        .filter(|t| t[..3].iter().all(|&v| on_sphere(v)))
        .copied()
        .collect();
    assert!(!sphere.is_empty());
    let chord = curvetet::geom::quadrature::enclosed_volume_linear(&back.nodes, &sphere).abs();
    assert!(
        (inclusion - chord).abs() <= 1e-10 * chord,
        "{inclusion} vs {chord}"
    );
    let o = Command::new("gmsh")
        .args([out.to_str().unwrap(), "-0", "-o"])
        .arg(tmp("box_inclusion_gmsh.msh"))
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&o.stdout).to_string() + &String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success() && !text.contains("Warning"), "{text}");
}
