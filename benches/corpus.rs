//! Corpus benchmark: curvetet against TetGen on every surface of a folder, in one run.
//!
//!     cargo bench --bench corpus                                  # ../shared/data/openscad
//!     cargo bench --bench corpus -- --dir DIR --timeout 60 --only example002,offset
//!     cargo bench --bench corpus -- --json corpus.json
//!     CURVETET_EXE=/tmp/curvetet cargo bench --bench corpus   # measure that build
//!
//! Per surface (every `.stl`, `.off`, `.obj`, `.ply` in the folder, by name):
//! - curvetet: `curvetet mesh IN -o OUT.vtu --report R.json -q` with default options, killed
//!   after `--timeout` seconds (default 60); wall time, tets, minimum dihedral angle,
//!   certified min J / max J, and the sliver counts of the report when it has them;
//! - TetGen:   `tetgen -pYqQ IN` (quality mesh, boundary kept) on the same file; its
//!   mesh's tets, smallest dihedral angle and sliver census (forced / unforced, by
//!   curvetet's own census against the same triangles), so that the times compare meshes
//!   whose quality the table shows.
//!
//! Prints a table, the count meshed, the total time ratio (over the surfaces both meshed,
//! and with failures counted at their time) and the worst per-surface ratio. The issue's
//! targets: every surface meshed, corpus total at most 3x TetGen's, no surface above
//! 10x TetGen's time + 0.5 s. Timing only; nothing is asserted (tests assert outcomes).

#[path = "common/off.rs"]
mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

struct Args {
    dir: PathBuf,
    timeout: f64,
    only: Vec<String>,
    json: Option<PathBuf>,
}

fn parse_args() -> Args {
    let mut a = Args {
        dir: Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/openscad"),
        timeout: 60.0,
        only: Vec::new(),
        json: None,
    };
    let mut it = std::env::args().skip(1);
    while let Some(x) = it.next() {
        match x.as_str() {
            "--dir" => a.dir = it.next().expect("--dir DIR").into(),
            "--timeout" => a.timeout = it.next().and_then(|s| s.parse().ok()).expect("--timeout S"),
            "--only" => {
                a.only = it
                    .next()
                    .expect("--only A,B")
                    .split(',')
                    .map(str::to_string)
                    .collect()
            }
            "--json" => a.json = Some(it.next().expect("--json FILE").into()),
            _ => {} // cargo bench passes --bench
        }
    }
    a
}

/// Wall time and exit (None: killed at the timeout) of `cmd`, output to `log`.
fn run(cmd: &mut Command, log: &Path, timeout: f64) -> (f64, Option<i32>) {
    cmd.stdin(Stdio::null())
        .stdout(std::fs::File::create(log).expect("log"))
        .stderr(std::fs::File::create(log.with_extension("err")).expect("log"));
    let t0 = Instant::now();
    let Ok(mut child) = cmd.spawn() else {
        return (0.0, Some(-1));
    };
    loop {
        if let Ok(Some(st)) = child.try_wait() {
            return (t0.elapsed().as_secs_f64(), Some(st.code().unwrap_or(-1)));
        }
        if t0.elapsed().as_secs_f64() > timeout {
            let _ = child.kill();
            let _ = child.wait();
            return (t0.elapsed().as_secs_f64(), None);
        }
        std::thread::sleep(Duration::from_millis(5));
    }
}

#[derive(Default, serde::Serialize)]
struct Row {
    name: String,
    triangles: usize,
    ct_secs: f64,
    ct_outcome: String,
    tets: usize,
    min_dihedral: f64,
    min_jac: f64,
    slivers_forced: Option<u64>,
    slivers_unforced: Option<u64>,
    tg_secs: f64,
    tg_ok: bool,
    /// TetGen's mesh, measured as curvetet's is (corner tets; the sliver census against
    /// its boundary triangles, which `-Y` keeps as the input's).
    tg_tets: usize,
    tg_min_dihedral: f64,
    tg_slivers_forced: Option<usize>,
    tg_slivers_unforced: Option<usize>,
}

