//! skid's reports: the validation report, the sweep report and the bench of cost against
//! error, made from the outputs that runs wrote (this crate reads them; it runs nothing but the
//! bench's own ladder of runs).
//!
//! The validation report reads runs (`<dir>/*/summary.json`, `history.csv`, `case.json`; model
//! runs of the drum scene through [`model_run`]) and
//! writes a markdown report with SVG plots next to it. Its sections, each from its own
//! directory of runs:
//!
//! - the benchmark ([`markdown`]): every run's drum spin-down against a reference run
//!   (DRUM.md section 3), with [`plot`]'s omega plots;
//! - the hard cases ([`hard`]): checks derived from each run's case;
//! - the load at which each pad formulation fails ([`pressure_limit`]);
//! - the convergence study ([`convergence`]): t_stop and e_slide against mesh and time-step
//!   refinement with observed orders, and Newton residual histories;
//! - the cost against problem size ([`scaling`]);
//! - the stress sweep of the solver ([`stress`]);
//! - the verification scenes ([`verification`]): runs of `cases/verification` against their
//!   analytic answers (Hertz contact, [`hertz`]; Coulomb friction).
//!
//! The sweep report ([`sweep`]) is a report of its own: the runs of parameter sweeps, merged
//! from the batch directories of their shards. [`mod@bench`] runs each case at a ladder of
//! time steps and methods and reports its cost beside its error.
//!
//! This module: reading runs, and the comparison math (interpolation, `e_slide`); [`mod@format`]:
//! number formatting and check lists shared by the sections.

pub mod alternation;
pub mod bench;
pub mod block_on_flat;
pub mod convergence;
pub mod format;
pub mod hard;
pub mod hertz;
pub mod markdown;
pub mod model_run;
pub mod moved_block;
pub mod pad_profile;
pub mod plot;
pub mod pressure_limit;
pub mod scaling;
pub mod stress;
pub mod sweep;
pub mod verification;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use format::Counts;

use skid_cases::atomic::write_atomic;
use skid_cases::csv_out::{CsvError, CsvTable, Row};
use skid_cases::runner::{CASE_JSON, MODEL_JSON};
use skid_cases::schema::Case;

/// The run used as reference when none is requested.
pub const DEFAULT_REFERENCE: &str = "3d-analytic-fine";

/// Errors of the report.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// A file or directory could not be read.
    #[error("{path}: cannot read: {source}")]
    Read {
        /// File or directory.
        path: PathBuf,
        /// Cause.
        source: std::io::Error,
    },
    /// A file is not what was expected.
    #[error("{path}: {message}")]
    Parse {
        /// File.
        path: PathBuf,
        /// What was expected.
        message: String,
    },
    /// No run directory (with a `summary.json`) was found.
    #[error("{0}: no runs found (expected subdirectories with summary.json and history.csv)")]
    NoRuns(PathBuf),
    /// The reference run is absent.
    #[error("{0}")]
    Reference(String),
    /// A plot could not be drawn.
    #[error("{path}: cannot draw the plot: {message}")]
    Plot {
        /// The SVG file.
        path: PathBuf,
        /// Cause.
        message: String,
    },
    /// An output could not be written.
    #[error("{path}: cannot write: {source}")]
    Write {
        /// File or directory.
        path: PathBuf,
        /// Cause.
        source: std::io::Error,
    },
}

impl From<CsvError> for ReportError {
    fn from(e: CsvError) -> Self {
        Self::Parse {
            path: e.path,
            message: e.message,
        }
    }
}

