//! Byte-level scanning shared by the Gmsh readers: whitespace-separated tokens with line
//! numbers, and fixed-size binary values for MSH 4.1 binary.
//!
//! Nothing here indexes untrusted data without a bounds check; every read past the end of
//! the data becomes [`ReadError::Truncated`].

use std::borrow::Cow;
use std::path::Path;

use super::{shorten, Location, ReadError};

/// One whitespace-separated token.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Token<'a> {
    /// The raw bytes (not necessarily UTF-8).
    pub raw: &'a [u8],
    /// 1-based line number of the token.
    pub line: usize,
    /// Byte offset of the token's first byte.
    pub offset: usize,
}

impl<'a> Token<'a> {
    /// The token as text, with invalid UTF-8 replaced, for messages.
    pub fn text(&self) -> Cow<'a, str> {
        String::from_utf8_lossy(self.raw)
    }

    /// True when the token is exactly `s`.
    pub fn is(&self, s: &str) -> bool {
        self.raw == s.as_bytes()
    }
}

/// A cursor over the bytes of one file.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Scanner<'a> {
    data: &'a [u8],
    pos: usize,
    line: usize,
    path: &'a Path,
    /// Report byte offsets instead of line numbers (binary files).
    pub binary: bool,
    /// The section being read, for messages (e.g. `$Nodes`).
    pub section: &'static str,
}

fn is_space(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\r' | b'\n' | 0x0b | 0x0c)
}

impl<'a> Scanner<'a> {
    /// A scanner at the start of `data`; `path` is only used in errors.
    pub fn new(data: &'a [u8], path: &'a Path) -> Self {
        Scanner { data, pos: 0, line: 1, path, binary: false, section: "header" }
    }

