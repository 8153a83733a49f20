//! CSV tables, written through the `csv` crate.
//!
//! Writing ([`PartialCsv`]): a header record, then one record per call, each field as given
//! (the caller formats the numbers), fields holding a comma, a quote or a line break quoted
//! (RFC 4180, `\n` ending each record). The records go to `<name>.partial`, renamed to `<name>`
//! by [`PartialCsv::finish`] ([`crate::atomic`]), so an interrupted process never leaves a file
//! that looks complete.

use std::fs::File;
use std::path::{Path, PathBuf};

use crate::atomic::partial_path;

/// A CSV file being written under its temporary name.
pub struct PartialCsv {
    writer: csv::Writer<File>,
    partial: PathBuf,
    final_path: PathBuf,
}

impl PartialCsv {
    /// Creates `path` + `.partial` and writes the header record `columns`.
    ///
    /// # Errors
    /// I/O errors.
    pub fn create(path: &Path, columns: &[&str]) -> std::io::Result<Self> {
        let partial = partial_path(path);
        let mut writer = csv::Writer::from_writer(File::create(&partial)?);
        writer.write_record(columns)?;
        Ok(Self {
            writer,
            partial,
            final_path: path.to_path_buf(),
        })
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
        let file = self.writer.into_inner().map_err(|e| e.into_error())?;
        file.sync_all()?;
        std::fs::rename(&self.partial, &self.final_path)
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
    fn fields_with_commas_quotes_and_line_breaks_are_quoted() {
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
    }
}
