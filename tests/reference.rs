//! Reference validation: curvetet against Debian's TetGen (`tetgen -pYQ`) and CGAL Mesh_3 on
//! every benchmark surface (tests/data, copies of ../shared/data).
//!
//! Per surface: curvetet's command-line tool meshes `NAME_p2.msh`; TetGen and a small CGAL
//! Mesh_3 program (tests/reference/cgal_mesh3.cpp, compiled once and cached under
//! target/tmp) mesh the linear twin `NAME_lin.off`. All three outputs are read back from
//! their files and checked by `compare` — its own readers and checks, not curvetet's:
//!
//! - conformity: no flat, inverted or duplicate tet; every interior face in exactly two
//!   tets with opposite orientations; curvetet's boundary == the P2 input triangles (corners
//!   and mid nodes, by exact coordinates and orientation) and TetGen's boundary == the
//!   linear input triangles (exact coordinates, -Y keeps them); the linear twin's corners
//!   == the P2 input's to 1e-15 relative (the .msh files carry 16 digits, the .off 17);
//! - volume: curvetet's straight-sided volume == TetGen's == the volume enclosed by the
//!   linear surface, to 1e-12 relative; curvetet's curved volume == the volume enclosed by
//!   the P2 surface (computed here exactly) to 1e-9 relative and within 1e-4 of the
//!   analytic/CAD volume of ../shared/data/README.md (screw: 5e-4, see `SURFACES`); CGAL's
//!   volume within area × facet distance of the linear volume (see `cgal_tolerance`);
//! - the side-by-side table: tets, volume, min dihedral angle, max equiangular skewness
//!   (paper eq. 2, of the straight-sided tets) and wall time per tool, written straight to
//!   stderr so it shows without `--nocapture`, and as JSON to target/tmp/reference/.
//!
//! Requires `tetgen`, `g++` and libcgal-dev + libgmp-dev + libmpfr-dev (scripts/install-deps
//! installs them); a missing tool is a failure, not a skip.

#[path = "reference/compare.rs"]
mod compare;

use compare::{Mesh, Surf};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;
use std::time::{Duration, Instant};

/// (name, V_p2 of the data README, analytic or CAD volume, tolerance of the curved volume
/// against it (relative), what that volume is).
///
/// The 1e-4 tolerance is the README's: the P2 surfaces themselves are within ~4e-5 of the
/// exact volumes. The screw's P2 surface (h = 4 mm, deliberately coarse) encloses 2.96e-4
/// less than its CAD solid, so no mesh of that surface can be within 1e-4; it gets 5e-4.
const SURFACES: [(&str, f64, f64, f64, &str); 6] = [
    ("sphere", 4.188659268, 4.188790205, 1e-4, "4/3 pi"),
    ("torus", 2.417959847, 2.418053078, 1e-4, "2 pi^2 R r^2"),
    ("tube", 4.71240098, 4.71238898, 1e-4, "1.5 pi"),
    ("lv", 3234.7592, 3234.734353, 1e-4, "truncated ellipsoids"),
    ("screw", 3787.149008, 3788.270593, 5e-4, "CAD (OCC)"),
    ("hinge", 6336.122621, 6336.38286, 1e-4, "STL facets"),
];

/// Surfaces curvetet is known not to mesh yet, with the reason. For these a failure of
/// the meshing step itself is reported (with curvetet's message) instead of failing the
/// test; TetGen and CGAL are still checked, and if curvetet does produce a mesh every check
/// applies to it. Remove the entry when the surface meshes.
const KNOWN_CURVETET_FAILURES: [(&str, &str); 1] = [(
    "hinge",
    "no valid mesh of the genus-5 hinge yet: the front did not close (before main 29e154d), \
     now it closes but 41 tets fail certification; the lead is fixing the front",
)];

/// Wall-clock limit per tool run, so a stuck front fails instead of hanging the suite.
const TIME_LIMIT: Duration = Duration::from_secs(600);

fn data(file: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(file)
}

