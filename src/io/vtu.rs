//! Reading VTK XML unstructured grid `.vtu` files.
//!
//! The XML is parsed by `quick-xml` (zero-copy over the in-memory file); the data arrays'
//! text numbers are parsed by our own cursor, binary ones through [`vtu_data`]. Read:
//! `ascii` arrays, inline `binary` (base64) arrays, and `appended` arrays in an
//! `<AppendedData>` section of `raw` or `base64` encoding (VTK's writer default); a
//! UInt32 or UInt64 header, either byte order, uncompressed or zlib- or LZ4-compressed
//! (meshio's and VTK's defaults). Several pieces are concatenated.
//!
//! [`vtu_data`]: super::vtu_data

use quick_xml::events::{BytesStart, Event};
use quick_xml::Reader;
use std::borrow::Cow;

use super::cursor::{capped, parse_f64, parse_i64, show, Cursor};
use super::vtk_cells::{self, add_cell, tag_rank};
use super::vtu_data::{array_bytes, base64_runs, Compressor, Layout};
use super::{PhysicalName, RawMesh};
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
    /// A field data array (tag, dimension) naming a physical group, as meshio writes
    /// Gmsh's physical names.
    Group,
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
    /// For an `appended` array: its offset into the appended data.
    appended: Option<u64>,
    /// Its `Name` (kept for [`Target::Group`] arrays only).
    name: String,
}

/// An appended array of a piece, read when the `<AppendedData>` section is reached.
struct Pending {
    target: Target,
    ty: NumType,
    offset: u64,
    at: usize,
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
    pending: Vec<Pending>,
}

