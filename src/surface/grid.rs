//! The broad phase of the intersection checks and of the ray queries of the nesting
//! test: uniform grids over axis-aligned boxes, one per size level.
//!
//! Levels: the boxes are grouped by size, each level holding boxes within a factor
//! [`LEVEL_RATIO`] of each other, and each level gets its own uniform grid sized for its
//! boxes. One grid for all would size its cells for the mean box: a few huge triangles
//! around many tiny ones (a small dense sphere inside a large cube) then make cells so
//! large that every tiny triangle shares one cell, and the pairs grow quadratically.
//! Pairs within a level come from its grid; a box of a smaller level finds its partners in
//! each larger level's grid, whose cells are at least its size, so it looks at a few cells.
//!
//! Each uniform grid is sparse: each (cell, box) registration is a sorted `(key, id)`
//! pair, so memory follows the registrations, not the grid's volume. The cell size starts
//! at the mean box size and doubles while the registrations would exceed 8 per box. Each
//! overlapping pair is reported once: in the cell holding the minimum corner of the two
//! boxes' intersection. Keys are ordered (y, z, x) so that a row of cells along +x is one
//! contiguous key range.

use rayon::prelude::*;

use crate::geom::P3;

/// An axis-aligned box: (min corner, max corner).
pub(crate) type Aabb = [P3; 2];

/// Most cells per axis (keys pack 3 x 21 bits).
const MAX_DIM: u64 = 1 << 20;

