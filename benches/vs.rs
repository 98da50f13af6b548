//! Side-by-side benchmark: curvetet vs TetGen vs Gmsh on the same surfaces, in one run.
//!
//!     cargo bench --bench vs                       # data surfaces + torus at 10k/100k tets
//!     cargo bench --bench vs -- --scales 10k,100k,1M --runs 3 --json bench.json
//!     cargo bench --bench vs -- --only sphere,torus --scales none
//!
//! Per input, each tool runs as its own process (`--runs` times, median wall time; peak
//! memory = the child's maximum resident set size, from wait4):
//! - curvetet: `curvetet mesh IN_p2.msh -o OUT.msh --threads T` — end to end: read, mesh,
//!   optimize, certify, write (T = `--threads`, default 1: the targets are per core);
//! - TetGen:   `tetgen -pYqQ IN_lin.off` (quality mesh, boundary kept), the linear twin;
//!   and again with `-a` (a volume bound of 1.9 × the volume per curvetet tet) so that it
//!   makes about as many tets as curvetet (plain -pYqQ has no size field and makes far
//!   fewer on big surfaces) — column "tg=";
//! - Gmsh:     when a Python with the `gmsh` module is found ($CURVETET_BENCH_PYTHON, the
//!   PyPI gmsh 4.15 venv of scripts/install-deps, python3, /usr/bin/python3): merge the linear twin (STL), HXT 3D (Mesh.Algorithm3D = 10,
//!   one thread), setOrder(2), write .msh; its time is measured inside the script (merge to
//!   write, Python start-up excluded), its memory includes the Python interpreter.
//!
//! Inputs: every tests/data/NAME_p2.msh (the paper's benchmark surfaces), the raw
//! marching-cubes blob tests/data/mc_blob.off smoothed and curved (`curve --smooth 10`:
//! an image-derived surface), and the built-in
//! torus (`curvetet demo --surface-only`) sized for ≈10k/100k/1M curvetet tets.
//! Ratios are curvetet/tool for wall time, and for time per tet (the tools make different
//! numbers of tets from the same surface). Timing only; nothing is asserted.

#[path = "common/off.rs"]
mod common;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

const GMSH_SCRIPT: &str = r#"
import sys, time, json, gmsh
gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.option.setNumber("General.NumThreads", 1)
t0 = time.perf_counter()
gmsh.merge(sys.argv[1])
s = gmsh.model.getEntities(2)
l = gmsh.model.geo.addSurfaceLoop([e[1] for e in s])
gmsh.model.geo.addVolume([l])
gmsh.model.geo.synchronize()
gmsh.option.setNumber("Mesh.Algorithm3D", 10)
t1 = time.perf_counter()
gmsh.model.mesh.generate(3)
t2 = time.perf_counter()
gmsh.model.mesh.setOrder(2)
t3 = time.perf_counter()
gmsh.write(sys.argv[2])
t4 = time.perf_counter()
types, tags, _ = gmsh.model.mesh.getElements(3)
n = sum(len(t) for t in tags)
print(json.dumps({"tets": n, "total": t4 - t0, "mesh3d": t2 - t1, "order2": t3 - t2}))
gmsh.finalize()
"#;

struct Args {
    runs: usize,
    threads: usize,
    scales: Vec<(String, usize)>,
    only: Option<Vec<String>>,
    json: PathBuf,
}

