//! Runs one case: builds the scene, integrates it, writes `case.json` (the case as run, overrides
//! applied), `history.csv`, `newton.csv`, `summary.json` and, if the case asks for it, the
//! ParaView field output in `fields/`. A model file runs the same way with its own outputs:
//! `model.json` (the model as run), the generic `history.csv` and `summary.json` of
//! [`crate::model_file`], and `newton.csv`.
//!
//! Each output is complete or absent: those of an earlier run in the directory are removed
//! before the run, and each file appears under its name only when written whole
//! ([`crate::atomic`], [`crate::csv_out`]); `summary.json` is written last, when the run has
//! ended.
//!
//! A run also writes its restart file `restart.json` every few increments and at the end of
//! each step ([`crate::restart`]); [`resume_run`] continues an interrupted run from it, in the
//! same directory, to the same outputs.

use std::path::{Path, PathBuf};

use skid_integrator::stepper::{
    Checkpoint, IncrementReport, Observer, RejectionReport, RunStatistics, resume, run,
};
use skid_integrator::{Model, RunError, State};

use serde::Serialize;

use crate::append_file::FileMark;
use crate::atomic::{json_text, write_atomic, write_json_atomic};
use crate::deck::is_deck;
use crate::fields::{self, FieldMemory, FieldWriter};
use crate::fingerprint::Fnv1a;
use crate::history::{DrumRecorder, SAMPLES_JOURNAL, SampleJournal};
use crate::model_file::contact_nodes;
use crate::model_file::history::{ModelRecorder, NodeColumns, ReactionColumns};
use crate::model_file::summary::{ModelSummary, summarize as summarize_model};
use crate::model_file::{self};
use crate::model_spec::{ModelSpec, declares_model};
use crate::newton::{NEWTON_CSV, NewtonRecorder};
use crate::restart::{
    DEFAULT_RESTART_EVERY, InputIdentity, RESTART_JSON, RecorderMemory, RestartFile,
};
use crate::scene::{case_scene, model_scene, read_deck_model};
use crate::schema::Case;
use crate::summary::{Summary, summarize};
use crate::validate::{CaseError, load_case, parse_case};

/// The case as run (overrides applied), written into the output directory.
pub const CASE_JSON: &str = "case.json";
/// The model as run (overrides applied), written into the output directory.
pub const MODEL_JSON: &str = "model.json";

/// The summary of a run of a case file or of a model file.
#[derive(Clone, Debug, Serialize, PartialEq)]
#[serde(untagged)]
pub enum RunSummary {
    /// A drum case.
    Case(Summary),
    /// A model file.
    Model(ModelSummary),
}

impl RunSummary {
    /// Why the run stopped early, if it did.
    pub fn error(&self) -> Option<&str> {
        match self {
            Self::Case(s) => s.error.as_deref(),
            Self::Model(s) => s.error.as_deref(),
        }
    }

    /// What a user should know before trusting the run.
    pub fn warnings(&self) -> &[String] {
        match self {
            Self::Case(s) => &s.warnings,
            Self::Model(s) => &s.warnings,
        }
    }
}

/// An input read for a run: a drum case, or a model (from a model file or a deck, with the
/// notes on what skid reads differently from the deck's requests).
enum Input {
    Case(Box<Case>),
    Model(Box<ModelSpec>, Vec<String>),
}

impl Input {
    /// Reads a case file, a model file (one that declares `skid_model`) or a deck, with
    /// `overrides`.
    fn read(path: &Path, overrides: &[String]) -> Result<Self, CaseError> {
        if is_deck(path) {
            let (spec, notes) = read_deck_model(path, overrides)?;
            return Ok(Self::Model(Box::new(spec), notes));
        }
        // Text that is not a model file (or not text: the case reader names the bad byte's
        // line) is read as a case file.
        match std::fs::read_to_string(path) {
            Ok(text) if declares_model(&text) => Ok(Self::Model(
                Box::new(model_file::parse_model(&text, path, overrides)?),
                Vec::new(),
            )),
            Err(source) if source.kind() != std::io::ErrorKind::InvalidData => {
                Err(CaseError::Read {
                    path: path.to_path_buf(),
                    source,
                })
            }
            _ => Ok(Self::Case(Box::new(load_case(path, overrides)?))),
        }
    }

