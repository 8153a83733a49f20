//! The report's SVG plots (plotters' SVG backend: text is written as SVG `<text>` elements, so
//! no font files are needed).

use std::path::Path;

use plotters::prelude::*;

use super::{ReportError, Run, omega_difference};
use skid_cases::atomic::write_atomic;

/// File name of the omega(t) plot.
pub const OMEGA_SVG: &str = "omega.svg";
/// File name of the omega(t) - omega_ref(t) plot.
pub const DIFFERENCE_SVG: &str = "omega-difference.svg";
/// File name of the hard cases' normalized spin-down plot.
pub const HARD_OMEGA_SVG: &str = "hard-omega.svg";
/// File name of the Newton residual plot of the convergence study.
pub const NEWTON_SVG: &str = "newton.svg";
/// File name of the plot of cost against problem size.
pub const SCALING_SVG: &str = "scaling.svg";
/// File name of the Hertz contact pressure plot of the verification section.
pub const HERTZ_SVG: &str = "hertz-pressure.svg";
/// The Cattaneo–Mindlin traction profile against the closed form.
pub const MINDLIN_SVG: &str = "mindlin-traction.svg";
/// File name of the stress sweep's plot of energy balance against time step.
pub const STRESS_SVG: &str = "stress-energy.svg";

/// The time axis of the benchmark plots.
const TIME_AXIS: &str = "t [s] (from the start of the dynamic step)";

const SIZE: (u32, u32) = (960, 600);

/// One curve of a plot.
struct Curve {
    label: String,
    points: Vec<(f64, f64)>,
    /// Drawn dashed in black (the analytic estimate) rather than in a palette colour.
    dashed: bool,
}

/// The range of `values` with 5 % margins (a unit-wide range around a single value).
fn padded_range(values: impl Iterator<Item = f64>) -> std::ops::Range<f64> {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if lo > hi {
        return 0.0..1.0;
    }
    let pad = if hi > lo { 0.05 * (hi - lo) } else { 0.5 };
    (lo - pad)..(hi + pad)
}

/// Draws `curves` into the SVG file `path`.
fn draw(
    path: &Path,
    title: &str,
    (x_label, y_label): (&str, &str),
    curves: &[Curve],
    legend: SeriesLabelPosition,
) -> Result<(), ReportError> {
    let points = || curves.iter().flat_map(|c| c.points.iter());
    let x = padded_range(points().map(|p| p.0));
    let x = x.start.max(0.0)..x.end;
    let y = padded_range(points().map(|p| p.1));
    write_svg(path, |root| {
        let mut chart = ChartBuilder::on(root)
            .caption(title, ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(48)
            .y_label_area_size(72)
            .build_cartesian_2d(x, y)
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .x_desc(x_label)
            .y_desc(y_label)
            .draw()
            .map_err(|e| e.to_string())?;
        let mut palette = 0;
        for curve in curves {
            let color = if curve.dashed {
                BLACK.to_rgba()
            } else {
                palette += 1;
                Palette99::pick(palette - 1).to_rgba()
            };
            let style = color.stroke_width(2);
            let points = curve.points.iter().copied();
            if curve.dashed {
                chart.draw_series(DashedLineSeries::new(points, 8, 6, style))
            } else {
                chart.draw_series(LineSeries::new(points, style))
            }
            .map_err(|e| e.to_string())?
            .label(curve.label.as_str())
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], color));
        }
        draw_legend(&mut chart, legend)
    })
}

/// Renders a plot into the SVG file `path`: `body` draws on a white canvas of [`SIZE`]; the
/// file is written only if every drawing call succeeded, and atomically.
fn write_svg(
    path: &Path,
    body: impl FnOnce(&DrawingArea<SVGBackend<'_>, plotters::coord::Shift>) -> Result<(), String>,
) -> Result<(), ReportError> {
    let error = |message: String| ReportError::Plot {
        path: path.to_path_buf(),
        message,
    };
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(|e| error(e.to_string()))?;
        body(&root).map_err(error)?;
        root.present().map_err(|e| error(e.to_string()))?;
    }
    write_atomic(path, &svg).map_err(|source| ReportError::Write {
        path: path.to_path_buf(),
        source,
    })
}

