//! The pipeline: size field → advancing front → P2 assembly → optimization → certification
//! and report. Each stage hands the next a value; nothing reaches back.

use crate::front::size::{corner_sizes, regular_edge_from_area, SizeField};
use crate::front::{run_front, FrontStats, RESTARTS};
use crate::geom::quadrature::tri6_area;
use crate::geom::shape::TET10_EDGES;
use crate::geom::vec3::{mid, P3};
use crate::mesh::report::{uncertified, QualityReport};
use crate::mesh::{build, check, TetMesh};
use crate::optimize::high_order::reoptimize_high_order_near;
use crate::optimize::{
    improve_linear_known, optimize_high_order, Boundary, HighOrderParams, LinearParams,
    OptimizeStats,
};
use crate::options::{Options, SizeFrom, SizeMode};
use crate::{Error, Result, Surface};
use std::time::Instant;

/// Wall-clock seconds of each stage.
#[derive(Debug, Clone, Default, serde::Serialize)]
#[non_exhaustive]
pub struct StageTimes {
    /// Size field set-up.
    pub size_field: f64,
    /// Advancing front.
    pub front: f64,
    /// P2 assembly (mid nodes).
    pub assemble: f64,
    /// Quality improvement and high-order optimization.
    pub optimize: f64,
    /// Conformity check and Jacobian certification.
    pub certify: f64,
    /// Quality report.
    pub report: f64,
}

/// A generated mesh with its report.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct Generated {
    /// The certified P2 mesh.
    pub mesh: TetMesh,
    /// Its quality.
    pub report: QualityReport,
    /// Front counters.
    pub front: FrontStats,
    /// Stage times.
    pub times: StageTimes,
    /// What the optimization stages did (all zero when `Options::optimize` is off).
    pub optimize: OptimizeStats,
    /// What the graded size field measured local sizes from (`None` when uniform).
    pub size_from: Option<SizeFrom>,
    /// Target edge length used where the size is uniform (paper eq. 1 or the user's),
    /// or the smallest boundary size when graded.
    pub size: f64,
    /// Per region, for a mesh of several regions ([`crate::generate_regions`]); empty
    /// for one surface.
    pub regions: Vec<crate::regions::RegionResult>,
}

/// The largest uniform size the boundary of `surface` supports: twice its mean corner edge
/// length. The front grows a layer at most 1.8 times its base face's size, and new points
/// keep a fraction of the target size from the front; a target far above the boundary's
/// edges leaves it without room for new points, so it crawls (the unit sphere of mean
/// edge 0.2 meshes at size 0.4 at once, but not within a minute at size 1). A larger
/// [`SizeMode::Fixed`] is clamped to this ([`size_field`]).
pub fn supported_size(surface: &Surface) -> f64 {
    let nodes = surface.nodes();
    let edges = surface.edges();
    let sum: f64 = edges
        .iter()
        .map(|e| crate::geom::vec3::dist(nodes[e.nodes[0] as usize], nodes[e.nodes[1] as usize]))
        .sum();
    2.0 * sum / edges.len().max(1) as f64
}

/// The size field of `surface` under `opts` (a fixed size above [`supported_size`] is
/// clamped to it).
pub fn size_field(surface: &Surface, opts: &Options) -> SizeField {
    match opts.size {
        SizeMode::Fixed(l) => SizeField::Uniform(l.min(supported_size(surface))),
        SizeMode::Uniform => {
            // Paper eq. 1: the regular tetrahedron on the mean curved triangle area.
            let n = surface.triangles().len().max(1) as f64;
            let area: f64 = surface
                .triangles()
                .iter()
                .map(|t| tri6_area(&std::array::from_fn(|k| surface.nodes()[t[k] as usize])))
                .sum();
            SizeField::Uniform(regular_edge_from_area(area / n))
        }
        SizeMode::Graded => {
            let nodes = surface.nodes();
            let corners = surface.corner_nodes();
            let pts: Vec<P3> = corners.iter().map(|&c| nodes[c as usize]).collect();
            let local = |v: u32| corners.binary_search(&v).map(|i| i as u32).unwrap_or(0);
            let edges: Vec<[u32; 2]> = surface
                .edges()
                .iter()
                .map(|e| [local(e.nodes[0]), local(e.nodes[1])])
                .collect();
            let tris: Vec<[u32; 3]> = surface
                .triangles()
                .iter()
                .map(|t| [local(t[0]), local(t[1]), local(t[2])])
                .collect();
            let (h, from) = corner_sizes(&pts, &edges, &tris, opts.size_from);
            SizeField::graded_from(pts, h, from, &edges, opts.gradation)
        }
    }
}

