//! The report's section on the stress sweep of the solver: the records of `scripts/stress.py`
//! (`stress.json`: one short run per record, drawn at random over the drum cases and the
//! block scenes, each classified by the script), summed per outcome, scene and diagnosis,
//! with the energy balance of the completed runs plotted against their time step, and
//! checks that the record is whole and says what the sweep must show: no crash, no silently
//! wrong completed run, a diagnosis for every failure, and every completed run's energy
//! balance within the sweep's own limit.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::format::{Checks, Counts, Sig, plain};
use super::plot::{STRESS_SVG, plot_scatter_log_log};
use super::{ReportError, read_json};

/// How a run of the sweep ended, as `scripts/stress.py` classified it.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq, PartialOrd, Ord)]
#[serde(rename_all = "lowercase")]
pub enum Outcome {
    /// Exit status 0 and every check of its outputs passed.
    Completed,
    /// Completed and passed the checks, with a warning in its summary (the time integration
    /// removed much of the energy).
    Warned,
    /// Stopped early (exit status 1) or refused its input (2), with a message.
    Failed,
    /// Stopped by the sweep's timeout.
    Timeout,
    /// Killed by a signal, panicked, an unexpected exit status, or a failure without a message.
    Crashed,
    /// Completed, but an output check failed.
    #[serde(rename = "silently wrong")]
    SilentlyWrong,
}

impl Outcome {
    /// Every outcome, in the order of the tables.
    pub const ALL: [Self; 6] = [
        Self::Completed,
        Self::Warned,
        Self::Failed,
        Self::Timeout,
        Self::Crashed,
        Self::SilentlyWrong,
    ];

    /// The name `stress.json` gives it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Completed => "completed",
            Self::Warned => "warned",
            Self::Failed => "failed",
            Self::Timeout => "timeout",
            Self::Crashed => "crashed",
            Self::SilentlyWrong => "silently wrong",
        }
    }

    /// Whether the run ended with outputs that were checked (completed, warned or wrong).
    fn checked(self) -> bool {
        matches!(self, Self::Completed | Self::Warned | Self::SilentlyWrong)
    }
}

/// `stress.json`: how the sweep was run and one record per run.
#[derive(Clone, Debug, Deserialize)]
pub struct StressSweep {
    /// The command that ran it.
    pub command: String,
    /// Runs asked for.
    pub runs: usize,
    /// Parallel runs.
    pub jobs: usize,
    /// Timeout per run, s.
    pub timeout_s: f64,
    /// Wall time of the whole sweep, s.
    pub total_wall_s: f64,
    /// Runs per outcome name, as the script counted them.
    pub counts: BTreeMap<String, usize>,
    /// The limits of the script's checks.
    pub thresholds: StressThresholds,
    /// The runs.
    pub records: Vec<StressRecord>,
}

/// The limits of the sweep's checks that this section checks again.
#[derive(Clone, Copy, Debug, Deserialize)]
pub struct StressThresholds {
    /// Largest energy balance residual of a completed run, relative to the energy in play.
    pub energy_relative: f64,
}

/// One run of the sweep.
#[derive(Clone, Debug, Deserialize)]
pub struct StressRecord {
    /// Its position in the sweep (its seed is the sweep's seed and this).
    pub index: usize,
    /// The case or model file's name.
    pub scene: String,
    /// How it ended.
    pub outcome: Outcome,
    /// The class of a failure (`stopped: inverted element`, `refused: ...`).
    #[serde(default)]
    pub diagnosis: Option<String>,
    /// The run's last words on stderr.
    #[serde(default)]
    pub message: String,
    /// The parameters drawn.
    pub params: StressParams,
    /// What the checks measured, for runs that completed.
    #[serde(default)]
    pub measures: Option<StressMeasures>,
    /// Wall time of the run, s.
    pub wall_s: f64,
}

/// The drawn parameters this section shows.
#[derive(Clone, Copy, Debug, Deserialize)]
pub struct StressParams {
    /// Time increment of the dynamic step, s.
    pub dt: f64,
}

/// The measures of a completed run this section shows.
#[derive(Clone, Copy, Debug, Deserialize)]
pub struct StressMeasures {
    /// Energy balance residual relative to the energy in play.
    #[serde(default)]
    pub energy_error: Option<f64>,
}

/// Reads `stress.json`.
///
/// # Errors
/// [`ReportError::Read`] or [`ReportError::Parse`] naming the file.
pub fn load(path: &Path) -> Result<StressSweep, ReportError> {
    read_json(path, "the stress sweep written by scripts/stress.py")
}

/// Plotted energy errors below this are drawn at it (a log axis has no zero).
const ENERGY_FLOOR: f64 = 1e-16;

