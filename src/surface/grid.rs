//! A uniform grid over axis-aligned boxes: the broad phase of the intersection checks
//! and of the ray queries of the nesting test.
//!
//! Sparse: each (cell, box) registration is a sorted `(key, id)` pair, so memory follows
//! the registrations, not the grid's volume. The cell size starts at the mean box size and
//! doubles while the registrations would exceed 8 per box (a few huge triangles cannot
//! blow it up). Each overlapping pair is reported once: in the cell holding the minimum
//! corner of the two boxes' intersection. Keys are ordered (y, z, x) so that a row of
//! cells along +x is one contiguous key range.

use rayon::prelude::*;

use crate::geom::P3;

/// An axis-aligned box: (min corner, max corner).
pub(crate) type Aabb = [P3; 2];

/// Most cells per axis (keys pack 3 x 21 bits).
const MAX_DIM: u64 = 1 << 20;

/// The grid (see the module docs).
pub(crate) struct Grid {
    origin: P3,
    inv_h: f64,
    dims: [u64; 3],
    /// Box ids of all registrations, grouped by cell, ids ascending within a cell.
    items: Vec<u32>,
    /// Non-empty cells, sorted by key: (key, start, end) into `items`.
    cells: Vec<(u64, u32, u32)>,
    /// Per box, the cell indices of its min corner.
    lo: Vec<[u32; 3]>,
}

/// Closed boxes overlap.
#[inline]
pub(crate) fn overlap(a: &Aabb, b: &Aabb) -> bool {
    (0..3).all(|d| a[0][d] <= b[1][d] && b[0][d] <= a[1][d])
}

/// The bounding box of some points.
#[inline]
pub(crate) fn bbox<const N: usize>(p: [P3; N]) -> Aabb {
    let mut lo = p[0];
    let mut hi = p[0];
    for q in &p[1..] {
        for d in 0..3 {
            lo[d] = lo[d].min(q[d]);
            hi[d] = hi[d].max(q[d]);
        }
    }
    [lo, hi]
}

impl Grid {
    #[inline]
    fn idx(&self, v: f64, d: usize) -> u64 {
        let f = ((v - self.origin[d]) * self.inv_h).floor();
        if f.is_nan() || f <= 0.0 {
            0
        } else {
            (f as u64).min(self.dims[d] - 1)
        }
    }

    #[inline]
    fn key(ix: u64, iy: u64, iz: u64) -> u64 {
        (iy << 42) | (iz << 21) | ix
    }

    /// Builds the grid over `boxes` (finite coordinates).
    pub fn build(boxes: &[Aabb]) -> Grid {
        let mut g = Grid {
            origin: [0.0; 3],
            inv_h: 1.0,
            dims: [1; 3],
            items: Vec::new(),
            cells: Vec::new(),
            lo: Vec::new(),
        };
        if boxes.is_empty() {
            return g;
        }
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        let mut mean = 0.0;
        for b in boxes {
            let mut e = 0.0f64;
            for d in 0..3 {
                lo[d] = lo[d].min(b[0][d]);
                hi[d] = hi[d].max(b[1][d]);
                e = e.max(b[1][d] - b[0][d]);
            }
            mean += e;
        }
        mean /= boxes.len() as f64;
        let ext = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
        let max_ext = ext[0].max(ext[1]).max(ext[2]);
        let max_ext = if max_ext > 0.0 && max_ext.is_finite() {
            max_ext
        } else {
            1.0
        };
        let mut h = if mean > 0.0 && mean.is_finite() {
            mean
        } else {
            max_ext
        };
        h = h.max(max_ext / (MAX_DIM - 2) as f64);
        g.origin = lo;
        let budget = 8.0 * boxes.len() as f64 + 64.0;
        loop {
            g.inv_h = 1.0 / h;
            for (dim, e) in g.dims.iter_mut().zip(ext) {
                let n = (e * g.inv_h).floor();
                *dim = if n.is_finite() && n >= 0.0 {
                    (n as u64 + 1).min(MAX_DIM)
                } else {
                    1
                };
            }
            let regs: f64 = boxes.iter().map(|b| g.span(b).2 as f64).sum();
            if regs <= budget || h >= max_ext {
                break;
            }
            h *= 2.0;
        }
        let mut reg: Vec<(u64, u32)> = Vec::new();
        g.lo.reserve(boxes.len());
        for (id, b) in boxes.iter().enumerate() {
            let (l, u, _) = g.span(b);
            g.lo.push(l.map(|x| x as u32));
            for iy in l[1]..=u[1] {
                for iz in l[2]..=u[2] {
                    for ix in l[0]..=u[0] {
                        reg.push((Grid::key(ix, iy, iz), id as u32));
                    }
                }
            }
        }
        reg.par_sort_unstable();

        g.items = reg.iter().map(|r| r.1).collect();
        let mut i = 0;
        while i < reg.len() {
            let mut j = i + 1;
            while j < reg.len() && reg[j].0 == reg[i].0 {
                j += 1;
            }
            g.cells.push((reg[i].0, i as u32, j as u32));
            i = j;
        }
        g
    }

