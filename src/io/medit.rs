//! medit (Gamma Mesh Format) ASCII `.mesh` files.
//!
//! Hand-written: the format is a flat keyword/count/values token stream. We read
//! `Vertices`, `Triangles`, `TrianglesP2`, `Tetrahedra` and `TetrahedraP2`, skip the
//! other element and geometry keywords whose record width is fixed, and refuse
//! `*Ordering` sections (a file-defined node order we do not interpret) and unknown
//! keywords. P2 node order: see `io::order` (P.-L. George's convention, as Gmsh writes).

use std::io::{self, Write};

use super::cursor::{capped, show, Cursor};
use super::order::{self, Convention};
use super::text_out::{int, point, uint};
use super::{MeshView, RawMesh};
use crate::error::Result;

/// Write an ASCII medit file (double precision, `MeshVersionFormatted 2`).
pub(crate) fn write<W: Write>(
    w: &mut W,
    view: &MeshView,
    volume_tag: i32,
    linear: bool,
) -> io::Result<()> {
    w.write_all(b"MeshVersionFormatted 2\n\nDimension 3\n\nVertices\n")?;
    uint(w, view.nodes.len() as u64)?;
    w.write_all(b"\n")?;
    for p in view.nodes {
        point(w, p)?;
        w.write_all(b" 0\n")?;
    }
    let record = |w: &mut W, nodes: &[u32], tag: i32| -> io::Result<()> {
        for &v in nodes {
            uint(w, v as u64 + 1)?;
            w.write_all(b" ")?;
        }
        int(w, tag as i64)?;
        w.write_all(b"\n")
    };
    if !view.tri6.is_empty() {
        w.write_all(if linear {
            b"\nTriangles\n".as_slice()
        } else {
            b"\nTrianglesP2\n".as_slice()
        })?;
        uint(w, view.tri6.len() as u64)?;
        w.write_all(b"\n")?;
        for (t, &tag) in view.tri6.iter().zip(view.tags) {
            let t = order::tri6_to(Convention::Medit, t);
            record(w, if linear { &t[..3] } else { &t }, tag)?;
        }
    }
    if !view.tet10.is_empty() {
        w.write_all(if linear {
            b"\nTetrahedra\n".as_slice()
        } else {
            b"\nTetrahedraP2\n".as_slice()
        })?;
        uint(w, view.tet10.len() as u64)?;
        w.write_all(b"\n")?;
        for (i, t) in view.tet10.iter().enumerate() {
            let t = order::tet10_to(Convention::Medit, t);
            let tag = view.tet_regions.get(i).copied().unwrap_or(volume_tag);
            record(w, if linear { &t[..4] } else { &t }, tag)?;
        }
    }
    w.write_all(b"\nEnd\n")
}

/// Keywords we skip: name, number of integers and of reals per record (`D` = one real
/// per dimension).
const SKIP: &[(&[u8], usize, usize)] = &[
    (b"Edges", 3, 0),
    (b"EdgesP2", 4, 0),
    (b"Quadrilaterals", 5, 0),
    (b"QuadrilateralsQ2", 10, 0),
    (b"Hexahedra", 9, 0),
    (b"Hexaedra", 9, 0),
    (b"HexahedraQ2", 28, 0),
    (b"Prisms", 7, 0),
    (b"Pentahedra", 7, 0),
    (b"Pyramids", 6, 0),
    (b"Corners", 1, 0),
    (b"Ridges", 1, 0),
    (b"RequiredVertices", 1, 0),
    (b"RequiredEdges", 1, 0),
    (b"RequiredTriangles", 1, 0),
    (b"RequiredQuadrilaterals", 1, 0),
    (b"RequiredTetrahedra", 1, 0),
    (b"NormalAtVertices", 2, 0),
    (b"TangentAtVertices", 2, 0),
    (b"NormalAtTriangleVertices", 3, 0),
    (b"TangentAtEdgeVertices", 3, 0),
    (b"VertexOnGeometricVertex", 2, 0),
    (b"VertexOnGeometricEdge", 2, 1),
    (b"EdgeOnGeometricEdge", 2, 0),
    (b"SubDomainFromMesh", 4, 0),
    (b"Normals", 0, usize::MAX),
    (b"Tangents", 0, usize::MAX),
];