/// The fields of `summary.json` the report uses.
#[derive(Clone, Debug, Deserialize, PartialEq)]
pub struct RunSummary {
    /// Case name.
    pub case: String,
    /// Spatial dimension.
    pub dimension: usize,
    /// `"completed"` or `"failed"`.
    pub status: String,
    /// Why the run stopped early, if it did.
    #[serde(default)]
    pub error: Option<String>,
    /// The kind of failure that stopped it early (e.g. `"inverted element"`).
    #[serde(default)]
    pub failure: Option<String>,
    /// Stop time from the start of the dynamic step, s.
    pub t_stop: Option<f64>,
    /// Initial angular velocity, rad/s.
    pub omega0: f64,
    /// Least-squares deceleration over `[0.1, 0.9] t_stop`, rad/s^2.
    pub deceleration: Option<f64>,
    /// Deceleration of the analytic estimate, rad/s^2 (a drum case's; `None` for a model run).
    #[serde(default)]
    pub deceleration_analytic: Option<f64>,
    /// Largest `|omega|` after the stop, rad/s.
    pub post_stop_max_abs_omega: Option<f64>,
    /// Largest angle change after the stop, rad.
    pub post_stop_max_angle_change: Option<f64>,
    /// Relative energy balance error.
    pub energy_balance_error: Option<f64>,
    /// Energy balance residual, J.
    pub energy_balance_residual_j: Option<f64>,
    /// Deepest penetration over the run, m.
    pub max_gap_violation_m: f64,
    /// Largest gap at a contact carrying force while sliding, m.
    pub max_sliding_separation_m: f64,
    /// Largest hourglass energy / strain energy over the dynamic steps.
    #[serde(default)]
    pub max_hourglass_ratio: Option<f64>,
    /// Converged increments.
    pub increments: usize,
    /// Newton iterations.
    pub newton_iterations: usize,
    /// Conic solves.
    pub contact_solves: usize,
    /// Failed attempts answered by a cutback.
    pub cutbacks: usize,
    /// Wall time of the run, s.
    pub wall_time_s: f64,
}

/// The drum's angular velocity over the dynamic part of a run.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct History {
    /// Time from the start of the dynamic part, s (non-decreasing).
    pub time: Vec<f64>,
    /// Drum angular velocity, rad/s.
    pub omega: Vec<f64>,
    /// The contact resultants of the same rows, where the history has them (a drum case's
    /// `history.csv`); empty otherwise.
    pub contact: Vec<ContactRow>,
    /// Non-finite numbers (NaN, infinity) anywhere in the file's rows.
    pub non_finite: usize,
}

/// The contact resultants of one history row (the drum history's columns of the same names).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactRow {
    /// Total normal contact force, N.
    pub normal_force: f64,
    /// Total friction force along the first tangent (the drum's circumference), N.
    pub friction_force: f64,
    /// The contact forces' moment about the drum's axis, acting on the drum, N m.
    pub friction_torque: f64,
    /// Contacts carrying force.
    pub active_contacts: usize,
    /// Of those, contacts sliding (`|t| >= mu N` to the solver's tolerance).
    pub sliding_contacts: usize,
}

/// One run of a batch.
#[derive(Clone, Debug, PartialEq)]
pub struct Run {
    /// The run's directory name (what the report calls it).
    pub name: String,
    /// Its summary.
    pub summary: RunSummary,
    /// Its dynamic history.
    pub history: History,
    /// The case as run (`case.json`), if the run directory has it.
    pub case: Option<Case>,
}

/// Keeps the dynamic part of a history: the last row before time first advances (the state the
/// dynamics starts from), then every row where time advances, shifted to start at zero. Static
/// steps take no time, so their rows drop out. Rows beyond the shorter slice are ignored.
pub fn dynamic_part(time: &[f64], omega: &[f64]) -> History {
    let n = time.len().min(omega.len());
    let rows = dynamic_rows(&time[..n]);
    let t0 = rows.first().map_or(0.0, |&r| time[r]);
    History {
        time: rows.iter().map(|&r| time[r] - t0).collect(),
        omega: rows.iter().map(|&r| omega[r]).collect(),
        ..History::default()
    }
}

/// The rows [`dynamic_part`] keeps (none if time never advances).
pub(crate) fn dynamic_rows(time: &[f64]) -> Vec<usize> {
    let Some(first) = time.windows(2).position(|w| w[1] > w[0]) else {
        return Vec::new();
    };
    let mut rows = vec![first];
    let mut last = time[first];
    for (r, &t) in time.iter().enumerate().skip(first + 1) {
        if t > last {
            rows.push(r);
            last = t;
        }
    }
    rows
}

