//! PLY (Stanford polygon format), ASCII and binary little/big endian, read only.
//!
//! Hand-written rather than `ply-rs`: that crate has had no release since 2020, reads every
//! element into a map of property names to boxed values (slow and memory-hungry for large
//! scans), and its list reader trusts the file's counts. Here the header is parsed once,
//! the body is read straight into flat arrays, and every count is checked against the
//! bytes left before it is used.
//!
//! Read: element `vertex` with scalar properties `x`, `y`, `z` of any PLY type (`char`,
//! `uchar`, `short`, `ushort`, `int`, `uint`, `float`, `double` and their `int8` ...
//! `float64` aliases; every value converts to `f64` exactly, so `float` coordinates stay
//! bit-identical); element `face` with a list property `vertex_indices` (or
//! `vertex_index`) of 0-based indices, polygons split as fans (see `linear`). Other
//! properties and elements (normals, colours, `edge`, `material`, ...) are skipped,
//! lists included. Vertices are welded exactly (`weld`), every tag is 0.

use super::cursor::{capped, parse_f64, parse_u64, show, Cursor};
use super::linear::{indexed_mesh, push_fan};
use super::RawMesh;
use crate::error::Result;
use crate::geom::P3;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Encoding {
    Ascii,
    Little,
    Big,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(t: &[u8]) -> Option<Scalar> {
        Some(match t {
            b"char" | b"int8" => Scalar::I8,
            b"uchar" | b"uint8" => Scalar::U8,
            b"short" | b"int16" => Scalar::I16,
            b"ushort" | b"uint16" => Scalar::U16,
            b"int" | b"int32" => Scalar::I32,
            b"uint" | b"uint32" => Scalar::U32,
            b"float" | b"float32" => Scalar::F32,
            b"double" | b"float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    /// The value of binary bytes `b` (exactly `size()` of them, file order).
    fn decode(self, b: &[u8], big: bool) -> f64 {
        let mut a = [0u8; 8];
        a[..b.len()].copy_from_slice(b);
        if big {
            a[..b.len()].reverse();
        }
        match self {
            Scalar::I8 => a[0] as i8 as f64,
            Scalar::U8 => a[0] as f64,
            Scalar::I16 => i16::from_le_bytes([a[0], a[1]]) as f64,
            Scalar::U16 => u16::from_le_bytes([a[0], a[1]]) as f64,
            Scalar::I32 => i32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::U32 => u32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::F32 => f32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::F64 => f64::from_le_bytes(a),
        }
    }
}

#[derive(Debug, Clone)]
enum Property<'a> {
    Scalar(Scalar, &'a [u8]),
    /// Count type, item type, name.
    List(Scalar, Scalar, &'a [u8]),
}

#[derive(Debug, Clone)]
struct Element<'a> {
    name: &'a [u8],
    count: u64,
    props: Vec<Property<'a>>,
}

/// Read a PLY file held in `data`.
pub(crate) fn read(data: &[u8], name: &str) -> Result<RawMesh> {
    let mut c = Cursor::new(data, name);
    let (encoding, elements) = header(&mut c)?;
    if encoding != Encoding::Ascii {
        c.set_binary(true);
    }
    let n_vertices = elements
        .iter()
        .find(|e| e.name == b"vertex")
        .map_or(0, |e| e.count);
    let mut body = Body {
        c,
        encoding,
        n_vertices,
    };
    let mut points: Vec<P3> = Vec::new();
    let mut tris: Vec<[u32; 3]> = Vec::new();
    let mut have_faces = false;
    for e in &elements {
        if e.props.is_empty() {
            continue; // takes no bytes, whatever its count
        }
        match e.name {
            b"vertex" => points = body.vertices(e)?,
            b"face" => {
                tris = body.faces(e)?;
                have_faces = true;
            }
            _ => body.skip(e)?,
        }
    }
    if !have_faces {
        return Err(body
            .c
            .err_at(0, "no 'face' element with a 'vertex_indices' list"));
    }
    indexed_mesh(&points, tris, name)
}

/// Parses the header, leaving the cursor at the first byte of the body.
fn header<'a>(c: &mut Cursor<'a>) -> Result<(Encoding, Vec<Element<'a>>)> {
    let first = c.rest_of_line();
    if first.trim_ascii() != b"ply" {
        return Err(c.err("not a PLY file: the first line must be 'ply'"));
    }
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        if c.remaining() == 0 {
            return Err(c.eof("'end_header'"));
        }
        let line = c.rest_of_line();
        let mut w = line
            .split(|b| b.is_ascii_whitespace())
            .filter(|t| !t.is_empty());
        let Some(key) = w.next() else { continue };
        match key {
            b"comment" | b"obj_info" => {}
            b"format" => {
                encoding = Some(match w.next() {
                    Some(b"ascii") => Encoding::Ascii,
                    Some(b"binary_little_endian") => Encoding::Little,
                    Some(b"binary_big_endian") => Encoding::Big,
                    other => {
                        return Err(c.err(format!(
                            "unknown PLY format '{}'",
                            show(other.unwrap_or(b""))
                        )))
                    }
                });
            }
            b"element" => {
                let (Some(name), Some(count)) = (w.next(), w.next().and_then(parse_u64)) else {
                    return Err(c.err("expected 'element NAME COUNT'"));
                };
                // The reader takes one vertex list and one face list: a second one would
                // leave the face indices checked against the wrong vertex count.
                if (name == b"vertex" || name == b"face") && elements.iter().any(|e| e.name == name)
                {
                    return Err(c.err(format!(
                        "a second '{}' element (one is allowed)",
                        String::from_utf8_lossy(name)
                    )));
                }
                elements.push(Element {
                    name,
                    count,
                    props: Vec::new(),
                });
            }
            b"property" => {
                let Some(e) = elements.last_mut() else {
                    return Err(c.err("'property' before any 'element'"));
                };
                let ty = w.next().unwrap_or(b"");
                let prop = if ty == b"list" {
                    let ct = w.next().and_then(Scalar::parse);
                    let it = w.next().and_then(Scalar::parse);
                    match (ct, it, w.next()) {
                        (Some(ct), Some(it), Some(n)) if !matches!(ct, Scalar::F32 | Scalar::F64) => {
                            Property::List(ct, it, n)
                        }
                        _ => return Err(c.err("expected 'property list COUNT_TYPE ITEM_TYPE NAME' with an integer count type")),
                    }
                } else {
                    match (Scalar::parse(ty), w.next()) {
                        (Some(t), Some(n)) => Property::Scalar(t, n),
                        _ => {
                            return Err(c.err(format!(
                                "expected 'property TYPE NAME', unknown type '{}'",
                                show(ty)
                            )))
                        }
                    }
                };
                e.props.push(prop);
            }
            b"end_header" => break,
            other => {
                return Err(c.err(format!("unknown PLY header line '{}'", show(other))));
            }
        }
    }
    let Some(encoding) = encoding else {
        return Err(c.err("the PLY header has no 'format' line"));
    };
    Ok((encoding, elements))
}

/// The body reader: one value at a time, text or binary.
struct Body<'a> {
    c: Cursor<'a>,
    encoding: Encoding,
    n_vertices: u64,
}

