//! Runs one case: builds the scene, integrates it, writes `case.json` (the case as run, overrides
//! applied), `history.csv`, `newton.csv`, `summary.json` and, if the case asks for it, the
//! ParaView field output in `fields/`. A model file runs the same way with its own outputs:
//! `model.json` (the model as run), the generic `history.csv` and `summary.json` of
//! [`crate::model_file`], and `newton.csv`.
//!
//! Each output is complete or absent: those of an earlier run in the directory are removed
//! before the run, and each file appears under its name only when written whole
//! ([`crate::atomic`], [`crate::csv_out`]).

use std::path::{Path, PathBuf};

use skid_integrator::Model;
use skid_integrator::stepper::{IncrementReport, Observer, run};

use serde::Serialize;

use crate::atomic::write_atomic;
use crate::check::{case_scene, model_scene};
use crate::deck::{is_deck, read_model};
use crate::fields::{self, DrumOutline, FieldWriter};
use crate::history::DrumRecorder;
use crate::model_file::history::ModelRecorder;
use crate::model_file::summary::{ModelSummary, summarize as summarize_model};
use crate::model_file::{self, ModelSpec, declares_model};
use crate::newton::{NEWTON_CSV, NewtonRecorder};
use crate::schema::Case;
use crate::summary::{Summary, summarize};
use crate::validate::{CaseError, load_case};

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
}

/// Runs a case file or a model file (one that declares `skid_model`) into `out_dir` (default
/// `out/<name>`).
///
/// # Errors
/// See [`run_case_file`].
pub fn run_file(
    path: &Path,
    overrides: &[String],
    out_dir: Option<&Path>,
) -> Result<RunSummary, CaseError> {
    if is_deck(path) {
        let (spec, notes) = read_deck_model(path, overrides)?;
        let dir = out_dir.map_or_else(|| Path::new("out").join(&spec.name), Path::to_path_buf);
        let summary = run_model(&spec, path, &dir)?;
        for note in &notes {
            eprintln!("skid: note: {note}");
        }
        return Ok(RunSummary::Model(summary));
    }
    // Text that is not a model file (or not text: the case reader names the bad byte's line)
    // is read as a case file.
    let text = match std::fs::read_to_string(path) {
        Ok(text) if declares_model(&text) => text,
        Err(source) if source.kind() != std::io::ErrorKind::InvalidData => {
            return Err(CaseError::Read {
                path: path.to_path_buf(),
                source,
            });
        }
        _ => return run_case_file(path, overrides, out_dir).map(RunSummary::Case),
    };
    let spec = model_file::parse_model(&text, path, overrides)?;
    let dir = out_dir.map_or_else(|| Path::new("out").join(&spec.name), Path::to_path_buf);
    run_model(&spec, path, &dir).map(RunSummary::Model)
}

/// Reads an input deck into its model with `overrides` applied to the model's fields (as in a
/// model file), with the notes on what skid reads differently from the deck's requests.
///
/// # Errors
/// [`CaseError::Deck`] naming the deck line at fault, or a bad override.
pub fn read_deck_model(
    path: &Path,
    overrides: &[String],
) -> Result<(ModelSpec, Vec<String>), CaseError> {
    let deck = read_model(path)?;
    if overrides.is_empty() {
        return Ok((deck.model, deck.notes));
    }
    let model = model_file::parse_model(&model_file::to_json(&deck.model), path, overrides)?;
    Ok((model, deck.notes))
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
    match case.dimension {
        2 => run_in::<2>(case, source, dir),
        3 => run_in::<3>(case, source, dir),
        d => Err(CaseError::Invalid {
            path: source.to_path_buf(),
            field: "dimension".into(),
            message: format!("expected 2 or 3, got {d}"),
        }),
    }
}

