//! STL, ASCII and binary (read only: STL holds linear triangles, curvetet writes P2).
//!
//! Hand-written rather than the `stl_io` crate: `stl_io` parses ASCII coordinates as
//! `f32`, which would round the 17-digit coordinates that ASCII STL files from CAD tools
//! and our benchmark data carry; curvetet keeps every input coordinate bit-identical.
//! The format is small enough that a bounds-checked reader is shorter than the glue.
//!
//! **Binary or ASCII.** A binary file is an 80-byte header, a little-endian `u32` facet
//! count n and n records of 50 bytes (normal, three vertices as 12 `f32`, a `u16`
//! attribute). Many binary files start their header with `solid` too, so the size decides
//! first: a file of exactly 84 + 50 n bytes is binary. Otherwise a file starting with
//! `solid` (after optional whitespace) is read as ASCII; any other file is binary and
//! must hold at least the n facets its header announces (trailing bytes are ignored).
//!
//! **ASCII**: `solid [name]`, then `facet normal nx ny nz` / `outer loop` / three `vertex x
//! y z` / `endloop` / `endfacet`, closed by `endsolid [name]`; several solids may follow
//! one another. Keywords are matched case-insensitively. Coordinates are parsed as `f64`.
//!
//! Facet normals are ignored: the vertex order (right-hand rule) is the orientation, as
//! the format specifies. Vertices are welded exactly (`weld`), every tag is 0.

use super::cursor::{capped, show, Cursor};
use super::weld::Welder;
use super::RawMesh;
use crate::error::Result;
use crate::geom::P3;

const HEADER: usize = 80;
const RECORD: usize = 50;

/// Read an STL file held in `data`.
pub(crate) fn read(data: &[u8], name: &str) -> Result<RawMesh> {
    if is_binary(data) {
        read_binary(data, name)
    } else {
        read_ascii(data, name)
    }
}

/// Is `data` a binary STL file? (See the module docs.)
pub(crate) fn is_binary(data: &[u8]) -> bool {
    if let Some(n) = facet_count(data) {
        if (HEADER as u64 + 4).checked_add(RECORD as u64 * n as u64) == Some(data.len() as u64) {
            return true;
        }
    }
    let start = data
        .iter()
        .position(|b| !b.is_ascii_whitespace())
        .unwrap_or(data.len());
    let word = &data[start..(start + 5).min(data.len())];
    !word.eq_ignore_ascii_case(b"solid")
}

