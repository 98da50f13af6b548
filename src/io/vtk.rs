//! Legacy VTK `.vtk` files, `UNSTRUCTURED_GRID`, ASCII or BINARY.
//!
//! Hand-written: the legacy format is a flat token stream (no crate worth a dependency
//! covers it); we read both the classic `CELLS n size` layout and the 5.x
//! `OFFSETS`/`CONNECTIVITY` layout, skip point data and unknown cell arrays, and take
//! the tags from the first cell array named in `vtk_cells::TAG_ARRAYS`. In a BINARY file
//! the keyword lines are text and each data block is big-endian values of the type its
//! line names, starting after that line's break.

use std::io::{self, Write};

use super::cursor::{capped, parse_f64, parse_i64, show, Cursor};
use super::text_out::{float, int, point, uint};
use super::vtk_cells::{self, add_cell, tag_rank, QUALITY_ARRAYS, TAG_ARRAY};
use super::{MeshView, RawMesh};
use crate::error::Result;

/// Write an ASCII legacy VTK file (version 4.2 layout): tetrahedra and boundary
/// triangles, the Int32 cell array `BoundaryTag`, and with `quality` (per tetrahedron)
/// the double cell arrays of [`QUALITY_ARRAYS`] (0 for triangles).
pub(crate) fn write<W: Write>(
    w: &mut W,
    view: &MeshView,
    quality: Option<&[[f64; 2]]>,
) -> io::Result<()> {
    w.write_all(
        b"# vtk DataFile Version 4.2\ncurvetet P2 mesh\nASCII\nDATASET UNSTRUCTURED_GRID\n",
    )?;
    w.write_all(b"POINTS ")?;
    uint(w, view.nodes.len() as u64)?;
    w.write_all(b" double\n")?;
    for p in view.nodes {
        point(w, p)?;
        w.write_all(b"\n")?;
    }
    let (ncells, nconn) = vtk_cells::sizes(view);
    w.write_all(b"CELLS ")?;
    uint(w, ncells as u64)?;
    w.write_all(b" ")?;
    uint(w, (ncells + nconn) as u64)?;
    w.write_all(b"\n")?;
    for c in vtk_cells::cells(view) {
        uint(w, c.len as u64)?;
        for &v in c.nodes() {
            w.write_all(b" ")?;
            uint(w, v as u64)?;
        }
        w.write_all(b"\n")?;
    }
    w.write_all(b"CELL_TYPES ")?;
    uint(w, ncells as u64)?;
    w.write_all(b"\n")?;
    for c in vtk_cells::cells(view) {
        uint(w, c.ty as u64)?;
        w.write_all(b"\n")?;
    }
    w.write_all(b"CELL_DATA ")?;
    uint(w, ncells as u64)?;
    w.write_all(b"\nSCALARS ")?;
    w.write_all(TAG_ARRAY.as_bytes())?;
    w.write_all(b" int 1\nLOOKUP_TABLE default\n")?;
    for c in vtk_cells::cells(view) {
        int(w, c.tag as i64)?;
        w.write_all(b"\n")?;
    }
    for (k, name) in QUALITY_ARRAYS.iter().enumerate() {
        let Some(q) = quality else { break };
        w.write_all(b"SCALARS ")?;
        w.write_all(name.as_bytes())?;
        w.write_all(b" double 1\nLOOKUP_TABLE default\n")?;
        for v in q
            .iter()
            .map(|e| e[k])
            .chain((0..view.tri6.len()).map(|_| 0.0))
        {
            float(w, v)?;
            w.write_all(b"\n")?;
        }
    }
    Ok(())
}

#[derive(Clone, Copy, PartialEq)]
enum Attach {
    None,
    Points,
    Cells,
}

struct Legacy<'a> {
    c: Cursor<'a>,
    points: Option<Vec<[f64; 3]>>,
    /// Cell `i` is `conn[offsets[i]..offsets[i + 1]]`.
    offsets: Vec<u64>,
    conn: Vec<u64>,
    have_cells: bool,
    types: Option<Vec<i64>>,
    /// (rank, tags) of the best tag array seen.
    tags: Option<(usize, Vec<i32>)>,
    attach: Attach,
    attach_count: u64,
    /// A BINARY file: data blocks are big-endian values.
    binary: bool,
}

/// A legacy data type: its size in bytes and whether it is a float.
#[derive(Clone, Copy)]
struct Scalar {
    size: usize,
    float: bool,
    signed: bool,
}

impl Scalar {
    const I32: Scalar = Scalar {
        size: 4,
        float: false,
        signed: true,
    };
    const U8: Scalar = Scalar {
        size: 1,
        float: false,
        signed: false,
    };

