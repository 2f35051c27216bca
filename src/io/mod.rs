//! Files: MercuryCG `.data`/`.fstat` saves, the official initial-configuration format,
//! checkpoints, the state hash, the diagnostics table, ParaView's VTK files, atomic writes.

pub mod atomic;
pub mod checkpoint;
pub mod csv_table;
pub mod diagnostics;
pub mod hash;
pub mod mercury;
pub mod official;
pub mod vtk;

/// A malformed input file: `file:line: message`.
#[derive(Debug, thiserror::Error)]
#[error("{file}:{line}: {msg}")]
pub struct FormatError {
    pub file: String,
    pub line: usize,
    pub msg: String,
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

/// Reads a text file; returns its name (for messages) and its text.
pub fn read_text(path: &std::path::Path) -> Result<(String, String), FormatError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| FormatError {
        file: file.clone(),
        line: 0,
        msg: format!("cannot read: {e}"),
    })?;
    Ok((file, text))
}

/// Parses whitespace-separated numbers of one line, naming file and line on failure; NaN and
/// infinities are rejected.
pub fn parse_numbers(
    file: &str,
    line_no: usize,
    line: &str,
    out: &mut Vec<f64>,
) -> Result<(), FormatError> {
    out.clear();
    for (col, tok) in line.split_whitespace().enumerate() {
        let v: f64 = tok.parse().map_err(|_| FormatError {
            file: file.into(),
            line: line_no,
            msg: format!("column {}: not a number: {tok:?}", col + 1),
        })?;
        if !v.is_finite() {
            return Err(FormatError {
                file: file.into(),
                line: line_no,
                msg: format!("column {}: not finite: {tok:?}", col + 1),
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
        assert_eq!(e.to_string(), "a.data:7: column 3: not finite: \"nan\"");
    }
}
