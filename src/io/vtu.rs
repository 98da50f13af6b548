//! Reading VTK XML unstructured grid `.vtu` files.
//!
//! The XML is parsed by `quick-xml` (zero-copy over the in-memory file) and base64 by
//! `base64`; the data arrays' numbers are parsed by our own cursor. Read: `ascii` arrays
//! and inline `binary` (base64) arrays with a UInt32 or UInt64 header, either byte
//! order, uncompressed, header encoded apart (as VTK does for compressed data) or in one
//! stream with the data (as VTK and meshio do otherwise); compressed and `appended`
//! arrays give a clear parse error. Several pieces are concatenated.

use base64::engine::general_purpose::STANDARD;
use base64::Engine;
use quick_xml::events::{BytesStart, Event};
use quick_xml::Reader;
use std::borrow::Cow;

use super::cursor::{capped, parse_f64, parse_i64, show, Cursor};
use super::vtk_cells::{self, add_cell, tag_rank};
use super::RawMesh;
use crate::error::{Error, Result};

/// The deepest nesting of XML elements read. A VTU file nests about six deep (VTKFile,
/// UnstructuredGrid, Piece, Points, DataArray, InformationKey); the bound keeps a file of
/// millions of unclosed tags from holding millions of open element names.
const MAX_DEPTH: usize = 64;

/// Element types of data arrays.
#[derive(Clone, Copy, PartialEq)]
enum NumType {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    F32,
    F64,
}

impl NumType {
    fn parse(t: &[u8]) -> Option<NumType> {
        Some(match t {
            b"Int8" | b"Char" => NumType::I8,
            b"UInt8" | b"UnsignedChar" => NumType::U8,
            b"Int16" | b"Short" => NumType::I16,
            b"UInt16" | b"UnsignedShort" => NumType::U16,
            b"Int32" | b"Int" => NumType::I32,
            b"UInt32" | b"UnsignedInt" => NumType::U32,
            b"Int64" | b"Long" | b"IdType" => NumType::I64,
            b"UInt64" | b"UnsignedLong" => NumType::U64,
            b"Float32" | b"Float" => NumType::F32,
            b"Float64" | b"Double" => NumType::F64,
            _ => return None,
        })
    }
    fn size(self) -> usize {
        match self {
            NumType::I8 | NumType::U8 => 1,
            NumType::I16 | NumType::U16 => 2,
            NumType::I32 | NumType::U32 | NumType::F32 => 4,
            NumType::I64 | NumType::U64 | NumType::F64 => 8,
        }
    }
    fn is_float(self) -> bool {
        matches!(self, NumType::F32 | NumType::F64)
    }
}

/// A decoded data array.
enum Values {
    I(Vec<i64>),
    F(Vec<f64>),
}

impl Values {
    fn len(&self) -> usize {
        match self {
            Values::I(v) => v.len(),
            Values::F(v) => v.len(),
        }
    }
}

/// What a data array is for.
#[derive(Clone, Copy, PartialEq)]
enum Target {
    Points,
    Connectivity,
    Offsets,
    Types,
    Tag(usize),
    Skip,
}

/// A data array being read.
struct Array<'a> {
    target: Target,
    ty: NumType,
    binary: bool,
    /// Byte offset of the array's opening tag and of its content.
    at: usize,
    content_at: Option<usize>,
    /// The content is a single slice of the file starting at `content_at`.
    in_file: bool,
    content: Cow<'a, [u8]>,
}

#[derive(Default)]
struct Piece {
    at: usize,
    npoints: u64,
    ncells: u64,
    points: Option<Values>,
    conn: Option<(usize, Values)>,
    offsets: Option<Values>,
    types: Option<Values>,
    tags: Option<(usize, Values)>,
}

struct Vtu<'a> {
    data: &'a [u8],
    name: &'a str,
    header64: bool,
    big_endian: bool,
    compressed: bool,
    seen_file: bool,
    mesh: RawMesh,
    piece: Option<Piece>,
    array: Option<Array<'a>>,
}

