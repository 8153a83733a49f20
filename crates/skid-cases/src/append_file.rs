//! Files a run appends to and a restart point marks.
//!
//! An [`AppendFile`] `<name>` is written as `<name>.partial` and renamed to `<name>` by
//! [`AppendFile::finish`] ([`crate::atomic`]), so an interrupted process never leaves a file
//! that looks complete. It counts and hashes (FNV-1a) every byte that reaches it, so a restart
//! point can say how much of it is on disk ([`AppendFile::mark`]: the length and the hash,
//! after a sync) without reading it again; a resumed run reopens the file cut back to that
//! mark ([`AppendFile::reopen`], which checks that the first bytes are the marked ones) and
//! appends from there. Marking therefore costs what was appended since the last mark, however
//! long the file has grown.

use std::fs::File;
use std::io::{self, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::atomic::partial_path;
use crate::fingerprint::Fnv1a;

/// How much of an [`AppendFile`] was on disk at a restart point: its length and the hash of
/// those bytes.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct FileMark {
    /// Length, bytes.
    pub bytes: u64,
    /// FNV-1a hash of those bytes (16 hex digits).
    pub fnv1a: String,
}

/// A file being appended to under its temporary name (see the module documentation).
/// Writes are not buffered here: wrap it in a buffered writer.
pub struct AppendFile {
    file: File,
    bytes: u64,
    hash: Fnv1a,
    partial: PathBuf,
    final_path: PathBuf,
}

impl AppendFile {
    /// Creates `path` + `.partial`, empty.
    ///
    /// # Errors
    /// I/O errors.
    pub fn create(path: &Path) -> io::Result<Self> {
        let partial = partial_path(path);
        Ok(Self {
            file: File::create(&partial)?,
            bytes: 0,
            hash: Fnv1a::default(),
            partial,
            final_path: path.to_path_buf(),
        })
    }

    /// Reopens the file of an interrupted run at `mark`: `path` + `.partial` (or `path` itself,
    /// renamed back, if the run was interrupted after finishing it), checked to begin with the
    /// marked bytes and cut back to them. Returns the file, positioned at its end, and those
    /// bytes.
    ///
    /// # Errors
    /// An `InvalidData` error naming the file if it is shorter than the mark or its first bytes
    /// differ from the marked ones; I/O errors.
    pub fn reopen(path: &Path, mark: &FileMark) -> io::Result<(Self, Vec<u8>)> {
        let partial = partial_path(path);
        if !partial.exists() && path.exists() {
            std::fs::rename(path, &partial)?;
        }
        let mut file = File::options().read(true).write(true).open(&partial)?;
        let mut marked = Vec::new();
        (&mut file).take(mark.bytes).read_to_end(&mut marked)?;
        let mut hash = Fnv1a::default();
        hash.update(&marked);
        let invalid = |what: String| {
            io::Error::new(
                io::ErrorKind::InvalidData,
                format!("{}: {what}", partial.display()),
            )
        };
        let bytes = marked.len() as u64;
        if bytes < mark.bytes {
            return Err(invalid(format!(
                "{bytes} bytes, shorter than the {} of the restart point",
                mark.bytes
            )));
        }
        if hash.hex() != mark.fnv1a {
            return Err(invalid(
                "its first bytes are not those written up to the restart point".into(),
            ));
        }
        file.set_len(mark.bytes)?;
        file.seek(SeekFrom::End(0))?;
        let reopened = Self {
            file,
            bytes,
            hash,
            partial,
            final_path: path.to_path_buf(),
        };
        Ok((reopened, marked))
    }

    /// Syncs what was written so far to disk and returns how much of the file that is, for a
    /// restart point (whatever buffers writes into this file must be flushed first).
    ///
    /// # Errors
    /// I/O errors.
    pub fn mark(&self) -> io::Result<FileMark> {
        self.file.sync_data()?;
        Ok(FileMark {
            bytes: self.bytes,
            fnv1a: self.hash.hex(),
        })
    }

    /// Syncs the file and renames it to its final name.
    ///
    /// # Errors
    /// I/O errors.
    pub fn finish(self) -> io::Result<()> {
        self.file.sync_all()?;
        std::fs::rename(&self.partial, &self.final_path)
    }
}

impl Write for AppendFile {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let n = self.file.write(buf)?;
        self.hash.update(&buf[..n]);
        self.bytes += n as u64;
        Ok(n)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.file.flush()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hash_of(bytes: &[u8]) -> String {
        let mut hash = Fnv1a::default();
        hash.update(bytes);
        hash.hex()
    }

    #[test]
    fn the_mark_is_the_length_and_hash_of_what_was_written() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("log.txt");
        let mut file = AppendFile::create(&path).expect("create");
        file.write_all(b"first\n").expect("write");
        file.write_all(b"second\n").expect("write");
        let mark = file.mark().expect("mark");
        assert_eq!(mark.bytes, 13);
        assert_eq!(mark.fnv1a, hash_of(b"first\nsecond\n"));
        assert!(
            !path.exists(),
            "only the partial file exists before finishing"
        );
        file.finish().expect("finish");
        assert_eq!(std::fs::read(&path).expect("read"), b"first\nsecond\n");
        assert!(!partial_path(&path).exists());
    }

    #[test]
    fn reopening_cuts_back_to_the_mark_returns_its_bytes_and_appends_after_them() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("log.txt");
        let mut file = AppendFile::create(&path).expect("create");
        file.write_all(b"kept\n").expect("write");
        let mark = file.mark().expect("mark");
        file.write_all(b"lost after the mark\n").expect("write");
        drop(file);
        let (mut file, marked) = AppendFile::reopen(&path, &mark).expect("reopen");
        assert_eq!(marked, b"kept\n");
        file.write_all(b"again\n").expect("write");
        let mark = file.mark().expect("mark");
        assert_eq!(mark.fnv1a, hash_of(b"kept\nagain\n"));
        file.finish().expect("finish");
        assert_eq!(std::fs::read(&path).expect("read"), b"kept\nagain\n");
        // a finished file is renamed back and reopened the same way
        let (_, marked) = AppendFile::reopen(&path, &mark).expect("reopen finished");
        assert_eq!(marked, b"kept\nagain\n");
        assert!(partial_path(&path).exists() && !path.exists());
    }

    #[test]
    fn a_file_that_is_short_or_differs_from_the_mark_is_refused_with_its_name() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("log.txt");
        let mut file = AppendFile::create(&path).expect("create");
        file.write_all(b"abc").expect("write");
        let mark = file.mark().expect("mark");
        drop(file);
        std::fs::write(partial_path(&path), b"ab").expect("shorten");
        let short = AppendFile::reopen(&path, &mark).err().expect("short");
        assert_eq!(short.kind(), io::ErrorKind::InvalidData);
        assert!(
            short.to_string().contains("log.txt.partial: 2 bytes"),
            "{short}"
        );
        std::fs::write(partial_path(&path), b"abd").expect("change");
        let changed = AppendFile::reopen(&path, &mark).err().expect("changed");
        assert!(changed.to_string().contains("first bytes"), "{changed}");
    }
}