/// One level's uniform grid (see the module docs).
struct Uniform {
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

impl Uniform {
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
    fn build(boxes: &[Aabb]) -> Uniform {
        let mut g = Uniform {
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
                        reg.push((Uniform::key(ix, iy, iz), id as u32));
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
    fn fold_pairs<T, I, V, M>(&self, boxes: &[Aabb], init: I, visit: V, merge: M) -> T
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

    /// Calls `f` with the id of every box of this grid that overlaps `q`, each once (in
    /// the cell of the intersection's min corner, as in [`Uniform::fold_pairs`]).
    fn overlapping(&self, boxes: &[Aabb], q: &Aabb, mut f: impl FnMut(u32)) {
        if self.cells.is_empty() {
            return;
        }
        let (l, u, _) = self.span(q);
        for iy in l[1]..=u[1] {
            for iz in l[2]..=u[2] {
                let k0 = Uniform::key(l[0], iy, iz);
                let start = self.cells.partition_point(|c| c.0 < k0);
                for &(key, s, e) in &self.cells[start..] {
                    let ix = key & 0x1f_ffff;
                    if key > Uniform::key(u[0], iy, iz) {
                        break;
                    }
                    let cell = [ix, iy, iz];
                    for &id in &self.items[s as usize..e as usize] {
                        let b = &boxes[id as usize];
                        if !overlap(q, b) {
                            continue;
                        }
                        let lb = self.lo[id as usize];
                        if (0..3).all(|d| l[d].max(lb[d] as u64) == cell[d]) {
                            f(id);
                        }
                    }
                }
            }
        }
    }

    /// Ids of the boxes that may meet the ray from `p` along +x, each once: those of the
    /// row of cells through `p` from `p`'s cell on whose closed (y, z) extent contains
    /// `p`'s (y, z) and whose max x >= `p.x` (the row holds many more).
    fn ray_x(&self, boxes: &[Aabb], p: P3, out: &mut Vec<u32>) {
        let (ix, iy, iz) = (self.idx(p[0], 0), self.idx(p[1], 1), self.idx(p[2], 2));
        let k0 = Uniform::key(ix, iy, iz);
        let k1 = Uniform::key(self.dims[0] - 1, iy, iz);
        let start = self.cells.partition_point(|c| c.0 < k0);
        for &(key, s, e) in &self.cells[start..] {
            if key > k1 {
                break;
            }
            let cx = key & 0x1f_ffff;
            for &id in &self.items[s as usize..e as usize] {
                let [lo, hi] = boxes[id as usize];
                let meets = hi[0] >= p[0]
                    && (lo[1]..=hi[1]).contains(&p[1])
                    && (lo[2]..=hi[2]).contains(&p[2]);
                // Report each box in the first row cell it occupies.
                if meets && self.idx(lo[0], 0).max(ix) == cx {
                    out.push(id);
                }
            }
        }
    }
}

/// Box sizes within one level differ by at most this factor.
const LEVEL_RATIO: f64 = 8.0;

/// One size level: its boxes (copies, in level order), their ids in the caller's slice
/// (`None`: the identity, when there is a single level), and its grid.
struct Level {
    boxes: Vec<Aabb>,
    ids: Option<Vec<u32>>,
    grid: Uniform,
}

impl Level {
    #[inline]
    fn id(&self, local: u32) -> u32 {
        self.ids.as_ref().map_or(local, |v| v[local as usize])
    }
}

/// The broad phase over boxes of any mix of sizes (see the module docs).
pub(crate) struct Grid {
    /// Levels by increasing box size; empty levels are left out.
    levels: Vec<Level>,
}

/// The largest extent of a box over the three axes.
fn extent(b: &Aabb) -> f64 {
    (0..3).map(|d| b[1][d] - b[0][d]).fold(0.0, f64::max)
}

impl Grid {
    /// Builds the levels and their grids over `boxes` (finite coordinates).
    pub fn build(boxes: &[Aabb]) -> Grid {
        let smallest = boxes
            .iter()
            .map(extent)
            .filter(|&e| e > 0.0)
            .fold(f64::INFINITY, f64::min);
        let level_of = |b: &Aabb| -> usize {
            let r = extent(b) / smallest;
            if r.is_finite() && r > 1.0 {
                (r.log2() / LEVEL_RATIO.log2()).floor().min(63.0) as usize
            } else {
                0
            }
        };
        let mut members: Vec<Vec<u32>> = Vec::new();
        for (i, b) in boxes.iter().enumerate() {
            let l = level_of(b);
            if members.len() <= l {
                members.resize_with(l + 1, Vec::new);
            }
            members[l].push(i as u32);
        }
        members.retain(|m| !m.is_empty());
        if members.len() <= 1 {
            return Grid {
                levels: vec![Level {
                    boxes: Vec::new(),
                    ids: None,
                    grid: Uniform::build(boxes),
                }],
            };
        }
        let levels = members
            .into_iter()
            .map(|ids| {
                let level_boxes: Vec<Aabb> = ids.iter().map(|&i| boxes[i as usize]).collect();
                Level {
                    grid: Uniform::build(&level_boxes),
                    boxes: level_boxes,
                    ids: Some(ids),
                }
            })
            .collect();
        Grid { levels }
    }

    /// The boxes of a level: the caller's for the single level, else the level's copies.
    fn boxes_of<'a>(&'a self, level: &'a Level, boxes: &'a [Aabb]) -> &'a [Aabb] {
        if level.ids.is_none() {
            boxes
        } else {
            &level.boxes
        }
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
        let ordered = |t: &mut T, a: u32, b: u32| visit(t, a.min(b), a.max(b));
        let mut acc = init();
        for (k, level) in self.levels.iter().enumerate() {
            let own = self.boxes_of(level, boxes);
            let within = level.grid.fold_pairs(
                own,
                &init,
                |t, a, b| ordered(t, level.id(a), level.id(b)),
                &merge,
            );
            acc = merge(acc, within);
            // This level's boxes against every larger level's grid.
            for larger in &self.levels[k + 1..] {
                let theirs = self.boxes_of(larger, boxes);
                let across = own
                    .par_iter()
                    .enumerate()
                    .fold(&init, |mut t, (a, q)| {
                        let a = level.id(a as u32);
                        larger
                            .grid
                            .overlapping(theirs, q, |b| ordered(&mut t, a, larger.id(b)));
                        t
                    })
                    .reduce(&init, &merge);
                acc = merge(acc, across);
            }
        }
        acc
    }

