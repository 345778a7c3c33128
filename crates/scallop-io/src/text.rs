//! Byte-level helpers for the text formats: lines, tokens and numbers with
//! their places, without allocating per line.

use crate::{MeshFormat, MeshReadError, Place};

/// ASCII whitespace as the text formats use it (space, tab, CR, LF, VT, FF).
pub(crate) fn is_space(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\r' | b'\n' | 0x0b | 0x0c)
}

/// A whitespace-separated token and where it starts.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Token<'a> {
    pub text: &'a [u8],
    /// Byte offset of the token's first byte in the file.
    pub offset: usize,
    /// Line of the token (from 1).
    pub line: usize,
}

impl<'a> Token<'a> {
    /// The token as text, or [`MeshReadError::NotText`] pointing at its first bad byte.
    pub fn as_str(&self, format: MeshFormat) -> Result<&'a str, MeshReadError> {
        std::str::from_utf8(self.text).map_err(|e| {
            let bad = e.valid_up_to();
            MeshReadError::NotText {
                format,
                place: Place::LineByte { line: self.line, byte: (self.offset + bad) as u64 },
                byte: self.text[bad],
            }
        })
    }

    /// Whether the token is `word`, ignoring ASCII case.
    pub fn is(&self, word: &str) -> bool {
        self.text.eq_ignore_ascii_case(word.as_bytes())
    }

    /// The token as a float (`nan` and `inf` parse; callers check finiteness).
    /// `Ok(None)` when it is text but not a number.
    pub fn as_f64(&self, format: MeshFormat) -> Result<Option<f64>, MeshReadError> {
        Ok(self.as_str(format)?.parse::<f64>().ok())
    }

    /// The token as an integer; `Ok(None)` when it is text but not an integer.
    pub fn as_i64(&self, format: MeshFormat) -> Result<Option<i64>, MeshReadError> {
        Ok(self.as_str(format)?.parse::<i64>().ok())
    }

    pub fn place(&self) -> Place {
        Place::Line { line: self.line }
    }

    /// The token for an error message: quoted, lossy, shortened.
    pub fn shown(&self) -> String {
        shown(self.text)
    }
}

/// Bytes for an error message: quoted, lossy UTF-8, at most 40 characters.
pub(crate) fn shown(bytes: &[u8]) -> String {
    let text = String::from_utf8_lossy(bytes);
    let mut out: String = text.chars().take(40).collect();
    if text.chars().nth(40).is_some() {
        out.push_str("...");
    }
    format!("'{out}'")
}

/// A stream of tokens across lines, tracking line numbers.
pub(crate) struct Lexer<'a> {
    bytes: &'a [u8],
    pos: usize,
    line: usize,
}

impl<'a> Lexer<'a> {
    pub fn new(bytes: &'a [u8]) -> Self {
        Lexer { bytes, pos: 0, line: 1 }
    }

    /// The next token, or `None` at the end of the input.
    pub fn next_token(&mut self) -> Option<Token<'a>> {
        while let Some(&b) = self.bytes.get(self.pos) {
            if !is_space(b) {
                break;
            }
            if b == b'\n' {
                self.line += 1;
            }
            self.pos += 1;
        }
        if self.pos >= self.bytes.len() {
            return None;
        }
        let start = self.pos;
        self.pos = token_end(self.bytes, start);
        Some(Token { text: &self.bytes[start..self.pos], offset: start, line: self.line })
    }

    /// Skips the rest of the current line (its content is not examined).
    pub fn skip_line(&mut self) {
        match self.bytes[self.pos..].iter().position(|&b| b == b'\n') {
            Some(n) => {
                self.pos += n + 1;
                self.line += 1;
            }
            None => self.pos = self.bytes.len(),
        }
    }

    /// The current line (the line of the last token, or the last line at the end).
    pub fn line(&self) -> usize {
        self.line
    }
}

/// One line of a text file, without its `\n` or trailing `\r`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Line<'a> {
    pub text: &'a [u8],
    /// Byte offset of the line's first byte in the file.
    pub offset: usize,
    /// Line number (from 1).
    pub number: usize,
}

