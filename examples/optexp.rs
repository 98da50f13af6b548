//! Development experiment driver (not part of the product).
use curvetet::front::run_front;
use curvetet::generate::size_field;
use curvetet::mesh::build;
use curvetet::mesh::quality::QualityReport;
use curvetet::optimize::*;
use curvetet::{io, Options};
use std::time::Instant;

fn cpu() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut ts) };
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let surf = io::read_surface(std::path::Path::new(&args[1])).unwrap();
    let goal: f64 = args.get(2).map(|s| s.parse().unwrap()).unwrap_or(0.6);
    let opts = Options::default();
    let t = Instant::now();
    let c0 = cpu();
    let size = size_field(&surf, &opts);
    let f = run_front(surf.nodes(), surf.triangles(), &opts, size, &mut |_, _| {
        false
    })
    .unwrap();
    let tf = t.elapsed().as_secs_f64();
    let cf = cpu() - c0;
    let bnd = Boundary::new(surf.nodes().len(), surf.triangles());
    let prm = LinearParams {
        goal_skewness: goal,
        ..Default::default()
    };
    let mut tl = f64::INFINITY;
    for _ in 0..2 {
        let c = cpu();
        let _ = improve_linear(f.pts.clone(), f.tets.clone(), &bnd, &prm);
        tl = tl.min(cpu() - c);
    }
    let (pts, tets, st) = improve_linear(f.pts, f.tets, &bnd, &prm);
    println!("front {tf:.3}s cpu {cf:.3}s linear cpu {tl:.3}s {st:?}");
    let mut mesh = build::assemble(
        &pts,
        &tets,
        surf.nodes().len(),
        surf.triangles(),
        surf.tags(),
    );
    let r = QualityReport::of(&mesh);
    println!(
        "before HO: tets {} minSJ {:.4} cert {:.4} maxskew {:.4} dih {:.2}..{:.2} invalid {}",
        r.num_tets,
        r.quality.scaled_jacobian.min,
        r.quality.scaled_jacobian_certified.min,
        r.quality.skewness.max,
        r.quality.min_dihedral.min,
        r.quality.max_dihedral.max,
        r.num_invalid
    );
    worst(&mesh, surf.nodes().len(), 8);
    if let Ok(t) = std::env::var("STAR") {
        star_report(&mesh, surf.nodes().len(), t.parse().unwrap());
    }
    let t = Instant::now();
    let c = cpu();
    let env = |k: &str, d: f64| {
        std::env::var(k)
            .ok()
            .map(|s| s.parse::<f64>().unwrap())
            .unwrap_or(d)
    };
    let d = HighOrderParams::default();
    let hp = HighOrderParams {
        threshold: env("TH", d.threshold),
        reach: env("REACH", d.reach),
        reach_below: env("REACHB", d.reach_below),
        layers: env("LAYERS", d.layers as f64) as usize,
        max_layers: env("MAXLAYERS", d.max_layers as f64) as usize,
        rounds: env("ROUNDS", d.rounds as f64) as usize,
        move_vertices: env("MV", 1.0) > 0.0,
        vertices_below: env("VB", d.vertices_below),
        max_skewness: env("MAXSKEW", d.max_skewness),
        max_skewness_rescue: env("MAXSKEWR", d.max_skewness_rescue),
        rescue_below: env("RESCUE", d.rescue_below),
        barrier_updates: env("BAR", d.barrier_updates as f64) as usize,
        iterations: env("IT", d.iterations as f64) as usize,
        stop_slack: env("SLACK", d.stop_slack),
    };
    let hs = optimize_high_order(&mut mesh, &bnd, &hp);
    let th = t.elapsed().as_secs_f64();
    println!("HO wall {th:.3}s cpu {:.3}s", cpu() - c);
    worst(&mesh, surf.nodes().len(), 8);
    worst_skew(&mesh, surf.nodes().len(), 12);
    let r = QualityReport::of(&mesh);
    println!("after HO {th:.3}s: minSJ {:.4} cert {:.4} maxskew {:.4} dih {:.2}..{:.2} invalid {} {hs:?}", r.quality.scaled_jacobian.min, r.quality.scaled_jacobian_certified.min, r.quality.skewness.max, r.quality.min_dihedral.min, r.quality.max_dihedral.max, r.num_invalid);
}