/// Reads `history.csv` text ([`CsvTable`]: columns found by name, `time` and `drum_omega`) and
/// keeps its dynamic part ([`dynamic_part`]), counting the non-finite numbers in every column;
/// `path` is only used in messages.
///
/// # Errors
/// [`ReportError::Parse`] naming the file, and the line and column at fault.
pub fn parse_history(text: &str, path: &Path) -> Result<History, ReportError> {
    let table = CsvTable::new(text, path)?;
    let (it, iw) = (table.column("time")?, table.column("drum_omega")?);
    let has = |name: &str| table.header().any(|n| n == name);
    let contact_columns = if CONTACT_COLUMNS.iter().all(|c| has(c)) {
        let [n, f, t, a, s] = CONTACT_COLUMNS.map(|c| table.column(c));
        Some((n?, f?, t?, a?, s?))
    } else {
        None
    };
    let (mut time, mut omega, mut contact) = (Vec::new(), Vec::new(), Vec::new());
    let mut non_finite = 0;
    for row in table {
        let row = row?;
        non_finite += non_finite_fields(&row);
        time.push(row.number(it)?);
        omega.push(row.number(iw)?);
        if let Some((n, f, t, a, s)) = contact_columns {
            contact.push(ContactRow {
                normal_force: row.number(n)?,
                friction_force: row.number(f)?,
                friction_torque: row.number(t)?,
                active_contacts: row.number(a)?,
                sliding_contacts: row.number(s)?,
            });
        }
    }
    let rows = dynamic_rows(&time);
    let contact = if contact.is_empty() {
        contact
    } else {
        rows.iter().map(|&r| contact[r]).collect()
    };
    Ok(History {
        non_finite,
        contact,
        ..dynamic_part(&time, &omega)
    })
}

/// The drum history's columns that [`ContactRow`] reads, in its field order.
const CONTACT_COLUMNS: [&str; 5] = [
    "normal_force",
    "friction_force",
    "friction_torque",
    "active_contacts",
    "sliding_contacts",
];

/// The fields of a history row that read as NaN or an infinity.
pub(crate) fn non_finite_fields(row: &Row<'_>) -> usize {
    row.fields()
        .filter_map(|f| f.trim().parse::<f64>().ok())
        .filter(|v| !v.is_finite())
        .count()
}

/// Linear interpolation of `values(times)` at `t`; `None` outside `[times[0], times[last]]`
/// or if the slices differ in length. `times` must be non-decreasing.
pub fn interpolate(times: &[f64], values: &[f64], t: f64) -> Option<f64> {
    if times.len() != values.len() {
        return None;
    }
    let (&first, &last) = (times.first()?, times.last()?);
    if !(first..=last).contains(&t) {
        return None;
    }
    let k = times.partition_point(|&x| x < t);
    if times[k] == t || k == 0 {
        return Some(values[k]);
    }
    let (t0, t1) = (times[k - 1], times[k]);
    let s = (t - t0) / (t1 - t0);
    Some(values[k - 1] + s * (values[k] - values[k - 1]))
}

/// `omega(t) - omega_ref(t)` at each of the run's times that the reference covers.
pub fn omega_difference(run: &History, reference: &History) -> Vec<(f64, f64)> {
    run.time
        .iter()
        .zip(&run.omega)
        .filter_map(|(&t, &w)| {
            interpolate(&reference.time, &reference.omega, t).map(|r| (t, w - r))
        })
        .collect()
}

/// `e_slide = max |omega(t) - omega_ref(t)| / |omega0|` over the run's times `t <= 0.9 t_stop`
/// (DRUM.md section 3); `None` if the reference does not cover that interval.
pub fn e_slide(run: &History, t_stop: f64, omega0: f64, reference: &History) -> Option<f64> {
    let mut worst = 0.0_f64;
    for (&t, &w) in run.time.iter().zip(&run.omega) {
        if t > 0.9 * t_stop {
            break;
        }
        let r = interpolate(&reference.time, &reference.omega, t)?;
        worst = worst.max((w - r).abs() / omega0.abs());
    }
    Some(worst)
}

