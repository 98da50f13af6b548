//! Closing a small stuck cavity exactly: when a front face cannot be advanced at any
//! relaxation level and its front component (a closed cavity) is small, search for a
//! tetrahedralization of the cavity by depth-first search over its own vertices (most
//! constrained face first, best quality first, every tet checked with the exact validity
//! test and the certified P2 Jacobian). If none exists without a Steiner point, add the
//! Chebyshev centre of the cavity's kernel (a small LP) as one.
//!
//! The search is complete for the vertex set it is given and bounded by a node budget.

use super::validity::{self, FaceRef, TET_OUT_FACES};
use super::Mesher;
use crate::geom::predicates::orient3d;
use crate::geom::tet_quality::{dihedral_extremes, skewness_from_extremes};
use crate::geom::vec3::*;

/// Largest cavity (front faces) the exact search takes on.
pub(super) const MAX_CAVITY_FACES: usize = 100;
/// Search nodes per cavity.
const NODE_BUDGET: usize = 2000;
/// First id of the Steiner points added during the search (below the front's own
/// special ids).
const STEINER: u32 = u32::MAX - 64;

struct Search<'s> {
    base: &'s dyn Fn(u32) -> P3,
    /// Steiner points added so far (ids `STEINER + k`).
    steiner: Vec<P3>,
    /// How many Steiner points the search may add where a face sees no vertex.
    max_steiner: usize,
    /// Front faces around the cavity that are not part of it (never crossed).
    fixed: Vec<FaceRef>,
    verts: Vec<u32>,
    open: Vec<FaceRef>,
    out: Vec<[u32; 4]>,
    nodes: usize,
    curved_ok: &'s dyn Fn([u32; 4], &[P3; 4]) -> bool,
}

impl Search<'_> {
    fn pos(&self, i: u32) -> P3 {
        if i >= STEINER && ((i - STEINER) as usize) < self.steiner.len() {
            self.steiner[(i - STEINER) as usize]
        } else {
            (self.base)(i)
        }
    }

    /// Is `v` a valid apex for open face `fi`, and its quality.
    fn apex_quality(&self, fi: usize, v: u32, near: &[FaceRef]) -> Option<f64> {
        let f = self.open[fi].v;
        let fp = f.map(|v| self.pos(v));
        let p = self.pos(v);
        if orient3d(fp[0], fp[1], fp[2], p) <= 0 {
            return None;
        }
        let t = [f[0], f[1], f[2], v];
        let tp = [fp[0], fp[1], fp[2], p];
        if validity::check(t, tp, near, |i| self.pos(i), 0.0).is_err() {
            return None;
        }
        if !(self.curved_ok)(t, &tp) {
            return None;
        }
        let (mn, mx) = dihedral_extremes(&tp);
        let q = 1.0 - skewness_from_extremes(mn, mx);
        Some(if q.is_nan() { -1.0 } else { q })
    }

    fn near_of(&self, fi: usize) -> Vec<FaceRef> {
        let mut near: Vec<FaceRef> = Vec::with_capacity(self.open.len() + self.fixed.len());
        for (k, g) in self.open.iter().enumerate() {
            if k != fi {
                near.push(*g);
            }
        }
        near.extend_from_slice(&self.fixed);
        near
    }

    /// Try Steiner points above open face `fi` (which sees no vertex): along its normal at
    /// a few heights; recurse with each valid one.
    fn dfs_with_steiner(&mut self, fi: usize) -> bool {
        if self.steiner.len() >= self.max_steiner {
            return false;
        }
        let f = self.open[fi].v;
        let fp = f.map(|v| self.pos(v));
        let c = centroid3(fp[0], fp[1], fp[2]);
        let n = normalize(tri_normal(fp[0], fp[1], fp[2]));
        let l = (dist(fp[0], fp[1]) + dist(fp[1], fp[2]) + dist(fp[2], fp[0])) / 3.0;
        let near = self.near_of(fi);
        let id = STEINER + self.steiner.len() as u32;
        for s in [0.8, 0.5, 0.3, 0.15] {
            let p = axpy(c, s * (2.0f64 / 3.0).sqrt() * l, n);
            self.steiner.push(p);
            if self.apex_quality(fi, id, &near).is_some() {
                self.verts.push(id);
                let (b, r, a) = self.apply(fi, id);
                if self.dfs() {
                    return true;
                }
                self.undo(b, r, a);
                self.verts.pop();
            }
            self.steiner.pop();
            if self.nodes > NODE_BUDGET {
                return false;
            }
        }
        false
    }

    fn valid_apexes(&self, fi: usize, buf: &mut Vec<(f64, u32)>) {
        buf.clear();
        let f = self.open[fi].v;
        let near = self.near_of(fi);
        for &v in &self.verts {
            if f.contains(&v) {
                continue;
            }
            if let Some(q) = self.apex_quality(fi, v, &near) {
                buf.push((q, v));
            }
        }
        buf.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    }

    /// Apply tet (open[fi], v); returns what to undo.
    fn apply(&mut self, fi: usize, v: u32) -> (FaceRef, Vec<FaceRef>, Vec<[u32; 3]>) {
        let base = self.open.swap_remove(fi);
        let t = [base.v[0], base.v[1], base.v[2], v];
        let mut removed = Vec::new();
        let mut added = Vec::new();
        for g in &TET_OUT_FACES[1..] {
            let nv = [t[g[0]], t[g[1]], t[g[2]]];
            let k = sorted(nv);
            if let Some(j) = self.open.iter().position(|o| sorted(o.v) == k) {
                removed.push(self.open.swap_remove(j));
            } else {
                self.open.push(FaceRef {
                    v: nv,
                    boundary: false,
                });
                added.push(nv);
            }
        }
        self.out.push(t);
        (base, removed, added)
    }

    fn undo(&mut self, base: FaceRef, removed: Vec<FaceRef>, added: Vec<[u32; 3]>) {
        self.out.pop();
        for a in added {
            if let Some(j) = self.open.iter().position(|o| o.v == a) {
                self.open.swap_remove(j);
            }
        }
        self.open.extend(removed);
        self.open.push(base);
    }

    fn dfs(&mut self) -> bool {
        if self.open.is_empty() {
            return true;
        }
        self.nodes += 1;
        if self.nodes > NODE_BUDGET {
            return false;
        }
        // Most constrained face first.
        let mut best: Option<(usize, Vec<(f64, u32)>)> = None;
        let mut buf = Vec::new();
        for fi in 0..self.open.len() {
            self.valid_apexes(fi, &mut buf);
            if buf.is_empty() {
                return self.dfs_with_steiner(fi);
            }
            if best.as_ref().map_or(true, |b| buf.len() < b.1.len()) {
                best = Some((fi, buf.clone()));
                if buf.len() == 1 {
                    break;
                }
            }
        }
        let Some((fi, options)) = best else {
            return false;
        };
        let key = self.open[fi].v;
        for (_, v) in options {
            let fi = self.open.iter().position(|o| o.v == key).unwrap_or(fi);
            let (b, r, a) = self.apply(fi, v);
            if self.dfs() {
                return true;
            }
            self.undo(b, r, a);
            if self.nodes > NODE_BUDGET {
                return false;
            }
        }
        false
    }
}

