//! The report's section on cost against problem size: the measurements of
//! `scripts/scaling.py` (`scaling.json`), tabled, plotted on log scales, with the exponent `p`
//! of `cost ~ n^p` fitted to them.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::ReportError;
use super::plot::{SCALING_SVG, plot_log_log};

/// File name of the plot of peak memory against problem size.
pub const MEMORY_SVG: &str = "scaling-memory.svg";

/// `scaling.json`: how the ladder was run and one record per level and contact solve.
#[derive(Clone, Debug, Deserialize)]
pub struct ScalingStudy {
    /// The case file every level derives from.
    pub case: String,
    /// Time increment of the dynamic step, s.
    pub dt: f64,
    /// `--threads` of the runs.
    pub threads: usize,
    /// The dynamic increments of each level's run.
    pub dynamic_increments: usize,
    /// The levels.
    pub records: Vec<ScalingRecord>,
}

/// One level of one contact solve.
#[derive(Clone, Debug, Deserialize)]
pub struct ScalingRecord {
    /// `reduced` or `global`.
    pub method: String,
    /// Pad elements, circumferential x radial x axial.
    pub mesh: String,
    /// `completed`, or why not.
    pub status: String,
    /// Equations of the model.
    pub equations: Option<usize>,
    /// Contact candidates.
    pub contact_candidates: Option<usize>,
    /// Wall time of the run, s.
    pub wall_time_s: Option<f64>,
    /// Wall time per dynamic increment: the dynamic step's wall time over its increments, s.
    pub dynamic_increment_s: Option<f64>,
    /// Wall time per Newton iteration of the dynamic step, s.
    pub dynamic_iteration_s: Option<f64>,
    /// Newton iterations per dynamic increment.
    pub dynamic_newton_per_increment: Option<f64>,
    /// Factorizations (tangent, LU and preconditioner) per dynamic increment.
    pub dynamic_factorizations_per_increment: Option<f64>,
    /// GMRES iterations per dynamic increment.
    #[serde(default)]
    pub dynamic_krylov_per_increment: Option<f64>,
    /// The largest resident set of the run's process, MB.
    pub peak_memory_mb: Option<f64>,
}