/// The legend of the labelled series, boxed on a translucent white background.
fn draw_legend<'a, CT: CoordTranslate>(
    chart: &mut ChartContext<'a, SVGBackend<'a>, CT>,
    position: SeriesLabelPosition,
) -> Result<(), String> {
    chart
        .configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(|e| e.to_string())
}

fn points(times: &[f64], values: &[f64]) -> Vec<(f64, f64)> {
    times.iter().copied().zip(values.iter().copied()).collect()
}

/// `omega.svg`: omega(t) of every run, and the analytic line `omega0 - decel t` of the
/// reference's case (60 - 600 t for the drum) down to zero.
///
/// # Errors
/// [`ReportError`] if the plot cannot be drawn or written.
pub fn plot_omega(runs: &[Run], reference: &Run, path: &Path) -> Result<(), ReportError> {
    let mut curves: Vec<Curve> = runs
        .iter()
        .map(|r| Curve {
            label: r.name.clone(),
            points: points(&r.history.time, &r.history.omega),
            dashed: false,
        })
        .collect();
    let w0 = reference.summary.omega0;
    if let Some(decel) = reference
        .summary
        .deceleration_analytic
        .filter(|d| d.abs() > 0.0)
    {
        curves.push(Curve {
            label: format!("analytic {w0} - {decel:.0} t"),
            points: vec![(0.0, w0), (w0 / decel, 0.0)],
            dashed: true,
        });
    }
    draw(
        path,
        "Drum angular velocity",
        (TIME_AXIS, "omega [rad/s]"),
        &curves,
        SeriesLabelPosition::UpperRight,
    )
}

/// `omega-difference.svg`: omega(t) - omega_ref(t) of every run but the reference, the
/// reference interpolated at the run's times.
///
/// # Errors
/// [`ReportError`] if the plot cannot be drawn or written.
pub fn plot_difference(runs: &[Run], reference: &Run, path: &Path) -> Result<(), ReportError> {
    let curves: Vec<Curve> = runs
        .iter()
        .filter(|r| r.name != reference.name)
        .map(|r| Curve {
            label: r.name.clone(),
            points: omega_difference(&r.history, &reference.history),
            dashed: false,
        })
        .collect();
    let title = format!("Difference to the reference {}", reference.name);
    draw(
        path,
        &title,
        (TIME_AXIS, "omega - omega_ref [rad/s]"),
        &curves,
        SeriesLabelPosition::LowerLeft,
    )
}

/// Where the normalized spin-down plot ends, in `t / t_est`.
const NORMALIZED_TIME_LIMIT: f64 = 1.5;

/// `hard-omega.svg`: `omega / omega0` against `t / t_est` (up to 1.5) of every `(run, t_est)`,
/// and the estimate's line `1 - t / t_est`: runs that brake as estimated fall on it whatever
/// their omega0, mu or pressure.
///
/// # Errors
/// [`ReportError`] if the plot cannot be drawn or written.
pub fn plot_normalized_spin_down(runs: &[(&Run, f64)], path: &Path) -> Result<(), ReportError> {
    let mut curves: Vec<Curve> = runs
        .iter()
        .map(|(r, t_est)| {
            let w0 = r.summary.omega0;
            Curve {
                label: r.name.clone(),
                points: r
                    .history
                    .time
                    .iter()
                    .zip(&r.history.omega)
                    .map(|(t, w)| (t / t_est, w / w0))
                    .take_while(|&(x, _)| x <= NORMALIZED_TIME_LIMIT)
                    .collect(),
                dashed: false,
            }
        })
        .collect();
    curves.push(Curve {
        label: "estimate 1 - t / t_est".into(),
        points: vec![(0.0, 1.0), (1.0, 0.0)],
        dashed: true,
    });
    draw(
        path,
        "Hard cases: normalized spin-down",
        ("t / t_est, t_est = I omega0 / (mu p A R)", "omega / omega0"),
        &curves,
        SeriesLabelPosition::UpperRight,
    )
}

