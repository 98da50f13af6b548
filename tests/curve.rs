//! Curving linear surfaces (tests/data/*_lin.off, the linear twins of the P2 benchmark
//! surfaces) into P2 surfaces: accuracy against the analytic sphere, torus and tube, no
//! folds on the sharp-featured hinge and screw, exact input vertices.

mod common;

use common::data_dir;
use curvetet::geom::quadrature::enclosed_volume_linear;
use curvetet::io::{self, RawMesh};
use curvetet::surface::curve::{
    curve_linear_report, CurveOptions, CurveReport, MidpointRule, NormalWeights,
};
use curvetet::Surface;
use std::f64::consts::PI;

fn read_lin(name: &str) -> RawMesh {
    io::read(&data_dir().join(format!("{name}_lin.off"))).unwrap()
}

fn curve(name: &str, opts: &CurveOptions) -> (RawMesh, Surface, CurveReport) {
    let raw = read_lin(name);
    let (s, r) = curve_linear_report(raw.nodes.clone(), raw.tri3.clone(), vec![], opts)
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    (raw, s, r)
}

/// Max distance of the mid nodes to a surface given by its distance function.
fn max_mid_distance(s: &Surface, dist: impl Fn([f64; 3]) -> f64) -> f64 {
    s.mid_nodes()
        .iter()
        .map(|&m| dist(s.nodes()[m as usize]).abs())
        .fold(0.0, f64::max)
}

