//! Why a front face is stuck: every candidate apex with the reason it was refused. Used on
//! the error path only (set `CURVETET_DIAGNOSE=1` to append it to the meshing error).

use super::grid::Aabb;
use super::size::regular_height;
use super::validity;
use super::Mesher;
use crate::geom::predicates::orient3d;
use crate::geom::tet_quality::{dihedral_extremes, skewness_from_extremes};
use crate::geom::vec3::*;
use std::fmt::Write;

impl Mesher<'_> {
    /// A multi-line report on the candidates of front face `fid`.
    pub(super) fn diagnose(&mut self, fid: u32) -> String {
        let f = self.faces[fid as usize];
        let fp = self.face_pts(fid);
        let c = centroid3(fp[0], fp[1], fp[2]);
        let n = normalize(tri_normal(fp[0], fp[1], fp[2]));
        let lf = (dist(fp[0], fp[1]) + dist(fp[1], fp[2]) + dist(fp[2], fp[0])) / 3.0;
        let h = regular_height(self.size_at(c).clamp(0.55 * lf, 1.8 * lf));
        let a = axpy(c, h, n);
        let r = 3.0 * self.alpha * h;
        let mut out = String::new();
        let _ =
            writeln!(
            out,
            "face {fid} {:?} (boundary triangle {}) at {:?}, mean edge {lf:.4}, field size {:.4}",
            f.v,
            if f.btri == u32::MAX { -1 } else { f.btri as i64 },
            c,
            self.size_at(c)
        );
        let mut found = Vec::new();
        self.front_vertices_within(a, r, &mut found);
        let mut ids: Vec<u32> = found.iter().map(|x| x.0).collect();
        for k in 0..3 {
            if let Some(&g) = self.edges.get(&(f.v[(k + 1) % 3], f.v[k])) {
                let gv = self.faces[g as usize].v;
                let w = self.wedge_deg(fid, g);
                let _ = writeln!(
                    out,
                    "  neighbour across edge {k}: face {g} {gv:?}, wedge {w:.2} deg"
                );
                if let Some(&x) = gv.iter().find(|x| !f.v.contains(x)) {
                    ids.push(x);
                }
            }
        }
        ids.sort_unstable();
        ids.dedup();
        for id in ids {
            if f.v.contains(&id) {
                continue;
            }
            let p = self.pts[id as usize];
            let o = orient3d(fp[0], fp[1], fp[2], p);
            if o <= 0 {
                continue;
            }
            let t = [f.v[0], f.v[1], f.v[2], id];
            let tp = [fp[0], fp[1], fp[2], p];
            self.gather_near(&Aabb::of(&tp), fid);
            let pts = &self.pts;
            let v = validity::check(t, tp, &self.near, |i| pts[i as usize], 0.0);
            let curved = self.p2_nodes(t, &tp).map(|x| super::curved_valid(&x));
            let (mn, mx) = dihedral_extremes(&tp);
            let _ = writeln!(
                out,
                "  apex {id}: dist {:.4}, min dihedral {mn:.2}, skew {:.3}, validity {:?}, P2 {}",
                dist(p, a),
                skewness_from_extremes(mn, mx),
                v.as_ref()
                    .map(|x| (x.min_gap_deg, x.min_gap_boundary_deg, x.num_closings)),
                match curved {
                    None => "straight",
                    Some(true) => "valid",
                    Some(false) => "INVALID",
                }
            );
        }
        // New points along the inward normal, as the front would place them.
        for s in [1.0, 0.7, 0.5, 0.3] {
            let p = axpy(c, s * h, n);
            let t = [f.v[0], f.v[1], f.v[2], validity::NEW_POINT];
            let tp = [fp[0], fp[1], fp[2], p];
            let mut bb = Aabb::of(&tp);
            for d in 0..3 {
                bb.lo[d] -= h;
                bb.hi[d] += h;
            }
            self.gather_near(&bb, fid);
            let pts = &self.pts;
            let pos = |i: u32| {
                if i == validity::NEW_POINT {
                    p
                } else {
                    pts[i as usize]
                }
            };
            let v = validity::check(t, tp, &self.near, pos, 0.0);
            let (mn, mx) = dihedral_extremes(&tp);
            let _ = writeln!(
                out,
                "  new point at {s} h: min dihedral {mn:.2}, skew {:.3}, validity {:?}",
                skewness_from_extremes(mn, mx),
                v.map(|x| (x.min_gap_deg, x.min_gap_boundary_deg))
            );
        }
        out
    }
}