/// The text of `path`.
///
/// # Errors
/// [`ReportError::Read`].
pub(crate) fn read(path: &Path) -> Result<String, ReportError> {
    std::fs::read_to_string(path).map_err(|source| ReportError::Read {
        path: path.to_path_buf(),
        source,
    })
}

/// Where the runs in `runs` came from: the one directory of the input files its `batch.json`
/// lists (`cases/inp` for the drum decks), else `cases/drum`, the benchmark's own.
pub(crate) fn batch_inputs(runs: &Path) -> String {
    let listed: Option<Vec<serde_json::Value>> = std::fs::read_to_string(runs.join("batch.json"))
        .ok()
        .and_then(|text| serde_json::from_str(&text).ok());
    let mut dirs: Vec<String> = listed
        .unwrap_or_default()
        .iter()
        .filter_map(|entry| entry.get("case_file")?.as_str().map(Path::new))
        .filter_map(|file| file.parent().map(|d| d.display().to_string()))
        .collect();
    dirs.sort();
    dirs.dedup();
    match dirs.as_slice() {
        [dir] if !dir.is_empty() => dir.clone(),
        _ => "cases/drum".into(),
    }
}

/// The JSON file `path` read as a `T`; `expected` says what it should be in the message of a
/// file that is not.
///
/// # Errors
/// [`ReportError::Read`], or [`ReportError::Parse`] naming the file.
pub(crate) fn read_json<T: serde::de::DeserializeOwned>(
    path: &Path,
    expected: &str,
) -> Result<T, ReportError> {
    serde_json::from_str(&read(path)?).map_err(|e| ReportError::Parse {
        path: path.to_path_buf(),
        message: format!("expected {expected}: {e}"),
    })
}

/// Reads one run directory: a drum case's run, or a model run (`model.json`, no `case.json`:
/// a model file or deck of the drum scene, see [`model_run`]).
///
/// # Errors
/// [`ReportError`] naming the file that is missing or malformed.
pub fn load_run(dir: &Path) -> Result<Run, ReportError> {
    if !dir.join(CASE_JSON).is_file() && dir.join(MODEL_JSON).is_file() {
        return model_run::load(dir);
    }
    let summary: RunSummary = read_json(&dir.join("summary.json"), "a skid run summary")?;
    let history_path = dir.join("history.csv");
    let history = parse_history(&read(&history_path)?, &history_path)?;
    let case_path = dir.join(CASE_JSON);
    let case = if case_path.is_file() {
        Some(read_json(
            &case_path,
            "the case as run (written by skid run)",
        )?)
    } else {
        None
    };
    let name = dir
        .file_name()
        .map_or_else(|| summary.case.clone(), |n| n.to_string_lossy().into());
    Ok(Run {
        name,
        summary,
        history,
        case,
    })
}

/// Reads every subdirectory of `runs` that holds a `summary.json`, sorted by name.
///
/// # Errors
/// [`ReportError`] if `runs` cannot be listed, a run is malformed, or there is none.
pub fn load_runs(runs: &Path) -> Result<Vec<Run>, ReportError> {
    let list = |source| ReportError::Read {
        path: runs.to_path_buf(),
        source,
    };
    let mut dirs = Vec::new();
    for entry in std::fs::read_dir(runs).map_err(list)? {
        let dir = entry.map_err(list)?.path();
        if dir.join("summary.json").is_file() {
            dirs.push(dir);
        }
    }
    if dirs.is_empty() {
        return Err(ReportError::NoRuns(runs.to_path_buf()));
    }
    dirs.sort();
    dirs.iter().map(|d| load_run(d)).collect()
}

/// Index of the reference run: `requested`, else [`DEFAULT_REFERENCE`], else the first run
/// whose name starts with `3d-analytic`.
///
/// # Errors
/// [`ReportError::Reference`] listing the runs present if there is no such run.
pub fn choose_reference(runs: &[Run], requested: Option<&str>) -> Result<usize, ReportError> {
    let find = |name: &str| runs.iter().position(|r| r.name == name);
    let found = match requested {
        Some(name) => find(name),
        None => find(DEFAULT_REFERENCE)
            .or_else(|| runs.iter().position(|r| r.name.starts_with("3d-analytic"))),
    };
    found.ok_or_else(|| {
        let names: Vec<&str> = runs.iter().map(|r| r.name.as_str()).collect();
        let wanted = requested.map_or_else(
            || format!("{DEFAULT_REFERENCE} or a 3d-analytic* run (pass --reference NAME)"),
            |n| format!("'{n}'"),
        );
        ReportError::Reference(format!(
            "no reference run {wanted}; runs present: {}",
            names.join(", ")
        ))
    })
}