impl Body<'_> {
    fn value(&mut self, t: Scalar, what: &str) -> Result<f64> {
        if self.encoding == Encoding::Ascii {
            let tok = self.c.expect_token(what)?;
            return parse_f64(tok).ok_or_else(|| {
                self.c
                    .err(format!("invalid number '{}' for {what}", show(tok)))
            });
        }
        let b = self.c.bytes(t.size(), what)?;
        Ok(t.decode(b, self.encoding == Encoding::Big))
    }

    /// A list length or index: a non-negative integer value.
    fn integer(&mut self, t: Scalar, what: &str) -> Result<u64> {
        let v = self.value(t, what)?;
        if v >= 0.0 && v.fract() == 0.0 && v <= u32::MAX as f64 {
            Ok(v as u64)
        } else {
            Err(self
                .c
                .err(format!("{what} {v} is not a valid non-negative integer")))
        }
    }

    /// Smallest number of bytes one instance of `e` takes (for capacity bounds).
    fn min_size(&self, e: &Element) -> usize {
        let per = |t: Scalar| {
            if self.encoding == Encoding::Ascii {
                2
            } else {
                t.size()
            }
        };
        e.props
            .iter()
            .map(|p| match p {
                Property::Scalar(t, _) | Property::List(t, _, _) => per(*t),
            })
            .sum::<usize>()
            .max(1)
    }

    fn skip_list(&mut self, ct: Scalar, it: Scalar) -> Result<()> {
        let n = self.integer(ct, "a list length")?;
        if self.encoding == Encoding::Ascii {
            for _ in 0..n {
                self.value(it, "a list item")?;
            }
        } else {
            self.c.need(n, it.size(), "list items")?;
            self.c.bytes(n as usize * it.size(), "list items")?;
        }
        Ok(())
    }

    fn vertices(&mut self, e: &Element) -> Result<Vec<P3>> {
        let find = |want: &[u8]| {
            e.props
                .iter()
                .position(|p| matches!(p, Property::Scalar(_, n) if *n == want))
        };
        let (Some(ix), Some(iy), Some(iz)) = (find(b"x"), find(b"y"), find(b"z")) else {
            return Err(self
                .c
                .err("the 'vertex' element has no scalar x, y and z properties"));
        };
        let mut out = Vec::with_capacity(capped(e.count, self.c.remaining(), self.min_size(e)));
        for _ in 0..e.count {
            let mut p = [0.0; 3];
            for (k, prop) in e.props.iter().enumerate() {
                match prop {
                    Property::Scalar(t, _) => {
                        let v = self.value(*t, "a vertex property")?;
                        if k == ix {
                            p[0] = v;
                        } else if k == iy {
                            p[1] = v;
                        } else if k == iz {
                            p[2] = v;
                        }
                    }
                    Property::List(ct, it, _) => self.skip_list(*ct, *it)?,
                }
            }
            out.push(p);
        }
        Ok(out)
    }

    fn faces(&mut self, e: &Element) -> Result<Vec<[u32; 3]>> {
        let Some(li) = e.props.iter().position(|p| {
            matches!(p, Property::List(_, _, n) if *n == b"vertex_indices" || *n == b"vertex_index")
        }) else {
            return Err(self.c.err("the 'face' element has no 'vertex_indices' list"));
        };
        let mut out = Vec::with_capacity(capped(e.count, self.c.remaining(), self.min_size(e)));
        let mut poly: Vec<u32> = Vec::new();
        for f in 0..e.count {
            for (k, prop) in e.props.iter().enumerate() {
                match prop {
                    Property::Scalar(t, _) => {
                        self.value(*t, "a face property")?;
                    }
                    Property::List(ct, it, _) if k == li => {
                        let n = self.integer(*ct, "a face's vertex count")?;
                        if n < 3 {
                            return Err(self.c.err(format!(
                                "face {f} has {n} vertices (at least 3 are needed)"
                            )));
                        }
                        poly.clear();
                        for _ in 0..n {
                            let v = self.integer(*it, "a vertex index")?;
                            if v >= self.n_vertices {
                                return Err(self.c.err(format!(
                                    "face {f}: vertex index {v} is not in 0..{}",
                                    self.n_vertices
                                )));
                            }
                            poly.push(v as u32);
                        }
                        push_fan(&poly, &mut out);
                    }
                    Property::List(ct, it, _) => self.skip_list(*ct, *it)?,
                }
            }
        }
        Ok(out)
    }

    fn skip(&mut self, e: &Element) -> Result<()> {
        for _ in 0..e.count {
            for prop in &e.props {
                match prop {
                    Property::Scalar(t, _) => {
                        self.value(*t, "a property")?;
                    }
                    Property::List(ct, it, _) => self.skip_list(*ct, *it)?,
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn binary(big: bool) -> Vec<u8> {
        let fmt = if big {
            "binary_big_endian"
        } else {
            "binary_little_endian"
        };
        let mut v = format!(
            "ply\nformat {fmt} 1.0\ncomment x\nelement vertex 3\nproperty float x\n\
             property float y\nproperty double z\nproperty list uchar int extra\n\
             element face 1\nproperty uchar flags\nproperty list uchar uint vertex_indices\n\
             end_header\n"
        )
        .into_bytes();
        let f32b = |x: f32| {
            if big {
                x.to_be_bytes()
            } else {
                x.to_le_bytes()
            }
        };
        let f64b = |x: f64| {
            if big {
                x.to_be_bytes()
            } else {
                x.to_le_bytes()
            }
        };
        let u32b = |x: u32| {
            if big {
                x.to_be_bytes()
            } else {
                x.to_le_bytes()
            }
        };
        for p in [[0.1f32, 0.0], [1.0, 0.0], [0.0, 1.0]] {
            v.extend(f32b(p[0]));
            v.extend(f32b(p[1]));
            v.extend(f64b(0.3));
            v.push(1);
            v.extend(u32b(7));
        }
        v.push(9);
        v.push(3);
        for i in [0u32, 1, 2] {
            v.extend(u32b(i));
        }
        v
    }

    #[test]
    fn binary_both_endians_exact_f32() {
        for big in [false, true] {
            let m = read(&binary(big), "t.ply").unwrap();
            assert_eq!(m.tri3, vec![[0, 1, 2]]);
            assert_eq!(m.nodes[0], [0.1f32 as f64, 0.0, 0.3]);
        }
        let mut b = binary(false);
        b.pop();
        assert!(read(&b, "t.ply").unwrap_err().to_string().contains("byte"));
    }

    #[test]
    fn ascii_with_quads() {
        let text =
            "ply\nformat ascii 1.0\nelement vertex 4\nproperty double x\nproperty double y\n\
                    property double z\nelement face 1\nproperty list uchar int vertex_index\n\
                    end_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";
        let m = read(text.as_bytes(), "t.ply").unwrap();
        assert_eq!(m.tri3, vec![[0, 1, 2], [0, 2, 3]]);
        let bad = text.replace("4 0 1 2 3", "4 0 1 2 4");
        let e = read(bad.as_bytes(), "t.ply").unwrap_err().to_string();
        assert!(e.starts_with("t.ply:14:"), "{e}");
    }
}