    /// The file the input is written to in the output directory, and its text there.
    ///
    /// # Errors
    /// The serializer's, should the input not serialize.
    fn as_run(&self) -> serde_json::Result<(&'static str, String)> {
        Ok(match self {
            Self::Case(case) => (CASE_JSON, json_text(case)?),
            Self::Model(spec, _) => (MODEL_JSON, model_file::to_json(spec)?),
        })
    }
}

/// Runs a case file, a model file (one that declares `skid_model`) or a deck into `out_dir`
/// (default `out/<name>`), writing a restart file every `restart_every` converged increments
/// (0: none; see [`crate::restart`]).
///
/// # Errors
/// See [`run_case_file`].
pub fn run_file(
    path: &Path,
    overrides: &[String],
    out_dir: Option<&Path>,
    restart_every: usize,
) -> Result<RunSummary, CaseError> {
    match Input::read(path, overrides)? {
        Input::Model(spec, notes) => {
            let dir = out_dir.map_or_else(|| Path::new("out").join(&spec.name), Path::to_path_buf);
            let summary = run_model_with(&spec, path, &dir, restart_every)?;
            for note in &notes {
                eprintln!("skid: note: {note}");
            }
            Ok(RunSummary::Model(summary))
        }
        Input::Case(case) => {
            let dir = out_dir.map_or_else(|| default_output_dir(&case), Path::to_path_buf);
            run_case_with(&case, path, &dir, restart_every).map(RunSummary::Case)
        }
    }
}

/// How [`resume_run`] found the run directory.
#[derive(Debug)]
pub enum Resumed {
    /// The run was continued to its end; its summary.
    Continued(Box<RunSummary>),
    /// The run had already ended: its `summary.json`, untouched.
    AlreadyEnded(serde_json::Value),
}

