//! A bounds-checked reader over the bytes of a mesh file: whitespace
//! separated text tokens and little/big-endian binary numbers, with errors
//! that name the line (text) or byte offset (binary) of the problem.

use std::str::FromStr;

use crate::{Location, MeshError};

/// Cursor over a whole file held in memory.
pub(crate) struct Cursor<'a> {
    data: &'a [u8],
    pos: usize,
    /// Report positions as byte offsets (binary data) instead of lines.
    pub binary: bool,
    /// Binary numbers are big-endian (byte-swapped relative to us).
    pub big_endian: bool,
}

impl<'a> Cursor<'a> {
    /// A text cursor at the start of `data`.
    pub fn new(data: &'a [u8]) -> Self {
        Cursor { data, pos: 0, binary: false, big_endian: false }
    }

    /// Bytes not read yet.
    pub fn remaining(&self) -> usize {
        self.data.len() - self.pos
    }

    /// The current location, for error messages.
    pub fn location_at(&self, pos: usize) -> Location {
        if self.binary {
            Location::Byte(pos)
        } else {
            Location::Line(1 + self.data[..pos.min(self.data.len())].iter().filter(|&&b| b == b'\n').count())
        }
    }

    /// A syntax error at the current position.
    pub fn error(&self, message: impl Into<String>) -> MeshError {
        MeshError::Syntax { at: self.location_at(self.pos), message: message.into() }
    }

    fn error_at(&self, pos: usize, message: impl Into<String>) -> MeshError {
        MeshError::Syntax { at: self.location_at(pos), message: message.into() }
    }

    fn skip_whitespace(&mut self) {
        while self.pos < self.data.len() && self.data[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
    }

    /// Skips whitespace and whole lines that start with `comment`.
    pub fn skip_space_and_comments(&mut self, comment: u8) {
        loop {
            self.skip_whitespace();
            if self.pos < self.data.len() && self.data[self.pos] == comment {
                self.skip_line();
            } else {
                return;
            }
        }
    }

    /// The next whitespace-separated token, or `None` at end of file.
    pub fn token(&mut self) -> Option<&'a [u8]> {
        self.skip_whitespace();
        let start = self.pos;
        while self.pos < self.data.len() && !self.data[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        (self.pos > start).then(|| &self.data[start..self.pos])
    }

    /// The next token as text; an error naming `what` at end of file.
    pub fn expect_token(&mut self, what: &str) -> Result<&'a str, MeshError> {
        let token =
            self.token().ok_or_else(|| self.error(format!("unexpected end of file, expected {what}")))?;
        std::str::from_utf8(token).map_err(|_| {
            self.error_at(self.pos - token.len(), format!("expected {what}, found non-text bytes"))
        })
    }

    /// The next token parsed as `T`.
    pub fn parse<T: FromStr>(&mut self, what: &str) -> Result<T, MeshError> {
        let token = self.expect_token(what)?;
        token.parse().map_err(|_| {
            let shown: String = token.chars().take(40).collect();
            self.error_at(self.pos - token.len(), format!("expected {what}, found `{shown}`"))
        })
    }

    /// Skips the rest of the current line including its `\n`.
    pub fn skip_line(&mut self) {
        while self.pos < self.data.len() && self.data[self.pos] != b'\n' {
            self.pos += 1;
        }
        self.pos = (self.pos + 1).min(self.data.len());
    }

    /// Skips spaces and `\r` up to and including the next `\n` (the line end
    /// after a text header, before binary data starts).
    pub fn skip_line_end(&mut self) -> Result<(), MeshError> {
        while self.pos < self.data.len() && matches!(self.data[self.pos], b' ' | b'\t' | b'\r') {
            self.pos += 1;
        }
        match self.data.get(self.pos) {
            Some(b'\n') => {
                self.pos += 1;
                Ok(())
            }
            _ => Err(self.error("expected the end of a header line before binary data")),
        }
    }

    /// The text between the next pair of double quotes.
    pub fn quoted(&mut self, what: &str) -> Result<String, MeshError> {
        self.skip_whitespace();
        if self.data.get(self.pos) != Some(&b'"') {
            return self.expect_token(what).map(str::to_owned);
        }
        let start = self.pos + 1;
        let len = self.data[start..]
            .iter()
            .position(|&b| b == b'"' || b == b'\n')
            .filter(|&n| self.data[start + n] == b'"')
            .ok_or_else(|| self.error(format!("unterminated quoted {what}")))?;
        self.pos = start + len + 1;
        Ok(String::from_utf8_lossy(&self.data[start..start + len]).into_owned())
    }

    /// Moves just past the next occurrence of `needle`; false if absent
    /// (the cursor then sits at the end of the file).
    pub fn skip_past(&mut self, needle: &[u8]) -> bool {
        match self.data[self.pos..].windows(needle.len()).position(|w| w == needle) {
            Some(i) => {
                self.pos += i + needle.len();
                true
            }
            None => {
                self.pos = self.data.len();
                false
            }
        }
    }

    /// The next `n` raw bytes.
    pub fn bytes(&mut self, n: usize, what: &str) -> Result<&'a [u8], MeshError> {
        if n > self.remaining() {
            return Err(self.error(format!("file ends inside binary {what}")));
        }
        self.pos += n;
        Ok(&self.data[self.pos - n..self.pos])
    }

    fn array<const N: usize>(&mut self, what: &str) -> Result<[u8; N], MeshError> {
        let mut a = [0u8; N];
        a.copy_from_slice(self.bytes(N, what)?);
        if self.big_endian {
            a.reverse();
        }
        Ok(a)
    }

    /// A binary 32-bit signed integer.
    pub fn bin_i32(&mut self, what: &str) -> Result<i32, MeshError> {
        self.array::<4>(what).map(i32::from_le_bytes)
    }

    /// A binary unsigned integer of `size` bytes (4 or 8).
    pub fn bin_unsigned(&mut self, size: usize, what: &str) -> Result<u64, MeshError> {
        if size == 4 {
            self.array::<4>(what).map(|a| u64::from(u32::from_le_bytes(a)))
        } else {
            self.array::<8>(what).map(u64::from_le_bytes)
        }
    }

    /// A binary IEEE double.
    pub fn bin_f64(&mut self, what: &str) -> Result<f64, MeshError> {
        self.array::<8>(what).map(f64::from_le_bytes)
    }

    /// Checks that `count` items of at least `min_bytes` each can fit in the
    /// rest of the file, so no allocation is ever sized from a lying count.
    pub fn check_count(&self, count: u64, min_bytes: usize, what: &str) -> Result<usize, MeshError> {
        let fits = (self.remaining() / min_bytes.max(1)) as u64;
        if count > fits {
            return Err(self.error(format!(
                "{what} count {count} does not fit in the rest of the file (truncated or corrupt?)"
            )));
        }
        Ok(count as usize)
    }
}

impl Cursor<'_> {
    /// Moves back to the position where `remaining()` was `remaining`.
    pub fn unread(&mut self, remaining: usize) {
        self.pos = self.data.len() - remaining;
    }
}