    /// Ids of the boxes that may meet the ray from `p` along +x: exactly those whose
    /// closed (y, z) extent contains `p`'s (y, z) and whose max x >= `p.x`, each once.
    pub fn ray_x(&self, boxes: &[Aabb], p: P3, out: &mut Vec<u32>) {
        out.clear();
        let mut local = Vec::new();
        for level in &self.levels {
            if level.ids.is_none() {
                level.grid.ray_x(boxes, p, out);
                continue;
            }
            local.clear();
            level.grid.ray_x(&level.boxes, p, &mut local);
            out.extend(local.iter().map(|&i| level.id(i)));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every overlapping pair, by brute force.
    fn brute(boxes: &[Aabb]) -> Vec<(u32, u32)> {
        let mut v = Vec::new();
        for i in 0..boxes.len() {
            for j in i + 1..boxes.len() {
                if overlap(&boxes[i], &boxes[j]) {
                    v.push((i as u32, j as u32));
                }
            }
        }
        v
    }

    fn pairs(boxes: &[Aabb]) -> Vec<(u32, u32)> {
        let g = Grid::build(boxes);
        let mut v = g.fold_pairs(
            boxes,
            Vec::new,
            |v: &mut Vec<(u32, u32)>, a, b| v.push((a, b)),
            |mut a, b| {
                a.extend(b);
                a
            },
        );
        v.sort_unstable();
        v
    }

    /// A deterministic pseudo-random sequence in [0, 1).
    fn lcg(state: &mut u64) -> f64 {
        *state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*state >> 11) as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn pairs_on_mixed_scales_are_exactly_the_overlapping_ones_once() {
        let mut st = 7;
        let mut boxes = Vec::new();
        // Boxes of sizes from 1e-4 to 1e3 around the origin, and some flat ones.
        for k in 0..600 {
            let size = 10f64.powf(-4.0 + 7.0 * lcg(&mut st));
            let c = [0, 1, 2].map(|_| (lcg(&mut st) - 0.5) * 2.0 * size.max(1.0));
            let mut h = [size / 2.0; 3];
            if k % 7 == 0 {
                h[k % 3] = 0.0;
            }
            boxes.push([
                [c[0] - h[0], c[1] - h[1], c[2] - h[2]],
                [c[0] + h[0], c[1] + h[1], c[2] + h[2]],
            ]);
        }
        let got = pairs(&boxes);
        assert_eq!(got, brute(&boxes));
        assert!(got.len() > 1000, "{}", got.len());
        // The ray query finds exactly the boxes the ray can meet, each once, through the
        // levels.
        let g = Grid::build(&boxes);
        let mut out = Vec::new();
        for _ in 0..50 {
            let p = [0, 1, 2].map(|_| (lcg(&mut st) - 0.5) * 2.0);
            g.ray_x(&boxes, p, &mut out);
            let mut sorted = out.clone();
            sorted.sort_unstable();
            sorted.dedup();
            assert_eq!(sorted.len(), out.len(), "a box reported twice");
            for (i, b) in boxes.iter().enumerate() {
                let hit = (1..3).all(|d| b[0][d] <= p[d] && p[d] <= b[1][d]) && b[1][0] >= p[0];
                assert_eq!(hit, out.contains(&(i as u32)), "box {i}, p {p:?}");
            }
        }
    }

    #[test]
    fn tiny_boxes_beside_huge_ones_do_not_share_one_cell() {
        // 5,000 tiny boxes in a ball of radius 1e-3 and 12 boxes of the faces of a cube
        // of side 1000: with one uniform grid the huge boxes made the cells so large that
        // all tiny boxes shared one (12.5 million candidate pairs); by level, the tiny
        // ones get their own grid.
        let mut st = 3;
        let mut boxes = Vec::new();
        for _ in 0..5_000 {
            let c = [0, 1, 2].map(|_| (lcg(&mut st) - 0.5) * 2e-3);
            let h = 2e-5;
            boxes.push([c.map(|x| x - h), c.map(|x| x + h)]);
        }
        for d in 0..3 {
            for side in [-500.0, 500.0] {
                for _ in 0..2 {
                    let mut lo = [-500.0; 3];
                    let mut hi = [500.0; 3];
                    lo[d] = side;
                    hi[d] = side;
                    boxes.push([lo, hi]);
                }
            }
        }
        let g = Grid::build(&boxes);
        let candidates: u64 = g
            .levels
            .iter()
            .flat_map(|l| &l.grid.cells)
            .map(|&(_, s, e)| ((e - s) as u64).pow(2) / 2)
            .sum();
        assert!(candidates < 200_000, "{candidates} candidate pairs");
        assert_eq!(pairs(&boxes), brute(&boxes));
    }
}
