//! Coordinate checks: finiteness, the range within which the exact predicates are exact,
//! and duplicate nodes (by sorting, O(n log n)).
//!
//! Why a range: Shewchuk's adaptive predicates (the `robust` crate) are exact only when no
//! intermediate product overflows or underflows. Orientation determinants are cubic in
//! coordinate differences, and their exact stages multiply round-off tails, which are
//! about 2^-53 times the smallest nonzero coordinates involved. With every coordinate at
//! most [`MAX_ABS_COORDINATE`] (1e30 ≈ 2^100, cubes ≈ 2^303) nothing overflows; with every
//! nonzero coordinate at least [`MIN_ABS_NONZERO_COORDINATE`] (1e-60 ≈ 2^-199, tail
//! cubes times 2^-53 ≈ 2^-806 > 2^-1022) nothing underflows. A model whose bounding-box
//! diagonal is below [`MIN_BOX_DIAGONAL`] is rejected as well: it is almost surely in the
//! wrong unit, and metric tolerances relative to its size would underflow.

use rayon::prelude::*;

use super::describe;
use crate::error::{Error, Result, SurfaceDefect};
use crate::geom::P3;

/// Largest admitted |coordinate|.
pub const MAX_ABS_COORDINATE: f64 = 1e30;
/// Smallest admitted nonzero |coordinate| (zero itself is fine).
pub const MIN_ABS_NONZERO_COORDINATE: f64 = 1e-60;
/// Smallest admitted bounding-box diagonal of the whole model.
pub const MIN_BOX_DIAGONAL: f64 = 1e-30;

/// NaN/Inf (any node, used or not), then the admitted range, then the model's size.
pub fn check_coordinates(nodes: &[P3]) -> Result<()> {
    for (i, p) in nodes.iter().enumerate() {
        if p.iter().any(|x| !x.is_finite()) {
            return Err(Error::surface(
                SurfaceDefect::NonFiniteCoordinate,
                format!("{} has a non-finite coordinate", describe::node(i, nodes)),
            ));
        }
    }
    for (i, p) in nodes.iter().enumerate() {
        if p.iter().any(|x| x.abs() > MAX_ABS_COORDINATE) {
            return Err(Error::surface(
                SurfaceDefect::CoordinateRange,
                format!(
                    "{}: |coordinate| > {MAX_ABS_COORDINATE:e}, beyond the range where the exact \
                     predicates cannot overflow; rescale the model",
                    describe::node(i, nodes)
                ),
            ));
        }
        if p.iter()
            .any(|x| *x != 0.0 && x.abs() < MIN_ABS_NONZERO_COORDINATE)
        {
            return Err(Error::surface(
                SurfaceDefect::CoordinateRange,
                format!(
                    "{}: a nonzero |coordinate| < {MIN_ABS_NONZERO_COORDINATE:e} would underflow \
                     in the exact predicates; round it to 0 or rescale the model",
                    describe::node(i, nodes)
                ),
            ));
        }
    }
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in nodes {
        for d in 0..3 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    if !nodes.is_empty() {
        let diag =
            ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt();
        if diag < MIN_BOX_DIAGONAL {
            return Err(Error::surface(
                SurfaceDefect::CoordinateRange,
                format!(
                    "the model's bounding box ({:?} to {:?}) has diagonal {diag:e} < \
                     {MIN_BOX_DIAGONAL:e}: too small for the predicates' range; rescale it",
                    lo, hi
                ),
            ));
        }
    }
    Ok(())
}

/// Two nodes with identical coordinates (0.0 and -0.0 are equal). Coordinates must be
/// finite.
pub fn check_duplicates(nodes: &[P3]) -> Result<()> {
    // Sort by a key that orders finite f64 numerically, with -0.0 mapped to 0.0.
    let key = |x: f64| {
        let b = (x + 0.0).to_bits(); // -0.0 + 0.0 == +0.0
        if b >> 63 == 1 {
            !b
        } else {
            b | (1 << 63)
        }
    };
    let mut order: Vec<([u64; 3], u32)> = nodes
        .iter()
        .enumerate()
        .map(|(i, p)| (p.map(key), i as u32))
        .collect();
    order.par_sort_unstable();
    let order: Vec<u32> = order.into_iter().map(|x| x.1).collect();
    let mut first: Option<(u32, u32)> = None;
    for w in order.windows(2) {
        let (a, b) = (w[0], w[1]);
        if nodes[a as usize] == nodes[b as usize] {
            let pair = (a.min(b), a.max(b));
            if first.map_or(true, |f| pair < f) {
                first = Some(pair);
            }
        }
    }
    if let Some((a, b)) = first {
        return Err(Error::surface(
            SurfaceDefect::DuplicateNode,
            format!(
                "{} and node {b} have identical coordinates (weld them)",
                describe::node(a as usize, nodes)
            ),
        ));
    }
    Ok(())
}
