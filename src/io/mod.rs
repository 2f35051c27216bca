//! Files: MercuryCG `.data`/`.fstat` saves, the official initial-configuration format,
//! checkpoints, the state hash, the diagnostics table, ParaView's VTK files, atomic writes, the
//! output folder's lock.

pub mod atomic;
pub mod checkpoint;
pub mod csv_table;
pub mod diagnostics;
pub mod hash;
pub mod lock;
pub mod mercury;
pub mod official;
pub mod vtk;

use std::fs::File;
use std::io::{BufRead, BufReader};
use std::path::Path;

/// A malformed input file: `file:line: message` (`file: message` when no line applies, as
/// for a file that cannot be opened).
#[derive(Debug, thiserror::Error)]
pub struct FormatError {
    pub file: String,
    /// Line (from 1), or 0 when the error is not on one line.
    pub line: usize,
    pub msg: String,
}

impl std::fmt::Display for FormatError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.line {
            0 => write!(f, "{}: {}", self.file, self.msg),
            line => write!(f, "{}:{line}: {}", self.file, self.msg),
        }
    }
}

/// `text` escaped for an XML attribute value or element text (`&`, `<`, `>`, `"` and `'`).
pub fn xml_escaped(text: &str) -> String {
    let mut s = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => s.push_str("&amp;"),
            '<' => s.push_str("&lt;"),
            '>' => s.push_str("&gt;"),
            '"' => s.push_str("&quot;"),
            '\'' => s.push_str("&apos;"),
            c => s.push(c),
        }
    }
    s
}

/// `text` as a TOML basic string, quotes included, escaped as TOML requires.
pub fn toml_string(text: &str) -> String {
    toml::Value::String(text.into()).to_string()
}

/// Formats an f64 so that it reads back to the same bits: plain decimal for moderate
/// magnitudes, shortest exponent form otherwise.
pub fn fmt_f64(out: &mut String, v: f64) {
    use std::fmt::Write;
    let a = v.abs();
    if a == 0.0 || (1e-5..1e16).contains(&a) {
        let _ = write!(out, "{v}");
    } else {
        let _ = write!(out, "{v:e}");
    }
}

/// The longest line (bytes) a text reader takes: a longer one, or a stream with no line end
/// (a binary file, `/dev/zero`), is an error before it is held in memory.
pub const MAX_LINE: usize = 1 << 20;

/// The largest file (bytes) read whole ([`read_text`], [`read_bounded`]).
pub const MAX_FILE: u64 = 1 << 30;

/// Reads a file whole, at most `most` bytes: a larger file, or an endless stream (a device, a
/// pipe), is an error naming it before more than `most` bytes are held.
pub fn read_bounded(path: &Path, most: u64) -> Result<Vec<u8>, FormatError> {
    use std::io::Read;
    let file = path.display().to_string();
    let cannot = |e: std::io::Error| FormatError {
        file: file.clone(),
        line: 0,
        msg: format!("cannot read: {e}"),
    };
    let f = File::open(path).map_err(cannot)?;
    let mut bytes = Vec::new();
    f.take(most + 1).read_to_end(&mut bytes).map_err(cannot)?;
    if bytes.len() as u64 > most {
        return Err(FormatError {
            file,
            line: 0,
            msg: format!("larger than the {most} bytes a file of this kind may have"),
        });
    }
    Ok(bytes)
}

/// Reads a text file whole (at most [`MAX_FILE`] bytes); returns its name (for messages) and
/// its text. Bytes that are not UTF-8 are an error naming their line.
pub fn read_text(path: &Path) -> Result<(String, String), FormatError> {
    let file = path.display().to_string();
    let bytes = read_bounded(path, MAX_FILE)?;
    let text = utf8(&file, bytes)?;
    Ok((file, text))
}

/// The text of the bytes of `file`, or an error naming the first line that is not UTF-8.
pub fn utf8(file: &str, bytes: Vec<u8>) -> Result<String, FormatError> {
    String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let bytes = e.as_bytes();
        let line_start = bytes[..at]
            .iter()
            .rposition(|&b| b == b'\n')
            .map_or(0, |k| k + 1);
        FormatError {
            file: file.into(),
            line: 1 + bytes[..at].iter().filter(|&&b| b == b'\n').count(),
            msg: not_utf8(at - line_start, bytes[at]),
        }
    })
}

