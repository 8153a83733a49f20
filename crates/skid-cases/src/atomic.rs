//! Output files that are complete or absent: a file `<name>` is written as `<name>.partial`,
//! flushed to disk, and renamed to `<name>`. A rename within a directory replaces the target in
//! one step, so a reader sees the earlier file or the whole new one, and a process interrupted
//! while writing leaves only the `.partial` sibling.

use std::io::Write;
use std::path::{Path, PathBuf};

use serde::Serialize;

/// The temporary sibling `path` is written under: `path` + `.partial`.
pub fn partial_path(path: &Path) -> PathBuf {
    let mut partial = path.as_os_str().to_owned();
    partial.push(".partial");
    PathBuf::from(partial)
}

/// Writes `bytes` to `path` through [`partial_path`], synced before the rename.
///
/// # Errors
/// I/O errors; `path` is then untouched.
pub fn write_atomic(path: &Path, bytes: impl AsRef<[u8]>) -> std::io::Result<()> {
    let partial = partial_path(path);
    let mut file = std::fs::File::create(&partial)?;
    file.write_all(bytes.as_ref())?;
    file.sync_all()?;
    std::fs::rename(&partial, path)
}

/// The pretty JSON text of `value`.
///
/// # Errors
/// The serializer's (a map whose keys are not strings, a type's own `Serialize` refusing).
pub fn json_text(value: &impl Serialize) -> serde_json::Result<String> {
    serde_json::to_string_pretty(value)
}

/// Writes the pretty JSON text of `value` to `path` as [`write_atomic`] does; a value that
/// cannot be serialized writes nothing.
///
/// # Errors
/// I/O errors, and a serialization error as one of kind `InvalidData`; `path` is then untouched.
pub fn write_json_atomic(path: &Path, value: &impl Serialize) -> std::io::Result<()> {
    let text =
        json_text(value).map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidData, e))?;
    write_atomic(path, text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_file_is_replaced_whole_and_no_partial_sibling_is_left() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("summary.json");
        std::fs::write(&path, "old, longer contents").expect("old file");
        write_atomic(&path, "new").expect("write");
        assert_eq!(std::fs::read_to_string(&path).expect("read"), "new");
        assert!(!partial_path(&path).exists());
    }

    #[test]
    fn a_failed_write_leaves_no_file() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("missing").join("report.md");
        assert!(write_atomic(&path, "text").is_err());
        assert!(!path.exists());
    }
}