fn parse_args() -> Args {
    let target = Path::new(env!("CARGO_MANIFEST_DIR")).join("target");
    let mut a = Args {
        runs: 3,
        threads: 1,
        scales: vec![("10k".into(), 10_000), ("100k".into(), 100_000)],
        only: None,
        json: target.join("bench_vs.json"),
    };
    let mut it = std::env::args().skip(1);
    while let Some(x) = it.next() {
        let mut val = || it.next().unwrap_or_else(|| panic!("{x} needs a value"));
        match x.as_str() {
            "--runs" => a.runs = val().parse().expect("--runs N"),
            "--threads" => a.threads = val().parse().expect("--threads N"),
            "--json" => a.json = PathBuf::from(val()),
            "--only" => a.only = Some(val().split(',').map(String::from).collect()),
            "--scales" => {
                let v = val();
                a.scales = if v == "none" {
                    Vec::new()
                } else {
                    v.split(',')
                        .map(|s| {
                            let n = match s.to_ascii_lowercase().as_str() {
                                x if x.ends_with('m') => {
                                    x[..x.len() - 1].parse::<usize>().unwrap() * 1_000_000
                                }
                                x if x.ends_with('k') => {
                                    x[..x.len() - 1].parse::<usize>().unwrap() * 1_000
                                }
                                x => x.parse().expect("--scales like 10k,100k,1M"),
                            };
                            (s.to_string(), n)
                        })
                        .collect()
                };
            }
            "--bench" => {} // passed by `cargo bench`
            other => panic!("unknown argument {other} (see the header of benches/vs.rs)"),
        }
    }
    a
}

/// One process run: wall seconds, peak RSS in bytes, stdout.
struct Run {
    secs: f64,
    rss: u64,
    stdout: String,
}

fn run(cmd: &mut Command, dir: &Path) -> Result<Run, String> {
    let out = dir.join("stdout.txt");
    let err = dir.join("stderr.txt");
    cmd.stdin(Stdio::null())
        .stdout(std::fs::File::create(&out).unwrap())
        .stderr(std::fs::File::create(&err).unwrap());
    let t0 = Instant::now();
    let child = cmd.spawn().map_err(|e| format!("{cmd:?}: {e}"))?;
    let mut status = 0;
    // SAFETY: plain wait4 on our own child's pid with valid out-pointers; the child is reaped
    // here (std's Child is dropped without waiting, which is allowed).
    let mut ru: libc::rusage = unsafe { std::mem::zeroed() };
    let r = unsafe { libc::wait4(child.id() as libc::pid_t, &mut status, 0, &mut ru) };
    let secs = t0.elapsed().as_secs_f64();
    if r < 0 {
        return Err(format!("wait4: {}", std::io::Error::last_os_error()));
    }
    if !(libc::WIFEXITED(status) && libc::WEXITSTATUS(status) == 0) {
        let e = std::fs::read_to_string(&err).unwrap_or_default();
        let tail: Vec<&str> = e.lines().collect();
        return Err(format!(
            "{:?} failed ({}): {}",
            cmd.get_program(),
            if libc::WIFEXITED(status) {
                format!("exit code {}", libc::WEXITSTATUS(status))
            } else {
                format!("signal {}", libc::WTERMSIG(status))
            },
            tail[tail.len().saturating_sub(3)..].join(" | ")
        ));
    }
    Ok(Run {
        secs,
        rss: ru.ru_maxrss as u64 * 1024,
        stdout: std::fs::read_to_string(&out).unwrap_or_default(),
    })
}

/// Median time, max memory, tets of `runs` runs of one tool.
#[derive(Clone, Default)]
struct Stat {
    secs: f64,
    rss: u64,
    tets: usize,
    all: Vec<f64>,
    err: Option<String>,
}

impl Stat {
    fn rate(&self) -> f64 {
        self.tets as f64 / self.secs
    }
    fn ok(&self) -> bool {
        self.err.is_none() && self.tets > 0
    }
}

fn measure(runs: usize, mut once: impl FnMut() -> Result<(f64, u64, usize), String>) -> Stat {
    let mut s = Stat::default();
    for _ in 0..runs {
        match once() {
            Ok((t, m, n)) => {
                s.all.push(t);
                s.rss = s.rss.max(m);
                s.tets = n;
            }
            Err(e) => {
                s.err = Some(e);
                return s;
            }
        }
    }
    let mut v = s.all.clone();
    v.sort_by(f64::total_cmp);
    s.secs = v[v.len() / 2];
    s
}