/// Runs of `records` per outcome.
fn tally<'a>(records: impl Iterator<Item = &'a StressRecord>) -> BTreeMap<Outcome, usize> {
    let mut counts: BTreeMap<Outcome, usize> = Outcome::ALL.iter().map(|&o| (o, 0)).collect();
    for r in records {
        *counts.entry(r.outcome).or_default() += 1;
    }
    counts
}

/// The checks of `sweep`: the record is whole and consistent, and it shows what the sweep
/// must.
fn checks(sweep: &StressSweep) -> Checks {
    let mut checks = Checks::default();
    let mut seen = vec![false; sweep.runs];
    let mut misplaced = 0;
    for r in &sweep.records {
        match seen.get_mut(r.index) {
            Some(s) if !*s => *s = true,
            _ => misplaced += 1,
        }
    }
    let missing = seen.iter().filter(|s| !**s).count();
    checks.record(
        "every run of the sweep has one record",
        missing == 0 && misplaced == 0,
        format!(
            "{} records of {} runs, {missing} missing, {misplaced} out of range or repeated",
            sweep.records.len(),
            sweep.runs
        ),
    );
    let counts = tally(sweep.records.iter());
    let differing: Vec<String> = Outcome::ALL
        .iter()
        .filter(|o| sweep.counts.get(o.name()).copied().unwrap_or(0) != counts[o])
        .map(|o| o.name().to_string())
        .chain(
            sweep
                .counts
                .keys()
                .filter(|k| !Outcome::ALL.iter().any(|o| o.name() == k.as_str()))
                .cloned(),
        )
        .collect();
    checks.record(
        "the counts of stress.json are those of its records",
        differing.is_empty(),
        if differing.is_empty() {
            "equal".into()
        } else {
            format!("differ in {}", differing.join(", "))
        },
    );
    let listed = |outcome: Outcome| {
        let runs: Vec<String> = sweep
            .records
            .iter()
            .filter(|r| r.outcome == outcome)
            .map(|r| r.index.to_string())
            .collect();
        if runs.is_empty() {
            "none".to_string()
        } else {
            format!("{} (runs {})", runs.len(), runs.join(", "))
        }
    };
    checks.record(
        "no run crashed",
        counts[&Outcome::Crashed] == 0,
        listed(Outcome::Crashed),
    );
    checks.record(
        "no completed run is silently wrong",
        counts[&Outcome::SilentlyWrong] == 0,
        listed(Outcome::SilentlyWrong),
    );
    let mute: Vec<String> = sweep
        .records
        .iter()
        .filter(|r| r.outcome == Outcome::Failed && r.message.trim().is_empty())
        .map(|r| r.index.to_string())
        .collect();
    checks.record(
        "every failed run says why",
        mute.is_empty(),
        if mute.is_empty() {
            format!(
                "{} failed runs, each with a message",
                counts[&Outcome::Failed]
            )
        } else {
            format!("no message from runs {}", mute.join(", "))
        },
    );
    let limit = sweep.thresholds.energy_relative;
    let (mut worst, mut over, mut unmeasured) = (0.0_f64, Vec::new(), Vec::new());
    for r in sweep
        .records
        .iter()
        .filter(|r| matches!(r.outcome, Outcome::Completed | Outcome::Warned))
    {
        match r.measures.and_then(|m| m.energy_error) {
            Some(e) if e.is_finite() => {
                worst = worst.max(e);
                if e > limit {
                    over.push(r.index.to_string());
                }
            }
            _ => unmeasured.push(r.index.to_string()),
        }
    }
    checks.record(
        &format!(
            "every run passed as completed has its energy balance within {} % of the energy \
             in play",
            plain(100.0 * limit)
        ),
        over.is_empty() && unmeasured.is_empty(),
        format!(
            "worst {}{}{}",
            Sig(worst),
            if over.is_empty() {
                String::new()
            } else {
                format!("; over the limit: runs {}", over.join(", "))
            },
            if unmeasured.is_empty() {
                String::new()
            } else {
                format!("; not measured: runs {}", unmeasured.join(", "))
            }
        ),
    );
    checks
}

