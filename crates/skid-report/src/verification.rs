//! The verification section of the report: the scenes of `cases/verification` whose answer is
//! known, checked against it from their run directories (`skid batch cases/verification
//! --out DIR`: each run's `model.json`, `summary.json`, `history.csv`, `contact_nodes.csv`).
//! Every scene is recognised by what its model holds, and its analytic answer computed from
//! that model:
//!
//! - Hertz ([`hertz`]): a rigid cylinder pressed frictionlessly on an elastic block, one run
//!   per mesh level: a table of half-width and peak pressure against the mesh, checks on the
//!   finest level (peak pressure within [`PEAK_TOLERANCE`], half-width within one element)
//!   and on convergence (the half-width error shrinks with every refinement; the peak
//!   pressure's change from one level to the next shrinks too, so that it converges, to
//!   whatever the finite block and finite strain make of Hertz's answer), and the pressure
//!   plot of the finest level;
//! - Cattaneo–Mindlin ([`cattaneo_mindlin`]): the Hertz scene with friction, then pushed
//!   sideways: the stick zone's width and traction against Mindlin's, per element type and
//!   mesh, with a measure of node-to-node alternation, its limit on the finest mesh and its
//!   decay under refinement, and the traction plot of the finest CPE4R mesh;
//! - Coulomb friction (any other scene with a frictional pair, [`coulomb`]): the friction
//!   resultant never exceeds `mu N` and equals it while every contact slides; a block on a
//!   fixed flat sticks or slides as its held loads say, and the runs of a scene that stick and
//!   slide bracket its threshold; a block moved over a fixed flat by prescribed motions makes
//!   its reactions balance the friction;
//! - a torque-free rigid body ([`free_rotation`]): its angular momentum and kinetic energy are
//!   constant, and a symmetric top precesses as Euler's equations say;
//! - a ball launched onto a deformable block ([`rolling`]): it slides, then rolls at the speed
//!   and from the time Coulomb friction and its inertia give;
//! - Cook's membrane ([`cook`]), one run per element formulation and mesh: a table of the
//!   loaded edge's deflection against the reference, checks that the locking-free elements
//!   converge to it and that the displacement element locks where the material is nearly
//!   incompressible;
//! - a neo-Hookean block on rollers compressed homogeneously ([`compression`]), one run per
//!   element formulation: its reaction and lateral stretch against the closed form in every
//!   increment, to 50 % compression, and its Newton iterations per increment.

pub mod cattaneo_mindlin;
pub mod compression;
pub mod cook;
pub mod coulomb;
pub mod free_rotation;
mod friction_rows;
mod reactions;
pub mod rolling;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::format::{Checks, Counts, Sig, percent};
use super::hertz::{self, HertzMeasure, HertzScene};
use super::plot::{HERTZ_SVG, plot_hertz_pressure};
use super::{ReportError, read};
use cattaneo_mindlin::MindlinScene;
use compression::CompressionScene;
use cook::CookScene;
use free_rotation::FreeBody;
use rolling::RollingBall;
use skid_cases::model_file::contact_nodes::CONTACT_NODES_CSV;
use skid_cases::model_spec::ModelSpec;
use skid_cases::runner::MODEL_JSON;

/// Largest relative error of the finest Hertz level's peak pressure.
pub const PEAK_TOLERANCE: f64 = 0.03;

/// The fields of a model run's `summary.json` this section reads.
#[derive(Clone, Debug, Deserialize, PartialEq)]
pub struct SceneSummary {
    /// `"completed"` or `"failed"`.
    pub status: String,
    /// Why the run stopped early, if it did.
    #[serde(default)]
    pub error: Option<String>,
    /// Wall time of the run, s.
    pub wall_time_s: f64,
    /// Increments cut back after a failed attempt.
    #[serde(default)]
    pub cutbacks: usize,
}

/// One run of a verification scene.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneRun {
    /// The run's directory name.
    pub name: String,
    /// The run directory.
    pub dir: PathBuf,
    /// The model as run (`model.json`).
    pub spec: ModelSpec,
    /// Its summary.
    pub summary: SceneSummary,
}