    fn parse(t: &[u8]) -> Option<Scalar> {
        let (size, float, signed) = match t.to_ascii_lowercase().as_slice() {
            b"char" | b"vtktypeint8" => (1, false, true),
            b"unsigned_char" | b"vtktypeuint8" => (1, false, false),
            b"short" | b"vtktypeint16" => (2, false, true),
            b"unsigned_short" | b"vtktypeuint16" => (2, false, false),
            b"int" | b"vtktypeint32" => (4, false, true),
            b"unsigned_int" | b"vtktypeuint32" => (4, false, false),
            b"long" | b"vtktypeint64" | b"vtkidtype" => (8, false, true),
            b"unsigned_long" | b"vtktypeuint64" => (8, false, false),
            b"float" => (4, true, true),
            b"double" => (8, true, true),
            _ => return None,
        };
        Some(Scalar {
            size,
            float,
            signed,
        })
    }
}

/// Read a legacy (ASCII or BINARY) .vtk file held in `data`.
pub(crate) fn read(data: &[u8], name: &str) -> Result<RawMesh> {
    let mut c = Cursor::new(data, name);
    let first = c.rest_of_line();
    if !first.starts_with(b"# vtk DataFile") {
        return Err(c.err("not a legacy VTK file: expected '# vtk DataFile Version ...'"));
    }
    c.rest_of_line(); // title
    let enc = c.expect_token("ASCII or BINARY")?;
    let binary = enc.eq_ignore_ascii_case(b"BINARY");
    if !binary && !enc.eq_ignore_ascii_case(b"ASCII") {
        return Err(c.err(format!("expected ASCII or BINARY, found '{}'", show(enc))));
    }
    let mut r = Legacy {
        c,
        points: None,
        offsets: Vec::new(),
        conn: Vec::new(),
        have_cells: false,
        types: None,
        tags: None,
        attach: Attach::None,
        attach_count: 0,
        binary,
    };
    r.c.set_swap(binary);
    r.body()?;
    r.finish()
}

fn upper(t: &[u8]) -> Vec<u8> {
    t.to_ascii_uppercase()
}

impl<'a> Legacy<'a> {
    fn max(&self) -> u64 {
        self.c.remaining() as u64
    }

    /// The data type named by token `t`: in a binary file it must be one we know.
    fn data_type(&self, t: &[u8]) -> Result<Option<Scalar>> {
        match Scalar::parse(t) {
            None if self.binary => Err(self.c.err(format!(
                "data type '{}' is not supported in a binary file",
                show(t)
            ))),
            s => Ok(s),
        }
    }

    /// Before a data block: in a binary file, move past the keyword line's break.
    fn start_data(&mut self) {
        if self.binary {
            self.c.rest_of_line();
        }
    }

    /// Does the current line hold another token? (In a binary file, data follows the
    /// line: a token must not be looked for past its break.)
    fn line_has_more(&self) -> bool {
        let d = self.c.data();
        let mut p = self.c.pos();
        while p < d.len() && d[p] != b'\n' {
            if !d[p].is_ascii_whitespace() {
                return true;
            }
            p += 1;
        }
        false
    }

    /// One value of a data block: a token in ASCII, `ty`'s big-endian bytes in binary;
    /// integers as `Ok(Err(i))`, floats as `Ok(Ok(x))`.
    fn value(&mut self, ty: Option<Scalar>, what: &str) -> Result<std::result::Result<f64, i64>> {
        if !self.binary {
            let t = self.c.expect_token(what)?;
            if let Some(i) = parse_i64(t) {
                return Ok(Err(i));
            }
            return parse_f64(t).map(Ok).ok_or_else(|| {
                self.c
                    .err(format!("invalid number '{}' for {what}", show(t)))
            });
        }
        let ty = ty.expect("binary data blocks have a known type");
        let b = self.c.bytes(ty.size, what)?;
        let mut w = [0u8; 8];
        for (k, &x) in b.iter().rev().enumerate() {
            w[k] = x;
        }
        Ok(match (ty.float, ty.size) {
            (true, 4) => Ok(f32::from_le_bytes(w[..4].try_into().expect("4")) as f64),
            (true, _) => Ok(f64::from_le_bytes(w)),
            (false, n) => {
                let v = u64::from_le_bytes(w);
                let bits = 8 * n as u32;
                if ty.signed && n < 8 && v >> (bits - 1) & 1 == 1 {
                    Err((v | (u64::MAX << bits)) as i64)
                } else {
                    Err(v as i64)
                }
            }
        })
    }