/// Generate a certified P2 tet mesh of `surface`.
pub fn generate(surface: &Surface, opts: &Options) -> Result<Generated> {
    generate_with_progress(surface, opts, &mut |_, _| false)
}

/// [`generate`] with a progress callback `(fraction, stage) -> cancel?`, called from the
/// calling thread at least once per percent of the front's work.
pub fn generate_with_progress(
    surface: &Surface,
    opts: &Options,
    progress: &mut dyn FnMut(f64, &str) -> bool,
) -> Result<Generated> {
    opts.validate()?;
    let pool = crate::threads::pool(opts.threads, opts.pin_threads)?;
    generate_inner(surface, opts, progress, &pool)
}

fn generate_inner(
    surface: &Surface,
    opts: &Options,
    progress: &mut dyn FnMut(f64, &str) -> bool,
    pool: &rayon::ThreadPool,
) -> Result<Generated> {
    // The front and the progress callback run on the calling thread; only the parallel
    // stages run inside `pool`.
    let mut times = StageTimes::default();
    let t = Instant::now();
    let size = size_field(surface, opts);
    let size_value = size.min_size();
    times.size_field = t.elapsed().as_secs_f64();

    let bnd = Boundary::new(surface.nodes().len(), surface.triangles())
        .with_sliver_floors(surface.nodes(), surface.triangles());
    // Front, linear stage, assembly, high-order stage, final check; when the check finds
    // elements the optimizer could not untangle (in a conforming mesh; without the
    // optimizer, a curved tet the front took as a last resort), again from the front's
    // next restart configuration (another search radius or size changes every
    // choice the greedy front makes, as for a front that cannot close). Bounded by
    // RESTARTS; the last attempt's result stands, whatever it is.
    let mut first = 0;
    // Seconds of the passes whose mesh a restart dropped.
    let mut dropped = 0.0;
    let (mut front_stats, mesh, ostats, conf, bad) = loop {
        let pass = Instant::now();
        let front = run_front(
            surface.nodes(),
            surface.triangles(),
            opts,
            &size,
            first,
            progress,
        )
        .map_err(|e| with_shape_hint(e, surface))?;
        times.front += pass.elapsed().as_secs_f64();

        let mut ostats = OptimizeStats::default();
        if opts.optimize && progress(0.0, "optimize") {
            return Err(Error::Cancelled);
        }
        let (pts, tets) = if opts.optimize {
            let t = Instant::now();
            let prm = LinearParams {
                chords: surface.chords_allowed(),
                ..if front.stats.whole_fill {
                    LinearParams::for_whole_fill()
                } else {
                    LinearParams::default()
                }
            };
            let (pts, tets, st) = pool.install(|| {
                improve_linear_known(front.pts, front.tets, Some(&front.quality), &bnd, &prm)
            });
            ostats.linear = st;
            ostats.time_linear = t.elapsed().as_secs_f64();
            (pts, tets)
        } else {
            (front.pts, front.tets)
        };

        let t = Instant::now();
        let mut mesh = build::assemble(
            &pts,
            &tets,
            surface.nodes().len(),
            surface.triangles(),
            surface.tags(),
        );
        mesh.groups = surface.groups().clone();
        times.assemble += t.elapsed().as_secs_f64();

        if opts.optimize {
            // The linear stage takes about as long as the high-order one.
            if progress(0.5, "optimize") {
                return Err(Error::Cancelled);
            }
            let t = Instant::now();
            ostats.high_order =
                pool.install(|| optimize_high_order(&mut mesh, &bnd, &high_order_params(opts)));
            ostats.time_high_order = t.elapsed().as_secs_f64();
        }
        times.optimize += ostats.time_linear + ostats.time_high_order;
        // Tests only (feature `fault-injection`, see INJECT_FAULT_ENV): corrupt the mesh
        // just before the final check.
        let mesh = inject_fault(mesh, surface.nodes().len(), first == 0);

        if progress(1.0, "certify") {
            return Err(Error::Cancelled);
        }
        let t = Instant::now();
        let (conf, bad) = pool.install(|| (check::check_conformity(&mesh), uncertified(&mesh)));
        times.certify += t.elapsed().as_secs_f64();
        // A whole fill has no front configuration after it.
        let next = front.stats.restarts as usize + 1;
        if conf.is_ok() && !bad.is_empty() && !front.stats.whole_fill && next < RESTARTS.len() {
            if progress(0.0, "front (restart: elements left invalid)") {
                return Err(Error::Cancelled);
            }
            first = next;
            dropped += pass.elapsed().as_secs_f64();
            continue;
        }
        let (mut mesh, mut conf, mut bad) = (mesh, conf, bad);
        if conf.is_ok() && !bad.is_empty() {
            let t = Instant::now();
            let (n_surf, chords) = (surface.nodes().len(), surface.chords_allowed());
            let prm = high_order_params(opts);
            let redo = |m: &mut TetMesh, again: Reoptimize| {
                match (opts.optimize, again) {
                    (true, Reoptimize::Everywhere) => {
                        pool.install(|| optimize_high_order(m, &bnd, &prm));
                    }
                    (true, Reoptimize::Near(moved)) => {
                        pool.install(|| reoptimize_high_order_near(m, &bnd, &prm, moved));
                    }
                    _ => {}
                }
                pool.install(|| uncertified(m))
            };
            [ostats.chords, ostats.interior_chords] =
                straighten_uncertified(&mut mesh, n_surf, chords, &mut bad, redo);
            if ostats.chords > 0 {
                conf = pool.install(|| check::check_conformity(&mesh));
            }
            ostats.time_chords = t.elapsed().as_secs_f64();
            times.optimize += ostats.time_chords;
            // Tests only: a fault on every attempt is put back after the repair above,
            // so that it still reaches the final check.
            if fault_persists() {
                mesh = inject_fault(mesh, surface.nodes().len(), false);
                bad = pool.install(|| uncertified(&mesh));
            }
        }
        break (front.stats, mesh, ostats, conf, bad);
    };
    front_stats.discarded_seconds += dropped;
    let conf = match conf {
        Ok(c) => c,
        Err(Error::InvalidMesh { elements, msg, .. }) => {
            return Err(Error::InvalidMesh {
                elements,
                msg,
                mesh: Some(Box::new(mesh)),
            })
        }
        Err(e) => return Err(e),
    };
    let rel = (conf.volume_linear - conf.enclosed_linear).abs() / conf.enclosed_linear.abs();
    if rel > 1e-10 {
        return Err(Error::InvalidMesh {
            elements: vec![],
            msg: format!(
                "tet volumes sum to {} but the boundary encloses {} (relative difference {rel:e})",
                conf.volume_linear, conf.enclosed_linear
            ),
            mesh: Some(Box::new(mesh)),
        });
    }
    if !bad.is_empty() {
        return Err(Error::InvalidMesh {
            msg: format!(
                "{} elements are not certified valid (Jacobian not positive); first: {:?}",
                bad.len(),
                &bad[..bad.len().min(10)]
            ),
            elements: bad,
            mesh: Some(Box::new(mesh)),
        });
    }
    let t = Instant::now();
    // `bad` is empty here: every element is certified.
    let report = pool.install(|| QualityReport::with_invalid(&mesh, 0));
    times.report = t.elapsed().as_secs_f64();
    Ok(Generated {
        mesh,
        report,
        front: front_stats,
        times,
        optimize: ostats,
        size_from: size.measured_from(),
        size: size_value,
        regions: Vec::new(),
    })
}

