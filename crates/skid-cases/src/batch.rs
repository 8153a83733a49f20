//! Running many case files, model files and input decks in parallel, each into
//! `<out>/<name>/`, and recording the outcome of every one in `<out>/batch.json`.
//!
//! A sweep file ([`crate::sweep`]) contributes one run per combination of its parameters, each
//! with its `parameters.json` beside its outputs. A batch may run one [`Shard`] of its runs:
//! the runs are numbered in input order (a sweep's in its order) and shard `I` of `N` takes
//! those whose position is `I - 1` modulo `N`, so that `N` shards started alike run every run
//! once between them.
//!
//! A case that cannot be read or built, or whose run stops early, is recorded as such and does
//! not stop the others.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;

use crate::atomic::{write_atomic, write_json_atomic};
use crate::deck::is_deck;
use crate::model_file::parse_model;
use crate::model_spec::{ModelSpec, declares_model};
use crate::runner::{RunSummary, run_case, run_model};
use crate::scene::read_deck_model;
use crate::schema::Case;
use crate::sweep::{SweepRun, declares_sweep, load_sweep};
use crate::validate::load_case;

/// The parameters of a sweep run, written into its output directory.
pub const PARAMETERS_JSON: &str = "parameters.json";

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
    /// The sweep run this is, with its parameters (absent for a file run as it is).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sweep: Option<SweepRun>,
    /// Wall time spent on the case (loading, building, running, writing), s.
    pub wall_time_s: f64,
}

/// The part of a batch one invocation runs: shard `index` (from 1) of `count`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    /// Which shard, from 1 to `count`.
    pub index: usize,
    /// How many shards the runs are dealt into.
    pub count: usize,
}

impl Shard {
    /// The whole batch: shard 1 of 1.
    pub const ALL: Shard = Shard { index: 1, count: 1 };

    /// Shard `index` of `count`.
    ///
    /// # Errors
    /// What was expected, unless `1 <= index <= count`.
    pub fn new(index: usize, count: usize) -> Result<Self, String> {
        if count == 0 || index == 0 || index > count {
            return Err(format!(
                "expected a shard I/N with 1 <= I <= N, got {index}/{count}"
            ));
        }
        Ok(Self { index, count })
    }

    /// Reads `I/N`, e.g. `2/3`.
    ///
    /// # Errors
    /// What was expected.
    pub fn parse(text: &str) -> Result<Self, String> {
        let expected = || format!("expected I/N (shard I of N, from 1), e.g. 2/3, got {text:?}");
        let (index, count) = text.split_once('/').ok_or_else(expected)?;
        let number = |s: &str| s.trim().parse::<usize>().map_err(|_| expected());
        Self::new(number(index)?, number(count)?)
    }

    /// The shard of a Slurm job array task, from the variables Slurm sets
    /// (`SLURM_ARRAY_TASK_ID`, `SLURM_ARRAY_TASK_MIN`, `SLURM_ARRAY_TASK_MAX`,
    /// `SLURM_ARRAY_TASK_COUNT`, read through `var`): task `MIN` is shard 1. The array must be
    /// contiguous (`--array=A-B`, any `A`).
    ///
    /// # Errors
    /// Which variable is missing or not a number, or that the array is not contiguous.
    pub fn from_slurm(var: impl Fn(&str) -> Option<String>) -> Result<Self, String> {
        let read = |name: &str| -> Result<usize, String> {
            let text = var(name).ok_or_else(|| {
                format!("--shard slurm: {name} is not set (is this a Slurm job array task?)")
            })?;
            text.trim()
                .parse()
                .map_err(|_| format!("--shard slurm: {name}: expected a number, got {text:?}"))
        };
        let (id, min, max, count) = (
            read("SLURM_ARRAY_TASK_ID")?,
            read("SLURM_ARRAY_TASK_MIN")?,
            read("SLURM_ARRAY_TASK_MAX")?,
            read("SLURM_ARRAY_TASK_COUNT")?,
        );
        if max < min || max - min + 1 != count || id < min || id > max {
            return Err(format!(
                "--shard slurm: expected a contiguous job array (--array=A-B), got tasks                  {min}..{max} counting {count}, this one {id}"
            ));
        }
        Self::new(id - min + 1, count)
    }

