//! The front's face queue: smallest (tries, class, key, face, version) first.
//!
//! One binary heap per (tries, class) pair (tries 0..=3, class 0..=2), each ordered by
//! (key, face, version) packed into two integers: the same order as the tuple, with
//! 16-byte entries and integer comparisons instead of a 24-byte tuple compared field by
//! field (f64 keys by `total_cmp`). The heaps hold every face of a large front, so their
//! sifting is a visible share of the front's time at 1M tets.

use std::cmp::Reverse;
use std::collections::{BinaryHeap, VecDeque};

/// Largest number of tries a face is queued with.
pub const MAX_TRIES: u8 = 3;
/// Number of queue classes.
pub const CLASSES: u8 = 3;

/// An f64 as a u64 with the order of `f64::total_cmp`.
#[inline]
fn total_order_bits(x: f64) -> u64 {
    let b = x.to_bits() as i64;
    // total_cmp's transform (flip the magnitude bits of negatives), then the sign bit so
    // that unsigned comparison orders negatives first.
    ((b ^ (((b >> 63) as u64) >> 1) as i64) as u64) ^ (1 << 63)
}

/// The size class of a face size key (a squared length, see the front's `face_size`):
/// ⌊log₄ key⌋, i.e. classes of a factor 2 in edge length, read exactly from the float's
/// exponent bits (no libm call, so the same class on every platform). Faces of one class
/// pop oldest first (lowest id), which keeps consecutive steps next to each other. Keys
/// below the normal positive range (zero: a degenerate face) come before every class;
/// infinite and NaN keys stay after them.
#[inline]
pub fn size_class(key: f64) -> f64 {
    if !key.is_finite() {
        return key;
    }
    if key < f64::MIN_POSITIVE {
        return f64::NEG_INFINITY;
    }
    let e = ((key.to_bits() >> 52) & 0x7ff) as i64 - 1023;
    e.div_euclid(2) as f64
}

/// Number of heaps: one per (tries, class).
const HEAPS: usize = (MAX_TRIES as usize + 1) * CLASSES as usize;

/// Most runs per heap (see [`FaceQueue`]).
const MAX_RUNS: usize = 16;

/// The queue. Per (tries, class): a binary heap, and up to [`MAX_RUNS`] runs, each the
/// entries of one key pushed in increasing order. Most faces are pushed once, when they
/// are made, with ids that only grow, and the large inputs' size classes are few keys:
/// so nearly every entry lands at the end of a run, O(1), instead of sifting through a
/// heap of the whole front. A pop takes the smallest of the heap's top and the runs'
/// fronts, so the order is exactly the heap-only order.
#[derive(Default)]
pub struct FaceQueue {
    heaps: [BinaryHeap<Reverse<(u64, u64)>>; HEAPS],
    runs: [Vec<(u64, VecDeque<u64>)>; HEAPS],
}

impl FaceQueue {
    /// Queue face `id` (version `ver`) with `tries` (at most [`MAX_TRIES`]), `class`
    /// (below [`CLASSES`]) and `key`.
    #[inline]
    pub fn push(&mut self, tries: u8, class: u8, key: f64, id: u32, ver: u32) {
        debug_assert!(tries <= MAX_TRIES && class < CLASSES);
        let h = tries as usize * CLASSES as usize + class as usize;
        let (k, iv) = (total_order_bits(key), (id as u64) << 32 | ver as u64);
        let runs = &mut self.runs[h];
        match runs.iter().position(|r| r.0 == k) {
            Some(i) if runs[i].1.back().map_or(true, |&b| b <= iv) => runs[i].1.push_back(iv),
            None if runs.len() < MAX_RUNS => runs.push((k, VecDeque::from([iv]))),
            _ => self.heaps[h].push(Reverse((k, iv))),
        }
    }

