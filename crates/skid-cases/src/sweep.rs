//! Parameter sweeps: a sweep file names a base input (case file, model file or deck) and
//! parameter ranges over its fields; `skid batch` expands it into one run per combination,
//! each with the base's fields overridden as by `--set` and named `<sweep name>-<index>`.
//!
//! The expansion is deterministic: in `product` mode the first parameter varies slowest (as
//! nested loops in the order the parameters are listed), in `zip` mode the `k`-th run takes the
//! `k`-th value of every parameter. Run indices start at 1 and are zero-padded to the width of
//! the run count, so the runs' directories sort in run order.

use std::path::{Path, PathBuf};

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use serde_json::Value;

use crate::validate::{CaseError, MAX_NAME, check_case_name, parse_document};

/// Format version a sweep file must declare in `skid_sweep`.
pub const SWEEP_FORMAT_VERSION: u32 = 1;

/// Most runs one sweep may expand into.
pub const MAX_RUNS: usize = 100_000;

/// A sweep file.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SweepSpec {
    /// Format version (1, the only one so far); its presence marks the file as a sweep file.
    pub skid_sweep: u32,
    /// Name of the sweep: run `i` is named `<name>-<i>` (its output directory), `i` counted
    /// from 1 and zero-padded to the width of the run count.
    pub name: String,
    /// The case file, model file or deck (.inp) every run starts from, relative to the sweep
    /// file's directory.
    pub base: PathBuf,
    /// Overrides applied to every run before its parameters, each `FIELD=VALUE` as given to
    /// `skid run --set` (e.g. `steps[1].duration=0.05`).
    #[serde(default)]
    pub set: Vec<String>,
    /// How the parameters' values combine into runs.
    #[serde(default)]
    pub mode: SweepMode,
    /// The parameters, in order (in `product` mode the first varies slowest).
    pub parameters: Vec<ParameterSpec>,
}

/// How the parameters' values combine into runs.
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum SweepMode {
    /// Every combination of the parameters' values (the Cartesian product).
    #[default]
    Product,
    /// The `k`-th run takes the `k`-th value of every parameter; all parameters have the same
    /// number of values.
    Zip,
}

/// One swept field: exactly one of `values` and `linspace`.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ParameterSpec {
    /// Field path as given to `--set`, e.g. `contact.mu` or `steps[1].dt`.
    pub field: String,
    /// The values, in order (any JSON values the field accepts).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub values: Option<Vec<Value>>,
    /// `[start, stop, count]`: `count` evenly spaced numbers from `start` to `stop`, both
    /// included.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub linspace: Option<(f64, f64, usize)>,
}

/// One value of a run's parameter.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
pub struct ParameterValue {
    /// Field path.
    pub field: String,
    /// The value set.
    pub value: Value,
}

/// One run of a sweep: recorded in `batch.json` and as `parameters.json` in its directory.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
pub struct SweepRun {
    /// The sweep's name.
    pub sweep: String,
    /// The sweep file.
    pub file: PathBuf,
    /// The run's name (and directory).
    pub name: String,
    /// Index of the run in the sweep, from 1.
    pub index: usize,
    /// Number of runs in the sweep.
    pub count: usize,
    /// The parameters' values, in the sweep's order.
    pub parameters: Vec<ParameterValue>,
}

impl SweepRun {
    /// The overrides of the run, to apply after the sweep's `set`: its parameters, then its
    /// name.
    pub fn overrides(&self) -> Vec<String> {
        self.parameters
            .iter()
            .map(|p| format!("{}={}", p.field, p.value))
            .chain([format!(
                "name={}",
                serde_json::Value::from(self.name.clone())
            )])
            .collect()
    }
}

/// A sweep file read and expanded.
#[derive(Clone, Debug, PartialEq)]
pub struct Sweep {
    /// The file as read.
    pub spec: SweepSpec,
    /// The base input, resolved against the sweep file's directory.
    pub base: PathBuf,
    /// The runs, in order.
    pub runs: Vec<SweepRun>,
}