#[allow(dead_code)]
pub fn worst(mesh: &curvetet::TetMesh, n_surf: usize, k: usize) {
    use curvetet::geom::quality::tet_quality;
    use curvetet::mesh::quality::tet_nodes;
    let mut v: Vec<(f64, usize)> = (0..mesh.tets.len())
        .map(|t| {
            (
                tet_quality(&tet_nodes(mesh, t)).scaled_jacobian_certified,
                t,
            )
        })
        .collect();
    v.sort_by(|a, b| a.0.total_cmp(&b.0));
    let bset: std::collections::HashSet<[u32; 3]> = mesh
        .boundary
        .iter()
        .map(|b| {
            let mut k = [b[0], b[1], b[2]];
            k.sort();
            k
        })
        .collect();
    for &(s, t) in v.iter().take(k) {
        let e = mesh.tets[t];
        let nb = e[..4].iter().filter(|&&x| (x as usize) < n_surf).count();
        let nbm = e[4..].iter().filter(|&&x| (x as usize) < n_surf).count();
        let faces = [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]]
            .iter()
            .filter(|f| {
                let mut k = [e[f[0]], e[f[1]], e[f[2]]];
                k.sort();
                bset.contains(&k)
            })
            .count();
        let q = tet_quality(&tet_nodes(mesh, t));
        println!("  tet {t}: sj {s:.4} bverts {nb} bmids {nbm} bfaces {faces} skew {:.3} dih {:.1}..{:.1}", q.skewness, q.min_dihedral, q.max_dihedral);
    }
}

#[allow(dead_code)]
pub fn worst_skew(mesh: &curvetet::TetMesh, n_surf: usize, k: usize) {
    use curvetet::geom::quality::tet_quality;
    use curvetet::mesh::quality::tet_nodes;
    let mut v: Vec<(f64, usize)> = (0..mesh.tets.len())
        .map(|t| (tet_quality(&tet_nodes(mesh, t)).skewness, t))
        .collect();
    v.sort_by(|a, b| b.0.total_cmp(&a.0));
    let bset: std::collections::HashSet<[u32; 3]> = mesh
        .boundary
        .iter()
        .map(|b| {
            let mut k = [b[0], b[1], b[2]];
            k.sort();
            k
        })
        .collect();
    for &(s, t) in v.iter().take(k) {
        let e = mesh.tets[t];
        let nb = e[..4].iter().filter(|&&x| (x as usize) < n_surf).count();
        let faces = [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]]
            .iter()
            .filter(|f| {
                let mut k = [e[f[0]], e[f[1]], e[f[2]]];
                k.sort();
                bset.contains(&k)
            })
            .count();
        let q = tet_quality(&tet_nodes(mesh, t));
        println!(
            "  skew tet {t}: skew {s:.3} bverts {nb} bfaces {faces} sj {:.3} dih {:.1}..{:.1}",
            q.scaled_jacobian_certified, q.min_dihedral, q.max_dihedral
        );
    }
}

#[allow(dead_code)]
pub fn star_report(mesh: &curvetet::TetMesh, n_surf: usize, t: usize) {
    use curvetet::geom::quality::tet_quality;
    use curvetet::mesh::quality::tet_nodes;
    let e = mesh.tets[t];
    println!("tet {t}: corners {:?} (n_surf {n_surf})", &e[..4]);
    for &v in &e[..4] {
        if (v as usize) < n_surf {
            continue;
        }
        println!(" interior vertex {v} at {:?}", mesh.nodes[v as usize]);
        for (s, f) in mesh.tets.iter().enumerate() {
            if f[..4].contains(&v) {
                let q = tet_quality(&tet_nodes(mesh, s));
                let nb = f[..4].iter().filter(|&&x| (x as usize) < n_surf).count();
                println!(
                    "   star tet {s}: bverts {nb} skew {:.3} sj {:.3} dih {:.1}..{:.1}",
                    q.skewness, q.scaled_jacobian_certified, q.min_dihedral, q.max_dihedral
                );
            }
        }
    }
}
