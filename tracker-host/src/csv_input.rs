//! Reading the product's CSV inputs (plots files, truth files) with errors a user can act on:
//! every error names the file, the line and the column; a header with a column twice, a
//! column the format does not have, or a required one missing is refused before any row is
//! read. Parsing is the `csv` crate's.

use std::collections::HashMap;
use std::path::Path;

use anyhow::{anyhow, bail, Context};

/// A CSV file's header, checked against a format.
pub struct Header {
    index: HashMap<String, usize>,
    file: String,
}

/// Opens `path` and checks its header: every one of `required`, any of `optional`, nothing
/// else, nothing twice.
///
/// # Errors
/// The file does not open or is not CSV, or its header breaks one of those rules.
pub fn open(
    path: &Path,
    required: &[&str],
    optional: &[&str],
) -> anyhow::Result<(csv::Reader<std::fs::File>, Header)> {
    let file = path.display().to_string();
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .flexible(false)
        .from_path(path)
        .with_context(|| format!("opening {file}"))?;
    let names = reader
        .headers()
        .with_context(|| format!("{file}: line 1: not a CSV header"))?
        .clone();
    let mut index = HashMap::new();
    for (i, name) in names.iter().enumerate() {
        if !required.contains(&name) && !optional.contains(&name) {
            bail!(
                "{file}: line 1, column {}: unknown column `{name}` (expected {}{})",
                i + 1,
                required.join(","),
                if optional.is_empty() {
                    String::new()
                } else {
                    format!(", optionally {}", optional.join(","))
                }
            );
        }
        if index.insert(name.to_string(), i).is_some() {
            bail!(
                "{file}: line 1, column {}: column `{name}` appears twice",
                i + 1
            );
        }
    }
    if let Some(missing) = required.iter().find(|c| !index.contains_key(**c)) {
        bail!("{file}: line 1: missing column `{missing}`");
    }
    Ok((reader, Header { index, file }))
}

/// Reads the next record into `record`; `false` at the end.
///
/// # Errors
/// A record the `csv` crate cannot read (a row with the wrong number of fields, bad UTF-8),
/// naming its line.
pub fn read(
    reader: &mut csv::Reader<std::fs::File>,
    header: &Header,
    record: &mut csv::StringRecord,
) -> anyhow::Result<bool> {
    reader.read_record(record).map_err(|e| {
        let line = e.position().map_or(0, |p| p.line());
        anyhow!("{}: line {line}: {e}", header.file())
    })
}

/// One row, with the header to find its columns by name.
pub struct Row<'a> {
    header: &'a Header,
    record: &'a csv::StringRecord,
    line: u64,
}

impl Header {
    /// The file's name as errors show it.
    pub fn file(&self) -> &str {
        &self.file
    }

    /// True when the file has `column`.
    pub fn has(&self, column: &str) -> bool {
        self.index.contains_key(column)
    }

    /// A row of this file.
    pub fn row<'a>(&'a self, record: &'a csv::StringRecord) -> Row<'a> {
        Row {
            header: self,
            line: record.position().map_or(0, |p| p.line()),
            record,
        }
    }
}

impl Row<'_> {
    /// The row's line number (1 is the header).
    pub fn line(&self) -> u64 {
        self.line
    }

    /// An error at this row's `column`.
    pub fn error(&self, column: &str, what: &str) -> anyhow::Error {
        let col = self.header.index.get(column).map_or(0, |i| i + 1);
        anyhow!(
            "{}: line {}, column {col} ({column}): {what}",
            self.header.file,
            self.line
        )
    }

    /// The text in `column`, `None` when the file has no such column or the cell is empty.
    pub fn text(&self, column: &str) -> Option<&str> {
        let i = *self.header.index.get(column)?;
        self.record.get(i).filter(|s| !s.is_empty())
    }

    /// A finite number in `column`, `None` when absent or empty.
    ///
    /// # Errors
    /// The cell holds something that is not a finite number.
    pub fn number(&self, column: &str) -> anyhow::Result<Option<f64>> {
        let Some(text) = self.text(column) else {
            return Ok(None);
        };
        match text.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(Some(v)),
            _ => Err(self.error(column, &format!("`{text}` is not a finite number"))),
        }
    }

    /// A finite number in `column` as `f32` (parsed as `f32`, so a value written as an
    /// `f32` reads back bit for bit), `None` when absent or empty.
    ///
    /// # Errors
    /// The cell holds something that is not a finite `f32`.
    pub fn number_f32(&self, column: &str) -> anyhow::Result<Option<f32>> {
        let Some(text) = self.text(column) else {
            return Ok(None);
        };
        match text.parse::<f32>() {
            Ok(v) if v.is_finite() => Ok(Some(v)),
            _ => Err(self.error(column, &format!("`{text}` is not a finite number"))),
        }
    }

    /// A finite `f32` that must be there.
    ///
    /// # Errors
    /// The cell is empty or not a finite number.
    pub fn required_f32(&self, column: &str) -> anyhow::Result<f32> {
        self.number_f32(column)?
            .ok_or_else(|| self.error(column, "empty; a number is required"))
    }

    /// A finite number that must be there.
    ///
    /// # Errors
    /// The cell is empty or not a finite number.
    pub fn required_number(&self, column: &str) -> anyhow::Result<f64> {
        self.number(column)?
            .ok_or_else(|| self.error(column, "empty; a number is required"))
    }

    /// A non-negative integer that must be there.
    ///
    /// # Errors
    /// The cell is empty or not an integer in `0..=u32::MAX`.
    pub fn required_u32(&self, column: &str) -> anyhow::Result<u32> {
        let text = self
            .text(column)
            .ok_or_else(|| self.error(column, "empty; an integer is required"))?;
        text.parse()
            .map_err(|_| self.error(column, &format!("`{text}` is not a non-negative integer")))
    }
}