impl SceneRun {
    /// Whether the run completed; if not, a failed check of its status says why.
    fn completed_or_recorded(&self, checks: &mut Checks) -> bool {
        let completed = self.summary.status == "completed";
        if !completed {
            let why = self.summary.error.clone();
            checks.record(
                &format!("{}: status", self.name),
                false,
                why.unwrap_or_else(|| self.summary.status.clone()),
            );
        }
        completed
    }
}

/// Reads every subdirectory of `dir` that holds a `summary.json` and a `model.json` (runs of
/// model files), sorted by name.
///
/// # Errors
/// [`ReportError`] if `dir` cannot be listed, a run's files are malformed, or there is none.
pub fn load(dir: &Path) -> Result<Vec<SceneRun>, ReportError> {
    let list = |source| ReportError::Read {
        path: dir.to_path_buf(),
        source,
    };
    let mut dirs = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(list)? {
        let run = entry.map_err(list)?.path();
        if run.join("summary.json").is_file() && run.join(MODEL_JSON).is_file() {
            dirs.push(run);
        }
    }
    if dirs.is_empty() {
        return Err(ReportError::NoRuns(dir.to_path_buf()));
    }
    dirs.sort();
    dirs.into_iter()
        .map(|run| {
            let parse = |path: PathBuf, what: &str| {
                let text = read(&path)?;
                Ok::<_, ReportError>((text, path, what.to_string()))
            };
            let (text, path, what) = parse(run.join(MODEL_JSON), "the model as run")?;
            let spec: ModelSpec = serde_json::from_str(&text).map_err(|e| ReportError::Parse {
                path: path.clone(),
                message: format!("expected {what} (written by skid run): {e}"),
            })?;
            let (text, path, what) = parse(run.join("summary.json"), "a model run's summary")?;
            let summary = serde_json::from_str(&text).map_err(|e| ReportError::Parse {
                path: path.clone(),
                message: format!("expected {what}: {e}"),
            })?;
            let name = run
                .file_name()
                .map_or_else(|| spec.name.clone(), |n| n.to_string_lossy().into());
            Ok(SceneRun {
                name,
                dir: run,
                spec,
                summary,
            })
        })
        .collect()
}

/// A completed Hertz run and what it measured.
struct HertzLevel<'a> {
    run: &'a SceneRun,
    scene: HertzScene,
    measure: HertzMeasure,
}

impl HertzLevel<'_> {
    /// `(p_FE(0) - p0) / p0`.
    fn peak_error(&self) -> f64 {
        self.measure.peak_pressure / self.scene.peak_pressure() - 1.0
    }

    /// `a_FE - a`, m.
    fn width_error(&self) -> f64 {
        self.measure.half_width - self.scene.half_width()
    }
}

