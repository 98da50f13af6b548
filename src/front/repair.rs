//! Local remeshing when a front face cannot be advanced at any relaxation level: delete
//! the tetrahedra around it (a ring that grows with each repair at the same place), which
//! merges the stuck pocket with its surroundings into a larger, easier cavity.

use super::grid::Aabb;
use super::validity::TET_OUT_FACES;
use super::Mesher;
use crate::geom::vec3::*;
use crate::Result;

/// Repairs allowed around one place before the front gives up there.
pub(super) const MAX_REPAIRS_PER_REGION: u32 = 12;

impl Mesher<'_> {
    fn repair_key(&self, fid: u32) -> (i32, i32, i32) {
        let fp = self.face_pts(fid);
        let c = centroid3(fp[0], fp[1], fp[2]);
        let cell = self.repair_cell;
        (
            (c[0] / cell).floor() as i32,
            (c[1] / cell).floor() as i32,
            (c[2] / cell).floor() as i32,
        )
    }

    /// Repairs done so far around face `fid`.
    pub(super) fn repair_count(&self, fid: u32) -> u32 {
        self.repairs_at
            .get(&self.repair_key(fid))
            .copied()
            .unwrap_or(0)
    }

    /// Delete the tets around stuck front face `fid` and requeue the faces nearby.
    pub(super) fn repair(&mut self, fid: u32) -> Result<()> {
        self.stats.repairs += 1;
        let fp = self.face_pts(fid);
        let c = centroid3(fp[0], fp[1], fp[2]);
        let key = self.repair_key(fid);
        let count = {
            let e = self.repairs_at.entry(key).or_insert(0);
            *e += 1;
            *e
        };
        if count > MAX_REPAIRS_PER_REGION {
            return Err(self.stuck_error(fid, "repeated local remeshing did not help"));
        }
        // The ring grows with each repair here, but stays local: a few element sizes.
        let lf = (dist(fp[0], fp[1]) + dist(fp[1], fp[2]) + dist(fp[2], fp[0])) / 3.0;
        let field = self.size_at(c);
        let local = if count <= 2 {
            lf.min(field)
        } else {
            lf.max(field)
        };
        let radius = local * (0.75 + 0.5 * count.min(6) as f64);
        let fv = self.faces[fid as usize].v;
        let r2 = radius * radius;
        let mut victims = Vec::new();
        for (ti, t) in self.tets.iter().enumerate() {
            if !self.tet_alive[ti] {
                continue;
            }
            let touches = t.iter().any(|v| fv.contains(v))
                || t.iter().any(|&v| dist2(self.pts[v as usize], c) <= r2);
            if touches {
                victims.push(ti);
            }
        }
        for &ti in &victims {
            self.delete_tet(ti);
        }
        self.stats.deleted += victims.len() as u64;
        // Requeue every live face in the region with a clean slate.
        let bb = Aabb {
            lo: [
                c[0] - 2.0 * radius,
                c[1] - 2.0 * radius,
                c[2] - 2.0 * radius,
            ],
            hi: [
                c[0] + 2.0 * radius,
                c[1] + 2.0 * radius,
                c[2] + 2.0 * radius,
            ],
        };
        let faces = &self.faces;
        let mut ids = std::mem::take(&mut self.near_ids);
        self.grid.query(&bb, |i| faces[i as usize].alive, &mut ids);
        if self.faces[fid as usize].alive && !ids.contains(&fid) {
            ids.push(fid);
        }
        for &i in &ids {
            let f = &mut self.faces[i as usize];
            if f.tries != 0 {
                f.tries = 0;
                f.ver += 1;
                self.enqueue(i);
            }
        }
        self.near_ids = ids;
        Ok(())
    }

    fn delete_tet(&mut self, ti: usize) {
        self.tet_alive[ti] = false;
        let t = self.tets[ti];
        let tp = t.map(|v| self.pts[v as usize]);
        self.volume_done -= tet_det(tp[0], tp[1], tp[2], tp[3]) / 6.0;
        for g in &TET_OUT_FACES {
            let v = [t[g[0]], t[g[1]], t[g[2]]];
            match self.face_map.get(&super::key3(v)) {
                Some(&other) => self.kill_face(other),
                None => self.add_face([v[0], v[2], v[1]]),
            }
        }
    }
}
