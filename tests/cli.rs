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
    assert_eq!(
        out.status.code(),
        Some(1),
        "clap refuses the combination (usage error)"
    );
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
