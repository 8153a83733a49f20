//! Reading and checking case files: every problem is reported with the file, the field path and
//! what was expected, before any model is built.

use std::path::{Path, PathBuf};

use serde_json::Value;
use thiserror::Error;

use crate::drum::BODY_NAMES;
use crate::schema::{
    Case, ContactFormulation, DrumSurfaceSpec, FacetElement, MaterialSpec, StepSpec,
};

/// A problem with a case file or its run.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum CaseError {
    /// The file could not be read.
    #[error("{path}: cannot read: {source}")]
    Read {
        /// File.
        path: PathBuf,
        /// Cause.
        source: std::io::Error,
    },
    /// Not valid JSON, or not of the schema (unknown/missing field, wrong type).
    #[error("{path}: {field}: {message}")]
    Parse {
        /// File.
        path: PathBuf,
        /// Field path, e.g. `pad.material.c10`.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// A value is out of its physical range or inconsistent with another.
    #[error("{path}: {field}: {message}")]
    Invalid {
        /// File.
        path: PathBuf,
        /// Field path.
        field: String,
        /// What was expected.
        message: String,
    },
    /// An override given on the command line is malformed.
    #[error("override '{0}': expected FIELD.PATH=VALUE, e.g. steps[1].dt=1e-4")]
    Override(String),
    /// The model could not be built.
    #[error("{path}: model: {message}")]
    Model {
        /// File.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// Results could not be written.
    #[error("{path}: cannot write: {source}")]
    Output {
        /// File or directory.
        path: PathBuf,
        /// Cause.
        source: std::io::Error,
    },
}

/// Reads a case file, applies `overrides` (`field.path=json`), parses and validates it.
///
/// # Errors
/// [`CaseError`] naming the file and field at fault.
pub fn load_case(path: &Path, overrides: &[String]) -> Result<Case, CaseError> {
    let text = std::fs::read_to_string(path).map_err(|source| CaseError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    parse_case(&text, path, overrides)
}

/// Parses and validates case text (`path` is only used in messages).
///
/// # Errors
/// [`CaseError`] naming the field at fault.
pub fn parse_case(text: &str, path: &Path, overrides: &[String]) -> Result<Case, CaseError> {
    if serde_json::from_str::<Value>(text).is_ok_and(|v| crate::model_file::is_model_file(&v)) {
        return Err(CaseError::Invalid {
            path: path.to_path_buf(),
            field: "skid_model".into(),
            message: "this is a model file, not a drum case file: run it with `skid run`".into(),
        });
    }
    let case: Case = parse_document(text, path, overrides)?;
    validate(&case).map_err(|(field, message)| CaseError::Invalid {
        path: path.to_path_buf(),
        field,
        message,
    })?;
    Ok(case)
}

/// Parses JSON text into `T` with `overrides` applied (`path` is only used in messages).
///
/// # Errors
/// [`CaseError::Parse`] for text that is not JSON (naming line and column) or not of `T`'s
/// format (naming the field path), [`CaseError::Override`] for a malformed override.
pub(crate) fn parse_document<T: serde::de::DeserializeOwned>(
    text: &str,
    path: &Path,
    overrides: &[String],
) -> Result<T, CaseError> {
    let parse_error = |field: String, message: String| CaseError::Parse {
        path: path.to_path_buf(),
        field,
        message,
    };
    let mut value: Value = serde_json::from_str(text).map_err(|e| {
        parse_error(
            format!("line {} column {}", e.line(), e.column()),
            format!("not valid JSON: {e}"),
        )
    })?;
    for o in overrides {
        apply_override(&mut value, o)?;
    }
    serde_path_to_error::deserialize(value).map_err(|e| {
        let field = match e.path().to_string() {
            p if p == "." => "(top level)".to_string(),
            p => p,
        };
        parse_error(field, e.into_inner().to_string())
    })
}

/// Sets a field: `drum.omega0=600`, `steps[1].dt=1e-4` (dots and `[i]` indices into existing
/// arrays).
fn apply_override(root: &mut Value, spec: &str) -> Result<(), CaseError> {
    let bad = || CaseError::Override(spec.to_string());
    let (path, raw) = spec.split_once('=').ok_or_else(bad)?;
    let new: Value = serde_json::from_str(raw).or_else(|_| {
        // Bare words are strings (`name=my-run`).
        Ok::<Value, CaseError>(Value::String(raw.to_string()))
    })?;
    let mut node = root;
    for part in path.split('.') {
        let (key, indices) = match part.find('[') {
            Some(i) => (&part[..i], &part[i..]),
            None => (part, ""),
        };
        if !key.is_empty() {
            // Optional sections may be absent from the file: create them. A misspelt key is
            // still caught, as an unknown field, when the result is parsed.
            let object = node.as_object_mut().ok_or_else(bad)?;
            node = object
                .entry(key.to_string())
                .or_insert_with(|| Value::Object(serde_json::Map::new()));
        }
        for idx in indices.split('[').filter(|s| !s.is_empty()) {
            let i: usize = idx.trim_end_matches(']').parse().map_err(|_| bad())?;
            node = node.get_mut(i).ok_or_else(bad)?;
        }
    }
    *node = new;
    Ok(())
}

type Problem = (String, String);

fn positive(field: &str, v: f64) -> Result<(), Problem> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err((
            field.into(),
            format!("expected a finite value > 0, got {v}"),
        ))
    }
}

