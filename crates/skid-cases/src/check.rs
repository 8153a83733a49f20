//! Checking an input without running it (`skid check`): a case file, model file or deck is
//! read, validated and built into its model (mesh, bodies, contact candidates) exactly as
//! [`crate::runner`] does before integrating, so that whatever `skid run` would refuse (a
//! misspelt field, an inverted element, an empty surface) is found with the same message, and
//! nothing is written. A sweep file is expanded and each of its runs checked so.

use std::path::Path;

use skid_integrator::Model;

use crate::deck::is_deck;
use crate::model_file::{self, Scene};
use crate::model_spec::{ModelSpec, declares_model};
use crate::scene::{case_scene, model_scene, read_deck_model};
use crate::schema::Case;
use crate::sweep::{declares_sweep, load_sweep};
use crate::validate::{CaseError, load_case, memory};

/// The check of one input: a file, or one run of a sweep file.
#[derive(Debug)]
pub struct Checked {
    /// What was checked: the file, or for a sweep run `FILE: RUN`.
    pub label: String,
    /// What it amounts to, or why it cannot run.
    pub result: Result<CheckReport, CaseError>,
}

/// Checks `path` with `overrides`: a sweep file as each of its runs (the overrides applied
/// after the sweep's `set` and before the run's parameters), any other file as itself
/// ([`check_file`]).
pub fn check_path(path: &Path, overrides: &[String]) -> Vec<Checked> {
    let label = path.display().to_string();
    let is_sweep =
        !is_deck(path) && std::fs::read_to_string(path).is_ok_and(|text| declares_sweep(&text));
    if !is_sweep {
        let result = check_file(path, overrides);
        return vec![Checked { label, result }];
    }
    match load_sweep(path) {
        Err(e) => vec![Checked {
            label,
            result: Err(e),
        }],
        Ok(sweep) => sweep
            .runs
            .iter()
            .map(|run| {
                let all: Vec<String> = sweep
                    .spec
                    .set
                    .iter()
                    .chain(overrides)
                    .cloned()
                    .chain(run.overrides())
                    .collect();
                Checked {
                    label: format!("{label}: {}", run.name),
                    result: check_file(&sweep.base, &all),
                }
            })
            .collect(),
    }
}

/// What an input that builds amounts to.
#[derive(Clone, Debug, PartialEq)]
pub struct CheckReport {
    /// What the file is: `case file`, `model file` or `deck`.
    pub kind: &'static str,
    /// The name of the case or model (its output directory).
    pub name: String,
    /// 2 or 3.
    pub dimension: usize,
    /// Equations of the assembled system (free degrees of freedom of nodes and bodies).
    pub equations: usize,
    /// Elements of the deformable part.
    pub elements: usize,
    /// Rigid bodies.
    pub rigid_bodies: usize,
    /// Contact candidates: slave nodes, summed over the contact pairs.
    pub contact_candidates: usize,
    /// Analysis steps.
    pub steps: usize,
    /// What skid reads differently from a deck's requests (empty for JSON files).
    pub notes: Vec<String>,
    /// The memory a case file's run needs at least, bytes (the estimate that refuses a case too
    /// large for the machine, [`crate::validate::memory`]); `None` for model files and decks.
    pub memory_bytes: Option<f64>,
}

impl CheckReport {
    /// The counts on one line: `case file, 2D, 1234 equations, ...`, and the memory estimate.
    pub fn line(&self) -> String {
        let memory = self.memory_bytes.map_or_else(String::new, |bytes| {
            format!(", at least {} of memory", memory::human(bytes))
        });
        format!(
            "{} '{}', {}D, {} equations, {} elements, {} rigid bodies, {} contact candidates, {} \
             steps{memory}",
            self.kind,
            self.name,
            self.dimension,
            self.equations,
            self.elements,
            self.rigid_bodies,
            self.contact_candidates,
            self.steps
        )
    }
}

/// Reads `path` (with `overrides`) as `skid run` would, and builds its model without running
/// it.
///
/// # Errors
/// The [`CaseError`] that `skid run` reports for the same file and overrides.
pub fn check_file(path: &Path, overrides: &[String]) -> Result<CheckReport, CaseError> {
    if is_deck(path) {
        let (spec, notes) = read_deck_model(path, overrides)?;
        return Ok(CheckReport {
            notes,
            ..check_model(&spec, path, "deck")?
        });
    }
    let text = match std::fs::read_to_string(path) {
        Ok(text) if declares_model(&text) => text,
        Err(source) if source.kind() != std::io::ErrorKind::InvalidData => {
            return Err(CaseError::Read {
                path: path.to_path_buf(),
                source,
            });
        }
        _ => return check_case(&load_case(path, overrides)?, path),
    };
    let spec = model_file::parse_model(&text, path, overrides)?;
    check_model(&spec, path, "model file")
}

/// Builds a validated case's model.
fn check_case(case: &Case, source: &Path) -> Result<CheckReport, CaseError> {
    let n = match case.dimension {
        2 => counts(&case_scene::<2>(case, source)?),
        3 => counts(&case_scene::<3>(case, source)?),
        d => return Err(bad_dimension(source, d)),
    };
    Ok(CheckReport {
        memory_bytes: Some(memory::needed(case)),
        ..report("case file", &case.name, case.dimension, n)
    })
}

/// Builds a model file's model.
fn check_model(
    spec: &ModelSpec,
    source: &Path,
    kind: &'static str,
) -> Result<CheckReport, CaseError> {
    let n = match spec.dimension {
        2 => counts(&model_scene::<2>(spec, source)?),
        3 => counts(&model_scene::<3>(spec, source)?),
        d => return Err(bad_dimension(source, d)),
    };
    Ok(report(kind, &spec.name, spec.dimension, n))
}

/// The error of a dimension other than 2 or 3.
fn bad_dimension(source: &Path, dimension: usize) -> CaseError {
    CaseError::Invalid {
        path: source.to_path_buf(),
        field: "dimension".into(),
        message: format!("expected 2 or 3, got {dimension}"),
    }
}

/// The counts of a scene: equations, elements, bodies, contact candidates, steps.
fn counts<const D: usize>(scene: &Scene<D>) -> [usize; 5] {
    let model: &Model<D> = &scene.model;
    [
        model.dofs().len(),
        model.elements().len(),
        model.bodies().len(),
        model.contacts().iter().map(|pair| pair.nodes.len()).sum(),
        scene.steps.len(),
    ]
}

/// The report of a file that builds, with the counts of [`counts`].
fn report(
    kind: &'static str,
    name: &str,
    dimension: usize,
    [equations, elements, rigid_bodies, contact_candidates, steps]: [usize; 5],
) -> CheckReport {
    CheckReport {
        kind,
        name: name.to_string(),
        dimension,
        equations,
        elements,
        rigid_bodies,
        contact_candidates,
        steps,
        notes: Vec::new(),
        memory_bytes: None,
    }
}