    fn float(&mut self, ty: Option<Scalar>, what: &str) -> Result<f64> {
        Ok(match self.value(ty, what)? {
            Ok(x) => x,
            Err(i) => i as f64,
        })
    }

    /// A non-negative integer value.
    fn uint(&mut self, ty: Option<Scalar>, what: &str) -> Result<u64> {
        match self.value(ty, what)? {
            Err(i) if i >= 0 => Ok(i as u64),
            Err(i) => Err(self
                .c
                .err(format!("invalid non-negative integer {i} for {what}"))),
            Ok(x) => Err(self.c.err(format!("{what} {x} is not an integer"))),
        }
    }

    fn body(&mut self) -> Result<()> {
        while let Some(tok) = self.c.token() {
            match upper(tok).as_slice() {
                b"DATASET" => {
                    let t = self.c.expect_token("dataset type")?;
                    if !t.eq_ignore_ascii_case(b"UNSTRUCTURED_GRID") {
                        return Err(self.c.err(format!(
                            "dataset '{}' is not supported (only UNSTRUCTURED_GRID)",
                            show(t)
                        )));
                    }
                }
                b"POINTS" => self.points()?,
                b"CELLS" => self.cells()?,
                b"CELL_TYPES" => self.cell_types()?,
                b"CELL_DATA" => {
                    self.attach_count = self.c.count("number of cells", self.max())?;
                    self.attach = Attach::Cells;
                }
                b"POINT_DATA" => {
                    self.attach_count = self.c.count("number of points", self.max())?;
                    self.attach = Attach::Points;
                }
                b"SCALARS" => self.scalars()?,
                b"FIELD" => self.field()?,
                b"VECTORS" | b"NORMALS" => self.skip_attribute(3, true)?,
                b"TENSORS" => self.skip_attribute(9, true)?,
                b"TEXTURE_COORDINATES" => {
                    self.c.expect_token("array name")?;
                    let dim = self.c.count("dimension", 3)? as usize;
                    self.skip_attribute(dim, true)?
                }
                b"COLOR_SCALARS" => {
                    self.c.expect_token("array name")?;
                    let n = self.c.count("number of values", 16)? as usize;
                    self.skip_attribute(n, false)?
                }
                b"LOOKUP_TABLE" => {
                    self.c.expect_token("table name")?;
                    let n = self.c.count("table size", self.max())?;
                    self.start_data();
                    self.skip_values(Some(Scalar::U8), n.saturating_mul(4))?;
                }
                b"METADATA" => self.metadata(),
                _ => return Err(self.c.err(format!("unexpected keyword '{}'", show(tok)))),
            }
        }
        Ok(())
    }

    fn points(&mut self) -> Result<()> {
        if self.points.is_some() {
            return Err(self.c.err("a second POINTS section"));
        }
        let n = self.c.count("number of points", u32::MAX as u64 - 1)?;
        let t = self.c.expect_token("point data type")?;
        let ty = self.data_type(t)?;
        self.start_data();
        let mut p = Vec::with_capacity(capped(n, self.c.remaining(), 6));
        for _ in 0..n {
            let x = self.float(ty, "x coordinate")?;
            let y = self.float(ty, "y coordinate")?;
            let z = self.float(ty, "z coordinate")?;
            p.push([x, y, z]);
        }
        self.points = Some(p);
        Ok(())
    }

    fn index(&mut self, ty: Option<Scalar>, npoints: u64, cell: usize) -> Result<u64> {
        let v = self.uint(ty, "point index")?;
        if v >= npoints {
            return Err(self.c.err(format!(
                "cell {cell} refers to point {v}, but there are {npoints} points"
            )));
        }
        Ok(v)
    }

