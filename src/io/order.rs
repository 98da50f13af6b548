//! The one table of node-order conversions between curvetet's internal (Gmsh) order and
//! the orders of the file formats we read and write. Every reader and writer converts
//! through [`tri6_to`], [`tri6_from`], [`tet10_to`] and [`tet10_from`]; nothing else in the
//! crate permutes element nodes.
//!
//! Internal (Gmsh type 9 / type 11) order:
//! - 6-node triangle: corners 0, 1, 2, then mid nodes of edges (0,1), (1,2), (2,0);
//! - 10-node tetrahedron: corners 0..3, then mid nodes of edges (0,1), (1,2), (2,0), (3,0),
//!   (3,2), (3,1).
//!
//! Other orders, with the evidence for each:
//! - **VTK** (`VTK_QUADRATIC_TRIANGLE` = 22, `VTK_QUADRATIC_TETRA` = 24): the tetra's edge
//!   nodes are on (0,1), (1,2), (2,0), (0,3), (1,3), (2,3), i.e. Gmsh's last two swapped;
//!   the triangle agrees with Gmsh (VTK's vtkQuadraticTetra / vtkQuadraticTriangle
//!   documentation; meshio's gmsh reader applies exactly this swap, meshio issue #765).
//! - **medit** (`TrianglesP2`, `TetrahedraP2`): the format itself (libMeshb 7) fixes no
//!   high-order order and offers optional `*Ordering` sections; the convention of the
//!   format's authors (P.-L. George, "Génération automatique de maillages", the reference
//!   Rheolef documents for its P2 tetrahedron) puts the tetra's edge nodes on (0,1), (1,2),
//!   (2,0), (0,3), (1,3), (2,3) and the triangle's on (0,1), (1,2), (2,0). Gmsh writes
//!   medit files in that order: `MElement::writeMESH` swaps nodes 8 and 9 of a
//!   `MSH_TET_10` and nothing else, and Debian's gmsh 4.8.4 converting a type-11 tet
//!   (`gmsh t.msh -0 -o t.mesh`) was observed to write `... 5 8 9` for the msh's
//!   `... 5 9 8`, with those nodes at the midpoints of edges (1,3) and (2,3). (Gmsh's
//!   *reader* of .mesh does not swap back, so a .mesh round trip through Gmsh alone is
//!   not consistent; we follow the writer and the George convention.) We write no
//!   `*Ordering` section, and refuse to read files that carry one.

/// A node-order convention of a file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Convention {
    /// Gmsh (internal order): element types 9 and 11.
    Gmsh,
    /// VTK: cell types 22 (quadratic triangle) and 24 (quadratic tetra).
    Vtk,
    /// medit / libMeshb: `TrianglesP2`, `TetrahedraP2` (P.-L. George's order).
    Medit,
}

/// All conventions, for tests and tools.
pub const CONVENTIONS: [Convention; 3] = [Convention::Gmsh, Convention::Vtk, Convention::Medit];

/// For each convention, `TRI6[c][k]` is the internal (Gmsh) index of the format's node `k`.
const TRI6: [[usize; 6]; 3] = [
    [0, 1, 2, 3, 4, 5], // Gmsh
    [0, 1, 2, 3, 4, 5], // VTK
    [0, 1, 2, 3, 4, 5], // medit
];

/// For each convention, `TET10[c][k]` is the internal (Gmsh) index of the format's node `k`.
const TET10: [[usize; 10]; 3] = [
    [0, 1, 2, 3, 4, 5, 6, 7, 8, 9], // Gmsh
    [0, 1, 2, 3, 4, 5, 6, 7, 9, 8], // VTK
    [0, 1, 2, 3, 4, 5, 6, 7, 9, 8], // medit
];

/// The corner pairs each convention's triangle mid nodes (nodes 3..5) sit on; documents
/// the tables above and lets the tests derive them independently.
pub const TRI6_EDGES: [[[usize; 2]; 3]; 3] = [
    [[0, 1], [1, 2], [2, 0]],
    [[0, 1], [1, 2], [2, 0]],
    [[0, 1], [1, 2], [2, 0]],
];