/// Whether text is a sweep file: JSON that declares `skid_sweep`.
pub fn declares_sweep(text: &str) -> bool {
    serde_json::from_str::<Value>(text).is_ok_and(|v| v.get("skid_sweep").is_some())
}

/// Reads sweep-file text (`path` names the file in messages and locates `base`) and expands it.
///
/// # Errors
/// [`CaseError::Parse`] or [`CaseError::Invalid`] naming the file and the field at fault.
pub fn parse_sweep(text: &str, path: &Path) -> Result<Sweep, CaseError> {
    let spec: SweepSpec = parse_document(text, path, &[])?;
    let invalid = |field: String, message: String| CaseError::Invalid {
        path: path.to_path_buf(),
        field,
        message,
    };
    if spec.skid_sweep != SWEEP_FORMAT_VERSION {
        return Err(invalid(
            "skid_sweep".into(),
            format!(
                "expected format version {SWEEP_FORMAT_VERSION}, got {}",
                spec.skid_sweep
            ),
        ));
    }
    check_case_name(&spec.name).map_err(|(field, message)| invalid(field, message))?;
    if spec.parameters.is_empty() {
        return Err(invalid(
            "parameters".into(),
            "expected at least one parameter".into(),
        ));
    }
    let mut columns = Vec::with_capacity(spec.parameters.len());
    for (i, parameter) in spec.parameters.iter().enumerate() {
        let values = parameter_values(parameter)
            .map_err(|(field, message)| invalid(format!("parameters[{i}]{field}"), message))?;
        columns.push(values);
    }
    let combinations = combine(&columns, spec.mode).map_err(|m| invalid("parameters".into(), m))?;
    let width = combinations.len().to_string().len();
    if spec.name.len() + 1 + width > MAX_NAME {
        return Err(invalid(
            "name".into(),
            format!(
                "expected at most {} characters, so that the run names `{}-{:0width$}` have at \
                 most {MAX_NAME}",
                MAX_NAME - 1 - width,
                spec.name,
                1
            ),
        ));
    }
    let count = combinations.len();
    let runs = combinations
        .into_iter()
        .enumerate()
        .map(|(k, values)| SweepRun {
            sweep: spec.name.clone(),
            file: path.to_path_buf(),
            name: format!("{}-{:0width$}", spec.name, k + 1),
            index: k + 1,
            count,
            parameters: spec
                .parameters
                .iter()
                .zip(values)
                .map(|(p, value)| ParameterValue {
                    field: p.field.clone(),
                    value,
                })
                .collect(),
        })
        .collect();
    let base = path.parent().unwrap_or(Path::new("")).join(&spec.base);
    Ok(Sweep { spec, base, runs })
}

