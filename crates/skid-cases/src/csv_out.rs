//! CSV tables, written and read through the `csv` crate.
//!
//! Writing ([`PartialCsv`]): a header record, then one record per call, each field as given
//! (the caller formats the numbers), fields holding a comma, a quote or a line break quoted
//! (RFC 4180, `\n` ending each record), into an [`AppendFile`]: written as `<name>.partial`,
//! renamed to `<name>` by [`PartialCsv::finish`], marked at restart points
//! ([`PartialCsv::mark`]) and reopened at a mark by a resumed run ([`PartialCsv::reopen`]).
//!
//! Reading ([`CsvTable`]): the first record is the header, whose names are trimmed; a column is
//! found by its name, and a record may hold fewer fields than the header (a missing field is an
//! error only where it is read). Errors name the file, the line the record starts on, and the
//! column.

use std::io;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use csv::StringRecord;

use crate::append_file::{AppendFile, FileMark};

/// A CSV file being written under its temporary name ([`AppendFile`]).
pub struct PartialCsv {
    writer: csv::Writer<AppendFile>,
}

impl PartialCsv {
    /// Creates `path` + `.partial` and writes the header record `columns`.
    ///
    /// # Errors
    /// I/O errors.
    pub fn create(path: &Path, columns: &[&str]) -> std::io::Result<Self> {
        let mut writer = csv::Writer::from_writer(AppendFile::create(path)?);
        writer.write_record(columns)?;
        Ok(Self { writer })
    }

    /// Reopens the file of an interrupted run at `mark` ([`AppendFile::reopen`]); records are
    /// appended from there.
    ///
    /// # Errors
    /// As [`AppendFile::reopen`].
    pub fn reopen(path: &Path, mark: &FileMark) -> io::Result<Self> {
        let (file, _) = AppendFile::reopen(path, mark)?;
        Ok(Self {
            writer: csv::Writer::from_writer(file),
        })
    }

    /// Flushes the records written so far to disk (synced) and returns how much of the file
    /// that is, for a restart point.
    ///
    /// # Errors
    /// I/O errors.
    pub fn mark(&mut self) -> io::Result<FileMark> {
        self.writer.flush()?;
        self.writer.get_ref().mark()
    }

    /// Writes one record, one field per column of the header.
    ///
    /// # Errors
    /// I/O errors, or a record whose length differs from the header's.
    pub fn record<I, T>(&mut self, fields: I) -> std::io::Result<()>
    where
        I: IntoIterator<Item = T>,
        T: AsRef<[u8]>,
    {
        Ok(self.writer.write_record(fields)?)
    }

    /// Flushes, syncs and renames the file to its final name.
    ///
    /// # Errors
    /// I/O errors.
    pub fn finish(self) -> std::io::Result<()> {
        self.writer
            .into_inner()
            .map_err(|e| e.into_error())?
            .finish()
    }
}

/// A CSV file that is not what was expected: `<path>: <message>`, the message naming the line
/// and the column where it can.
#[derive(Debug, thiserror::Error)]
#[error("{path}: {message}")]
pub struct CsvError {
    /// The file.
    pub path: PathBuf,
    /// What is wrong, and where (line, column).
    pub message: String,
}

/// A column of a [`CsvTable`], found by its name.
#[derive(Clone, Copy, Debug)]
pub struct Column<'n> {
    index: usize,
    name: &'n str,
}

/// The records of a CSV text after its header, read one at a time.
pub struct CsvTable<'a> {
    reader: csv::Reader<&'a [u8]>,
    text: &'a [u8],
    path: &'a Path,
    header: StringRecord,
}