/// Tets, smallest dihedral angle and sliver census of the mesh TetGen wrote at `base`
/// (`base.1.node`, `.1.ele`, `.1.face`); None where a file is missing or malformed.
fn tetgen_quality(base: &Path) -> Option<(usize, f64, curvetet::SliverCensus)> {
    let read = |ext: &str| std::fs::read_to_string(base.with_extension(ext)).ok();
    // Each file: a header line, then one line per item, `#` comments skipped; items are
    // numbered from the `.node` file's first index.
    let rows = |text: &str| -> Vec<Vec<f64>> {
        text.lines()
            .map(|l| l.split('#').next().unwrap_or(""))
            .filter(|l| !l.trim().is_empty())
            .skip(1)
            .map(|l| {
                l.split_whitespace()
                    .filter_map(|x| x.parse().ok())
                    .collect()
            })
            .collect()
    };
    let nodes = rows(&read("1.node")?);
    let first = nodes.first()?.first().copied()? as u32;
    let pts: Vec<[f64; 3]> = nodes
        .iter()
        .map(|r| (r.len() >= 4).then(|| [r[1], r[2], r[3]]))
        .collect::<Option<_>>()?;
    let n = pts.len();
    let index = |x: f64| -> Option<u32> {
        let i = (x as u32).checked_sub(first)?;
        ((i as usize) < n).then_some(i)
    };
    // The first `N` node ids of a row after its own number.
    fn ids<const N: usize>(r: &[f64], index: impl Fn(f64) -> Option<u32>) -> Option<[u32; N]> {
        let c = r.get(1..1 + N)?;
        let mut out = [0; N];
        for (o, &x) in out.iter_mut().zip(c) {
            *o = index(x)?;
        }
        Some(out)
    }
    let mut mesh = curvetet::TetMesh {
        nodes: pts,
        ..Default::default()
    };
    for r in rows(&read("1.ele")?) {
        let [a, b, c, d] = ids::<4>(&r, index)?;
        mesh.tets.push([a, b, c, d, 0, 0, 0, 0, 0, 0]);
    }
    for r in rows(&read("1.face")?) {
        let [a, b, c] = ids::<3>(&r, index)?;
        mesh.boundary.push([a, b, c, 0, 0, 0]);
    }
    let min_dihedral = mesh
        .tets
        .iter()
        .map(|t| {
            let c = [t[0], t[1], t[2], t[3]].map(|v| mesh.nodes[v as usize]);
            curvetet::geom::tet_quality::dihedral_extremes(&c).0
        })
        .fold(f64::INFINITY, f64::min);
    Some((
        mesh.tets.len(),
        min_dihedral,
        curvetet::mesh::slivers::census(&mesh),
    ))
}

/// The largest curvetet time / (10 x TetGen's + 0.5 s) among `rows`, and its surface.
fn worst_ratio<'a>(rows: impl Iterator<Item = &'a Row>) -> (f64, &'a str) {
    rows.map(|r| (r.ct_secs / (10.0 * r.tg_secs + 0.5), r.name.as_str()))
        .fold((0.0, ""), |a, b| if b.0 > a.0 { b } else { a })
}