/// Continues the interrupted run in `dir` from its restart file ([`crate::restart`]) with the
/// input as run stored beside it (`case.json` or `model.json`), to the outputs the
/// uninterrupted run writes. With `input` (a file and its overrides), that input must be the
/// one the run was started with. The restart interval is `restart_every`, or the run's own.
/// A run that has ended (its `summary.json` written) is not run again:
/// [`Resumed::AlreadyEnded`].
///
/// # Errors
/// [`CaseError::Resume`] if `dir` holds no run, no restart file, or one that does not fit the
/// input as run (changed since, or another input given); [`CaseError::Output`] as for a run.
pub fn resume_run(
    dir: &Path,
    input: Option<(&Path, &[String])>,
    restart_every: Option<usize>,
) -> Result<Resumed, CaseError> {
    let refuse = |message: String| CaseError::Resume {
        dir: dir.to_path_buf(),
        message,
    };
    if !dir.is_dir() {
        return Err(refuse("no such directory".into()));
    }
    let found: Vec<&str> = [CASE_JSON, MODEL_JSON]
        .into_iter()
        .filter(|f| dir.join(f).is_file())
        .collect();
    let [file] = found[..] else {
        return Err(refuse(format!(
            "expected the input as run, {CASE_JSON} or {MODEL_JSON} (one of them), found {}",
            if found.is_empty() { "neither" } else { "both" }
        )));
    };
    let source = dir.join(file);
    let text = std::fs::read_to_string(&source).map_err(|e| CaseError::Read {
        path: source.clone(),
        source: e,
    })?;
    if let Some((path, overrides)) = input {
        let (given_file, given_text) = Input::read(path, overrides)?
            .as_run()
            .map_err(|e| refuse(format!("{}: cannot be written back: {e}", path.display())))?;
        if given_file != file || given_text != text {
            return Err(refuse(format!(
                "{} (with its --set overrides) is not the input this run was started with \
                 ({file}); resume without naming the input, or run it afresh elsewhere",
                path.display()
            )));
        }
    }
    let summary_path = dir.join("summary.json");
    if summary_path.exists() {
        let text = std::fs::read_to_string(&summary_path).map_err(|source| CaseError::Read {
            path: summary_path.clone(),
            source,
        })?;
        let summary = serde_json::from_str(&text)
            .map_err(|e| refuse(format!("summary.json is not JSON: {e}")))?;
        return Ok(Resumed::AlreadyEnded(summary));
    }
    let restart = RestartFile::read(dir).map_err(refuse)?;
    let identity = InputIdentity {
        file: file.into(),
        fnv1a: Fnv1a::of(text.as_bytes()),
    };
    if restart.input != identity {
        return Err(refuse(format!(
            "{RESTART_JSON} was written for {} with hash {}, but {file} has hash {}: the input \
             as run has changed since",
            restart.input.file, restart.input.fnv1a, identity.fnv1a
        )));
    }
    let stored = if file == CASE_JSON {
        Input::Case(Box::new(parse_case(&text, &source, &[])?))
    } else {
        Input::Model(
            Box::new(model_file::parse_model(&text, &source, &[])?),
            Vec::new(),
        )
    };
    let read_back = stored
        .as_run()
        .map_err(|e| refuse(format!("{file}: cannot be written back: {e}")))?;
    if read_back.1 != text {
        return Err(refuse(format!(
            "{file} does not read back as the input it was written from"
        )));
    }
    let every = restart_every.unwrap_or(restart.restart_every);
    let start = Start::Resume(Box::new(restart));
    match stored {
        Input::Case(case) => match case.dimension {
            3 => run_in::<3>(&case, &source, dir, every, start),
            _ => run_in::<2>(&case, &source, dir, every, start),
        }
        .map(|s| Resumed::Continued(Box::new(RunSummary::Case(s)))),
        Input::Model(spec, _) => match spec.dimension {
            3 => run_model_in::<3>(&spec, &source, dir, every, start),
            _ => run_model_in::<2>(&spec, &source, dir, every, start),
        }
        .map(|s| Resumed::Continued(Box::new(RunSummary::Model(s)))),
    }
}

/// Default output directory of a case: `out/<case name>`.
pub fn default_output_dir(case: &Case) -> PathBuf {
    Path::new("out").join(&case.name)
}

/// Loads `path` (with `overrides`) and runs it into `out_dir` (default `out/<name>`).
///
/// # Errors
/// [`CaseError`] for a bad case file, an inconsistent model or unwritable outputs. A run that
/// stops early (cutbacks exhausted) is not an error here: its summary says `"failed"` and why.
pub fn run_case_file(
    path: &Path,
    overrides: &[String],
    out_dir: Option<&Path>,
) -> Result<Summary, CaseError> {
    let case = load_case(path, overrides)?;
    let dir = out_dir.map_or_else(|| default_output_dir(&case), Path::to_path_buf);
    run_case(&case, path, &dir)
}

/// Runs a validated case into `dir`.
///
/// # Errors
/// See [`run_case_file`].
pub fn run_case(case: &Case, source: &Path, dir: &Path) -> Result<Summary, CaseError> {
    run_case_with(case, source, dir, DEFAULT_RESTART_EVERY)
}

/// Runs a validated case into `dir`, writing a restart file every `restart_every` converged
/// increments (0: none).
///
/// # Errors
/// See [`run_case_file`].
pub fn run_case_with(
    case: &Case,
    source: &Path,
    dir: &Path,
    restart_every: usize,
) -> Result<Summary, CaseError> {
    match case.dimension {
        2 => run_in::<2>(case, source, dir, restart_every, Start::Fresh),
        3 => run_in::<3>(case, source, dir, restart_every, Start::Fresh),
        d => Err(CaseError::Invalid {
            path: source.to_path_buf(),
            field: "dimension".into(),
            message: format!("expected 2 or 3, got {d}"),
        }),
    }
}