/// Rounds of [`straighten_uncertified`] that optimize again.
const CHORD_ROUNDS: usize = 4;

/// Rounds of [`straighten_uncertified`] after those, that only certify again.
const STRAIGHT_ROUNDS: usize = 12;

/// What a round of [`straighten_uncertified`] asks its `redo` to optimize again before
/// it certifies.
#[derive(Clone, Copy, Debug)]
enum Reoptimize<'a> {
    /// The whole mesh (the first round, after the edges of every uncertified element
    /// went straight).
    Everywhere,
    /// Only near these nodes, the mid nodes the round straightened: the rest of the mesh
    /// is as the last optimization left it, and optimizing it all again would repeat
    /// that work for the few elements left.
    Near(&'a [u32]),
    /// Nothing: certify only.
    No,
}

/// Where elements are left uncertified, put the mid nodes of their edges back on the
/// chords and optimize and certify again (`redo`, which returns the elements still
/// uncertified into `bad`; [`Reoptimize`] says where it optimizes again); a few rounds,
/// while some are left with curved edges. An interior edge always may; a boundary edge
/// only on a surface curved from a linear one (`chords`: [`Surface::chords_allowed`]),
/// whose own edges are the straight ones.
///
/// The first [`CHORD_ROUNDS`] optimize again, which can bend the straightened interior
/// edges once more, so that each round leaves some elements uncertified again; the next
/// [`STRAIGHT_ROUNDS`] only certify, so every round straightens for good, and an element
/// whose edges all end up straight is valid where its corner tet is positive.
///
/// A thin pocket of the surface can leave an interior vertex closer to a curved boundary
/// edge than the edge bulges (the whole fill's tets on OpenSCAD's example004 and
/// example010), and no placement of the interior nodes certifies such an element; the
/// high-order stage's attempts at it leave its interior edges bent too, which inverts a
/// nearly flat tet. Straight-sided, a tet of positive volume is valid. Returns the
/// numbers of boundary and interior edges straightened.
fn straighten_uncertified(
    mesh: &mut TetMesh,
    n_surf: usize,
    chords: bool,
    bad: &mut Vec<usize>,
    mut redo: impl FnMut(&mut TetMesh, Reoptimize) -> Vec<usize>,
) -> [usize; 2] {
    let mut straightened = [0, 0];
    for round in 0..CHORD_ROUNDS + STRAIGHT_ROUNDS {
        // (mid node, its chord midpoint, boundary?)
        let mut moves = Vec::new();
        for &e in bad.iter() {
            let t = mesh.tets[e];
            for (k, [i, j]) in TET10_EDGES.iter().enumerate() {
                let m = t[4 + k] as usize;
                // Only a boundary edge's mid node is a surface node.
                let boundary = m < n_surf;
                let c = mid(mesh.nodes[t[*i] as usize], mesh.nodes[t[*j] as usize]);
                if (chords || !boundary) && mesh.nodes[m] != c {
                    moves.push((m, c, boundary));
                }
            }
        }
        if moves.is_empty() {
            break;
        }
        let mut moved = Vec::with_capacity(moves.len());
        for (m, c, boundary) in moves {
            if mesh.nodes[m] != c {
                mesh.nodes[m] = c;
                straightened[usize::from(!boundary)] += 1;
                moved.push(m as u32);
            }
        }
        let again = match round {
            0 => Reoptimize::Everywhere,
            r if r < CHORD_ROUNDS => Reoptimize::Near(&moved),
            _ => Reoptimize::No,
        };
        *bad = redo(mesh, again);
        if bad.is_empty() {
            break;
        }
    }
    straightened
}

