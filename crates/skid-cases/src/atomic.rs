//! Output files that are complete or absent: a file `<name>` is written as `<name>.partial`,
//! flushed to disk, and renamed to `<name>`. A rename within a directory replaces the target in
//! one step, so a reader sees the earlier file or the whole new one, and a process interrupted
//! while writing leaves only the `.partial` sibling.

use std::io::Write;
use std::path::{Path, PathBuf};

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