    /// The smallest entry: (tries, face, version).
    #[inline]
    pub fn pop(&mut self) -> Option<(u8, u32, u32)> {
        for h in 0..HEAPS {
            // The smallest run front, then against the heap's top.
            let mut best: Option<(u64, u64, usize)> = None;
            for (i, r) in self.runs[h].iter().enumerate() {
                if let Some(&iv) = r.1.front() {
                    if best.map_or(true, |b| (r.0, iv) < (b.0, b.1)) {
                        best = Some((r.0, iv, i));
                    }
                }
            }
            let top = self.heaps[h].peek().map(|e| e.0);
            let iv = match (best, top) {
                (Some((k, iv, i)), t) if t.map_or(true, |t| (k, iv) < t) => {
                    self.runs[h][i].1.pop_front();
                    iv
                }
                (_, Some((_, iv))) => {
                    self.heaps[h].pop();
                    iv
                }
                _ => continue,
            };
            let tries = (h / CLASSES as usize) as u8;
            return Some((tries, (iv >> 32) as u32, iv as u32));
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    #[test]
    fn size_classes_are_factors_of_four() {
        assert_eq!(size_class(1.0), 0.0);
        assert_eq!(size_class(3.99), 0.0);
        assert_eq!(size_class(4.0), 1.0);
        assert_eq!(size_class(0.25), -1.0);
        assert_eq!(size_class(0.2499), -2.0);
        assert_eq!(size_class(0.0), f64::NEG_INFINITY);
        assert_eq!(size_class(f64::MIN_POSITIVE / 2.0), f64::NEG_INFINITY);
        assert_eq!(size_class(f64::INFINITY), f64::INFINITY);
        assert!(size_class(f64::NAN).is_nan());
        // Monotone: a smaller key never gets a larger class.
        let mut rng = rand::rngs::StdRng::seed_from_u64(3);
        for _ in 0..10_000 {
            let a: f64 = 10f64.powf(rng.random_range(-300.0..300.0));
            let b: f64 = a * rng.random_range(1.0..10.0);
            assert!(size_class(a) <= size_class(b), "{a} {b}");
            let c = size_class(a);
            assert!(4f64.powf(c) <= a * (1.0 + 1e-12) && a < 4f64.powf(c + 1.0) * (1.0 + 1e-12));
        }
    }

    #[test]
    fn pops_in_the_order_of_the_tuple() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(9);
        let mut q = FaceQueue::default();
        let mut reference = BinaryHeap::new();
        let keys = [0.0, -0.0, 1e-300, 0.5, 0.5, 3.0, 75.0, f64::INFINITY, -2.0];
        for i in 0..3000u32 {
            let tries = rng.random_range(0..=MAX_TRIES);
            let class = rng.random_range(0..CLASSES);
            let key = if rng.random_bool(0.5) {
                keys[rng.random_range(0..keys.len())]
            } else {
                rng.random_range(0.0..100.0)
            };
            let id = rng.random_range(0..500u32);
            let ver = rng.random_range(0..4u32);
            q.push(tries, class, key, id, ver);
            reference.push(Reverse((tries, class, TotalF64(key), id, ver, i)));
            // Interleave pops, as the front does.
            if rng.random_bool(0.3) {
                let Reverse((t, _, _, id, ver, _)) = reference.pop().unwrap();
                assert_eq!(q.pop(), Some((t, id, ver)));
            }
        }
        while let Some(Reverse((t, _, _, id, ver, _))) = reference.pop() {
            assert_eq!(q.pop(), Some((t, id, ver)));
        }
        assert_eq!(q.pop(), None);
    }

    /// f64 ordered by total_cmp (what the front's queue key was).
    #[derive(PartialEq)]
    struct TotalF64(f64);
    impl Eq for TotalF64 {}
    impl PartialOrd for TotalF64 {
        fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
            Some(self.cmp(o))
        }
    }
    impl Ord for TotalF64 {
        fn cmp(&self, o: &Self) -> std::cmp::Ordering {
            self.0.total_cmp(&o.0)
        }
    }
}
