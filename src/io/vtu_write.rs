//! Writing VTK XML unstructured grid `.vtu` files: one piece holding the tetrahedra and
//! the boundary triangles, with the Int32 cell array `BoundaryTag` (0 for tetrahedra);
//! data arrays in ASCII or inline base64 (UInt64 header, little-endian, one stream).

use std::io::{self, Write};

use base64::engine::general_purpose::STANDARD;

use super::text_out::{float, int, uint};
use super::vtk_cells::{self, QUALITY_ARRAYS, TAG_ARRAY};
use super::{MeshView, PhysicalName};

/// Write a `.vtu` file with the tetrahedra and the boundary triangles, the Int32 cell
/// array `BoundaryTag` (0 for tetrahedra), and with `quality` (per tetrahedron) the
/// Float64 cell arrays of [`QUALITY_ARRAYS`] (0 for triangles). Each named group is a
/// field data array of that name holding (tag, dimension), as meshio keeps Gmsh's
/// physical names.
pub(crate) fn write<W: Write>(
    w: &mut W,
    view: &MeshView,
    names: &[PhysicalName],
    quality: Option<&[[f64; 2]]>,
    binary: bool,
) -> io::Result<()> {
    let (ncells, nconn) = vtk_cells::sizes(view);
    let format = if binary { "binary" } else { "ascii" };
    w.write_all(b"<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n  <UnstructuredGrid>\n")?;
    if !names.is_empty() {
        w.write_all(b"    <FieldData>\n")?;
        for n in names {
            writeln!(
                w,
                "      <DataArray type=\"Int32\" Name=\"{}\" NumberOfTuples=\"1\" NumberOfComponents=\"2\" format=\"ascii\">{} {}</DataArray>",
                quick_xml::escape::escape(n.name.as_str()),
                n.tag,
                n.dim
            )?;
        }
        w.write_all(b"    </FieldData>\n")?;
    }
    write!(
        w,
        "    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{ncells}\">\n      <Points>\n",
        view.nodes.len()
    )?;
    writeln!(
        w,
        "        <DataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\" format=\"{format}\">"
    )?;
    array(w, binary, 8 * 3 * view.nodes.len(), |w, bin| {
        for p in view.nodes {
            if bin {
                for x in p {
                    w.write_all(&x.to_le_bytes())?;
                }
            } else {
                float(w, p[0])?;
                w.write_all(b" ")?;
                float(w, p[1])?;
                w.write_all(b" ")?;
                float(w, p[2])?;
                w.write_all(b"\n")?;
            }
        }
        Ok(())
    })?;
    w.write_all(b"        </DataArray>\n      </Points>\n      <Cells>\n")?;

    writeln!(
        w,
        "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"{format}\">"
    )?;
    array(w, binary, 8 * nconn, |w, bin| {
        for c in vtk_cells::cells(view) {
            for (k, &v) in c.nodes().iter().enumerate() {
                if bin {
                    w.write_all(&(v as i64).to_le_bytes())?;
                } else {
                    if k > 0 {
                        w.write_all(b" ")?;
                    }
                    uint(w, v as u64)?;
                }
            }
            if !bin {
                w.write_all(b"\n")?;
            }
        }
        Ok(())
    })?;
    writeln!(
        w,
        "        </DataArray>\n        <DataArray type=\"Int64\" Name=\"offsets\" format=\"{format}\">"
    )?;
    array(w, binary, 8 * ncells, |w, bin| {
        let mut off = 0u64;
        for c in vtk_cells::cells(view) {
            off += c.len as u64;
            if bin {
                w.write_all(&off.to_le_bytes())?;
            } else {
                uint(w, off)?;
                w.write_all(b"\n")?;
            }
        }
        Ok(())
    })?;
    writeln!(
        w,
        "        </DataArray>\n        <DataArray type=\"UInt8\" Name=\"types\" format=\"{format}\">"
    )?;
    array(w, binary, ncells, |w, bin| {
        for c in vtk_cells::cells(view) {
            if bin {
                w.write_all(&[c.ty])?;
            } else {
                uint(w, c.ty as u64)?;
                w.write_all(b"\n")?;
            }
        }
        Ok(())
    })?;
    writeln!(
        w,
        "        </DataArray>\n      </Cells>\n      <CellData Scalars=\"{TAG_ARRAY}\">\n        <DataArray type=\"Int32\" Name=\"{TAG_ARRAY}\" format=\"{format}\">"
    )?;
    array(w, binary, 4 * ncells, |w, bin| {
        for c in vtk_cells::cells(view) {
            if bin {
                w.write_all(&c.tag.to_le_bytes())?;
            } else {
                int(w, c.tag as i64)?;
                w.write_all(b"\n")?;
            }
        }
        Ok(())
    })?;
    w.write_all(b"        </DataArray>\n")?;
    for (k, name) in QUALITY_ARRAYS.iter().enumerate() {
        let Some(q) = quality else { break };
        writeln!(
            w,
            "        <DataArray type=\"Float64\" Name=\"{name}\" format=\"{format}\">"
        )?;
        array(w, binary, 8 * ncells, |w, bin| {
            let values = q
                .iter()
                .map(|e| e[k])
                .chain((0..view.tri6.len()).map(|_| 0.0));
            for v in values {
                if bin {
                    w.write_all(&v.to_le_bytes())?;
                } else {
                    float(w, v)?;
                    w.write_all(b"\n")?;
                }
            }
            Ok(())
        })?;
        w.write_all(b"        </DataArray>\n")?;
    }
    w.write_all(b"      </CellData>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n")
}

/// Write one data array's content: text as is, or base64 of (UInt64 byte count, data)
/// as one stream, streamed without holding the array in memory.
fn array<W: Write>(
    w: &mut W,
    binary: bool,
    nbytes: usize,
    body: impl FnOnce(&mut dyn Write, bool) -> io::Result<()>,
) -> io::Result<()> {
    if binary {
        let enc = base64::write::EncoderWriter::new(&mut *w, &STANDARD);
        // Values come 1 to 8 bytes at a time: buffer them for the encoder.
        let mut buf = io::BufWriter::with_capacity(1 << 16, enc);
        buf.write_all(&(nbytes as u64).to_le_bytes())?;
        body(&mut buf, true)?;
        let mut enc = buf.into_inner().map_err(|e| e.into_error())?;
        enc.finish()?;
        drop(enc);
        w.write_all(b"\n")
    } else {
        body(w, false)
    }
}