/// Read a `.vtu` file held in `data`.
pub(crate) fn read(data: &[u8], name: &str) -> Result<RawMesh> {
    let mut v = Vtu {
        data,
        name,
        header64: false,
        big_endian: false,
        compressed: false,
        seen_file: false,
        mesh: RawMesh::default(),
        piece: None,
        array: None,
    };
    v.parse()?;
    Ok(v.mesh)
}

fn attr<'b>(e: &'b BytesStart, key: &[u8]) -> Option<Cow<'b, [u8]>> {
    e.attributes()
        .flatten()
        .find(|a| a.key.local_name().as_ref() == key)
        .map(|a| a.value)
}

fn attr_u64(e: &BytesStart, key: &[u8]) -> Option<u64> {
    attr(e, key).and_then(|v| super::cursor::parse_u64(v.trim_ascii()))
}

impl<'a> Vtu<'a> {
    fn loc(&self, at: usize) -> String {
        Cursor::new(self.data, self.name).location_at(at)
    }

    fn err(&self, at: usize, msg: impl Into<String>) -> Error {
        Error::parse(self.loc(at), msg)
    }

    fn parse(&mut self) -> Result<()> {
        let mut rd = Reader::from_reader(self.data);
        let mut path: Vec<Vec<u8>> = Vec::new();
        loop {
            let before = rd.buffer_position() as usize;
            let ev = rd
                .read_event()
                .map_err(|e| self.err(rd.error_position() as usize, format!("XML error: {e}")))?;
            match ev {
                Event::Start(e) => {
                    let name = e.local_name().as_ref().to_vec();
                    if name == b"AppendedData" {
                        // Everything we read precedes it; its raw bytes are not XML.
                        break;
                    }
                    if path.len() >= MAX_DEPTH {
                        return Err(self.err(
                            before,
                            format!("elements nested more than {MAX_DEPTH} deep"),
                        ));
                    }
                    self.open(&e, &path, before)?;
                    path.push(name);
                }
                Event::Empty(e) => {
                    let name = e.local_name().as_ref().to_vec();
                    self.open(&e, &path, before)?;
                    self.close(&name, before)?;
                }
                Event::End(e) => {
                    self.close(e.local_name().as_ref(), before)?;
                    path.pop();
                }
                // Only the DataArray's own text: VTK nests <InformationKey> elements in it.
                Event::Text(t) if path.last().is_some_and(|p| p == b"DataArray") => {
                    self.text(t.into_inner(), rd.buffer_position() as usize)
                }
                Event::CData(t) if path.last().is_some_and(|p| p == b"DataArray") => {
                    self.text(t.into_inner(), rd.buffer_position() as usize)
                }
                Event::GeneralRef(_)
                    if self
                        .array
                        .as_ref()
                        .is_some_and(|a| a.target != Target::Skip) =>
                {
                    return Err(self.err(before, "entity reference inside a data array"));
                }
                Event::Eof => {
                    if let Some(open) = path.last() {
                        return Err(self.err(
                            self.data.len(),
                            format!("unexpected end of file inside <{}>", show(open)),
                        ));
                    }
                    break;
                }
                _ => {}
            }
        }
        if !self.seen_file {
            return Err(self.err(0, "not a VTK XML file: no <VTKFile> element"));
        }
        Ok(())
    }

