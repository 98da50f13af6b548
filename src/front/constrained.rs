//! Closing a stuck cavity by the constrained fill ([`crate::geom::cdt_fill`]): the
//! cavity's front faces are kept exactly, added points are strictly inside it. Used when
//! the exact apex search cannot close a cavity (thin wedges, pinched pockets).

use super::validity::{self, FaceRef, TET_OUT_FACES};
use super::{key3, Mesher};
use crate::geom::cdt_fill::{self, Patience, Split};
use crate::geom::vec3::{tet_det, P3};

/// Largest cavity (front faces) handed to the fill.
pub(super) const MAX_FILL_FACES: usize = 1000;

impl Mesher<'_> {
    /// Fill the cavity bounded by live front faces `comp`; `fixed` are the other live
    /// front faces nearby, which no new tet may touch. True when the tets are inserted.
    pub(super) fn constrained_fill(&mut self, comp: &[u32], fixed: &[FaceRef]) -> bool {
        let verts = self.cavity_vertices(comp);
        let local = |v: u32| verts.binary_search(&v).map_or(u32::MAX, |i| i as u32);
        let pts: Vec<P3> = verts.iter().map(|&v| self.pts[v as usize]).collect();
        // Front faces have the unmeshed region on their positive side, as the fill wants.
        let faces: Vec<[u32; 3]> = comp
            .iter()
            .map(|&f| self.faces[f as usize].v.map(local))
            .collect();
        // No other try follows here: the search runs every round.
        let (split, patience) = (Split::AtCrossing, Patience::Exhaustive);
        let stages = &mut Default::default();
        let Ok(filled) = cdt_fill::fill(&pts, &faces, split, None, patience, stages) else {
            return false;
        };
        // Global ids: the cavity's vertices, then the new points (not yet added).
        let first_new = self.pts.len() as u32;
        let id = |v: u32| {
            if (v as usize) < verts.len() {
                verts[v as usize]
            } else {
                first_new + v - verts.len() as u32
            }
        };
        let new_pts = &filled.pts[verts.len()..];
        let pos = |v: u32| {
            if v >= first_new {
                new_pts[(v - first_new) as usize]
            } else {
                self.pts[v as usize]
            }
        };
        let tets: Vec<[u32; 4]> = filled.tets.iter().map(|t| t.map(id)).collect();
        for t in &tets {
            let tp = t.map(pos);
            if validity::check(*t, tp, fixed, pos, 0.0).is_err() {
                return false;
            }
            // Curved tets the fill makes next to a curved face are left to the optimizer
            // except on the last attempt (a restart follows one it cannot untangle).
            if !(self.opts.optimize && self.fill_p2_invalid)
                && self
                    .p2_nodes(*t, &tp)
                    .is_some_and(|x| !super::curved_valid(&x))
            {
                return false;
            }
        }
        for &p in new_pts {
            self.new_point(p);
        }
        for t in tets {
            self.insert_any(t);
        }
        true
    }

    /// Add tet `t` (positive) whatever front faces it has: each of its faces closes the
    /// front face it matches or opens a new one.
    fn insert_any(&mut self, t: [u32; 4]) {
        let tp = t.map(|v| self.pts[v as usize]);
        self.volume_done += tet_det(tp[0], tp[1], tp[2], tp[3]) / 6.0;
        self.tets.push(t);
        self.tet_q.push(f64::NAN);
        self.tet_alive.push(true);
        for g in &TET_OUT_FACES {
            let v = [t[g[0]], t[g[1]], t[g[2]]];
            match self.face_map.get(&key3(v)) {
                Some(&other) => self.kill_face(other),
                None => self.add_face(v),
            }
        }
    }
}