impl<'a> Line<'a> {
    /// The whitespace-separated tokens of the line.
    pub fn tokens(&self) -> Tokens<'a> {
        Tokens { text: self.text, pos: 0, base: self.offset, line: self.number }
    }
}

/// Iterator over the lines of a byte slice.
pub(crate) struct Lines<'a> {
    bytes: &'a [u8],
    pos: usize,
    number: usize,
}

impl<'a> Lines<'a> {
    /// Lines of `bytes[start..]`, the first numbered `first_number`.
    pub fn new(bytes: &'a [u8], start: usize, first_number: usize) -> Self {
        Lines { bytes, pos: start.min(bytes.len()), number: first_number }
    }

    /// Offset of the first byte not yet returned (the start of the next line).
    pub fn offset(&self) -> usize {
        self.pos
    }

    /// Bytes not yet returned.
    pub fn remaining(&self) -> usize {
        self.bytes.len() - self.pos
    }

    /// Number of the last line returned (0 before the first when starting at line 1).
    pub fn last_number(&self) -> usize {
        self.number.saturating_sub(1)
    }
}

impl<'a> Iterator for Lines<'a> {
    type Item = Line<'a>;

    fn next(&mut self) -> Option<Line<'a>> {
        if self.pos >= self.bytes.len() {
            return None;
        }
        let start = self.pos;
        let rest = &self.bytes[start..];
        let (mut text, advance) = match rest.iter().position(|&b| b == b'\n') {
            Some(n) => (&rest[..n], n + 1),
            None => (rest, rest.len()),
        };
        if let [head @ .., b'\r'] = text {
            text = head;
        }
        self.pos += advance;
        let number = self.number;
        self.number += 1;
        Some(Line { text, offset: start, number })
    }
}

/// Iterator over the tokens of one line.
pub(crate) struct Tokens<'a> {
    text: &'a [u8],
    pos: usize,
    base: usize,
    line: usize,
}

impl<'a> Iterator for Tokens<'a> {
    type Item = Token<'a>;

    fn next(&mut self) -> Option<Token<'a>> {
        while self.pos < self.text.len() && is_space(self.text[self.pos]) {
            self.pos += 1;
        }
        if self.pos >= self.text.len() {
            return None;
        }
        let start = self.pos;
        self.pos = token_end(self.text, start);
        Some(Token { text: &self.text[start..self.pos], offset: self.base + start, line: self.line })
    }
}

/// The end of the token that starts at `start`: the first white space after it,
/// or the end of `bytes`.
#[inline]
fn token_end(bytes: &[u8], start: usize) -> usize {
    bytes[start..].iter().position(|&b| is_space(b)).map_or(bytes.len(), |n| start + n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_strip_cr_and_count() {
        let text = b"a b\r\n\nc";
        let lines: Vec<_> = Lines::new(text, 0, 1).map(|l| (l.number, l.offset, l.text)).collect();
        assert_eq!(lines, vec![(1, 0, &b"a b"[..]), (2, 5, &b""[..]), (3, 6, &b"c"[..])]);
    }

    #[test]
    fn lexer_tracks_lines_and_offsets() {
        let mut lx = Lexer::new(b"solid x\n  facet\r\n\n 1.5");
        let t = lx.next_token().map(|t| (t.text, t.offset, t.line));
        assert_eq!(t, Some((&b"solid"[..], 0, 1)));
        lx.skip_line();
        let t = lx.next_token().map(|t| (t.text, t.offset, t.line));
        assert_eq!(t, Some((&b"facet"[..], 10, 2)));
        let t = lx.next_token().map(|t| (t.text, t.offset, t.line));
        assert_eq!(t, Some((&b"1.5"[..], 19, 4)));
        assert!(lx.next_token().is_none());
    }

    #[test]
    fn bad_utf8_points_at_the_byte() {
        let line = Line { text: b"v 1 2\xff3 4", offset: 100, number: 7 };
        let tok = line.tokens().nth(2).map(|t| t.as_str(MeshFormat::Obj));
        let Some(Err(MeshReadError::NotText { place, byte, .. })) = tok else { panic!("expected NotText") };
        assert_eq!(place, Place::LineByte { line: 7, byte: 105 });
        assert_eq!(byte, 0xff);
    }
}