    /// Whether the run at `position` (from 0, over the whole batch) belongs to this shard.
    pub fn takes(self, position: usize) -> bool {
        position % self.count == self.index - 1
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
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

/// One run of a batch: the file it runs, its input (or why it cannot run), and the sweep run
/// it is, if any.
struct Job {
    file: PathBuf,
    loaded: Loaded,
    sweep: Option<SweepRun>,
}

fn error_entry(
    file: &Path,
    name: String,
    error: String,
    sweep: Option<SweepRun>,
    started: Instant,
) -> BatchEntry {
    BatchEntry {
        case_file: file.to_path_buf(),
        name,
        status: BatchStatus::Error,
        summary: None,
        notes: Vec::new(),
        error: Some(error),
        sweep,
        wall_time_s: started.elapsed().as_secs_f64(),
    }
}

/// Reads a deck, a model file (JSON declaring `skid_model`) or a case file, with `overrides`.
fn load(file: &Path, overrides: &[String]) -> Result<Input, String> {
    if is_deck(file) {
        return read_deck_model(file, overrides)
            .map(|(spec, notes)| Input::Model(spec, notes))
            .map_err(|e| e.to_string());
    }
    if let Ok(text) = std::fs::read_to_string(file)
        && declares_model(&text)
    {
        return parse_model(&text, file, overrides)
            .map(|spec| Input::Model(spec, Vec::new()))
            .map_err(|e| e.to_string());
    }
    load_case(file, overrides)
        .map(Input::Case)
        .map_err(|e| e.to_string())
}

/// The name of a file that could not be read: its stem.
fn stem(file: &Path) -> String {
    file.file_stem().map_or_else(
        || file.display().to_string(),
        |s| s.to_string_lossy().into(),
    )
}

/// Loads every file, a sweep file as its runs (its base with each run's overrides); a run
/// whose name an earlier one already uses cannot run (both would write the same output
/// directory).
fn load_all(files: &[PathBuf]) -> Vec<Job> {
    let mut jobs = Vec::new();
    for file in files {
        let started = Instant::now();
        let is_sweep =
            !is_deck(file) && std::fs::read_to_string(file).is_ok_and(|text| declares_sweep(&text));
        if !is_sweep {
            let loaded =
                load(file, &[]).map_err(|e| error_entry(file, stem(file), e, None, started));
            jobs.push(Job {
                file: file.clone(),
                loaded,
                sweep: None,
            });
            continue;
        }
        match load_sweep(file) {
            Err(e) => jobs.push(Job {
                file: file.clone(),
                loaded: Err(error_entry(file, stem(file), e.to_string(), None, started)),
                sweep: None,
            }),
            Ok(sweep) => {
                for run in sweep.runs {
                    let started = Instant::now();
                    let overrides: Vec<String> = sweep
                        .spec
                        .set
                        .iter()
                        .cloned()
                        .chain(run.overrides())
                        .collect();
                    let loaded = load(&sweep.base, &overrides).map_err(|e| {
                        error_entry(&sweep.base, run.name.clone(), e, Some(run.clone()), started)
                    });
                    jobs.push(Job {
                        file: sweep.base.clone(),
                        loaded,
                        sweep: Some(run),
                    });
                }
            }
        }
    }
    let mut owners: HashMap<String, PathBuf> = HashMap::new();
    for job in &mut jobs {
        let Ok(input) = &job.loaded else { continue };
        let name = input.name().to_string();
        let source = job
            .sweep
            .as_ref()
            .map_or_else(|| job.file.clone(), |run| run.file.clone());
        if let Some(owner) = owners.get(&name) {
            let message = format!("name '{name}' is already used by {}", owner.display());
            job.loaded = Err(error_entry(
                &job.file,
                name,
                message,
                job.sweep.clone(),
                Instant::now(),
            ));
        } else {
            owners.insert(name, source);
        }
    }
    jobs
}

/// Runs one loaded input into `<out>/<name>/`, a sweep run with its `parameters.json`.
fn run_one(file: &Path, input: &Input, sweep: Option<&SweepRun>, out: &Path) -> BatchEntry {
    let started = Instant::now();
    let name = input.name().to_string();
    let dir = out.join(&name);
    if let Some(run) = sweep {
        let path = dir.join(PARAMETERS_JSON);
        let written = std::fs::create_dir_all(&dir).and_then(|()| write_json_atomic(&path, run));
        if let Err(e) = written {
            let message = format!("{}: cannot write: {e}", path.display());
            return error_entry(file, name, message, Some(run.clone()), started);
        }
    }
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
                sweep: sweep.cloned(),
                wall_time_s: started.elapsed().as_secs_f64(),
            }
        }
        Err(e) => error_entry(file, name, e.to_string(), sweep.cloned(), started),
    }
}