/// Where the report's sections come from; a section is written when its directory is given.
#[derive(Clone, Copy, Debug, Default)]
pub struct ReportSources<'a> {
    /// Benchmark runs, one subdirectory per run, compared with a reference run.
    pub runs: Option<&'a Path>,
    /// The reference run among `runs` (see [`choose_reference`]).
    pub reference: Option<&'a str>,
    /// Hard-case runs, one subdirectory per run, each with its `case.json`.
    pub hard: Option<&'a Path>,
    /// The convergence study: one subdirectory per series, holding one per level.
    pub convergence: Option<&'a Path>,
    /// The measurements of cost against problem size (`scaling.json` of
    /// `scripts/scaling.py`).
    pub scaling: Option<&'a Path>,
    /// The records of the stress sweep (`stress.json` of `scripts/stress.py`).
    pub stress: Option<&'a Path>,
    /// The pad formulations' failure loads (`pressure-limit.json` of
    /// `scripts/pressure_limit.py`).
    pub pressure_limit: Option<&'a Path>,
    /// Runs of the verification scenes (`skid batch cases/verification`), one
    /// subdirectory per run.
    pub verification: Option<&'a Path>,
}

/// What [`write_report`] wrote and found.
#[derive(Clone, Debug, PartialEq)]
pub struct ReportOutcome {
    /// The reference run's name, if the benchmark section was written.
    pub reference: Option<String>,
    /// Files written: the markdown report and the plots.
    pub files: Vec<PathBuf>,
    /// Acceptance checks passed, failed and skipped, over all sections.
    pub counts: Counts,
}

/// The shell commands that regenerate a report from `sources` into `out`.
fn regenerate(sources: &ReportSources<'_>, out: &Path) -> String {
    let mut commands = Vec::new();
    let mut report = String::from("skid report");
    if let Some(runs) = sources.runs {
        commands.push(format!(
            "skid batch {} --out {}",
            batch_inputs(runs),
            runs.display()
        ));
        let _ = write!(report, " --runs {}", runs.display());
        if let Some(reference) = sources.reference {
            let _ = write!(report, " --reference {reference}");
        }
    }
    if let Some(hard) = sources.hard {
        commands.push(format!("skid batch cases/hard --out {}", hard.display()));
        let _ = write!(report, " --hard {}", hard.display());
    }
    if let Some(limit) = sources.pressure_limit {
        commands.push("scripts/pressure_limit.py".into());
        let _ = write!(report, " --pressure-limit {}", limit.display());
    }
    if let Some(convergence) = sources.convergence {
        commands.push(format!("scripts/convergence.sh {}", convergence.display()));
        let _ = write!(report, " --convergence {}", convergence.display());
    }
    if let Some(scaling) = sources.scaling {
        let dir = scaling.parent().unwrap_or(Path::new("."));
        commands.push(format!("scripts/scaling.py --out {}", dir.display()));
        let _ = write!(report, " --scaling {}", scaling.display());
    }
    if let Some(stress) = sources.stress {
        let dir = stress.parent().unwrap_or(Path::new("."));
        commands.push(format!("scripts/stress.py --results {}", dir.display()));
        let _ = write!(report, " --stress {}", stress.display());
    }
    if let Some(verification) = sources.verification {
        commands.push(format!(
            "skid batch cases/verification --out {}",
            verification.display()
        ));
        let _ = write!(report, " --verification {}", verification.display());
    }
    let _ = write!(report, " --out {}", out.display());
    commands.push(report);
    commands.join("\n")
}

