//! CSV tables of numbers through the `csv` crate: written with [`fmt_f64`] so that every
//! number reads back to the same bits, read record by record with the line of each record (for
//! messages that name file, line and column).

use super::{fmt_f64, FormatError};

/// The CSV text of a header and rows of numbers, each number as [`fmt_f64`] writes it, `\n`
/// after every record; fields are quoted only when they hold a comma, a quote or a line break.
pub fn write<H, R>(header: H, rows: impl IntoIterator<Item = R>) -> String
where
    H: IntoIterator,
    H::Item: AsRef<[u8]>,
    R: IntoIterator<Item = f64>,
{
    let mut w = csv::Writer::from_writer(Vec::new());
    let fail = "a CSV table is written to memory";
    w.write_record(header).expect(fail);
    let mut field = String::new();
    let mut record = csv::StringRecord::new();
    for row in rows {
        record.clear();
        for v in row {
            field.clear();
            fmt_f64(&mut field, v);
            record.push_field(&field);
        }
        w.write_record(&record).expect(fail);
    }
    String::from_utf8(w.into_inner().expect(fail)).expect("CSV of UTF-8 fields")
}

/// The records of `text` with their lines (from 1), header included, with surrounding spaces
/// trimmed from each field and any number of fields per record; blank lines and, with
/// `comments`, lines starting with `#` are skipped. A record that cannot be read is a
/// [`FormatError`] of `file` at its line.
pub fn records<'a>(
    file: &'a str,
    text: &'a str,
    comments: bool,
) -> impl Iterator<Item = Result<(usize, csv::StringRecord), FormatError>> + 'a {
    csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .trim(csv::Trim::All)
        .comment(comments.then_some(b'#'))
        .from_reader(text.as_bytes())
        .into_records()
        .map(move |r| {
            let at = |p: Option<&csv::Position>| {
                p.map_or(0, |p| line_at(text, p.line() as usize, p.byte(), comments))
            };
            match r {
                Ok(record) => Ok((at(record.position()), record)),
                Err(e) => Err(FormatError {
                    file: file.into(),
                    line: at(e.position()),
                    msg: e.to_string(),
                }),
            }
        })
}

/// The line (from 1) of the first record at or after byte `byte` of `text`, which is on line
/// `line`: the reader reports a record from the end of the previous one, before the blank (and
/// comment) lines it skipped.
fn line_at(text: &str, line: usize, byte: u64, comments: bool) -> usize {
    let bytes = text.as_bytes();
    let start = (byte as usize).min(bytes.len());
    let mut at = start;
    loop {
        match bytes.get(at) {
            Some(b'\r' | b'\n') => at += 1,
            Some(b'#') if comments && (at == 0 || bytes[at - 1] == b'\n') => {
                at += bytes[at..]
                    .iter()
                    .position(|&b| b == b'\n')
                    .unwrap_or(bytes.len() - at)
            }
            _ => break,
        }
    }
    line + bytes[start..at].iter().filter(|&&b| b == b'\n').count()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_written_bit_exactly_and_read_with_their_lines() {
        let text = write(["a", "b,c"], [vec![1.0, 0.1], vec![-2.5e-300, 1e20]]);
        assert_eq!(text, "a,\"b,c\"\n1,0.1\n-2.5e-300,1e20\n");
        let text = format!("\n{text}\n# a, comment\n\n  7 , 8\n");
        let read: Vec<_> = records("t.csv", &text, true).map(Result::unwrap).collect();
        assert_eq!(read.len(), 4);
        assert_eq!(&read[1].1[1], "0.1");
        let lines: Vec<usize> = read.iter().map(|r| r.0).collect();
        assert_eq!(lines, [2, 3, 4, 8]);
        assert_eq!(&read[3].1[0], "7");
    }
}
