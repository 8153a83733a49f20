//! The convergence section: t_stop and e_slide against mesh and time-step refinement, with the
//! observed order of convergence, and the Newton residual history of an increment.
//!
//! A study is a directory with one subdirectory per series, each holding one run directory per
//! level (`scripts/convergence.sh` writes one). What a series refines is read from the levels'
//! `case.json`: their cases must differ only in the pad mesh or only in the time step. The
//! level size `h` is the time step, or the element length along the circumference (the
//! sliding direction) `L / n_circumferential`, whether the other directions are refined with
//! it (uniform refinement) or not; levels are sorted from coarse to fine.
//!
//! Observed order from three levels refined by the ratio `r = h1/h2 = h2/h3`:
//! `p = ln(|f1 - f2| / |f2 - f3|) / ln r`, and the Richardson extrapolation
//! `f3 + (f3 - f2) / (r^p - 1)`. For the angular velocity history the differences are the
//! max norms `d12 = max |omega1 - omega2| / omega0` over `t <= 0.9 t_stop` of the coarser run
//! (the finer interpolated at the coarser's times, [`e_slide`]).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde_json::Value;

use super::format::{Sig, percent, show};
use super::plot::{NEWTON_SVG, plot_newton};
use super::{ReportError, Run, e_slide, load_runs};
use skid_cases::csv_out::CsvTable;
use skid_cases::newton::{CONVERGED, NEWTON_CSV};
use skid_cases::schema::{Case, StepSpec};

/// What the levels of a series refine.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Refinement {
    /// The pad mesh.
    Mesh,
    /// The time step of the dynamic steps.
    TimeStep,
}

/// One level of a series.
#[derive(Clone, Debug)]
pub struct Level {
    /// The run.
    pub run: Run,
    /// Its size: circumferential element length or time step.
    pub h: f64,
    /// Its element counts or time step, as text.
    pub label: String,
}

/// A series of levels, coarse to fine.
#[derive(Clone, Debug)]
pub struct Series {
    /// The series' directory name.
    pub name: String,
    /// What it refines.
    pub refinement: Refinement,
    /// Its levels, coarse to fine.
    pub levels: Vec<Level>,
    /// The Newton residuals of the coarsest level's hardest dynamic increment.
    pub newton: Option<NewtonIncrement>,
}

/// The Newton residuals of one increment (`newton.csv`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NewtonIncrement {
    /// Step name.
    pub step: String,
    /// Increment number within the step.
    pub increment: usize,
    /// Time at its end, s.
    pub time: f64,
    /// Scaled force residual after each Newton iteration.
    pub force: Vec<f64>,
    /// Scaled contact residual after each Newton iteration.
    pub contact: Vec<f64>,
}

/// Observed order of convergence from three levels refined by the constant ratio `r > 1`:
/// `ln(|f1 - f2| / |f2 - f3|) / ln r`; `None` if a difference vanishes or is not finite.
pub fn observed_order(f1: f64, f2: f64, f3: f64, r: f64) -> Option<f64> {
    order_of_differences((f1 - f2).abs(), (f2 - f3).abs(), r)
}

/// Observed order from the sizes `d12 >= 0`, `d23 >= 0` of two successive differences
/// between levels refined by the ratio `r > 1`: `ln(d12 / d23) / ln r`.
pub fn order_of_differences(d12: f64, d23: f64, r: f64) -> Option<f64> {
    let p = (d12 / d23).ln() / r.ln();
    (d12 > 0.0 && d23 > 0.0 && r > 1.0 && p.is_finite()).then_some(p)
}

/// Richardson extrapolation of the finest two of three levels, `f3 + (f3 - f2) / (r^p - 1)`;
/// `None` unless `p > 0` (the levels converge).
pub fn richardson(f2: f64, f3: f64, r: f64, p: f64) -> Option<f64> {
    let f = f3 + (f3 - f2) / (r.powf(p) - 1.0);
    (p > 0.0 && f.is_finite()).then_some(f)
}