/// Runs the runs of `files` that belong to `shard` on a pool of `jobs` threads (0: one per
/// core), each into `<out>/<name>/`, calls `progress` with the entry and the number of runs of
/// the shard as each run ends, and writes `<out>/batch.json` listing them.
///
/// Returns the entries in the order of `files` (a sweep's runs in its order).
///
/// # Errors
/// [`BatchError`] if the thread pool cannot start or `out`/`batch.json` cannot be written; a
/// failing case is an entry with status `error` or `failed`, not an error.
pub fn run_batch(
    files: &[PathBuf],
    out: &Path,
    jobs: usize,
    shard: Shard,
    progress: impl Fn(&BatchEntry, usize) + Sync,
) -> Result<Vec<BatchEntry>, BatchError> {
    std::fs::create_dir_all(out).map_err(|source| BatchError::Output {
        path: out.to_path_buf(),
        source,
    })?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs)
        .build()
        .map_err(|source| BatchError::Pool { jobs, source })?;
    let loaded: Vec<Job> = load_all(files)
        .into_iter()
        .enumerate()
        .filter(|(position, _)| shard.takes(*position))
        .map(|(_, job)| job)
        .collect();
    let total = loaded.len();
    let entries: Vec<BatchEntry> = pool.install(|| {
        loaded
            .par_iter()
            .map(|job| {
                let entry = match &job.loaded {
                    Ok(input) => run_one(&job.file, input, job.sweep.as_ref(), out),
                    Err(entry) => entry.clone(),
                };
                progress(&entry, total);
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
        assert!(loaded[0].loaded.is_ok());
        let duplicate = loaded[1].loaded.as_ref().expect_err("same name as a.json");
        assert_eq!(duplicate.status, BatchStatus::Error);
        assert!(
            duplicate
                .error
                .as_deref()
                .is_some_and(|e| e.contains("a.json"))
        );
        let malformed = loaded[2].loaded.as_ref().expect_err("malformed");
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
        // on one-point elements the pad folds under this load (the case runs it on CPE4)
        let reduced = r#"pad.formulation="reduced""#.to_string();
        let folds = r#"expect.failure="inverted_element""#.to_string();
        let overrides = [reduced.clone(), folds];
        let case = crate::validate::parse_case(text, file, &overrides).expect("valid case");
        let entry = run_one(file, &Input::Case(case), None, dir.path());
        assert_eq!(entry.status, BatchStatus::FailedAsExpected, "{entry:?}");
        assert!(entry.status.as_expected());
        let other = r#"expect.failure="newton_not_converged""#.to_string();
        let case = crate::validate::parse_case(text, file, &[reduced, other]).expect("valid case");
        let entry = run_one(file, &Input::Case(case), None, dir.path());
        assert_eq!(entry.status, BatchStatus::Failed, "{entry:?}");
        assert!(!entry.status.as_expected());
    }

    #[test]
    fn shards_deal_every_run_to_exactly_one_of_them() {
        let shards: Vec<Shard> = (1..=3).map(|i| Shard::new(i, 3).expect("shard")).collect();
        for position in 0..14 {
            let owners = shards.iter().filter(|s| s.takes(position)).count();
            assert_eq!(owners, 1, "position {position}");
        }
        assert!(shards[1].takes(1) && shards[1].takes(4));
        assert!(Shard::ALL.takes(0) && Shard::ALL.takes(7));
    }

    #[test]
    fn shards_are_read_as_i_of_n_from_1() {
        assert_eq!(Shard::parse("2/3"), Ok(Shard { index: 2, count: 3 }));
        assert_eq!(Shard::parse("2/3").map(|s| s.to_string()), Ok("2/3".into()));
        for bad in ["0/3", "4/3", "1/0", "3", "a/3", "1/b", ""] {
            let e = Shard::parse(bad).expect_err(bad);
            assert!(e.contains("expected"), "{bad}: {e}");
        }
    }

    #[test]
    fn a_slurm_array_task_is_its_shard_counted_from_the_first_task() {
        let env = |vars: &'static [(&'static str, &'static str)]| {
            move |name: &str| {
                vars.iter()
                    .find(|(n, _)| *n == name)
                    .map(|(_, v)| (*v).to_string())
            }
        };
        let zero_based = env(&[
            ("SLURM_ARRAY_TASK_ID", "0"),
            ("SLURM_ARRAY_TASK_MIN", "0"),
            ("SLURM_ARRAY_TASK_MAX", "2"),
            ("SLURM_ARRAY_TASK_COUNT", "3"),
        ]);
        assert_eq!(
            Shard::from_slurm(zero_based),
            Ok(Shard { index: 1, count: 3 })
        );
        let one_based = env(&[
            ("SLURM_ARRAY_TASK_ID", "3"),
            ("SLURM_ARRAY_TASK_MIN", "1"),
            ("SLURM_ARRAY_TASK_MAX", "3"),
            ("SLURM_ARRAY_TASK_COUNT", "3"),
        ]);
        assert_eq!(
            Shard::from_slurm(one_based),
            Ok(Shard { index: 3, count: 3 })
        );
        let stepped = env(&[
            ("SLURM_ARRAY_TASK_ID", "2"),
            ("SLURM_ARRAY_TASK_MIN", "0"),
            ("SLURM_ARRAY_TASK_MAX", "4"),
            ("SLURM_ARRAY_TASK_COUNT", "3"),
        ]);
        assert!(Shard::from_slurm(stepped).is_err_and(|e| e.contains("contiguous")));
        let outside = env(&[]);
        assert!(
            Shard::from_slurm(outside).is_err_and(|e| e.contains("SLURM_ARRAY_TASK_ID is not set"))
        );
    }

    #[test]
    fn a_sweep_file_contributes_its_runs_each_with_its_overrides() {
        let dir = tempfile::tempdir().expect("tempdir");
        let base = dir.path().join("base.json");
        std::fs::write(&base, include_str!("../../../cases/drum/2d-analytic.json")).expect("write");
        let sweep = dir.path().join("mu.json");
        std::fs::write(
            &sweep,
            r#"{"skid_sweep": 1, "name": "mu", "base": "base.json",
                "set": ["drum.omega0=3"],
                "parameters": [{"field": "contact.mu", "values": [0.1, -1, 0.3]}]}"#,
        )
        .expect("write");
        let jobs = load_all(&[sweep.clone(), base.clone()]);
        assert_eq!(jobs.len(), 4);
        let Ok(Input::Case(first)) = &jobs[0].loaded else {
            panic!("the first run loads")
        };
        assert_eq!(
            (first.name.as_str(), first.contact.mu, first.drum.omega0),
            ("mu-1", 0.1, 3.0)
        );
        let negative = jobs[1].loaded.as_ref().expect_err("mu = -1 is refused");
        assert_eq!(negative.name, "mu-2");
        assert!(
            negative
                .error
                .as_deref()
                .is_some_and(|e| e.contains("contact.mu"))
        );
        assert_eq!(negative.sweep.as_ref().map(|r| r.index), Some(2));
        assert!(jobs[2].loaded.is_ok());
        assert!(jobs[3].sweep.is_none() && jobs[3].loaded.is_ok());
    }
}