fn facet_count(data: &[u8]) -> Option<u32> {
    let b = data.get(HEADER..HEADER + 4)?;
    Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

fn read_binary(data: &[u8], name: &str) -> Result<RawMesh> {
    let mut c = Cursor::new(data, name);
    c.set_binary(true);
    c.bytes(HEADER, "the 80-byte binary STL header")?;
    let n = c.bin_usize(4, "the facet count")?;
    c.need(n, RECORD, "facets")?;
    let n = n as usize;
    let mut welder = Welder::with_capacity(capped(n as u64, c.remaining(), RECORD));
    let mut tri3 = Vec::with_capacity(n);
    let f32_at = |b: &[u8], k: usize| -> f64 {
        f32::from_le_bytes([b[4 * k], b[4 * k + 1], b[4 * k + 2], b[4 * k + 3]]) as f64
    };
    for _ in 0..n {
        let at = c.pos();
        let rec = c.bytes(RECORD, "a facet")?;
        let mut t = [0u32; 3];
        for (v, tv) in t.iter_mut().enumerate() {
            let p: P3 = [0, 1, 2].map(|d| f32_at(rec, 3 + 3 * v + d));
            *tv = welder.add(p, || c.location_at(at))?;
        }
        tri3.push(t);
    }
    Ok(RawMesh {
        nodes: welder.into_nodes(),
        tri3_tags: vec![0; tri3.len()],
        tri3,
        ..RawMesh::default()
    })
}

/// The next token, which must be `word` (any case).
fn keyword(c: &mut Cursor, word: &str) -> Result<()> {
    let t = c.expect_token(word)?;
    if !t.eq_ignore_ascii_case(word.as_bytes()) {
        return Err(c.err(format!("expected '{word}', found '{}'", show(t))));
    }
    Ok(())
}

fn read_ascii(data: &[u8], name: &str) -> Result<RawMesh> {
    let mut c = Cursor::new(data, name);
    // A facet takes at least ~100 bytes of text; reserve no more than the file justifies.
    let mut welder = Welder::with_capacity(capped(u64::MAX, data.len(), 200));
    let mut tri3 = Vec::with_capacity(capped(u64::MAX, data.len(), 100));
    let mut solids = 0usize;
    while let Some(t) = c.token() {
        if !t.eq_ignore_ascii_case(b"solid") {
            return Err(c.err(format!("expected 'solid', found '{}'", show(t))));
        }
        c.rest_of_line(); // the solid's name
        solids += 1;
        loop {
            let t = c.expect_token("'facet' or 'endsolid'")?;
            if t.eq_ignore_ascii_case(b"endsolid") {
                // The name after endsolid is optional and may be absent at the end of file.
                c.rest_of_line();
                break;
            }
            if !t.eq_ignore_ascii_case(b"facet") {
                return Err(c.err(format!(
                    "expected 'facet' or 'endsolid', found '{}'",
                    show(t)
                )));
            }
            keyword(&mut c, "normal")?;
            for _ in 0..3 {
                c.f64("a facet normal component")?;
            }
            keyword(&mut c, "outer")?;
            keyword(&mut c, "loop")?;
            let mut tri = [0u32; 3];
            for tv in tri.iter_mut() {
                keyword(&mut c, "vertex")?;
                let at = c.pos();
                let p = [c.f64("x")?, c.f64("y")?, c.f64("z")?];
                *tv = welder.add(p, || c.location_at(at))?;
            }
            let t = c.expect_token("'endloop'")?;
            if !t.eq_ignore_ascii_case(b"endloop") {
                let msg = if t.eq_ignore_ascii_case(b"vertex") {
                    "a facet with more than 3 vertices (STL facets are triangles)".to_string()
                } else {
                    format!("expected 'endloop', found '{}'", show(t))
                };
                return Err(c.err(msg));
            }
            keyword(&mut c, "endfacet")?;
            tri3.push(tri);
        }
    }
    if solids == 0 {
        return Err(c.eof("'solid'"));
    }
    Ok(RawMesh {
        nodes: welder.into_nodes(),
        tri3_tags: vec![0; tri3.len()],
        tri3,
        ..RawMesh::default()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A binary STL of `tris` (as given, no welding).
    pub(crate) fn binary(header: &[u8], tris: &[[[f32; 3]; 3]]) -> Vec<u8> {
        let mut v = vec![0u8; HEADER];
        v[..header.len()].copy_from_slice(header);
        v.extend((tris.len() as u32).to_le_bytes());
        for t in tris {
            v.extend([0u8; 12]);
            for p in t {
                for x in p {
                    v.extend(x.to_le_bytes());
                }
            }
            v.extend([0u8; 2]);
        }
        v
    }

    const TET: [[[f32; 3]; 3]; 4] = [
        [[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]],
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
        [[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]],
        [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    ];

    #[test]
    fn binary_with_solid_header_is_binary_and_welded() {
        let b = binary(b"solid trap: a binary file whose header says solid", &TET);
        assert!(is_binary(&b));
        let m = read(&b, "t.stl").unwrap();
        assert_eq!(m.nodes.len(), 4);
        assert_eq!(m.tri3.len(), 4);
        assert_eq!(m.tri3[3], [2, 1, 3]);
    }

    #[test]
    fn ascii_keeps_all_digits_and_rejects_quads() {
        let text = "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0.1000000000000000055511 0 0\n\
                    vertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid s\n";
        let m = read(text.as_bytes(), "a.stl").unwrap();
        assert_eq!(m.nodes[0][0], 0.1);
        let quad = text.replace("endloop", "vertex 1 1 0\nendloop");
        let e = read(quad.as_bytes(), "q.stl").unwrap_err().to_string();
        assert!(e.contains("a.stl") || e.contains("q.stl:7"), "{e}");
        assert!(e.contains("more than 3 vertices"), "{e}");
    }

    #[test]
    fn binary_shorter_than_its_count_is_an_error() {
        let mut b = binary(b"bin", &TET);
        b.truncate(b.len() - 1);
        let e = read(&b, "t.stl").unwrap_err().to_string();
        assert!(e.contains("byte"), "{e}");
    }
}
