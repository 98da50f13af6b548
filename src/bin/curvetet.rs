//! `curvetet`: the command-line tool. Messages go to stderr, results to stdout; the exit
//! code is 0 only on success.

use clap::{Args, Parser, Subcommand};
use curvetet::geom::quadrature::{enclosed_volume, enclosed_volume_linear};
use curvetet::io::{self, MshVersion, WriteOptions};
use curvetet::mesh::report::QualityReport;
use curvetet::mesh::{check, TetMesh};
use curvetet::surface::curve::{curve_linear_report, CurveOptions, CurveReport};
use curvetet::surface::geometry::{
    triangle_shape, ELONGATED_MEDIAN_ASPECT_RATIO, POOR_ASPECT_RATIO,
};
use curvetet::surface::Repair;
use curvetet::{
    Error, Generated, MeshInput, Options, RegionMode, Regions, SizeFrom, SizeMode, Surface,
};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// The exit codes, shown by `--help` and in docs/cli.md.
const EXIT_CODES: &str = "\
Exit codes:
  0  success
  1  usage error: unknown or bad option or argument, output equal to the input, ...
  2  I/O error: a file cannot be read or written (missing, not a regular file, full disk)
  3  malformed input file (the message gives file:line or byte offset)
  4  invalid surface (not closed, self-intersecting, ...; the message names the element)
  5  meshing failed
  6  the mesh failed its final check (a bug: please report it); `check`: invalid mesh
  7  cancelled
Outputs are written to a temporary file beside the target and renamed over it when
complete: a failed or interrupted run never leaves a partial file under the output's name.";

#[derive(Parser)]
#[command(
    name = "curvetet",
    version,
    after_help = EXIT_CODES,
    about = "Quadratic (10-node) curved tetrahedral meshes, directly from a closed quadratic (6-node) triangle surface"
)]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Mesh a closed surface into a P2 tet mesh: a P2 surface (.msh, .vtu, .vtk, .mesh), or
    /// a linear one (.stl, .off, .obj, .ply, or 3-node triangles), which is curved first.
    Mesh(MeshArgs),
    /// Curve a closed linear triangle surface (.stl, .off, .obj, .ply, ...) into a P2
    /// surface and write it (.msh, .vtu, .vtk, .mesh).
    Curve {
        /// Input linear surface.
        input: PathBuf,
        /// Output P2 surface.
        #[arg(short, long)]
        output: PathBuf,
        #[command(flatten)]
        curve: CurveArgs,
        #[command(flatten)]
        write: WriteArgs,
    },
    /// Check a surface (P2 or linear) or a volume mesh and print its report.
    Check {
        /// The file to check.
        file: PathBuf,
        /// Print the report as JSON.
        #[arg(long)]
        json: bool,
        /// Draw the scaled-Jacobian and skewness histograms of a volume mesh as SVG here.
        #[arg(long)]
        plot: Option<PathBuf>,
        /// For a surface: take a closed shell nested in another as an inner region, not a
        /// cavity (as `mesh --nested-regions`)
        #[arg(long)]
        nested_regions: bool,
        #[command(flatten)]
        curve: CurveArgs,
    },
    /// Convert a mesh between formats (by extension: .msh .vtu .vtk .mesh).
    Convert {
        /// Input file.
        input: PathBuf,
        /// Output file.
        output: PathBuf,
        #[command(flatten)]
        write: WriteArgs,
    },
    /// The built-in example: a P2 torus surface built analytically, meshed.
    Demo {
        /// Where to write the volume mesh.
        #[arg(short, long, default_value = "demo_torus.msh")]
        output: PathBuf,
        /// Also write the P2 surface here.
        #[arg(long)]
        surface: Option<PathBuf>,
        /// Only build and write the surface (to --output), do not mesh.
        #[arg(long)]
        surface_only: bool,
        /// Approximate number of surface triangles.
        #[arg(long, default_value_t = 1728)]
        triangles: usize,
        #[command(flatten)]
        mesh: MeshOptions,
    },
}

#[derive(Args)]
struct MeshArgs {
    /// Input surface.
    input: PathBuf,
    /// Output volume mesh (.msh, .vtu, .vtk, .mesh).
    #[arg(short, long)]
    output: PathBuf,
    #[command(flatten)]
    curve: CurveArgs,
    #[command(flatten)]
    mesh: MeshOptions,
    /// Refuse early, with a clear error, an input that would need more memory than this
    /// (bytes, or with a K, M, G or T suffix, powers of 1024): checked on the file size
    /// before reading and on an estimate of the meshing peak before meshing. Default: the
    /// memory available when the run starts
    #[arg(long, value_parser = parse_bytes)]
    max_memory: Option<u64>,
    /// Take a closed shell nested in another as the boundary of an inner region to mesh
    /// too, not as a cavity (several regions are found without it where the triangles
    /// meet at junction edges: an interface between two regions given once)
    #[arg(long)]
    nested_regions: bool,
}