fn sorted(mut v: [u32; 3]) -> [u32; 3] {
    v.sort_unstable();
    v
}

impl Mesher<'_> {
    /// The front component (closed cavity) containing live face `fid`, if it has at most
    /// `max` faces.
    pub(super) fn component(&mut self, fid: u32, max: usize) -> Option<Vec<u32>> {
        let mut comp = vec![fid];
        let mut seen = std::collections::HashSet::new();
        seen.insert(fid);
        let mut i = 0;
        let mut ids = Vec::new();
        while i < comp.len() {
            let f = self.faces[comp[i] as usize].v;
            let p = f.map(|v| self.pts[v as usize]);
            let bb = super::grid::Aabb::of(&p);
            let faces = &self.faces;
            self.grid.query(&bb, |k| faces[k as usize].alive, &mut ids);
            for &k in &ids {
                if seen.contains(&k) {
                    continue;
                }
                let g = self.faces[k as usize].v;
                if g.iter().filter(|x| f.contains(x)).count() == 2 {
                    seen.insert(k);
                    comp.push(k);
                    if comp.len() > max {
                        return None;
                    }
                }
            }
            i += 1;
        }
        Some(comp)
    }

    /// Try to tetrahedralize the cavity made of live front faces `comp`; on success the
    /// tets are inserted and true is returned.
    pub(super) fn fill_cavity(&mut self, comp: &[u32]) -> bool {
        let verts = self.cavity_vertices(comp);
        let open: Vec<FaceRef> = comp
            .iter()
            .map(|&f| FaceRef {
                v: self.faces[f as usize].v,
                boundary: self.faces[f as usize].btri != u32::MAX,
            })
            .collect();
        let fixed = self.fixed_around(comp);
        // First on the cavity's own vertices, then with the kernel's centre as a Steiner
        // point, then with up to three Steiner points placed where a face sees no vertex.
        let kernel = self.kernel_point(&open);
        let passes: [(Option<P3>, usize); 3] = [(None, 0), (kernel, 1), (None, 3)];
        for (pre, max_steiner) in passes {
            if max_steiner == 1 && pre.is_none() {
                continue;
            }
            let pts = &self.pts;
            let base =
                move |i: u32| -> P3 { pts.get(i as usize).copied().unwrap_or([f64::NAN; 3]) };
            let me = &*self;
            let curved_ok = |t: [u32; 4], tp: &[P3; 4]| {
                me.p2_nodes(t, tp).map_or(true, |x| super::curved_valid(&x))
            };
            let mut vs = verts.clone();
            let mut steiner = Vec::new();
            if let Some(p) = pre {
                steiner.push(p);
                vs.push(STEINER);
            }
            let mut s = Search {
                base: &base,
                steiner,
                max_steiner,
                fixed: fixed.clone(),
                verts: vs,
                open: open.clone(),
                out: Vec::new(),
                nodes: 0,
                curved_ok: &curved_ok,
            };
            if s.dfs() {
                let tets = s.out;
                let ids: Vec<u32> = s.steiner.iter().map(|&p| self.new_point(p)).collect();
                for t in tets {
                    let t = t.map(|v| {
                        if v >= STEINER && ((v - STEINER) as usize) < ids.len() {
                            ids[(v - STEINER) as usize]
                        } else {
                            v
                        }
                    });
                    let base = [t[0], t[1], t[2]];
                    let Some(&fid) = self.face_map.get(&super::key3(base)) else {
                        continue;
                    };
                    self.insert_tet(t, fid, f64::NAN);
                }
                return true;
            }
        }
        false
    }

    /// The vertices of front faces `comp`, sorted.
    pub(super) fn cavity_vertices(&self, comp: &[u32]) -> Vec<u32> {
        let mut verts: Vec<u32> = comp
            .iter()
            .flat_map(|&f| self.faces[f as usize].v)
            .collect();
        verts.sort_unstable();
        verts.dedup();
        verts
    }

    /// The live front faces other than `comp`'s in the box of `comp`'s vertices: never to
    /// be crossed by what fills it.
    pub(super) fn fixed_around(&mut self, comp: &[u32]) -> Vec<FaceRef> {
        let pts: Vec<P3> = comp
            .iter()
            .flat_map(|&f| self.faces[f as usize].v)
            .map(|v| self.pts[v as usize])
            .collect();
        let mut bb = super::grid::Aabb::of(&pts);
        for d in 0..3 {
            let pad = 1e-9 * (bb.hi[d] - bb.lo[d]).abs().max(1.0);
            bb.lo[d] -= pad;
            bb.hi[d] += pad;
        }
        let faces = &self.faces;
        let mut ids = Vec::new();
        self.grid.query(&bb, |k| faces[k as usize].alive, &mut ids);
        ids.iter()
            .filter(|k| !comp.contains(k))
            .map(|&k| FaceRef {
                v: self.faces[k as usize].v,
                boundary: self.faces[k as usize].btri != u32::MAX,
            })
            .collect()
    }

    /// A point strictly inside every face's inner half-space (the Chebyshev centre of the
    /// cavity's kernel), if the kernel has an interior.
    fn kernel_point(&self, open: &[FaceRef]) -> Option<P3> {
        use microlp::{ComparisonOp, OptimizationDirection, Problem};
        let mut pr = Problem::new(OptimizationDirection::Maximize);
        let inf = f64::INFINITY;
        // Work relative to the first vertex for conditioning.
        let o = self.pts[open[0].v[0] as usize];
        let x = pr.add_var(0.0, (-inf, inf));
        let y = pr.add_var(0.0, (-inf, inf));
        let z = pr.add_var(0.0, (-inf, inf));
        let t = pr.add_var(1.0, (0.0, inf));
        for f in open {
            let p = f.v.map(|v| sub(self.pts[v as usize], o));
            let n = normalize(tri_normal(p[0], p[1], p[2]));
            // n . (q - p0) >= t   (inward normals)
            pr.add_constraint(
                [(x, n[0]), (y, n[1]), (z, n[2]), (t, -1.0)],
                ComparisonOp::Ge,
                dot(n, p[0]),
            );
        }
        let sol = pr.solve().ok()?.into_solution().ok()?;
        if sol.var_value(t) <= 0.0 {
            return None;
        }
        let q = add([sol.var_value(x), sol.var_value(y), sol.var_value(z)], o);
        // Confirm exactly: strictly inside every face.
        open.iter()
            .all(|f| {
                let p = f.v.map(|v| self.pts[v as usize]);
                orient3d(p[0], p[1], p[2], q) > 0
            })
            .then_some(q)
    }
}