/// How a run begins: afresh (the directory cleared), or from a restart file in it.
enum Start {
    Fresh,
    Resume(Box<RestartFile>),
}

/// An output that cannot be written: `path` and the I/O error.
fn output(path: PathBuf) -> impl FnOnce(std::io::Error) -> CaseError {
    move |source| CaseError::Output { path, source }
}

/// An output that a resumed run continues could not be reopened: missing or changed since the
/// restart point, so the run cannot be resumed ([`CaseError::Resume`]), or unreadable
/// ([`CaseError::Output`]).
fn reopen_error(dir: &Path, path: PathBuf) -> impl FnOnce(std::io::Error) -> CaseError + '_ {
    move |source| match source.kind() {
        std::io::ErrorKind::NotFound | std::io::ErrorKind::InvalidData => CaseError::Resume {
            dir: dir.to_path_buf(),
            message: format!(
                "{}: the output written so far is missing or has changed since the restart \
                 point ({source})",
                path.display()
            ),
        },
        _ => CaseError::Output { path, source },
    }
}

/// A restart file that does not fit the run it is resumed into.
fn misfit(dir: &Path, message: &str) -> CaseError {
    CaseError::Resume {
        dir: dir.to_path_buf(),
        message: format!("{RESTART_JSON}: {message}"),
    }
}

fn run_in<const D: usize>(
    case: &Case,
    source: &Path,
    dir: &Path,
    restart_every: usize,
    start: Start,
) -> Result<Summary, CaseError> {
    let scene = case_scene::<D>(case, source)?;
    let fields_dir = dir.join(fields::FIELDS_DIR);
    let (mut recorder, mut newton, mut field_writer, input, checkpoint) = match start {
        Start::Fresh => {
            clear_outputs(dir)?;
            let input = write_input(dir, CASE_JSON, json_text(case))?;
            let recorder = DrumRecorder::create(dir, restart_every > 0)
                .map_err(output(dir.join("history.csv")))?;
            let newton = NewtonRecorder::create(dir).map_err(output(dir.join(NEWTON_CSV)))?;
            let fields = field_writer(dir, case.output.field_interval, None)?;
            (recorder, newton, fields, input, None)
        }
        Start::Resume(restart) => {
            let RestartFile {
                input,
                history,
                newton,
                recorder,
                fields,
                checkpoint,
                ..
            } = *restart;
            let RecorderMemory::Drum(journal) = recorder else {
                return Err(misfit(dir, "it holds a model file's history, not a drum's"));
            };
            let journal = SampleJournal::reopen(dir, &journal)
                .map_err(reopen_error(dir, dir.join(SAMPLES_JOURNAL)))?;
            let recorder = DrumRecorder::reopen(dir, &history, journal)
                .map_err(reopen_error(dir, dir.join("history.csv")))?;
            let newton = NewtonRecorder::reopen(dir, &newton)
                .map_err(reopen_error(dir, dir.join(NEWTON_CSV)))?;
            let fields = field_writer(
                dir,
                case.output.field_interval,
                Some((fields, &checkpoint.state)),
            )?;
            (recorder, newton, fields, input, Some(checkpoint))
        }
    };
    let mut observers = Observers {
        history: &mut recorder,
        newton: &mut newton,
        fields: field_writer.as_mut(),
        restart: RestartWriter::new(dir, restart_every, input, checkpoint.as_ref()),
    };
    let (stats, result) = integrate(
        &scene.model,
        &scene.steps,
        &scene.settings,
        &mut observers,
        checkpoint.as_ref(),
    );
    let samples = recorder.finish().map_err(output(dir.join("history.csv")))?;
    newton.finish().map_err(output(dir.join(NEWTON_CSV)))?;
    if let Some(writer) = field_writer {
        writer.finish(&scene.model).map_err(output(fields_dir))?;
    }
    let summary = summarize(case, &samples, &stats, result.err().as_ref());
    write_json_atomic(&dir.join("summary.json"), &summary)
        .map_err(output(dir.join("summary.json")))?;
    Ok(summary)
}

