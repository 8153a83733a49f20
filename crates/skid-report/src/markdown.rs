//! The benchmark section of the report: the reference, the plots, a table of the runs and the
//! acceptance checks of DRUM.md section 3. The text holds no date, so the same runs give the
//! same report.

use std::fmt::Write as _;
use std::path::Path;

use super::format::{Checks, Counts, percent, show};
use super::plot::{DIFFERENCE_SVG, OMEGA_SVG};
use super::{Run, e_slide};

/// Tolerance on t_stop between any two runs (and to the reference).
const T_STOP_TOLERANCE: f64 = 0.01;
/// Tolerance on e_slide for analytic drum surfaces.
const E_SLIDE_ANALYTIC: f64 = 0.005;
/// Tolerance on e_slide for faceted drum surfaces.
const E_SLIDE_FACETED: f64 = 0.01;
/// Tolerance on t_stop between general contact and the contact pair.
const GENERAL_VS_PAIR: f64 = 0.001;
/// After the stop: largest |omega|, rad/s.
const POST_STOP_OMEGA: f64 = 5.0;
/// After the stop: largest angle change, rad.
const POST_STOP_ANGLE: f64 = 0.03;
/// The runs of the benchmark (DRUM.md section 1) and the refined reference.
const BENCHMARK: [&str; 9] = [
    "2d-analytic",
    "2d-r2d2",
    "3d-analytic",
    "3d-analytic-general",
    "3d-r3d4",
    "3d-m3d4r",
    "3d-s4r",
    "3d-c3d4",
    "3d-analytic-fine",
];

/// `|a - b| / min(|a|, |b|)`: the relative difference, symmetric and the stricter of the two.
fn relative(a: f64, b: f64) -> f64 {
    (a - b).abs() / a.abs().min(b.abs())
}

/// Per-run measures against the reference.
struct Measures {
    /// Signed `(t_stop - t_stop_ref) / t_stop_ref`.
    t_stop_vs_reference: Option<f64>,
    /// See [`e_slide`].
    e_slide: Option<f64>,
}

fn measure(run: &Run, reference: &Run) -> Measures {
    let (t, t_ref) = (run.summary.t_stop, reference.summary.t_stop);
    Measures {
        t_stop_vs_reference: t.zip(t_ref).map(|(t, r)| (t - r) / r),
        e_slide: t.and_then(|t| e_slide(&run.history, t, run.summary.omega0, &reference.history)),
    }
}

fn table(runs: &[Run], measures: &[Measures], out: &mut String) {
    out.push_str(
        "| run | dim | status | t_stop [s] | t_stop vs reference [%] | e_slide [%] \
         | post-stop max abs omega [rad/s] | post-stop max angle change [rad] \
         | energy balance error [%] | increments | Newton iterations | contact solves \
         | wall time [s] |\n",
    );
    out.push_str("|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (run, m) in runs.iter().zip(measures) {
        let s = &run.summary;
        let name = if s.case == run.name {
            run.name.clone()
        } else {
            format!("{} (case {})", run.name, s.case)
        };
        let _ = writeln!(
            out,
            "| {name} | {}D | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.2} |",
            s.dimension,
            s.status,
            show(s.t_stop),
            percent(m.t_stop_vs_reference),
            percent(m.e_slide),
            show(s.post_stop_max_abs_omega),
            show(s.post_stop_max_angle_change),
            percent(s.energy_balance_error),
            s.increments,
            s.newton_iterations,
            s.contact_solves,
            s.wall_time_s,
        );
    }
}

fn acceptance(runs: &[Run], measures: &[Measures], reference: usize) -> Checks {
    let mut c = Checks::default();
    let no_stop = "the drum did not stop";
    for (i, (run, m)) in runs.iter().zip(measures).enumerate() {
        let name = &run.name;
        c.record(
            &format!("{name}: status"),
            run.summary.status == "completed",
            run.summary.status.clone(),
        );
        if i != reference {
            c.check_fraction(
                &format!("{name}: t_stop within 1 % of the reference"),
                m.t_stop_vs_reference.map(f64::abs),
                T_STOP_TOLERANCE,
                "no stop time (this run or the reference)",
            );
            let analytic = name.contains("analytic");
            let (limit, kind) = if analytic {
                (E_SLIDE_ANALYTIC, "0.5 % (analytic drum)")
            } else {
                (E_SLIDE_FACETED, "1 % (faceted drum)")
            };
            c.check_fraction(
                &format!("{name}: e_slide < {kind}"),
                m.e_slide,
                limit,
                "not measurable (no stop, or the reference does not cover 0.9 t_stop)",
            );
        }
        let others: Vec<(f64, &str)> = runs
            .iter()
            .enumerate()
            .filter(|&(j, _)| j != i)
            .filter_map(|(_, o)| o.summary.t_stop.map(|t| (t, o.name.as_str())))
            .collect();
        match run.summary.t_stop {
            _ if others.is_empty() => {
                c.skip(
                    &format!("{name}: t_stop within 1 % of every other run"),
                    "no other run stopped",
                );
            }
            Some(t) => {
                let (worst, other) = others
                    .iter()
                    .map(|&(o, n)| (relative(t, o), n))
                    .fold((0.0, ""), |a, b| if b.0 > a.0 { b } else { a });
                c.check_fraction(
                    &format!("{name}: t_stop within 1 % of every other run, largest difference (to {other})"),
                    Some(worst),
                    T_STOP_TOLERANCE,
                    "",
                );
            }
            None => c.check_fraction(
                &format!("{name}: t_stop within 1 % of every other run"),
                None,
                T_STOP_TOLERANCE,
                no_stop,
            ),
        }
        c.check(
            &format!("{name}: post-stop max |omega| < 5 rad/s"),
            run.summary.post_stop_max_abs_omega,
            POST_STOP_OMEGA,
            no_stop,
        );
        c.check(
            &format!("{name}: post-stop max angle change < 0.03 rad"),
            run.summary.post_stop_max_angle_change,
            POST_STOP_ANGLE,
            no_stop,
        );
    }
    let find = |n: &str| runs.iter().find(|r| r.name == n);
    let label = "3d-analytic-general vs 3d-analytic: t_stop within 0.1 %";
    match (find("3d-analytic-general"), find("3d-analytic")) {
        (Some(general), Some(pair)) => c.check_fraction(
            label,
            general
                .summary
                .t_stop
                .zip(pair.summary.t_stop)
                .map(|(g, p)| relative(g, p)),
            GENERAL_VS_PAIR,
            "no stop time",
        ),
        _ => c.skip(label, "run(s) absent"),
    }
    for absent in BENCHMARK.iter().filter(|n| find(n).is_none()) {
        c.skip(&format!("{absent}: its checks"), "run absent");
    }
    c
}