fn run_in<const D: usize>(case: &Case, source: &Path, dir: &Path) -> Result<Summary, CaseError> {
    let scene = case_scene::<D>(case, source)?;
    let output = |path: PathBuf| move |source| CaseError::Output { path, source };
    clear_outputs(dir)?;
    write_atomic(
        &dir.join(CASE_JSON),
        serde_json::to_string_pretty(case).unwrap_or_default(),
    )
    .map_err(output(dir.join(CASE_JSON)))?;
    let fields_dir = dir.join(fields::FIELDS_DIR);
    let mut recorder = DrumRecorder::create(dir).map_err(output(dir.join("history.csv")))?;
    let mut newton = NewtonRecorder::create(dir).map_err(output(dir.join(NEWTON_CSV)))?;
    let mut field_writer = case
        .output
        .field_interval
        .map(|interval| {
            let drum = DrumOutline {
                radius: case.drum.radius,
                width: case.drum.width,
            };
            FieldWriter::create(dir, interval, drum)
        })
        .transpose()
        .map_err(output(fields_dir.clone()))?;
    let mut observers = Observers {
        history: &mut recorder,
        newton: &mut newton,
        fields: field_writer.as_mut(),
    };
    let (stats, result) = run(&scene.model, &scene.steps, &scene.settings, &mut observers);
    let samples = recorder.finish().map_err(output(dir.join("history.csv")))?;
    newton.finish().map_err(output(dir.join(NEWTON_CSV)))?;
    if let Some(writer) = field_writer {
        writer
            .finish(&scene.model)
            .map_err(output(fields_dir.clone()))?;
    }
    let summary = summarize(case, &samples, &stats, result.err().as_ref());
    write_atomic(
        &dir.join("summary.json"),
        serde_json::to_string_pretty(&summary).unwrap_or_default(),
    )
    .map_err(output(dir.join("summary.json")))?;
    Ok(summary)
}

/// Creates `dir` and removes the results of an earlier run from it: stale results must not
/// survive next to a new, possibly interrupted one.
fn clear_outputs(dir: &Path) -> Result<(), CaseError> {
    let output = |path: PathBuf| move |source| CaseError::Output { path, source };
    std::fs::create_dir_all(dir).map_err(output(dir.to_path_buf()))?;
    for stale in [
        "history.csv",
        NEWTON_CSV,
        "summary.json",
        CASE_JSON,
        MODEL_JSON,
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
    let invalid = |field: &str, message: String| CaseError::Invalid {
        path: source.to_path_buf(),
        field: field.into(),
        message,
    };
    match spec.dimension {
        2 => run_model_in::<2>(spec, source, dir),
        3 => run_model_in::<3>(spec, source, dir),
        d => Err(invalid("dimension", format!("expected 2 or 3, got {d}"))),
    }
}

fn run_model_in<const D: usize>(
    spec: &ModelSpec,
    source: &Path,
    dir: &Path,
) -> Result<ModelSummary, CaseError> {
    let scene = model_scene::<D>(spec, source)?;
    let output = |path: PathBuf| move |source| CaseError::Output { path, source };
    clear_outputs(dir)?;
    write_atomic(&dir.join(MODEL_JSON), model_file::to_json(spec))
        .map_err(output(dir.join(MODEL_JSON)))?;
    let mut history =
        ModelRecorder::create(dir, &scene.model).map_err(output(dir.join("history.csv")))?;
    let mut newton = NewtonRecorder::create(dir).map_err(output(dir.join(NEWTON_CSV)))?;
    let mut observers = Observers {
        history: &mut history,
        newton: &mut newton,
        fields: None,
    };
    let (stats, result) = run(&scene.model, &scene.steps, &scene.settings, &mut observers);
    let record = history.finish().map_err(output(dir.join("history.csv")))?;
    newton.finish().map_err(output(dir.join(NEWTON_CSV)))?;
    let summary = summarize_model(
        &spec.name,
        &scene.model,
        &record,
        &stats,
        result.err().as_ref(),
    );
    write_atomic(
        &dir.join("summary.json"),
        serde_json::to_string_pretty(&summary).unwrap_or_default(),
    )
    .map_err(output(dir.join("summary.json")))?;
    Ok(summary)
}

/// The observers of a run: its history (the drum's or a model's), the Newton residuals and,
/// optionally, the field output.
struct Observers<'a, H> {
    history: &'a mut H,
    newton: &'a mut NewtonRecorder,
    fields: Option<&'a mut FieldWriter>,
}

impl<const D: usize, H: Observer<D>> Observer<D> for Observers<'_, H> {
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
        Ok(())
    }
}