/// Read an ASCII medit file held in `data`.
pub(crate) fn read(data: &[u8], name: &str) -> Result<RawMesh> {
    let mut c = Cursor::new(data, name);
    c.set_hash_comments(true);
    let mut mesh = RawMesh::default();
    let mut dim = 3usize;
    let mut seen_version = false;
    let mut have_vertices = false;
    let mut ended = false;
    while let Some(tok) = c.token() {
        let max = c.remaining() as u64;
        match tok {
            b"MeshVersionFormatted" => {
                let v = c.u64("mesh version")?;
                if !(1..=4).contains(&v) {
                    return Err(c.err(format!("unsupported MeshVersionFormatted {v}")));
                }
                seen_version = true;
            }
            b"Dimension" => {
                let d = c.u64("dimension")?;
                if d != 2 && d != 3 {
                    return Err(c.err(format!("unsupported dimension {d}")));
                }
                dim = d as usize;
            }
            b"Vertices" => {
                if have_vertices {
                    return Err(c.err("a second Vertices section"));
                }
                have_vertices = true;
                let n = c.count("number of vertices", u32::MAX as u64 - 1)?;
                mesh.nodes.reserve(capped(n, c.remaining(), 2 * (dim + 1)));
                for _ in 0..n {
                    let x = c.f64("x coordinate")?;
                    let y = c.f64("y coordinate")?;
                    let z = if dim == 3 {
                        c.f64("z coordinate")?
                    } else {
                        0.0
                    };
                    c.i64("vertex reference")?;
                    mesh.nodes.push([x, y, z]);
                }
            }
            b"Triangles" | b"TrianglesP2" | b"Tetrahedra" | b"TetrahedraP2" => {
                if !have_vertices {
                    return Err(c.err(format!("{} before Vertices", show(tok))));
                }
                let k = match tok {
                    b"Triangles" => 3,
                    b"TrianglesP2" => 6,
                    b"Tetrahedra" => 4,
                    _ => 10,
                };
                let n = c.count("number of elements", max)?;
                let nv = mesh.nodes.len() as u64;
                let mut v = [0u32; 10];
                let kw = show(tok);
                for i in 0..n {
                    for o in v.iter_mut().take(k) {
                        let idx = c.u64("vertex index")?;
                        if idx == 0 || idx > nv {
                            return Err(c.err(format!(
                                "{kw} element {} refers to vertex {idx}, but there are {nv} vertices (1-based)",
                                i + 1
                            )));
                        }
                        *o = (idx - 1) as u32;
                    }
                    let tag = c.i32("element reference")?;
                    match k {
                        3 => {
                            mesh.tri3.push([v[0], v[1], v[2]]);
                            mesh.tri3_tags.push(tag);
                        }
                        6 => {
                            let t: [u32; 6] = v[..6].try_into().expect("6 nodes");
                            mesh.tri6.push(order::tri6_from(Convention::Medit, &t));
                            mesh.tri6_tags.push(tag);
                        }
                        4 => {
                            mesh.tet4.push([v[0], v[1], v[2], v[3]]);
                            mesh.tet4_tags.push(tag);
                        }
                        _ => {
                            mesh.tet10.push(order::tet10_from(Convention::Medit, &v));
                            mesh.tet10_tags.push(tag);
                        }
                    }
                }
            }
            b"End" => {
                ended = true;
                break;
            }
            t if t.ends_with(b"Ordering") => {
                return Err(c.err(format!(
                    "{} sections (file-defined node orders) are not supported",
                    show(t)
                )))
            }
            t => {
                let Some(&(_, ints, reals)) = SKIP.iter().find(|s| s.0 == t) else {
                    return Err(c.err(format!("unknown medit keyword '{}'", show(t))));
                };
                let n = c.count("number of records", max)?;
                let reals = if reals == usize::MAX { dim } else { reals };
                let per = (ints + reals) as u64;
                if t.starts_with(b"Edges")
                    || t.starts_with(b"Quad")
                    || t.starts_with(b"Hexa")
                    || t.starts_with(b"Prisms")
                    || t.starts_with(b"Pentahedra")
                    || t.starts_with(b"Pyramids")
                {
                    mesh.ignored_elements += n;
                }
                for _ in 0..n.saturating_mul(per) {
                    c.expect_token("a record value")?;
                }
            }
        }
    }
    if !seen_version {
        return Err(c.err_at(0, "not a medit file: no MeshVersionFormatted"));
    }
    if !ended {
        return Err(c.eof("End"));
    }
    if !have_vertices {
        return Err(c.eof("Vertices"));
    }
    Ok(mesh)
}