/// `123`, `64K`, `500M`, `4G`, `1T` (powers of 1024; a trailing `B`/`iB` is allowed).
fn parse_bytes(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let t = t
        .strip_suffix("iB")
        .or_else(|| t.strip_suffix('B'))
        .unwrap_or(t);
    let (num, mult) = match t.char_indices().last() {
        Some((i, c)) if c.is_ascii_alphabetic() => {
            let m: u64 = match c.to_ascii_uppercase() {
                'K' => 1 << 10,
                'M' => 1 << 20,
                'G' => 1 << 30,
                'T' => 1 << 40,
                _ => return Err(format!("unknown size suffix in {s:?} (use K, M, G or T)")),
            };
            (&t[..i], m)
        }
        _ => (t, 1),
    };
    let v: f64 = num
        .trim()
        .parse()
        .map_err(|_| format!("not a memory size: {s:?} (e.g. 4G, 500M)"))?;
    if !(v.is_finite() && v > 0.0) {
        return Err(format!("the memory size must be > 0 (got {s:?})"));
    }
    Ok((v * mult as f64).min(u64::MAX as f64) as u64)
}

/// The memory the system can give without swapping (Linux's `MemAvailable`), if known.
fn available_memory() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib.saturating_mul(1024))
}

fn mib(b: u64) -> String {
    format!("{:.1} MiB", b as f64 / (1u64 << 20) as f64)
}

#[derive(Args)]
struct CurveArgs {
    /// For a linear input surface: edges whose triangles' normals differ by more than this
    /// angle (degrees) are sharp features, kept sharp and followed by the curving.
    #[arg(long, default_value_t = 40.0)]
    feature_angle: f64,
    /// For a linear input surface: Taubin-smooth its vertices with this many iterations
    /// before curving. For surfaces from image segmentation (marching cubes), whose needle
    /// and cap triangles leave the front stuck: 10 makes them well shaped. Moves the
    /// surface (by a fraction of a voxel) and rounds sharp edges. At most 1000
    #[arg(long, default_value_t = 0)]
    smooth: u32,
    /// Refuse a surface with inconsistently oriented triangles or unused vertices (by
    /// default they are reoriented or dropped, with a warning)
    #[arg(long)]
    strict: bool,
}

impl CurveArgs {
    fn options(&self) -> CurveOptions {
        CurveOptions::default()
            .with_feature_angle_deg(self.feature_angle)
            .with_smooth_iterations(self.smooth)
            .with_repair(self.repair())
    }

    fn repair(&self) -> Repair {
        if self.strict {
            Repair::Strict
        } else {
            Repair::Unambiguous
        }
    }
}

#[derive(Args)]
struct MeshOptions {
    /// Search radius factor: candidates within ALPHA * h of the ideal point.
    #[arg(long, default_value_t = 1.5)]
    alpha: f64,
    /// Uniform target edge length (default: graded from the boundary triangles).
    #[arg(long)]
    size: Option<f64>,
    /// The paper's uniform size from the mean curved triangle area (eq. 1).
    #[arg(long, conflicts_with = "size")]
    uniform_size: bool,
    /// What the graded size measures at each surface vertex: its mean edge length
    /// (edges), the equilateral edge of its triangles' mean area (areas: smaller on
    /// elongated triangles, where edge sizes can leave the front stuck), or areas when
    /// most triangles are elongated, else edges (auto)
    #[arg(long, value_enum, default_value_t = SizeFromArg::Auto, conflicts_with_all = ["size", "uniform_size"])]
    size_from: SizeFromArg,
    /// Growth rate of the graded size: sizes grow by at most this fraction of the
    /// distance from the boundary (larger: fewer tets inside; smaller: a smoother field)
    #[arg(long, default_value_t = Options::default().gradation, conflicts_with_all = ["size", "uniform_size"])]
    gradation: f64,
    /// Skip quality improvement and high-order optimization.
    #[arg(long)]
    no_optimize: bool,
    /// More high-order rounds where some element starts poor (CAD parts such as the
    /// screw): two to three times that stage's work, for fewer elements left between the
    /// worst one and min J / max J 0.85; the worst is about as good either way
    #[arg(long, conflicts_with = "no_optimize")]
    thorough: bool,
    /// Worker threads (0 = all cores; at most 4 per CPU and at most 1024); the result does
    /// not depend on it.
    #[arg(long, default_value_t = 0)]
    threads: usize,
    /// Write the quality report as JSON here.
    #[arg(long)]
    report: Option<PathBuf>,
    /// Draw the scaled-Jacobian and skewness histograms as SVG here.
    #[arg(long)]
    plot: Option<PathBuf>,
    /// On failure, write what was meshed anyway (for debugging).
    #[arg(long)]
    keep_partial: bool,
    /// No progress bar.
    #[arg(short, long)]
    quiet: bool,
    #[command(flatten)]
    write: WriteArgs,
}

/// [`SizeFrom`] on the command line.
#[derive(Clone, Copy, clap::ValueEnum)]
enum SizeFromArg {
    Auto,
    Edges,
    Areas,
}

#[derive(Args)]
struct WriteArgs {
    /// Write Gmsh MSH 2.2 instead of 4.1.
    #[arg(long)]
    msh22: bool,
    /// Write binary (.msh, or .vtu with base64 arrays; not available for .vtk and .mesh).
    #[arg(long)]
    binary: bool,
}