/// Reads the runs named by `sources` and writes the report `out`, its plots beside it.
///
/// # Errors
/// [`ReportError`] for unreadable runs, an absent reference, a malformed convergence study, or
/// outputs that cannot be written.
pub fn write_report(sources: &ReportSources<'_>, out: &Path) -> Result<ReportOutcome, ReportError> {
    let dir = out
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir).map_err(|source| ReportError::Write {
        path: dir.to_path_buf(),
        source,
    })?;
    let mut text = format!(
        "# Braking-drum validation report\n\n\
         Written by `skid report`. To regenerate (all of it: `scripts/validate.sh`):\n\n\
         ```sh\n{}\n```\n\n",
        regenerate(sources, out)
    );
    let mut files = vec![out.to_path_buf()];
    let mut counts = Counts::default();
    let mut reference = None;
    if let Some(runs_dir) = sources.runs {
        let runs = load_runs(runs_dir)?;
        let r = choose_reference(&runs, sources.reference)?;
        let omega_svg = dir.join(plot::OMEGA_SVG);
        let difference_svg = dir.join(plot::DIFFERENCE_SVG);
        plot::plot_omega(&runs, &runs[r], &omega_svg)?;
        plot::plot_difference(&runs, &runs[r], &difference_svg)?;
        files.extend([omega_svg, difference_svg]);
        let (section, n) = markdown::render(runs_dir, &runs, r);
        text.push_str(&section);
        counts += n;
        reference = Some(runs[r].name.clone());
    }
    if let Some(hard_dir) = sources.hard {
        let runs = load_runs(hard_dir)?;
        let (section, n, plots) = hard::section(hard_dir, &runs, dir)?;
        text.push('\n');
        text.push_str(&section);
        files.extend(plots);
        counts += n;
    }
    if let Some(limit_file) = sources.pressure_limit {
        let ladder = pressure_limit::load(limit_file)?;
        let (section, n) = pressure_limit::section(limit_file, &ladder);
        text.push('\n');
        text.push_str(&section);
        counts += n;
    }
    if let Some(study_dir) = sources.convergence {
        let study = convergence::load_study(study_dir)?;
        let (section, plots) = convergence::section(study_dir, &study, dir)?;
        text.push('\n');
        text.push_str(&section);
        files.extend(plots);
    }
    if let Some(scaling_file) = sources.scaling {
        let study = scaling::load(scaling_file)?;
        let (section, plots) = scaling::section(scaling_file, &study, dir)?;
        text.push('\n');
        text.push_str(&section);
        files.extend(plots);
    }
    if let Some(stress_file) = sources.stress {
        let sweep = stress::load(stress_file)?;
        let (section, n, plots) = stress::section(stress_file, &sweep, dir)?;
        text.push('\n');
        text.push_str(&section);
        files.extend(plots);
        counts += n;
    }
    if let Some(verification_dir) = sources.verification {
        let runs = verification::load(verification_dir)?;
        let (section, n, plots) = verification::section(verification_dir, &runs, dir)?;
        text.push('\n');
        text.push_str(&section);
        files.extend(plots);
        counts += n;
    }
    let _ = write!(text, "\n## All checks\n\n{}\n", counts.line());
    write_atomic(out, &text).map_err(|source| ReportError::Write {
        path: out.to_path_buf(),
        source,
    })?;
    Ok(ReportOutcome {
        reference,
        files,
        counts,
    })
}

/// Synthetic runs for the report's unit tests.
#[cfg(test)]
pub(crate) mod test_runs {
    use super::{ContactRow, History, Run, RunSummary};