    fn open(&mut self, e: &BytesStart, path: &[Vec<u8>], at: usize) -> Result<()> {
        let name = e.local_name();
        let parent = path.last().map(|p| p.as_slice());
        match name.as_ref() {
            b"VTKFile" => {
                self.seen_file = true;
                let ty = attr(e, b"type");
                if ty.as_deref() != Some(b"UnstructuredGrid".as_slice()) {
                    return Err(self.err(
                        at,
                        format!(
                            "VTK file type '{}' is not supported (only UnstructuredGrid)",
                            show(ty.as_deref().unwrap_or(b""))
                        ),
                    ));
                }
                self.header64 = attr(e, b"header_type").as_deref() == Some(b"UInt64".as_slice());
                self.big_endian =
                    attr(e, b"byte_order").as_deref() == Some(b"BigEndian".as_slice());
                self.compressed =
                    attr(e, b"compressor").is_some_and(|c| !c.trim_ascii().is_empty());
            }
            b"Piece" => {
                if parent != Some(b"UnstructuredGrid".as_slice()) {
                    return Err(self.err(at, "<Piece> outside <UnstructuredGrid>"));
                }
                let npoints = attr_u64(e, b"NumberOfPoints")
                    .ok_or_else(|| self.err(at, "<Piece> without a valid NumberOfPoints"))?;
                let ncells = attr_u64(e, b"NumberOfCells")
                    .ok_or_else(|| self.err(at, "<Piece> without a valid NumberOfCells"))?;
                self.piece = Some(Piece {
                    at,
                    npoints,
                    ncells,
                    ..Piece::default()
                });
            }
            b"DataArray" => self.open_array(e, parent, at)?,
            _ => {}
        }
        Ok(())
    }

    fn open_array(&mut self, e: &BytesStart, parent: Option<&[u8]>, at: usize) -> Result<()> {
        let Some(piece) = &self.piece else {
            self.array = Some(Array {
                target: Target::Skip,
                ty: NumType::U8,
                binary: false,
                at,
                content_at: None,
                in_file: false,
                content: Cow::Borrowed(b""),
            });
            return Ok(());
        };
        let aname = attr(e, b"Name").unwrap_or(Cow::Borrowed(b""));
        let ncomp = attr_u64(e, b"NumberOfComponents").unwrap_or(1);
        let mut target = match parent {
            Some(b"Points") if piece.points.is_none() => Target::Points,
            Some(b"Cells") => match aname.as_ref() {
                b"connectivity" => Target::Connectivity,
                b"offsets" => Target::Offsets,
                b"types" => Target::Types,
                _ => Target::Skip,
            },
            Some(b"CellData") if ncomp == 1 => match tag_rank(&aname) {
                Some(r) if piece.tags.as_ref().map_or(true, |(old, _)| r < *old) => Target::Tag(r),
                _ => Target::Skip,
            },
            _ => Target::Skip,
        };
        if target == Target::Points && ncomp != 3 {
            return Err(self.err(at, format!("points have {ncomp} components, expected 3")));
        }
        let tyname = attr(e, b"type").unwrap_or(Cow::Borrowed(b""));
        let ty = NumType::parse(&tyname);
        let format = attr(e, b"format").unwrap_or(Cow::Borrowed(b"ascii"));
        if target != Target::Skip {
            if ty.is_none() {
                return Err(self.err(at, format!("unknown data type '{}'", show(&tyname))));
            }
            match format.as_ref() {
                b"ascii" | b"binary" => {}
                b"appended" => {
                    return Err(self.err(
                        at,
                        "appended data arrays are not supported (save the file with ASCII or inline binary data)",
                    ))
                }
                f => return Err(self.err(at, format!("unknown data format '{}'", show(f)))),
            }
            if format.as_ref() == b"binary" && self.compressed {
                return Err(self.err(
                    at,
                    "compressed binary data arrays are not supported (save the file uncompressed)",
                ));
            }
        } else {
            target = Target::Skip;
        }
        self.array = Some(Array {
            target,
            ty: ty.unwrap_or(NumType::U8),
            binary: format.as_ref() == b"binary",
            at,
            content_at: None,
            in_file: false,
            content: Cow::Borrowed(b""),
        });
        Ok(())
    }

