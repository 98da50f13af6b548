//! Exact vertex welding for the linear surface readers.
//!
//! Binary STL stores every facet's three vertices again; OFF, OBJ and PLY files sometimes
//! repeat a vertex too (split at a texture seam, or concatenated parts). Vertices with
//! *identical* coordinates become one vertex: no tolerance, so no two distinct input points
//! are ever merged, and the kept coordinates are bit-identical to the file's (an `f32`
//! converts to `f64` exactly). `0.0` and `-0.0` count as equal, as in the surface's
//! duplicate-node check, so welding leaves nothing for that check to reject. Vertices keep
//! the order of their first occurrence, so a file without repeats keeps its numbering.

use std::collections::HashMap;

use crate::error::{Error, Result};
use crate::geom::P3;

/// The hash key of a point: its bit patterns, with `-0.0` mapped to `0.0`.
#[inline]
fn key(p: P3) -> [u64; 3] {
    p.map(|x| (x + 0.0).to_bits())
}

/// Collects distinct points, handing out one index per distinct coordinate triple.
#[derive(Default)]
pub(crate) struct Welder {
    map: HashMap<[u64; 3], u32>,
    nodes: Vec<P3>,
}

impl Welder {
    /// A welder with room for about `n` distinct points.
    pub fn with_capacity(n: usize) -> Self {
        Welder {
            map: HashMap::with_capacity(n),
            nodes: Vec::with_capacity(n),
        }
    }

    /// The index of `p`, adding it if it is new. Fails only past `u32` indices.
    pub fn add(&mut self, p: P3, location: impl FnOnce() -> String) -> Result<u32> {
        if let Some(&i) = self.map.get(&key(p)) {
            return Ok(i);
        }
        let i = u32::try_from(self.nodes.len())
            .ok()
            .filter(|&i| i < u32::MAX)
            .ok_or_else(|| Error::parse(location(), "more than 2^32 - 1 distinct vertices"))?;
        self.map.insert(key(p), i);
        self.nodes.push(p);
        Ok(i)
    }

    /// The distinct points, in order of first occurrence.
    pub fn into_nodes(self) -> Vec<P3> {
        self.nodes
    }
}

/// Welds an indexed vertex list: the distinct points and, per input vertex, its new index.
pub(crate) fn weld_indexed(points: &[P3], name: &str) -> Result<(Vec<P3>, Vec<u32>)> {
    let mut w = Welder::with_capacity(points.len());
    let mut remap = Vec::with_capacity(points.len());
    for &p in points {
        remap.push(w.add(p, || name.to_string())?);
    }
    Ok((w.into_nodes(), remap))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identical_points_weld_and_keep_first_order() {
        let pts = [
            [1.0, 2.0, 3.0],
            [0.0, 0.0, 0.0],
            [1.0, 2.0, 3.0],
            [-0.0, 0.0, -0.0],
            [1.0, 2.0, 3.000_000_000_000_000_4],
        ];
        let (nodes, remap) = weld_indexed(&pts, "t").unwrap();
        assert_eq!(remap, vec![0, 1, 0, 1, 2]);
        assert_eq!(nodes.len(), 3);
        assert_eq!(nodes[2][2].to_bits(), 3.000_000_000_000_000_4f64.to_bits());
    }
}
