//! A byte cursor shared by the readers: whitespace-separated tokens for the text formats,
//! fixed-size little/big-endian values for Gmsh's binary sections, and error locations
//! (`file:LINE` for text files, `file: byte N` for binary ones).
//!
//! Hand-written on purpose: the numbers are parsed straight from the input slice (no
//! `String` per number), line numbers are computed only when an error is reported, and
//! every read is bounds-checked so hostile input ends in an `Err`, never a panic.

use crate::error::{Error, Result};

/// A read position in an in-memory file.
pub(crate) struct Cursor<'a> {
    data: &'a [u8],
    pos: usize,
    /// Start of the last token or value read, for error locations.
    mark: usize,
    name: &'a str,
    /// Report byte offsets rather than lines.
    binary: bool,
    /// Swap the bytes of binary values (file written on a big-endian machine).
    swap: bool,
    /// `#` starts a comment running to the end of the line (medit).
    hash_comments: bool,
}

impl<'a> Cursor<'a> {
    /// A cursor at the start of `data`; `name` is used in error locations.
    pub fn new(data: &'a [u8], name: &'a str) -> Self {
        Cursor {
            data,
            pos: 0,
            mark: 0,
            name,
            binary: false,
            swap: false,
            hash_comments: false,
        }
    }

    /// Report errors as byte offsets from now on.
    pub fn set_binary(&mut self, binary: bool) {
        self.binary = binary;
    }

    /// Swap the byte order of binary values.
    pub fn set_swap(&mut self, swap: bool) {
        self.swap = swap;
    }

    /// Treat `#` as the start of a comment.
    pub fn set_hash_comments(&mut self, on: bool) {
        self.hash_comments = on;
    }

    /// The current byte offset.
    pub fn pos(&self) -> usize {
        self.pos
    }

    /// Bytes left after the current position.
    pub fn remaining(&self) -> usize {
        self.data.len() - self.pos
    }