/// The corner pairs each convention's tetrahedron mid nodes (nodes 4..9) sit on.
pub const TET10_EDGES: [[[usize; 2]; 6]; 3] = [
    [[0, 1], [1, 2], [2, 0], [3, 0], [3, 2], [3, 1]],
    [[0, 1], [1, 2], [2, 0], [0, 3], [1, 3], [2, 3]],
    [[0, 1], [1, 2], [2, 0], [0, 3], [1, 3], [2, 3]],
];

fn index(c: Convention) -> usize {
    match c {
        Convention::Gmsh => 0,
        Convention::Vtk => 1,
        Convention::Medit => 2,
    }
}

/// An internal (Gmsh-order) triangle's nodes in convention `c`'s order.
#[inline]
pub fn tri6_to<T: Copy>(c: Convention, t: &[T; 6]) -> [T; 6] {
    let p = &TRI6[index(c)];
    std::array::from_fn(|k| t[p[k]])
}

/// A triangle read in convention `c`'s order, in internal (Gmsh) order.
#[inline]
pub fn tri6_from<T: Copy>(c: Convention, t: &[T; 6]) -> [T; 6] {
    let p = &TRI6[index(c)];
    let mut out = *t;
    for k in 0..6 {
        out[p[k]] = t[k];
    }
    out
}

/// An internal (Gmsh-order) tetrahedron's nodes in convention `c`'s order.
#[inline]
pub fn tet10_to<T: Copy>(c: Convention, t: &[T; 10]) -> [T; 10] {
    let p = &TET10[index(c)];
    std::array::from_fn(|k| t[p[k]])
}

/// A tetrahedron read in convention `c`'s order, in internal (Gmsh) order.
#[inline]
pub fn tet10_from<T: Copy>(c: Convention, t: &[T; 10]) -> [T; 10] {
    let p = &TET10[index(c)];
    let mut out = *t;
    for k in 0..10 {
        out[p[k]] = t[k];
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::shape;

    /// The internal index of the mid node on corners {a, b}.
    fn internal_mid(edges: &[[usize; 2]], first: usize, a: usize, b: usize) -> usize {
        let k = edges
            .iter()
            .position(|e| (e[0] == a && e[1] == b) || (e[0] == b && e[1] == a))
            .expect("edge exists");
        first + k
    }

    #[test]
    fn tables_follow_from_edge_definitions() {
        // The internal edge lists must be the shape functions' own.
        assert_eq!(TRI6_EDGES[0], shape::TRI6_EDGES);
        assert_eq!(TET10_EDGES[0], shape::TET10_EDGES);
        for c in CONVENTIONS {
            let i = index(c);
            for k in 0..3 {
                assert_eq!(TRI6[i][k], k, "corners fixed");
                let [a, b] = TRI6_EDGES[i][k];
                assert_eq!(TRI6[i][3 + k], internal_mid(&shape::TRI6_EDGES, 3, a, b));
            }
            assert_eq!(TET10[i][..4], [0, 1, 2, 3], "corners fixed");
            for k in 0..6 {
                let [a, b] = TET10_EDGES[i][k];
                assert_eq!(TET10[i][4 + k], internal_mid(&shape::TET10_EDGES, 4, a, b));
            }
        }
    }

    #[test]
    fn to_and_from_are_inverse() {
        let t6 = [10u32, 11, 12, 13, 14, 15];
        let t10 = [0u32, 1, 2, 3, 4, 5, 6, 7, 8, 9];
        for c in CONVENTIONS {
            assert_eq!(tri6_from(c, &tri6_to(c, &t6)), t6);
            assert_eq!(tet10_from(c, &tet10_to(c, &t10)), t10);
        }
        assert_eq!(
            tet10_to(Convention::Vtk, &t10),
            [0, 1, 2, 3, 4, 5, 6, 7, 9, 8]
        );
    }
}