/// The first Python that imports `gmsh`, with the module's version: $CURVETET_BENCH_PYTHON,
/// then the PyPI gmsh venv scripts/install-deps makes (Gmsh 4.15, the reference
/// version), then the system's python3-gmsh (4.8).
fn python_with_gmsh() -> Option<(String, String)> {
    let mut c: Vec<String> = Vec::new();
    if let Ok(p) = std::env::var("CURVETET_BENCH_PYTHON") {
        c.push(p);
    }
    let venv = std::env::var("CURVETET_PYPI_GMSH_VENV").unwrap_or_else(|_| {
        format!(
            "{}/.cache/curvetet/pypi-gmsh",
            std::env::var("HOME").unwrap_or_default()
        )
    });
    c.push(format!("{venv}/bin/python"));
    c.extend(["python3".into(), "/usr/bin/python3".into()]);
    c.into_iter().find_map(|p| {
        let o = Command::new(&p)
            .args(["-c", "import gmsh; print(gmsh.__version__)"])
            .stderr(Stdio::null())
            .output()
            .ok()?;
        o.status
            .success()
            .then(|| (p, String::from_utf8_lossy(&o.stdout).trim().to_string()))
    })
}

fn have(tool: &str) -> bool {
    Command::new(tool)
        .arg("-h")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok()
}

/// Writes the linear twin of a P2 surface (its corners) as OFF and ASCII STL, with
/// round-trip (17 significant digit) coordinates.
fn write_linear(s: &curvetet::Surface, off: &Path, stl: &Path) -> f64 {
    let nodes = s.nodes();
    let tris = s.triangles();
    let o = common::linear_off(s);
    let mut st = String::from("solid twin\n");
    let mut vol = 0.0;
    for t in tris {
        let [a, b, c] = [t[0], t[1], t[2]].map(|v| nodes[v as usize]);
        vol += (a[0] * (b[1] * c[2] - b[2] * c[1])
            + a[1] * (b[2] * c[0] - b[0] * c[2])
            + a[2] * (b[0] * c[1] - b[1] * c[0]))
            / 6.0;
        st += "facet normal 0 0 0\nouter loop\n";
        for &v in &t[..3] {
            let p = nodes[v as usize];
            let _ = writeln!(st, "vertex {:e} {:e} {:e}", p[0], p[1], p[2]);
        }
        st += "endloop\nendfacet\n";
    }
    st += "endsolid twin\n";
    std::fs::write(off, o).unwrap();
    std::fs::write(stl, st).unwrap();
    vol
}

