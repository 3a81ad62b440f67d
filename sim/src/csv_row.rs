//! Formatting the rows of margemu's CSV outputs (`truth.csv`, `marg.csv`, `perturbation.csv`):
//! an integer time stamp, then floats, comma-separated, one row per line.
//!
//! Each float is written in its shortest round-trip form, spelled as the `ryu` crate spells it,
//! which is how these files have always been written: `0.0`, `-0.0`, `1.5`, `0.00001`, `1e-7`,
//! `1e16`, `1.7976931348623157e308`, `NaN`, `inf`, `-inf`. The digits come from `zmij`, a faster
//! shortest round-trip formatter whose digits and layout are ryu's, except that it writes a `+`
//! in positive exponents (`1e+16`), which [`RowBuf`] leaves out. Integers are written with `itoa`.
//!
//! A row is formatted into one reusable buffer ([`RowBuf`]) and handed to the writer whole, so a
//! row costs one `write_all`, no formatting machinery and no allocation once the buffer has grown.
//!
//! ```
//! use margemu_sim::csv_row::RowBuf;
//! let mut row = RowBuf::default();
//! assert_eq!(row.format(5, [0.5f64, -0.0, 1e16, 1e-7]), b"5,0.5,-0.0,1e16,1e-7\n");
//! assert_eq!(row.format(7, [f32::NAN, 9.80665f32]), b"7,NaN,9.80665\n");
//! ```

use std::io::{self, Write};

/// A float type of a CSV column: `f32` (MARG samples) or `f64` (truth).
pub trait CsvFloat: Copy + zmij::Float {
    /// Whether `self` is small enough that its shortest form has no positive exponent (both
    /// crates write plain decimals from 1e-5 up to at least 1e7, for `f32` and `f64` alike).
    fn is_below_exponent_form(self) -> bool;
}

impl CsvFloat for f32 {
    fn is_below_exponent_form(self) -> bool {
        self.abs() < 1e7
    }
}

impl CsvFloat for f64 {
    fn is_below_exponent_form(self) -> bool {
        self.abs() < 1e7
    }
}

/// One CSV row's bytes, reused from row to row.
#[derive(Clone, Debug, Default)]
pub struct RowBuf {
    bytes: Vec<u8>,
}

impl RowBuf {
    /// The row `t_ns,v0,v1,…` with its line end.
    pub fn format<F: CsvFloat>(&mut self, t_ns: u64, values: impl IntoIterator<Item = F>) -> &[u8] {
        self.bytes.clear();
        self.bytes
            .extend_from_slice(itoa::Buffer::new().format(t_ns).as_bytes());
        for v in values {
            self.bytes.push(b',');
            push_float(&mut self.bytes, v);
        }
        self.bytes.push(b'\n');
        &self.bytes
    }

    /// Writes the row `t_ns,v0,v1,…` to `out` in one `write_all`.
    pub fn write<F: CsvFloat>(
        &mut self,
        out: &mut impl Write,
        t_ns: u64,
        values: impl IntoIterator<Item = F>,
    ) -> io::Result<()> {
        out.write_all(self.format(t_ns, values))
    }
}

/// Appends `v`, spelled as `ryu` spells it (see the module docs).
fn push_float<F: CsvFloat>(bytes: &mut Vec<u8>, v: F) {
    let mut digits = zmij::Buffer::new();
    let text = digits.format(v).as_bytes();
    if v.is_below_exponent_form() {
        bytes.extend_from_slice(text);
        return;
    }
    match text.iter().position(|&c| c == b'+') {
        Some(plus) => {
            bytes.extend_from_slice(&text[..plus]);
            bytes.extend_from_slice(&text[plus + 1..]);
        }
        None => bytes.extend_from_slice(text),
    }
}

/// A header row: the column names, comma-separated, with the line end.
pub fn header(columns: &[&str]) -> String {
    let mut line = columns.join(",");
    line.push('\n');
    line
}

#[cfg(test)]
mod tests;