/// Convergence order of an iteration from its residuals `e_k`:
/// `q_k = ln(e_{k+1} / e_k) / ln(e_k / e_{k-1})` for `k = 1 .. n-2` (2 for quadratic
/// convergence, 1 for linear); `None` where a residual is zero or the ratio is undefined.
pub fn iteration_orders(e: &[f64]) -> Vec<Option<f64>> {
    e.windows(3)
        .map(|w| {
            let q = (w[2] / w[1]).ln() / (w[1] / w[0]).ln();
            (w.iter().all(|&x| x > 0.0) && q.is_finite()).then_some(q)
        })
        .collect()
}

/// The case without the fields a convergence series may vary (and the labels).
fn invariant_part(case: &Case) -> Value {
    let mut v = serde_json::to_value(case).unwrap_or(Value::Null);
    if let Some(o) = v.as_object_mut() {
        for key in ["name", "description", "expect"] {
            o.remove(key);
        }
    }
    if let Some(pad) = v.get_mut("pad").and_then(Value::as_object_mut) {
        pad.remove("elements");
    }
    if let Some(steps) = v.get_mut("steps").and_then(Value::as_array_mut) {
        for step in steps.iter_mut().filter_map(Value::as_object_mut) {
            step.remove("dt");
        }
    }
    v
}

/// The time steps of the case's dynamic steps, in order.
pub(crate) fn time_steps(case: &Case) -> Vec<f64> {
    case.steps
        .iter()
        .filter_map(|s| match s {
            StepSpec::Dynamic { dt, .. } => Some(*dt),
            StepSpec::Static { .. } => None,
        })
        .collect()
}

fn dynamic_steps(case: &Case) -> Vec<&str> {
    case.steps
        .iter()
        .filter_map(|s| match s {
            StepSpec::Dynamic { name, .. } => Some(name.as_str()),
            StepSpec::Static { .. } => None,
        })
        .collect()
}

/// The element length along the circumference, `L / n_circumferential`.
fn element_length(case: &Case) -> f64 {
    case.pad.length / case.pad.elements.circumferential as f64
}

/// The pad's element counts, `circumferential x radial [x axial]` (the axial count in 3D).
pub(crate) fn pad_mesh_label(case: &Case) -> String {
    let e = &case.pad.elements;
    if case.dimension == 3 {
        format!("{} x {} x {}", e.circumferential, e.radial, e.axial)
    } else {
        format!("{} x {}", e.circumferential, e.radial)
    }
}

/// What a level is: its element counts, or its time steps.
fn level_label(case: &Case, refinement: Refinement) -> String {
    match refinement {
        Refinement::Mesh => pad_mesh_label(case),
        Refinement::TimeStep => time_steps(case)
            .iter()
            .map(|dt| format!("dt {}", Sig(*dt)))
            .collect::<Vec<_>>()
            .join(", "),
    }
}

/// What `cases` refine: they must differ in the mesh or in the time step, not both, and in
/// nothing else.
///
/// # Errors
/// What else differs, naming two levels.
fn refinement(names: &[&str], cases: &[&Case]) -> Result<Refinement, String> {
    let first = cases.first().ok_or("no levels")?;
    let base = invariant_part(first);
    if let Some(k) = cases.iter().position(|c| invariant_part(c) != base) {
        return Err(format!(
            "levels {} and {} differ in more than the pad mesh and the time step",
            names[0], names[k]
        ));
    }
    let mesh = cases.iter().any(|c| c.pad.elements != first.pad.elements);
    let dt = cases.iter().any(|c| time_steps(c) != time_steps(first));
    match (mesh, dt) {
        (true, false) => Ok(Refinement::Mesh),
        (false, true) => Ok(Refinement::TimeStep),
        (true, true) => Err("levels differ in both the pad mesh and the time step".into()),
        (false, false) => Err("levels do not differ in the pad mesh nor the time step".into()),
    }
}