    /// The whole input.
    pub fn data(&self) -> &'a [u8] {
        self.data
    }

    /// Move to byte `pos` (clamped to the end).
    pub fn seek(&mut self, pos: usize) {
        self.pos = pos.min(self.data.len());
        self.mark = self.pos;
    }

    /// The location string of byte `at`.
    pub fn location_at(&self, at: usize) -> String {
        let at = at.min(self.data.len());
        if self.binary {
            format!("{}: byte {}", self.name, at)
        } else {
            let line = 1 + self.data[..at].iter().filter(|&&b| b == b'\n').count();
            format!("{}:{}", self.name, line)
        }
    }

    /// A parse error at the start of the last token or value read.
    pub fn err(&self, msg: impl Into<String>) -> Error {
        Error::parse(self.location_at(self.mark), msg)
    }

    /// A parse error at byte `at`.
    pub fn err_at(&self, at: usize, msg: impl Into<String>) -> Error {
        Error::parse(self.location_at(at), msg)
    }

    /// An "unexpected end of file" error naming what was expected.
    pub fn eof(&self, what: &str) -> Error {
        Error::parse(
            self.location_at(self.data.len()),
            format!("unexpected end of file, expected {what}"),
        )
    }

    // ----- text -----

    /// Skip whitespace (and comments, if enabled).
    #[inline]
    pub fn skip_ws(&mut self) {
        let d = self.data;
        while self.pos < d.len() {
            let b = d[self.pos];
            if b.is_ascii_whitespace() {
                self.pos += 1;
            } else if b == b'#' && self.hash_comments {
                while self.pos < d.len() && d[self.pos] != b'\n' {
                    self.pos += 1;
                }
            } else {
                break;
            }
        }
    }

    /// The next whitespace-separated token, or `None` at the end of the input.
    #[inline]
    pub fn token(&mut self) -> Option<&'a [u8]> {
        self.skip_ws();
        let d = self.data;
        if self.pos >= d.len() {
            self.mark = self.pos;
            return None;
        }
        let start = self.pos;
        while self.pos < d.len() && !d[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        self.mark = start;
        Some(&d[start..self.pos])
    }

    /// The next token without consuming it.
    pub fn peek_token(&mut self) -> Option<&'a [u8]> {
        let (pos, mark) = (self.pos, self.mark);
        let t = self.token();
        self.pos = pos;
        self.mark = mark;
        t
    }

    /// The next token; an error naming `what` at the end of the input.
    #[inline]
    pub fn expect_token(&mut self, what: &str) -> Result<&'a [u8]> {
        self.token().ok_or_else(|| self.eof(what))
    }

    /// Require the next token to be `word`.
    pub fn expect_word(&mut self, word: &str) -> Result<()> {
        let t = self.expect_token(word)?;
        if t != word.as_bytes() {
            return Err(self.err(format!("expected '{word}', found '{}'", show(t))));
        }
        Ok(())
    }

    /// The rest of the current line (without its line break), moving past the break.
    pub fn rest_of_line(&mut self) -> &'a [u8] {
        let d = self.data;
        let start = self.pos;
        while self.pos < d.len() && d[self.pos] != b'\n' {
            self.pos += 1;
        }
        let mut end = self.pos;
        if self.pos < d.len() {
            self.pos += 1;
        }
        if end > start && d[end - 1] == b'\r' {
            end -= 1;
        }
        self.mark = start;
        &d[start..end]
    }

    /// Parse the next token as a float. NaN and infinities are accepted (the surface
    /// checks reject them later); a Fortran `D` exponent is accepted too.
    #[inline]
    pub fn f64(&mut self, what: &str) -> Result<f64> {
        let t = self.expect_token(what)?;
        parse_f64(t).ok_or_else(|| self.err(format!("invalid number '{}' for {what}", show(t))))
    }

    /// Parse the next token as a signed integer.
    #[inline]
    pub fn i64(&mut self, what: &str) -> Result<i64> {
        let t = self.expect_token(what)?;
        parse_i64(t).ok_or_else(|| self.err(format!("invalid integer '{}' for {what}", show(t))))
    }

    /// Parse the next token as an unsigned integer.
    #[inline]
    pub fn u64(&mut self, what: &str) -> Result<u64> {
        let t = self.expect_token(what)?;
        parse_u64(t).ok_or_else(|| {
            self.err(format!(
                "invalid non-negative integer '{}' for {what}",
                show(t)
            ))
        })
    }

    /// Parse the next token as an `i32`.
    pub fn i32(&mut self, what: &str) -> Result<i32> {
        let v = self.i64(what)?;
        i32::try_from(v).map_err(|_| self.err(format!("{what} {v} does not fit in 32 bits")))
    }

    /// Parse the next token as a count, which must be at most `max`.
    pub fn count(&mut self, what: &str, max: u64) -> Result<u64> {
        let v = self.u64(what)?;
        if v > max {
            return Err(self.err(format!("{what} {v} is larger than the file allows")));
        }
        Ok(v)
    }

    // ----- binary -----

    /// The next `n` raw bytes.
    #[inline]
    pub fn bytes(&mut self, n: usize, what: &str) -> Result<&'a [u8]> {
        self.mark = self.pos;
        if self.remaining() < n {
            return Err(self.eof(what));
        }
        let s = &self.data[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }

    /// Fail unless `n` items of `size` bytes remain.
    pub fn need(&self, n: u64, size: usize, what: &str) -> Result<()> {
        match n.checked_mul(size as u64) {
            Some(b) if b <= self.remaining() as u64 => Ok(()),
            _ => Err(self.err_at(
                self.pos,
                format!(
                    "{n} {what} need more bytes than the {} left in the file",
                    self.remaining()
                ),
            )),
        }
    }

    #[inline]
    fn array<const N: usize>(&mut self, what: &str) -> Result<[u8; N]> {
        let s = self.bytes(N, what)?;
        let mut a = [0u8; N];
        a.copy_from_slice(s);
        if self.swap {
            a.reverse();
        }
        Ok(a)
    }

    /// A binary `i32`.
    #[inline]
    pub fn bin_i32(&mut self, what: &str) -> Result<i32> {
        Ok(i32::from_le_bytes(self.array(what)?))
    }

    /// A binary `f64`.
    #[inline]
    pub fn bin_f64(&mut self, what: &str) -> Result<f64> {
        Ok(f64::from_le_bytes(self.array(what)?))
    }

    /// A binary unsigned integer of `size` bytes (4 or 8: Gmsh's `size_t`).
    #[inline]
    pub fn bin_usize(&mut self, size: usize, what: &str) -> Result<u64> {
        if size == 4 {
            Ok(u32::from_le_bytes(self.array(what)?) as u64)
        } else {
            Ok(u64::from_le_bytes(self.array(what)?))
        }
    }
}

