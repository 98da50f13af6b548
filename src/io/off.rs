//! OFF (Object File Format), ASCII, read only.
//!
//! Hand-written: there is no maintained Rust crate for OFF, and the format is a header line
//! and two lists. Accepted: an optional header keyword `OFF` with the optional prefixes
//! of the variants that add per-vertex data (`ST`, `C`, `N`: `COFF`, `NOFF`, `STCNOFF`,
//! ...), whose extra values after x y z are ignored; the counts `nv nf [ne]` on the header
//! line or the next one; `#` comments and blank lines anywhere. Vertex indices are 0-based.
//! A face line is `n i1 ... in` with optional colour values after the indices (ignored);
//! polygons are split as fans (see `linear`). Rejected with a clear message: binary OFF
//! (`OFF BINARY`) and other dimensions (`4OFF`, `nOFF`). Vertices are welded exactly
//! (`weld`), every tag is 0.

use super::cursor::{capped, parse_f64, parse_u64, show};
use super::linear::{indexed_mesh, push_fan};
use super::lines::Lines;
use super::RawMesh;
use crate::error::Result;
use crate::geom::P3;

/// Read an OFF file held in `data`.
pub(crate) fn read(data: &[u8], name: &str) -> Result<RawMesh> {
    let mut l = Lines::new(data, name);
    let mut tok: Vec<&[u8]> = Vec::new();
    if !l.next_tokens(&mut tok) {
        return Err(l.eof("the OFF header"));
    }
    let mut counts: Vec<&[u8]> = tok.clone();
    let first = tok[0];
    if parse_u64(first).is_none() {
        let Some(prefix) = first
            .len()
            .checked_sub(3)
            .filter(|&k| first[k..].eq_ignore_ascii_case(b"OFF"))
            .map(|k| &first[..k])
        else {
            return Err(l.err(format!(
                "expected the OFF header keyword, found '{}'",
                show(first)
            )));
        };
        if !prefix.iter().all(|b| b"STCNstcn".contains(b)) {
            return Err(l.err(format!(
                "'{}' files are not supported (only 3D OFF: OFF, COFF, NOFF, STOFF, ...)",
                show(first)
            )));
        }
        if tok
            .get(1)
            .is_some_and(|t| t.eq_ignore_ascii_case(b"BINARY"))
        {
            return Err(l.err("binary OFF is not supported; write it as ASCII OFF"));
        }
        counts = tok[1..].to_vec();
        if counts.is_empty() {
            if !l.next_tokens(&mut tok) {
                return Err(l.eof("the OFF counts 'vertices faces edges'"));
            }
            counts = tok.clone();
        }
    }
    let nv = counts.first().and_then(|t| parse_u64(t));
    let nf = counts.get(1).and_then(|t| parse_u64(t));
    let (Some(nv), Some(nf)) = (nv, nf) else {
        return Err(l.err("expected the counts 'vertices faces [edges]'"));
    };
    // A vertex line takes at least 6 bytes ("0 0 0\n"), a face line at least 8.
    let mut points: Vec<P3> = Vec::with_capacity(capped(nv, l.remaining(), 6));
    for i in 0..nv {
        if !l.next_tokens(&mut tok) {
            return Err(l.eof(&format!("vertex {i} of {nv}")));
        }
        if tok.len() < 3 {
            return Err(l.err(format!("vertex {i}: expected x y z")));
        }
        let mut p = [0.0; 3];
        for d in 0..3 {
            p[d] = parse_f64(tok[d])
                .ok_or_else(|| l.err(format!("vertex {i}: invalid number '{}'", show(tok[d]))))?;
        }
        points.push(p);
    }
    let mut tris: Vec<[u32; 3]> = Vec::with_capacity(capped(nf, l.remaining(), 8));
    let mut poly: Vec<u32> = Vec::new();
    for f in 0..nf {
        if !l.next_tokens(&mut tok) {
            return Err(l.eof(&format!("face {f} of {nf}")));
        }
        let n = parse_u64(tok[0])
            .ok_or_else(|| l.err(format!("face {f}: invalid vertex count '{}'", show(tok[0]))))?;
        if n < 3 {
            return Err(l.err(format!("face {f} has {n} vertices (at least 3 are needed)")));
        }
        if (tok.len() as u64) < n + 1 {
            return Err(l.err(format!(
                "face {f}: {n} vertices announced, {} indices given",
                tok.len() - 1
            )));
        }
        poly.clear();
        for t in &tok[1..=n as usize] {
            match parse_u64(t) {
                Some(v) if v < points.len() as u64 => poly.push(v as u32),
                _ => {
                    return Err(l.err(format!(
                        "face {f}: vertex index '{}' is not in 0..{} (OFF indices are 0-based)",
                        show(t),
                        points.len()
                    )))
                }
            }
        }
        push_fan(&poly, &mut tris);
    }
    indexed_mesh(&points, tris, name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_variants_comments_and_polygons() {
        let text = "# a comment\nOFF\n# counts next\n5 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n\
                    0 0 0\n\n4 0 1 2 3 255 0 0\n3 4 2 1\n";
        let m = read(text.as_bytes(), "t.off").unwrap();
        // Vertex 4 repeats vertex 0: welded.
        assert_eq!(m.nodes.len(), 4);
        assert_eq!(m.tri3, vec![[0, 1, 2], [0, 2, 3], [0, 2, 1]]);
        let same_line = "OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
        assert_eq!(read(same_line.as_bytes(), "t.off").unwrap().tri3.len(), 1);
        let coff = "COFF\n3 1 0\n0 0 0 1 1 1 1\n1 0 0 1 1 1 1\n0 1 0 1 1 1 1\n3 0 1 2\n";
        assert_eq!(read(coff.as_bytes(), "t.off").unwrap().nodes.len(), 3);
    }

    #[test]
    fn bad_index_names_the_line() {
        let text = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n";
        let e = read(text.as_bytes(), "t.off").unwrap_err().to_string();
        assert!(e.starts_with("t.off:6:"), "{e}");
        for bad in ["4OFF\n", "OFF BINARY\n3 1 0\n", "PLY\n", "OFF\n3\n"] {
            assert!(read(bad.as_bytes(), "b.off").is_err(), "{bad}");
        }
    }
}
