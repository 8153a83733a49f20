//! The sweep report (`skid report --sweep DIR...`): the runs of one or more sweeps, merged
//! from the `batch.json` of every directory given (one batch, or the shards of one), one table
//! per sweep in run order: each run's parameters and its key results.
//!
//! The report depends only on the runs, not on how they were split into shards nor on where
//! the shards wrote them, nor on wall times: the shards of a sweep merge into the report of
//! the same sweep run as one batch, byte for byte.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde_json::Value;

use super::ReportError;
use super::format::show;
use skid_cases::atomic::write_atomic;
use skid_cases::sweep::SweepRun;

/// What the sweep report found.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SweepOutcome {
    /// Sweeps in the report.
    pub sweeps: usize,
    /// Runs listed.
    pub runs: usize,
    /// Runs of the sweeps that no directory lists.
    pub missing: usize,
    /// Runs that did not end as their file says they should (completed, or stopped with the
    /// failure they expect).
    pub unexpected: usize,
}

impl SweepOutcome {
    /// The closing line: `N runs of M sweeps, N missing, N not as expected`.
    pub fn line(&self) -> String {
        format!(
            "{} runs of {} sweeps, {} missing, {} not as expected",
            self.runs, self.sweeps, self.missing, self.unexpected
        )
    }
}

/// One run as `batch.json` records it.
struct Run {
    sweep: SweepRun,
    status: String,
    summary: Value,
    /// The directory whose `batch.json` lists it.
    dir: PathBuf,
}

/// Reads the sweep runs of `<dir>/batch.json`.
fn read_batch(dir: &Path) -> Result<Vec<Run>, ReportError> {
    let path = dir.join("batch.json");
    let text = std::fs::read_to_string(&path).map_err(|source| ReportError::Read {
        path: path.clone(),
        source,
    })?;
    let parse = |message: String| ReportError::Parse {
        path: path.clone(),
        message,
    };
    let entries: Vec<Value> = serde_json::from_str(&text)
        .map_err(|e| parse(format!("expected the list of a batch's runs: {e}")))?;
    let mut runs = Vec::new();
    for (i, entry) in entries.into_iter().enumerate() {
        let Some(sweep) = entry.get("sweep") else {
            continue;
        };
        let sweep: SweepRun = serde_json::from_value(sweep.clone())
            .map_err(|e| parse(format!("[{i}].sweep: {e}")))?;
        let status = entry
            .get("status")
            .and_then(Value::as_str)
            .ok_or_else(|| parse(format!("[{i}].status: expected a string")))?
            .to_string();
        runs.push(Run {
            sweep,
            status,
            summary: entry.get("summary").cloned().unwrap_or(Value::Null),
            dir: dir.to_path_buf(),
        });
    }
    Ok(runs)
}

/// Merges the sweep runs of the batches in `dirs` and writes their report to `out`.
///
/// # Errors
/// [`ReportError::Read`] or [`ReportError::Parse`] for a `batch.json` that cannot be read,
/// [`ReportError::Parse`] for a run listed twice, batches that disagree on a sweep's runs, or
/// no sweep run in any of them, [`ReportError::Write`] if the report cannot be written.
pub fn write_sweep_report(dirs: &[PathBuf], out: &Path) -> Result<SweepOutcome, ReportError> {
    let mut sweeps: BTreeMap<String, BTreeMap<usize, Run>> = BTreeMap::new();
    for dir in dirs {
        for run in read_batch(dir)? {
            let runs = sweeps.entry(run.sweep.sweep.clone()).or_default();
            if let Some(first) = runs.values().next()
                && (first.sweep.count != run.sweep.count || first.sweep.file != run.sweep.file)
            {
                return Err(ReportError::Parse {
                    path: dir.join("batch.json"),
                    message: format!(
                        "run {} is of a sweep '{}' of {} runs from {}, but {} lists one of {} \
                         runs from {}",
                        run.sweep.name,
                        run.sweep.sweep,
                        run.sweep.count,
                        run.sweep.file.display(),
                        first.dir.display(),
                        first.sweep.count,
                        first.sweep.file.display()
                    ),
                });
            }
            if let Some(other) = runs.get(&run.sweep.index) {
                return Err(ReportError::Parse {
                    path: dir.join("batch.json"),
                    message: format!(
                        "run {} is also listed by {}: give each shard's directory once",
                        run.sweep.name,
                        other.dir.join("batch.json").display()
                    ),
                });
            }
            runs.insert(run.sweep.index, run);
        }
    }
    if sweeps.is_empty() {
        let names: Vec<String> = dirs.iter().map(|d| d.display().to_string()).collect();
        return Err(ReportError::Parse {
            path: PathBuf::from(names.join(", ")),
            message: "no sweep runs in batch.json (run a sweep file with `skid batch`)".into(),
        });
    }
    let mut outcome = SweepOutcome::default();
    let mut text = String::from("# Sweeps\n\nWritten by `skid report --sweep`.\n");
    for (name, runs) in &sweeps {
        render(&mut text, name, runs, &mut outcome);
    }
    let dir = out
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let write = |path: &Path| {
        let path = path.to_path_buf();
        move |source| ReportError::Write { path, source }
    };
    std::fs::create_dir_all(dir).map_err(write(dir))?;
    write_atomic(out, &text).map_err(write(out))?;
    Ok(outcome)
}