impl<'a> CsvTable<'a> {
    /// Reads the header of `text`; `path` is only used in messages.
    ///
    /// # Errors
    /// An empty text, or malformed CSV.
    pub fn new(text: &'a str, path: &'a Path) -> Result<Self, CsvError> {
        let mut reader = csv::ReaderBuilder::new()
            .flexible(true)
            .trim(csv::Trim::Headers)
            .from_reader(text.as_bytes());
        let header = reader
            .headers()
            .map_err(|e| error(path, e.to_string()))?
            .clone();
        if header.is_empty() {
            return Err(error(path, "empty file, expected a CSV header".into()));
        }
        Ok(Self {
            reader,
            text: text.as_bytes(),
            path,
            header,
        })
    }

    /// The column names, in file order.
    pub fn header(&self) -> impl Iterator<Item = &str> {
        self.header.iter()
    }

    /// The column called `name`.
    ///
    /// # Errors
    /// No such column in the header.
    pub fn column<'n>(&self, name: &'n str) -> Result<Column<'n>, CsvError> {
        self.header
            .iter()
            .position(|c| c == name)
            .map(|index| Column { index, name })
            .ok_or_else(|| error(self.path, format!("no column '{name}' in the header")))
    }

    /// The line `record` starts on. The reader's position of a record is where it began
    /// looking for it, before the empty lines it skips, so those are counted here.
    fn start_line(&self, record: &StringRecord) -> u64 {
        let Some(position) = record.position() else {
            return 0;
        };
        let mut skipped = self
            .text
            .get(usize::try_from(position.byte()).unwrap_or(usize::MAX)..)
            .unwrap_or_default()
            .iter()
            .peekable();
        let mut ends = 0;
        while let Some(&b) = skipped.next_if(|&&b| b == b'\n' || b == b'\r') {
            if b == b'\n' || skipped.peek() != Some(&&b'\n') {
                ends += 1;
            }
        }
        position.line() + ends as u64
    }
}

impl<'a> Iterator for CsvTable<'a> {
    type Item = Result<Row<'a>, CsvError>;

    fn next(&mut self) -> Option<Self::Item> {
        let mut record = StringRecord::new();
        match self.reader.read_record(&mut record) {
            Ok(true) => Some(Ok(Row {
                line: self.start_line(&record),
                record,
                path: self.path,
            })),
            Ok(false) => None,
            Err(e) => Some(Err(error(self.path, e.to_string()))),
        }
    }
}

/// One record of a [`CsvTable`].
#[derive(Clone, Debug)]
pub struct Row<'a> {
    record: StringRecord,
    line: u64,
    path: &'a Path,
}

impl Row<'_> {
    /// The line the record starts on (the header is line 1).
    pub fn line(&self) -> u64 {
        self.line
    }

    /// The record's fields, in file order.
    pub fn fields(&self) -> impl Iterator<Item = &str> {
        self.record.iter()
    }

    /// The field in `column`.
    ///
    /// # Errors
    /// The record has no field there.
    pub fn text(&self, column: Column<'_>) -> Result<&str, CsvError> {
        self.record
            .get(column.index)
            .ok_or_else(|| self.error(format!("no value in '{}'", column.name)))
    }

    /// The field in `column` parsed as a number (surrounding spaces ignored).
    ///
    /// # Errors
    /// The field is absent or not a `T`.
    pub fn number<T: FromStr>(&self, column: Column<'_>) -> Result<T, CsvError> {
        self.record
            .get(column.index)
            .and_then(|f| f.trim().parse().ok())
            .ok_or_else(|| self.error(format!("expected a number in '{}'", column.name)))
    }

    fn error(&self, message: String) -> CsvError {
        error(self.path, format!("line {}: {message}", self.line()))
    }
}