/// The verification section for `runs` (read from `dir`), its plots written into `plots`:
/// the text, the counts of its checks and the plot files.
///
/// # Errors
/// [`ReportError`] if a completed run's `contact_nodes.csv` or `history.csv` is absent or
/// malformed, or a plot cannot be written.
pub fn section(
    dir: &Path,
    runs: &[SceneRun],
    plots: &Path,
) -> Result<(String, Counts, Vec<PathBuf>), ReportError> {
    let mut out = format!(
        "## Verification scenes\n\n\
         Runs in `{}` (`skid batch cases/verification`), each checked against the \
         analytic answer of its model as run.\n\n",
        dir.display()
    );
    let mut checks = Checks::default();
    let mut files = Vec::new();
    let mut unchecked = Vec::new();
    let mut hertz_runs = Vec::new();
    let mut mindlin_runs = Vec::new();
    let mut coulomb_runs = Vec::new();
    let mut free_runs = Vec::new();
    let mut ball_runs = Vec::new();
    let mut cook_runs = Vec::new();
    let mut compression_runs = Vec::new();
    for run in runs {
        if let Some(scene) = HertzScene::recognise(&run.spec) {
            hertz_runs.push((run, scene));
        } else if let Some(scene) = MindlinScene::recognise(&run.spec) {
            mindlin_runs.push((run, scene));
        } else if let Some(ball) = RollingBall::recognise(&run.spec) {
            ball_runs.push((run, ball));
        } else if run.spec.contact.iter().any(|p| p.mu > 0.0) {
            coulomb_runs.push(run);
        } else if let Some(body) = FreeBody::recognise(&run.spec) {
            free_runs.push((run, body));
        } else if let Some(membrane) = CookScene::recognise(&run.spec) {
            cook_runs.push((run, membrane));
        } else if let Some(block) = CompressionScene::recognise(&run.spec) {
            compression_runs.push((run, block));
        } else {
            unchecked.push(run.name.as_str());
        }
    }
    if !hertz_runs.is_empty() {
        let (text, file) = hertz_section(&hertz_runs, plots, &mut checks)?;
        out.push_str(&text);
        files.extend(file);
    }
    if !mindlin_runs.is_empty() {
        let (text, file) = cattaneo_mindlin::section(&mindlin_runs, plots, &mut checks)?;
        out.push_str(&text);
        files.extend(file);
    }
    if !coulomb_runs.is_empty() {
        out.push_str(&coulomb::section(&coulomb_runs, &mut checks)?);
    }
    if !free_runs.is_empty() {
        out.push_str(&free_rotation::section(&free_runs, &mut checks)?);
    }
    if !ball_runs.is_empty() {
        out.push_str(&rolling::section(&ball_runs, &mut checks)?);
    }
    if !cook_runs.is_empty() {
        out.push_str(&cook::section(&cook_runs, &mut checks)?);
    }
    if !compression_runs.is_empty() {
        out.push_str(&compression::section(&compression_runs, &mut checks)?);
    }
    for name in unchecked {
        checks.skip(
            &format!("{name}: its checks"),
            "no analytic answer known for it",
        );
    }
    let counts = checks.counts;
    let _ = write!(
        out,
        "### Acceptance\n\n{}\n{}\n",
        checks.text,
        counts.line()
    );
    Ok((out, counts, files))
}