/// A token for an error message: lossy UTF-8, cut to a sane length.
pub(crate) fn show(t: &[u8]) -> String {
    let cut = &t[..t.len().min(40)];
    let mut s = String::from_utf8_lossy(cut).into_owned();
    if t.len() > 40 {
        s.push_str("...");
    }
    s
}

/// Parse a float token; `None` if it is not one.
#[inline]
pub(crate) fn parse_f64(t: &[u8]) -> Option<f64> {
    if let Some(v) = std::str::from_utf8(t)
        .ok()
        .and_then(|s| s.parse::<f64>().ok())
    {
        return Some(v);
    }
    // Fortran writes 1.0D+00.
    if t.len() <= 64 && t.iter().any(|&b| b == b'd' || b == b'D') {
        let mut buf = [0u8; 64];
        for (o, &b) in buf.iter_mut().zip(t) {
            *o = if b == b'd' || b == b'D' { b'e' } else { b };
        }
        return std::str::from_utf8(&buf[..t.len()])
            .ok()
            .and_then(|s| s.parse::<f64>().ok());
    }
    None
}

/// Parse an unsigned decimal integer token.
#[inline]
pub(crate) fn parse_u64(t: &[u8]) -> Option<u64> {
    let t = t.strip_prefix(b"+").unwrap_or(t);
    if t.is_empty() || t.len() > 20 {
        return None;
    }
    let mut v: u64 = 0;
    for &b in t {
        if !b.is_ascii_digit() {
            return None;
        }
        v = v.checked_mul(10)?.checked_add((b - b'0') as u64)?;
    }
    Some(v)
}

/// Parse a signed decimal integer token.
#[inline]
pub(crate) fn parse_i64(t: &[u8]) -> Option<i64> {
    if let Some(rest) = t.strip_prefix(b"-") {
        let v = parse_u64(rest)?;
        if v <= i64::MAX as u64 + 1 {
            Some((v as i64).wrapping_neg())
        } else {
            None
        }
    } else {
        i64::try_from(parse_u64(t)?).ok()
    }
}

/// At most `count` items, but no more than `remaining / min_bytes` (an item takes at
/// least `min_bytes` of input): the capacity to reserve for a count read from a header.
#[inline]
pub(crate) fn capped(count: u64, remaining: usize, min_bytes: usize) -> usize {
    let by_size = remaining / min_bytes.max(1);
    count.min(by_size as u64) as usize
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers() {
        assert_eq!(parse_u64(b"123"), Some(123));
        assert_eq!(parse_u64(b"+7"), Some(7));
        assert_eq!(parse_u64(b"-7"), None);
        assert_eq!(parse_u64(b"99999999999999999999999"), None);
        assert_eq!(parse_i64(b"-9223372036854775808"), Some(i64::MIN));
        assert_eq!(parse_i64(b"-9223372036854775809"), None);
        assert_eq!(parse_f64(b"1.5e3"), Some(1500.0));
        assert_eq!(parse_f64(b"1.5D+03"), Some(1500.0));
        assert!(parse_f64(b"nan").unwrap().is_nan());
        assert_eq!(parse_f64(b"1.2.3"), None);
        assert_eq!(parse_f64(b""), None);
    }

    #[test]
    fn locations() {
        let mut c = Cursor::new(b"a b\nc\n\nd x", "f");
        for _ in 0..4 {
            c.token();
        }
        assert_eq!(c.err("m").to_string(), "f:4: m");
        c.set_binary(true);
        assert_eq!(c.err("m").to_string(), "f: byte 7: m");
        assert!(c.f64("z").is_err());
        assert!(c.f64("z").unwrap_err().to_string().contains("end of file"));
    }
}