/// A summary's number, or `n/a`.
fn number(summary: &Value, field: &str) -> String {
    show(summary.get(field).and_then(Value::as_f64))
}

/// Appends one sweep's section.
fn render(text: &mut String, name: &str, runs: &BTreeMap<usize, Run>, outcome: &mut SweepOutcome) {
    let Some(first) = runs.values().next() else {
        return;
    };
    let count = first.sweep.count;
    let missing: Vec<String> = (1..=count)
        .filter(|i| !runs.contains_key(i))
        .map(|i| format!("`{name}-{i:0width$}`", width = count.to_string().len()))
        .collect();
    let completed = runs.values().filter(|r| r.status == "completed").count();
    let unexpected = runs
        .values()
        .filter(|r| r.status != "completed" && r.status != "failed_as_expected")
        .count();
    outcome.sweeps += 1;
    outcome.runs += runs.len();
    outcome.missing += missing.len();
    outcome.unexpected += unexpected;
    let _ = write!(
        text,
        "\n## {name}\n\nSweep file `{}`: {} of {count} runs listed, {completed} completed.\n",
        first.sweep.file.display(),
        runs.len(),
    );
    if !missing.is_empty() {
        let _ = write!(
            text,
            "\nMissing (no directory lists them): {}.\n",
            missing.join(", ")
        );
    }
    text.push_str("\n| run |");
    for parameter in &first.sweep.parameters {
        let _ = write!(text, " `{}` |", parameter.field);
    }
    text.push_str(
        " status | final time (s) | t_stop (s) | deceleration (rad/s^2) | analytic deceleration \
         (rad/s^2) |\n|---|",
    );
    text.push_str(&"---|".repeat(first.sweep.parameters.len() + 5));
    text.push('\n');
    for run in runs.values() {
        let _ = write!(text, "| {} |", run.sweep.name);
        for parameter in &run.sweep.parameters {
            let _ = write!(text, " {} |", parameter.value);
        }
        let _ = writeln!(
            text,
            " {} | {} | {} | {} | {} |",
            run.status,
            number(&run.summary, "final_time"),
            number(&run.summary, "t_stop"),
            number(&run.summary, "deceleration"),
            number(&run.summary, "deceleration_analytic"),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use skid_cases::sweep::ParameterValue;

    fn entry(index: usize, status: &str, t_stop: Option<f64>) -> Value {
        let run = SweepRun {
            sweep: "s".into(),
            file: "cases/sweeps/s.json".into(),
            name: format!("s-{index}"),
            index,
            count: 3,
            parameters: vec![ParameterValue {
                field: "contact.mu".into(),
                value: Value::from(0.1 * index as f64),
            }],
        };
        serde_json::json!({
            "name": run.name,
            "status": status,
            "summary": {"final_time": 0.01, "t_stop": t_stop, "deceleration": 600.0,
                        "deceleration_analytic": 610.0},
            "sweep": run,
            "wall_time_s": 0.5,
        })
    }

    fn batch(dir: &Path, entries: &[Value]) {
        std::fs::create_dir_all(dir).expect("dir");
        std::fs::write(
            dir.join("batch.json"),
            serde_json::to_string(entries).expect("json"),
        )
        .expect("write");
    }

    #[test]
    fn shards_merge_in_run_order_and_missing_runs_are_named() {
        let root = tempfile::tempdir().expect("tempdir");
        let (a, b) = (root.path().join("a"), root.path().join("b"));
        batch(&a, &[entry(3, "failed", None)]);
        batch(&b, &[entry(1, "completed", Some(0.005))]);
        let out = root.path().join("report/sweep.md");
        let outcome = write_sweep_report(&[a.clone(), b.clone()], &out).expect("report");
        assert_eq!(
            outcome,
            SweepOutcome {
                sweeps: 1,
                runs: 2,
                missing: 1,
                unexpected: 1
            }
        );
        let text = std::fs::read_to_string(&out).expect("report");
        let first = text.find("| s-1 |").expect("s-1");
        let third = text.find("| s-3 |").expect("s-3");
        assert!(first < third, "{text}");
        assert!(
            text.contains("Missing (no directory lists them): `s-2`."),
            "{text}"
        );
        assert!(
            text.contains("| s-1 | 0.1 | completed | 0.01000 | 0.005000 |"),
            "{text}"
        );
        assert!(
            !text.contains(&a.display().to_string()),
            "no directory in {text}"
        );
        let twice = write_sweep_report(&[a.clone(), a.clone()], &out).expect_err("twice");
        assert!(
            twice.to_string().contains("s-3 is also listed by"),
            "{twice}"
        );
    }

    #[test]
    fn directories_without_sweep_runs_are_an_error() {
        let root = tempfile::tempdir().expect("tempdir");
        batch(
            root.path(),
            &[serde_json::json!({"name": "x", "status": "completed"})],
        );
        let e = write_sweep_report(&[root.path().to_path_buf()], &root.path().join("s.md"))
            .expect_err("no sweep");
        assert!(e.to_string().contains("no sweep runs"), "{e}");
        let missing = root.path().join("absent");
        let e = write_sweep_report(&[missing], &root.path().join("s.md")).expect_err("absent");
        assert!(
            e.to_string().contains("absent/batch.json: cannot read"),
            "{e}"
        );
    }
}