/// Parses `newton.csv` text ([`CsvTable`]: columns found by name) and keeps the increment of a
/// dynamic step (named in `dynamic`) with the most Newton iterations, the earliest of equals,
/// among the converged increments (a `status` column, where there is one, says which rows are
/// theirs); `None` if there is none. `path` is only used in messages.
///
/// # Errors
/// [`ReportError::Parse`] naming the file, and the line or column at fault.
pub fn hardest_increment(
    text: &str,
    path: &Path,
    dynamic: &[&str],
) -> Result<Option<NewtonIncrement>, ReportError> {
    let table = CsvTable::new(text, path)?;
    let (is, ii, it, ie, ic) = (
        table.column("step")?,
        table.column("increment")?,
        table.column("time")?,
        table.column("force_residual")?,
        table.column("contact_residual")?,
    );
    // the checks of failed attempts are not the increment's (files without the column have
    // none)
    let status = table.column("status").ok();
    let mut best: Option<NewtonIncrement> = None;
    let mut current = NewtonIncrement::default();
    let mut flush = |current: &mut NewtonIncrement| {
        let longer = best
            .as_ref()
            .is_none_or(|b| current.force.len() > b.force.len());
        if !current.force.is_empty() && longer {
            best = Some(std::mem::take(current));
        } else {
            *current = NewtonIncrement::default();
        }
    };
    for row in table {
        let row = row?;
        let step = row.text(is)?;
        if !dynamic.contains(&step) {
            continue;
        }
        if let Some(status) = status
            && row.text(status)? != CONVERGED
        {
            continue;
        }
        let increment = row.number(ii)?;
        if current.step != step || current.increment != increment {
            flush(&mut current);
            current.step = step.to_string();
            current.increment = increment;
        }
        current.time = row.number(it)?;
        current.force.push(row.number(ie)?);
        current.contact.push(row.number(ic)?);
    }
    flush(&mut current);
    Ok(best)
}

fn load_series(dir: &Path, name: String) -> Result<Series, ReportError> {
    let runs = load_runs(dir)?;
    let parse = |message: String| ReportError::Parse {
        path: dir.to_path_buf(),
        message,
    };
    let mut cases = Vec::with_capacity(runs.len());
    for run in &runs {
        cases.push(run.case.clone().ok_or_else(|| {
            parse(format!(
                "level {} has no case.json, which says what the level refines; run it again",
                run.name
            ))
        })?);
    }
    let names: Vec<&str> = runs.iter().map(|r| r.name.as_str()).collect();
    let case_refs: Vec<&Case> = cases.iter().collect();
    let refinement = refinement(&names, &case_refs).map_err(parse)?;
    let size = |c: &Case| match refinement {
        Refinement::Mesh => element_length(c),
        Refinement::TimeStep => time_steps(c).first().copied().unwrap_or(0.0),
    };
    let mut levels: Vec<Level> = runs
        .into_iter()
        .zip(&cases)
        .map(|(run, case)| Level {
            h: size(case),
            label: level_label(case, refinement),
            run,
        })
        .collect();
    levels.sort_by(|a, b| b.h.total_cmp(&a.h));
    if let Some(w) = levels.windows(2).find(|w| w[0].h == w[1].h) {
        return Err(parse(format!(
            "levels {} and {} have the same size {}",
            w[0].run.name, w[1].run.name, w[0].h
        )));
    }
    let coarsest = &levels[0];
    let newton_path = dir.join(&coarsest.run.name).join(NEWTON_CSV);
    let newton = if newton_path.is_file() {
        let text = std::fs::read_to_string(&newton_path).map_err(|source| ReportError::Read {
            path: newton_path.clone(),
            source,
        })?;
        let dynamic = coarsest
            .run
            .case
            .as_ref()
            .map(dynamic_steps)
            .unwrap_or_default();
        hardest_increment(&text, &newton_path, &dynamic)?
    } else {
        None
    };
    Ok(Series {
        name,
        refinement,
        levels,
        newton,
    })
}