fn work_dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("reference")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Runs `cmd` with a time limit: Ok((stderr, wall seconds)) on success, else Err(what
/// failed, with the tail of its output).
fn run(mut cmd: Command, what: &str) -> Result<(String, f64), String> {
    let t0 = Instant::now();
    let mut child = cmd
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .map_err(|e| format!("{what}: cannot start: {e}"))?;
    // Drain the pipes on threads so a chatty child cannot block.
    let mut out = child.stdout.take().unwrap();
    let mut err = child.stderr.take().unwrap();
    let to = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = std::io::Read::read_to_string(&mut out, &mut s);
        s
    });
    let te = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = std::io::Read::read_to_string(&mut err, &mut s);
        s
    });
    let status = loop {
        if let Some(s) = child.try_wait().map_err(|e| e.to_string())? {
            break s;
        }
        if t0.elapsed() > TIME_LIMIT {
            let _ = child.kill();
            let _ = child.wait();
            return Err(format!("{what}: killed after {TIME_LIMIT:?}"));
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let secs = t0.elapsed().as_secs_f64();
    let (o, e) = (to.join().unwrap(), te.join().unwrap());
    if status.success() {
        Ok((e, secs))
    } else {
        let tail: Vec<&str> = o.lines().chain(e.lines()).collect();
        let tail = tail[tail.len().saturating_sub(15)..].join("\n");
        Err(format!("{what}: {status}\n{tail}"))
    }
}

/// The CGAL program, compiled once per source text and cached under target/tmp.
fn cgal_program() -> Result<PathBuf, String> {
    static BIN: OnceLock<Result<PathBuf, String>> = OnceLock::new();
    BIN.get_or_init(|| {
        let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/reference/cgal_mesh3.cpp");
        let text = std::fs::read(&src).map_err(|e| format!("{}: {e}", src.display()))?;
        let args = [
            "-O2",
            "-std=c++17",
            "-frounding-math",
            "-DCGAL_NDEBUG",
            "-DNDEBUG",
        ];
        let libs = ["-lgmp", "-lmpfr"];
        // FNV-1a of source, flags, compiler version and CGAL version: the cache key.
        let gxx = Command::new("g++")
            .arg("-dumpfullversion")
            .output()
            .map(|o| o.stdout)
            .unwrap_or_default();
        let cgal = std::fs::read("/usr/include/CGAL/version.h").unwrap_or_default();
        let mut h: u64 = 0xcbf29ce484222325;
        for b in text
            .iter()
            .chain(args.concat().as_bytes())
            .chain(&gxx)
            .chain(&cgal)
        {
            h = (h ^ u64::from(*b)).wrapping_mul(0x100000001b3);
        }
        let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("reference-bin");
        std::fs::create_dir_all(&dir).unwrap();
        let bin = dir.join(format!("cgal_mesh3-{h:016x}"));
        if bin.exists() {
            return Ok(bin);
        }
        let tmp = dir.join(format!("cgal_mesh3-{h:016x}.tmp{}", std::process::id()));
        let mut cmd = Command::new("g++");
        cmd.args(args).arg(&src).arg("-o").arg(&tmp).args(libs);
        let mut w = std::io::stderr();
        let _ = writeln!(
            w,
            "reference: compiling {} (CGAL, once; ~1 min)",
            src.display()
        );
        run(
            cmd,
            "g++ (CGAL Mesh_3 program; needs libcgal-dev libgmp-dev libmpfr-dev)",
        )?;
        std::fs::rename(&tmp, &bin).map_err(|e| e.to_string())?;
        Ok(bin)
    })
    .clone()
}

/// One tool's result on one surface.
#[derive(Default)]
struct Row {
    tool: &'static str,
    tets: usize,
    nodes: usize,
    volume: f64,
    curved_volume: Option<f64>,
    min_dihedral: f64,
    max_skew: f64,
    frac_skew_09: f64,
    min_sj: Option<f64>,
    secs: f64,
    note: String,
}

impl Row {
    fn measure(tool: &'static str, m: &Mesh, secs: f64) -> Row {
        let (min_dihedral, max_skew, frac_skew_09) = compare::linear_quality(m);
        let (curved_volume, min_sj) = if m.mids.is_empty() {
            (None, None)
        } else {
            let (v, q) = compare::curved_volume(m);
            (Some(v), Some(q))
        };
        Row {
            tool,
            tets: m.tets.len(),
            nodes: m.nodes.len(),
            volume: compare::linear_volume(m),
            curved_volume,
            min_dihedral,
            max_skew,
            frac_skew_09,
            min_sj,
            secs,
            note: String::new(),
        }
    }

    fn line(&self) -> String {
        if self.tets == 0 {
            return format!("  {:<9} {}", self.tool, self.note);
        }
        format!(
            "  {:<9} {:>7} {:>7} {:>16.10} {:>16} {:>8.2} {:>7.3} {:>8.4} {:>7} {:>7.2}s {}",
            self.tool,
            self.tets,
            self.nodes,
            self.volume,
            self.curved_volume
                .map_or("-".to_string(), |v| format!("{v:.10}")),
            self.min_dihedral,
            self.max_skew,
            self.frac_skew_09 * 100.0,
            self.min_sj.map_or("-".to_string(), |v| format!("{v:.3}")),
            self.secs,
            self.note
        )
    }

    fn json(&self) -> String {
        let opt = |v: Option<f64>| v.map_or("null".to_string(), |v| format!("{v:e}"));
        format!(
            "{{\"tool\":\"{}\",\"tets\":{},\"nodes\":{},\"volume_linear\":{:e},\"volume_curved\":{},\"min_dihedral_deg\":{:e},\"max_skewness\":{:e},\"frac_skewness_gt_0.9\":{:e},\"min_scaled_jacobian_sampled\":{},\"seconds\":{:e},\"note\":{:?}}}",
            self.tool,
            self.tets,
            self.nodes,
            self.volume,
            opt(self.curved_volume),
            self.min_dihedral,
            self.max_skew,
            self.frac_skew_09,
            opt(self.min_sj),
            self.secs,
            self.note
        )
    }
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// CGAL Mesh_3 approximates the surface: its boundary vertices lie on the input surface and
/// the facet-distance criterion bounds how far its facets stray from it (the program uses
/// d = h/10). The volume between the two surfaces is then at most about area × d: that is
/// the tolerance on |V_cgal - V_lin|.
fn cgal_tolerance(area: f64, h: f64) -> f64 {
    area * h / 10.0
}

/// Everything for one surface; returns the failures (empty when all checks pass).
fn reference(name: &str) -> Vec<String> {
    let (_, v_p2_readme, v_exact, exact_tol, exact_what) =
        *SURFACES.iter().find(|s| s.0 == name).unwrap();
    let known = KNOWN_CURVETET_FAILURES
        .iter()
        .find(|k| k.0 == name)
        .map(|k| k.1);
    let dir = work_dir(name);
    let mut fail: Vec<String> = Vec::new();
    let mut rows: Vec<Row> = Vec::new();
    let mut notes: Vec<String> = Vec::new();

    // The inputs, read independently.
    let p2 = compare::read_msh41_surface(&data(&format!("{name}_p2.msh"))).unwrap();
    let lin = compare::read_off(&data(&format!("{name}_lin.off"))).unwrap();
    let v_lin = compare::surface_volume_linear(&lin);
    let v_p2 = compare::surface_volume_p2(&p2);
    let area = compare::surface_area(&lin);
    let h = compare::mean_edge(&lin);
    // The twins are the same triangles: the linear surface is the P2 one's corners (the
    // .msh files carry 16 significant digits, the .off files 17: equal to 1e-15 relative).
    match compare::twins_match(&p2, &lin, 1e-15) {
        Ok(d) => notes.push(format!(
            "NOTE {name}: {name}_lin.off == corners of {name}_p2.msh up to {d:.1e} relative"
        )),
        Err(e) => fail.push(format!(
            "{name}_lin.off is not the corners of {name}_p2.msh: {e}"
        )),
    }
    if rel(v_p2, v_p2_readme) > 2e-8 {
        fail.push(format!(
            "V_p2 computed here {v_p2} vs data README {v_p2_readme} (rel {:.1e})",
            rel(v_p2, v_p2_readme)
        ));
    }
    let corners = Surf {
        nodes: p2.nodes.clone(),
        tris: p2.tris.clone(),
        mids: Vec::new(),
    };
    // curvetet's straight-sided volume is compared with its own input's corners.
    let v_lin_p2 = compare::surface_volume_linear(&corners);
    if rel(v_lin_p2, v_lin) > 1e-13 {
        fail.push("linear volumes of the twins differ".into());
    }

    // curvetet, through its command-line tool, read back from the .msh it writes.
    let out = dir.join("curvetet.msh");
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_curvetet"));
    cmd.arg("mesh")
        .arg(data(&format!("{name}_p2.msh")))
        .arg("-q")
        .arg("-o")
        .arg(&out)
        .arg("--report")
        .arg(dir.join("curvetet_report.json"));
    match run(cmd, "curvetet mesh") {
        Ok((_, secs)) => {
            let m = compare::read_msh41(&out).unwrap_or_else(|e| panic!("{e}"));
            let mut row = Row::measure("curvetet", &m, secs);
            if m.mids.is_empty() {
                fail.push("curvetet: the output has no 10-node tets".into());
            }
            match compare::conformity(&m, Some(1)) {
                Err(e) => fail.push(format!("curvetet conformity: {e}")),
                Ok(c) => {
                    if let Err(e) = compare::boundary_matches(&m, &c, &p2) {
                        fail.push(format!("curvetet boundary != input: {e}"));
                    }
                    if let Err((x, y)) = compare::file_boundary_consistent(&m, &c) {
                        fail.push(format!(
                            "curvetet's triangles: {x} are not boundary faces, {y} boundary faces not listed"
                        ));
                    }
                }
            }
            if rel(row.volume, v_lin_p2) > 1e-12 {
                fail.push(format!(
                    "curvetet linear volume {} vs V_lin {v_lin_p2} (rel {:.1e} > 1e-12)",
                    row.volume,
                    rel(row.volume, v_lin_p2)
                ));
            }
            if let Some(vc) = row.curved_volume {
                if rel(vc, v_p2) > 1e-9 {
                    fail.push(format!(
                        "curvetet curved volume {vc} vs V_p2 {v_p2} (rel {:.1e} > 1e-9)",
                        rel(vc, v_p2)
                    ));
                }
                if rel(vc, v_exact) > exact_tol {
                    fail.push(format!(
                        "curvetet curved volume {vc} vs {exact_what} {v_exact} (rel {:.1e} > {exact_tol:e})",
                        rel(vc, v_exact)
                    ));
                }
                row.note = format!("curved vs {exact_what}: {:.1e}", rel(vc, v_exact));
            }
            if let Some(reason) = known {
                notes.push(format!(
                    "NOTE {name}: listed as a known curvetet failure ({reason}) but it meshed: \
                     remove it from KNOWN_CURVETET_FAILURES"
                ));
            }
            rows.push(row);
        }
        Err(e) => {
            let first = e.lines().next().unwrap_or("").to_string();
            let last = e.lines().last().unwrap_or("").to_string();
            match known {
                Some(reason) => {
                    notes.push(format!(
                        "NOTE {name}: KNOWN FAILURE of curvetet ({reason}): {first} / {last}"
                    ));
                    rows.push(Row {
                        tool: "curvetet",
                        note: format!("KNOWN FAILURE: {last}"),
                        ..Row::default()
                    });
                }
                None => {
                    fail.push(format!("curvetet failed: {e}"));
                    rows.push(Row {
                        tool: "curvetet",
                        note: format!("FAILED: {last}"),
                        ..Row::default()
                    });
                }
            }
        }
    }

    // TetGen 1.5 (Debian): -p PLC, -Y keep boundary, -Q quiet, -z 0-based. It writes next to
    // its input and rejects OFF comments: copy the input into the work directory.
    let off = dir.join(format!("{name}.off"));
    std::fs::copy(data(&format!("{name}_lin.off")), &off).unwrap();
    let mut cmd = Command::new("tetgen");
    cmd.arg("-pYQz").arg(&off);
    match run(cmd, "tetgen -pYQz (install: apt-get install tetgen)") {
        Err(e) => {
            fail.push(format!("tetgen failed: {e}"));
            rows.push(Row {
                tool: "tetgen",
                note: "FAILED".into(),
                ..Row::default()
            });
        }
        Ok((_, secs)) => match compare::read_tetgen(&dir.join(format!("{name}.1"))) {
            Err(e) => fail.push(format!("tetgen output: {e}")),
            Ok(m) => {
                let mut row = Row::measure("tetgen", &m, secs);
                // TetGen 1.5's .ele tets are right-handed (positive volume).
                match compare::conformity(&m, Some(1)) {
                    Err(e) => fail.push(format!("tetgen conformity: {e}")),
                    Ok(c) => {
                        if let Err(e) = compare::boundary_matches(&m, &c, &lin) {
                            fail.push(format!("tetgen boundary != input: {e}"));
                        }
                        if let Err((x, y)) = compare::file_boundary_consistent(&m, &c) {
                            fail.push(format!(
                                "tetgen .face: {x} are not boundary faces, {y} boundary faces not listed"
                            ));
                        }
                        row.note = format!(
                            "{}-handed tets",
                            if c.orientation > 0 { "right" } else { "left" }
                        );
                    }
                }
                row.volume = row.volume.abs();
                if rel(row.volume, v_lin) > 1e-12 {
                    fail.push(format!(
                        "tetgen volume {} vs V_lin {v_lin} (rel {:.1e} > 1e-12)",
                        row.volume,
                        rel(row.volume, v_lin)
                    ));
                }
                rows.push(row);
            }
        },
    }

    // CGAL Mesh_3 at the surface's mean edge length.
    match cgal_program() {
        Err(e) => fail.push(format!("CGAL program: {e}")),
        Ok(bin) => {
            let out = dir.join("cgal.mesh");
            let mut cmd = Command::new(bin);
            cmd.arg(data(&format!("{name}_lin.off")))
                .arg(&out)
                .arg(format!("{h}"));
            match run(cmd, "cgal_mesh3") {
                Err(e) => fail.push(format!("CGAL failed: {e}")),
                Ok((_, secs)) => match compare::read_medit(&out) {
                    Err(e) => fail.push(format!("CGAL output: {e}")),
                    Ok(m) => {
                        let mut row = Row::measure("cgal", &m, secs);
                        // CGAL's cells are right-handed (positive orientation).
                        match compare::conformity(&m, Some(1)) {
                            Err(e) => fail.push(format!("CGAL conformity: {e}")),
                            Ok(c) => {
                                // Not a failure: Mesh_3's surface facets (the medit
                                // Triangles) approximate the boundary of its cells and can
                                // differ from it by a few facets; reported.
                                if let Err((x, y)) = compare::file_boundary_consistent(&m, &c) {
                                    notes.push(format!(
                                        "NOTE {name}: CGAL lists {x} surface facets that are not \
                                         boundary faces of its tets; {y} boundary faces unlisted"
                                    ));
                                }
                                row.volume = row.volume.abs();
                                row.note = format!(
                                    "{}-handed tets; ",
                                    if c.orientation > 0 { "right" } else { "left" }
                                );
                            }
                        }
                        let tol = cgal_tolerance(area, h);
                        let d = (row.volume - v_lin).abs();
                        row.note += &format!(
                            "|V-V_lin| = {:.1e} rel, tolerance {:.1e}",
                            d / v_lin,
                            tol / v_lin
                        );
                        if d > tol {
                            fail.push(format!(
                                "CGAL volume {} vs V_lin {v_lin}: off by {d:e} > area*h/10 = {tol:e}",
                                row.volume
                            ));
                        }
                        rows.push(row);
                    }
                },
            }
        }
    }

    // The table block for this surface, written in one piece straight to stderr.
    let mut s = format!(
        "\n== {name}: {} P2 triangles, h = {h:.4}, V_lin = {v_lin:.10}, V_p2 = {v_p2:.10}, {exact_what} = {v_exact}\n  \
         {:<9} {:>7} {:>7} {:>16} {:>16} {:>8} {:>7} {:>8} {:>7} {:>8}\n",
        p2.tris.len(),
        "tool",
        "tets",
        "nodes",
        "V straight",
        "V curved",
        "min dih",
        "max sk",
        "%sk>0.9",
        "min SJ",
        "time"
    );
    for r in &rows {
        s += &r.line();
        s.push('\n');
    }
    for n in &notes {
        s += n;
        s.push('\n');
    }
    for f in &fail {
        s += &format!("  FAIL {name}: {f}\n");
    }
    let _ = std::io::stderr().write_all(s.as_bytes());
    let json = format!(
        "{{\"surface\":\"{name}\",\"v_lin\":{v_lin:e},\"v_p2\":{v_p2:e},\"v_reference\":{v_exact:e},\"rows\":[{}],\"failures\":{:?}}}\n",
        rows.iter().map(Row::json).collect::<Vec<_>>().join(","),
        fail
    );
    let _ = std::fs::write(
        Path::new(env!("CARGO_TARGET_TMPDIR"))
            .join("reference")
            .join(format!("{name}.json")),
        json,
    );
    fail
}

fn check(name: &str) {
    let fail = reference(name);
    assert!(fail.is_empty(), "{name}: {}", fail.join("\n"));
}

#[test]
fn reference_sphere() {
    check("sphere");
}

#[test]
fn reference_torus() {
    check("torus");
}

#[test]
fn reference_tube() {
    check("tube");
}

#[test]
fn reference_lv() {
    check("lv");
}

#[test]
fn reference_screw() {
    check("screw");
}

#[test]
fn reference_hinge() {
    check("hinge");
}

/// The checks themselves catch what they should: a flipped tet, a missing tet (a hole:
/// faces shared by one tet that are not input triangles), and a moved boundary node.
#[test]
fn reference_checks_catch_defects() {
    let lin = compare::read_off(&data("sphere_lin.off")).unwrap();
    let dir = work_dir("selftest");
    let off = dir.join("s.off");
    std::fs::copy(data("sphere_lin.off"), &off).unwrap();
    let mut cmd = Command::new("tetgen");
    cmd.arg("-pYQz").arg(&off);
    run(cmd, "tetgen").unwrap();
    let m = compare::read_tetgen(&dir.join("s.1")).unwrap();
    let c = compare::conformity(&m, None).unwrap();
    compare::boundary_matches(&m, &c, &lin).unwrap();

    let mut flipped = Mesh {
        nodes: m.nodes.clone(),
        tets: m.tets.clone(),
        ..Mesh::default()
    };
    flipped.tets[7].swap(0, 1);
    assert!(compare::conformity(&flipped, None).is_err());

    let mut holed = Mesh {
        nodes: m.nodes.clone(),
        tets: m.tets.clone(),
        ..Mesh::default()
    };
    holed.tets.remove(m.tets.len() / 2);
    let c = compare::conformity(&holed, None).unwrap();
    assert!(compare::boundary_matches(&holed, &c, &lin).is_err());

    let mut dup = Mesh {
        nodes: m.nodes.clone(),
        tets: m.tets.clone(),
        ..Mesh::default()
    };
    dup.tets.push(m.tets[3]);
    assert!(compare::conformity(&dup, None).is_err());

    let mut moved = Mesh {
        nodes: m.nodes.clone(),
        tets: m.tets.clone(),
        ..Mesh::default()
    };
    let v = lin.tris[0][0];
    moved.nodes[v][0] = f64::from_bits(moved.nodes[v][0].to_bits() + 1);
    let c = compare::conformity(&moved, None).unwrap();
    assert!(compare::boundary_matches(&moved, &c, &lin).is_err());
}