/// Reads `scaling.json`.
///
/// # Errors
/// [`ReportError::Read`] or [`ReportError::Parse`] naming the file.
pub fn load(path: &Path) -> Result<ScalingStudy, ReportError> {
    let text = std::fs::read_to_string(path).map_err(|source| ReportError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    serde_json::from_str(&text).map_err(|e| ReportError::Parse {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}

/// The least-squares slope `p` of `ln y` against `ln x` over the points with positive,
/// finite coordinates, if there are two distinct `x` among them.
pub fn fitted_exponent(points: &[(f64, f64)]) -> Option<f64> {
    let logs: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0 && x.is_finite() && y.is_finite())
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    if logs.len() < 2 {
        return None;
    }
    let count = logs.len() as f64;
    let mx = logs.iter().map(|p| p.0).sum::<f64>() / count;
    let my = logs.iter().map(|p| p.1).sum::<f64>() / count;
    let sxx: f64 = logs.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = logs.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

/// The methods of `study` in the order they first appear.
fn methods(study: &ScalingStudy) -> Vec<&str> {
    let mut methods: Vec<&str> = Vec::new();
    for r in &study.records {
        if !methods.contains(&r.method.as_str()) {
            methods.push(&r.method);
        }
    }
    methods
}

/// `(equations, value)` of the completed levels of `method`.
fn points(
    study: &ScalingStudy,
    method: &str,
    value: impl Fn(&ScalingRecord) -> Option<f64>,
) -> Vec<(f64, f64)> {
    study
        .records
        .iter()
        .filter(|r| r.method == method && r.status == "completed")
        .filter_map(|r| Some((r.equations? as f64, value(r)?)))
        .collect()
}

/// The markdown section of `study` (read from `source`) and its plots, written into `dir`.
///
/// # Errors
/// [`ReportError`] if a plot cannot be written.
pub fn section(
    source: &Path,
    study: &ScalingStudy,
    dir: &Path,
) -> Result<(String, Vec<PathBuf>), ReportError> {
    let mut text = String::from("## Cost against problem size\n\n");
    let _ = writeln!(
        text,
        "`scripts/scaling.py` (`{}`): `{}` at a ladder of pad meshes (circumferential x radial \
         x axial), each level run once, with {} dynamic increments of {} s after the static \
         preload, at `--threads {}`; the cost of a dynamic increment is the dynamic step's own \
         wall time over its increments, so the preload is not counted. Peak memory: the \
         largest resident set of the run's process (the preload's included). \
         The exponent `p` of `cost ~ n^p` (n equations) is fitted by least squares over the \
         completed levels.\n",
        source.display(),
        study.case,
        study.dynamic_increments,
        study.dt,
        study.threads
    );
    let _ = writeln!(text, "![cost against equations]({SCALING_SVG})\n");
    let _ = writeln!(text, "![peak memory against equations]({MEMORY_SVG})\n");
    text.push_str(
        "| contact solve | mesh | equations | contact candidates | status | per dynamic \
         increment [s] | per Newton iteration [s] | Newton iterations per increment | \
         factorizations per increment | GMRES iterations per increment | peak memory [MB] |\n\
         |---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let number = |v: Option<f64>, digits: usize| {
        v.map_or_else(|| "n/a".to_string(), |v| format!("{v:.digits$}"))
    };
    let count = |v: Option<usize>| v.map_or_else(|| "n/a".to_string(), |v| v.to_string());
    for r in &study.records {
        let _ = writeln!(
            text,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            r.method,
            r.mesh,
            count(r.equations),
            count(r.contact_candidates),
            r.status,
            number(r.dynamic_increment_s, 4),
            number(r.dynamic_iteration_s, 4),
            number(r.dynamic_newton_per_increment, 2),
            number(r.dynamic_factorizations_per_increment, 2),
            number(r.dynamic_krylov_per_increment, 1),
            number(r.peak_memory_mb, 0),
        );
    }
    text.push('\n');
    let mut cost = Vec::new();
    let mut memory = Vec::new();
    for method in methods(study) {
        for (what, value) in [
            (
                "per dynamic increment",
                (|r: &ScalingRecord| r.dynamic_increment_s) as fn(&ScalingRecord) -> Option<f64>,
            ),
            ("per Newton iteration", |r: &ScalingRecord| {
                r.dynamic_iteration_s
            }),
        ] {
            let series = points(study, method, value);
            let p = fitted_exponent(&series);
            let shown = p.map_or_else(|| "n/a".to_string(), |p| format!("{p:.2}"));
            let _ = writeln!(text, "- {method}, time {what}: p = {shown}");
            cost.push((format!("{method}, {what} (p = {shown})"), series));
        }
        let series = points(study, method, |r| r.peak_memory_mb);
        let p = fitted_exponent(&series);
        let shown = p.map_or_else(|| "n/a".to_string(), |p| format!("{p:.2}"));
        let _ = writeln!(text, "- {method}, peak memory: p = {shown}");
        memory.push((format!("{method} (p = {shown})"), series));
    }
    let cost_svg = dir.join(SCALING_SVG);
    let memory_svg = dir.join(MEMORY_SVG);
    plot_log_log(
        "Cost against problem size",
        &cost,
        ("equations", "wall time [s]"),
        &cost_svg,
    )?;
    plot_log_log(
        "Peak memory against problem size",
        &memory,
        ("equations", "peak resident memory [MB]"),
        &memory_svg,
    )?;
    Ok((text, vec![cost_svg, memory_svg]))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The exponent of an exact power law is its power; too few points give none.
    #[test]
    fn the_fitted_exponent_of_a_power_law_is_its_power() {
        let points: Vec<(f64, f64)> = [1e2, 1e3, 1e4, 1e5]
            .iter()
            .map(|&n: &f64| (n, 3.0 * n.powf(1.4)))
            .collect();
        let p = fitted_exponent(&points).expect("fits");
        assert!((p - 1.4).abs() < 1e-12, "{p}");
        assert_eq!(fitted_exponent(&points[..1]), None);
        assert_eq!(fitted_exponent(&[(10.0, 1.0), (10.0, 2.0)]), None);
        assert_eq!(fitted_exponent(&[(10.0, 1.0), (-1.0, 2.0)]), None);
    }

    /// A study renders its table, its exponents and two plots; a failed level is listed but
    /// left out of the fit.
    #[test]
    fn a_study_renders_a_table_exponents_and_plots() {
        let record = |mesh: &str, n: usize, t: f64, status: &str| ScalingRecord {
            method: "global".into(),
            mesh: mesh.into(),
            status: status.into(),
            equations: Some(n),
            contact_candidates: Some(n / 30),
            wall_time_s: Some(10.0 * t),
            dynamic_increment_s: Some(t),
            dynamic_iteration_s: Some(t / 3.0),
            dynamic_newton_per_increment: Some(3.0),
            dynamic_factorizations_per_increment: Some(1.5),
            dynamic_krylov_per_increment: Some(9.0),
            peak_memory_mb: Some(n as f64 / 100.0),
        };
        let study = ScalingStudy {
            case: "cases/drum/3d-analytic.json".into(),
            dt: 1e-4,
            threads: 1,
            dynamic_increments: 4,
            records: vec![
                record("10 x 1 x 1", 100, 1e-3, "completed"),
                record("40 x 8 x 8", 10_000, 1e-1, "completed"),
                record("100 x 16 x 20", 100_000, 99.0, "stopped after 600 s"),
            ],
        };
        let dir = tempfile::tempdir().expect("tempdir");
        let (text, plots) =
            section(Path::new("validation/scaling.json"), &study, dir.path()).expect("renders");
        assert!(text.contains("| global | 40 x 8 x 8 | 10000 | 333 | completed | 0.1000 |"));
        assert!(text.contains("stopped after 600 s"));
        assert!(
            text.contains("- global, time per dynamic increment: p = 1.00"),
            "{text}"
        );
        assert!(text.contains("- global, peak memory: p = 1.00"), "{text}");
        assert_eq!(plots.len(), 2);
        assert!(plots.iter().all(|p| p.is_file()));
    }
}