    /// A completed 3D run whose drum decelerates from 60 rad/s at `decel` rad/s^2, sampled
    /// every millisecond to 0.15 s and held at zero after the stop, with a summary that says
    /// so (post-stop motion 2 rad/s and 0.01 rad, energy error 0.1 %, no case), and the
    /// contact resultants of the benchmark's drum (I = 0.175 kg m^2, R = 0.2 m, mu = 0.15):
    /// six contacts sliding with the torque that decelerates it into each row until the stop,
    /// sticking after it.
    pub(crate) fn spin_down(name: &str, decel: f64) -> Run {
        let time: Vec<f64> = (0..=150).map(|k| k as f64 * 1e-3).collect();
        let omega: Vec<f64> = time.iter().map(|t| (60.0 - decel * t).max(0.0)).collect();
        let (inertia, radius, mu) = (0.175, 0.2, 0.15);
        let contact = (0..time.len())
            .map(|k| {
                // the torque that takes the drum from the previous row to this one
                let torque = if k == 0 {
                    0.0
                } else {
                    inertia * (omega[k] - omega[k - 1]) / (time[k] - time[k - 1])
                };
                let slides = torque != 0.0;
                let friction = torque.abs() / radius;
                ContactRow {
                    normal_force: if slides { friction / mu } else { 3500.0 },
                    friction_force: friction,
                    friction_torque: torque,
                    active_contacts: 6,
                    sliding_contacts: if slides { 6 } else { 0 },
                }
            })
            .collect();
        Run {
            name: name.into(),
            summary: RunSummary {
                case: name.into(),
                dimension: 3,
                status: "completed".into(),
                error: None,
                failure: None,
                t_stop: (decel > 0.0).then(|| 60.0 / decel),
                omega0: 60.0,
                deceleration: Some(decel),
                deceleration_analytic: Some(600.0),
                post_stop_max_abs_omega: Some(2.0),
                post_stop_max_angle_change: Some(0.01),
                energy_balance_error: Some(1e-3),
                energy_balance_residual_j: Some(0.3),
                max_gap_violation_m: 1e-12,
                max_sliding_separation_m: 1e-12,
                max_hourglass_ratio: Some(0.005),
                increments: 1500,
                newton_iterations: 3000,
                contact_solves: 3000,
                cutbacks: 0,
                wall_time_s: 1.5,
            },
            history: History {
                time,
                omega,
                contact,
                non_finite: 0,
            },
            case: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The regenerating command names the directory the batch's inputs came from.
    #[test]
    fn the_batch_inputs_are_named_by_their_directory() {
        let dir = tempfile::tempdir().expect("tempdir");
        assert_eq!(batch_inputs(dir.path()), "cases/drum");
        let listed = r#"[{"case_file": "cases/inp/2d-analytic.inp"},
                         {"case_file": "cases/inp/3d-r3d4.inp"}]"#;
        std::fs::write(dir.path().join("batch.json"), listed).expect("write");
        assert_eq!(batch_inputs(dir.path()), "cases/inp");
        let mixed = r#"[{"case_file": "cases/inp/2d-analytic.inp"},
                        {"case_file": "cases/drum/3d-r3d4.json"}]"#;
        std::fs::write(dir.path().join("batch.json"), mixed).expect("write");
        assert_eq!(batch_inputs(dir.path()), "cases/drum");
    }

    fn linear(omega0: f64, decel: f64, dt: f64, n: usize) -> History {
        let time: Vec<f64> = (0..=n).map(|k| k as f64 * dt).collect();
        let omega = time.iter().map(|t| omega0 - decel * t).collect();
        History {
            time,
            omega,
            ..History::default()
        }
    }

    #[test]
    fn interpolation_is_exact_on_lines_and_undefined_outside() {
        let h = History {
            time: vec![0.0, 1.0, 3.0],
            omega: vec![10.0, 8.0, 0.0],
            ..History::default()
        };
        assert_eq!(interpolate(&h.time, &h.omega, 0.0), Some(10.0));
        assert_eq!(interpolate(&h.time, &h.omega, 0.5), Some(9.0));
        assert_eq!(interpolate(&h.time, &h.omega, 2.0), Some(4.0));
        assert_eq!(interpolate(&h.time, &h.omega, 3.0), Some(0.0));
        assert_eq!(interpolate(&h.time, &h.omega, 3.5), None);
        assert_eq!(interpolate(&h.time, &h.omega, -0.1), None);
        assert_eq!(interpolate(&[], &[], 0.0), None);
        assert_eq!(interpolate(&h.time, &h.omega[..2], 0.5), None);
    }