struct Vtu<'a> {
    data: &'a [u8],
    name: &'a str,
    header64: bool,
    big_endian: bool,
    compressor: Compressor,
    seen_file: bool,
    /// Pieces waiting for their appended arrays (and the pieces after them, kept in
    /// order), with the offsets of their `</Piece>`.
    deferred: Vec<(Piece, usize)>,
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
        compressor: Compressor::None,
        seen_file: false,
        deferred: Vec::new(),
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
                        // Everything else precedes it; its raw bytes are not XML.
                        self.appended(&e, before, rd.buffer_position() as usize)?;
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
        if let Some(p) = self.deferred.first().and_then(|(p, _)| p.pending.first()) {
            return Err(self.err(
                p.at,
                "an appended data array, but the file has no <AppendedData> section",
            ));
        }
        Ok(())
    }

    /// Read the deferred pieces' appended arrays from the `<AppendedData>` element
    /// starting at `at`, whose start tag ends at `content`.
    fn appended(&mut self, e: &BytesStart, at: usize, content: usize) -> Result<()> {
        let encoding = attr(e, b"encoding").unwrap_or(Cow::Borrowed(b"raw"));
        let base64 = match encoding.trim_ascii() {
            b"raw" => false,
            b"base64" => true,
            other => {
                return Err(self.err(
                    at,
                    format!("unknown appended data encoding '{}'", show(other)),
                ))
            }
        };
        // The data starts after an underscore.
        let rest = &self.data[content.min(self.data.len())..];
        let skip = rest.iter().take_while(|b| b.is_ascii_whitespace()).count();
        if rest.get(skip) != Some(&b'_') {
            return Err(self.err(content + skip, "<AppendedData> does not start with '_'"));
        }
        let start = content + skip + 1;
        let layout = self.layout();
        for (mut piece, end) in std::mem::take(&mut self.deferred) {
            for p in std::mem::take(&mut piece.pending) {
                let from = usize::try_from(p.offset)
                    .ok()
                    .and_then(|o| o.checked_add(start))
                    .filter(|&o| o <= self.data.len())
                    .ok_or_else(|| {
                        self.err(
                            p.at,
                            format!(
                                "appended data offset {} is past the end of the file",
                                p.offset
                            ),
                        )
                    })?;
                let bytes: Cow<[u8]> = if base64 {
                    Cow::Owned(base64_runs(&self.data[from..]).map_err(|m| self.err(p.at, m))?)
                } else {
                    Cow::Borrowed(&self.data[from..])
                };
                let values = array_bytes(&bytes, layout)
                    .map_err(|m| self.err(p.at, m))
                    .and_then(|b| self.values(&b, p.ty, p.at))?;
                store(&mut piece, p.target, p.at, values);
            }
            self.finish_piece(piece, end)?;
        }
        Ok(())
    }

    fn layout(&self) -> Layout {
        Layout {
            header64: self.header64,
            big_endian: self.big_endian,
            compressor: self.compressor,
        }
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
                self.compressor = Compressor::parse(attr(e, b"compressor").as_deref())
                    .map_err(|m| self.err(at, m))?;
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
            // Outside a piece: only a group's name, (tag, dim) of an integer type in ascii
            // or inline binary, is read; anything else there is skipped.
            let ty = attr(e, b"type").and_then(|t| NumType::parse(&t));
            let format = attr(e, b"format");
            let group = parent == Some(b"FieldData".as_slice())
                && attr_u64(e, b"NumberOfComponents") == Some(2)
                && attr_u64(e, b"NumberOfTuples").unwrap_or(1) == 1
                && ty.is_some_and(|t| !t.is_float())
                && matches!(format.as_deref(), Some(b"ascii") | Some(b"binary") | None);
            self.array = Some(Array {
                target: if group { Target::Group } else { Target::Skip },
                ty: ty.unwrap_or(NumType::U8),
                binary: format.as_deref() == Some(b"binary".as_slice()),
                at,
                content_at: None,
                in_file: false,
                content: Cow::Borrowed(b""),
                appended: None,
                name: attr(e, b"Name")
                    .and_then(|n| {
                        quick_xml::escape::unescape(&String::from_utf8_lossy(&n))
                            .ok()
                            .map(|c| c.into_owned())
                    })
                    .unwrap_or_default(),
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
        let mut appended = None;
        if target != Target::Skip {
            if ty.is_none() {
                return Err(self.err(at, format!("unknown data type '{}'", show(&tyname))));
            }
            match format.as_ref() {
                b"ascii" | b"binary" => {}
                b"appended" => {
                    appended = Some(attr_u64(e, b"offset").ok_or_else(|| {
                        self.err(at, "an appended data array without a valid offset")
                    })?)
                }
                f => return Err(self.err(at, format!("unknown data format '{}'", show(f)))),
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
            appended,
            name: String::new(),
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
                    if a.target == Target::Group {
                        self.group_name(a)?;
                    } else if a.target != Target::Skip {
                        self.finish_array(a)?;
                    }
                }
            }
            b"Piece" => {
                if let Some(p) = self.piece.take() {
                    if p.pending.is_empty() && self.deferred.is_empty() {
                        self.finish_piece(p, at)?;
                    } else {
                        self.deferred.push((p, at));
                    }
                }
            }
            _ => {}
        }
        Ok(())
    }

    /// A field data array naming a group: kept when it holds (tag, dimension 0..3).
    fn group_name(&mut self, a: Array<'a>) -> Result<()> {
        let at = a.content_at.unwrap_or(a.at);
        let values = self.inline_values(&a, at)?;
        if let Values::I(v) = values {
            if let [tag, dim] = v[..] {
                if let (Ok(tag), true) = (i32::try_from(tag), (0..=3).contains(&dim)) {
                    self.mesh.physical_names.push(PhysicalName {
                        dim: dim as u8,
                        tag,
                        name: a.name,
                    });
                }
            }
        }
        Ok(())
    }

    fn finish_array(&mut self, a: Array<'a>) -> Result<()> {
        if let Some(offset) = a.appended {
            let piece = self.piece.as_mut().expect("arrays are read inside a piece");
            piece.pending.push(Pending {
                target: a.target,
                ty: a.ty,
                offset,
                at: a.at,
            });
            return Ok(());
        }
        let at = a.content_at.unwrap_or(a.at);
        let values = self.inline_values(&a, at)?;
        let piece = self.piece.as_mut().expect("arrays are read inside a piece");
        store(piece, a.target, at, values);
        Ok(())
    }

    /// The values of an array held inline (base64 binary or ASCII), its content at `at`.
    fn inline_values(&self, a: &Array<'a>, at: usize) -> Result<Values> {
        if a.binary {
            let bytes = base64_runs(a.content.trim_ascii())
                .and_then(|b| array_bytes(&b, self.layout()))
                .map_err(|m| self.err(at, m))?;
            self.values(&bytes, a.ty, at)
        } else {
            self.decode_ascii(a, at)
        }
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

    /// The values of an array's data bytes (file byte order).
    fn values(&self, payload: &[u8], ty: NumType, at: usize) -> Result<Values> {
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
            pending: _,
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

/// Put an array's values where they belong in the piece.
fn store(piece: &mut Piece, target: Target, at: usize, values: Values) {
    match target {
        Target::Points => piece.points = Some(values),
        Target::Connectivity => piece.conn = Some((at, values)),
        Target::Offsets => piece.offsets = Some(values),
        Target::Types => piece.types = Some(values),
        Target::Tag(r) => piece.tags = Some((r, values)),
        Target::Group | Target::Skip => {}
    }
}
