//! Reading and checking case files: every problem is reported with the file, the field path and
//! what was expected, before any model is built.

use std::path::{Path, PathBuf};

use serde_json::Value;
use thiserror::Error;

use crate::schema::{
    BODY_NAMES, Case, ContactFormulation, DrumSurfaceSpec, FacetElement, HourglassControl,
    MaterialSpec, PadFormulation, PadSpec, StepSpec,
};

mod json;
pub mod memory;

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
    /// Not valid UTF-8 or JSON, or not of the schema (unknown/missing field, wrong type).
    #[error("{path}: {field}: {message}")]
    Parse {
        /// File.
        path: PathBuf,
        /// Field path, e.g. `pad.material.c10`, or `line L column C` of a syntax error.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// A value is out of its physical range or inconsistent with another, or the case does
    /// not fit in memory.
    #[error("{path}: {field}: {message}")]
    Invalid {
        /// File.
        path: PathBuf,
        /// Field path.
        field: String,
        /// What was expected.
        message: String,
    },
    /// An override given on the command line cannot be applied.
    #[error("{path}: --set {spec}: {message}")]
    Override {
        /// The case file it applies to.
        path: PathBuf,
        /// The override as given.
        spec: String,
        /// What is wrong and what was expected.
        message: String,
    },
    /// An input deck is outside the keyword subset or inconsistent (the error names its file
    /// and line).
    #[error("{0}")]
    Deck(#[from] crate::deck::keywords::DeckError),
    /// The model could not be built.
    #[error("{path}: model: {message}")]
    Model {
        /// File.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// An interrupted run cannot be resumed: no restart file, or one that does not fit.
    #[error("{dir}: cannot resume: {message}")]
    Resume {
        /// The run directory.
        dir: PathBuf,
        /// Why not.
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
    let bytes = std::fs::read(path).map_err(|source| CaseError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    match String::from_utf8(bytes) {
        Ok(text) => parse_case(&text, path, overrides),
        Err(e) => {
            let error = json::utf8_error(e.as_bytes()).unwrap_or(json::SyntaxError {
                place: "line 1 column 1".into(),
                message: "not valid UTF-8".into(),
            });
            Err(CaseError::Parse {
                path: path.to_path_buf(),
                field: error.place,
                message: error.message,
            })
        }
    }
}

/// Parses and validates case text (`path` is only used in messages), and checks that the case
/// fits in the memory available ([`memory`]).
///
/// # Errors
/// [`CaseError`] naming the field at fault.
pub fn parse_case(text: &str, path: &Path, overrides: &[String]) -> Result<Case, CaseError> {
    if crate::model_spec::declares_model(text) {
        return Err(CaseError::Invalid {
            path: path.to_path_buf(),
            field: "skid_model".into(),
            message: "this is a model file, not a drum case file: run it with `skid run`".into(),
        });
    }
    let case: Case = parse_document(text, path, overrides)?;
    let invalid = |(field, message): Problem| CaseError::Invalid {
        path: path.to_path_buf(),
        field,
        message,
    };
    validate(&case).map_err(invalid)?;
    memory::check(&case, memory::available()).map_err(invalid)?;
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
    let mut value = json::parse_json(text).map_err(|e| parse_error(e.place, e.message))?;
    for spec in overrides {
        apply_override(&mut value, spec).map_err(|message| CaseError::Override {
            path: path.to_path_buf(),
            spec: spec.clone(),
            message,
        })?;
    }
    json::to_typed(&value).map_err(|(field, message)| parse_error(json::path_text(&field), message))
}

/// Longest field path an override may give, in parts (`steps[1].adaptive.min_dt` has 3).
const MAX_OVERRIDE_PARTS: usize = 16;

/// Sets a field: `drum.omega0=600`, `steps[1].dt=1e-4` (dots and `[i]` indices into existing
/// arrays). The value is JSON; anything else is taken as a string (`name=my-run`), except a
/// word that reads as a number, which must be finite (`nan`, `inf`, `1e999` are refused; a
/// string of that spelling is written as JSON, `name="nan"`).
///
/// # Errors
/// What is wrong with `spec`, and what was expected.
fn apply_override(root: &mut Value, spec: &str) -> Result<(), String> {
    let syntax = || "expected FIELD.PATH=VALUE, e.g. steps[1].dt=1e-4".to_string();
    let (path, raw) = spec.split_once('=').ok_or_else(syntax)?;
    let parts: Vec<&str> = path.split('.').collect();
    if parts.len() > MAX_OVERRIDE_PARTS {
        return Err(format!(
            "expected a field path of at most {MAX_OVERRIDE_PARTS} parts, got {}",
            parts.len()
        ));
    }
    let new = match json::parse_json(raw) {
        Ok(value) => value,
        Err(_) => match raw.trim().parse::<f64>() {
            Ok(number) if !number.is_finite() => {
                return Err(format!("{path}: expected a finite number, got {raw}"));
            }
            _ => Value::String(raw.to_string()),
        },
    };
    let mut node = root;
    let mut reached = String::new();
    for part in parts {
        let (key, indices) = match part.find('[') {
            Some(i) => (&part[..i], &part[i..]),
            None => (part, ""),
        };
        if key.is_empty() {
            return Err(syntax());
        }
        let holder = if reached.is_empty() {
            "the case".to_string()
        } else {
            reached.clone()
        };
        if !reached.is_empty() {
            reached.push('.');
        }
        reached.push_str(key);
        // Optional sections may be absent from the file: create them. A misspelt key is still
        // caught, as an unknown field, when the result is parsed.
        let object = node
            .as_object_mut()
            .ok_or_else(|| format!("{holder}: expected an object to hold `{key}`"))?;
        node = object
            .entry(key.to_string())
            .or_insert_with(|| Value::Object(serde_json::Map::new()));
        let mut rest = indices;
        while !rest.is_empty() {
            let index = rest
                .strip_prefix('[')
                .and_then(|r| r.split_once(']'))
                .and_then(|(i, r)| Some((i.parse::<usize>().ok()?, r)));
            let Some((i, r)) = index else {
                return Err(format!("{part}: expected an index [N], N >= 0"));
            };
            rest = r;
            let array = node
                .as_array_mut()
                .ok_or_else(|| format!("{reached}: expected an array to index with [{i}]"))?;
            let len = array.len();
            node = array.get_mut(i).ok_or_else(|| {
                format!("{reached}[{i}]: expected an index below {len}, the length of {reached}")
            })?;
            reached.push_str(&format!("[{i}]"));
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

/// The enhanced hourglass control only on the one-point element, and without a scale.
fn check_hourglass(p: &PadSpec) -> Result<(), Problem> {
    if p.hourglass == HourglassControl::Enhanced && p.formulation != PadFormulation::Reduced {
        return Err((
            "pad.hourglass".into(),
            format!(
                "the enhanced hourglass control is for the one-point element: expected \
                 pad.formulation = \"reduced\", got \"{}\"",
                p.formulation.name()
            ),
        ));
    }
    p.hourglass
        .check_scale(p.hourglass_scale)
        .map_err(|message| ("pad.hourglass_scale".into(), message))
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

/// Longest case or step name, in characters.
pub(crate) const MAX_NAME: usize = 100;

/// A case name is the name of its output directory: 1 to [`MAX_NAME`] ASCII letters, digits and
/// `.`, `_`, `+`, `-`, not starting with `.` (hidden, or the directory itself or its parent)
/// or `-` (read as an option on a command line).
pub(crate) fn check_case_name(name: &str) -> Result<(), Problem> {
    check_file_name("name", name, "the name of the output directory")
}

/// A name that names a file or directory (`role` says which, for the message): 1 to
/// [`MAX_NAME`] ASCII letters, digits and `.`, `_`, `+`, `-`, not starting with `.` or `-`.
pub(crate) fn check_file_name(field: &str, name: &str, role: &str) -> Result<(), Problem> {
    let allowed = |c: char| c.is_ascii_alphanumeric() || "._+-".contains(c);
    if name.is_empty()
        || name.chars().count() > MAX_NAME
        || !name.chars().all(allowed)
        || name.starts_with(['.', '-'])
    {
        return Err((
            field.into(),
            format!(
                "expected 1 to {MAX_NAME} of the characters A-Z a-z 0-9 . _ + - not starting \
                 with . or - ({role}), got {name:?}"
            ),
        ));
    }
    Ok(())
}

/// A step name labels rows of the CSV output and lines of messages: 1 to [`MAX_NAME`]
/// characters, none of them a control character (line break, tab), not starting or ending
/// with white space.
fn check_step_name(field: &str, name: &str) -> Result<(), Problem> {
    if name.is_empty()
        || name.chars().count() > MAX_NAME
        || name.chars().any(char::is_control)
        || name.trim() != name
    {
        return Err((
            field.into(),
            format!(
                "expected 1 to {MAX_NAME} characters, no control characters (line breaks, \
                 tabs) and no white space at either end, got {name:?}"
            ),
        ));
    }
    Ok(())
}

/// Physical ranges and cross-field consistency.
///
/// # Errors
/// The first problem as (field path, what was expected).
pub fn validate(case: &Case) -> Result<(), Problem> {
    check_case_name(&case.name)?;
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
    check_hourglass(p)?;
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
                check_step_name(&f("name"), name)?;
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
                check_step_name(&f("name"), name)?;
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