    fn text(&mut self, t: Cow<'a, [u8]>, end: usize) {
        let Some(a) = self.array.as_mut() else {
            return;
        };
        if a.target == Target::Skip {
            return;
        }
        if a.content_at.is_none() {
            // Where the text lies in the file, for error lines (borrowed text only).
            let base = self.data.as_ptr() as usize;
            let at = match &t {
                Cow::Borrowed(s) => (s.as_ptr() as usize).checked_sub(base),
                Cow::Owned(_) => None,
            };
            a.content_at = Some(at.filter(|&o| o <= self.data.len()).unwrap_or(end));
            a.in_file = at.is_some_and(|o| o + t.len() <= self.data.len());
            a.content = t;
        } else {
            a.in_file = false;
            a.content.to_mut().push(b' ');
            a.content.to_mut().extend_from_slice(&t);
        }
    }

    fn close(&mut self, name: &[u8], at: usize) -> Result<()> {
        match name {
            b"DataArray" => {
                if let Some(a) = self.array.take() {
                    if a.target != Target::Skip {
                        self.finish_array(a)?;
                    }
                }
            }
            b"Piece" => {
                if let Some(p) = self.piece.take() {
                    self.finish_piece(p, at)?;
                }
            }
            _ => {}
        }
        Ok(())
    }

    fn finish_array(&mut self, a: Array<'a>) -> Result<()> {
        let at = a.content_at.unwrap_or(a.at);
        let values = if a.binary {
            self.decode_binary(&a.content, a.ty, at)?
        } else {
            self.decode_ascii(&a, at)?
        };
        let piece = self.piece.as_mut().expect("arrays are read inside a piece");
        match a.target {
            Target::Points => piece.points = Some(values),
            Target::Connectivity => piece.conn = Some((at, values)),
            Target::Offsets => piece.offsets = Some(values),
            Target::Types => piece.types = Some(values),
            Target::Tag(r) => piece.tags = Some((r, values)),
            Target::Skip => {}
        }
        Ok(())
    }

    fn decode_ascii(&self, a: &Array<'a>, at: usize) -> Result<Values> {
        // Parse in place when the content is a slice of the file, so errors get its line.
        let (data, start) = if a.in_file {
            (&self.data[..at + a.content.len()], at)
        } else {
            (a.content.as_ref(), 0)
        };
        let mut c = Cursor::new(data, self.name);
        c.seek(start);
        let cap = capped(u64::MAX, data.len() - start, 2);
        if a.ty.is_float() {
            let mut v = Vec::with_capacity(cap);
            while let Some(t) = c.token() {
                v.push(parse_f64(t).ok_or_else(|| {
                    self.err_or(&c, start, format!("invalid number '{}'", show(t)))
                })?);
            }
            Ok(Values::F(v))
        } else {
            let mut v = Vec::with_capacity(cap);
            while let Some(t) = c.token() {
                v.push(parse_i64(t).ok_or_else(|| {
                    self.err_or(&c, start, format!("invalid integer '{}'", show(t)))
                })?);
            }
            Ok(Values::I(v))
        }
    }

    /// An error at the cursor's token when the cursor runs over the file itself.
    fn err_or(&self, c: &Cursor, start: usize, msg: String) -> Error {
        if c.data().len() <= self.data.len() && std::ptr::eq(c.data().as_ptr(), self.data.as_ptr())
        {
            c.err(msg)
        } else {
            self.err(start, msg)
        }
    }