    #[test]
    fn e_slide_of_a_steeper_line_is_the_gap_at_ninety_percent_of_its_stop() {
        // Reference 60 - 600 t on a fine grid; run 60 - 606 t on a coarser, offset grid.
        let reference = linear(60.0, 600.0, 1e-4, 1500);
        let run = linear(60.0, 606.0, 3e-4, 500);
        let t_stop = 60.0 / 606.0;
        // The largest gap 6 t is at the last sample with t <= 0.9 t_stop.
        let last = run
            .time
            .iter()
            .copied()
            .filter(|&t| t <= 0.9 * t_stop)
            .fold(0.0, f64::max);
        let e = e_slide(&run, t_stop, 60.0, &reference).expect("covered");
        assert!((e - 6.0 * last / 60.0).abs() < 1e-12, "{e}");
        assert!(e > 0.0085 && e < 0.0091, "{e}");
        assert_eq!(e_slide(&reference, 0.1, 60.0, &reference), Some(0.0));
    }

    #[test]
    fn e_slide_needs_a_reference_that_covers_the_sliding_phase() {
        let reference = linear(60.0, 600.0, 1e-3, 50);
        let run = linear(60.0, 600.0, 1e-3, 150);
        assert_eq!(e_slide(&run, 0.1, 60.0, &reference), None);
    }

    #[test]
    fn difference_is_taken_where_the_reference_is_defined() {
        let reference = linear(60.0, 600.0, 1e-3, 10);
        let run = linear(61.0, 600.0, 2e-3, 10);
        let d = omega_difference(&run, &reference);
        assert_eq!(d.len(), 6);
        assert!(d.iter().all(|&(_, e)| (e - 1.0).abs() < 1e-12));
    }

    #[test]
    fn history_keeps_the_dynamic_rows_from_the_state_the_dynamics_starts_from() {
        let text = "time,step,drum_omega\n\
                    0.0,initial,60\n\
                    0.0,preload,60\n\
                    0.0,preload,60.5\n\
                    0.5,spin,50\n\
                    1.0,spin,40\n\
                    1.0,settle,41\n";
        let h = parse_history(text, Path::new("h.csv")).expect("parses");
        assert_eq!(h.time, vec![0.0, 0.5, 1.0]);
        assert_eq!(h.omega, vec![60.5, 50.0, 40.0]);
    }

    #[test]
    fn a_quoted_step_name_with_commas_leaves_the_columns_in_place() {
        let text = "time,step,drum_omega\n\
                    0.0,preload,60\n\
                    0.5,\"spin, down \"\"fast\"\"\",50\n\
                    1.0,\"spin, down \"\"fast\"\"\",40\n";
        let h = parse_history(text, Path::new("h.csv")).expect("parses");
        assert_eq!(h.time, vec![0.0, 0.5, 1.0]);
        assert_eq!(h.omega, vec![60.0, 50.0, 40.0]);
    }

    #[test]
    fn malformed_histories_name_the_file_line_and_column() {
        let e = parse_history("time,x\n0,1\n", Path::new("run/history.csv"))
            .expect_err("no omega column");
        assert_eq!(
            e.to_string(),
            "run/history.csv: no column 'drum_omega' in the header"
        );
        let e = parse_history(
            "time,drum_omega\n0,1\n0.1,oops\n",
            Path::new("run/history.csv"),
        )
        .expect_err("not a number");
        assert_eq!(
            e.to_string(),
            "run/history.csv: line 3: expected a number in 'drum_omega'"
        );
    }

    fn run(name: &str) -> Run {
        test_runs::spin_down(name, 600.0)
    }

    #[test]
    fn the_reference_defaults_to_the_fine_run_then_to_the_first_analytic_3d_run() {
        let runs = [
            run("2d-analytic"),
            run("3d-analytic"),
            run("3d-analytic-fine"),
        ];
        assert_eq!(choose_reference(&runs, None).expect("fine"), 2);
        assert_eq!(choose_reference(&runs[..2], None).expect("pair"), 1);
        assert_eq!(
            choose_reference(&runs, Some("2d-analytic")).expect("asked"),
            0
        );
        let e = choose_reference(&runs[..1], None).expect_err("none");
        assert!(e.to_string().contains("2d-analytic"), "{e}");
        assert!(choose_reference(&runs, Some("nope")).is_err());
    }
}