/// `newton.svg`: the force residual after each Newton iteration, on a log scale, of every
/// `(label, residuals)` (non-positive residuals are left out).
///
/// # Errors
/// [`ReportError`] if the plot cannot be drawn or written.
pub fn plot_newton(histories: &[(String, Vec<f64>)], path: &Path) -> Result<(), ReportError> {
    let positive = || {
        histories
            .iter()
            .flat_map(|(_, r)| r.iter().copied())
            .filter(|r| r.is_finite() && *r > 0.0)
    };
    let (lo, hi) = positive().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), r| {
        (lo.min(r), hi.max(r))
    });
    let (lo, hi) = if lo <= hi {
        (lo / 3.0, hi * 3.0)
    } else {
        (1e-12, 1.0)
    };
    let iterations = histories.iter().map(|(_, r)| r.len()).max().unwrap_or(1);
    write_svg(path, |root| {
        let mut chart = ChartBuilder::on(root)
            .caption("Newton residuals", ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(48)
            .y_label_area_size(72)
            .build_cartesian_2d(0.5..iterations as f64 + 0.5, (lo..hi).log_scale())
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .x_desc("Newton iteration")
            .y_desc("scaled force residual")
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .draw()
            .map_err(|e| e.to_string())?;
        for (k, (label, residuals)) in histories.iter().enumerate() {
            let color = Palette99::pick(k).to_rgba();
            let points = residuals
                .iter()
                .enumerate()
                .filter(|(_, r)| r.is_finite() && **r > 0.0)
                .map(|(i, r)| ((i + 1) as f64, *r));
            chart
                .draw_series(LineSeries::new(points, color.stroke_width(2)).point_size(4))
                .map_err(|e| e.to_string())?
                .label(label.as_str())
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], color));
        }
        draw_legend(&mut chart, SeriesLabelPosition::UpperRight)
    })
}

/// File name of the work-precision plot of `skid bench`'s time-step ladders.
pub const WORK_PRECISION_SVG: &str = "work-precision.svg";

/// File name of the work-precision plot of `skid bench`'s pad-mesh ladders.
pub const WORK_PRECISION_MESH_SVG: &str = "work-precision-mesh.svg";

/// The range of the positive finite `values`, widened by a factor 2 each way, for a log axis.
fn log_range(values: impl Iterator<Item = f64>) -> std::ops::Range<f64> {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if lo <= hi {
        lo / 2.0..hi * 2.0
    } else {
        1e-3..1.0
    }
}

/// How the series of a log-log plot are drawn.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Marks {
    /// Points joined by lines (a curve per series).
    Lines,
    /// Points alone (a cloud per series).
    Points,
}

/// A plot titled `title` on log scales in both axes, one curve of points per `(label,
/// [(x, y)])` (points with a non-positive value are left out): `work-precision.svg` (error
/// against wall time), `scaling.svg` (cost against equations).
///
/// # Errors
/// [`ReportError`] if the plot cannot be drawn or written.
pub fn plot_log_log(
    title: &str,
    series: &[(String, Vec<(f64, f64)>)],
    labels: (&str, &str),
    path: &Path,
) -> Result<(), ReportError> {
    log_log(title, series, labels, Marks::Lines, None, path)
}

