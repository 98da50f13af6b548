//! The linear corner surface of a P2 surface as OFF text, shared by the benchmarks that
//! hand TetGen (or another linear mesher) the same surface curvetet meshes.

use std::fmt::Write as _;

/// OFF text of the corners of `s`'s triangles (the surface's own vertices, renumbered in
/// first-use order, in `{:e}` round-trip notation; mid nodes left out).
pub fn linear_off(s: &curvetet::Surface) -> String {
    let nodes = s.nodes();
    let tris = s.triangles();
    let mut used = vec![u32::MAX; nodes.len()];
    let mut pts = Vec::new();
    for t in tris {
        for &v in &t[..3] {
            if used[v as usize] == u32::MAX {
                used[v as usize] = pts.len() as u32;
                pts.push(nodes[v as usize]);
            }
        }
    }
    let mut o = format!("OFF\n{} {} 0\n", pts.len(), tris.len());
    for p in &pts {
        let _ = writeln!(o, "{:e} {:e} {:e}", p[0], p[1], p[2]);
    }
    for t in tris {
        let _ = writeln!(
            o,
            "3 {} {} {}",
            used[t[0] as usize], used[t[1] as usize], used[t[2] as usize]
        );
    }
    o
}
