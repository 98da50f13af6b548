//! Gmsh element types: the number of nodes of each, so that elements curvetet does not
//! use (points, lines, quads, higher orders...) can be skipped, in binary files too.
//!
//! The table was dumped from Gmsh 4.8.4 itself (`gmsh.model.mesh.getElementProperties`
//! for types 1..200); types 34 and 35 (polygon, polyhedron) have no fixed node count and
//! are refused.

const TABLE: &[(i32, u16)] = &[
    (1, 2),
    (2, 3),
    (3, 4),
    (4, 4),
    (5, 8),
    (6, 6),
    (7, 5),
    (8, 3),
    (9, 6),
    (10, 9),
    (11, 10),
    (12, 27),
    (13, 18),
    (14, 14),
    (15, 1),
    (16, 8),
    (17, 20),
    (18, 15),
    (19, 13),
    (20, 9),
    (21, 10),
    (22, 12),
    (23, 15),
    (24, 15),
    (25, 21),
    (26, 4),
    (27, 5),
    (28, 6),
    (29, 20),
    (30, 35),
    (31, 56),
    (32, 22),
    (33, 28),
    (36, 16),
    (37, 25),
    (38, 36),
    (39, 12),
    (40, 16),
    (41, 20),
    (42, 28),
    (43, 36),
    (44, 45),
    (45, 55),
    (46, 66),
    (47, 49),
    (48, 64),
    (49, 81),
    (50, 100),
    (51, 121),
    (52, 18),
    (53, 21),
    (54, 24),
    (55, 27),
    (56, 30),
    (57, 24),
    (58, 28),
    (59, 32),
    (60, 36),
    (61, 40),
    (62, 7),
    (63, 8),
    (64, 9),
    (65, 10),
    (66, 11),
    (71, 84),
    (72, 120),
    (73, 165),
    (74, 220),
    (75, 286),
    (79, 34),
    (80, 40),
    (81, 46),
    (82, 52),
    (83, 58),
    (84, 1),
    (85, 1),
    (86, 1),
    (87, 1),
    (88, 1),
    (89, 1),
    (92, 64),
    (93, 125),
    (94, 216),
    (95, 343),
    (96, 512),
    (97, 729),
    (98, 1000),
    (99, 32),
    (100, 44),
    (101, 56),
    (102, 68),
    (103, 80),
    (104, 92),
    (105, 104),
    (118, 30),
    (119, 55),
    (120, 91),
    (121, 140),
    (122, 204),
    (123, 285),
    (124, 385),
    (125, 21),
    (126, 29),
    (127, 37),
    (128, 45),
    (129, 53),
    (130, 61),
    (131, 69),
    (132, 1),
    (137, 16),
];

/// Number of nodes of Gmsh element type `ty`, if known.
pub(crate) fn nodes_per_element(ty: i32) -> Option<usize> {
    TABLE
        .binary_search_by_key(&ty, |&(t, _)| t)
        .ok()
        .map(|i| TABLE[i].1 as usize)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_is_sorted_and_has_our_types() {
        assert!(TABLE.windows(2).all(|w| w[0].0 < w[1].0));
        assert_eq!(nodes_per_element(2), Some(3));
        assert_eq!(nodes_per_element(9), Some(6));
        assert_eq!(nodes_per_element(4), Some(4));
        assert_eq!(nodes_per_element(11), Some(10));
        assert_eq!(nodes_per_element(15), Some(1));
        assert_eq!(nodes_per_element(34), None);
        assert_eq!(nodes_per_element(-1), None);
    }
}