/// The field writer of a run whose input asks for frames every `interval` (none without):
/// created afresh, or, on resuming (`resumed`: the restart file's field memory and the restart
/// point's state), reopened where the restart point left the output.
///
/// # Errors
/// [`CaseError::Output`] if `<dir>/fields` cannot be written; [`CaseError::Resume`] if the
/// restart file's field output does not fit the input's or is missing.
fn field_writer(
    dir: &Path,
    interval: Option<f64>,
    resumed: Option<(Option<FieldMemory>, &State)>,
) -> Result<Option<FieldWriter>, CaseError> {
    let fields_dir = dir.join(fields::FIELDS_DIR);
    match (interval, resumed) {
        (None, None | Some((None, _))) => Ok(None),
        (Some(interval), None) => FieldWriter::create(dir, interval)
            .map(Some)
            .map_err(output(fields_dir)),
        (Some(interval), Some((Some(memory), state))) => {
            FieldWriter::reopen(dir, interval, memory, state.clone())
                .map(Some)
                .map_err(reopen_error(dir, fields_dir))
        }
        (None, Some((Some(_), _))) | (Some(_), Some((None, _))) => Err(misfit(
            dir,
            "its field output does not fit the input's field_interval",
        )),
    }
}

/// Writes the input as run, `text`, into `dir/file`, and returns its identity for the restart
/// files.
fn write_input(
    dir: &Path,
    file: &str,
    text: serde_json::Result<String>,
) -> Result<InputIdentity, CaseError> {
    let text = text
        .map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidData, e))
        .map_err(output(dir.join(file)))?;
    let identity = InputIdentity {
        file: file.into(),
        fnv1a: Fnv1a::of(text.as_bytes()),
    };
    write_atomic(&dir.join(file), text).map_err(output(dir.join(file)))?;
    Ok(identity)
}

/// The run of `steps` from the start, or from `checkpoint`.
fn integrate<const D: usize>(
    model: &Model<D>,
    steps: &[skid_integrator::Step],
    settings: &skid_integrator::Settings,
    observer: &mut dyn Observer<D>,
    checkpoint: Option<&Checkpoint>,
) -> (RunStatistics, Result<State, RunError>) {
    match checkpoint {
        Some(checkpoint) => resume(model, steps, settings, observer, checkpoint),
        None => run(model, steps, settings, observer),
    }
}

/// Creates `dir` and removes the results of an earlier run from it: stale results must not
/// survive next to a new, possibly interrupted one.
fn clear_outputs(dir: &Path) -> Result<(), CaseError> {
    let output = |path: PathBuf| move |source| CaseError::Output { path, source };
    std::fs::create_dir_all(dir).map_err(output(dir.to_path_buf()))?;
    for stale in [
        "history.csv",
        NEWTON_CSV,
        contact_nodes::CONTACT_NODES_CSV,
        "summary.json",
        CASE_JSON,
        MODEL_JSON,
        RESTART_JSON,
        SAMPLES_JOURNAL,
    ] {
        let p = dir.join(stale);
        if p.exists() {
            std::fs::remove_file(&p).map_err(output(p.clone()))?;
        }
    }
    fields::clear(dir).map_err(output(dir.join(fields::FIELDS_DIR)))
}

/// Runs a model into `dir`.
///
/// # Errors
/// [`CaseError::Invalid`] naming the field at fault, or [`CaseError::Output`].
pub fn run_model(spec: &ModelSpec, source: &Path, dir: &Path) -> Result<ModelSummary, CaseError> {
    run_model_with(spec, source, dir, DEFAULT_RESTART_EVERY)
}