/// The message for byte `byte`, at offset `at` (from 0) of its line, that is not UTF-8.
fn not_utf8(at: usize, byte: u8) -> String {
    format!(
        "not UTF-8 text: byte 0x{byte:02x} at byte {} of the line (a binary or differently \
         encoded file?)",
        at + 1
    )
}

/// Opens a text file to be read line by line with [`Lines`].
pub fn open(path: &Path) -> Result<Lines<BufReader<File>>, FormatError> {
    let file = path.display().to_string();
    let f = File::open(path).map_err(|e| FormatError {
        file: file.clone(),
        line: 0,
        msg: format!("cannot read: {e}"),
    })?;
    Ok(Lines::new(&file, BufReader::new(f)))
}

/// The lines of a text stream, one at a time (a file is never held whole), numbered from 1,
/// without their `\n` or `\r\n`. A line that is not UTF-8 or cannot be read is an error naming
/// the file and the line.
pub struct Lines<R> {
    file: String,
    reader: R,
    buf: Vec<u8>,
    line: usize,
}

impl<R: BufRead> Lines<R> {
    /// Lines of `reader`, reported as those of `file`.
    pub fn new(file: &str, reader: R) -> Self {
        Lines {
            file: file.into(),
            reader,
            buf: Vec::new(),
            line: 0,
        }
    }

    /// The file's name, for messages.
    pub fn file(&self) -> &str {
        &self.file
    }

    /// The number of the line last returned (0 before the first).
    pub fn line(&self) -> usize {
        self.line
    }

    /// An error at line `line` of this file.
    pub fn error(&self, line: usize, msg: impl Into<String>) -> FormatError {
        FormatError {
            file: self.file.clone(),
            line,
            msg: msg.into(),
        }
    }

    /// The next bytes of the stream, not consumed: before the first line, its first bytes (to
    /// tell formats apart).
    pub fn peek(&mut self) -> Result<&[u8], FormatError> {
        let file = &self.file;
        self.reader.fill_buf().map_err(|e| FormatError {
            file: file.clone(),
            line: 1,
            msg: format!("cannot read: {e}"),
        })
    }

    /// The next line and its number, `None` at the end of the stream. A line longer than
    /// [`MAX_LINE`] bytes is an error.
    pub fn next_line(&mut self) -> Result<Option<(usize, &str)>, FormatError> {
        use std::io::Read;
        self.buf.clear();
        let limit = MAX_LINE as u64 + 2;
        let read = (&mut self.reader)
            .take(limit)
            .read_until(b'\n', &mut self.buf);
        self.line += 1;
        match read {
            Ok(0) => {
                self.line -= 1;
                return Ok(None);
            }
            Ok(n) if n as u64 == limit && self.buf.last() != Some(&b'\n') => {
                return Err(self.error(
                    self.line,
                    format!(
                        "a line longer than {MAX_LINE} bytes, or no line end at all (a binary \
                         file, or a device?)"
                    ),
                ))
            }
            Ok(_) => {}
            Err(e) => return Err(self.error(self.line, format!("cannot read: {e}"))),
        }
        for end in [b'\n', b'\r'] {
            if self.buf.last() == Some(&end) {
                self.buf.pop();
            }
        }
        match std::str::from_utf8(&self.buf) {
            Ok(s) => Ok(Some((self.line, s))),
            Err(e) => {
                let at = e.valid_up_to();
                Err(self.error(self.line, not_utf8(at, self.buf[at])))
            }
        }
    }

    /// The next line that is not blank, `None` at the end of the stream.
    pub fn next_nonblank(&mut self) -> Result<Option<(usize, &str)>, FormatError> {
        loop {
            // Two look-ups keep the borrow checker content with the early return.
            match self.next_line()? {
                None => return Ok(None),
                Some((_, l)) if l.trim().is_empty() => continue,
                Some(_) => break,
            }
        }
        let line = self.line;
        Ok(Some((
            line,
            std::str::from_utf8(&self.buf).unwrap_or_default(),
        )))
    }
}

