//! The report's section on the load at which each pad formulation fails: the records of
//! `scripts/pressure_limit.py` (`pressure-limit.json`: the hard case `<dim>-pressure-x10` run
//! with each element formulation, and the one-point element with each hourglass control, at a
//! ladder of back-plate pressures), tabled per
//! dimension with the first factor at which each formulation's run fails, and checks that the
//! record is whole and that every completed run obeys the physics the hard-case section checks:
//! the friction resultant never above `mu N` ([`FRICTION_TOLERANCE`]), the drum's angular
//! momentum balanced by the contact impulses ([`MOMENTUM_TOLERANCE`]) and the energy balance
//! within [`ENERGY_TOLERANCE`].

use std::collections::BTreeSet;
use std::fmt::Write as _;
use std::path::Path;

use serde::Deserialize;

use super::format::{Checks, Counts, Sig, plain};
use super::hard::{ENERGY_TOLERANCE, FRICTION_TOLERANCE, MOMENTUM_TOLERANCE};
use super::{ReportError, read_json};

/// The record of the script.
#[derive(Clone, Debug, Deserialize, PartialEq)]
pub struct Ladder {
    /// The command that wrote it.
    pub command: String,
    /// The pressure factors, ascending.
    pub factors: Vec<f64>,
    /// The benchmark's back-plate pressure the factors multiply, Pa.
    pub benchmark_pressure_pa: f64,
    /// One record per dimension, formulation and factor.
    pub runs: Vec<LadderRun>,
}

/// One run of the ladder.
#[derive(Clone, Debug, Deserialize, PartialEq)]
pub struct LadderRun {
    /// `2d` or `3d`.
    pub dimension: String,
    /// The pad formulation (`pad.formulation`).
    pub formulation: String,
    /// Its Abaqus name in this dimension.
    pub element: String,
    /// The pressure factor.
    pub factor: f64,
    /// `completed`, `failed`, `timeout` or `crashed`.
    pub status: String,
    /// The kind of failure, for a failed run.
    #[serde(default)]
    pub failure: Option<String>,
    /// Time the run reached, s.
    #[serde(default)]
    pub final_time: Option<f64>,
    /// Stop time of the drum, s.
    #[serde(default)]
    pub t_stop: Option<f64>,
    /// `I omega0 / (mu p A R)`, s (completed runs).
    #[serde(default)]
    pub t_stop_estimate: Option<f64>,
    /// `max (|F_t| - mu N) / (mu max N)` over the history (completed runs).
    #[serde(default)]
    pub friction_excess: Option<f64>,
    /// `max |I (omega - omega0) - sum h T| / (I omega0)` (completed runs).
    #[serde(default)]
    pub momentum_residual: Option<f64>,
    /// The run's energy balance error (relative).
    #[serde(default)]
    pub energy_balance_error: Option<f64>,
}

impl LadderRun {
    fn completed(&self) -> bool {
        self.status == "completed"
    }

    /// The table cell: `ok` with the stop time against its estimate, or how and when it stopped.
    fn cell(&self) -> String {
        match self.status.as_str() {
            "completed" => match (self.t_stop, self.t_stop_estimate) {
                (Some(t), Some(e)) => format!("ok, t_stop {:+.0} %", 100.0 * (t / e - 1.0)),
                _ => "ok".into(),
            },
            "failed" => {
                let what = match self.failure.as_deref() {
                    Some("inverted element") => "folds",
                    Some(other) => other,
                    None => "failed",
                };
                match self.final_time {
                    Some(t) if t > 0.0 => format!("{what} at {:.1} ms", 1e3 * t),
                    _ => format!("{what} in the preload"),
                }
            }
            other => other.into(),
        }
    }
}

/// Reads `pressure-limit.json`.
///
/// # Errors
/// [`ReportError::Read`] or [`ReportError::Parse`] naming the file.
pub fn load(path: &Path) -> Result<Ladder, ReportError> {
    read_json(path, "the record of scripts/pressure_limit.py")
}

