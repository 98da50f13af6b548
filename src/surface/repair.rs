//! Repairs of an input surface that have one right answer, made (with a warning) unless
//! the caller asks for [`Repair::Strict`]:
//!
//! - **Unused nodes** (vertices no triangle uses) are dropped and the rest renumbered,
//!   keeping their order. Nothing refers to them, so nothing else changes.
//! - **Inconsistent orientation**: on a closed manifold surface (every edge used by exactly
//!   two triangles) each shell has exactly two consistent orientations. A breadth-first
//!   walk over edge adjacency flips a triangle whenever it runs a shared edge in the same
//!   direction as the triangle it was reached from (`consistent_flips`); the shell then
//!   agrees with its first triangle. Which of the two orientations is outward is decided
//!   afterwards, per shell, by the exact enclosed volume and nesting depth of
//!   [`orientation`](super::orientation) (the outer shell faces out, a cavity's shell
//!   faces into the cavity, i.e. always out of the material). A shell that cannot be made
//!   consistent (a non-orientable one) is left alone, and the topology check reports it.
//!
//! Anything else (open, non-manifold, self-intersecting, ...) has no unique repair and
//! stays an error. Both repairs run only where the strict checks would fail, so a clean
//! input goes through exactly as before: same nodes, same triangles, no warning.

use crate::error::Error;
use std::collections::VecDeque;

/// Whether building a [`Surface`](super::Surface) repairs what is unambiguous in its
/// input (see the [module docs](self)).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum Repair {
    /// Drop unused nodes and reorient inconsistently oriented shells, each with a warning
    /// (the default).
    #[default]
    Unambiguous,
    /// Refuse both, as [`UnusedNode`](crate::SurfaceDefect::UnusedNode) and
    /// [`InconsistentOrientation`](crate::SurfaceDefect::InconsistentOrientation) errors
    /// (the command line's `--strict`). A consistently inside-out surface is still
    /// flipped with a warning, as it always was.
    Strict,
}

impl Repair {
    /// Are repairs allowed?
    pub fn allowed(self) -> bool {
        self == Repair::Unambiguous
    }
}

/// What the repairs before the final checks did, carried into the [`Surface`]'s warnings.
///
/// [`Surface`]: super::Surface
#[derive(Debug, Clone, Default)]
pub(crate) struct Done {
    /// Nodes dropped because no triangle used them, of how many, and what the input
    /// calls them ("nodes", "vertices").
    dropped: Option<(usize, usize, &'static str)>,
    /// Per triangle, whether the consistency walk flipped it (empty: none was).
    pub flipped: Vec<bool>,
}

impl Done {
    /// Record that `n` of `total` nodes (called `what`) were dropped.
    pub fn record_dropped(&mut self, n: usize, total: usize, what: &'static str) {
        self.dropped = Some((n, total, what));
    }

    /// The warning for the dropped nodes, if any were.
    pub fn dropped_warning(&self) -> Option<String> {
        self.dropped.map(|(n, total, what)| {
            format!(
                "{n} of {total} {what} used by no triangle: dropped, the others renumbered \
                 (`--strict` refuses this)"
            )
        })
    }

    /// What [`DroppedNote::explain`] needs to say about the dropped nodes.
    pub fn dropped_note(&self) -> DroppedNote {
        DroppedNote(self.dropped.map(|(n, _, what)| (n, what)))
    }

