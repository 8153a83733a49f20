//! Running many case files, model files and input decks in parallel, each into
//! `<out>/<name>/`, and recording the outcome of every one in `<out>/batch.json`.
//!
//! A case that cannot be read or built, or whose run stops early, is recorded as such and does
//! not stop the others.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;

use crate::atomic::write_atomic;
use crate::deck::is_deck;
use crate::model_file::{ModelSpec, declares_model, parse_model};
use crate::runner::{RunSummary, read_deck_model, run_case, run_model};
use crate::schema::Case;
use crate::validate::load_case;

/// How one case of a batch ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BatchStatus {
    /// The run reached the end of its last step.
    Completed,
    /// The run stopped early with the failure its case expects (`expect.failure`); its
    /// summary says where and why.
    FailedAsExpected,
    /// The run started but stopped early; its summary says where and why.
    Failed,
    /// The case could not be run: unreadable or invalid file, model or output error.
    Error,
}

impl BatchStatus {
    /// Whether the case ended as its file says it should: completed, or stopped with the
    /// failure it expects.
    pub fn as_expected(self) -> bool {
        matches!(self, Self::Completed | Self::FailedAsExpected)
    }

    /// The name used in `batch.json` and in listings.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Completed => "completed",
            Self::FailedAsExpected => "failed_as_expected",
            Self::Failed => "failed",
            Self::Error => "error",
        }
    }
}

/// One case of a batch: an element of `batch.json`.
#[derive(Clone, Debug, Serialize)]
pub struct BatchEntry {
    /// The case file.
    pub case_file: PathBuf,
    /// The case name (the file stem if the file could not be read).
    pub name: String,
    /// How it ended.
    pub status: BatchStatus,
    /// The run summary, if the run started.
    pub summary: Option<RunSummary>,
    /// What skid read differently from a deck's requests (empty for JSON files).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
    /// Why the case could not be run, or why the run stopped early.
    pub error: Option<String>,
    /// Wall time spent on the case (loading, building, running, writing), s.
    pub wall_time_s: f64,
}

/// Errors that stop a whole batch (a single case's failure does not).
#[derive(Debug, thiserror::Error)]
pub enum BatchError {
    /// A directory given as input could not be listed.
    #[error("{path}: cannot list the directory: {source}")]
    List {
        /// The directory.
        path: PathBuf,
        /// Cause.
        source: std::io::Error,
    },
    /// No case file was found in the inputs.
    #[error("no case files, model files or decks (*.json, *.inp) in {0}")]
    NoCases(String),
    /// The worker threads could not be started.
    #[error("cannot start {jobs} worker threads: {source}")]
    Pool {
        /// Requested threads.
        jobs: usize,
        /// Cause.
        source: rayon::ThreadPoolBuildError,
    },
    /// `batch.json` or the output directory could not be written.
    #[error("{path}: cannot write: {source}")]
    Output {
        /// File or directory.
        path: PathBuf,
        /// Cause.
        source: std::io::Error,
    },
}

/// Expands `paths` into input files: a file is taken as is, a directory contributes its
/// `*.json` and `*.inp` files sorted by name.
///
/// # Errors
/// [`BatchError::List`] for a directory that cannot be read, [`BatchError::NoCases`] if nothing
/// is left.
pub fn collect_case_files(paths: &[PathBuf]) -> Result<Vec<PathBuf>, BatchError> {
    let mut files = Vec::new();
    for path in paths {
        if path.is_dir() {
            let list = |source| BatchError::List {
                path: path.clone(),
                source,
            };
            let mut found = Vec::new();
            for entry in std::fs::read_dir(path).map_err(list)? {
                let file = entry.map_err(list)?.path();
                if file.is_file()
                    && (file.extension().is_some_and(|e| e == "json") || is_deck(&file))
                {
                    found.push(file);
                }
            }
            found.sort();
            files.extend(found);
        } else {
            files.push(path.clone());
        }
    }
    if files.is_empty() {
        let names: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
        return Err(BatchError::NoCases(names.join(", ")));
    }
    Ok(files)
}

