//! General model files: any scene the solver can run, as one JSON document
//! ([`crate::model_spec`] gives its format), read, built into a model and written out.
//!
//! - [`mod@build`]: resolving names and checking values into a [`Scene`] (the integrator's model,
//!   steps and settings), each problem reported with its field path;
//! - [`history`]: the generic `history.csv` (every body's motions, every pair's resultants,
//!   the energy ledger);
//! - [`parts`]: several deformable parts merged into the one mesh the solver integrates;
//! - [`summary`]: the generic `summary.json`;
//! - [`contact_nodes`]: every contact candidate's position and forces at the end of the run
//!   (`contact_nodes.csv`).
//!
//! A case file of the drum benchmark is generated into a model file by
//! [`crate::drum::model_spec`], and runs through the same [`build()`].

pub mod build;
pub mod contact_nodes;
pub mod history;
pub mod parts;
pub mod summary;

use std::path::Path;

pub use build::{Scene, SpecError, build};
pub use parts::merge_parts;

use crate::model_spec::ModelSpec;
use crate::validate::{CaseError, parse_document};

/// Parses model-file text with `overrides` applied (`path` is only used in messages), its
/// `parts` merged into `part` ([`merge_parts`]). Names and values are checked when the scene is
/// built ([`build()`]).
///
/// # Errors
/// [`CaseError::Parse`] for text that is not JSON or not of the format, naming the line or the
/// field; [`CaseError::Invalid`] for parts that cannot be merged.
pub fn parse_model(text: &str, path: &Path, overrides: &[String]) -> Result<ModelSpec, CaseError> {
    let spec: ModelSpec = parse_document(text, path, overrides)?;
    merge_parts(spec).map_err(|e| CaseError::Invalid {
        path: path.to_path_buf(),
        field: e.field,
        message: e.message,
    })
}

/// The model file's text: pretty JSON whose numbers read back to the same bits.
///
/// # Errors
/// The serializer's, should the model not serialize.
pub fn to_json(spec: &ModelSpec) -> serde_json::Result<String> {
    crate::atomic::json_text(spec)
}
