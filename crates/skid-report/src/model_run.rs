//! A model run of the drum scene (a model file or deck: `model.json`, a generic
//! `summary.json` and `history.csv`) read as a benchmark run, so that the benchmark section
//! compares deck and model-file runs with case runs.
//!
//! The drum is the body that turns: of the `B.omega` columns of the history (each with its
//! `B.angle`), the one largest in magnitude where the dynamic part starts. Its spin-down is
//! measured as a drum case's summary measures it ([`SpinDown`]: stop time, deceleration,
//! post-stop motion), so that a deck and its case file give the same figures. The model run's
//! summary gives the rest; its energy balance error is the model summary's (the residual over
//! the largest energy in play, here the drum's initial kinetic energy), and it has no analytic
//! deceleration.

use std::path::Path;

use serde::Deserialize;
use skid_cases::csv_out::CsvTable;
use skid_cases::spin_down::{SpinDown, SpinPoint};

use super::{
    History, ReportError, Run, RunSummary, dynamic_rows, non_finite_fields, read, read_json,
};

/// The fields of a model run's `summary.json` the benchmark reads.
#[derive(Deserialize)]
struct ModelRunSummary {
    model: String,
    dimension: usize,
    status: String,
    #[serde(default)]
    error: Option<String>,
    #[serde(default)]
    failure: Option<String>,
    #[serde(default)]
    energy_balance_error: Option<f64>,
    #[serde(default)]
    energy_balance_residual_j: Option<f64>,
    max_gap_violation_m: f64,
    max_sliding_separation_m: f64,
    increments: usize,
    newton_iterations: usize,
    contact_solves: usize,
    cutbacks: usize,
    wall_time_s: f64,
}

/// The turning body's history, from the start of the dynamic part.
struct Spin {
    points: Vec<SpinPoint>,
    non_finite: usize,
}

/// Reads the model run in `dir` as a benchmark run.
///
/// # Errors
/// [`ReportError`] naming the file that is missing or malformed, or the history in which no
/// body turns.
pub(crate) fn load(dir: &Path) -> Result<Run, ReportError> {
    let summary: ModelRunSummary =
        read_json(&dir.join("summary.json"), "a skid model run summary")?;
    let history_path = dir.join("history.csv");
    let spin = turning_body(&read(&history_path)?, &history_path)?;
    let omega0 = spin.points.first().map_or(0.0, |p| p.omega);
    let measured = SpinDown::measure(&spin.points, omega0);
    let t0 = spin.points.first().map_or(0.0, |p| p.time);
    let name = dir
        .file_name()
        .map_or_else(|| summary.model.clone(), |n| n.to_string_lossy().into());
    Ok(Run {
        name,
        summary: RunSummary {
            case: summary.model,
            dimension: summary.dimension,
            status: summary.status,
            error: summary.error,
            failure: summary.failure,
            t_stop: measured.t_stop,
            omega0,
            deceleration: measured.deceleration,
            deceleration_analytic: None,
            post_stop_max_abs_omega: measured.post_stop_max_abs_omega,
            post_stop_max_angle_change: measured.post_stop_max_angle_change,
            energy_balance_error: summary.energy_balance_error,
            energy_balance_residual_j: summary.energy_balance_residual_j,
            max_gap_violation_m: summary.max_gap_violation_m,
            max_sliding_separation_m: summary.max_sliding_separation_m,
            max_hourglass_ratio: None,
            increments: summary.increments,
            newton_iterations: summary.newton_iterations,
            contact_solves: summary.contact_solves,
            cutbacks: summary.cutbacks,
            wall_time_s: summary.wall_time_s,
        },
        history: History {
            time: spin.points.iter().map(|p| p.time - t0).collect(),
            omega: spin.points.iter().map(|p| p.omega).collect(),
            non_finite: spin.non_finite,
            ..History::default()
        },
        case: None,
    })
}

/// The body that turns most where the dynamic part of the history `text` starts, with its
/// states over that part; `path` is only used in messages.
fn turning_body(text: &str, path: &Path) -> Result<Spin, ReportError> {
    let table = CsvTable::new(text, path)?;
    let bodies: Vec<String> = table
        .header()
        .filter_map(|name| name.strip_suffix(".omega"))
        .filter(|body| table.header().any(|n| n == format!("{body}.angle")))
        .map(str::to_string)
        .collect();
    let time_column = table.column("time")?;
    let names: Vec<[String; 2]> = bodies
        .iter()
        .map(|b| [format!("{b}.angle"), format!("{b}.omega")])
        .collect();
    let columns = names
        .iter()
        .map(|[angle, omega]| Ok((table.column(angle)?, table.column(omega)?)))
        .collect::<Result<Vec<_>, ReportError>>()?;
    let (mut time, mut states) = (Vec::new(), vec![Vec::new(); bodies.len()]);
    let mut non_finite = 0;
    for row in table {
        let row = row?;
        non_finite += non_finite_fields(&row);
        time.push(row.number::<f64>(time_column)?);
        for ((angle, omega), body) in columns.iter().zip(&mut states) {
            body.push((row.number::<f64>(*angle)?, row.number::<f64>(*omega)?));
        }
    }
    let rows = dynamic_rows(&time);
    let start = rows.first().copied();
    let turning = start.and_then(|r| {
        (0..bodies.len())
            .filter(|&b| states[b][r].1 != 0.0)
            .max_by(|&a, &b| states[a][r].1.abs().total_cmp(&states[b][r].1.abs()))
    });
    let Some(b) = turning else {
        return Err(ReportError::Parse {
            path: path.to_path_buf(),
            message: "no body turns where the dynamic part starts (expected a 'B.omega' and \
                      'B.angle' column of the drum, non-zero after the static steps)"
                .into(),
        });
    };
    Ok(Spin {
        points: rows
            .iter()
            .map(|&r| SpinPoint {
                time: time[r],
                angle: states[b][r].0,
                omega: states[b][r].1,
            })
            .collect(),
        non_finite,
    })
}