fn non_negative(field: &str, v: f64) -> Result<(), Problem> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err((
            field.into(),
            format!("expected a finite value >= 0, got {v}"),
        ))
    }
}

/// Physical ranges and cross-field consistency.
///
/// # Errors
/// The first problem as (field path, what was expected).
pub fn validate(case: &Case) -> Result<(), Problem> {
    if case.name.trim().is_empty() || case.name.contains(['/', '\\']) || case.name.starts_with('.')
    {
        return Err((
            "name".into(),
            "expected a non-empty name usable as a directory name".into(),
        ));
    }
    if case.dimension != 2 && case.dimension != 3 {
        return Err((
            "dimension".into(),
            format!("expected 2 or 3, got {}", case.dimension),
        ));
    }
    let d = &case.drum;
    positive("drum.radius", d.radius)?;
    positive("drum.width", d.width)?;
    non_negative("drum.mass", d.mass)?;
    positive("drum.rotary_inertia", d.rotary_inertia)?;
    if !d.omega0.is_finite() {
        return Err(("drum.omega0".into(), "expected a finite value".into()));
    }
    match d.surface {
        DrumSurfaceSpec::Analytic => {}
        DrumSurfaceSpec::Facets { element, count } => {
            let two_d = element == FacetElement::R2d2;
            if two_d != (case.dimension == 2) {
                return Err((
                    "drum.surface.element".into(),
                    format!(
                        "expected {} in {}D, got {element:?}",
                        if case.dimension == 2 {
                            "r2d2"
                        } else {
                            "r3d4, m3d4r or s4r"
                        },
                        case.dimension
                    ),
                ));
            }
            if !(3..=100_000).contains(&count) {
                return Err((
                    "drum.surface.count".into(),
                    format!("expected 3..=100000 facets, got {count}"),
                ));
            }
        }
        DrumSurfaceSpec::Tetrahedra {
            sectors,
            rings,
            layers,
            inner_radius,
        } => {
            if case.dimension != 3 {
                return Err((
                    "drum.surface".into(),
                    "expected a 3D case for a tetrahedral drum".into(),
                ));
            }
            if !(3..=100_000).contains(&sectors) {
                return Err((
                    "drum.surface.sectors".into(),
                    format!("expected 3..=100000, got {sectors}"),
                ));
            }
            for (field, n) in [
                ("drum.surface.rings", rings),
                ("drum.surface.layers", layers),
            ] {
                if !(1..=1000).contains(&n) {
                    return Err((field.into(), format!("expected 1..=1000, got {n}")));
                }
            }
            positive("drum.surface.inner_radius", inner_radius)?;
            if inner_radius >= d.radius {
                return Err((
                    "drum.surface.inner_radius".into(),
                    format!("expected less than the drum radius {}", d.radius),
                ));
            }
        }
    }
    let p = &case.pad;
    positive("pad.length", p.length)?;
    positive("pad.width", p.width)?;
    positive("pad.thickness", p.thickness)?;
    positive("pad.density", p.density)?;
    positive("pad.hourglass_scale", p.hourglass_scale)?;
    non_negative("pad.standoff", p.standoff)?;
    if p.length >= 2.0 * d.radius {
        return Err((
            "pad.length".into(),
            format!("expected less than the drum diameter {}", 2.0 * d.radius),
        ));
    }
    for (field, n) in [
        ("pad.elements.circumferential", p.elements.circumferential),
        ("pad.elements.radial", p.elements.radial),
        ("pad.elements.axial", p.elements.axial),
    ] {
        if n == 0 || n > 10_000 {
            return Err((
                field.into(),
                format!("expected 1..=10000 elements, got {n}"),
            ));
        }
    }
    match p.material {
        MaterialSpec::PolynomialN1 { c10, c01, d1 } => {
            non_negative("pad.material.c10", c10)?;
            non_negative("pad.material.c01", c01)?;
            positive("pad.material.d1", d1)?;
            if c10 + c01 <= 0.0 {
                return Err((
                    "pad.material".into(),
                    "expected c10 + c01 > 0 (positive shear modulus)".into(),
                ));
            }
        }
    }
    non_negative("back_plate.pressure", case.back_plate.pressure)?;
    non_negative("back_plate.mass", case.back_plate.mass)?;
    if p.quasi_static && case.back_plate.mass > 0.0 {
        return Err((
            "back_plate.mass".into(),
            format!(
                "expected 0 with a quasi-static pad (the plate is tied to it and moves with \
                 it), got {}",
                case.back_plate.mass
            ),
        ));
    }
    non_negative("contact.mu", case.contact.mu)?;
    if let ContactFormulation::General { search_distance } = case.contact.formulation {
        positive("contact.formulation.search_distance", search_distance)?;
    }
    if case.steps.is_empty() {
        return Err(("steps".into(), "expected at least one step".into()));
    }
    for (i, step) in case.steps.iter().enumerate() {
        let f = |name: &str| format!("steps[{i}].{name}");
        let hold = match step {
            StepSpec::Static {
                name,
                increments,
                hold,
                regularization_time,
            } => {
                if name.is_empty() {
                    return Err((f("name"), "expected a non-empty name".into()));
                }
                if *increments == 0 {
                    return Err((f("increments"), "expected at least 1".into()));
                }
                positive(&f("regularization_time"), *regularization_time)?;
                hold
            }
            StepSpec::Dynamic {
                name,
                duration,
                dt,
                alpha,
                hold,
                adaptive,
            } => {
                if name.is_empty() {
                    return Err((f("name"), "expected a non-empty name".into()));
                }
                positive(&f("duration"), *duration)?;
                positive(&f("dt"), *dt)?;
                if dt > duration {
                    return Err((f("dt"), format!("expected dt <= duration ({duration})")));
                }
                if let Some(a) = adaptive {
                    positive(&f("adaptive.tolerance"), a.tolerance)?;
                    positive(&f("adaptive.min_dt"), a.min_dt)?;
                    positive(&f("adaptive.max_dt"), a.max_dt)?;
                    if a.min_dt > *dt {
                        return Err((
                            f("adaptive.min_dt"),
                            format!("expected min_dt <= dt ({dt})"),
                        ));
                    }
                    if a.max_dt < *dt || a.max_dt > *duration {
                        return Err((
                            f("adaptive.max_dt"),
                            format!("expected dt ({dt}) <= max_dt <= duration ({duration})"),
                        ));
                    }
                }
                // The integrator owns the admissible range; its message names it.
                skid_integrator::hht::Hht::new(*alpha).map_err(|message| (f("alpha"), message))?;
                hold
            }
        };
        if let Some(h) = hold.iter().find(|h| !BODY_NAMES.contains(&h.as_str())) {
            return Err((
                f("hold"),
                format!("expected \"drum\" or \"back_plate\", got \"{h}\""),
            ));
        }
    }
    let s = &case.solver;
    if s.max_newton_iterations == 0 {
        return Err((
            "solver.max_newton_iterations".into(),
            "expected at least 1".into(),
        ));
    }
    positive("solver.force_tolerance", s.force_tolerance)?;
    positive("solver.contact_tolerance", s.contact_tolerance)?;
    positive("solver.coulomb_tolerance", s.coulomb_tolerance)?;
    if s.max_fixed_point_iterations == 0 {
        return Err((
            "solver.max_fixed_point_iterations".into(),
            "expected at least 1".into(),
        ));
    }
    if !(s.cutback_factor > 0.0 && s.cutback_factor < 1.0) {
        return Err((
            "solver.cutback_factor".into(),
            format!("expected a value in (0, 1), got {}", s.cutback_factor),
        ));
    }
    if let Some(interval) = case.output.field_interval {
        positive("output.field_interval", interval)?;
    }
    if let Some(tolerance) = case.expect.t_stop_estimate_tolerance {
        positive("expect.t_stop_estimate_tolerance", tolerance)?;
    }
    Ok(())
}