/// The first factor at which a run of `runs` did not complete.
fn failure_load(runs: &[&LadderRun]) -> Option<f64> {
    runs.iter().find(|r| !r.completed()).map(|r| r.factor)
}

/// The largest `value` of the completed runs, `None` if one of them lacks it.
fn worst(ladder: &Ladder, value: impl Fn(&LadderRun) -> Option<f64>) -> Option<f64> {
    ladder
        .runs
        .iter()
        .filter(|r| r.completed())
        .map(value)
        .try_fold(0.0_f64, |acc, v| v.map(|v| acc.max(v)))
}

/// The section for the record `ladder` read from `path`, and its check counts.
pub fn section(path: &Path, ladder: &Ladder) -> (String, Counts) {
    let mut out = String::new();
    let _ = write!(
        out,
        "## The load at which each element formulation fails\n\n\
         The record `{}` of `{}`: the hard case `<dim>-pressure-x10` (10 x 1 (x 1) pad, \
         mu = 0.15, dt = 1e-4 s, to 0.1 s or 1.5 times the estimated stop) with the \
         back-plate pressure at the factor of the benchmark's {} MPa in the column head and \
         each pad formulation. `ok`: completed, with \
         its stop time against the instantaneous-sliding estimate I omega0 / (mu p A R) (the \
         later stop of a heavily loaded pad is the time it takes the drum to shear it, see the \
         hard case's expectation); otherwise how and when the run stopped.\n\n",
        path.display(),
        ladder.command,
        plain(ladder.benchmark_pressure_pa / 1e6),
    );
    for dim in ["2d", "3d"] {
        let _ = write!(out, "{}:\n\n| element | fails from |", dim.to_uppercase());
        for f in &ladder.factors {
            let _ = write!(out, " x {} |", plain(*f));
        }
        out.push_str("\n|---|---|");
        out.push_str(&"---|".repeat(ladder.factors.len()));
        out.push('\n');
        let mut formulations: Vec<&str> = Vec::new();
        for r in ladder.runs.iter().filter(|r| r.dimension == dim) {
            if !formulations.contains(&r.formulation.as_str()) {
                formulations.push(&r.formulation);
            }
        }
        for formulation in formulations {
            let mut row: Vec<&LadderRun> = ladder
                .runs
                .iter()
                .filter(|r| r.dimension == dim && r.formulation == formulation)
                .collect();
            row.sort_by(|a, b| a.factor.total_cmp(&b.factor));
            let limit = failure_load(&row).map_or_else(
                || format!("none to x {}", plain(row.last().map_or(0.0, |r| r.factor))),
                |f| format!("x {}", plain(f)),
            );
            let _ = write!(out, "| {} | {limit} |", row[0].element);
            for r in &row {
                let _ = write!(out, " {} |", r.cell());
            }
            out.push('\n');
        }
        out.push('\n');
    }
    let mut checks = Checks::default();
    // whole: each formulation the record names, in both dimensions at every factor, once
    let formulations: BTreeSet<&str> = ladder.runs.iter().map(|r| r.formulation.as_str()).collect();
    let expected = 2 * formulations.len() * ladder.factors.len();
    let once = |dim: &str, formulation: &str, factor: f64| {
        let is = |r: &&LadderRun| {
            r.dimension == dim && r.formulation == formulation && r.factor == factor
        };
        ladder.runs.iter().filter(is).count() == 1
    };
    let whole = ["2d", "3d"].into_iter().all(|dim| {
        formulations
            .iter()
            .all(|f| ladder.factors.iter().all(|&factor| once(dim, f, factor)))
    });
    checks.record(
        "every dimension, formulation and factor recorded",
        whole && ladder.runs.len() == expected,
        format!(
            "{} runs of {expected} ({} formulations)",
            ladder.runs.len(),
            formulations.len()
        ),
    );
    let crashed = ladder.runs.iter().filter(|r| r.status == "crashed").count();
    checks.record("no run crashed", crashed == 0, format!("{crashed} crashed"));
    let completed = ladder.runs.iter().filter(|r| r.completed()).count();
    let mut bound = |what: &str, measure: &str, value: Option<f64>, limit: f64, unit: &str| {
        let scale = if unit == " %" { 100.0 } else { 1.0 };
        checks.record(
            &format!("{what}, over the {completed} completed runs"),
            value.is_some_and(|v| v <= limit),
            format!(
                "{measure} {}{unit} (limit {}{unit})",
                value.map_or("missing".into(), |v| Sig(scale * v).to_string()),
                Sig(scale * limit)
            ),
        );
    };
    bound(
        "friction resultant never above mu N",
        "max (|F_t| - mu N) / (mu max N)",
        worst(ladder, |r| r.friction_excess),
        FRICTION_TOLERANCE,
        "",
    );
    bound(
        "drum's angular momentum balanced by the contact impulses",
        "max |I (omega - omega0) - sum h T| / (I omega0)",
        worst(ladder, |r| r.momentum_residual),
        MOMENTUM_TOLERANCE,
        "",
    );
    bound(
        "energy balance",
        "max error",
        worst(ladder, |r| r.energy_balance_error),
        ENERGY_TOLERANCE,
        " %",
    );
    out.push_str(&checks.text);
    (out, checks.counts)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(dim: &str, formulation: &str, factor: f64, folds: bool) -> LadderRun {
        LadderRun {
            dimension: dim.into(),
            formulation: formulation.into(),
            element: format!("{formulation}-{dim}"),
            factor,
            status: if folds { "failed" } else { "completed" }.into(),
            failure: folds.then(|| "inverted element".into()),
            final_time: Some(if folds { 2.03e-3 } else { 0.1 }),
            t_stop: (!folds).then_some(0.0113),
            t_stop_estimate: (!folds).then_some(0.01),
            friction_excess: (!folds).then_some(1e-10),
            momentum_residual: (!folds).then_some(1e-10),
            energy_balance_error: Some(0.004),
        }
    }

    fn ladder() -> Ladder {
        let mut runs = Vec::new();
        for dim in ["2d", "3d"] {
            for formulation in ["reduced", "enhanced", "full", "hybrid", "incompatible"] {
                for factor in [1.0, 10.0] {
                    let folds = formulation != "full" && factor == 10.0;
                    runs.push(run(dim, formulation, factor, folds));
                }
            }
        }
        Ladder {
            command: "scripts/pressure_limit.py".into(),
            factors: vec![1.0, 10.0],
            benchmark_pressure_pa: 0.35e6,
            runs,
        }
    }

    #[test]
    fn the_table_gives_each_formulation_its_failure_load() {
        let (text, counts) = section(Path::new("pressure-limit.json"), &ladder());
        assert_eq!((counts.passed, counts.failed), (5, 0), "{text}");
        assert!(
            text.contains("| reduced-2d | x 10 | ok, t_stop +13 % | folds at 2.0 ms |"),
            "{text}"
        );
        assert!(text.contains("| full-3d | none to x 10 |"), "{text}");
    }

    #[test]
    fn a_completed_run_that_breaks_the_physics_or_a_missing_run_fails() {
        let mut l = ladder();
        l.runs[0].friction_excess = Some(1e-5);
        l.runs[2].momentum_residual = None;
        l.runs.pop();
        let (text, counts) = section(Path::new("pressure-limit.json"), &l);
        assert_eq!(counts.failed, 3, "{text}");
        assert!(text.contains("19 runs of 20 (5 formulations)"), "{text}");
    }

    /// A run recorded twice in place of another leaves the count right but the record not
    /// whole.
    #[test]
    fn a_run_recorded_twice_in_place_of_another_fails() {
        let mut l = ladder();
        l.runs[1].factor = l.runs[0].factor;
        let (text, counts) = section(Path::new("pressure-limit.json"), &l);
        assert!(
            text.contains(
                "**FAIL** every dimension, formulation and factor recorded: 20 runs of 20"
            ),
            "{text}"
        );
        assert!(counts.failed >= 1, "{text}");
    }
}