/// A scatter plot titled `title` on log scales in both axes: one set of points per `(label,
/// [(x, y)])` (points with a non-positive value are left out), and a dashed horizontal line
/// at `limit`'s value, labelled, if given: `stress-energy.svg` (each run's energy error
/// against its time step, and the limit).
///
/// # Errors
/// [`ReportError`] if the plot cannot be drawn or written.
pub fn plot_scatter_log_log(
    title: &str,
    series: &[(String, Vec<(f64, f64)>)],
    labels: (&str, &str),
    limit: Option<(String, f64)>,
    path: &Path,
) -> Result<(), ReportError> {
    log_log(title, series, labels, Marks::Points, limit, path)
}

/// The log-log plot of [`plot_log_log`] and [`plot_scatter_log_log`].
fn log_log(
    title: &str,
    series: &[(String, Vec<(f64, f64)>)],
    (x_label, y_label): (&str, &str),
    marks: Marks,
    limit: Option<(String, f64)>,
    path: &Path,
) -> Result<(), ReportError> {
    let positive = |p: &&(f64, f64)| p.0 > 0.0 && p.1 > 0.0 && p.0.is_finite() && p.1.is_finite();
    let all = || series.iter().flat_map(|(_, p)| p.iter()).filter(positive);
    let x = log_range(all().map(|p| p.0));
    let y = log_range(all().map(|p| p.1).chain(limit.as_ref().map(|l| l.1)));
    write_svg(path, |root| {
        let mut chart = ChartBuilder::on(root)
            .caption(title, ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(48)
            .y_label_area_size(72)
            .build_cartesian_2d(x.clone().log_scale(), y.log_scale())
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .x_desc(x_label)
            .y_desc(y_label)
            .x_label_formatter(&|v| format!("{v:.0e}"))
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .draw()
            .map_err(|e| e.to_string())?;
        for (k, (label, points)) in series.iter().enumerate() {
            let color = Palette99::pick(k).to_rgba();
            let points: Vec<(f64, f64)> = points.iter().filter(positive).copied().collect();
            match marks {
                Marks::Lines => chart
                    .draw_series(LineSeries::new(points, color.stroke_width(2)).point_size(4))
                    .map_err(|e| e.to_string())?
                    .label(label.as_str())
                    .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], color)),
                Marks::Points => chart
                    .draw_series(
                        points
                            .into_iter()
                            .map(|p| Circle::new(p, 3, color.filled())),
                    )
                    .map_err(|e| e.to_string())?
                    .label(label.as_str())
                    .legend(move |(x, y)| Circle::new((x + 10, y), 3, color.filled())),
            };
        }
        if let Some((label, value)) = &limit {
            let style = BLACK.stroke_width(2);
            chart
                .draw_series(DashedLineSeries::new(
                    [(x.start, *value), (x.end, *value)],
                    8,
                    6,
                    style,
                ))
                .map_err(|e| e.to_string())?
                .label(label.as_str())
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], style));
        }
        let legend = match marks {
            Marks::Lines => SeriesLabelPosition::LowerLeft,
            Marks::Points => SeriesLabelPosition::LowerRight,
        };
        draw_legend(&mut chart, legend)
    })
}

/// `hertz-pressure.svg`: the contact pressure of a Hertz run, `p / p0` against `|x| / a`, its
/// nodes with `x >= 0` and those with `x <= 0` (mirrored) as two curves, and the analytic
/// `sqrt(1 - x^2 / a^2)` (dashed) out to `x = a`; `profile` holds `(x, p)` in order of x.
///
/// # Errors
/// [`ReportError`] if the plot cannot be drawn or written.
pub fn plot_hertz_pressure(
    title: &str,
    profile: &[(f64, f64)],
    (half_width, peak): (f64, f64),
    path: &Path,
) -> Result<(), ReportError> {
    let scaled = |&(x, p): &(f64, f64)| (x.abs() / half_width, p / peak);
    let right: Vec<(f64, f64)> = profile.iter().filter(|p| p.0 >= 0.0).map(scaled).collect();
    let mut left: Vec<(f64, f64)> = profile.iter().filter(|p| p.0 <= 0.0).map(scaled).collect();
    left.reverse();
    let analytic = (0..=100)
        .map(|k| {
            let s = f64::from(k) / 100.0;
            (s, (1.0 - s * s).sqrt())
        })
        .collect();
    let curves = [
        Curve {
            label: "FE, x >= 0".into(),
            points: right,
            dashed: false,
        },
        Curve {
            label: "FE, x <= 0 (mirrored)".into(),
            points: left,
            dashed: false,
        },
        Curve {
            label: "Hertz p0 sqrt(1 - x^2/a^2)".into(),
            points: analytic,
            dashed: true,
        },
    ];
    draw(
        path,
        title,
        ("|x| / a (a, p0: Hertz)", "p / p0"),
        &curves,
        SeriesLabelPosition::UpperRight,
    )
}