/// The high-order stage's tuning for `opts` ([`Options::thorough`]).
fn high_order_params(opts: &Options) -> HighOrderParams {
    if opts.thorough {
        HighOrderParams::thorough()
    } else {
        HighOrderParams::default()
    }
}

/// A meshing failure says that it is a bug (the surface passed every check, and the
/// whole fill is meant to mesh any such surface), and, on a surface with poorly shaped
/// or mostly elongated triangles, so and what may get round it meanwhile.
fn with_shape_hint(e: Error, s: &Surface) -> Error {
    use crate::surface::geometry::{
        triangle_shape, ELONGATED_MEDIAN_ASPECT_RATIO, POOR_ASPECT_RATIO,
    };
    let Error::MeshingFailed { msg, partial } = e else {
        return e;
    };
    let shape = triangle_shape(s.nodes(), s.triangles());
    let (poor, worst, median) = (shape.poor, shape.worst, shape.median);
    let hint = if poor > 0 {
        Some(format!(
            "{poor} of {} boundary triangles are poorly shaped (aspect ratio above \
             {POOR_ASPECT_RATIO}, worst {worst:.0}); the front needs well-shaped boundary \
             triangles: smooth a surface from image segmentation before curving (CLI \
             `--smooth 10`, `CurveOptions::smooth_iterations`, C \
             `curvetet_surface_from_linear_smoothed`); remesh a CAD part's needle and cap \
             triangles (smoothing moves its sharp edges)",
            s.triangles().len(),
        ))
    } else if shape.elongated() {
        Some(format!(
            "most boundary triangles are elongated (median aspect ratio {median:.1}, above \
             {ELONGATED_MEDIAN_ASPECT_RATIO}; worst {worst:.1}), and the front gets stuck \
             where long boundary edges meet short ones: remesh the surface with more \
             isotropic triangles"
        ))
    } else {
        None
    };
    let meanwhile = hint
        .map(|h| format!(" Meanwhile: {h}."))
        .unwrap_or_default();
    Error::MeshingFailed {
        msg: format!("{msg}. {REPORT_FAILURE}{meanwhile}"),
        partial,
    }
}