/// The benchmark section of the report for `runs` (read from `runs_dir`) against
/// `runs[reference]`, with the counts of its acceptance checks.
pub fn render(runs_dir: &Path, runs: &[Run], reference: usize) -> (String, Counts) {
    let reference_run = &runs[reference];
    let measures: Vec<Measures> = runs.iter().map(|r| measure(r, reference_run)).collect();
    let mut out = String::new();
    let _ = write!(
        out,
        "## Benchmark: the drum idealizations\n\n\
         Runs in `{dir}` (`skid batch {inputs}`). \
         Reference: **{reference}**. omega_ref(t) is its drum angular velocity, linearly \
         interpolated at each run's times; times count from the start of the dynamic step. \
         e_slide = max |omega - omega_ref| / omega0 over t <= 0.9 t_stop of the run \
         (DRUM.md section 3).\n\n\
         ### Drum angular velocity\n\n\
         ![omega(t) of every run and the analytic line]({OMEGA_SVG})\n\n\
         ![omega(t) - omega_ref(t)]({DIFFERENCE_SVG})\n\n\
         ### Runs\n\n",
        dir = runs_dir.display(),
        inputs = super::batch_inputs(runs_dir),
        reference = reference_run.name,
    );
    table(runs, &measures, &mut out);
    let checks = acceptance(runs, &measures, reference);
    let n = checks.counts;
    let _ = write!(
        out,
        "\n### Acceptance\n\n\
         t_stop within 1 % of the reference and of every other run; e_slide < 0.5 % for \
         analytic drums, < 1 % for faceted ones; general contact vs contact pair within \
         0.1 %; after the stop |omega| < 5 rad/s and the angle within 0.03 rad. t_stop \
         differences are relative: to the reference's t_stop for the reference check, to the \
         smaller of the two for the others.\n\n{}\n{}\n",
        checks.text,
        n.line(),
    );
    (out, n)
}

#[cfg(test)]
mod tests {
    use super::super::test_runs::spin_down;
    use super::*;

    fn run(name: &str, decel: f64) -> Run {
        spin_down(name, decel)
    }

    #[test]
    fn acceptance_passes_close_runs_fails_far_ones_and_skips_absent_ones() {
        // t_stop: 0.1 (reference), 0.1002 (+0.2 %), 0.0976 (-2.4 %).
        let runs = [
            run("3d-analytic", 600.0),
            run("3d-analytic-general", 600.0 / 1.002),
            run("3d-r3d4", 615.0),
        ];
        let (text, counts) = render(Path::new("out"), &runs, 0);
        assert!(text.contains("Reference: **3d-analytic**"));
        assert!(text.contains("Runs in `out` (`skid batch cases/drum`)"));
        for run in &runs {
            assert!(text.contains(&format!("| {} | 3D |", run.name)), "{text}");
        }
        let line = |prefix: &str| {
            text.lines()
                .find(|l| l.contains(prefix))
                .unwrap_or_else(|| panic!("no line {prefix} in\n{text}"))
                .to_string()
        };
        assert!(line("3d-analytic-general: t_stop within 1 % of the reference").contains("PASS"));
        assert!(line("3d-r3d4: t_stop within 1 % of the reference").contains("FAIL"));
        // General vs pair differ by 0.2 %: more than 0.1 %.
        assert!(line("3d-analytic-general vs 3d-analytic").contains("FAIL"));
        // e_slide of the general run: 0.2 % slower deceleration, gap 600 (1 - 1/1.002) t.
        let e = line("3d-analytic-general: e_slide");
        assert!(e.contains("PASS"), "{e}");
        assert!(line("3d-r3d4: e_slide < 1 % (faceted drum)").contains("FAIL"));
        assert!(line("2d-r2d2: its checks").contains("SKIPPED"));
        assert_eq!(counts.skipped, BENCHMARK.len() - runs.len());
        assert!(counts.passed > 0 && counts.failed > 0);
        let (again, _) = render(Path::new("out"), &runs, 0);
        assert_eq!(text, again, "the report is deterministic");
    }

    #[test]
    fn runs_that_did_not_stop_fail_with_a_reason() {
        let mut short = run("2d-analytic", 600.0);
        short.summary.t_stop = None;
        short.summary.post_stop_max_abs_omega = None;
        let runs = [run("3d-analytic", 600.0), short];
        let (text, _) = render(Path::new("out"), &runs, 0);
        assert!(
            text.contains(
                "- **FAIL** 2d-analytic: post-stop max |omega| < 5 rad/s: the drum did not stop"
            ),
            "{text}"
        );
        assert!(
            text.contains("| 2d-analytic | 3D | completed | n/a |"),
            "{text}"
        );
    }
}
