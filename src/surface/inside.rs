//! Which points a closed surface encloses: exact ray parity, as the shells' nesting
//! ([`super::orientation`]) is found, for many points at once.

use super::grid::{bbox, Aabb, Grid};
use super::orientation::ray_crosses;
use crate::geom::P3;

/// For each point of `pts`, whether the closed surface made of triangles `tris` (corner
/// positions; any orientation, any number of shells) encloses it: an odd number of
/// triangles crossed by the symbolically perturbed ray from it along +x. Exact for a
/// point off every triangle; a point on a triangle may be called either.
pub(crate) fn enclosed(tris: &[[P3; 3]], pts: &[P3]) -> Vec<bool> {
    let boxes: Vec<Aabb> = tris.iter().map(|t| bbox(*t)).collect();
    let grid = Grid::build(&boxes);
    let mut cand = Vec::new();
    pts.iter()
        .map(|&p| {
            grid.ray_x(&boxes, p, &mut cand);
            let crossed = cand
                .iter()
                .filter(|&&t| {
                    let [a, b, c] = tris[t as usize];
                    ray_crosses(p, a, b, c)
                })
                .count();
            crossed % 2 == 1
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit cube's 12 triangles (outward).
    fn cube() -> Vec<[P3; 3]> {
        let (pts, faces) = crate::geom::testutil::unit_cube();
        faces.iter().map(|f| f.map(|v| pts[v as usize])).collect()
    }

    /// Points on the lines of the cube's edges and diagonals (rays through its edges
    /// and corners) are still classified by the perturbed parity.
    #[test]
    fn points_inside_and_outside_a_cube() {
        let tris = cube();
        let pts = [
            [0.5, 0.5, 0.5],
            [0.25, 0.5, 0.75],
            [0.5, 0.5, 0.5 + 1e-9],
            [-0.5, 0.5, 0.5],
            [-0.5, 0.0, 0.0],
            [-0.5, 1.0, 1.0],
            [0.5, 1.5, 0.5],
            [0.5, 0.5, 1.5],
            [1.5, 0.5, 0.5],
            [0.5, 0.5, 0.999_999],
            [0.000_001, 0.999_999, 0.5],
        ];
        let got = enclosed(&tris, &pts);
        let want = [
            true, true, true, false, false, false, false, false, false, true, true,
        ];
        assert_eq!(got, want);
    }

    /// Two nested shells: the space between them is enclosed, the void inside is not.
    #[test]
    fn a_void_is_not_enclosed() {
        let outer = cube();
        let inner: Vec<[P3; 3]> = outer
            .iter()
            .map(|t| t.map(|p| p.map(|x| 0.25 + 0.5 * x)))
            .collect();
        let tris: Vec<[P3; 3]> = outer.into_iter().chain(inner).collect();
        let got = enclosed(&tris, &[[0.1, 0.1, 0.1], [0.5, 0.5, 0.5], [2.0, 0.5, 0.5]]);
        assert_eq!(got, [true, false, false]);
    }
}