    /// Cell index ranges of a box and their product (number of cells).
    fn span(&self, b: &Aabb) -> ([u64; 3], [u64; 3], u64) {
        let l = [0, 1, 2].map(|d| self.idx(b[0][d], d));
        let u = [0, 1, 2].map(|d| self.idx(b[1][d], d));
        let n = (0..3).map(|d| u[d] - l[d] + 1).product();
        (l, u, n)
    }

    /// Visits every pair (i < j) of overlapping boxes exactly once, in parallel: each
    /// worker folds its pairs into a state made by `init` with `visit`, and the states are
    /// merged with `merge`. With an order-independent `merge` (e.g. a minimum) the result
    /// does not depend on the thread count.
    pub fn fold_pairs<T, I, V, M>(&self, boxes: &[Aabb], init: I, visit: V, merge: M) -> T
    where
        T: Send,
        I: Fn() -> T + Sync + Send,
        V: Fn(&mut T, u32, u32) + Sync + Send,
        M: Fn(T, T) -> T + Sync + Send,
    {
        self.cells
            .par_iter()
            .fold(&init, |mut state, &(key, s, e)| {
                let cell = [key & 0x1f_ffff, key >> 42, (key >> 21) & 0x1f_ffff].map(|x| x as u32);
                let ids = &self.items[s as usize..e as usize];
                for (k, &a) in ids.iter().enumerate() {
                    let ba = &boxes[a as usize];
                    let la = self.lo[a as usize];
                    for &b in &ids[k + 1..] {
                        if !overlap(ba, &boxes[b as usize]) {
                            continue;
                        }
                        // Only in the cell of the intersection's min corner (idx is
                        // monotone, so that cell is the max of the two min-corner cells).
                        let lb = self.lo[b as usize];
                        if (0..3).all(|d| la[d].max(lb[d]) == cell[d]) {
                            visit(&mut state, a, b);
                        }
                    }
                }
                state
            })
            .reduce(&init, merge)
    }

    /// Ids of the boxes that may meet the ray from `p` along +x: those registered in the
    /// row of cells through `p` from `p`'s cell on, each once. Every box whose closed
    /// (y, z) extent contains `p`'s (y, z) and whose max x >= `p.x` is among them.
    pub fn ray_x(&self, boxes: &[Aabb], p: P3, out: &mut Vec<u32>) {
        out.clear();
        let (ix, iy, iz) = (self.idx(p[0], 0), self.idx(p[1], 1), self.idx(p[2], 2));
        let k0 = Grid::key(ix, iy, iz);
        let k1 = Grid::key(self.dims[0] - 1, iy, iz);
        let start = self.cells.partition_point(|c| c.0 < k0);
        for &(key, s, e) in &self.cells[start..] {
            if key > k1 {
                break;
            }
            let cx = key & 0x1f_ffff;
            for &id in &self.items[s as usize..e as usize] {
                // Report each box in the first row cell it occupies.
                if self.idx(boxes[id as usize][0][0], 0).max(ix) == cx {
                    out.push(id);
                }
            }
        }
    }
}