impl WriteArgs {
    fn options(&self) -> WriteOptions {
        WriteOptions::default()
            .with_msh_version(if self.msh22 {
                MshVersion::V22
            } else {
                MshVersion::V41
            })
            .with_binary(self.binary)
            // The VTK filter's per-tet quality arrays, in .vtu and .vtk meshes.
            .with_quality_arrays(true)
    }
}

impl MeshOptions {
    fn options(&self) -> Options {
        Options::default()
            .with_alpha(self.alpha)
            .with_size(match (self.size, self.uniform_size) {
                (Some(h), _) => SizeMode::Fixed(h),
                (None, true) => SizeMode::Uniform,
                (None, false) => SizeMode::Graded,
            })
            .with_size_from(match self.size_from {
                SizeFromArg::Auto => SizeFrom::Auto,
                SizeFromArg::Edges => SizeFrom::Edges,
                SizeFromArg::Areas => SizeFrom::Areas,
            })
            .with_gradation(self.gradation)
            .with_optimize(!self.no_optimize)
            .with_thorough(self.thorough)
            .with_threads(self.threads)
            // The command owns its process: keep each worker on its own CPU (see
            // curvetet::threads; CURVETET_PIN_THREADS=0 turns it off).
            .with_pin_threads(true)
    }
}

/// On SIGINT, SIGTERM or SIGHUP, remove the temporary files of the outputs being written
/// and end by that signal: an interrupted run leaves its outputs as they were. The
/// signals are blocked in every thread (the workers inherit it) and taken by one thread
/// that waits for them.
#[cfg(unix)]
fn clean_up_on_signals() {
    // SAFETY: plain libc signal-mask calls on a local, zero-initialised set.
    let set = unsafe {
        let mut set: libc::sigset_t = std::mem::zeroed();
        libc::sigemptyset(&mut set);
        for s in [libc::SIGINT, libc::SIGTERM, libc::SIGHUP] {
            libc::sigaddset(&mut set, s);
        }
        if libc::pthread_sigmask(libc::SIG_BLOCK, &set, std::ptr::null_mut()) != 0 {
            return;
        }
        set
    };
    std::thread::spawn(move || loop {
        let mut sig = 0;
        // SAFETY: waits on a valid set.
        if unsafe { libc::sigwait(&set, &mut sig) } != 0 {
            continue;
        }
        io::remove_unfinished_temporaries();
        // SAFETY: restore the default action and deliver the signal to this thread, which
        // ends the process as if the signal had not been caught.
        unsafe {
            libc::signal(sig, libc::SIG_DFL);
            libc::pthread_sigmask(libc::SIG_UNBLOCK, &set, std::ptr::null_mut());
            libc::raise(sig);
        }
    });
}

#[cfg(not(unix))]
fn clean_up_on_signals() {}

fn main() -> ExitCode {
    clean_up_on_signals();
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            // --help and --version print to stdout and succeed; a usage error exits 1.
            let _ = e.print();
            return if e.use_stderr() {
                ExitCode::from(1)
            } else {
                ExitCode::SUCCESS
            };
        }
    };
    let r = match cli.cmd {
        Cmd::Mesh(a) => cmd_mesh(&a),
        Cmd::Curve {
            input,
            output,
            curve,
            write,
        } => cmd_curve(&input, &output, &curve, &write),
        Cmd::Check {
            file,
            json,
            plot,
            nested_regions,
            curve,
        } => cmd_check(&file, json, plot.as_deref(), nested_regions, &curve),
        Cmd::Convert {
            input,
            output,
            write,
        } => cmd_convert(&input, &output, &write),
        Cmd::Demo {
            output,
            surface,
            surface_only,
            triangles,
            mesh,
        } => cmd_demo(&output, surface.as_deref(), surface_only, triangles, &mesh),
    };
    match r {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(exit_code(&e))
        }
    }
}

/// The exit codes ([`EXIT_CODES`]): the C ABI's status codes (1 to 7; its one mapping,
/// which matches every kind of error).
fn exit_code(e: &Error) -> u8 {
    curvetet::capi::curvetet_status::of(e) as u8
}

/// Print a line of results on stdout. A closed stdout (`curvetet check X | head -1`) is
/// not an error: the reader has what it wanted, and the exit code still tells the result.
macro_rules! say {
    ($($t:tt)*) => {
        stdout_line(format_args!($($t)*))
    };
}

fn stdout_line(args: std::fmt::Arguments) -> Result<(), Error> {
    use std::io::Write;
    match writeln!(std::io::stdout().lock(), "{args}") {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(Error::io("stdout", e)),
        _ => Ok(()),
    }
}