/// The markdown section of `sweep` (read from `source`), its plot written into `dir`, and its
/// check counts.
///
/// # Errors
/// [`ReportError`] if the plot cannot be written.
pub fn section(
    source: &Path,
    sweep: &StressSweep,
    dir: &Path,
) -> Result<(String, Counts, Vec<PathBuf>), ReportError> {
    let mut text = String::from("## Stress sweep\n\n");
    let details = source.with_extension("md");
    let _ = writeln!(
        text,
        "`{}` (`{}`): {} short runs of `skid run` with random friction, pressure, time step, \
         speed, mesh and solver settings over the drum cases and the block scenes, {} at a \
         time with a {} s timeout each, {:.1} min of wall time in all. `{}` lists every \
         flagged run with the command that repeats it.\n",
        sweep.command,
        source.display(),
        sweep.records.len(),
        sweep.jobs,
        plain(sweep.timeout_s),
        sweep.total_wall_s / 60.0,
        details.display()
    );
    let mut scenes: BTreeMap<&str, Vec<&StressRecord>> = BTreeMap::new();
    for r in &sweep.records {
        scenes.entry(&r.scene).or_default().push(r);
    }
    text.push_str("| scene | runs |");
    for o in Outcome::ALL {
        let _ = write!(text, " {} |", o.name());
    }
    text.push_str(" wall [s] |\n|---|---|");
    text.push_str(&"---|".repeat(Outcome::ALL.len() + 1));
    text.push('\n');
    let mut row = |name: &str, records: &[&StressRecord]| {
        let counts = tally(records.iter().copied());
        let _ = write!(text, "| {name} | {} |", records.len());
        for o in Outcome::ALL {
            let _ = write!(text, " {} |", counts[&o]);
        }
        let wall: f64 = records.iter().map(|r| r.wall_s).sum();
        let _ = writeln!(text, " {wall:.0} |");
    };
    for (scene, records) in &scenes {
        row(scene, records);
    }
    let all: Vec<&StressRecord> = sweep.records.iter().collect();
    row("**all**", &all);
    text.push('\n');

    let mut diagnoses: BTreeMap<&str, (usize, usize)> = BTreeMap::new();
    for r in sweep
        .records
        .iter()
        .filter(|r| r.outcome == Outcome::Failed)
    {
        let key = r.diagnosis.as_deref().unwrap_or("(none)");
        diagnoses.entry(key).or_insert((0, r.index)).0 += 1;
    }
    if !diagnoses.is_empty() {
        let mut by_count: Vec<(&str, (usize, usize))> = diagnoses.into_iter().collect();
        by_count.sort_by(|a, b| b.1.0.cmp(&a.1.0).then(a.0.cmp(b.0)));
        text.push_str("| failure diagnosis | runs | first run |\n|---|---|---|\n");
        for (diagnosis, (count, first)) in by_count {
            let _ = writeln!(
                text,
                "| {} | {count} | {first} |",
                diagnosis.replace('|', "\\|")
            );
        }
        text.push('\n');
    }

    let mut series: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    for outcome in Outcome::ALL.into_iter().filter(|o| o.checked()) {
        let points: Vec<(f64, f64)> = sweep
            .records
            .iter()
            .filter(|r| r.outcome == outcome)
            .filter_map(|r| {
                let e = r.measures?.energy_error?;
                Some((r.params.dt, e.max(ENERGY_FLOOR)))
            })
            .collect();
        if !points.is_empty() {
            series.push((format!("{} ({})", outcome.name(), points.len()), points));
        }
    }
    let svg = dir.join(STRESS_SVG);
    plot_scatter_log_log(
        "Stress sweep: energy balance of the completed runs",
        &series,
        ("time step [s]", "energy residual / energy in play"),
        Some((
            format!(
                "limit {} %",
                plain(100.0 * sweep.thresholds.energy_relative)
            ),
            sweep.thresholds.energy_relative,
        )),
        &svg,
    )?;
    let _ = writeln!(
        text,
        "![energy balance against time step]({STRESS_SVG})\n\nEach completed run's energy \
         balance residual (with the time integration's own dissipation counted) over the \
         energy in play, against its time step; residuals below {ENERGY_FLOOR:e} are drawn \
         at it.\n"
    );
    let checks = checks(sweep);
    text.push_str(&checks.text);
    let _ = writeln!(text, "\n{}", checks.counts.line());
    Ok((text, checks.counts, vec![svg]))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(index: usize, scene: &str, outcome: Outcome, energy: Option<f64>) -> StressRecord {
        StressRecord {
            index,
            scene: scene.into(),
            outcome,
            diagnosis: (outcome == Outcome::Failed).then(|| "stopped: inverted element".into()),
            message: if outcome == Outcome::Failed {
                "skid: run stopped early: element 0 inverted".into()
            } else {
                String::new()
            },
            params: StressParams {
                dt: 1e-4 * (1 + index) as f64,
            },
            measures: energy.map(|e| StressMeasures {
                energy_error: Some(e),
            }),
            wall_s: 0.5,
        }
    }

    fn sweep(records: Vec<StressRecord>) -> StressSweep {
        let counts = tally(records.iter())
            .into_iter()
            .map(|(o, n)| (o.name().to_string(), n))
            .collect();
        StressSweep {
            command: "scripts/stress.py --runs 4 --seed 1 --jobs 2".into(),
            runs: records.len(),
            jobs: 2,
            timeout_s: 60.0,
            total_wall_s: 2.0,
            counts,
            thresholds: StressThresholds {
                energy_relative: 0.05,
            },
            records,
        }
    }

    fn clean() -> StressSweep {
        sweep(vec![
            record(0, "2d-analytic", Outcome::Completed, Some(1e-9)),
            record(1, "2d-analytic", Outcome::Failed, None),
            record(2, "3d-r3d4", Outcome::Warned, Some(0.0)),
            record(3, "3d-r3d4", Outcome::Timeout, None),
        ])
    }

    /// A clean sweep renders its tables and plot, and passes every check.
    #[test]
    fn a_clean_sweep_passes_its_checks() {
        let dir = tempfile::tempdir().expect("tempdir");
        let (text, counts, plots) =
            section(Path::new("validation/stress.json"), &clean(), dir.path()).expect("renders");
        assert_eq!(counts.failed, 0, "{text}");
        assert_eq!(counts.passed, 6, "{text}");
        assert!(
            text.contains("| 2d-analytic | 2 | 1 | 0 | 1 | 0 | 0 | 0 | 1 |"),
            "{text}"
        );
        assert!(
            text.contains("| **all** | 4 | 1 | 1 | 1 | 1 | 0 | 0 | 2 |"),
            "{text}"
        );
        assert!(
            text.contains("| stopped: inverted element | 1 | 1 |"),
            "{text}"
        );
        assert!(text.contains("validation/stress.md"), "{text}");
        assert!(plots.iter().all(|p| p.is_file()));
    }

    /// Each defect of a sweep fails the check that names it, and only that one.
    #[test]
    fn each_defect_fails_its_own_check() {
        let failing = |sweep: &StressSweep| -> Vec<String> {
            let checks = checks(sweep);
            checks
                .text
                .lines()
                .filter(|l| l.starts_with("- **FAIL**"))
                .map(str::to_string)
                .collect()
        };
        assert!(failing(&clean()).is_empty());

        let mut crashed = clean();
        crashed.records[1].outcome = Outcome::Crashed;
        crashed.counts = sweep(crashed.records.clone()).counts;
        let f = failing(&crashed);
        assert_eq!(f.len(), 1, "{f:?}");
        assert!(
            f[0].contains("no run crashed") && f[0].contains("runs 1"),
            "{f:?}"
        );

        let mut wrong = clean();
        wrong.records[0].outcome = Outcome::SilentlyWrong;
        wrong.counts = sweep(wrong.records.clone()).counts;
        let f = failing(&wrong);
        assert_eq!(f.len(), 1, "{f:?}");
        assert!(f[0].contains("silently wrong"), "{f:?}");

        let mut miscounted = clean();
        miscounted.counts.insert("crashed".into(), 1);
        let f = failing(&miscounted);
        assert_eq!(f.len(), 1, "{f:?}");
        assert!(f[0].contains("differ in crashed"), "{f:?}");

        let mut short = clean();
        short.runs = 5;
        let f = failing(&short);
        assert_eq!(f.len(), 1, "{f:?}");
        assert!(f[0].contains("1 missing"), "{f:?}");

        let mut repeated = clean();
        repeated.records[3].index = 2;
        let f = failing(&repeated);
        assert_eq!(f.len(), 1, "{f:?}");
        assert!(
            f[0].contains("1 missing, 1 out of range or repeated"),
            "{f:?}"
        );

        let mut mute = clean();
        mute.records[1].message = " ".into();
        let f = failing(&mute);
        assert_eq!(f.len(), 1, "{f:?}");
        assert!(f[0].contains("no message from runs 1"), "{f:?}");

        let mut lossy = clean();
        lossy.records[2].measures = Some(StressMeasures {
            energy_error: Some(0.2),
        });
        let f = failing(&lossy);
        assert_eq!(f.len(), 1, "{f:?}");
        assert!(f[0].contains("over the limit: runs 2"), "{f:?}");

        let mut unmeasured = clean();
        unmeasured.records[0].measures = None;
        let f = failing(&unmeasured);
        assert_eq!(f.len(), 1, "{f:?}");
        assert!(f[0].contains("not measured: runs 0"), "{f:?}");
    }

    /// The outcome names are those of `scripts/stress.py`; an unknown one is refused.
    #[test]
    fn outcomes_read_by_their_script_names() {
        for o in Outcome::ALL {
            let read: Outcome = serde_json::from_str(&format!("\"{}\"", o.name())).expect("reads");
            assert_eq!(read, o);
        }
        assert!(serde_json::from_str::<Outcome>("\"exploded\"").is_err());
    }
}