    fn cells(&mut self) -> Result<()> {
        if self.have_cells {
            return Err(self.c.err("a second CELLS section"));
        }
        let Some(npoints) = self.points.as_ref().map(|p| p.len() as u64) else {
            return Err(self.c.err("CELLS before POINTS"));
        };
        self.have_cells = true;
        let a = self.c.count("number of cells", self.max())?;
        let b = self.c.count("cell list size", self.max())?;
        if self.c.peek_token() == Some(b"OFFSETS") {
            // VTK 5.x: a = number of offsets (cells + 1), b = connectivity length.
            self.c.token();
            let t = self.c.expect_token("offsets type")?;
            let ty = self.data_type(t)?;
            self.start_data();
            self.offsets.reserve(capped(a, self.c.remaining(), 2));
            for _ in 0..a {
                let o = self.uint(ty, "offset")?;
                if o > b || self.offsets.last().is_some_and(|&l| o < l) {
                    return Err(self.c.err(format!("bad cell offset {o}")));
                }
                self.offsets.push(o);
            }
            if self.offsets.first().is_some_and(|&o| o != 0) {
                return Err(self.c.err("the first cell offset must be 0"));
            }
            self.c.expect_word("CONNECTIVITY")?;
            let t = self.c.expect_token("connectivity type")?;
            let ty = self.data_type(t)?;
            self.start_data();
            self.conn.reserve(capped(b, self.c.remaining(), 2));
            let mut cell = 0;
            for k in 0..b {
                while cell + 1 < self.offsets.len() && self.offsets[cell + 1] <= k {
                    cell += 1;
                }
                let v = self.index(ty, npoints, cell)?;
                self.conn.push(v);
            }
            if self.offsets.is_empty() {
                self.offsets.push(0);
            }
            if *self.offsets.last().expect("non-empty") != b {
                return Err(self
                    .c
                    .err("the last cell offset is not the connectivity length"));
            }
        } else {
            self.offsets.reserve(capped(a, self.c.remaining(), 2) + 1);
            self.conn.reserve(capped(b, self.c.remaining(), 2));
            self.offsets.push(0);
            self.start_data();
            let ty = Some(Scalar::I32);
            for cell in 0..a as usize {
                let k = self.uint(ty, "number of cell points")?;
                if k > self.max() {
                    return Err(self.c.err(format!(
                        "cell {cell} has {k} points, more than the file holds"
                    )));
                }
                for _ in 0..k {
                    let v = self.index(ty, npoints, cell)?;
                    self.conn.push(v);
                }
                self.offsets.push(self.conn.len() as u64);
            }
            if self.conn.len() as u64 + a != b {
                return Err(self.c.err(format!(
                    "the cell list has {} numbers but the CELLS line says {b}",
                    self.conn.len() as u64 + a
                )));
            }
        }
        Ok(())
    }

    fn cell_types(&mut self) -> Result<()> {
        if !self.have_cells {
            return Err(self.c.err("CELL_TYPES before CELLS"));
        }
        if self.types.is_some() {
            return Err(self.c.err("a second CELL_TYPES section"));
        }
        let ncells = self.offsets.len() as u64 - 1;
        let n = self.c.count("number of cells", self.max())?;
        if n != ncells {
            return Err(self
                .c
                .err(format!("CELL_TYPES has {n} cells but CELLS has {ncells}")));
        }
        let mut t = Vec::with_capacity(capped(n, self.c.remaining(), 2));
        self.start_data();
        for i in 0..n as usize {
            let ty = match self.value(Some(Scalar::I32), "cell type")? {
                Err(i) => i,
                Ok(x) => return Err(self.c.err(format!("cell type {x} is not an integer"))),
            };
            let len = self.offsets[i + 1] - self.offsets[i];
            if let Some(want) = vtk_cells::cell_len(ty) {
                if len != want as u64 {
                    return Err(self.c.err(format!(
                        "cell {i} of type {ty} has {len} points, expected {want}"
                    )));
                }
            }
            t.push(ty);
        }
        self.types = Some(t);
        Ok(())
    }

    /// `SCALARS name type [ncomp]`, an optional `LOOKUP_TABLE name`, then the values.
    fn scalars(&mut self) -> Result<()> {
        let name = self.c.expect_token("array name")?;
        let t = self.c.expect_token("data type")?;
        let ty = self.data_type(t)?;
        let mut ncomp = 1;
        if let Some(t) = self
            .c
            .peek_token()
            .filter(|_| !self.binary || self.line_has_more())
        {
            if let Some(v) = parse_i64(t) {
                self.c.token();
                if !(1..=4).contains(&v) {
                    return Err(self.c.err(format!("bad number of components {v}")));
                }
                ncomp = v as u64;
            }
        }
        if self
            .c
            .peek_token()
            .is_some_and(|t| t.eq_ignore_ascii_case(b"LOOKUP_TABLE"))
        {
            self.c.token();
            self.c.expect_token("lookup table name")?;
        }
        let n = self.attached()?.saturating_mul(ncomp);
        self.start_data();
        self.values(name, ty, n, ncomp == 1)
    }

