//! CSV outputs that appear only when complete: rows go to `<name>.partial`, which is renamed to
//! `<name>` when the run has ended, so an interrupted process never leaves a file that looks
//! complete.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::atomic::partial_path;

/// A CSV file being written under its temporary name.
pub struct PartialCsv {
    writer: BufWriter<File>,
    partial: PathBuf,
    final_path: PathBuf,
}

impl PartialCsv {
    /// Creates `path` + `.partial` and writes the header line `columns`.
    ///
    /// # Errors
    /// I/O errors.
    pub fn create(path: &Path, columns: &[&str]) -> std::io::Result<Self> {
        let partial = partial_path(path);
        let mut writer = BufWriter::new(File::create(&partial)?);
        writeln!(writer, "{}", columns.join(","))?;
        Ok(Self {
            writer,
            partial,
            final_path: path.to_path_buf(),
        })
    }

    /// Where the rows go.
    pub fn rows(&mut self) -> &mut impl Write {
        &mut self.writer
    }

    /// Flushes, syncs and renames the file to its final name.
    ///
    /// # Errors
    /// I/O errors.
    pub fn finish(mut self) -> std::io::Result<()> {
        self.writer.flush()?;
        self.writer.get_ref().sync_all()?;
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
        writeln!(csv.rows(), "1,2").expect("row");
        assert!(!path.exists());
        assert!(dir.path().join("x.csv.partial").exists());
        csv.finish().expect("finish");
        assert_eq!(std::fs::read_to_string(&path).expect("read"), "a,b\n1,2\n");
        assert!(!dir.path().join("x.csv.partial").exists());
    }
}
