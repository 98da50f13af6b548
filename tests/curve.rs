//! Curving linear surfaces (tests/data/*_lin.off, the linear twins of the P2 benchmark
//! surfaces) into P2 surfaces: accuracy against the analytic sphere, torus and tube, no
//! folds on the sharp-featured hinge and screw, exact input vertices.

mod common;

use common::data_dir;
use curvetet::geom::quadrature::enclosed_volume_linear;
use curvetet::io::{self, RawMesh};
use curvetet::surface::curve::{curve_linear_report, CurveOptions, CurveReport, MidpointRule};
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

/// (linear volume error, curved volume error, max mid-node distance), all absolute.
fn accuracy(name: &str, exact: f64, dist: fn([f64; 3]) -> f64, rule: MidpointRule) -> [f64; 3] {
    let opts = CurveOptions {
        rule,
        ..CurveOptions::default()
    };
    let (raw, s, r) = curve(name, &opts);
    let v_lin = enclosed_volume_linear(&raw.nodes, &raw.tri3);
    let v = s.volume();
    let d = max_mid_distance(&s, dist);
    eprintln!(
        "{name} {rule:?}: V_lin {v_lin:.9} (err {:.3e}), V_curved {v:.9} (err {:.3e}), ratio \
         {:.1}, max mid-node distance {d:.3e}, min n.cos {:.4}; {r:?}",
        (v_lin - exact).abs() / exact,
        (v - exact).abs() / exact,
        (v_lin - exact).abs() / (v - exact).abs(),
        s.min_normal_cosine()
    );
    [(v_lin - exact).abs(), (v - exact).abs(), d]
}

#[test]
fn sphere_volume_and_mid_nodes() {
    let [lin, cur, d] = accuracy("sphere", 4.0 * PI / 3.0, sphere_dist, MidpointRule::Arc);
    accuracy("sphere", 4.0 * PI / 3.0, sphere_dist, MidpointRule::PnTriangle);
    assert!(lin / cur >= 10.0, "ratio {}", lin / cur);
    assert!(d < 1e-2, "{d}");
}

#[test]
fn torus_volume_and_mid_nodes() {
    let exact = 2.0 * PI * PI * 0.35 * 0.35;
    let [lin, cur, d] = accuracy("torus", exact, torus_dist, MidpointRule::Arc);
    accuracy("torus", exact, torus_dist, MidpointRule::PnTriangle);
    assert!(lin / cur >= 10.0, "ratio {}", lin / cur);
    assert!(d < 1e-2, "{d}");
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
    assert!(rims > 100 && ends > rims);
    assert!(rim_err < 1e-4, "{rim_err}");
}