    fn decode_binary(&self, content: &[u8], ty: NumType, at: usize) -> Result<Values> {
        let trimmed = content.trim_ascii();
        let b64: Cow<[u8]> = if trimmed.iter().any(|b| b.is_ascii_whitespace()) {
            Cow::Owned(
                trimmed
                    .iter()
                    .copied()
                    .filter(|b| !b.is_ascii_whitespace())
                    .collect(),
            )
        } else {
            Cow::Borrowed(trimmed)
        };
        let hsize: usize = if self.header64 { 8 } else { 4 };
        let hchars = hsize.div_ceil(3) * 4;
        if b64.len() < hchars {
            return Err(self.err(at, "binary data array shorter than its header"));
        }
        let bad = |e: base64::DecodeError| self.err(at, format!("invalid base64 data: {e}"));
        // VTK may encode the header separately (then it ends in exactly `pad` '='s: two
        // for a 4-byte header, one for 8 bytes) or in one stream with the data.
        let pad = (3 - hsize % 3) % 3;
        let separate =
            b64[hchars - pad..hchars].iter().all(|&b| b == b'=') && b64[hchars - pad - 1] != b'=';
        let (header, payload) = if separate {
            let h = STANDARD.decode(&b64[..hchars]).map_err(bad)?;
            let p = STANDARD.decode(&b64[hchars..]).map_err(bad)?;
            (h, p)
        } else {
            let mut all = STANDARD.decode(&b64).map_err(bad)?;
            let p = all.split_off(hsize.min(all.len()));
            (all, p)
        };
        if header.len() < hsize {
            return Err(self.err(at, "binary data array shorter than its header"));
        }
        let mut h = [0u8; 8];
        h[..hsize].copy_from_slice(&header[..hsize]);
        if self.big_endian {
            h[..hsize].reverse();
        }
        let nbytes = u64::from_le_bytes(h);
        if nbytes > payload.len() as u64 {
            return Err(self.err(
                at,
                format!(
                    "binary data array declares {nbytes} bytes but holds {}",
                    payload.len()
                ),
            ));
        }
        let payload = &payload[..nbytes as usize];
        let size = ty.size();
        if payload.len() % size != 0 {
            return Err(self.err(
                at,
                format!(
                    "binary data array of {} bytes is not a whole number of values",
                    payload.len()
                ),
            ));
        }
        let be = self.big_endian;
        let word = |c: &[u8]| {
            let mut b = [0u8; 8];
            b[..c.len()].copy_from_slice(c);
            if be {
                b[..c.len()].reverse();
            }
            b
        };
        let chunks = payload.chunks_exact(size);
        Ok(match ty {
            NumType::F32 => Values::F(
                chunks
                    .map(|c| f32::from_le_bytes(word(c)[..4].try_into().expect("4")) as f64)
                    .collect(),
            ),
            NumType::F64 => Values::F(chunks.map(|c| f64::from_le_bytes(word(c))).collect()),
            NumType::I8 => Values::I(chunks.map(|c| c[0] as i8 as i64).collect()),
            NumType::U8 => Values::I(chunks.map(|c| c[0] as i64).collect()),
            NumType::I16 => Values::I(
                chunks
                    .map(|c| i16::from_le_bytes(word(c)[..2].try_into().expect("2")) as i64)
                    .collect(),
            ),
            NumType::U16 => Values::I(
                chunks
                    .map(|c| u16::from_le_bytes(word(c)[..2].try_into().expect("2")) as i64)
                    .collect(),
            ),
            NumType::I32 => Values::I(
                chunks
                    .map(|c| i32::from_le_bytes(word(c)[..4].try_into().expect("4")) as i64)
                    .collect(),
            ),
            NumType::U32 => Values::I(
                chunks
                    .map(|c| u32::from_le_bytes(word(c)[..4].try_into().expect("4")) as i64)
                    .collect(),
            ),
            // Values past i64::MAX wrap negative and are then rejected as indices.
            NumType::I64 | NumType::U64 => {
                Values::I(chunks.map(|c| i64::from_le_bytes(word(c))).collect())
            }
        })
    }