    /// `FIELD name narrays`, then per array `name ncomp ntuples type` and the values.
    fn field(&mut self) -> Result<()> {
        self.c.expect_token("field name")?;
        let narrays = self.c.count("number of arrays", self.max())?;
        for _ in 0..narrays {
            let name = self.c.expect_token("array name")?;
            let ncomp = self.c.count("number of components", self.max())?;
            let ntuples = self.c.count("number of tuples", self.max())?;
            let t = self.c.expect_token("data type")?;
            let ty = self.data_type(t)?;
            self.start_data();
            let is_tag = ncomp == 1 && self.attach == Attach::Cells && ntuples == self.attach_count;
            self.values(name, ty, ncomp.saturating_mul(ntuples), is_tag)?;
            if self.c.peek_token().is_some_and(|t| t == b"METADATA") {
                self.c.token();
                self.metadata();
            }
        }
        Ok(())
    }

    /// The number of tuples of the current `CELL_DATA`/`POINT_DATA` block.
    fn attached(&self) -> Result<u64> {
        if self.attach == Attach::None {
            return Err(self.c.err("attribute data outside CELL_DATA or POINT_DATA"));
        }
        Ok(self.attach_count)
    }

    /// Read `n` values; keep them as tags if `maybe_tag` and the array has a tag name.
    fn values(&mut self, name: &[u8], ty: Option<Scalar>, n: u64, maybe_tag: bool) -> Result<()> {
        let rank = if maybe_tag && self.attach == Attach::Cells {
            tag_rank(name)
        } else {
            None
        };
        let better = match (&self.tags, rank) {
            (_, None) => false,
            (None, Some(_)) => true,
            (Some((old, _)), Some(r)) => r < *old,
        };
        if !better {
            return self.skip_values(ty, n);
        }
        let mut tags = Vec::with_capacity(capped(n, self.c.remaining(), 2));
        for _ in 0..n {
            let v = match self.value(ty, "tag value")? {
                Err(i) => Some(i),
                Ok(x) => (x.fract() == 0.0 && x.abs() < 1e18).then_some(x as i64),
            };
            let v = v
                .and_then(|v| i32::try_from(v).ok())
                .ok_or_else(|| self.c.err("invalid tag value (not a 32-bit integer)"))?;
            tags.push(v);
        }
        self.tags = Some((rank.expect("ranked"), tags));
        Ok(())
    }

    fn skip_values(&mut self, ty: Option<Scalar>, n: u64) -> Result<()> {
        if self.binary {
            let size = ty.expect("binary data blocks have a known type").size as u64;
            let bytes = n
                .checked_mul(size)
                .filter(|&b| b <= self.max())
                .ok_or_else(|| self.c.eof(&format!("{n} data values")))?;
            self.c.bytes(bytes as usize, "data values")?;
            return Ok(());
        }
        for _ in 0..n {
            self.c.expect_token("a data value")?;
        }
        Ok(())
    }

    /// Skip an attribute of `ncomp` values per tuple: `typed` ones name their data type
    /// (after the array name), the others are unsigned chars in binary.
    fn skip_attribute(&mut self, ncomp: usize, typed: bool) -> Result<()> {
        let ty = if typed {
            self.c.expect_token("array name")?;
            let t = self.c.expect_token("data type")?;
            self.data_type(t)?
        } else {
            Some(Scalar::U8)
        };
        let n = self.attached()?.saturating_mul(ncomp as u64);
        self.start_data();
        self.skip_values(ty, n)
    }

    /// VTK 5 `METADATA` blocks run to the next blank line.
    fn metadata(&mut self) {
        self.c.rest_of_line();
        while self.c.remaining() > 0 {
            let line = self.c.rest_of_line();
            if line.iter().all(|b| b.is_ascii_whitespace()) {
                break;
            }
        }
    }

    fn finish(self) -> Result<RawMesh> {
        let Some(points) = self.points else {
            return Err(self.c.eof("POINTS"));
        };
        if !self.have_cells {
            return Err(self.c.eof("CELLS"));
        }
        let Some(types) = self.types else {
            return Err(self.c.eof("CELL_TYPES"));
        };
        let tags = match self.tags {
            Some((_, t)) if t.len() == types.len() => Some(t),
            Some((_, t)) => {
                return Err(self.c.err(format!(
                    "the tag array has {} values for {} cells",
                    t.len(),
                    types.len()
                )))
            }
            None => None,
        };
        let npoints = points.len() as u64;
        let mut mesh = RawMesh {
            nodes: points,
            ..RawMesh::default()
        };
        for (i, &ty) in types.iter().enumerate() {
            let (s, e) = (self.offsets[i] as usize, self.offsets[i + 1] as usize);
            let tag = tags.as_ref().map_or(0, |t| t[i]);
            add_cell(&mut mesh, i, ty, &self.conn[s..e], 0, npoints, tag)
                .map_err(|m| self.c.err(m))?;
        }
        Ok(mesh)
    }
}
