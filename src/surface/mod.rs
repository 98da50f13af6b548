//! The input side: the P2 surface model and its checks.
//!
//! [`Surface::new`] is the only way to build a [`Surface`]; it runs every check below, in
//! this order (cheap and fundamental first), and returns the first failure as
//! [`Error::InvalidSurface`] with a [`SurfaceDefect`] kind and a message naming the
//! triangle (0-based index and corner nodes), edge (its two nodes) or node (index and
//! coordinates):
//!
//! 1. [`indices`]: no triangles ([`Empty`](SurfaceDefect::Empty)); a node index past the
//!    end ([`IndexOutOfRange`](SurfaceDefect::IndexOutOfRange)); a triangle using a node
//!    twice among its six ([`RepeatedNode`](SurfaceDefect::RepeatedNode)).
//! 2. [`coords`]: NaN/Inf ([`NonFiniteCoordinate`](SurfaceDefect::NonFiniteCoordinate));
//!    the range the exact predicates need ([`CoordinateRange`](SurfaceDefect::CoordinateRange),
//!    limits in [`coords::MAX_ABS_COORDINATE`] and friends).
//! 3. Unused nodes ([`UnusedNode`](SurfaceDefect::UnusedNode); dropped with a warning
//!    before the coordinate checks unless [`Repair::Strict`], see [`repair`]), then
//!    identical coordinates ([`DuplicateNode`](SurfaceDefect::DuplicateNode), by sorting).
//! 4. [`topology`]: the corner-edge rule (see there) — non-manifold edges, open edges,
//!    edges used twice in one direction (each shell made consistent with a warning unless
//!    [`Repair::Strict`]), mid-node sharing; then one fan per vertex.
//! 5. [`geometry`]: exactly collinear corners; a mid node more than an edge length from
//!    its edge's midpoint ([`MidNodeMismatch`](SurfaceDefect::MidNodeMismatch)); folded
//!    curved triangles (order-6 lattice).
//! 6. [`intersect`]: exact self-intersection of the chord triangles, then of the four flat
//!    sub-triangles of every curved triangle (both are errors; see there why).
//! 7. [`orientation`]: per shell, the exact sign of the enclosed chord volume and the
//!    nesting depth (exact ray parity); an all-inward surface is flipped with a warning;
//!    in a mixed one the wrong shells are flipped with a warning (an error under
//!    [`Repair::Strict`]).
//!
//! A *linear* surface (3-node triangles, from STL/OFF/OBJ/PLY) becomes a P2 surface
//! through [`curve`] ([`Surface::from_linear`]): the same checks on its flat triangles,
//! then mid nodes on a smooth reconstruction, then `Surface::new`.

pub mod coords;
pub mod curve;
pub mod demo;
mod describe;
mod exact_sum;
pub mod geometry;
mod grid;
pub mod indices;
pub(crate) mod inside;
pub mod intersect;
pub mod measure;
pub mod orientation;
pub mod regions;
pub mod repair;
pub mod topology;

#[cfg(test)]
mod tests;

use std::collections::HashMap;

use crate::error::{Error, Result, SurfaceDefect};
use crate::geom::P3;

pub use repair::Repair;
pub use topology::SurfaceEdge;

/// Surfaces where more than one triangle in this many is poorly shaped
/// ([`geometry::POOR_ASPECT_RATIO`]) get a warning: 1 % (the hinge has 2 of 1,960; raw
/// marching-cubes surfaces 4-11 %).
pub const POOR_SHAPE_WARN_ONE_IN: usize = 100;

/// The warning recorded when an inside-out surface was flipped.
pub const FLIPPED_WARNING: &str = "orientation was inward; flipped";

/// Most triangles a surface may have: sub-triangle ids (4 per triangle) must fit in `u32`.
pub const MAX_TRIANGLES: usize = 1 << 29;