/// What every meshing failure says: the surface passed the checks, so the failure is
/// curvetet's.
const REPORT_FAILURE: &str = "This surface passed the surface checks, so curvetet should \
                              mesh it: this is a bug, please report it with the surface \
                              file.";

/// The environment variable that makes [`generate`] corrupt its own mesh just before the
/// final check, to prove the check catches it (`Error::InvalidMesh`, C status
/// `CURVETET_ERR_INVALID_MESH`, CLI exit 6): `invert[:T]` swaps two corners of tet `T`
/// (default 0; conformity fails), `jacobian[:T]` moves an interior mid node of tet `T` next
/// to a corner (the mesh stays conforming but tet `T` is not certified valid), and
/// `jacobian-once[:T]` does so on the first attempt only (the restart must then deliver a
/// certified mesh). Read only in a build with the cargo feature `fault-injection` (the
/// test `invalid_mesh` requires it): a library in use never looks at it.
pub const INJECT_FAULT_ENV: &str = "CURVETET_INJECT_INVALID_MESH";

/// Without the `fault-injection` feature: the mesh unchanged.
#[cfg(not(feature = "fault-injection"))]
fn inject_fault(mesh: TetMesh, _surface_nodes: usize, _first_attempt: bool) -> TetMesh {
    mesh
}

/// Without the `fault-injection` feature: no fault.
#[cfg(not(feature = "fault-injection"))]
fn fault_persists() -> bool {
    false
}

/// Whether [`INJECT_FAULT_ENV`] asks for a Jacobian fault on every attempt (which
/// [`straighten_uncertified`] would otherwise repair before the final check).
#[cfg(feature = "fault-injection")]
fn fault_persists() -> bool {
    std::env::var(INJECT_FAULT_ENV)
        .is_ok_and(|s| s.split_once(':').map_or(s.as_str(), |x| x.0) == "jacobian")
}