fn sphere_dist(p: [f64; 3]) -> f64 {
    (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() - 1.0
}

fn torus_dist(p: [f64; 3]) -> f64 {
    let rho = (p[0] * p[0] + p[1] * p[1]).sqrt();
    ((rho - 1.0).powi(2) + p[2] * p[2]).sqrt() - 0.35
}

/// (volume error ratio linear / curved, max mid-node distance).
fn accuracy(name: &str, exact: f64, dist: fn([f64; 3]) -> f64, opts: &CurveOptions) -> [f64; 2] {
    let (raw, s, r) = curve(name, opts);
    let v_lin = enclosed_volume_linear(&raw.nodes, &raw.tri3);
    let v = s.volume();
    let d = max_mid_distance(&s, dist);
    let ratio = (v_lin - exact).abs() / (v - exact).abs();
    eprintln!(
        "{name} {:?} {:?}: V_lin {v_lin:.9} (rel. err {:.3e}), V_curved {v:.9} (rel. err \
         {:.3e}), ratio {ratio:.1}, max mid-node distance {d:.3e}, min n.cos {:.4}; {r:?}",
        opts.rule,
        opts.normals,
        (v_lin - exact).abs() / exact,
        (v - exact).abs() / exact,
        s.min_normal_cosine()
    );
    assert_eq!(
        r.straightened.fold + r.straightened.intersection,
        0,
        "{name}"
    );
    [ratio, d]
}

fn with(rule: MidpointRule, normals: NormalWeights) -> CurveOptions {
    CurveOptions::default()
        .with_rule(rule)
        .with_normals(normals)
}

/// Measured (see the `curve` module docs): default (arc, Max) ratio 508, distance 2.2e-16;
/// PN 98 and 1.6e-4; angle-weighted normals 129 and 1.3e-3.
#[test]
fn sphere_volume_and_mid_nodes() {
    let exact = 4.0 * PI / 3.0;
    let [ratio, d] = accuracy("sphere", exact, sphere_dist, &CurveOptions::default());
    assert!(ratio >= 300.0, "ratio {ratio}");
    assert!(d < 1e-12, "{d}");
    let [pn, _] = accuracy(
        "sphere",
        exact,
        sphere_dist,
        &with(MidpointRule::PnTriangle, NormalWeights::Max),
    );
    assert!(ratio > 3.0 * pn, "arc {ratio} vs PN {pn}");
    let [angle, d] = accuracy(
        "sphere",
        exact,
        sphere_dist,
        &with(MidpointRule::Arc, NormalWeights::Angle),
    );
    assert!(angle >= 80.0 && d < 2e-3, "{angle} {d}");
}

/// Measured: default ratio 162, distance 8.2e-4; PN 39 and 9.7e-4; angle 89 and 1.4e-3.
#[test]
fn torus_volume_and_mid_nodes() {
    let exact = 2.0 * PI * PI * 0.35 * 0.35;
    let [ratio, d] = accuracy("torus", exact, torus_dist, &CurveOptions::default());
    assert!(ratio >= 100.0, "ratio {ratio}");
    assert!(d < 1.2e-3, "{d}");
    let [pn, _] = accuracy(
        "torus",
        exact,
        torus_dist,
        &with(MidpointRule::PnTriangle, NormalWeights::Max),
    );
    assert!(ratio > 2.0 * pn, "arc {ratio} vs PN {pn}");
    let [angle, d] = accuracy(
        "torus",
        exact,
        torus_dist,
        &with(MidpointRule::Arc, NormalWeights::Angle),
    );
    assert!(angle >= 50.0 && d < 2e-3, "{angle} {d}");
}

#[test]
fn tube_flat_ends_and_round_rims() {
    let (raw, s, r) = curve("tube", &CurveOptions::default());
    eprintln!("tube: {r:?}");
    let n = raw.nodes.len();
    let nodes = s.nodes();
    let rad = |p: [f64; 3]| (p[0] * p[0] + p[1] * p[1]).sqrt();
    let (mut ends, mut rims) = (0, 0);
    let (mut rim_err, mut cyl_err) = (0.0f64, 0.0f64);
    for e in s.edges() {
        let [a, b] = e.nodes.map(|v| nodes[v as usize]);
        let m = nodes[e.mid as usize];
        assert!((e.mid as usize) >= n);
        for z in [0.0, 2.0] {
            if a[2] == z && b[2] == z {
                assert_eq!(m[2], z, "end-face mid node off its plane: {m:?}");
                ends += 1;
                // On a rim both ends are on the same circle.
                for r0 in [1.0, 0.5] {
                    if (rad(a) - r0).abs() < 1e-9 && (rad(b) - r0).abs() < 1e-9 {
                        rims += 1;
                        rim_err = rim_err.max((rad(m) - r0).abs());
                    }
                }
            }
        }
        if a[2] != b[2] || (a[2] != 0.0 && a[2] != 2.0) {
            let r0 = if rad(a) > 0.75 { 1.0 } else { 0.5 };
            cyl_err = cyl_err.max((rad(m) - r0).abs());
        }
    }
    eprintln!(
        "tube: {ends} end-face edges, {rims} rim edges, max rim radius error {rim_err:.3e}, \
         max cylinder radius error {cyl_err:.3e}"
    );
    // Measured: 830 end-face edges (118 on rims), rim radius error 2.2e-16 (the rims are
    // arcs through exact circle tangents), cylinder mid nodes within 5.6e-4 of the radius.
    assert!(rims > 100 && ends > rims);
    assert!(rim_err < 1e-12, "{rim_err}");
    assert!(cyl_err < 1e-3, "{cyl_err}");
}

/// Sharp-featured, mixed-size surfaces: curved without any folded triangle, and checked.
#[test]
fn hinge_and_screw_curve_without_folds() {
    for name in ["hinge", "screw"] {
        let (raw, s, r) = curve(name, &CurveOptions::default());
        let c = s.min_normal_cosine();
        let v_lin = enclosed_volume_linear(&raw.nodes, &raw.tri3);
        eprintln!(
            "{name}: min n.cos {c:.4}, V_lin {v_lin:.6}, V_curved {:.6}; {r:?}",
            s.volume()
        );
        assert!(
            c >= CurveOptions::default().min_normal_cosine,
            "{name}: {c}"
        );
        assert!(r.feature_edges > 0 && r.curved_edges > 0, "{name}: {r:?}");
        // Input vertices are the first nodes, bit-identical.
        assert_eq!(&s.nodes()[..raw.nodes.len()], &raw.nodes[..]);
    }
}

/// Curve, then mesh end to end to a certified-valid P2 mesh (the sphere, a smooth case).
#[test]
fn sphere_curves_then_meshes() {
    let (_, s, _) = curve("sphere", &CurveOptions::default());
    let g = curvetet::generate(&s, &curvetet::Options::default())
        .unwrap_or_else(|e| panic!("sphere: {e}"));
    eprintln!(
        "sphere: {} tets, min certified SJ {:.3}",
        g.report.num_tets, g.report.quality.scaled_jacobian_certified.min
    );
    assert_eq!(g.report.num_invalid, 0);
    assert_eq!(g.mesh.boundary.len(), s.triangles().len());
}

/// Curve, then mesh the sharp-featured surfaces end to end: certified valid, the curved
/// boundary kept.
#[test]
fn hinge_and_screw_curve_then_mesh() {
    for name in ["hinge", "screw"] {
        let (_, s, _) = curve(name, &CurveOptions::default());
        let t = std::time::Instant::now();
        let g = curvetet::generate(&s, &curvetet::Options::default())
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        eprintln!(
            "{name}: {} tets in {:.1} s, min certified SJ {:.3}",
            g.report.num_tets,
            t.elapsed().as_secs_f64(),
            g.report.quality.scaled_jacobian_certified.min
        );
        assert_eq!(g.report.num_invalid, 0, "{name}");
        assert_eq!(g.mesh.boundary.len(), s.triangles().len(), "{name}");
    }
}

/// Mangled linear surfaces (vertices moved by random amounts, some far enough to fold or
/// cross the surface; triangles with swapped corners) never panic; whatever is accepted
/// passes the guards' normal-cosine bound.
#[test]
fn mangled_surfaces_never_panic() {
    let raw = read_lin("screw");
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut rnd = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let (mut ok, mut err) = (0, 0);
    for k in 0..40 {
        let mut nodes = raw.nodes.clone();
        let mut tris = raw.tri3.clone();
        let amp = [1e-9, 1e-3, 0.5, 5.0][k % 4];
        for _ in 0..1 + k % 5 {
            let v = (rnd() * nodes.len() as f64) as usize % nodes.len();
            for x in nodes[v].iter_mut() {
                *x += amp * (rnd() - 0.5);
            }
        }
        if k % 7 == 6 {
            let t = (rnd() * tris.len() as f64) as usize % tris.len();
            tris[t].swap(0, 1);
        }
        let opts = CurveOptions::default();
        let r = std::panic::catch_unwind(|| {
            curve_linear_report(nodes, tris, vec![], &opts).map(|(s, _)| s.min_normal_cosine())
        });
        match r {
            Ok(Ok(c)) => {
                assert!(c >= opts.min_normal_cosine, "case {k}: {c}");
                ok += 1;
            }
            Ok(Err(_)) => err += 1,
            Err(_) => panic!("case {k}: curving panicked"),
        }
    }
    eprintln!("mangled: {ok} accepted, {err} rejected");
    assert!(ok > 0 && err > 0);
}

/// Options are validated; a surface curved through `Surface::from_linear` is the default
/// one with that feature angle.
#[test]
fn options_and_from_linear() {
    let raw = read_lin("tube");
    for bad in [-1.0, 181.0, f64::NAN] {
        let e = Surface::from_linear(raw.nodes.clone(), raw.tri3.clone(), vec![], bad);
        assert!(
            matches!(e, Err(curvetet::Error::InvalidArgument(_))),
            "{bad}"
        );
    }
    let a = Surface::from_linear(raw.nodes.clone(), raw.tri3.clone(), vec![7; 2292], 40.0).unwrap();
    let (_, b, _) = curve("tube", &CurveOptions::default());
    assert_eq!(a.nodes(), b.nodes());
    assert!(a.tags().iter().all(|&t| t == 7));
    // With features off (180 degrees) the rims are no longer followed as curves: the flat
    // ends' edges still stay flat, but the sharp rims are smoothed over.
    let c = Surface::from_linear(raw.nodes, raw.tri3, vec![], 180.0).unwrap();
    assert_ne!(c.nodes(), a.nodes());
}

/// Two coarse spheres whose flat faces face each other across a tiny gap: the linear
/// surface is clean, but curving bulges both faces across the gap. The surface check finds
/// the intersection, the guard straightens the edges involved, and the result is valid.
#[test]
fn curving_that_would_intersect_is_straightened() {
    // Linear icosphere (level 1, 80 triangles), corners only.
    let (p2nodes, p2tris) = common::icosphere(1);
    let mut remap = vec![u32::MAX; p2nodes.len()];
    let mut nodes: Vec<[f64; 3]> = Vec::new();
    let mut tris: Vec<[u32; 3]> = Vec::new();
    for t in &p2tris {
        tris.push([0, 1, 2].map(|k| {
            let v = t[k] as usize;
            if remap[v] == u32::MAX {
                remap[v] = nodes.len() as u32;
                nodes.push(p2nodes[v]);
            }
            remap[v]
        }));
    }
    // Rotate so that triangle 0's normal is +x (Rodrigues), then its plane is x = c.
    let [a, b, c] = tris[0].map(|v| nodes[v as usize]);
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let w = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let n = [
        u[1] * w[2] - u[2] * w[1],
        u[2] * w[0] - u[0] * w[2],
        u[0] * w[1] - u[1] * w[0],
    ];
    let ln = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    let n = n.map(|x| x / ln);
    // Axis k = n x e_x, angle between n and e_x.
    let k = [0.0, n[2], -n[1]];
    let s = (k[1] * k[1] + k[2] * k[2]).sqrt();
    let cth = n[0];
    let k = k.map(|x| x / s);
    let rot = |p: [f64; 3]| {
        let kxp = [
            k[1] * p[2] - k[2] * p[1],
            k[2] * p[0] - k[0] * p[2],
            k[0] * p[1] - k[1] * p[0],
        ];
        let kdp = k[0] * p[0] + k[1] * p[1] + k[2] * p[2];
        [0, 1, 2].map(|d| p[d] * cth + kxp[d] * s + k[d] * kdp * (1.0 - cth))
    };
    for p in &mut nodes {
        *p = rot(*p);
    }
    let plane = nodes[tris[0][0] as usize][0];
    assert!(tris[0]
        .iter()
        .all(|&v| (nodes[v as usize][0] - plane).abs() < 1e-12));
    // The second sphere: turned by 180 degrees about z, its facing plane 1e-3 beyond.
    let shift = 2.0 * plane + 1e-3;
    let nv = nodes.len() as u32;
    let second: Vec<[f64; 3]> = nodes.iter().map(|p| [shift - p[0], -p[1], p[2]]).collect();
    nodes.extend(second);
    let more: Vec<[u32; 3]> = tris.iter().map(|t| t.map(|v| v + nv)).collect();
    tris.extend(more);
    let (s, r) = curve_linear_report(nodes, tris, vec![], &CurveOptions::default())
        .unwrap_or_else(|e| panic!("{e}"));
    eprintln!("two spheres: {r:?}");
    assert!(r.straightened.intersection > 0, "{r:?}");
    assert!(r.curved_edges > 0);
    assert_eq!(s.shell_count(), 2);
}

/// The command-line tool: `curve` writes a P2 surface that reads back unchanged, `check`
/// reports a linear surface's defect with exit code 4, and a read-only output format is
/// refused before any work (exit code 1).
#[test]
fn command_line_curve_and_check() {
    let exe = env!("CARGO_BIN_EXE_curvetet");
    let dir = std::env::temp_dir().join(format!("curvetet-curve-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("sphere_p2.msh");
    let input = data_dir().join("sphere_lin.off");
    let st = std::process::Command::new(exe)
        .args([
            "curve",
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ])
        .args(["--feature-angle", "40"])
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let back = io::read_surface(&out).unwrap();
    let (_, s, _) = curve("sphere", &CurveOptions::default());
    assert_eq!(back.nodes(), s.nodes());
    assert_eq!(back.triangles(), s.triangles());

    let bad = data_dir().join("bad/open_lin.off");
    let st = std::process::Command::new(exe)
        .args(["check", bad.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(st.status.code(), Some(4));
    assert!(String::from_utf8_lossy(&st.stderr).contains("not-closed"));

    let st = std::process::Command::new(exe)
        .args(["mesh", input.to_str().unwrap(), "-o"])
        .arg(dir.join("x.stl"))
        .output()
        .unwrap();
    assert_eq!(st.status.code(), Some(1));
    std::fs::remove_dir_all(&dir).ok();
}

/// `io::read_any_surface` curves linear files and passes P2 files through.
#[test]
fn read_any_surface_curves_only_linear_input() {
    let opts = CurveOptions::default();
    let lin = io::read_any_surface(&data_dir().join("tube_lin.off"), &opts).unwrap();
    let (_, s, _) = curve("tube", &opts);
    assert_eq!(lin.nodes(), s.nodes());
    let p2 = io::read_any_surface(&data_dir().join("sphere_p2.msh"), &opts).unwrap();
    let strict = io::read_surface(&data_dir().join("sphere_p2.msh")).unwrap();
    assert_eq!(p2.nodes(), strict.nodes());
    let e = io::read_surface(&data_dir().join("tube_lin.off")).unwrap_err();
    assert_eq!(e.surface_defect().map(|k| k.name()), Some("linear-surface"));
}
