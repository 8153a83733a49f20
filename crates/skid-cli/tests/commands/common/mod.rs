//! What several test files share: the `skid` binary, the shipped cases and the bad-input
//! corpus (`cases/bad/`, see its README).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use serde_json::Value;

/// The `skid` binary of this build.
pub fn skid() -> Command {
    Command::new(env!("CARGO_BIN_EXE_skid"))
}

/// Runs `command` and returns its output; panics with its standard error unless it succeeded.
pub fn succeeds(command: &mut Command) -> Output {
    let out = command.output().expect("skid starts");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// A file under the repository's `cases/`.
pub fn shipped(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../cases")
        .join(relative)
}

/// One entry of the corpus, read from its `.expect` file.
pub struct Entry {
    /// The `.expect` file.
    pub expect: PathBuf,
    /// The file to run.
    pub case: PathBuf,
    /// The `--set` overrides to pass.
    pub overrides: Vec<String>,
    /// Fragments the message must contain.
    pub messages: Vec<String>,
}

/// The corpus directory.
pub fn corpus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../cases/bad")
}

/// Reads one `.expect` file.
pub fn read_entry(expect: &Path) -> Entry {
    let text = std::fs::read_to_string(expect).expect("expect file");
    let dir = expect.parent().expect("directory");
    let mut case = expect.with_extension("json");
    let (mut overrides, mut messages) = (Vec::new(), Vec::new());
    for line in text
        .lines()
        .filter(|l| !l.is_empty() && !l.starts_with('#'))
    {
        match line.split_once(": ") {
            Some(("case", file)) => case = dir.join(file),
            Some(("set", spec)) => overrides.push(spec.to_string()),
            Some(("message", fragment)) => messages.push(fragment.to_string()),
            _ => panic!("{}: unreadable line {line:?}", expect.display()),
        }
    }
    assert!(!messages.is_empty(), "{}: no message", expect.display());
    Entry {
        expect: expect.to_path_buf(),
        case,
        overrides,
        messages,
    }
}

/// The corpus files with `extension`, sorted.
pub fn files_with(extension: &str) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(corpus())
        .expect("cases/bad")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == extension))
        .collect();
    files.sort();
    files
}

/// Every entry of the corpus.
pub fn entries() -> Vec<Entry> {
    files_with("expect").iter().map(|p| read_entry(p)).collect()
}

/// Keys of `summary.json` (at any depth, the per-step costs included) and `batch.json` that
/// hold wall times or the process's peak memory, which vary from run to run.
pub const TIMING_KEYS: [&str; 7] = [
    "wall_time_s",
    "assembly_s",
    "linear_solve_s",
    "factorization_s",
    "contact_solve_s",
    "output_s",
    "peak_memory_mb",
];

/// `value` without its [`TIMING_KEYS`], at any depth; panics if it held none of them, so that a
/// renamed timing field cannot make the comparison fail for the wrong reason or pass unseen.
pub fn without_timings(mut value: Value) -> Value {
    fn strip(value: &mut Value, removed: &mut usize) {
        match value {
            Value::Object(map) => {
                for key in TIMING_KEYS {
                    if map.remove(key).is_some() {
                        *removed += 1;
                    }
                }
                map.values_mut().for_each(|v| strip(v, removed));
            }
            Value::Array(items) => items.iter_mut().for_each(|v| strip(v, removed)),
            _ => {}
        }
    }
    let mut removed = 0;
    strip(&mut value, &mut removed);
    assert!(removed > 0, "no timing field found in {value}");
    value
}