/// The fault [`INJECT_FAULT_ENV`] asks for, if any.
#[cfg(feature = "fault-injection")]
fn inject_fault(mut mesh: TetMesh, surface_nodes: usize, first_attempt: bool) -> TetMesh {
    let Ok(spec) = std::env::var(INJECT_FAULT_ENV) else {
        return mesh;
    };
    let (kind, tet) = spec.split_once(':').unwrap_or((spec.as_str(), "0"));
    let Some(t) = tet.parse::<usize>().ok().filter(|&t| t < mesh.tets.len()) else {
        return mesh;
    };
    match kind {
        "invert" => {
            let e = &mut mesh.tets[t];
            // Swap corners 0 and 1 and the mid nodes that follow them: (1,2)<->(2,0) and
            // (3,0)<->(3,1); the tet is then inverted, its faces mismatched.
            e.swap(0, 1);
            e.swap(5, 6);
            e.swap(7, 9);
        }
        "jacobian" | "jacobian-once" if kind == "jacobian" || first_attempt => {
            let e = mesh.tets[t];
            if let Some(k) = (0..6).find(|&k| e[4 + k] as usize >= surface_nodes) {
                let (a, b) = (
                    mesh.nodes[e[TET10_EDGES[k][0]] as usize],
                    mesh.nodes[e[TET10_EDGES[k][1]] as usize],
                );
                // A mid node closer than a quarter of the edge to a corner: the Jacobian
                // is negative at that corner.
                mesh.nodes[e[4 + k] as usize] =
                    std::array::from_fn(|i| a[i] + 0.05 * (b[i] - a[i]));
            }
        }
        _ => {}
    }
    mesh
}

/// Bytes per tetrahedron at the peak of [`generate`] (front, P2 assembly, certification),
/// measured on graded torus meshes of 6 k to 330 k tets (about 500 bytes per tet there;
/// the estimate uses less so that it stays a lower bound).
pub const BYTES_PER_TET: u64 = 400;
/// Bytes per input triangle held by the surface and its topology.
pub const BYTES_PER_TRIANGLE: u64 = 300;

