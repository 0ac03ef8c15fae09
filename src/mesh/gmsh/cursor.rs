//! Byte cursor shared by the ASCII and binary parsers.

use std::str::FromStr;

use super::{GmshError, GmshErrorKind, Location};

/// Reads tokens (ASCII) or little-endian values (binary) and knows where it
/// is, so every error can say so.
pub(super) struct Cursor<'a> {
    pub(super) data: &'a [u8],
    pub(super) path: &'a str,
    pub(super) pos: usize,
    /// 1-based line of `pos`; only meaningful in ASCII files.
    pub(super) line: usize,
    /// Set by `$MeshFormat`: section bodies are binary, locations are bytes.
    pub(super) binary: bool,
    /// The section being read, for end-of-file messages.
    pub(super) section: &'static str,
}

impl<'a> Cursor<'a> {
    pub(super) fn new(data: &'a [u8], path: &'a str) -> Self {
        Cursor {
            data,
            path,
            pos: 0,
            line: 1,
            binary: false,
            section: "MeshFormat",
        }
    }

    pub(super) fn here(&self) -> Location {
        if self.binary {
            Location::Byte(self.pos)
        } else {
            Location::Line(self.line)
        }
    }

    pub(super) fn error(&self, location: Location, kind: GmshErrorKind) -> GmshError {
        GmshError {
            path: self.path.to_string(),
            location,
            kind,
        }
    }

    pub(super) fn eof(&self, what: &'static str) -> GmshError {
        self.error(
            self.here(),
            GmshErrorKind::UnexpectedEof {
                section: self.section,
                what,
            },
        )
    }

    pub(super) fn at_end(&self) -> bool {
        self.pos >= self.data.len()
    }

    pub(super) fn skip_ws(&mut self) {
        while let Some(&b) = self.data.get(self.pos) {
            if !b.is_ascii_whitespace() {
                break;
            }
            if b == b'\n' {
                self.line += 1;
            }
            self.pos += 1;
        }
    }

    /// Location of the next value: in ASCII the next token's line.
    pub(super) fn start(&mut self) -> Location {
        if !self.binary {
            self.skip_ws();
        }
        self.here()
    }

    /// The next whitespace-delimited token and where it starts.
    pub(super) fn token(&mut self, what: &'static str) -> Result<(&'a [u8], Location), GmshError> {
        self.skip_ws();
        let at = self.here();
        let start = self.pos;
        while self
            .data
            .get(self.pos)
            .is_some_and(|b| !b.is_ascii_whitespace())
        {
            self.pos += 1;
        }
        match self.data.get(start..self.pos) {
            Some(t) if !t.is_empty() => Ok((t, at)),
            _ => Err(self.eof(what)),
        }
    }

    /// The rest of the current line without its newline, which is consumed.
    pub(super) fn rest_of_line(&mut self) -> &'a [u8] {
        let start = self.pos;
        while self.data.get(self.pos).is_some_and(|&b| b != b'\n') {
            self.pos += 1;
        }
        let line = self.data.get(start..self.pos).unwrap_or_default();
        if !self.at_end() {
            self.pos += 1;
            self.line += 1;
        }
        line
    }

    pub(super) fn ascii<T: FromStr>(&mut self, what: &'static str) -> Result<T, GmshError> {
        let (token, at) = self.token(what)?;
        std::str::from_utf8(token)
            .ok()
            .and_then(|s| s.parse().ok())
            .ok_or_else(|| self.error(at, bad_number(what, token)))
    }

    pub(super) fn bytes<const N: usize>(
        &mut self,
        what: &'static str,
    ) -> Result<[u8; N], GmshError> {
        let end = self.pos.checked_add(N).ok_or_else(|| self.eof(what))?;
        let b: [u8; N] = self
            .data
            .get(self.pos..end)
            .and_then(|s| s.try_into().ok())
            .ok_or_else(|| self.eof(what))?;
        self.pos = end;
        Ok(b)
    }

    /// A `size_t`: 8 bytes in binary sections.
    pub(super) fn size(&mut self, what: &'static str) -> Result<u64, GmshError> {
        if self.binary {
            Ok(u64::from_le_bytes(self.bytes(what)?))
        } else {
            self.ascii(what)
        }
    }

    /// An `int`: 4 bytes in binary sections.
    pub(super) fn int(&mut self, what: &'static str) -> Result<i32, GmshError> {
        if self.binary {
            Ok(i32::from_le_bytes(self.bytes(what)?))
        } else {
            self.ascii(what)
        }
    }

    /// A finite `double`.
    pub(super) fn double(&mut self, what: &'static str) -> Result<f64, GmshError> {
        let at = self.start();
        let x: f64 = if self.binary {
            f64::from_le_bytes(self.bytes(what)?)
        } else {
            self.ascii(what)?
        };
        if x.is_finite() {
            Ok(x)
        } else {
            Err(self.error(at, bad_number(what, x.to_string().as_bytes())))
        }
    }

    /// The `$EndName` line closing the current section.
    pub(super) fn expect_end(&mut self) -> Result<(), GmshError> {
        let expected = format!("$End{}", self.section);
        let (token, at) = self.token("the section end marker")?;
        if token == expected.as_bytes() {
            Ok(())
        } else {
            let found = shorten(token);
            Err(self.error(at, GmshErrorKind::Expected { expected, found }))
        }
    }

    /// Skips an unknown section by searching for its end marker.
    pub(super) fn skip_section(&mut self, name: &str) -> Result<(), GmshError> {
        let marker = format!("$End{name}");
        let rest = self.data.get(self.pos..).unwrap_or_default();
        let found = rest
            .windows(marker.len())
            .position(|w| w == marker.as_bytes())
            .ok_or_else(|| self.eof("an unknown section"))?;
        let skipped = rest.get(..found + marker.len()).unwrap_or_default();
        self.line += skipped.iter().filter(|&&b| b == b'\n').count();
        self.pos += skipped.len();
        Ok(())
    }
}

pub(super) fn bad_number(what: &'static str, token: &[u8]) -> GmshErrorKind {
    GmshErrorKind::BadNumber {
        what,
        token: shorten(token),
    }
}

/// A token for a message: lossy UTF-8, at most 40 characters.
pub(super) fn shorten(token: &[u8]) -> String {
    String::from_utf8_lossy(token).chars().take(40).collect()
}

/// A count from the file as a capacity hint, capped so that a corrupt count
/// cannot exhaust memory; the read loops themselves stop at end of file.
pub(super) fn capacity(count: u64) -> usize {
    usize::try_from(count).unwrap_or(usize::MAX).min(1 << 16)
}