/// A file after loading: what it runs, with its name and notes.
#[derive(Clone, Debug)]
enum Input {
    /// A drum case file.
    Case(Case),
    /// A model file or a deck, read into a model.
    Model(ModelSpec, Vec<String>),
}

impl Input {
    fn name(&self) -> &str {
        match self {
            Self::Case(case) => &case.name,
            Self::Model(spec, _) => &spec.name,
        }
    }
}

/// A file after loading: its input, or the entry recording why it cannot run.
type Loaded = Result<Input, BatchEntry>;

fn error_entry(file: &Path, name: String, error: String, started: Instant) -> BatchEntry {
    BatchEntry {
        case_file: file.to_path_buf(),
        name,
        status: BatchStatus::Error,
        summary: None,
        notes: Vec::new(),
        error: Some(error),
        wall_time_s: started.elapsed().as_secs_f64(),
    }
}

/// Reads a deck, a model file (JSON declaring `skid_model`) or a case file.
fn load(file: &Path) -> Result<Input, String> {
    if is_deck(file) {
        return read_deck_model(file, &[])
            .map(|(spec, notes)| Input::Model(spec, notes))
            .map_err(|e| e.to_string());
    }
    if let Ok(text) = std::fs::read_to_string(file)
        && declares_model(&text)
    {
        return parse_model(&text, file, &[])
            .map(|spec| Input::Model(spec, Vec::new()))
            .map_err(|e| e.to_string());
    }
    load_case(file, &[])
        .map(Input::Case)
        .map_err(|e| e.to_string())
}

/// Loads every file; one whose name an earlier file already uses cannot run (both would write
/// the same output directory).
fn load_all(files: &[PathBuf]) -> Vec<(PathBuf, Loaded)> {
    let mut owners: HashMap<String, PathBuf> = HashMap::new();
    files
        .iter()
        .map(|file| {
            let started = Instant::now();
            let stem = file.file_stem().map_or_else(
                || file.display().to_string(),
                |s| s.to_string_lossy().into(),
            );
            let loaded = match load(file) {
                Err(e) => Err(error_entry(file, stem, e, started)),
                Ok(input) => match owners.get(input.name()) {
                    Some(owner) => {
                        let message = format!(
                            "name '{}' is already used by {}",
                            input.name(),
                            owner.display()
                        );
                        Err(error_entry(
                            file,
                            input.name().to_string(),
                            message,
                            started,
                        ))
                    }
                    None => {
                        owners.insert(input.name().to_string(), file.clone());
                        Ok(input)
                    }
                },
            };
            (file.clone(), loaded)
        })
        .collect()
}

fn run_one(file: &Path, input: &Input, out: &Path) -> BatchEntry {
    let started = Instant::now();
    let name = input.name().to_string();
    let dir = out.join(&name);
    let (result, expected, notes) = match input {
        Input::Case(case) => (
            run_case(case, file, &dir).map(RunSummary::Case),
            case.expect.failure,
            Vec::new(),
        ),
        Input::Model(spec, notes) => (
            run_model(spec, file, &dir).map(RunSummary::Model),
            None,
            notes.clone(),
        ),
    };
    match result {
        Ok(summary) => {
            let failure = match &summary {
                RunSummary::Case(s) => s.failure.clone(),
                RunSummary::Model(s) => s.failure.clone(),
            };
            BatchEntry {
                case_file: file.to_path_buf(),
                name,
                status: match (summary.error(), expected) {
                    (None, _) => BatchStatus::Completed,
                    (Some(_), Some(expected)) if expected.matches(failure.as_deref()) => {
                        BatchStatus::FailedAsExpected
                    }
                    (Some(_), _) => BatchStatus::Failed,
                },
                error: summary.error().map(str::to_string),
                summary: Some(summary),
                notes,
                wall_time_s: started.elapsed().as_secs_f64(),
            }
        }
        Err(e) => error_entry(file, name, e.to_string(), started),
    }
}