fn main() {
    let args = parse_args();
    let exe = env!("CARGO_BIN_EXE_curvetet");
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let work = root.join("target/bench_vs");
    let _ = std::fs::remove_dir_all(&work);
    std::fs::create_dir_all(&work).unwrap();
    let python = python_with_gmsh();
    let tetgen = have("tetgen");
    eprintln!(
        "bench vs: {} run(s) per tool, median; curvetet --threads {}; tetgen: {}; gmsh: {}",
        args.runs,
        args.threads,
        if tetgen {
            "yes"
        } else {
            "NOT FOUND (apt-get install tetgen)"
        },
        python.as_ref().map_or(
            "NOT FOUND (apt-get install python3-gmsh)".to_string(),
            |(p, v)| { format!("{v} (Python module via {p})") }
        )
    );

    // Inputs: (label, P2 surface path).
    let mut inputs: Vec<(String, PathBuf)> = Vec::new();
    for name in ["sphere", "torus", "tube", "lv", "screw", "hinge"] {
        if args
            .only
            .as_ref()
            .map_or(true, |o| o.iter().any(|x| x == name))
        {
            inputs.push((name.into(), root.join(format!("tests/data/{name}_p2.msh"))));
        }
    }
    // An image-derived surface: the raw marching-cubes blob of tests/data, smoothed and
    // curved by `curvetet curve --smooth 10` (every tool then meshes that same surface).
    if args
        .only
        .as_ref()
        .map_or(true, |o| o.iter().any(|x| x == "mc_blob"))
    {
        let p = work.join("mc_blob_smoothed_p2.msh");
        let st = Command::new(exe)
            .arg("curve")
            .arg(root.join("tests/data/mc_blob.off"))
            .args(["--smooth", "10", "-o"])
            .arg(&p)
            .stderr(Stdio::null())
            .status()
            .unwrap();
        assert!(st.success(), "curvetet curve --smooth failed");
        inputs.push(("mc_blob".into(), p));
    }
    for (label, tets) in &args.scales {
        // The demo torus makes ≈ 0.063 · triangles^1.5 tets (measured).
        let tris = ((*tets as f64 / 0.063).powf(2.0 / 3.0)).round() as usize;
        let p = work.join(format!("demo_torus_{label}_p2.msh"));
        let st = Command::new(exe)
            .args([
                "demo",
                "--surface-only",
                "--triangles",
                &tris.to_string(),
                "-o",
            ])
            .arg(&p)
            .stdout(Stdio::null())
            .status()
            .unwrap();
        assert!(st.success(), "curvetet demo failed");
        inputs.push((format!("torus{label}"), p));
    }

    let mut table = String::new();
    let mut json = Vec::new();
    let header = format!(
        "{:<11} {:>6} | {:>8} {:>8} {:>8} {:>6} | {:>8} {:>8} {:>8} {:>6} | {:>8} {:>8} {:>8} {:>6} | {:>8} {:>8} {:>8} {:>6} | {:>6} {:>6} {:>6} {:>7} {:>7}",
        "input", "tris",
        "ct tets", "ct s", "ct t/s", "ct B/t",
        "tg tets", "tg s", "tg t/s", "tg B/t",
        "tg= tets", "tg= s", "tg= t/s", "B/t",
        "gm tets", "gm s", "gm t/s", "gm B/t",
        "ct/tg", "ct/tg=", "ct/gm", "ct/tg/t", "ct/gm/t"
    );
    eprintln!("{header}");
    table += &header;
    table.push('\n');
    for (label, p2) in &inputs {
        let dir = work.join(label);
        std::fs::create_dir_all(&dir).unwrap();
        let surface = match curvetet::io::read_surface(p2) {
            Ok(s) => s,
            Err(e) => {
                eprintln!("{label}: cannot read {}: {e}", p2.display());
                continue;
            }
        };
        let off = dir.join("twin.off");
        let stl = dir.join("twin.stl");
        let volume = write_linear(&surface, &off, &stl);
        let tris = surface.triangles().len();

        let report = dir.join("report.json");
        let ct = measure(args.runs, || {
            let r = run(
                Command::new(exe)
                    .arg("mesh")
                    .arg(p2)
                    .args(["-q", "--threads", &args.threads.to_string(), "-o"])
                    .arg(dir.join("curvetet.msh"))
                    .arg("--report")
                    .arg(&report),
                &dir,
            )?;
            let j: serde_json::Value =
                serde_json::from_str(&std::fs::read_to_string(&report).map_err(|e| e.to_string())?)
                    .map_err(|e| e.to_string())?;
            let n = j["report"]["num_tets"]
                .as_u64()
                .ok_or("no num_tets in report")? as usize;
            Ok((r.secs, r.rss, n))
        });
        let tetgen_run = |flags: &str| {
            if !tetgen {
                return Stat {
                    err: Some("tetgen not found".into()),
                    ..Stat::default()
                };
            }
            measure(args.runs, || {
                let r = run(Command::new("tetgen").arg(flags).arg(&off), &dir)?;
                let ele =
                    std::fs::read_to_string(dir.join("twin.1.ele")).map_err(|e| e.to_string())?;
                let n = ele
                    .split_whitespace()
                    .next()
                    .and_then(|w| w.parse().ok())
                    .ok_or("bad .ele")?;
                Ok((r.secs, r.rss, n))
            })
        };
        let tg = tetgen_run("-pYqQ");
        // TetGen with a volume bound that gives about as many tets as curvetet made
        // (-a at 1.9 × volume per curvetet tet: measured on the torus, ±20 %).
        let tg_flags = if ct.ok() {
            format!("-pYqQa{:e}", 1.9 * volume / ct.tets as f64)
        } else {
            String::new()
        };
        let tgm = if ct.ok() {
            tetgen_run(&tg_flags)
        } else {
            Stat {
                err: Some("no curvetet tet count to match".into()),
                ..Stat::default()
            }
        };
        let gm = if let Some((py, _)) = &python {
            let script = work.join("gmsh_hxt_p2.py");
            std::fs::write(&script, GMSH_SCRIPT).unwrap();
            measure(args.runs, || {
                let r = run(
                    Command::new(py)
                        .arg(&script)
                        .arg(&stl)
                        .arg(dir.join("gmsh.msh")),
                    &dir,
                )?;
                let j: serde_json::Value = serde_json::from_str(r.stdout.trim())
                    .map_err(|e| format!("gmsh script output {:?}: {e}", r.stdout))?;
                let n = j["tets"].as_u64().unwrap_or(0) as usize;
                Ok((j["total"].as_f64().unwrap_or(r.secs), r.rss, n))
            })
        } else {
            Stat {
                err: Some("python gmsh module not found".into()),
                ..Stat::default()
            }
        };

        let cell = |s: &Stat| {
            if s.ok() {
                format!(
                    "{:>8} {:>8.3} {:>8.0} {:>6.0}",
                    s.tets,
                    s.secs,
                    s.rate(),
                    s.rss as f64 / s.tets as f64
                )
            } else {
                format!("{:>8} {:>8} {:>8} {:>6}", "-", "FAIL", "-", "-")
            }
        };
        let ratio = |a: &Stat, b: &Stat, per_tet: bool| {
            if a.ok() && b.ok() {
                let r = if per_tet {
                    (a.secs / a.tets as f64) / (b.secs / b.tets as f64)
                } else {
                    a.secs / b.secs
                };
                format!("{r:.2}")
            } else {
                "-".into()
            }
        };
        let line = format!(
            "{:<11} {:>6} | {} | {} | {} | {} | {:>6} {:>6} {:>6} {:>7} {:>7}",
            label,
            tris,
            cell(&ct),
            cell(&tg),
            cell(&tgm),
            cell(&gm),
            ratio(&ct, &tg, false),
            ratio(&ct, &tgm, false),
            ratio(&ct, &gm, false),
            ratio(&ct, &tg, true),
            ratio(&ct, &gm, true)
        );
        eprintln!("{line}");
        for (tool, s) in [
            ("curvetet", &ct),
            ("tetgen", &tg),
            ("tetgen -a", &tgm),
            ("gmsh", &gm),
        ] {
            if let Some(e) = &s.err {
                eprintln!("    {tool} on {label}: {e}");
            }
        }
        table += &line;
        table.push('\n');
        let js = |s: &Stat| {
            serde_json::json!({
                "tets": s.tets, "median_seconds": s.secs, "runs_seconds": s.all,
                "tets_per_second": if s.ok() { s.rate() } else { 0.0 },
                "peak_rss_bytes": s.rss,
                "bytes_per_tet": if s.ok() { s.rss as f64 / s.tets as f64 } else { 0.0 },
                "error": s.err,
            })
        };
        json.push(serde_json::json!({
            "input": label, "triangles": tris,
            "curvetet": js(&ct), "tetgen": js(&tg), "gmsh_hxt_p2": js(&gm),
            "tetgen_matched": js(&tgm), "tetgen_matched_flags": tg_flags,
        }));
    }
    let doc = serde_json::json!({
        "runs": args.runs, "curvetet_threads": args.threads,
        "gmsh_version": python.as_ref().map(|p| p.1.clone()),
        "commands": {
            "curvetet": "curvetet mesh IN_p2.msh -q --threads T -o OUT.msh --report R.json",
            "tetgen": "tetgen -pYqQ twin.off",
            "tetgen_matched": "tetgen -pYqQa<1.9 V / curvetet tets> twin.off",
            "gmsh": "merge twin.stl; Mesh.Algorithm3D=10 (HXT), 1 thread; generate(3); setOrder(2); write",
        },
        "results": json,
    });
    std::fs::write(&args.json, serde_json::to_string_pretty(&doc).unwrap()).unwrap();
    eprintln!(
        "columns: tets, median seconds, tets/s, peak RSS bytes per tet; ct/tg and ct/gm = time ratios, \
         /t = per-tet time ratios (< 1: curvetet faster); tg= = tetgen -pYqQa with a volume bound \
         matched to curvetet's tet count\nJSON: {}",
        args.json.display()
    );
}