/// Runs a model into `dir`, writing a restart file every `restart_every` converged increments
/// (0: none).
///
/// # Errors
/// As [`run_model`].
pub fn run_model_with(
    spec: &ModelSpec,
    source: &Path,
    dir: &Path,
    restart_every: usize,
) -> Result<ModelSummary, CaseError> {
    let invalid = |field: &str, message: String| CaseError::Invalid {
        path: source.to_path_buf(),
        field: field.into(),
        message,
    };
    match spec.dimension {
        2 => run_model_in::<2>(spec, source, dir, restart_every, Start::Fresh),
        3 => run_model_in::<3>(spec, source, dir, restart_every, Start::Fresh),
        d => Err(invalid("dimension", format!("expected 2 or 3, got {d}"))),
    }
}

fn run_model_in<const D: usize>(
    spec: &ModelSpec,
    source: &Path,
    dir: &Path,
    restart_every: usize,
    start: Start,
) -> Result<ModelSummary, CaseError> {
    let scene = model_scene::<D>(spec, source)?;
    let reactions = ReactionColumns::new(spec, &scene.model);
    let nodes = NodeColumns::new::<D>(spec);
    let history_path = dir.join(model_file::history::HISTORY_CSV);
    let fields_dir = dir.join(fields::FIELDS_DIR);
    let (mut history, mut newton, mut field_writer, input, checkpoint) = match start {
        Start::Fresh => {
            clear_outputs(dir)?;
            let input = write_input(dir, MODEL_JSON, model_file::to_json(spec))?;
            let history =
                ModelRecorder::create(dir, &scene.model, reactions.clone(), nodes.clone())
                    .map_err(output(history_path.clone()))?;
            let newton = NewtonRecorder::create(dir).map_err(output(dir.join(NEWTON_CSV)))?;
            let fields = field_writer(dir, spec.output.field_interval, None)?;
            (history, newton, fields, input, None)
        }
        Start::Resume(restart) => {
            let RestartFile {
                input,
                history,
                newton,
                recorder,
                fields,
                checkpoint,
                ..
            } = *restart;
            let RecorderMemory::Model(record) = recorder else {
                return Err(misfit(dir, "it holds a drum case's history, not a model's"));
            };
            let history =
                ModelRecorder::reopen(dir, &history, *record, reactions.clone(), nodes.clone())
                    .map_err(reopen_error(dir, history_path.clone()))?;
            let newton = NewtonRecorder::reopen(dir, &newton)
                .map_err(reopen_error(dir, dir.join(NEWTON_CSV)))?;
            let fields = field_writer(
                dir,
                spec.output.field_interval,
                Some((fields, &checkpoint.state)),
            )?;
            (history, newton, fields, input, Some(checkpoint))
        }
    };
    let mut observers = Observers {
        history: &mut history,
        newton: &mut newton,
        fields: field_writer.as_mut(),
        restart: RestartWriter::new(dir, restart_every, input, checkpoint.as_ref()),
    };
    let (stats, result) = integrate(
        &scene.model,
        &scene.steps,
        &scene.settings,
        &mut observers,
        checkpoint.as_ref(),
    );
    let record = history.finish().map_err(output(history_path))?;
    newton.finish().map_err(output(dir.join(NEWTON_CSV)))?;
    if let Some(writer) = field_writer {
        writer.finish(&scene.model).map_err(output(fields_dir))?;
    }
    if let Ok(state) = &result {
        let path = dir.join(contact_nodes::CONTACT_NODES_CSV);
        contact_nodes::write(dir, &scene.model, state).map_err(output(path))?;
    }
    let summary = summarize_model(
        &spec.name,
        &scene.model,
        &record,
        &stats,
        result.err().as_ref(),
    );
    write_json_atomic(&dir.join("summary.json"), &summary)
        .map_err(output(dir.join("summary.json")))?;
    Ok(summary)
}