fn progress_bar(quiet: bool) -> ProgressBar {
    if quiet || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let pb = ProgressBar::with_draw_target(Some(1000), ProgressDrawTarget::stderr());
    pb.set_style(
        ProgressStyle::with_template("{msg:>8} [{bar:40}] {percent:>3}% {elapsed}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    pb
}

/// The options a mesh was made and written with, for `--report`.
fn options_json(o: &Options, w: &WriteOptions) -> serde_json::Value {
    serde_json::json!({
        "alpha": o.alpha,
        "size": o.size,
        "size_from": o.size_from,
        "gradation": o.gradation,
        "optimize": o.optimize,
        "thorough": o.thorough,
        "threads": o.threads,
        "min_dihedral_deg": o.min_dihedral_deg,
        "max_skewness": o.max_skewness,
        "min_edge_face_angle_deg": o.min_edge_face_angle_deg,
        "msh_version": w.msh_version.as_str(),
        "binary": w.binary,
    })
}

/// Where the surface came from and how long reading (and curving) it took, for
/// `--report`.
struct InputInfo {
    json: serde_json::Value,
    read_seconds: f64,
}

fn run_mesh(
    mesh_input: &MeshInput,
    m: &MeshOptions,
    output: &Path,
    input: InputInfo,
) -> Result<(), Error> {
    for w in mesh_input.warnings() {
        eprintln!("warning: {w}");
    }
    let opts = m.options();
    if let (SizeMode::Fixed(l), MeshInput::Surface(surface)) = (opts.size, mesh_input) {
        let most = curvetet::generate::supported_size(surface);
        if l > most {
            eprintln!(
                "warning: --size {l} is more than the boundary supports (twice its mean edge \
                 length); meshing with size {most:.6}"
            );
        }
    }
    let pb = progress_bar(m.quiet);
    let mut cb = |f: f64, stage: &str| {
        pb.set_message(stage.to_string());
        pb.set_position((f * 1000.0) as u64);
        false
    };
    if let MeshInput::Regions(r) = mesh_input {
        if !m.quiet {
            eprintln!(
                "{} regions: meshing each on its own boundary, into one conforming mesh",
                r.regions().len()
            );
        }
    }
    let r = curvetet::generate_input(mesh_input, &opts, &mut cb);
    pb.finish_and_clear();
    let g: Generated = match r {
        Ok(g) => g,
        Err(e) => {
            if m.keep_partial {
                let partial = match &e {
                    Error::MeshingFailed {
                        partial: Some(p), ..
                    } => Some(p),
                    Error::InvalidMesh { mesh: Some(p), .. } => Some(p),
                    _ => None,
                };
                if let Some(p) = partial {
                    io::write_mesh(output, p, &m.write.options())?;
                    eprintln!(
                        "wrote the partial mesh to {} (--keep-partial)",
                        output.display()
                    );
                }
            }
            return Err(e);
        }
    };
    if g.optimize.chords > 0 {
        eprintln!(
            "warning: {} boundary edges are straight (the input's own edges): no curved \
             element on them could be certified",
            g.optimize.chords
        );
    }
    let t = std::time::Instant::now();
    io::write_mesh(output, &g.mesh, &m.write.options())?;
    let write_seconds = t.elapsed().as_secs_f64();
    let r = &g.report;
    // Where front attempts were thrown away (a whole fill or a later attempt meshed),
    // how long they took: the part of the time that a better surface would save.
    let dropped = if g.front.discarded_seconds > 0.0 {
        format!(
            ", {:.3} s of it in attempts dropped",
            g.front.discarded_seconds
        )
    } else {
        String::new()
    };
    let fill = if g.front.whole_fill {
        "; whole fill"
    } else {
        ""
    };
    eprintln!(
        "{} tets, {} nodes in {:.3} s (front {:.3} s{dropped}{fill}); min scaled Jacobian {:.3} (certified {:.3}), max skewness {:.3}, dihedral {:.1}..{:.1} deg",
        r.num_tets,
        r.num_nodes,
        g.times.front + g.times.assemble + g.times.optimize + g.times.certify + g.times.size_field,
        g.times.front,
        r.quality.scaled_jacobian.min,
        r.quality.scaled_jacobian_certified.min,
        r.quality.skewness.max,
        r.quality.min_dihedral.min,
        r.quality.max_dihedral.max,
    );
    for x in &g.regions {
        eprintln!(
            "  region {} ({}): {} tets, volume {:.9}, min scaled Jacobian {:.3}",
            x.id,
            x.name,
            x.report.num_tets,
            x.report.volume_curved,
            x.report.quality.scaled_jacobian.min
        );
    }
    eprintln!("wrote {}", output.display());
    if let Some(p) = &m.plot {
        write_plot(p, r, &output.display().to_string())?;
    }
    if let Some(path) = &m.report {
        let mut times =
            serde_json::to_value(&g.times).map_err(|e| Error::InvalidArgument(e.to_string()))?;
        times["read"] = input.read_seconds.into();
        times["write"] = write_seconds.into();
        let mut json = serde_json::json!({
            "curvetet_version": env!("CARGO_PKG_VERSION"),
            "input": input.json,
            "output": output.display().to_string(),
            "options": options_json(&opts, &m.write.options()),
            "input_triangles": mesh_input.num_triangles(),
            "report": r,
            "front": g.front,
            "times": times,
            "optimize": g.optimize,
            "size": g.size,
            "size_from": g.size_from,
        });
        if !g.regions.is_empty() {
            json["regions"] = serde_json::to_value(&g.regions)
                .map_err(|e| Error::InvalidArgument(e.to_string()))?;
        }
        let text = serde_json::to_string_pretty(&json)
            .map_err(|e| Error::InvalidArgument(e.to_string()))?;
        io::write_atomic(path, |w| w.write_all(text.as_bytes()))?;
    }
    Ok(())
}

/// What `path` holds to mesh: several regions (see [`RegionMode`]), or one surface: P2
/// as it is, linear curved (with a summary on stderr).
fn read_input(path: &Path, c: &CurveArgs, mode: RegionMode) -> Result<MeshInput, Error> {
    let raw = io::read(path)?;
    let name = path.display().to_string();
    if MeshInput::several_regions(&raw, mode) {
        return MeshInput::from_raw(raw, &name, &c.options(), mode);
    }
    if !raw.tri6.is_empty() || raw.tri3.is_empty() {
        return io::surface_from_raw_with_repair(raw, &name, c.repair()).map(MeshInput::Surface);
    }
    let (s, r) = curve_raw(raw, &name, c)?;
    eprintln!("{}", curve_summary(&name, &s, &r));
    Ok(MeshInput::Surface(s))
}

/// Curves a linear surface read from a file.
fn curve_raw(raw: io::RawMesh, name: &str, c: &CurveArgs) -> Result<(Surface, CurveReport), Error> {
    if !raw.tet4.is_empty() || !raw.tet10.is_empty() {
        // Let the library say why (a linear volume mesh is not a surface).
        return io::surface_from_raw_any(raw, name, &c.options())
            .map(|s| (s, CurveReport::default()));
    }
    let groups = raw.groups();
    let (s, r) = curve_linear_report(raw.nodes, raw.tri3, raw.tri3_tags, &c.options())?;
    Ok((s.with_groups(groups), r))
}

fn curve_summary(name: &str, s: &Surface, r: &CurveReport) -> String {
    let corners = s.corner_nodes().len();
    format!(
        "{name}: linear surface, {corners} vertices, {} triangles: curved {} of {} edges \
         ({} feature edges, {} kept flat, {} straightened to avoid folds, {} to avoid \
         intersections); volume {:.9} (linear {:.9}), min cos(curved normal, chord normal) {:.4}",
        s.triangles().len(),
        r.curved_edges,
        r.edges,
        r.feature_edges,
        r.flat_edges,
        r.straightened.fold,
        r.straightened.intersection,
        s.volume(),
        s.chord_volume(),
        s.min_normal_cosine()
    )
}

/// Everything about a command's outputs that can be checked before reading its input, so
/// that a bad request fails at once and no input is ever overwritten: each mesh output
/// is a format curvetet writes with these write options; each output's directory exists
/// and takes new files; no output is the input (also through a link) or another output.
fn check_outputs(
    input: Option<&Path>,
    meshes: &[&Path],
    others: &[&Path],
    w: &WriteOptions,
) -> Result<(), Error> {
    for &m in meshes {
        let f = io::Format::from_path(m)?;
        if !f.is_writable() {
            return Err(Error::InvalidArgument(format!(
                "{}: .{} is read only; write .msh, .vtu, .vtk or .mesh",
                m.display(),
                f.extension()
            )));
        }
        io::check_write_options(f, w)
            .map_err(|e| Error::InvalidArgument(format!("{}: {e}", m.display())))?;
    }
    let all: Vec<&Path> = meshes.iter().chain(others).copied().collect();
    for (i, &o) in all.iter().enumerate() {
        if let Some(input) = input {
            if io::same_file(input, o) {
                return Err(Error::InvalidArgument(format!(
                    "{}: this output is the input file {}; write it to another file",
                    o.display(),
                    input.display()
                )));
            }
        }
        if let Some(&p) = all[..i].iter().find(|&&p| io::same_file(p, o)) {
            return Err(Error::InvalidArgument(format!(
                "{} and {} are the same file: give each output its own",
                p.display(),
                o.display()
            )));
        }
        io::check_output_dir(o)?;
    }
    Ok(())
}

fn cmd_mesh(a: &MeshArgs) -> Result<(), Error> {
    let others: Vec<&Path> = [&a.mesh.report, &a.mesh.plot]
        .into_iter()
        .flatten()
        .map(PathBuf::as_path)
        .collect();
    check_outputs(
        Some(&a.input),
        &[&a.output],
        &others,
        &a.mesh.write.options(),
    )?;
    a.mesh.options().validate()?;
    a.curve.options().validate()?;
    // The budget: --max-memory, else the memory available now, so that a request that
    // cannot finish (a tiny --size) is refused at once rather than swapping for hours.
    let budget = match a.max_memory {
        Some(b) => Some((b, format!("--max-memory {}", mib(b)))),
        None => available_memory().map(|b| {
            (
                b,
                format!("the memory available, {} (--max-memory overrides)", mib(b)),
            )
        }),
    };
    if let Some((budget, what)) = &budget {
        // Reading holds at least the file's bytes' worth of nodes and triangles.
        let len = std::fs::metadata(&a.input)
            .map_err(|e| Error::io(&a.input, e))?
            .len();
        if len > *budget {
            return Err(Error::InvalidArgument(format!(
                "{}: reading this {} file needs more than {what}",
                a.input.display(),
                mib(len),
            )));
        }
    }
    // The surface checks (parallel) run on as many threads as the meshing: `--threads 1`
    // is one thread from start to end.
    let t = std::time::Instant::now();
    let mode = if a.nested_regions {
        RegionMode::EveryShell
    } else {
        RegionMode::Auto
    };
    let mesh_input = curvetet::threads::pool(a.mesh.threads, true)?
        .install(|| read_input(&a.input, &a.curve, mode))?;
    let input = InputInfo {
        json: serde_json::json!({
            "path": a.input.display().to_string(),
            "feature_angle": a.curve.feature_angle,
            "smooth": a.curve.smooth,
            "strict": a.curve.strict,
            "regions": mesh_input.num_regions(),
            "warnings": mesh_input.warnings(),
        }),
        read_seconds: t.elapsed().as_secs_f64(),
    };
    if let Some((budget, what)) = &budget {
        let need = mesh_input.estimated_peak_memory(&a.mesh.options());
        if need > *budget {
            return Err(Error::InvalidArgument(format!(
                "{}: meshing {} triangles needs at least about {} (estimate), more than \
                 {what}",
                a.input.display(),
                mesh_input.num_triangles(),
                mib(need),
            )));
        }
    }
    run_mesh(&mesh_input, &a.mesh, &a.output, input)
}

fn cmd_curve(input: &Path, output: &Path, c: &CurveArgs, w: &WriteArgs) -> Result<(), Error> {
    check_outputs(Some(input), &[output], &[], &w.options())?;
    c.options().validate()?;
    let raw = io::read(input)?;
    let name = input.display().to_string();
    if !raw.tri6.is_empty() {
        return Err(Error::InvalidArgument(format!(
            "{name}: already a P2 surface ({} 6-node triangles); nothing to curve",
            raw.tri6.len()
        )));
    }
    let (s, r) = curve_raw(raw, &name, c)?;
    for w in s.warnings() {
        eprintln!("warning: {w}");
    }
    eprintln!("{}", curve_summary(&name, &s, &r));
    io::write_surface(output, s.nodes(), s.triangles(), s.tags(), &w.options())?;
    eprintln!("wrote {}", output.display());
    Ok(())
}

fn cmd_demo(
    output: &Path,
    surface_out: Option<&Path>,
    surface_only: bool,
    n: usize,
    m: &MeshOptions,
) -> Result<(), Error> {
    let mut meshes = vec![output];
    meshes.extend(surface_out);
    let others: Vec<&Path> = [&m.report, &m.plot]
        .into_iter()
        .flatten()
        .map(PathBuf::as_path)
        .collect();
    check_outputs(None, &meshes, &others, &m.write.options())?;
    m.options().validate()?;
    let (big_r, r) = (1.0, 0.35);
    let (nu, nv) = curvetet::surface::demo::torus_resolution(n, big_r, r);
    let (nodes, tris) = curvetet::surface::demo::torus(nu, nv, big_r, r);
    let surface = Surface::new(nodes, tris, vec![])?;
    eprintln!(
        "demo: P2 torus R = {big_r}, r = {r}: {} triangles, {} nodes, enclosed volume {:.9} (exact {:.9})",
        surface.triangles().len(),
        surface.nodes().len(),
        enclosed_volume(surface.nodes(), surface.triangles()),
        2.0 * std::f64::consts::PI.powi(2) * big_r * r * r
    );
    let wopts = m.write.options();
    if surface_only {
        io::write_surface(
            output,
            surface.nodes(),
            surface.triangles(),
            surface.tags(),
            &wopts,
        )?;
        eprintln!("wrote {}", output.display());
        return Ok(());
    }
    if let Some(p) = surface_out {
        io::write_surface(
            p,
            surface.nodes(),
            surface.triangles(),
            surface.tags(),
            &wopts,
        )?;
        eprintln!("wrote {}", p.display());
    }
    let input = InputInfo {
        json: serde_json::json!({"demo": "torus", "R": big_r, "r": r, "triangles": n}),
        read_seconds: 0.0,
    };
    run_mesh(&MeshInput::Surface(surface), m, output, input)
}

fn cmd_convert(input: &Path, output: &Path, w: &WriteArgs) -> Result<(), Error> {
    check_outputs(Some(input), &[output], &[], &w.options())?;
    let raw = io::read(input)?;
    if raw.tet10.is_empty() {
        let s = io::surface_from_raw(raw, &input.display().to_string())?;
        for w in s.warnings() {
            eprintln!("warning: {w}");
        }
        io::write_surface(output, s.nodes(), s.triangles(), s.tags(), &w.options())?;
    } else {
        let m = raw.into_tet_mesh()?;
        io::write_mesh(output, &m, &w.options())?;
    }
    eprintln!("wrote {}", output.display());
    Ok(())
}

fn write_plot(path: &Path, report: &QualityReport, title: &str) -> Result<(), Error> {
    let svg = curvetet::mesh::plot::quality_svg(report, title);
    io::write_atomic(path, |w| w.write_all(svg.as_bytes()))?;
    eprintln!("wrote {}", path.display());
    Ok(())
}

/// The corner triangles' shape: how many are poorly shaped for the front, the worst, the
/// median (elongated triangles above [`ELONGATED_MEDIAN_ASPECT_RATIO`]).
fn shape_json(s: &Surface) -> serde_json::Value {
    let shape = triangle_shape(s.nodes(), s.triangles());
    serde_json::json!({
        "poor_aspect_ratio": POOR_ASPECT_RATIO,
        "poorly_shaped": shape.poor,
        "worst_aspect_ratio": shape.worst,
        "median_aspect_ratio": shape.median,
        "elongated_median_aspect_ratio": ELONGATED_MEDIAN_ASPECT_RATIO,
    })
}

/// [`shape_json`] as a line of `check`'s text report.
fn shape_line(s: &Surface) -> String {
    let shape = triangle_shape(s.nodes(), s.triangles());
    format!(
        "triangle aspect ratio: worst {:.2}, median {:.2}, {} of {} above {POOR_ASPECT_RATIO}",
        shape.worst,
        shape.median,
        shape.poor,
        s.triangles().len()
    )
}

/// `check`'s report on a surface of several regions.
fn say_regions(name: &str, r: &Regions, json: bool) -> Result<(), Error> {
    for w in r.warnings() {
        eprintln!("warning: {w}");
    }
    let names: Vec<String> = r
        .regions()
        .iter()
        .map(|x| {
            r.groups()
                .name(3, x.id)
                .map(str::to_string)
                .unwrap_or_else(|| format!("{}{}", io::REGION_NAME_PREFIX, x.id))
        })
        .collect();
    if json {
        let list: Vec<serde_json::Value> = r
            .regions()
            .iter()
            .zip(&names)
            .map(|(x, n)| {
                serde_json::json!({
                    "id": x.id, "name": n, "triangles": x.surface.triangles().len(),
                    "shells": x.surface.shell_count(), "enclosed_volume": x.surface.volume(),
                    "enclosed_volume_linear": x.surface.chord_volume(),
                })
            })
            .collect();
        let j = serde_json::json!({
            "kind": "regions", "file": name, "valid": true,
            "triangles": r.num_triangles(), "regions": list, "warnings": r.warnings(),
        });
        say!("{}", serde_json::to_string_pretty(&j).unwrap_or_default())?;
    } else {
        say!(
            "{name}: valid surface of {} regions, {} triangles (interfaces once)",
            r.regions().len(),
            r.num_triangles()
        )?;
        for (x, n) in r.regions().iter().zip(&names) {
            say!(
                "  region {} \"{n}\": {} boundary triangles, {} shells, enclosed volume {:.12} \
                 (linear {:.12})",
                x.id,
                x.surface.triangles().len(),
                x.surface.shell_count(),
                x.surface.volume(),
                x.surface.chord_volume()
            )?;
        }
    }
    Ok(())
}

fn cmd_check(
    path: &Path,
    json: bool,
    plot: Option<&Path>,
    nested_regions: bool,
    c: &CurveArgs,
) -> Result<(), Error> {
    let mode = if nested_regions {
        RegionMode::EveryShell
    } else {
        RegionMode::Auto
    };
    let plots: Vec<&Path> = plot.into_iter().collect();
    check_outputs(Some(path), &[], &plots, &WriteOptions::default())?;
    c.options().validate()?;
    let raw = io::read(path)?;
    let name = path.display().to_string();
    let linear = raw.tri6.is_empty() && !raw.tri3.is_empty();
    if MeshInput::several_regions(&raw, mode) {
        let MeshInput::Regions(r) = MeshInput::from_raw(raw, &name, &c.options(), mode)? else {
            unreachable!("several regions")
        };
        return say_regions(&name, &r, json);
    }
    if linear && raw.tet10.is_empty() && raw.tet4.is_empty() {
        let (s, r) = curve_raw(raw, &name, c)?;
        for w in s.warnings() {
            eprintln!("warning: {w}");
        }
        if json {
            let j = serde_json::json!({
                "kind": "linear-surface", "file": name, "valid": true,
                "vertices": s.corner_nodes().len(), "triangles": s.triangles().len(),
                "shells": s.shell_count(), "enclosed_volume_linear": s.chord_volume(),
                "triangle_shape": shape_json(&s),
                "curved": {
                    "edges": r.edges, "feature_edges": r.feature_edges,
                    "curved_edges": r.curved_edges, "flat_edges": r.flat_edges,
                    "straightened_fold": r.straightened.fold,
                    "straightened_intersection": r.straightened.intersection,
                    "enclosed_volume": s.volume(), "min_normal_cosine": s.min_normal_cosine(),
                },
                "warnings": s.warnings(),
            });
            say!("{}", serde_json::to_string_pretty(&j).unwrap_or_default())?;
        } else {
            say!("{name}: valid closed linear surface")?;
            say!(
                "  vertices {}, triangles {}, shells {}, enclosed volume {:.12}",
                s.corner_nodes().len(),
                s.triangles().len(),
                s.shell_count(),
                s.chord_volume()
            )?;
            say!("  {}", shape_line(&s))?;
            say!(
                "  curves to a valid P2 surface (feature angle {} deg): {} of {} edges curved, \
                 {} feature edges, {} straightened by the guards; volume {:.12}, min \
                 cos(curved normal, chord normal) {:.4}",
                c.feature_angle,
                r.curved_edges,
                r.edges,
                r.feature_edges,
                r.straightened.fold + r.straightened.intersection,
                s.volume(),
                s.min_normal_cosine()
            )?;
        }
        return Ok(());
    }
    if raw.tet10.is_empty() && raw.tet4.is_empty() {
        let s = io::surface_from_raw_with_repair(raw, &name, c.repair())?;
        for w in s.warnings() {
            eprintln!("warning: {w}");
        }
        let v = enclosed_volume(s.nodes(), s.triangles());
        let vl = enclosed_volume_linear(s.nodes(), s.triangles());
        let corners = s.corner_nodes().len();
        if json {
            let j = serde_json::json!({
                "kind": "surface", "file": name, "valid": true,
                "nodes": s.nodes().len(), "corner_nodes": corners, "triangles": s.triangles().len(),
                "shells": s.shell_count(), "enclosed_volume": v, "enclosed_volume_linear": vl,
                "min_normal_cosine": s.min_normal_cosine(), "warnings": s.warnings(),
                "triangle_shape": shape_json(&s),
            });
            say!("{}", serde_json::to_string_pretty(&j).unwrap_or_default())?;
        } else {
            say!("{name}: valid closed P2 surface")?;
            say!(
                "  nodes {} ({corners} corners), triangles {}, shells {}",
                s.nodes().len(),
                s.triangles().len(),
                s.shell_count()
            )?;
            say!("  enclosed volume {v:.12} (linear {vl:.12})")?;
            say!("  {}", shape_line(&s))?;
            say!(
                "  min cos(curved normal, chord normal) {:.4}",
                s.min_normal_cosine()
            )?;
        }
        return Ok(());
    }
    // Region ids: the tets' tags, when they are not all one.
    let regions = if raw.tet10_tags.windows(2).any(|w| w[0] != w[1]) {
        raw.tet10_tags.clone()
    } else {
        Vec::new()
    };
    let region_counts: std::collections::BTreeMap<i32, usize> =
        raw.tet10_tags.iter().fold(Default::default(), |mut c, &t| {
            *c.entry(t).or_default() += 1;
            c
        });
    let m: TetMesh = raw.into_tet_mesh()?;
    let region_name = |t: i32| m.groups.name(3, t).unwrap_or("").to_string();
    let conf = check::check_conformity_regions(&m, &regions)?;
    let report = QualityReport::of(&m);
    if let Some(p) = plot {
        write_plot(p, &report, &name)?;
    }
    let rel = (conf.volume_linear - conf.enclosed_linear).abs() / conf.enclosed_linear.abs();
    let ok = report.num_invalid == 0 && rel <= 1e-10;
    if json {
        let j = serde_json::json!({
            "kind": "volume", "file": name, "valid": ok, "conformity": conf,
            "regions": region_counts.iter().map(|(t, n)| serde_json::json!({"tag": t, "name": region_name(*t), "tets": n})).collect::<Vec<_>>(),
            "volume_relative_difference": rel, "report": report,
        });
        say!("{}", serde_json::to_string_pretty(&j).unwrap_or_default())?;
    } else {
        let q = &report.quality;
        say!(
            "{name}: {} P2 volume mesh",
            if ok { "valid" } else { "INVALID" }
        )?;
        say!(
            "  tets {}, nodes {}, boundary triangles {}",
            report.num_tets,
            report.num_nodes,
            report.num_boundary_faces
        )?;
        say!(
            "  conforming: {} interior faces shared by two tets, boundary closed",
            conf.interior_faces
        )?;
        if region_counts.len() > 1 {
            let list: Vec<String> = region_counts
                .iter()
                .map(|(t, n)| match region_name(*t) {
                    x if x.is_empty() => format!("{t} ({n} tets)"),
                    x => format!("{t} \"{x}\" ({n} tets)"),
                })
                .collect();
            say!(
                "  regions: {}; {} interface triangles between them",
                list.join(", "),
                conf.interface_faces
            )?;
        }
        say!("  volume: tets {:.12}, enclosed by the linear boundary {:.12} (rel. diff. {rel:.1e}); curved {:.12}", conf.volume_linear, conf.enclosed_linear, report.volume_curved)?;
        say!("  certified-invalid elements: {}", report.num_invalid)?;
        say!(
            "  scaled Jacobian min {:.4} (certified {:.4}) mean {:.4}",
            q.scaled_jacobian.min,
            q.scaled_jacobian_certified.min,
            q.scaled_jacobian.mean
        )?;
        say!(
            "  skewness max {:.4} mean {:.4}; > 0.85: {}, > 0.9: {}",
            q.skewness.max,
            q.skewness.mean,
            report.skew_above_085,
            report.skew_above_09
        )?;
        say!(
            "  dihedral angles {:.2} .. {:.2} deg",
            q.min_dihedral.min,
            q.max_dihedral.max
        )?;
    }
    if !ok {
        return Err(Error::InvalidMesh {
            elements: vec![],
            msg: format!(
                "{} elements not certified valid, volume relative difference {rel:e}",
                report.num_invalid
            ),
            mesh: None,
        });
    }
    Ok(())
}