/// Runs every file on a pool of `jobs` threads (0: one per core), each into `<out>/<name>/`, calls `progress` as each case ends, and writes `<out>/batch.json`.
///
/// Returns the entries in the order of `files`.
///
/// # Errors
/// [`BatchError`] if the thread pool cannot start or `out`/`batch.json` cannot be written; a
/// failing case is an entry with status `error` or `failed`, not an error.
pub fn run_batch(
    files: &[PathBuf],
    out: &Path,
    jobs: usize,
    progress: impl Fn(&BatchEntry) + Sync,
) -> Result<Vec<BatchEntry>, BatchError> {
    std::fs::create_dir_all(out).map_err(|source| BatchError::Output {
        path: out.to_path_buf(),
        source,
    })?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs)
        .build()
        .map_err(|source| BatchError::Pool { jobs, source })?;
    let loaded = load_all(files);
    let entries: Vec<BatchEntry> = pool.install(|| {
        loaded
            .par_iter()
            .map(|(file, loaded)| {
                let entry = match loaded {
                    Ok(input) => run_one(file, input, out),
                    Err(entry) => entry.clone(),
                };
                progress(&entry);
                entry
            })
            .collect()
    });
    let path = out.join("batch.json");
    let text = serde_json::to_string_pretty(&entries).map_err(|e| BatchError::Output {
        path: path.clone(),
        source: e.into(),
    })?;
    write_atomic(&path, &text).map_err(|source| BatchError::Output { path, source })?;
    Ok(entries)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn directories_contribute_their_json_files_sorted_and_files_are_kept() {
        let dir = tempfile::tempdir().expect("tempdir");
        for name in ["b.json", "a.json", "notes.txt"] {
            std::fs::write(dir.path().join(name), "{}").expect("write");
        }
        let extra = PathBuf::from("elsewhere/c.json");
        let files =
            collect_case_files(&[dir.path().to_path_buf(), extra.clone()]).expect("collects");
        assert_eq!(
            files,
            vec![dir.path().join("a.json"), dir.path().join("b.json"), extra]
        );
    }

    #[test]
    fn an_empty_directory_is_an_error_naming_it() {
        let dir = tempfile::tempdir().expect("tempdir");
        let e = collect_case_files(&[dir.path().to_path_buf()]).expect_err("nothing to run");
        assert!(e.to_string().contains(&dir.path().display().to_string()));
    }

    #[test]
    fn bad_and_duplicate_cases_are_entries_and_do_not_stop_the_others() {
        let dir = tempfile::tempdir().expect("tempdir");
        let good = include_str!("../../../cases/drum/2d-analytic.json");
        let (a, b, bad) = (
            dir.path().join("a.json"),
            dir.path().join("b.json"),
            dir.path().join("bad.json"),
        );
        std::fs::write(&a, good).expect("write");
        std::fs::write(&b, good).expect("write");
        std::fs::write(&bad, "{ not json").expect("write");
        let loaded = load_all(&[a.clone(), b.clone(), bad.clone()]);
        assert!(loaded[0].1.is_ok());
        let duplicate = loaded[1].1.as_ref().expect_err("same name as a.json");
        assert_eq!(duplicate.status, BatchStatus::Error);
        assert!(
            duplicate
                .error
                .as_deref()
                .is_some_and(|e| e.contains("a.json"))
        );
        let malformed = loaded[2].1.as_ref().expect_err("malformed");
        assert_eq!(malformed.name, "bad");
        assert!(
            malformed
                .error
                .as_deref()
                .is_some_and(|e| e.contains("bad.json"))
        );
    }

    #[test]
    fn a_run_that_stops_with_the_failure_its_case_expects_is_failed_as_expected() {
        let dir = tempfile::tempdir().expect("tempdir");
        let text = include_str!("../../../cases/hard/2d-pressure-x10.json");
        let file = Path::new("2d-pressure-x10.json");
        let case = crate::validate::parse_case(text, file, &[]).expect("valid case");
        let entry = run_one(file, &Input::Case(case), dir.path());
        assert_eq!(entry.status, BatchStatus::FailedAsExpected, "{entry:?}");
        assert!(entry.status.as_expected());
        let other = r#"expect.failure="newton_not_converged""#.to_string();
        let case = crate::validate::parse_case(text, file, &[other]).expect("valid case");
        let entry = run_one(file, &Input::Case(case), dir.path());
        assert_eq!(entry.status, BatchStatus::Failed, "{entry:?}");
        assert!(!entry.status.as_expected());
    }
}