fn error(path: &Path, message: String) -> CsvError {
    CsvError {
        path: path.to_path_buf(),
        message,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_file_appears_under_its_name_only_when_finished() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("x.csv");
        let mut csv = PartialCsv::create(&path, &["a", "b"]).expect("create");
        csv.record(["1", "2"]).expect("record");
        assert!(!path.exists());
        assert!(dir.path().join("x.csv.partial").exists());
        csv.finish().expect("finish");
        assert_eq!(std::fs::read_to_string(&path).expect("read"), "a,b\n1,2\n");
        assert!(!dir.path().join("x.csv.partial").exists());
    }

    #[test]
    fn a_writer_dropped_without_finishing_leaves_no_file_under_the_final_name() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("history.csv");
        {
            let mut csv = PartialCsv::create(&path, &["step", "time"]).expect("create");
            csv.record(["spin", "0.1"]).expect("record");
        }
        assert!(!path.exists());
        let partial = std::fs::read_to_string(dir.path().join("history.csv.partial"));
        assert_eq!(partial.expect("partial"), "step,time\nspin,0.1\n");
    }

    #[test]
    fn records_of_the_wrong_length_are_refused() {
        let dir = tempfile::tempdir().expect("tempdir");
        let mut csv = PartialCsv::create(&dir.path().join("x.csv"), &["a", "b"]).expect("create");
        assert!(csv.record(["1"]).is_err());
    }

    #[test]
    fn fields_with_commas_quotes_and_line_breaks_are_quoted_and_read_back() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("x.csv");
        let names = ["spin, down \"fast\"", "two\nlines", "plain"];
        let mut csv = PartialCsv::create(&path, &["step", "omega"]).expect("create");
        for (k, name) in names.iter().enumerate() {
            csv.record([name.to_string(), format!("{k}.5")])
                .expect("record");
        }
        csv.finish().expect("finish");
        let text = std::fs::read_to_string(&path).expect("read");
        assert_eq!(
            text,
            "step,omega\n\"spin, down \"\"fast\"\"\",0.5\n\"two\nlines\",1.5\nplain,2.5\n"
        );
        let table = CsvTable::new(&text, &path).expect("header");
        let (step, omega) = (
            table.column("step").expect("step"),
            table.column("omega").expect("omega"),
        );
        let rows: Vec<Row<'_>> = table.collect::<Result<_, _>>().expect("records");
        let read: Vec<(&str, f64, u64)> = rows
            .iter()
            .map(|r| {
                let name = r.text(step).expect("step");
                (name, r.number(omega).expect("omega"), r.line())
            })
            .collect();
        // The record with a line break in a field spans lines 3 and 4.
        assert_eq!(
            read,
            vec![(names[0], 0.5, 2), (names[1], 1.5, 3), (names[2], 2.5, 5)]
        );
    }

    #[test]
    fn errors_name_the_file_the_line_and_the_column() {
        let path = Path::new("run/history.csv");
        let text = "time, drum_omega\n0,1\n\n0.1,oops\n0.2\n";
        let table = CsvTable::new(text, path).expect("header");
        let e = table.column("step").expect_err("no such column");
        assert_eq!(
            e.to_string(),
            "run/history.csv: no column 'step' in the header"
        );
        let omega = table.column("drum_omega").expect("trimmed header name");
        let rows: Vec<Row<'_>> = table.collect::<Result<_, _>>().expect("records");
        assert_eq!(rows.len(), 3, "the empty line is no record");
        assert_eq!(rows[0].number::<f64>(omega).expect("number"), 1.0);
        let e = rows[1].number::<f64>(omega).expect_err("not a number");
        assert_eq!(
            e.to_string(),
            "run/history.csv: line 4: expected a number in 'drum_omega'"
        );
        let e = rows[2].text(omega).expect_err("short record");
        assert_eq!(
            e.to_string(),
            "run/history.csv: line 5: no value in 'drum_omega'"
        );
        let crlf = CsvTable::new("a\r\n1\r\n\r\n\r\n2\r\n", path).expect("header");
        let lines: Vec<u64> = crlf.map(|r| r.expect("record").line()).collect();
        assert_eq!(lines, vec![2, 5]);
        let e = CsvTable::new("", path).err().expect("empty");
        assert!(e.to_string().contains("empty file"), "{e}");
    }
}