/// The Hertz part of the section: table, plot and checks (see the module documentation).
fn hertz_section(
    runs: &[(&SceneRun, HertzScene)],
    plots: &Path,
    checks: &mut Checks,
) -> Result<(String, Option<PathBuf>), ReportError> {
    let mut levels = Vec::new();
    for (run, scene) in runs {
        if !run.completed_or_recorded(checks) {
            continue;
        }
        let path = run.dir.join(CONTACT_NODES_CSV);
        let nodes = hertz::read_candidates(&read(&path)?, &path, &scene.pair)?;
        match hertz::measure(&nodes, scene.thickness) {
            Ok(measure) => levels.push(HertzLevel {
                run,
                scene: scene.clone(),
                measure,
            }),
            Err(why) => checks.record(&format!("{}: Hertz measures", run.name), false, why),
        }
    }
    // Coarsest first.
    levels.sort_by(|a, b| {
        (b.measure.centre_element / b.scene.half_width())
            .total_cmp(&(a.measure.centre_element / a.scene.half_width()))
    });
    let mut out = String::from(
        "### Hertz: rigid cylinder on an elastic block (plane strain)\n\n\
         `E* = E / (1 - nu^2)`, `a = sqrt(4 P R / (pi E*))`, `p0 = 2 P / (pi a)`, \
         `p(x) = p0 sqrt(1 - x^2 / a^2)`, with `E` and `nu` the small-strain moduli of the \
         material as run (`G = 2 (C10 + C01)`, `K = 2 / D1`) and `P` the cylinder's load over \
         the thickness. The pressure of a node is its normal force over its tributary area (half \
         its two segments, deformed, times the thickness; nominal: the reference segments); \
         `p_FE(0)` is that of the node at x = 0; `a_FE` is half the reference distance between \
         the outermost nodes carrying force, short of the discrete contact's edge by up to one \
         element `h_edge`. `h` is the element size at the centre. RMS: of \
         `(p_FE - p) / p0` over the nodes with |x| <= a.\n\n\
         | run | a / h | closed nodes | a [mm] | a_FE [mm] | (a_FE - a) / h_edge \
         | p0 [kPa] | p_FE(0) [kPa] | p_FE(0) vs p0 [%] | nominal p_FE(0) vs p0 [%] \
         | RMS [% of p0] | resultant vs P [%] | wall time [s] |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for l in &levels {
        let (s, m) = (&l.scene, &l.measure);
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.2} |",
            l.run.name,
            Sig(s.half_width() / m.centre_element),
            m.closed,
            Sig(1e3 * s.half_width()),
            Sig(1e3 * m.half_width),
            Sig(l.width_error() / m.edge_element),
            Sig(1e-3 * s.peak_pressure()),
            Sig(1e-3 * m.peak_pressure),
            Sig(100.0 * l.peak_error()),
            Sig(100.0 * (m.nominal_peak_pressure / s.peak_pressure() - 1.0)),
            percent(hertz::profile_error(s, &m.profile)),
            Sig(100.0 * (m.resultant / s.load - 1.0)),
            l.run.summary.wall_time_s,
        );
    }
    let Some(finest) = levels.last() else {
        return Ok((out, None));
    };
    let name = &finest.run.name;
    let plot = plots.join(HERTZ_SVG);
    plot_hertz_pressure(
        &format!("Hertz contact pressure, {name}"),
        &finest.measure.profile,
        (finest.scene.half_width(), finest.scene.peak_pressure()),
        &plot,
    )?;
    let _ = write!(
        out,
        "\n![p(x) / p0 of {name} against Hertz]({HERTZ_SVG})\n\n"
    );
    checks.check_fraction(
        &format!(
            "{name} (finest): peak pressure within {} % of Hertz",
            100.0 * PEAK_TOLERANCE
        ),
        Some(finest.peak_error().abs()),
        PEAK_TOLERANCE,
        "",
    );
    let edge = finest.measure.edge_element;
    checks.record(
        &format!("{name} (finest): half-width within one element (h_edge) of Hertz"),
        finest.width_error().abs() <= edge,
        format!(
            "a_FE - a = {} mm, h_edge = {} mm",
            Sig(1e3 * finest.width_error()),
            Sig(1e3 * edge)
        ),
    );
    if levels.len() < 3 {
        checks.skip(
            "Hertz: convergence with refinement",
            "fewer than three mesh levels",
        );
        return Ok((out, Some(plot)));
    }
    for pair in levels.windows(2) {
        let (coarse, fine) = (&pair[0], &pair[1]);
        checks.record(
            &format!(
                "{} -> {}: the half-width error shrinks",
                coarse.run.name, fine.run.name
            ),
            fine.width_error().abs() < coarse.width_error().abs(),
            format!(
                "{} mm -> {} mm",
                Sig(1e3 * coarse.width_error()),
                Sig(1e3 * fine.width_error())
            ),
        );
    }
    for three in levels.windows(3) {
        let [p0, p1, p2] = [0, 1, 2].map(|k| three[k].measure.peak_pressure);
        let (first, second) = ((p1 - p0).abs(), (p2 - p1).abs());
        let ratio = three[0].measure.centre_element / three[1].measure.centre_element;
        checks.record(
            &format!(
                "{} -> {} -> {}: the peak pressure converges (its change shrinks)",
                three[0].run.name, three[1].run.name, three[2].run.name
            ),
            second < first,
            format!(
                "changes {} % then {} % of p0, observed order {}",
                Sig(100.0 * first / three[0].scene.peak_pressure()),
                Sig(100.0 * second / three[0].scene.peak_pressure()),
                Sig((first / second).ln() / ratio.ln())
            ),
        );
    }
    Ok((out, Some(plot)))
}