/// A lower-bound estimate of the peak memory [`generate`] needs for `surface` under
/// `opts`, in bytes: enough to refuse early an input that certainly does not fit a budget
/// (the CLI's `--max-memory`); an estimate under the budget does not promise the run fits.
///
/// Tets are estimated as the enclosed volume over the regular tet volume of the target
/// size for a uniform size, and as twice the boundary triangles for a graded size (the
/// graded meshes measured have 3 to 11 tets per boundary triangle).
pub fn estimated_peak_memory(surface: &Surface, opts: &Options) -> u64 {
    let tris = surface.triangles().len() as f64;
    let by_size = match opts.size {
        SizeMode::Graded => 0.0,
        SizeMode::Fixed(_) | SizeMode::Uniform => {
            let h = size_field(surface, opts).min_size();
            let regular = h * h * h / (6.0 * std::f64::consts::SQRT_2);
            if regular > 0.0 {
                surface.chord_volume().abs() / regular
            } else {
                f64::INFINITY
            }
        }
    };
    let tets = by_size.max(2.0 * tris).min(1e18);
    (tets as u64)
        .saturating_mul(BYTES_PER_TET)
        .saturating_add((tris as u64).saturating_mul(BYTES_PER_TRIANGLE))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::curve::CurveOptions;

    /// Corners of a thin tet: base ABC on the surface (z = 0), interior apex D at height
    /// 0.01.
    const A: P3 = [0.0, 0.0, 0.0];
    const B: P3 = [1.0, 0.0, 0.0];
    const C: P3 = [0.0, 1.0, 0.0];
    const D: P3 = [0.3, 0.3, 0.01];

    /// The thin tet with mid nodes `ab` on its boundary edge AB and `da` on its interior
    /// edge DA, the others on their chords; nodes 0-5 are the surface's (corners, then
    /// mid nodes), Gmsh order (edges 01 12 20 30 32 31).
    fn thin_tet(ab: P3, da: P3) -> TetMesh {
        TetMesh {
            nodes: vec![
                A,
                B,
                C,
                ab,
                mid(B, C),
                mid(C, A),
                D,
                da,
                mid(D, B),
                mid(D, C),
            ],
            tets: vec![[0, 1, 2, 6, 3, 4, 5, 7, 9, 8]],
            ..TetMesh::default()
        }
    }

    /// A boundary edge bulging past a low interior apex: the element cannot be certified
    /// curved; with the edge back on its chord it is a valid straight-sided one.
    #[test]
    fn a_boundary_edge_bulging_past_the_apex_is_straightened() {
        // AB bulges toward the apex, 5x its height.
        let mut mesh = thin_tet([0.5, 0.0, 0.05], mid(D, A));
        let mut bad = uncertified(&mesh);
        assert_eq!(bad, vec![0], "the bulging element must start uncertified");
        let n = straighten_uncertified(&mut mesh, 6, true, &mut bad, |m, _| uncertified(m));
        assert_eq!(n, [1, 0], "only the curved boundary edge is straightened");
        assert!(bad.is_empty(), "{bad:?}");
        assert_eq!(mesh.nodes[3], mid(A, B));
        assert_eq!(mesh.nodes[7], mid(D, A));
    }

    /// A bent interior edge on a thin tet is straightened on any surface; a curved
    /// boundary edge only where the surface allows chords.
    #[test]
    fn a_bent_interior_edge_is_straightened_a_boundary_one_only_with_chords() {
        // The interior edge DA bent through the base's plane.
        let bent = [0.15, 0.15, -0.02];
        let mut mesh = thin_tet(mid(A, B), bent);
        let mut bad = uncertified(&mesh);
        assert_eq!(bad, vec![0], "the bent element must start uncertified");
        let n = straighten_uncertified(&mut mesh, 6, false, &mut bad, |m, _| uncertified(m));
        assert_eq!(n, [0, 1]);
        assert!(bad.is_empty(), "{bad:?}");
        assert_eq!(mesh.nodes[7], mid(D, A));
        // A curved boundary edge stays as it is without chords.
        let bulge = [0.5, 0.0, 0.05];
        let mut mesh = thin_tet(bulge, mid(D, A));
        let mut bad = uncertified(&mesh);
        assert_eq!(bad, vec![0]);
        let n = straighten_uncertified(&mut mesh, 6, false, &mut bad, |m, _| uncertified(m));
        assert_eq!(n, [0, 0]);
        assert_eq!(bad, vec![0]);
        assert_eq!(mesh.nodes[3], bulge);
    }

    /// An optimizer that bends a straightened interior edge back every time it runs (as
    /// the high-order stage can, for a nearly flat tet among poor neighbours): the rounds
    /// that only certify straighten it for good.
    #[test]
    fn rounds_that_only_certify_keep_a_straightened_edge_straight() {
        let bent = [0.15, 0.15, -0.02];
        let mut mesh = thin_tet(mid(A, B), bent);
        let mut bad = uncertified(&mesh);
        assert_eq!(bad, vec![0]);
        let mut optimized = Vec::new();
        let redo = |m: &mut TetMesh, again: Reoptimize| {
            if !matches!(again, Reoptimize::No) {
                optimized.push(format!("{again:?}"));
                m.nodes[7] = bent;
            }
            uncertified(m)
        };
        straighten_uncertified(&mut mesh, 6, false, &mut bad, redo);
        // Every optimizing round ran and bent it back: the first everywhere, the next
        // ones near the node they straightened.
        let mut expected = vec!["Everywhere".to_string()];
        expected.resize(CHORD_ROUNDS, "Near([7])".to_string());
        assert_eq!(optimized, expected);
        assert!(bad.is_empty(), "{bad:?}");
        assert_eq!(mesh.nodes[7], mid(D, A));
    }

    fn mc_blob(smooth_iterations: u32) -> Surface {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/mc_blob.off");
        let opts = CurveOptions {
            smooth_iterations,
            ..CurveOptions::default()
        };
        crate::io::read_any_surface(&path, &opts).expect("curves")
    }

    #[test]
    fn a_stuck_front_on_poor_triangles_says_what_helps() {
        let failed = || Error::MeshingFailed {
            msg: "stuck".into(),
            partial: None,
        };
        let Error::MeshingFailed { msg, .. } = with_shape_hint(failed(), &mc_blob(0)) else {
            panic!("not a meshing failure");
        };
        assert!(
            msg.starts_with(&format!(
                "stuck. {REPORT_FAILURE} Meanwhile: 101 of 2316 boundary triangles"
            )),
            "{msg}"
        );
        assert!(msg.contains("--smooth 10"), "{msg}");
        // Well-shaped triangles: only the request for a report; other errors are left
        // alone.
        let Error::MeshingFailed { msg, .. } = with_shape_hint(failed(), &mc_blob(10)) else {
            panic!("not a meshing failure");
        };
        assert_eq!(msg, format!("stuck. {REPORT_FAILURE}"));
        let e = with_shape_hint(Error::Cancelled, &mc_blob(0));
        assert!(matches!(e, Error::Cancelled));
    }

    #[test]
    fn a_stuck_front_on_elongated_triangles_says_so() {
        let failed = || Error::MeshingFailed {
            msg: "stuck".into(),
            partial: None,
        };
        let surface = |nu, nv| {
            let (nodes, tris) = crate::surface::demo::torus(nu, nv, 1.0, 0.35);
            let n = tris.len();
            Surface::new(nodes, tris, vec![0; n]).expect("a valid torus")
        };
        // 25 x 54 (scripts/aniso-torus.py's, exactly curved): every triangle about 3.6
        // (aspect ratio below 10, so not "poorly shaped").
        let Error::MeshingFailed { msg, .. } = with_shape_hint(failed(), &surface(25, 54)) else {
            panic!("not a meshing failure");
        };
        assert!(
            msg.starts_with(&format!(
                "stuck. {REPORT_FAILURE} Meanwhile: most boundary triangles are elongated \
                 (median aspect ratio 3."
            )),
            "{msg}"
        );
        assert!(msg.contains("remesh the surface"), "{msg}");
        // 50 x 54: median 2.0, the message is left alone.
        let Error::MeshingFailed { msg, .. } = with_shape_hint(failed(), &surface(50, 54)) else {
            panic!("not a meshing failure");
        };
        assert_eq!(msg, format!("stuck. {REPORT_FAILURE}"));
    }

    /// The corner qualities the front hands to the linear stage are, bit for bit, what
    /// the linear stage would measure (it uses them instead of measuring).
    #[test]
    fn front_qualities_are_the_linear_stages() {
        use crate::optimize::linear::ElementQuality;
        let s = mc_blob(10);
        let opts = Options::default();
        let size = size_field(&s, &opts);
        let front = run_front(s.nodes(), s.triangles(), &opts, &size, 0, &mut |_, _| false)
            .expect("meshes");
        assert_eq!(front.quality.len(), front.tets.len());
        let bnd = Boundary::new(s.nodes().len(), s.triangles());
        let mut used = 0;
        for (t, &q) in front.tets.iter().zip(&front.quality) {
            if q.is_nan() || t.iter().filter(|&&v| bnd.is_fixed(v)).count() >= 2 {
                continue;
            }
            let c = t.map(|v| front.pts[v as usize]);
            let e = ElementQuality.eval(&bnd, &front.pts, *t, &c);
            assert_eq!(q.to_bits(), e.to_bits(), "tet {t:?}: {q} vs {e}");
            used += 1;
        }
        assert!(
            used > front.tets.len() / 2,
            "{used} of {}",
            front.tets.len()
        );
    }
}