/// The Cattaneo–Mindlin traction `q / (mu p0)` against `x / a`: the FE nodes `fe`, Mindlin's
/// `mindlin` (dashed) and the slip bound `mu p / (mu p0)` of Hertz's pressure, `bound`.
///
/// # Errors
/// [`ReportError::Plot`] if it cannot be drawn or written.
pub fn plot_mindlin_traction(
    title: &str,
    fe: Vec<(f64, f64)>,
    mindlin: Vec<(f64, f64)>,
    bound: Vec<(f64, f64)>,
    path: &Path,
) -> Result<(), ReportError> {
    let curves = [
        Curve {
            label: "FE".into(),
            points: fe,
            dashed: false,
        },
        Curve {
            label: "slip bound mu p (Hertz)".into(),
            points: bound,
            dashed: false,
        },
        Curve {
            label: "Mindlin q(x)".into(),
            points: mindlin,
            dashed: true,
        },
    ];
    draw(
        path,
        title,
        ("x / a (a, p0: Hertz)", "q / (mu p0)"),
        &curves,
        SeriesLabelPosition::UpperRight,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_are_padded_and_degenerate_ones_widened() {
        assert_eq!(padded_range([0.0, 10.0].into_iter()), -0.5..10.5);
        assert_eq!(padded_range([2.0].into_iter()), 1.5..2.5);
        assert_eq!(padded_range(std::iter::empty()), 0.0..1.0);
        assert_eq!(padded_range([f64::NAN, 1.0, 3.0].into_iter()), 0.9..3.1);
    }

    #[test]
    fn plots_are_svg_with_text_labels_and_one_path_per_curve() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("p.svg");
        let curves = [
            Curve {
                label: "run-a".into(),
                points: vec![(0.0, 60.0), (0.1, 0.0)],
                dashed: false,
            },
            Curve {
                label: "analytic".into(),
                points: vec![(0.0, 60.0), (0.1, 0.0)],
                dashed: true,
            },
        ];
        draw(
            &path,
            "title",
            ("t [s]", "omega [rad/s]"),
            &curves,
            SeriesLabelPosition::UpperRight,
        )
        .expect("draws");
        let svg = std::fs::read_to_string(&path).expect("written");
        assert!(svg.starts_with("<svg"), "{}", &svg[..50]);
        for text in ["title", "omega [rad/s]", "run-a", "analytic"] {
            assert!(
                svg.contains(&format!("\n{text}\n</text>")),
                "no text {text}"
            );
        }
        assert!(svg.contains("<polyline"));
    }

    #[test]
    fn the_newton_plot_is_logarithmic_and_labels_every_history() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join(NEWTON_SVG);
        let histories = vec![
            ("2d".to_string(), vec![1e-2, 1e-4, 1e-8]),
            ("3d".to_string(), vec![1e-3, 0.0, 1e-6]),
        ];
        plot_newton(&histories, &path).expect("draws");
        let svg = std::fs::read_to_string(&path).expect("written");
        for text in ["Newton residuals", "2d", "3d", "1e-8"] {
            assert!(
                svg.contains(&format!("\n{text}\n</text>")),
                "no text {text}"
            );
        }
        plot_newton(&[], &path).expect("an empty plot draws too");
    }
}