/// Reads a convergence study: every subdirectory of `dir` holding runs is a series.
///
/// # Errors
/// [`ReportError`] if `dir` cannot be listed, holds no series, or a series is malformed.
pub fn load_study(dir: &Path) -> Result<Vec<Series>, ReportError> {
    let list = |source| ReportError::Read {
        path: dir.to_path_buf(),
        source,
    };
    let mut found = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(list)? {
        let path = entry.map_err(list)?.path();
        let holds_runs = path.is_dir()
            && std::fs::read_dir(&path)
                .map(|e| e.flatten().any(|e| e.path().join("summary.json").is_file()))
                .unwrap_or(false);
        if holds_runs {
            found.push(path);
        }
    }
    if found.is_empty() {
        return Err(ReportError::NoRuns(dir.to_path_buf()));
    }
    found.sort();
    found
        .into_iter()
        .map(|path| {
            let name = path
                .file_name()
                .map_or_else(String::new, |n| n.to_string_lossy().into());
            load_series(&path, name)
        })
        .collect()
}

/// `max |omega_coarse - omega_fine| / omega0` over `t <= 0.9 t_stop` of the coarser run.
fn omega_difference(coarse: &Run, fine: &Run) -> Option<f64> {
    let t_stop = coarse.summary.t_stop?;
    e_slide(
        &coarse.history,
        t_stop,
        coarse.summary.omega0,
        &fine.history,
    )
}

fn series_table(series: &Series, out: &mut String) {
    let unit = match series.refinement {
        Refinement::Mesh => "elements | circumferential element length h [m]",
        Refinement::TimeStep => "time step | h [s]",
    };
    let finest = &series.levels[series.levels.len() - 1].run;
    let _ = writeln!(
        out,
        "| level | {unit} | t_stop [s] | t_stop change from the previous level [%] \
         | deceleration [rad/s^2] | e_slide vs the finest level [%] | max abs omega difference \
         to the previous level / omega0 [%] | increments | Newton iterations | wall time [s] |\n\
         |---|---|---|---|---|---|---|---|---|---|---|"
    );
    for (k, level) in series.levels.iter().enumerate() {
        let s = &level.run.summary;
        let previous = k.checked_sub(1).map(|j| &series.levels[j].run);
        let change = previous
            .and_then(|p| p.summary.t_stop.zip(s.t_stop))
            .map(|(a, b)| (b - a) / a);
        let difference = previous.and_then(|p| omega_difference(p, &level.run));
        let e = s
            .t_stop
            .and_then(|t| e_slide(&level.run.history, t, s.omega0, &finest.history));
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.2} |",
            level.run.name,
            level.label,
            Sig(level.h),
            show(s.t_stop),
            percent(change),
            show(s.deceleration),
            percent(e),
            percent(difference),
            s.increments,
            s.newton_iterations,
            s.wall_time_s,
        );
    }
}

fn orders(series: &Series, out: &mut String) {
    let levels = &series.levels;
    if levels.len() < 3 {
        let _ = writeln!(
            out,
            "\nObserved order: needs three levels, this series has {}.",
            levels.len()
        );
        return;
    }
    out.push('\n');
    for w in levels.windows(3) {
        let (r12, r23) = (w[0].h / w[1].h, w[1].h / w[2].h);
        let names = format!("{}, {}, {}", w[0].run.name, w[1].run.name, w[2].run.name);
        if (r12 / r23 - 1.0).abs() > 1e-6 {
            let _ = writeln!(
                out,
                "- {names}: ratios {} and {} differ; no observed order",
                Sig(r12),
                Sig(r23)
            );
            continue;
        }
        let measure = |f: fn(&Run) -> Option<f64>| {
            let values: Option<Vec<f64>> = w.iter().map(|l| f(&l.run)).collect();
            match values.as_deref() {
                Some(&[f1, f2, f3]) => {
                    let p = observed_order(f1, f2, f3, r12);
                    let extrapolated = p.and_then(|p| richardson(f2, f3, r12, p));
                    let sign = if (f1 - f2) * (f2 - f3) < 0.0 {
                        " (differences change sign)"
                    } else {
                        ""
                    };
                    format!("{}{sign}, extrapolated {}", show(p), show(extrapolated))
                }
                _ => "n/a".to_string(),
            }
        };
        let d12 = omega_difference(&w[0].run, &w[1].run);
        let d23 = omega_difference(&w[1].run, &w[2].run);
        let p_omega = d12
            .zip(d23)
            .and_then(|(a, b)| order_of_differences(a, b, r12));
        let _ = writeln!(
            out,
            "- {names} (r = {}): observed order of t_stop {}; of the deceleration {}; of \
             omega(t) (max norm of the differences) {}",
            Sig(r12),
            measure(|r| r.summary.t_stop),
            measure(|r| r.summary.deceleration),
            show(p_omega),
        );
    }
}