/// A closed quadratic (6-node) triangle surface: the input of the mesher.
///
/// Node order per triangle (Gmsh's): corners 0, 1, 2, then the mid-edge nodes of edges
/// (0,1), (1,2), (2,0). Triangles are oriented with outward normals (right-hand rule).
/// Build one with [`Surface::new`], which runs every check; the fields are read-only
/// thereafter so a `Surface` in hand is always a valid one.
#[derive(Debug, Clone)]
pub struct Surface {
    nodes: Vec<P3>,
    tris: Vec<[u32; 6]>,
    tags: Vec<i32>,
    /// The volume's tag and the group names, for the writers.
    groups: crate::io::Groups,
    warnings: Vec<String>,
    /// Sorted corner node ids.
    corners: Vec<u32>,
    /// Corner edges sorted by `nodes` (smaller id first).
    edges: Vec<SurfaceEdge>,
    /// Per triangle, the neighbour across local edge k (corners k -> k+1).
    neighbors: Vec<[u32; 3]>,
    /// Per triangle, its shell (connected component), numbered by lowest triangle.
    shell: Vec<u32>,
    shell_count: usize,
    /// The mid nodes are curvetet's own: the surface was curved from a linear one
    /// ([`curve::curve_linear`]), whose boundary is the straight edges. The mesher may put a
    /// mid node back on its chord where a curved boundary element cannot be certified.
    chords_allowed: bool,
}

impl Surface {
    /// Checks a P2 surface and builds it.
    ///
    /// `nodes` are coordinates; `tris` are 6-node triangles (0-based node indices, Gmsh
    /// order); `tags` gives one tag per triangle, or is empty (all tags 0). Runs every
    /// check listed in the [module docs](self) and returns the first failure; a
    /// consistently inward surface is flipped (see [`FLIPPED_WARNING`]). Unused nodes are
    /// dropped and inconsistently oriented shells reoriented, with a warning
    /// ([`repair`]); [`Surface::new_with_repair`] with [`Repair::Strict`] refuses them.
    pub fn new(nodes: Vec<P3>, tris: Vec<[u32; 6]>, tags: Vec<i32>) -> Result<Surface> {
        Surface::new_with_repair(nodes, tris, tags, Repair::Unambiguous)
    }

    /// [`Surface::new`], with the unambiguous repairs ([`repair`]) allowed or refused.
    pub fn new_with_repair(
        nodes: Vec<P3>,
        tris: Vec<[u32; 6]>,
        tags: Vec<i32>,
        repair: Repair,
    ) -> Result<Surface> {
        Surface::build(nodes, tris, tags, repair, repair::Done::default())
    }

    /// [`Surface::new_with_repair`] after repairs `done` earlier (by the linear checks),
    /// so that one warning tells all.
    pub(crate) fn build(
        mut nodes: Vec<P3>,
        mut tris: Vec<[u32; 6]>,
        tags: Vec<i32>,
        repair: Repair,
        mut done: repair::Done,
    ) -> Result<Surface> {
        let tags = if tags.is_empty() {
            vec![0; tris.len()]
        } else if tags.len() != tris.len() {
            return Err(Error::InvalidArgument(format!(
                "{} tags for {} triangles (give one tag per triangle, or none)",
                tags.len(),
                tris.len()
            )));
        } else {
            tags
        };
        if tris.len() > MAX_TRIANGLES {
            return Err(Error::InvalidArgument(format!(
                "{} triangles: at most {MAX_TRIANGLES} are supported",
                tris.len()
            )));
        }
        if nodes.len() > u32::MAX as usize {
            return Err(Error::InvalidArgument(format!(
                "{} nodes: node indices are u32",
                nodes.len()
            )));
        }
        indices::check_indices(nodes.len(), &tris)?;
        if repair.allowed() {
            if let Some((kept, renumbered, dropped)) = repair::drop_unused(&nodes, &tris) {
                done.record_dropped(dropped, nodes.len(), "nodes");
                (nodes, tris) = (kept, renumbered);
            }
        }
        let dropped = done.dropped_note();
        Surface::checked(nodes, tris, tags, repair, done).map_err(|e| dropped.explain(e))
    }

