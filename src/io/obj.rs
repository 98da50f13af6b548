//! Wavefront OBJ, geometry only, read only.
//!
//! Hand-written: the OBJ crates (`tobj`, `obj-rs`) parse coordinates as `f32` by default
//! or pull in materials and texture handling we do not need; curvetet needs `v` and `f`
//! lines with exact `f64` coordinates and located errors.
//!
//! Read: `v x y z [w] [r g b]` (x y z kept, the rest ignored) and `f` lines whose vertices
//! are `i`, `i/t`, `i//n` or `i/t/n` (only the position index `i` is used). Indices are
//! 1-based; negative indices count back from the last vertex defined so far (-1 = the
//! latest), as the format specifies. A positive index may refer to a vertex defined later
//! in the file; it is checked once the whole file is read. Polygons are split as fans (see
//! `linear`). Every other statement (`vt`, `vn`, `g`, `o`, `s`, `usemtl`, `mtllib`, `l`,
//! `p`, ...) is ignored; `l` and `p` elements are counted in
//! [`RawMesh::ignored_elements`]. Vertices are welded exactly (`weld`), every tag is 0.

use super::cursor::{capped, parse_f64, parse_i64, show};
use super::linear::{indexed_mesh, push_fan};
use super::lines::Lines;
use super::RawMesh;
use crate::error::{Error, Result};
use crate::geom::P3;

/// Read an OBJ file held in `data`.
pub(crate) fn read(data: &[u8], name: &str) -> Result<RawMesh> {
    let mut l = Lines::new(data, name);
    let mut tok: Vec<&[u8]> = Vec::new();
    let mut points: Vec<P3> = Vec::with_capacity(capped(u64::MAX, data.len(), 64));
    let mut tris: Vec<[u32; 3]> = Vec::with_capacity(capped(u64::MAX, data.len(), 64));
    let mut poly: Vec<i64> = Vec::new();
    let mut ids: Vec<u32> = Vec::new();
    // A face that refers to a vertex not yet defined: (largest index, where).
    let mut forward: Option<(i64, String)> = None;
    let mut ignored = 0u64;
    while l.next_tokens(&mut tok) {
        match tok[0] {
            b"v" => {
                if tok.len() < 4 {
                    return Err(l.err("a 'v' line needs x y z"));
                }
                let mut p = [0.0; 3];
                for d in 0..3 {
                    p[d] = parse_f64(tok[1 + d]).ok_or_else(|| {
                        l.err(format!("invalid coordinate '{}'", show(tok[1 + d])))
                    })?;
                }
                points.push(p);
            }
            b"f" => {
                if tok.len() < 4 {
                    return Err(l.err(format!(
                        "a face with {} vertices (at least 3 are needed)",
                        tok.len() - 1
                    )));
                }
                poly.clear();
                let defined = points.len() as i64;
                for t in &tok[1..] {
                    let pos = t.split(|&b| b == b'/').next().unwrap_or(t);
                    let i = parse_i64(pos)
                        .ok_or_else(|| l.err(format!("invalid vertex index '{}'", show(t))))?;
                    let v = match i {
                        0 => return Err(l.err("vertex index 0 (OBJ indices start at 1)")),
                        i if i > 0 => i - 1,
                        i => defined + i,
                    };
                    if v < 0 {
                        return Err(l.err(format!(
                            "relative vertex index {i} reaches before the first vertex ({defined} defined so far)"
                        )));
                    }
                    if v >= defined && forward.as_ref().map_or(true, |f| v > f.0) {
                        forward = Some((v, l.location()));
                    }
                    poly.push(v);
                }
                ids.clear();
                ids.extend(poly.iter().map(|&v| u32::try_from(v).unwrap_or(u32::MAX)));
                push_fan(&ids, &mut tris);
            }
            b"l" | b"p" => ignored += 1,
            _ => {}
        }
    }
    if let Some((v, at)) = forward {
        if v >= points.len() as i64 {
            return Err(Error::parse(
                at,
                format!(
                    "vertex index {} is past the last vertex ({} in the file)",
                    v + 1,
                    points.len()
                ),
            ));
        }
    }
    if points.len() >= u32::MAX as usize {
        return Err(l.err("too many vertices for 32-bit indices"));
    }
    let mut m = indexed_mesh(&points, tris, name)?;
    m.ignored_elements = ignored;
    Ok(m)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slashes_negatives_quads() {
        let text = "# cube corner\nv 0 0 0\nv 1 0 0\nv 1 1 0 1.0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n\
                    g part\nf 1/1/1 2/1/1 3/1/1 4/1/1\nf -1//1 -3//1 -2//1\nl 1 2\n";
        let m = read(text.as_bytes(), "t.obj").unwrap();
        assert_eq!(m.tri3, vec![[0, 1, 2], [0, 2, 3], [3, 1, 2]]);
        assert_eq!(m.ignored_elements, 1);
    }

    #[test]
    fn bad_indices_name_the_line() {
        for (text, line) in [
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", ":4:"),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", ":4:"),
            ("v 0 0 0\nf -2 -1 -1\n", ":2:"),
            ("v 0 0\n", ":1:"),
        ] {
            let e = read(text.as_bytes(), "t.obj").unwrap_err().to_string();
            assert!(e.contains(line), "{text}: {e}");
        }
        // A forward reference is fine once the vertex exists.
        let fwd = "f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n";
        assert_eq!(read(fwd.as_bytes(), "t.obj").unwrap().tri3, vec![[0, 1, 2]]);
    }
}