    fn finish_piece(&mut self, p: Piece, at: usize) -> Result<()> {
        let Piece {
            at: piece_at,
            npoints,
            ncells,
            points,
            conn,
            offsets,
            types,
            tags,
        } = p;
        let base = self.mesh.nodes.len() as u64;
        if base.saturating_add(npoints) >= u32::MAX as u64 {
            return Err(self.err(piece_at, "too many points"));
        }
        match points {
            Some(Values::F(v)) if v.len() as u64 == 3 * npoints => self
                .mesh
                .nodes
                .extend(v.chunks_exact(3).map(|c| [c[0], c[1], c[2]])),
            Some(Values::I(v)) if v.len() as u64 == 3 * npoints => self.mesh.nodes.extend(
                v.chunks_exact(3)
                    .map(|c| [c[0] as f64, c[1] as f64, c[2] as f64]),
            ),
            Some(v) => {
                return Err(self.err(
                    at,
                    format!(
                        "the piece has {} point coordinates, expected 3 x {npoints}",
                        v.len()
                    ),
                ))
            }
            None if npoints == 0 => {}
            None => return Err(self.err(at, "the piece has no <Points> data array")),
        }
        if ncells == 0 {
            return Ok(());
        }
        let ints = |v: Option<Values>, what: &str| -> Result<Vec<i64>> {
            match v {
                Some(Values::I(v)) if v.len() as u64 == ncells => Ok(v),
                Some(Values::I(v)) => Err(self.err(
                    at,
                    format!("the {what} array has {} values for {ncells} cells", v.len()),
                )),
                Some(Values::F(_)) => Err(self.err(at, format!("the {what} array is not integer"))),
                None => Err(self.err(at, format!("the piece has no {what} array"))),
            }
        };
        let offsets = ints(offsets, "offsets")?;
        let types = ints(types, "types")?;
        let tags: Option<Vec<i32>> = match tags {
            None => None,
            Some((_, Values::I(v))) if v.len() as u64 == ncells => Some(
                v.iter()
                    .map(|&x| i32::try_from(x).ok())
                    .collect::<Option<_>>()
                    .ok_or_else(|| self.err(at, "a tag does not fit in 32 bits"))?,
            ),
            Some((_, Values::F(v))) if v.len() as u64 == ncells => Some(
                v.iter()
                    .map(|&x| (x.fract() == 0.0 && x.abs() <= i32::MAX as f64).then_some(x as i32))
                    .collect::<Option<_>>()
                    .ok_or_else(|| self.err(at, "a tag is not a 32-bit integer"))?,
            ),
            Some((_, v)) => {
                return Err(self.err(
                    at,
                    format!("the tag array has {} values for {ncells} cells", v.len()),
                ))
            }
        };
        let (conn_at, conn) = match conn {
            Some((a, Values::I(v))) => (a, v),
            Some((a, Values::F(_))) => {
                return Err(self.err(a, "the connectivity array is not integer"))
            }
            None => return Err(self.err(at, "the piece has no connectivity array")),
        };
        let mut prev = 0usize;
        let mut cell = [0u64; 10];
        for (i, (&end, &ty)) in offsets.iter().zip(&types).enumerate() {
            if end < prev as i64 || end as u64 > conn.len() as u64 {
                return Err(self.err(at, format!("bad offset {end} for cell {i}")));
            }
            let nodes = &conn[prev..end as usize];
            prev = end as usize;
            let Some(want) = vtk_cells::cell_len(ty) else {
                self.mesh.ignored_elements += 1;
                continue;
            };
            if nodes.len() != want {
                return Err(self.err(
                    conn_at,
                    format!(
                        "cell {i} of type {ty} has {} points, expected {want}",
                        nodes.len()
                    ),
                ));
            }
            for (o, &v) in cell.iter_mut().zip(nodes) {
                if v < 0 {
                    return Err(self.err(conn_at, format!("cell {i} refers to point {v}")));
                }
                *o = v as u64;
            }
            let tag = tags.as_ref().map_or(0, |t| t[i]);
            add_cell(
                &mut self.mesh,
                i,
                ty,
                &cell[..want],
                base as u32,
                npoints,
                tag,
            )
            .map_err(|m| self.err(conn_at, m))?;
        }
        Ok(())
    }
}