    /// The checks of [`Surface::build`] after the indices (and the dropping of unused
    /// nodes).
    fn checked(
        nodes: Vec<P3>,
        mut tris: Vec<[u32; 6]>,
        tags: Vec<i32>,
        repair: Repair,
        mut done: repair::Done,
    ) -> Result<Surface> {
        coords::check_coordinates(&nodes)?;
        indices::check_unused(nodes.len(), &tris, &nodes)?;
        coords::check_duplicates(&nodes)?;
        let topo = match topology::Topology::build(&nodes, &tris) {
            // Every edge is used twice (open and non-manifold edges are reported first),
            // some in the same direction: make each shell consistent, if it can be.
            Err(e)
                if repair.allowed()
                    && e.surface_defect() == Some(SurfaceDefect::InconsistentOrientation) =>
            {
                let Some(flips) = repair::consistent_flips(&tris) else {
                    return Err(e);
                };
                for (t, &f) in tris.iter_mut().zip(&flips) {
                    if f {
                        repair::flip(t);
                    }
                }
                done.add_flips(&flips);
                topology::Topology::build(&nodes, &tris)?
            }
            r => r?,
        };
        geometry::check_degenerate(&nodes, &tris)?;
        geometry::check_mid_offsets(&nodes, &tris)?;
        geometry::check_folded(&nodes, &tris)?;
        intersect::check_intersections(&nodes, &tris)?;
        let mut warnings = Vec::new();
        warnings.extend(done.dropped_warning());
        let mut neighbors = topo.neighbors;
        let mut edges = topo.edges;
        let n_shells = topo.shell_count;
        let shell_flipped = match orientation::orient_shells(
            &nodes,
            &tris,
            &topo.shell,
            n_shells,
            repair.allowed(),
        )? {
            orientation::Shells::Outward => vec![false; n_shells],
            orientation::Shells::Inward => {
                orientation::flip_all(&mut tris, &mut neighbors, &mut edges);
                vec![true; n_shells]
            }
            orientation::Shells::Wrong(wrong) => {
                orientation::flip_shells(
                    &mut tris,
                    &mut neighbors,
                    &mut edges,
                    &topo.shell,
                    &wrong,
                );
                wrong
            }
        };
        if done.flipped.is_empty() && shell_flipped.iter().all(|&f| f) {
            warnings.push(FLIPPED_WARNING.to_string());
        } else if !done.flipped.is_empty() || shell_flipped.iter().any(|&f| f) {
            // Net flips: the consistency walk's, undone or not by its shell's flip.
            let mut per_shell = vec![0usize; n_shells];
            for (t, &s) in topo.shell.iter().enumerate() {
                let walked = done.flipped.get(t).copied().unwrap_or(false);
                if walked != shell_flipped[s as usize] {
                    per_shell[s as usize] += 1;
                }
            }
            warnings.push(repair::reoriented_warning(
                per_shell.iter().sum(),
                tris.len(),
                per_shell.iter().filter(|&&n| n > 0).count(),
                n_shells,
            ));
        }
        let shape = geometry::triangle_shape(&nodes, &tris);
        let (poor, worst) = (shape.poor, shape.worst);
        if poor * POOR_SHAPE_WARN_ONE_IN > tris.len() {
            warnings.push(format!(
                "{poor} of {} triangles have an aspect ratio above {} (worst {worst:.0}): the \
                 advancing front may not close on them; smooth (`--smooth 10`) or remesh a \
                 surface from image segmentation",
                tris.len(),
                geometry::POOR_ASPECT_RATIO
            ));
        }
        if shape.elongated() {
            warnings.push(format!(
                "most triangles are elongated (median aspect ratio {:.1}, above {}): the \
                 advancing front may not close on them; remesh the surface with more \
                 isotropic triangles",
                shape.median,
                geometry::ELONGATED_MEDIAN_ASPECT_RATIO
            ));
        }
        Ok(Surface {
            nodes,
            tris,
            tags,
            groups: crate::io::Groups::default(),
            warnings,
            corners: topo.corners,
            edges,
            neighbors,
            shell: topo.shell,
            shell_count: topo.shell_count,
            chords_allowed: false,
        })
    }

    /// Whether a mid node may go back on its chord (see [`Surface::with_chords_allowed`]).
    pub(crate) fn chords_allowed(&self) -> bool {
        self.chords_allowed
    }

    /// Mark the mid nodes as curvetet's own (a surface curved from a linear one): where
    /// a curved boundary element cannot be certified, the mesher may straighten its
    /// boundary edges back to the input's chords.
    pub(crate) fn with_chords_allowed(mut self) -> Surface {
        self.chords_allowed = true;
        self
    }