/// Reads a sweep file and expands it.
///
/// # Errors
/// [`CaseError::Read`] for a file that cannot be read, else as [`parse_sweep`].
pub fn load_sweep(path: &Path) -> Result<Sweep, CaseError> {
    let text = std::fs::read_to_string(path).map_err(|source| CaseError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    parse_sweep(&text, path)
}

/// The values of one parameter, or (the field below the parameter, what was expected).
fn parameter_values(parameter: &ParameterSpec) -> Result<Vec<Value>, (String, String)> {
    let field = &parameter.field;
    if field.is_empty() || field.contains('=') || field.contains(char::is_whitespace) {
        return Err((
            ".field".into(),
            format!("expected a field path such as `contact.mu`, got {field:?}"),
        ));
    }
    if field == "name" {
        return Err((
            ".field".into(),
            "expected a field other than `name`: the sweep names its runs".into(),
        ));
    }
    let values = match (&parameter.values, parameter.linspace) {
        (Some(values), None) => values.clone(),
        (None, Some((start, stop, count))) => {
            if count == 0 || count > MAX_RUNS {
                return Err((
                    ".linspace".into(),
                    format!("expected a count from 1 to {MAX_RUNS}, got {count}"),
                ));
            }
            if !(start.is_finite() && stop.is_finite()) {
                return Err((".linspace".into(), "expected finite start and stop".into()));
            }
            linspace(start, stop, count)
                .into_iter()
                .map(Value::from)
                .collect()
        }
        _ => {
            return Err((
                String::new(),
                "expected exactly one of `values` and `linspace`".into(),
            ));
        }
    };
    if values.is_empty() {
        return Err((".values".into(), "expected at least one value".into()));
    }
    Ok(values)
}

/// `count` evenly spaced numbers from `start` to `stop`, both included (`start` alone for 1).
fn linspace(start: f64, stop: f64, count: usize) -> Vec<f64> {
    if count == 1 {
        return vec![start];
    }
    let last = (count - 1) as f64;
    (0..count)
        .map(|i| {
            if i + 1 == count {
                stop
            } else {
                let t = i as f64 / last;
                start * (1.0 - t) + stop * t
            }
        })
        .collect()
}

/// The combinations of the parameters' values, in run order.
///
/// # Errors
/// What was expected, for zipped parameters of different lengths or too many runs.
fn combine(columns: &[Vec<Value>], mode: SweepMode) -> Result<Vec<Vec<Value>>, String> {
    match mode {
        SweepMode::Zip => {
            let count = columns[0].len();
            if let Some((i, c)) = columns.iter().enumerate().find(|(_, c)| c.len() != count) {
                return Err(format!(
                    "expected every parameter of a zip sweep to have {count} values (as \
                     parameters[0]), parameters[{i}] has {}",
                    c.len()
                ));
            }
            Ok((0..count)
                .map(|k| columns.iter().map(|c| c[k].clone()).collect())
                .collect())
        }
        SweepMode::Product => {
            let count = columns
                .iter()
                .try_fold(1usize, |n, c| n.checked_mul(c.len()))
                .filter(|&n| n <= MAX_RUNS)
                .ok_or_else(|| format!("expected at most {MAX_RUNS} runs in the product"))?;
            Ok((0..count)
                .map(|k| {
                    // Mixed-radix digits of k, the last parameter varying fastest.
                    let mut rest = k;
                    let mut run: Vec<Value> = columns
                        .iter()
                        .rev()
                        .map(|c| {
                            let value = c[rest % c.len()].clone();
                            rest /= c.len();
                            value
                        })
                        .collect();
                    run.reverse();
                    run
                })
                .collect())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sweep(text: &str) -> Result<Sweep, CaseError> {
        parse_sweep(text, Path::new("sweeps/s.json"))
    }

    #[test]
    fn a_product_varies_the_first_parameter_slowest_and_names_runs_in_order() {
        let s = sweep(
            r#"{"skid_sweep": 1, "name": "s", "base": "../drum/a.json",
                "parameters": [{"field": "contact.mu", "values": [0.1, 0.2]},
                               {"field": "back_plate.pressure", "linspace": [1e5, 3e5, 3]}]}"#,
        )
        .expect("valid sweep");
        assert_eq!(s.base, Path::new("sweeps/../drum/a.json"));
        let names: Vec<&str> = s.runs.iter().map(|r| r.name.as_str()).collect();
        assert_eq!(names, ["s-1", "s-2", "s-3", "s-4", "s-5", "s-6"]);
        let values: Vec<(f64, f64)> = s
            .runs
            .iter()
            .map(|r| {
                let v = |i: usize| r.parameters[i].value.as_f64().expect("number");
                (v(0), v(1))
            })
            .collect();
        assert_eq!(
            values,
            [
                (0.1, 1e5),
                (0.1, 2e5),
                (0.1, 3e5),
                (0.2, 1e5),
                (0.2, 2e5),
                (0.2, 3e5)
            ]
        );
        assert_eq!(
            s.runs[4].overrides(),
            [
                "contact.mu=0.2",
                "back_plate.pressure=200000.0",
                "name=\"s-5\""
            ]
        );
    }

    #[test]
    fn zip_pairs_values_and_indices_are_padded_to_the_run_count() {
        let s = sweep(
            r#"{"skid_sweep": 1, "name": "z", "base": "b.inp", "mode": "zip",
                "parameters": [{"field": "a", "linspace": [0, 1, 12]},
                               {"field": "b", "linspace": [1, 12, 12]}]}"#,
        )
        .expect("valid sweep");
        assert_eq!(s.runs.len(), 12);
        assert_eq!(s.runs[0].name, "z-01");
        assert_eq!(s.runs[11].name, "z-12");
        assert_eq!(s.runs[11].parameters[0].value, Value::from(1.0));
        assert_eq!(s.runs[11].parameters[1].value, Value::from(12.0));
    }

    #[test]
    fn errors_name_the_file_and_the_field() {
        let cases = [
            (
                r#"{"skid_sweep": 1, "name": "s", "base": "b.json", "parameters": []}"#,
                "sweeps/s.json: parameters: expected at least one parameter",
            ),
            (
                r#"{"skid_sweep": 1, "name": "s", "base": "b.json",
                    "parameters": [{"field": "a", "values": [1], "linspace": [0, 1, 2]}]}"#,
                "sweeps/s.json: parameters[0]: expected exactly one of",
            ),
            (
                r#"{"skid_sweep": 1, "name": "s", "base": "b.json",
                    "parameters": [{"field": "a", "linspace": [0, 1, 0]}]}"#,
                "sweeps/s.json: parameters[0].linspace: expected a count",
            ),
            (
                r#"{"skid_sweep": 1, "name": "s", "base": "b.json",
                    "parameters": [{"field": "name", "values": ["x"]}]}"#,
                "sweeps/s.json: parameters[0].field: expected a field other than `name`",
            ),
            (
                r#"{"skid_sweep": 1, "name": "s", "base": "b.json", "mode": "zip",
                    "parameters": [{"field": "a", "values": [1, 2]},
                                   {"field": "b", "values": [1]}]}"#,
                "sweeps/s.json: parameters: expected every parameter of a zip sweep to have 2",
            ),
            (
                r#"{"skid_sweep": 1, "name": "a/b", "base": "b.json",
                    "parameters": [{"field": "a", "values": [1]}]}"#,
                "sweeps/s.json: name: expected 1 to 100 of the characters",
            ),
            (
                r#"{"skid_sweep": 2, "name": "s", "base": "b.json",
                    "parameters": [{"field": "a", "values": [1]}]}"#,
                "sweeps/s.json: skid_sweep: expected format version 1, got 2",
            ),
            (
                r#"{"skid_sweep": 1, "name": "s", "base": "b.json",
                    "parameters": [{"field": "a", "valuez": [1]}]}"#,
                "sweeps/s.json: parameters[0].valuez: unknown field",
            ),
        ];
        for (text, message) in cases {
            let error = sweep(text).expect_err(text).to_string();
            assert!(error.starts_with(message), "{error}\n  expected {message}");
        }
        assert!(
            sweep(
                r#"{"skid_sweep": 1, "name": "s", "base": "b.json",
                    "parameters": [{"field": "a", "linspace": [0, 1, 1000]},
                                   {"field": "b", "linspace": [0, 1, 1000]}]}"#,
            )
            .is_err_and(|e| e.to_string().contains("at most 100000 runs"))
        );
    }

    #[test]
    fn only_json_declaring_skid_sweep_is_a_sweep() {
        assert!(declares_sweep(r#"{"skid_sweep": 1}"#));
        assert!(!declares_sweep(r#"{"skid_model": 1}"#));
        assert!(!declares_sweep("*HEADING"));
    }
}