    /// The file path (for errors).
    pub fn path(&self) -> &'a Path {
        self.path
    }

    /// Bytes left after the cursor.
    pub fn remaining(&self) -> usize {
        self.data.len().saturating_sub(self.pos)
    }

    /// Where a token is, as a line (text) or a byte offset (binary file).
    pub fn location_of(&self, t: &Token<'_>) -> Location {
        if self.binary {
            Location::Byte(t.offset)
        } else {
            Location::Line(t.line)
        }
    }

    /// Where the next token or binary value starts. In text mode this skips whitespace.
    pub fn here(&mut self) -> Location {
        if self.binary {
            Location::Byte(self.pos)
        } else {
            self.skip_space();
            Location::Line(self.line)
        }
    }

    fn skip_space(&mut self) {
        while let Some(&b) = self.data.get(self.pos) {
            if !is_space(b) {
                break;
            }
            if b == b'\n' {
                self.line += 1;
            }
            self.pos += 1;
        }
    }

    /// The next token, or `None` at the end of the data.
    pub fn next_raw(&mut self) -> Option<Token<'a>> {
        self.skip_space();
        let start = self.pos;
        while self.data.get(self.pos).is_some_and(|&b| !is_space(b)) {
            self.pos += 1;
        }
        let raw = self.data.get(start..self.pos)?;
        if raw.is_empty() {
            return None;
        }
        Some(Token { raw, line: self.line, offset: start })
    }

    /// A "truncated section" error at the cursor.
    pub fn truncated(&mut self, expected: &str, found: String) -> ReadError {
        ReadError::Truncated {
            path: self.path.to_path_buf(),
            at: self.here(),
            section: self.section,
            expected: expected.to_string(),
            found,
        }
    }

    /// A "garbage token" error for `t`.
    pub fn garbage(&self, t: &Token<'_>, expected: &str) -> ReadError {
        ReadError::Garbage {
            path: self.path.to_path_buf(),
            at: self.location_of(t),
            section: self.section,
            token: shorten(&t.text()),
            expected: expected.to_string(),
        }
    }

    /// A data token: fails with `Truncated` at the end of the data or at a `$` section marker
    /// (which means the section ended early).
    pub fn token(&mut self, expected: &str) -> Result<Token<'a>, ReadError> {
        let before = *self;
        match self.next_raw() {
            None => Err(self.truncated(expected, "end of file".into())),
            Some(t) if t.raw.first() == Some(&b'$') => {
                *self = before;
                let found = format!("`{}`", shorten(&t.text()));
                Err(self.truncated(expected, found))
            }
            Some(t) => Ok(t),
        }
    }

    fn parse_token<T: std::str::FromStr>(&mut self, expected: &str) -> Result<T, ReadError> {
        let t = self.token(expected)?;
        std::str::from_utf8(t.raw).ok().and_then(|s| s.parse::<T>().ok()).ok_or_else(|| self.garbage(&t, expected))
    }

    /// A non-negative integer token.
    pub fn u64(&mut self, expected: &str) -> Result<u64, ReadError> {
        self.parse_token(expected)
    }

    /// A signed integer token.
    pub fn i64(&mut self, expected: &str) -> Result<i64, ReadError> {
        self.parse_token(expected)
    }

    /// A floating-point token (NaN and infinities parse; the mesh builder rejects them).
    pub fn f64(&mut self, expected: &str) -> Result<f64, ReadError> {
        self.parse_token(expected)
    }

    /// The next token must be exactly `marker` (e.g. `$EndNodes`).
    pub fn expect_marker(&mut self, marker: &str) -> Result<(), ReadError> {
        let expected = format!("`{marker}`");
        match self.next_raw() {
            None => Err(self.truncated(&expected, "end of file".into())),
            Some(t) if t.is(marker) => Ok(()),
            Some(t) => Err(self.garbage(&t, &expected)),
        }
    }

    /// Skips everything up to and including the marker `end` (e.g. `$EndEntities`). In binary
    /// mode the marker is searched for as bytes at the start of a line.
    pub fn skip_section(&mut self, end: &str) -> Result<(), ReadError> {
        let expected = format!("`{end}`");
        if self.binary {
            let needle = format!("\n{end}");
            let rest = self.data.get(self.pos..).unwrap_or(&[]);
            match find(rest, needle.as_bytes()) {
                Some(i) => {
                    self.pos += i + needle.len();
                    Ok(())
                }
                None => {
                    self.pos = self.data.len();
                    Err(self.truncated(&expected, "end of file".into()))
                }
            }
        } else {
            loop {
                match self.next_raw() {
                    None => return Err(self.truncated(&expected, "end of file".into())),
                    Some(t) if t.is(end) => return Ok(()),
                    Some(_) => {}
                }
            }
        }
    }

    /// After a section marker in a binary file: skips the rest of the marker's line, which
    /// must be blank, so that binary data starts right after its `\n`.
    pub fn end_of_line(&mut self) -> Result<(), ReadError> {
        while let Some(&b) = self.data.get(self.pos) {
            match b {
                b' ' | b'\t' | b'\r' => self.pos += 1,
                b'\n' => {
                    self.pos += 1;
                    self.line += 1;
                    return Ok(());
                }
                _ => {
                    let t = Token {
                        raw: self.data.get(self.pos..self.pos + 1).unwrap_or(&[]),
                        line: self.line,
                        offset: self.pos,
                    };
                    return Err(self.garbage(&t, "end of line"));
                }
            }
        }
        Err(self.truncated("end of line", "end of file".into()))
    }

    /// The next `n` raw bytes (binary data).
    pub fn take(&mut self, n: usize, expected: &str) -> Result<&'a [u8], ReadError> {
        match self.data.get(self.pos..).and_then(|rest| rest.get(..n)) {
            Some(bytes) => {
                self.pos += n;
                Ok(bytes)
            }
            None => {
                let found = format!("end of file ({} bytes left)", self.remaining());
                Err(self.truncated(expected, found))
            }
        }
    }
}

/// Position of the first occurrence of `needle` in `hay`.
fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    if needle.is_empty() {
        return Some(0);
    }
    hay.windows(needle.len()).position(|w| w == needle)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tokens_have_lines() {
        let p = Path::new("x");
        let mut s = Scanner::new(b"a b\n\n  c\n", p);
        assert_eq!(s.next_raw().unwrap().line, 1);
        assert_eq!(s.next_raw().unwrap().line, 1);
        let c = s.next_raw().unwrap();
        assert_eq!((c.line, c.offset, c.raw), (3, 7, &b"c"[..]));
        assert!(s.next_raw().is_none());
    }

    #[test]
    fn marker_ends_data() {
        let p = Path::new("x");
        let mut s = Scanner::new(b"1 $EndNodes", p);
        assert_eq!(s.u64("n").unwrap(), 1);
        let e = s.u64("node tag").unwrap_err().to_string();
        assert!(e.contains("truncated") && e.contains("$EndNodes"), "{e}");
        s.expect_marker("$EndNodes").unwrap();
    }

    #[test]
    fn take_is_bounded() {
        let p = Path::new("x");
        let mut s = Scanner::new(b"abc", p);
        assert!(s.take(usize::MAX, "x").is_err());
        assert_eq!(s.take(2, "x").unwrap(), b"ab");
        assert!(s.take(2, "x").is_err());
    }
}
