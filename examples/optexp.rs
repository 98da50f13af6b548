//! Development experiment driver (not part of the product).
use curvetet::front::run_front;
use curvetet::generate::size_field;
use curvetet::mesh::build;
use curvetet::mesh::quality::QualityReport;
use curvetet::optimize::*;
use curvetet::{io, Options};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let surf = io::read_surface(std::path::Path::new(&args[1])).unwrap();
    let goal: f64 = args.get(2).map(|s| s.parse().unwrap()).unwrap_or(0.6);
    let opts = Options::default();
    let t = Instant::now();
    let size = size_field(&surf, &opts);
    let f = run_front(surf.nodes(), surf.triangles(), &opts, size, &mut |_, _| false).unwrap();
    let tf = t.elapsed().as_secs_f64();
    let bnd = Boundary::new(surf.nodes().len(), surf.triangles());
    let t = Instant::now();
    let prm = LinearParams { goal_skewness: goal, ..Default::default() };
    let (pts, tets, st) = improve_linear(f.pts, f.tets, &bnd, &prm);
    let tl = t.elapsed().as_secs_f64();
    println!("front {tf:.3}s linear {tl:.3}s {st:?}");
    let mut mesh = build::assemble(&pts, &tets, surf.nodes().len(), surf.triangles(), surf.tags());
    let r = QualityReport::of(&mesh);
    println!("before HO: tets {} minSJ {:.4} cert {:.4} maxskew {:.4} dih {:.2}..{:.2} invalid {}", r.num_tets, r.quality.scaled_jacobian.min, r.quality.scaled_jacobian_certified.min, r.quality.skewness.max, r.quality.min_dihedral.min, r.quality.max_dihedral.max, r.num_invalid);
    let t = Instant::now();
    let hs = optimize_high_order(&mut mesh, &bnd, &HighOrderParams::default());
    let th = t.elapsed().as_secs_f64();
    let r = QualityReport::of(&mesh);
    println!("after HO {th:.3}s: minSJ {:.4} cert {:.4} maxskew {:.4} dih {:.2}..{:.2} invalid {} {hs:?}", r.quality.scaled_jacobian.min, r.quality.scaled_jacobian_certified.min, r.quality.skewness.max, r.quality.min_dihedral.min, r.quality.max_dihedral.max, r.num_invalid);
}