    /// Record the flips `f` (one flag per triangle) on top of earlier ones.
    pub fn add_flips(&mut self, f: &[bool]) {
        if self.flipped.is_empty() {
            self.flipped = f.to_vec();
        } else {
            for (a, &b) in self.flipped.iter_mut().zip(f) {
                *a ^= b;
            }
        }
    }
}

/// How many nodes were dropped, and what the input calls them, if any were.
#[derive(Debug, Clone, Copy)]
pub(crate) struct DroppedNote(Option<(usize, &'static str)>);

impl DroppedNote {
    /// A surface error found after unused nodes were dropped names nodes by their new
    /// numbers: say so, so that the numbers are not taken for the file's.
    pub fn explain(self, e: Error) -> Error {
        match (self.0, e) {
            (Some((n, what)), Error::InvalidSurface { kind, msg }) => {
                let note = format!(
                    " ({what} numbered after dropping the {n} that no triangle uses; \
                     `--strict` keeps the input's numbers)"
                );
                let msg = if msg.ends_with(&note) {
                    msg
                } else {
                    msg + &note
                };
                Error::InvalidSurface { kind, msg }
            }
            (_, e) => e,
        }
    }
}

/// A triangle with its orientation reversed: corners (c0, c1, c2) become (c0, c2, c1),
/// and for a 6-node triangle the mid nodes follow their edges, [c0, c1, c2, m01, m12,
/// m20] becoming [c0, c2, c1, m20, m12, m01].
pub(crate) fn flip<const N: usize>(t: &mut [u32; N]) {
    t.swap(1, 2);
    if N == 6 {
        t.swap(3, 5);
    }
}

/// The warning for reoriented triangles.
pub(crate) fn reoriented_warning(
    flipped: usize,
    total: usize,
    shells: usize,
    n_shells: usize,
) -> String {
    format!(
        "orientation was inconsistent: flipped {flipped} of {total} triangles in {shells} of \
         {n_shells} shell(s), so that every shell faces out of the solid (a cavity's shell \
         into the cavity) (`--strict` refuses this)"
    )
}

/// `nodes` and `tris` without the nodes no triangle uses (order kept, indices
/// renumbered), and how many were dropped; `None` when every node is used or some index
/// is out of range (which the index check reports).
pub(crate) fn drop_unused<T: Copy, const N: usize>(
    nodes: &[T],
    tris: &[[u32; N]],
) -> Option<(Vec<T>, Vec<[u32; N]>, usize)> {
    let mut used = vec![false; nodes.len()];
    for t in tris {
        for &v in t {
            *used.get_mut(v as usize)? = true;
        }
    }
    let dropped = used.iter().filter(|u| !**u).count();
    if dropped == 0 {
        return None;
    }
    let mut map = vec![u32::MAX; nodes.len()];
    let mut kept = Vec::with_capacity(nodes.len() - dropped);
    for (i, p) in nodes.iter().enumerate() {
        if used[i] {
            map[i] = kept.len() as u32;
            kept.push(*p);
        }
    }
    let tris = tris.iter().map(|t| t.map(|v| map[v as usize])).collect();
    Some((kept, tris, dropped))
}

/// Per triangle, whether to flip it so that every shell is consistently oriented (each
/// shell keeps the orientation of its lowest triangle). `None` when some edge is not
/// used by exactly two triangles (not a closed manifold surface: nothing to decide) or a
/// shell is non-orientable. Only corners (the first three nodes) are looked at.
pub(crate) fn consistent_flips<const N: usize>(tris: &[[u32; N]]) -> Option<Vec<bool>> {
    let rec = super::topology::edge_uses(tris);
    // Does the use r run its edge from the smaller corner to the larger?
    let forward = |r: &(u32, u32, u32, u8)| tris[r.2 as usize][r.3 as usize] == r.0;
    // Per triangle, up to three (neighbour, same direction) pairs.
    let mut adj: Vec<[(u32, bool); 3]> = vec![[(u32::MAX, false); 3]; tris.len()];
    let mut fill = vec![0u8; tris.len()];
    for g in rec.chunk_by(|x, y| x.0 == y.0 && x.1 == y.1) {
        let [r0, r1] = g else {
            return None;
        };
        let same = forward(r0) == forward(r1);
        for (r, o) in [(r0, r1), (r1, r0)] {
            let t = r.2 as usize;
            adj[t][fill[t] as usize] = (o.2, same);
            fill[t] += 1;
        }
    }
    let mut flip = vec![false; tris.len()];
    let mut seen = vec![false; tris.len()];
    let mut queue = VecDeque::new();
    for s in 0..tris.len() {
        if seen[s] {
            continue;
        }
        seen[s] = true;
        queue.push_back(s);
        while let Some(t) = queue.pop_front() {
            for &(n, same) in &adj[t][..fill[t] as usize] {
                let want = flip[t] ^ same;
                let n = n as usize;
                if !seen[n] {
                    seen[n] = true;
                    flip[n] = want;
                    queue.push_back(n);
                } else if flip[n] != want {
                    return None; // non-orientable
                }
            }
        }
    }
    Some(flip)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// The tetrahedron (0, 1, 2, 3), outward.
    const TET: [[u32; 3]; 4] = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];

    #[test]
    fn flips_make_a_shell_consistent() {
        let mut tris = TET.to_vec();
        flip(&mut tris[2]);
        let f = consistent_flips(&tris).expect("orientable");
        assert_eq!(f, vec![false, false, true, false]);
        // Consistent already: nothing to flip.
        assert_eq!(consistent_flips(&TET), Some(vec![false; 4]));
        // The lowest triangle of the shell decides: here the three others flip.
        let mut tris = TET.to_vec();
        flip(&mut tris[0]);
        assert_eq!(consistent_flips(&tris), Some(vec![false, true, true, true]));
    }

    #[test]
    fn open_or_non_manifold_is_left_alone() {
        assert_eq!(consistent_flips(&TET[..3]), None);
        let mut tris = TET.to_vec();
        tris.push([0, 1, 4]);
        tris.push([0, 4, 1]);
        assert_eq!(consistent_flips(&tris), None);
    }

    /// The 6-vertex projective plane: closed, every edge used twice, non-orientable.
    pub(crate) const RP2: [[u32; 3]; 10] = [
        [0, 1, 2],
        [0, 2, 3],
        [0, 3, 4],
        [0, 4, 5],
        [0, 5, 1],
        [1, 2, 4],
        [2, 3, 5],
        [3, 4, 1],
        [4, 5, 2],
        [5, 1, 3],
    ];

    #[test]
    fn a_non_orientable_surface_is_left_alone() {
        assert_eq!(consistent_flips(&RP2), None);
    }

    #[test]
    fn p2_flip_moves_mid_nodes_with_their_edges() {
        let mut t = [0, 1, 2, 10, 12, 20];
        flip(&mut t);
        assert_eq!(t, [0, 2, 1, 20, 12, 10]);
        let mut t = [0, 1, 2];
        flip(&mut t);
        assert_eq!(t, [0, 2, 1]);
    }

    #[test]
    fn unused_nodes_are_dropped_in_order() {
        let nodes = [10.0, 11.0, 12.0, 13.0, 14.0];
        let tris = vec![[0u32, 2, 4]];
        let (n, t, d) = drop_unused(&nodes, &tris).expect("two unused");
        assert_eq!((n, t, d), (vec![10.0, 12.0, 14.0], vec![[0, 1, 2]], 2));
        assert!(drop_unused(&nodes[..3], &[[0u32, 1, 2]]).is_none());
        assert!(drop_unused(&nodes[..3], &[[0u32, 1, 7]]).is_none());
    }
}