    /// Nodes (corners and mid-edge nodes).
    pub fn nodes(&self) -> &[P3] {
        &self.nodes
    }
    /// 6-node triangles, 0-based, outward.
    pub fn triangles(&self) -> &[[u32; 6]] {
        &self.tris
    }
    /// One tag per triangle (Gmsh physical or entity tag; 0 when none).
    pub fn tags(&self) -> &[i32] {
        &self.tags
    }

    /// The volume's tag and the group names the mesh of this surface is written with
    /// (default: volume [`crate::io::VOLUME_TAG`], no names).
    pub fn groups(&self) -> &crate::io::Groups {
        &self.groups
    }

    /// This surface with the volume tag and group names `groups` (as read from its file
    /// by [`crate::io::read_surface`]).
    pub fn with_groups(mut self, groups: crate::io::Groups) -> Surface {
        self.groups = groups;
        self
    }
    /// Warnings raised while checking (e.g. [`FLIPPED_WARNING`]).
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Corner (vertex) node ids, sorted. The mesher's candidate points on the boundary.
    pub fn corner_nodes(&self) -> &[u32] {
        &self.corners
    }

    /// Is `node` a corner of some triangle (rather than a mid-edge node)?
    pub fn is_corner(&self, node: u32) -> bool {
        self.corners.binary_search(&node).is_ok()
    }

    /// Mid-edge node ids, sorted (every node is either a corner or a mid node).
    pub fn mid_nodes(&self) -> Vec<u32> {
        let mut m: Vec<u32> = self.edges.iter().map(|e| e.mid).collect();
        m.sort_unstable();
        m
    }

    /// Corner edges, sorted by their node pair (smaller id first): each with its mid
    /// node and its two triangles. Binary-search it, or use [`Surface::mid_node`].
    pub fn edges(&self) -> &[SurfaceEdge] {
        &self.edges
    }

    /// The mid node of corner edge (a, b) in either order, if it is an edge.
    pub fn mid_node(&self, a: u32, b: u32) -> Option<u32> {
        let key = [a.min(b), a.max(b)];
        self.edges
            .binary_search_by(|e| e.nodes.cmp(&key))
            .ok()
            .map(|i| self.edges[i].mid)
    }

    /// The corner edge -> mid node map as a `HashMap` keyed by `(min, max)` node ids.
    pub fn edge_mid_map(&self) -> HashMap<(u32, u32), u32> {
        self.edges
            .iter()
            .map(|e| ((e.nodes[0], e.nodes[1]), e.mid))
            .collect()
    }

    /// Per triangle, the neighbouring triangle across local edge k (corners k -> k+1).
    pub fn neighbors(&self) -> &[[u32; 3]] {
        &self.neighbors
    }

    /// Per triangle, the id of its shell (connected component through edges); shells are
    /// numbered in order of their lowest triangle.
    pub fn shell_ids(&self) -> &[u32] {
        &self.shell
    }

    /// Number of shells (1 for a simple body; more for cavities or separate bodies).
    pub fn shell_count(&self) -> usize {
        self.shell_count
    }

    /// Volume enclosed by the curved P2 surface (divergence theorem, exact for P2 up to
    /// rounding: the integrand is a degree-4 polynomial).
    pub fn volume(&self) -> f64 {
        measure::curved_volume(&self.nodes, &self.tris)
    }

    /// Volume enclosed by the chord (corner-only) triangles
    /// ([`enclosed_volume_linear`](crate::geom::quadrature::enclosed_volume_linear)).
    pub fn chord_volume(&self) -> f64 {
        crate::geom::quadrature::enclosed_volume_linear(&self.nodes, &self.tris)
    }

    /// Smallest cosine between the curved normal and the chord normal over all
    /// triangles, on the order-6 lattice (1 for flat triangles; > 0 since checked).
    pub fn min_normal_cosine(&self) -> f64 {
        geometry::min_normal_cosine(&self.nodes, &self.tris)
    }

    /// Takes the surface apart: (nodes, triangles, tags).
    pub fn into_parts(self) -> (Vec<P3>, Vec<[u32; 6]>, Vec<i32>) {
        (self.nodes, self.tris, self.tags)
    }
}