fn main() {
    let a = parse_args();
    // $CURVETET_EXE: another build to measure (e.g. a copy, so that rebuilding the tree
    // during a long run does not change the program under test).
    let exe = match std::env::var_os("CURVETET_EXE") {
        Some(e) => PathBuf::from(e),
        None => {
            let st = Command::new("cargo")
                .args(["build", "--release", "--quiet", "--bin", "curvetet"])
                .current_dir(env!("CARGO_MANIFEST_DIR"))
                .status()
                .expect("cargo");
            assert!(st.success(), "cargo build failed");
            Path::new(env!("CARGO_MANIFEST_DIR")).join("target/release/curvetet")
        }
    };
    let mut files: Vec<PathBuf> = std::fs::read_dir(&a.dir)
        .unwrap_or_else(|e| panic!("{}: {e}", a.dir.display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            let ext = p.extension().and_then(|x| x.to_str()).unwrap_or("");
            ["stl", "off", "obj", "ply"].contains(&ext.to_ascii_lowercase().as_str())
        })
        .filter(|p| {
            a.only.is_empty()
                || a.only
                    .iter()
                    .any(|o| p.file_stem().unwrap().to_str() == Some(o))
        })
        .collect();
    files.sort();
    let tmp = std::env::temp_dir().join(format!("curvetet-corpus-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).expect("tmp");
    let have_tetgen = Command::new("tetgen")
        .arg("-h")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok();
    if !have_tetgen {
        // Not a failure of TetGen's on each part: no reference at all.
        println!(
            "TetGen not found on PATH (scripts/install-deps installs it): its times and the \
             ratios below are not measured"
        );
    }
    println!(
        "{:<22} {:>6} {:>9} {:>8} {:>7} {:>7} {:>8} {:>9} {:>7} {:>6} {:>7} {:>7} {:>10}",
        "surface",
        "tris",
        "curvetet",
        "outcome",
        "tets",
        "min dih",
        "min J",
        "slivers",
        "TetGen",
        "ratio",
        "TG tets",
        "TG dih",
        "TG slivers"
    );
    let mut rows = Vec::new();
    for f in &files {
        let name = f.file_stem().unwrap().to_string_lossy().to_string();
        let mut r = Row {
            name: name.clone(),
            ..Default::default()
        };
        // TetGen reads ASCII OFF (not binary STL): the corners of what curvetet read.
        let off = tmp.join(format!("{name}.off"));
        if let Ok(s) = curvetet::io::read_any_surface(f, &Default::default()) {
            r.triangles = s.triangles().len();
            write_off(&s, &off);
        }
        let rep = tmp.join(format!("{name}.json"));
        let _ = std::fs::remove_file(&rep);
        let (t, code) = run(
            Command::new(&exe).args([
                "mesh".as_ref(),
                f.as_os_str(),
                "-q".as_ref(),
                "-o".as_ref(),
                tmp.join(format!("{name}.vtu")).as_os_str(),
                "--report".as_ref(),
                rep.as_os_str(),
            ]),
            &tmp.join(format!("{name}.log")),
            a.timeout,
        );
        r.ct_secs = t;
        r.ct_outcome = match code {
            None => "timeout".into(),
            Some(0) => "ok".into(),
            Some(c) => format!("exit {c}"),
        };
        if code == Some(0) {
            let j: serde_json::Value =
                serde_json::from_str(&std::fs::read_to_string(&rep).unwrap_or_default())
                    .unwrap_or_default();
            let q = &j["report"]["quality"];
            r.tets = j["report"]["num_tets"].as_u64().unwrap_or(0) as usize;
            r.min_dihedral = q["min_dihedral"]["min"].as_f64().unwrap_or(f64::NAN);
            r.min_jac = q["scaled_jacobian_certified"]["min"]
                .as_f64()
                .unwrap_or(f64::NAN);
            r.slivers_forced = j["report"]["slivers"]["forced"].as_u64();
            r.slivers_unforced = j["report"]["slivers"]["unforced"].as_u64();
        }
        if have_tetgen {
            let (t, code) = run(
                Command::new("tetgen").arg("-pYqQ").arg(&off),
                &tmp.join(format!("{name}.tetgen.log")),
                a.timeout,
            );
            r.tg_secs = t;
            r.tg_ok = code == Some(0);
            if let Some((tets, min_dih, census)) = tetgen_quality(&off).filter(|_| r.tg_ok) {
                r.tg_tets = tets;
                r.tg_min_dihedral = min_dih;
                r.tg_slivers_forced = Some(census.forced);
                r.tg_slivers_unforced = Some(census.unforced);
            }
        }
        let sl = match (r.slivers_forced, r.slivers_unforced) {
            (Some(fo), Some(un)) => format!("{fo}/{un}"),
            _ => "-".into(),
        };
        let (tg_tets, tg_dih, tg_sl) = match (r.tg_slivers_forced, r.tg_slivers_unforced) {
            (Some(fo), Some(un)) => (
                r.tg_tets.to_string(),
                format!("{:.2}", r.tg_min_dihedral),
                format!("{fo}/{un}"),
            ),
            _ => ("-".into(), "-".into(), "-".into()),
        };
        println!(
            "{:<22} {:>6} {:>9.2} {:>8} {:>7} {:>7.2} {:>8.3} {:>9} {:>7.2} {:>6.1} {:>7} {:>7} {:>10}",
            r.name,
            r.triangles,
            r.ct_secs,
            r.ct_outcome,
            r.tets,
            r.min_dihedral,
            r.min_jac,
            sl,
            r.tg_secs,
            r.ct_secs / r.tg_secs.max(1e-3),
            tg_tets,
            tg_dih,
            tg_sl
        );
        if have_tetgen && !r.tg_ok {
            println!("  (TetGen failed on {name})");
        }
        rows.push(r);
    }
    let ok = rows.iter().filter(|r| r.ct_outcome == "ok").count();
    let total_ct: f64 = rows.iter().map(|r| r.ct_secs).sum();
    let total_tg: f64 = rows.iter().map(|r| r.tg_secs).sum();
    let worst = worst_ratio(rows.iter());
    // Where TetGen failed, its time is no reference: the worst ratio over the surfaces it
    // meshed too.
    let worst_tg = worst_ratio(rows.iter().filter(|r| r.tg_ok));
    let unforced: u64 = rows.iter().filter_map(|r| r.slivers_unforced).sum();
    let tg_unforced: usize = rows.iter().filter_map(|r| r.tg_slivers_unforced).sum();
    if !have_tetgen {
        println!(
            "meshed {ok} of {}; total {total_ct:.1} s; unforced slivers {unforced}",
            rows.len()
        );
    } else {
        println!(
        "meshed {ok} of {}; total {total_ct:.1} s vs TetGen {total_tg:.1} s (ratio {:.1}, target <= 3); \
         worst time / (10 x TetGen + 0.5 s) = {:.2} ({}; target <= 1), {:.2} ({}) where TetGen \
         meshed; unforced slivers {unforced} (TetGen's meshes: {tg_unforced})",
        rows.len(),
        total_ct / total_tg.max(1e-3),
        worst.0,
        worst.1,
        worst_tg.0,
        worst_tg.1
    );
    }
    if let Some(j) = a.json {
        std::fs::write(&j, serde_json::to_string_pretty(&rows).unwrap()).expect("json");
    }
    let _ = std::fs::remove_dir_all(&tmp);
}

/// The corners of a surface as ASCII OFF, with round-trip coordinates.
fn write_off(s: &curvetet::Surface, off: &Path) {
    std::fs::write(off, common::linear_off(s)).expect("off");
}
