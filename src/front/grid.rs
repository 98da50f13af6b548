//! A hashed uniform grid of front faces, for the "which front faces are near this
//! candidate tetrahedron" query of the validity tests.
//!
//! Hand-written rather than a crate: faces come and go at every step, the query is a box,
//! and removal is lazy (dead ids are skipped and swept out when a cell gets dirty),
//! which a general R-tree crate would make slower than this ~100-line structure.

use crate::geom::vec3::P3;
use std::collections::HashMap;

/// Axis-aligned box.
#[derive(Clone, Copy, Debug)]
pub struct Aabb {
    /// Minimum corner.
    pub lo: P3,
    /// Maximum corner.
    pub hi: P3,
}

impl Aabb {
    /// The box of a set of points.
    pub fn of(pts: &[P3]) -> Aabb {
        let mut lo = pts[0];
        let mut hi = pts[0];
        for p in &pts[1..] {
            for d in 0..3 {
                lo[d] = lo[d].min(p[d]);
                hi[d] = hi[d].max(p[d]);
            }
        }
        Aabb { lo, hi }
    }
    /// Do the closed boxes overlap?
    #[inline]
    pub fn overlaps(&self, o: &Aabb) -> bool {
        (0..3).all(|d| self.lo[d] <= o.hi[d] && o.lo[d] <= self.hi[d])
    }
}

type Key = (i32, i32, i32);

/// Uniform hashed grid of face ids.
pub struct FaceGrid {
    inv: f64,
    origin: P3,
    cells: HashMap<Key, Vec<u32>>,
    stamp: Vec<u32>,
    epoch: u32,
}

impl FaceGrid {
    /// A grid with cubic cells of side `cell` anchored at `origin`.
    pub fn new(origin: P3, cell: f64) -> FaceGrid {
        FaceGrid {
            inv: 1.0 / cell,
            origin,
            cells: HashMap::new(),
            stamp: Vec::new(),
            epoch: 0,
        }
    }

    #[inline]
    fn key_range(&self, b: &Aabb) -> (Key, Key) {
        let k = |p: P3| -> Key {
            let f =
                |d: usize| (((p[d] - self.origin[d]) * self.inv).floor()).clamp(-1e9, 1e9) as i32;
            (f(0), f(1), f(2))
        };
        (k(b.lo), k(b.hi))
    }

    /// Insert face `id` with bounding box `b`.
    pub fn insert(&mut self, id: u32, b: &Aabb) {
        let (lo, hi) = self.key_range(b);
        for i in lo.0..=hi.0 {
            for j in lo.1..=hi.1 {
                for k in lo.2..=hi.2 {
                    self.cells.entry((i, j, k)).or_default().push(id);
                }
            }
        }
        if self.stamp.len() <= id as usize {
            self.stamp.resize(id as usize + 1, 0);
        }
    }

    /// Collect into `out` the ids of faces in cells overlapping `b` for which `alive(id)`
    /// holds (each id once). Dead ids found in visited cells are swept out.
    pub fn query(&mut self, b: &Aabb, alive: impl Fn(u32) -> bool, out: &mut Vec<u32>) {
        out.clear();
        self.epoch = self.epoch.wrapping_add(1);
        if self.epoch == 0 {
            self.stamp.iter_mut().for_each(|s| *s = 0);
            self.epoch = 1;
        }
        let (lo, hi) = self.key_range(b);
        // Guard against absurd ranges (a huge box on a fine grid): cap the cell count.
        let span = (hi.0 as i64 - lo.0 as i64 + 1)
            * (hi.1 as i64 - lo.1 as i64 + 1)
            * (hi.2 as i64 - lo.2 as i64 + 1);
        if span > 4096 {
            // Fall back to scanning every cell (rare: only for faces much larger than cells).
            for list in self.cells.values_mut() {
                list.retain(|&f| alive(f));
                for &f in list.iter() {
                    if self.stamp[f as usize] != self.epoch {
                        self.stamp[f as usize] = self.epoch;
                        out.push(f);
                    }
                }
            }
            return;
        }
        for i in lo.0..=hi.0 {
            for j in lo.1..=hi.1 {
                for k in lo.2..=hi.2 {
                    if let Some(list) = self.cells.get_mut(&(i, j, k)) {
                        let mut dead = 0;
                        for &f in list.iter() {
                            if !alive(f) {
                                dead += 1;
                                continue;
                            }
                            if self.stamp[f as usize] != self.epoch {
                                self.stamp[f as usize] = self.epoch;
                                out.push(f);
                            }
                        }
                        if dead * 2 > list.len() {
                            list.retain(|&f| alive(f));
                        }
                    }
                }
            }
        }
    }
}
