//! Line-oriented tokenizing for OFF and OBJ: one logical record per line, `#` comments,
//! blank lines skipped, error locations `file:LINE`.

use super::cursor::Cursor;
use crate::error::Error;

/// Walks the non-blank, comment-stripped lines of a text file.
pub(crate) struct Lines<'a> {
    c: Cursor<'a>,
    /// Byte offset where the current line starts.
    start: usize,
}

impl<'a> Lines<'a> {
    /// Lines of `data`; `name` is used in error locations.
    pub fn new(data: &'a [u8], name: &'a str) -> Self {
        Lines {
            c: Cursor::new(data, name),
            start: 0,
        }
    }

    /// The next line that holds a token, split into whitespace-separated tokens (into
    /// `out`, cleared first); `false` at the end of the file.
    pub fn next_tokens(&mut self, out: &mut Vec<&'a [u8]>) -> bool {
        out.clear();
        while self.c.remaining() > 0 {
            self.start = self.c.pos();
            let mut line = self.c.rest_of_line();
            if let Some(h) = line.iter().position(|&b| b == b'#') {
                line = &line[..h];
            }
            out.extend(
                line.split(|b| b.is_ascii_whitespace())
                    .filter(|t| !t.is_empty()),
            );
            if !out.is_empty() {
                return true;
            }
        }
        false
    }

    /// Bytes after the current position (an upper bound on what is left to read).
    pub fn remaining(&self) -> usize {
        self.c.remaining()
    }

    /// A parse error on the current line.
    pub fn err(&self, msg: impl Into<String>) -> Error {
        self.c.err_at(self.start, msg)
    }

    /// The location (`file:LINE`) of the current line.
    pub fn location(&self) -> String {
        self.c.location_at(self.start)
    }

    /// An end-of-file error naming what was expected.
    pub fn eof(&self, what: &str) -> Error {
        self.c.eof(what)
    }
}