fn newton_table(series: &Series, out: &mut String) {
    let Some(n) = &series.newton else {
        let _ = writeln!(
            out,
            "\nNewton residuals: no newton.csv with a dynamic increment in {}.",
            series.levels[0].run.name
        );
        return;
    };
    let _ = writeln!(
        out,
        "\nNewton residuals of {} (the coarsest level), step {} increment {} (t = {} s), the \
         dynamic increment with the most iterations; rate q_k = ln(e_k+1 / e_k) / \
         ln(e_k / e_k-1) of the force residual (2: quadratic, 1: linear):\n\n\
         | iteration | force residual | contact residual | e_k / e_k-1 | rate q |\n\
         |---|---|---|---|---|",
        series.levels[0].run.name,
        n.step,
        n.increment,
        Sig(n.time),
    );
    let rates = iteration_orders(&n.force);
    for (k, (f, c)) in n.force.iter().zip(&n.contact).enumerate() {
        let ratio = k.checked_sub(1).map(|j| f / n.force[j]);
        let rate = k.checked_sub(2).and_then(|j| rates[j]);
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {} |",
            k + 1,
            Sig(*f),
            Sig(*c),
            show(ratio),
            show(rate),
        );
    }
}

/// The convergence section for `study` (read from `dir`) and the Newton residual plot it wrote
/// into `plot_dir`.
///
/// # Errors
/// [`ReportError`] if the plot cannot be written.
pub fn section(
    dir: &Path,
    study: &[Series],
    plot_dir: &Path,
) -> Result<(String, Vec<PathBuf>), ReportError> {
    let plot = plot_dir.join(NEWTON_SVG);
    let histories: Vec<(String, Vec<f64>)> = study
        .iter()
        .filter_map(|s| {
            s.newton.as_ref().map(|n| {
                let label = format!(
                    "{}: {} increment {}",
                    s.levels[0].run.name, n.step, n.increment
                );
                (format!("{} / {label}", s.name), n.force.clone())
            })
        })
        .collect();
    plot_newton(&histories, &plot)?;
    let mut out = String::new();
    let _ = write!(
        out,
        "## Convergence\n\n\
         Runs in `{dir}` (`scripts/convergence.sh`), one directory per series and one per \
         level. Each series refines the pad mesh or the time step of a drum case (read from the \
         levels' case.json), with everything else equal; h is the element length along the \
         circumference (the sliding direction) or the time step. Observed order from three levels \
         refined by the ratio r: p = ln(|f1 - f2| / |f2 - f3|) / ln r; Richardson \
         extrapolation f3 + (f3 - f2) / (r^p - 1) where p > 0. The deceleration is the \
         least-squares slope of omega(t) over [0.1, 0.9] t_stop (the mean friction torque \
         over I, insensitive to the pad vibration that moves t_stop by up to 1 %, DRUM.md \
         2.2). For omega(t) the differences are \
         max |omega_coarse - omega_fine| / omega0 over t <= 0.9 t_stop of the coarser level. \
         e_slide is measured against the finest level of the series (DRUM.md section 3).\n\n\
         ![Newton residuals of the hardest dynamic increment of each series' coarsest \
         level]({NEWTON_SVG})\n",
        dir = dir.display()
    );
    for series in study {
        let what = match series.refinement {
            Refinement::Mesh => "pad mesh",
            Refinement::TimeStep => "time step",
        };
        let _ = write!(out, "\n### {} ({what})\n\n", series.name);
        series_table(series, &mut out);
        orders(series, &mut out);
        newton_table(series, &mut out);
    }
    Ok((out, vec![plot]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn observed_order_recovers_the_order_of_a_power_law() {
        // f(h) = 1 + 3 h^2 at h = 0.4, 0.2, 0.1: order 2, extrapolation 1.
        let f = |h: f64| 1.0 + 3.0 * h * h;
        let p = observed_order(f(0.4), f(0.2), f(0.1), 2.0).expect("order");
        assert!((p - 2.0).abs() < 1e-12, "{p}");
        let x = richardson(f(0.2), f(0.1), 2.0, p).expect("extrapolation");
        assert!((x - 1.0).abs() < 1e-12, "{x}");
        // First order with ratio 3, decreasing from above or below alike.
        let g = |h: f64| 5.0 - 0.7 * h;
        let p = observed_order(g(0.9), g(0.3), g(0.1), 3.0).expect("order");
        assert!((p - 1.0).abs() < 1e-12, "{p}");
    }

    #[test]
    fn observed_order_is_undefined_or_negative_where_levels_do_not_converge() {
        assert_eq!(observed_order(1.0, 1.0, 1.0, 2.0), None);
        assert_eq!(observed_order(2.0, 1.0, 1.0, 2.0), None);
        assert_eq!(observed_order(2.0, 1.0, 0.5, 1.0), None);
        assert_eq!(observed_order(f64::NAN, 1.0, 0.5, 2.0), None);
        // Differences growing from 1 to 2: order -1, and no extrapolation.
        let p = observed_order(0.0, 1.0, 3.0, 2.0).expect("order");
        assert!((p + 1.0).abs() < 1e-12, "{p}");
        assert_eq!(richardson(1.0, 3.0, 2.0, p), None);
    }

    #[test]
    fn iteration_orders_tell_quadratic_from_linear_convergence() {
        let quadratic = [1e-1, 1e-2, 1e-4, 1e-8];
        let q = iteration_orders(&quadratic);
        assert_eq!(q.len(), 2);
        assert!(
            q.iter().all(|q| (q.expect("rate") - 2.0).abs() < 1e-9),
            "{q:?}"
        );
        let linear = [1e-2, 1e-3, 1e-4, 1e-5];
        let q = iteration_orders(&linear);
        assert!(
            q.iter().all(|q| (q.expect("rate") - 1.0).abs() < 1e-9),
            "{q:?}"
        );
        assert_eq!(iteration_orders(&[1e-2, 1e-3]), vec![]);
        assert_eq!(iteration_orders(&[1e-2, 1e-3, 0.0]), vec![None]);
    }

    #[test]
    fn the_hardest_dynamic_increment_is_found_and_static_ones_ignored() {
        let text = "step,increment,time,size,iteration,force_residual,contact_residual\n\
                    preload,1,0,0.2,1,1e-1,1e-3\n\
                    preload,1,0,0.2,2,1e-3,1e-5\n\
                    preload,1,0,0.2,3,1e-6,1e-8\n\
                    preload,1,0,0.2,4,1e-9,1e-12\n\
                    spin,1,1e-4,1e-4,1,1e-3,1e-6\n\
                    spin,1,1e-4,1e-4,2,1e-7,1e-12\n\
                    spin,2,2e-4,1e-4,1,1e-2,1e-5\n\
                    spin,2,2e-4,1e-4,2,1e-4,1e-9\n\
                    spin,2,2e-4,1e-4,3,1e-8,1e-16\n\
                    spin,3,3e-4,1e-4,1,1e-2,1e-5\n\
                    spin,3,3e-4,1e-4,2,1e-4,1e-9\n\
                    spin,3,3e-4,1e-4,3,1e-8,1e-16\n";
        let path = Path::new("run/newton.csv");
        let n = hardest_increment(text, path, &["spin"])
            .expect("parses")
            .expect("found");
        assert_eq!((n.step.as_str(), n.increment), ("spin", 2));
        assert_eq!(n.force, vec![1e-2, 1e-4, 1e-8]);
        assert_eq!(n.contact, vec![1e-5, 1e-9, 1e-16]);
        assert!((n.time - 2e-4).abs() < 1e-18);
        assert_eq!(
            hardest_increment(text, path, &["other"]).expect("parses"),
            None
        );
        let e = hardest_increment("step,increment\n", path, &["spin"]).expect_err("columns");
        assert_eq!(
            e.to_string(),
            "run/newton.csv: no column 'time' in the header"
        );
        let e = hardest_increment(
            "step,increment,time,force_residual,contact_residual\nspin,1,0,x,1\n",
            path,
            &["spin"],
        )
        .expect_err("number");
        assert_eq!(
            e.to_string(),
            "run/newton.csv: line 2: expected a number in 'force_residual'"
        );
    }

    #[test]
    fn a_quoted_step_name_with_commas_is_one_field() {
        let text = "step,increment,time,size,iteration,force_residual,contact_residual\n\
                    \"spin, down \"\"fast\"\"\",1,1e-4,1e-4,1,1e-3,1e-6\n\
                    \"spin, down \"\"fast\"\"\",1,1e-4,1e-4,2,1e-7,1e-12\n";
        let n = hardest_increment(text, Path::new("newton.csv"), &["spin, down \"fast\""])
            .expect("parses")
            .expect("found");
        assert_eq!(n.step, "spin, down \"fast\"");
        assert_eq!(n.increment, 1);
        assert_eq!(n.force, vec![1e-3, 1e-7]);
        assert_eq!(n.contact, vec![1e-6, 1e-12]);
    }

    fn case(overrides: &[&str]) -> Case {
        let text = include_str!("../../../cases/drum/2d-analytic.json");
        let overrides: Vec<String> = overrides.iter().map(|o| o.to_string()).collect();
        skid_cases::validate::parse_case(text, Path::new("2d-analytic.json"), &overrides)
            .expect("valid case")
    }

    #[test]
    fn a_series_refines_the_mesh_or_the_time_step_and_nothing_else() {
        let names = ["a", "b", "c"];
        let coarse = case(&[]);
        let fine_mesh = case(&[
            "pad.elements.circumferential=20",
            "pad.elements.radial=2",
            "name=other",
        ]);
        let fine_dt = case(&["steps[1].dt=5e-5"]);
        let other = case(&["contact.mu=0.2"]);
        assert_eq!(
            refinement(&names, &[&coarse, &fine_mesh]),
            Ok(Refinement::Mesh)
        );
        assert_eq!(
            refinement(&names, &[&coarse, &fine_dt]),
            Ok(Refinement::TimeStep)
        );
        let both = case(&["pad.elements.circumferential=20", "steps[1].dt=5e-5"]);
        assert!(refinement(&names, &[&coarse, &both]).is_err());
        assert!(refinement(&names, &[&coarse, &coarse]).is_err());
        let e = refinement(&names, &[&coarse, &fine_dt, &other]).expect_err("mu differs");
        assert!(e.contains("a and c"), "{e}");
        // 10 elements along the 0.1 m pad, then 20.
        assert!((element_length(&coarse) - 0.01).abs() < 1e-15);
        assert!((element_length(&coarse) / element_length(&fine_mesh) - 2.0).abs() < 1e-12);
        assert_eq!(level_label(&fine_mesh, Refinement::Mesh), "20 x 2");
        assert_eq!(level_label(&fine_dt, Refinement::TimeStep), "dt 5.000e-5");
    }
}