/// A history observer whose file and memory go into the restart files.
trait History<const D: usize>: Observer<D> {
    /// Flushes the history file to disk and returns its mark.
    fn mark(&mut self) -> std::io::Result<FileMark>;
    /// What the summary will be computed from, so far, on disk.
    fn memory(&mut self) -> std::io::Result<RecorderMemory>;
}

impl<const D: usize> History<D> for DrumRecorder {
    fn mark(&mut self) -> std::io::Result<FileMark> {
        DrumRecorder::mark(self)
    }

    fn memory(&mut self) -> std::io::Result<RecorderMemory> {
        self.journal_mark().map(RecorderMemory::Drum)
    }
}

impl<const D: usize> History<D> for ModelRecorder {
    fn mark(&mut self) -> std::io::Result<FileMark> {
        ModelRecorder::mark(self)
    }

    fn memory(&mut self) -> std::io::Result<RecorderMemory> {
        Ok(RecorderMemory::Model(Box::new(self.record().clone())))
    }
}

/// When and where a run writes its restart files.
struct RestartWriter {
    dir: PathBuf,
    /// Converged increments between restart files (0: none).
    every: usize,
    input: InputIdentity,
    /// Converged increments since the last restart file.
    since: usize,
}

impl RestartWriter {
    /// Restart files every `every` increments into `dir` for the run of `input`, counting from
    /// `checkpoint` (a resumed run) or the start.
    fn new(
        dir: &Path,
        every: usize,
        input: InputIdentity,
        checkpoint: Option<&Checkpoint>,
    ) -> Self {
        let done = checkpoint.map_or(0, |c| c.statistics.increments);
        Self {
            dir: dir.to_path_buf(),
            every,
            input,
            since: if every == 0 { 0 } else { done % every },
        }
    }
}

/// The observers of a run: its history (the drum's or a model's), the Newton residuals,
/// optionally the field output, and the restart files.
struct Observers<'a, H> {
    history: &'a mut H,
    newton: &'a mut NewtonRecorder,
    fields: Option<&'a mut FieldWriter>,
    restart: RestartWriter,
}

impl<const D: usize, H: History<D>> Observer<D> for Observers<'_, H> {
    fn on_increment(
        &mut self,
        model: &Model<D>,
        report: &IncrementReport<'_>,
    ) -> std::io::Result<()> {
        self.history.on_increment(model, report)?;
        self.newton.on_increment(model, report)?;
        if let Some(fields) = self.fields.as_deref_mut() {
            fields.on_increment(model, report)?;
        }
        if report.increment > 0 {
            self.restart.since += 1;
        }
        Ok(())
    }

    fn on_rejection(
        &mut self,
        model: &Model<D>,
        report: &RejectionReport<'_>,
    ) -> std::io::Result<()> {
        self.newton.on_rejection(model, report)
    }

    fn wants_checkpoint(&mut self, boundary: bool) -> bool {
        self.restart.every > 0 && (boundary || self.restart.since >= self.restart.every)
    }

    /// Writes the restart file: the history and residual files flushed to disk first, so that
    /// the marks it holds are on disk whenever it is.
    fn on_checkpoint(&mut self, _model: &Model<D>, checkpoint: &Checkpoint) -> std::io::Result<()> {
        let restart = RestartFile {
            format: crate::restart::RESTART_FORMAT,
            skid_version: env!("CARGO_PKG_VERSION").into(),
            input: self.restart.input.clone(),
            restart_every: self.restart.every,
            history: self.history.mark()?,
            newton: self.newton.mark()?,
            recorder: self.history.memory()?,
            fields: self.fields.as_deref().map(FieldWriter::memory),
            checkpoint: checkpoint.clone(),
        };
        restart.write(&self.restart.dir)?;
        self.restart.since = 0;
        Ok(())
    }
}