/// A count read as a number (a header's `N`): a whole number from 0 to 2^53, else an error
/// naming `field`.
pub fn count(file: &str, line: usize, field: &str, v: f64) -> Result<usize, FormatError> {
    if v >= 0.0 && v.fract() == 0.0 && v <= 2f64.powi(53) {
        Ok(v as usize)
    } else {
        Err(FormatError {
            file: file.into(),
            line,
            msg: {
                let mut got = String::new();
                fmt_f64(&mut got, v);
                format!("{field}: expected a whole number >= 0, got {got}")
            },
        })
    }
}

/// Room to reserve for `n` announced items: no more than a modest number, so that a header
/// announcing absurdly many costs nothing before the lines show it wrong.
pub fn reserve(n: usize) -> usize {
    n.min(1 << 16)
}

/// Parses whitespace-separated numbers of one line, naming file and line on failure; NaN and
/// infinities are rejected.
pub fn parse_numbers(
    file: &str,
    line_no: usize,
    line: &str,
    out: &mut Vec<f64>,
) -> Result<(), FormatError> {
    parse_fields(file, line_no, line, &[], out)
}

/// As [`parse_numbers`], naming column k `names[k]` in messages when there is such a name.
pub fn parse_fields(
    file: &str,
    line_no: usize,
    line: &str,
    names: &[&str],
    out: &mut Vec<f64>,
) -> Result<(), FormatError> {
    out.clear();
    for (col, tok) in line.split_whitespace().enumerate() {
        let column = match names.get(col) {
            Some(name) => format!("column {} ({name})", col + 1),
            None => format!("column {}", col + 1),
        };
        let v: f64 = tok.parse().map_err(|_| FormatError {
            file: file.into(),
            line: line_no,
            msg: format!("{column}: not a number: {tok:?}"),
        })?;
        if !v.is_finite() {
            return Err(FormatError {
                file: file.into(),
                line: line_no,
                msg: format!("{column}: not finite: {tok:?} (expected a finite number)"),
            });
        }
        out.push(v);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn formatted_numbers_round_trip_bit_for_bit(bits in any::<u64>()) {
            let v = f64::from_bits(bits);
            prop_assume!(v.is_finite());
            let mut s = String::new();
            fmt_f64(&mut s, v);
            let back: f64 = s.parse().unwrap();
            prop_assert_eq!(back.to_bits(), v.to_bits());
        }
    }

    #[test]
    fn nan_is_rejected_with_file_and_line() {
        let mut v = Vec::new();
        let e = parse_numbers("a.data", 7, "1 2 nan", &mut v).unwrap_err();
        assert_eq!(
            e.to_string(),
            "a.data:7: column 3: not finite: \"nan\" (expected a finite number)"
        );
    }

    #[test]
    fn xml_and_toml_escapes_read_back() {
        let name = "a<b&c\"d'e>";
        assert_eq!(xml_escaped(name), "a&lt;b&amp;c&quot;d&apos;e&gt;");
        let t: toml::Table = format!("k = {}", toml_string("a\"b\\c\u{7}"))
            .parse()
            .unwrap();
        assert_eq!(t["k"].as_str(), Some("a\"b\\c\u{7}"));
    }

    #[test]
    fn an_endless_line_is_refused_before_it_is_held() {
        let endless = std::io::BufReader::new(std::io::repeat(b'0'));
        let mut lines = Lines::new("zero", endless);
        let e = lines.next_line().unwrap_err().to_string();
        assert!(e.starts_with("zero:1: a line longer than"), "{e}");
        let long = format!("{}\nb\n", "a".repeat(MAX_LINE));
        let mut lines = Lines::new("f", long.as_bytes());
        assert_eq!(
            lines.next_line().unwrap().map(|(_, l)| l.len()),
            Some(MAX_LINE)
        );
        assert_eq!(lines.next_line().unwrap(), Some((2, "b")));
    }

    #[test]
    fn an_endless_file_is_refused_when_read_whole() {
        let e = read_bounded(Path::new("/dev/zero"), 1000)
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "/dev/zero: larger than the 1000 bytes a file of this kind may have"
        );
    }
}
