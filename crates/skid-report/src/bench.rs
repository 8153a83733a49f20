//! `skid bench`: the cost of a case beside its error, over a ladder of time steps and methods.
//!
//! A method ([`BenchMethod`]) is a contact solve, optionally on the case with its pad
//! quasi-static (no inertia, DRUM.md's pad modelled only as far as the spin-down needs it).
//! Each case is run, for every method asked for, at the time
//! steps `dt_k = dt ratio^(coarser - k)`, `k = 0 .. levels` (every dynamic step's `dt` scaled
//! alike: `coarser` levels coarser than the case, the case itself, then finer). The finest level of a case
//! and solve is its converged reference, and each level's error is measured against it in the
//! quantities that converge (DRUM.md 2.2, 3):
//!
//! - the deceleration (least-squares slope of omega over `[0.1, 0.9] t_stop`), relative;
//! - `e_slide = max |omega - omega_ref| / omega0` over `t <= 0.9 t_stop`;
//! - `t_stop`, relative, which the pad vibration left at the stop moves by up to 1 %: a
//!   difference inside that band is not a discretisation error.
//!
//! With an element axis ([`BenchSettings::elements`]) every method's ladders run once per pad
//! element formulation, and every element's levels are measured against the first element's
//! references: the errors then say what each element costs for the drum's accuracy, not how
//! close it comes to its own finest level.
//!
//! A bench of one level (`levels = 1`, `coarser = 0`) runs each case at its own time step only,
//! with no reference and no errors: the cost of a set of cases as they are written, reported
//! with its total (the cases run one after another).
//!
//! A run shorter than [`REPEAT_BELOW_S`] is run once more as a warm-up and then `repeats`
//! times, and its wall time is the median (the solver's own wall time, without process start
//! or output of the report). The record keeps every measured time, the split of the median
//! run into assembly, linear solves (of which factorizations), contact solves and output, its
//! factorizations, and the largest peak resident memory of the level's runs. Where the runs
//! share a process ([`Isolation`]), a case's pad-mesh levels run after every method's smaller
//! pads, so that no level's peak memory holds what the allocator kept of a larger one; the
//! records keep each method's ladder order.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::{ReportError, e_slide, load_run, read_json};
use skid_cases::atomic::{write_atomic, write_json_atomic};
use skid_cases::model_file::summary::RunCost;
use skid_cases::peak_memory;
use skid_cases::runner::run_case_with;
use skid_cases::schema::{AdaptiveSpec, Case, ContactSolveSpec, PadFormulation, StepSpec};
use skid_cases::validate::CaseError;

/// Runs shorter than this (s) are repeated and their median taken.
pub const REPEAT_BELOW_S: f64 = 2.0;

/// Ratio of the element counts of successive pad-mesh levels, in every direction.
pub const MESH_RATIO: usize = 2;

/// Most pad-mesh levels of a bench: the fourth 3D level has 512 times the elements of the
/// case's pad (70,000 equations from the 10 x 1 x 1 benchmark pad).
pub const MAX_MESH_LEVELS: usize = 4;

/// Which resolution a ladder of levels refines.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Ladder {
    /// The time step of the dynamic steps, on the case's pad.
    #[default]
    TimeStep,
    /// The pad mesh, at the case's own time step.
    PadMesh,
}

impl Ladder {
    /// How the report names it.
    pub fn label(self) -> &'static str {
        match self {
            Self::TimeStep => "time step",
            Self::PadMesh => "pad mesh",
        }
    }
}

/// File name of the bench records in the output directory.
pub const BENCH_JSON: &str = "bench.json";

/// What to run.
#[derive(Clone, Debug, PartialEq)]
pub struct BenchSettings {
    /// Time-step levels per case and contact solve (at least 1; a single level is the case's
    /// own time step, measured against no reference).
    pub levels: usize,
    /// Ratio between successive time steps (> 1).
    pub ratio: f64,
    /// Levels coarser than the case's own time step (fewer than `levels`).
    pub coarser: usize,
    /// Timed repetitions of a short run (at least 1).
    pub repeats: usize,
    /// The methods to compare.
    pub methods: Vec<BenchMethod>,
    /// Pad-mesh levels per case and method at the case's own time step (0: none): the case's
    /// pad, then each level's element counts [`MESH_RATIO`] times the last's in every
    /// direction, the finest being the reference (at most [`MAX_MESH_LEVELS`]).
    pub meshes: usize,
    /// The pad elements to compare (empty: the case's own): every method's ladders are run
    /// with each, and the later elements' levels are measured against the first's references.
    pub elements: Vec<PadFormulation>,
    /// Which process runs each run.
    pub isolation: Isolation,
}

/// Which process runs each run of a level.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum Isolation {
    /// The bench's own, one run after another: a run's wall time and peak memory then depend
    /// a little on what earlier runs left in the process's allocator (see
    /// [`BenchRecord::peak_memory_mb`]).
    #[default]
    InProcess,
    /// A process of its own for every run, `skid --threads <threads> run <level>.json --out
    /// <level> --restart-every 0` with the `skid` executable given, so that no run sees what
    /// another left: its wall time is the solver's own (from its `summary.json`, without the
    /// process start) and its peak memory that of a process that ran nothing else.
    Process {
        /// The `skid` executable.
        skid: PathBuf,
        /// Its `--threads`.
        threads: usize,
    },
}

impl Default for BenchSettings {
    fn default() -> Self {
        Self {
            levels: 5,
            ratio: 2.0,
            coarser: 2,
            repeats: 5,
            methods: vec![BenchMethod::Reduced, BenchMethod::Global],
            meshes: 0,
            elements: Vec::new(),
            isolation: Isolation::InProcess,
        }
    }
}

/// How a case is run in the bench.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BenchMethod {
    /// The case as it is, with its own contact solve setting.
    Case,
    /// The case as it is, reduced contact solve.
    Reduced,
    /// The case as it is, global contact solve.
    Global,
    /// As [`Self::Case`], with adaptive increments in the dynamic steps (see [`adapt`]);
    /// measured against the finest `case` level where the bench runs it before, since both
    /// solve the same model.
    Adaptive,
    /// The pad quasi-static (`pad.quasi_static`), global contact solve.
    QuasiStatic,
    /// As [`Self::QuasiStatic`], with adaptive increments in the dynamic steps (see
    /// [`adapt`]); measured against the finest `quasi-static` level where the bench runs it,
    /// since both solve the same model.
    QuasiStaticAdaptive,
}

impl BenchMethod {
    /// Every method, in the order of the report.
    pub const ALL: [Self; 6] = [
        Self::Case,
        Self::Reduced,
        Self::Global,
        Self::Adaptive,
        Self::QuasiStatic,
        Self::QuasiStaticAdaptive,
    ];

    /// The name the method has on the command line and in the records.
    pub fn label(self) -> &'static str {
        match self {
            Self::Case => "case",
            Self::Reduced => "reduced",
            Self::Global => "global",
            Self::Adaptive => "adaptive",
            Self::QuasiStatic => "quasi-static",
            Self::QuasiStaticAdaptive => "quasi-static-adaptive",
        }
    }

    /// The method of a label.
    ///
    /// # Errors
    /// A message listing the labels.
    pub fn parse(label: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|m| m.label() == label)
            .ok_or_else(|| {
                let names: Vec<_> = Self::ALL.iter().map(|m| m.label()).collect();
                format!("expected one of {}, got {label:?}", names.join(", "))
            })
    }

    /// The fixed-step method that solves the same model, whose finest level is this method's
    /// reference.
    fn fixed_counterpart(self) -> Option<Self> {
        match self {
            Self::Adaptive => Some(Self::Case),
            Self::QuasiStaticAdaptive => Some(Self::QuasiStatic),
            _ => None,
        }
    }

    /// Whether the dynamic steps take adaptive increments: the methods measured against a
    /// fixed-step counterpart.
    fn is_adaptive(self) -> bool {
        self.fixed_counterpart().is_some()
    }

    /// Sets the case up to run by this method.
    fn apply(self, case: &mut Case) {
        let (solve, quasi_static) = match self {
            Self::Case | Self::Adaptive => (case.solver.contact_solve, case.pad.quasi_static),
            Self::Reduced => (ContactSolveSpec::Reduced, case.pad.quasi_static),
            Self::Global => (ContactSolveSpec::Global, case.pad.quasi_static),
            Self::QuasiStatic | Self::QuasiStaticAdaptive => (ContactSolveSpec::Global, true),
        };
        case.solver.contact_solve = solve;
        case.pad.quasi_static = quasi_static;
        if quasi_static {
            // the plate moves with the pad and has no inertia of its own either
            case.back_plate.mass = 0.0;
        }
    }
}

/// One level of one case and contact solve.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BenchRecord {
    /// Case name.
    pub case: String,
    /// Method ([`BenchMethod::label`]).
    pub method: String,
    /// The pad's element (its Abaqus name) where the bench has an element axis (absent:
    /// the case's own).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub element: Option<String>,
    /// Time step of the dynamic steps, s.
    pub dt: f64,
    /// `dt` over the case's own time step (absent in records written before it was kept).
    #[serde(default)]
    pub dt_factor: Option<f64>,
    /// The ladder the level belongs to (time step in older records).
    #[serde(default)]
    pub ladder: Ladder,
    /// The pad's elements, `circumferential x radial [x axial]` (absent in older records).
    #[serde(default)]
    pub pad_mesh: Option<String>,
    /// The model's equations (absent in older records).
    #[serde(default)]
    pub equations: Option<usize>,
    /// `"completed"` or `"failed"`.
    pub status: String,
    /// Median wall time, s.
    pub wall_time_s: f64,
    /// Every timed run's wall time, s.
    pub wall_times_s: Vec<f64>,
    /// Of the median run: assembly, s.
    pub assembly_s: f64,
    /// Of the median run: factorizations and solves, s.
    pub linear_solve_s: f64,
    /// Of the median run: of `linear_solve_s`, the numeric factorizations, s (absent in
    /// records written before it was kept).
    #[serde(default)]
    pub factorization_s: Option<f64>,
    /// Of the median run: conic and dense Coulomb solves, s.
    pub contact_solve_s: f64,
    /// Of the median run: history and field output, s (absent in older records).
    #[serde(default)]
    pub output_s: Option<f64>,
    /// The largest peak resident memory of the level's runs, MB (MiB): each run's
    /// `peak_memory_mb`, that of the process that ran it. `skid bench` runs each in a process
    /// of its own ([`Isolation::Process`]), so it is the run's own with the process's baseline
    /// of a few MB; in the bench's own process ([`Isolation::InProcess`]) the peak is reset
    /// before each run, and it includes what the allocator kept of earlier levels. Absent
    /// where it is not known (outside Linux) and in older records.
    #[serde(default)]
    pub peak_memory_mb: Option<f64>,
    /// Converged increments.
    pub increments: usize,
    /// Newton iterations.
    pub newton_iterations: usize,
    /// Numeric factorizations of every kind (absent in older records).
    #[serde(default)]
    pub factorizations: Option<usize>,
    /// Increments the global contact solve handed to the reduced one.
    pub contact_fallbacks: usize,
    /// Reduced increments that went on with global steps, their tangent without the contacts
    /// being indefinite (absent in older records).
    #[serde(default)]
    pub global_switches: usize,
    /// Stop time, s.
    pub t_stop: Option<f64>,
    /// Sliding deceleration, rad/s^2.
    pub deceleration: Option<f64>,
    /// `|decel - decel_ref| / |decel_ref|` against the finest level.
    pub deceleration_error: Option<f64>,
    /// `e_slide` against the finest level.
    pub e_slide: Option<f64>,
    /// `|t_stop - t_stop_ref| / t_stop_ref` against the finest level.
    pub t_stop_difference: Option<f64>,
    /// Whether this level is the reference of its case and method.
    pub reference: bool,
}

impl BenchRecord {
    /// What the report tells its ladders apart by within a case: the method, and the pad
    /// element where the bench has an element axis (`global, CPE4H`).
    pub fn variant(&self) -> String {
        match &self.element {
            Some(element) => format!("{}, {element}", self.method),
            None => self.method.clone(),
        }
    }
}

/// Why a bench could not be completed.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// A case could not be run.
    #[error(transparent)]
    Case(#[from] CaseError),
    /// A run's outputs could not be read back.
    #[error(transparent)]
    Report(#[from] ReportError),
    /// Settings out of range.
    #[error("bench settings: {0}")]
    Settings(String),
    /// A run's own process could not be started or ended without its summary.
    #[error("{case}: {message}")]
    Process {
        /// The level's case file.
        case: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// The records could not be written.
    #[error("cannot write {path}: {source}")]
    Write {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
}

/// Local error tolerance of an adaptive method's level at `factor` 1.
pub const ADAPTIVE_TOLERANCE: f64 = 1e-6;

/// The adaptive increments of a level at `factor`, in a dynamic step whose (scaled) time step is
/// `dt`: `dt` first, tolerance `ADAPTIVE_TOLERANCE factor^2` (the estimate is of order `h^2`
/// in the change of acceleration), increments from `dt / 1000` to `50 dt` (at most the step).
pub fn adapt(dt: f64, duration: f64, factor: f64) -> AdaptiveSpec {
    AdaptiveSpec {
        tolerance: ADAPTIVE_TOLERANCE * factor * factor,
        min_dt: dt * 1e-3,
        max_dt: (50.0 * dt).min(duration),
    }
}

/// The case with every dynamic step's time step multiplied by `factor`, set up for `method`.
pub fn level_case(case: &Case, factor: f64, method: BenchMethod) -> Case {
    let mut case = case.clone();
    for step in &mut case.steps {
        if let StepSpec::Dynamic {
            dt,
            duration,
            adaptive,
            ..
        } = step
        {
            *dt *= factor;
            if method.is_adaptive() {
                *adaptive = Some(adapt(*dt, *duration, factor));
            }
        }
    }
    method.apply(&mut case);
    case
}

/// The case with its pad's element counts multiplied by `factor` in every direction (the
/// axial one in 3D only).
pub fn mesh_case(case: &Case, factor: usize) -> Case {
    let mut case = case.clone();
    let elements = &mut case.pad.elements;
    elements.circumferential *= factor;
    elements.radial *= factor;
    if case.dimension == 3 {
        elements.axial *= factor;
    }
    case
}

/// The median of `values` (the mean of the middle two for an even count); `NaN` if empty.
pub fn median(values: &[f64]) -> f64 {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len();
    match n {
        0 => f64::NAN,
        _ if n % 2 == 1 => sorted[n / 2],
        _ => 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]),
    }
}

/// The smallest dynamic time step of a case (the one the ladder's factors apply to).
fn base_dt(case: &Case) -> Option<f64> {
    crate::convergence::time_steps(case)
        .into_iter()
        .reduce(f64::min)
}

/// Runs the ladders of every case (`(case, source file)`) into `out/runs/<case>/<method>/<k>`
/// (the pad-mesh ladder's finer levels into `.../mesh-<k>`; its first is the time-step
/// ladder's level at the case's own step, the same run), calling `progress` with a line per
/// level as it runs (a case's finer pads after all its methods' time-step ladders), and writes
/// `out/bench.json`, each method's ladders in order.
///
/// # Errors
/// [`BenchError`] for bad settings, a case that cannot be built or outputs that cannot be
/// written or read back. A run that stops early is a record with status `"failed"`.
pub fn run_bench(
    cases: &[(Case, PathBuf)],
    settings: &BenchSettings,
    out: &Path,
    mut progress: impl FnMut(&BenchRecord),
) -> Result<Vec<BenchRecord>, BenchError> {
    let ratio_ok = settings.ratio.partial_cmp(&1.0) == Some(std::cmp::Ordering::Greater)
        && settings.ratio.is_finite();
    if settings.levels < 1 || !ratio_ok || settings.coarser >= settings.levels {
        return Err(BenchError::Settings(format!(
            "expected at least 1 level, a finite ratio above 1 and fewer coarser levels than \
             levels, got {} levels, ratio {}, {} coarser",
            settings.levels, settings.ratio, settings.coarser
        )));
    }
    if settings.repeats == 0 || settings.methods.is_empty() {
        return Err(BenchError::Settings(
            "expected at least one repeat and one contact solve".into(),
        ));
    }
    if settings.meshes > MAX_MESH_LEVELS {
        return Err(BenchError::Settings(format!(
            "expected at most {MAX_MESH_LEVELS} pad-mesh levels (each has {} times the \
             elements of the last in 3D), got {}",
            MESH_RATIO.pow(3),
            settings.meshes
        )));
    }
    let mut records = Vec::new();
    for (case, source) in cases {
        let Some(dt) = base_dt(case) else {
            return Err(BenchError::Settings(format!(
                "{}: the case has no dynamic step to refine",
                source.display()
            )));
        };
        let variants: Vec<Option<PadFormulation>> = if settings.elements.is_empty() {
            vec![None]
        } else {
            settings.elements.iter().copied().map(Some).collect()
        };
        // the references of the first element's ladders, shared by the others
        let mut shared: Option<Vec<References>> = None;
        for element in variants {
            let mut variant = case.clone();
            let dir = match element {
                Some(e) => {
                    variant.pad.formulation = e;
                    out.join("runs").join(&case.name).join(e.name())
                }
                None => out.join("runs").join(&case.name),
            };
            let bench = Variant {
                case: &variant,
                element,
                source,
                dt,
                dir,
            };
            let (mut measured, references) =
                bench.run(settings, shared.as_deref(), &mut progress)?;
            records.append(&mut measured);
            shared.get_or_insert(references);
        }
    }
    let path = out.join(BENCH_JSON);
    std::fs::create_dir_all(out)
        .and_then(|()| write_json_atomic(&path, &records))
        .map_err(|source| BenchError::Write { path, source })?;
    Ok(records)
}

/// A run directory and the record of its level.
type RunDir = (BenchRecord, PathBuf);

/// The levels one method's ladders were measured against, for the later elements of a bench
/// with an element axis to share.
struct References {
    /// The method.
    method: BenchMethod,
    /// The time-step ladder's reference.
    time_step: Option<RunDir>,
    /// The pad-mesh ladder's reference.
    pad_mesh: Option<RunDir>,
}

/// One case with one pad element (or as written): every method's ladders.
struct Variant<'a> {
    /// The case, its pad's formulation set.
    case: &'a Case,
    /// The pad element the bench sets, if it has an element axis.
    element: Option<PadFormulation>,
    /// The case file.
    source: &'a Path,
    /// The case's smallest dynamic time step, s.
    dt: f64,
    /// Where its methods' runs go (`<dir>/<method>/...`).
    dir: PathBuf,
}

impl Variant<'_> {
    /// Runs every method's ladders, calling `progress` with a line per level (the finer pads
    /// after every method's time-step ladder), and measures each ladder against `shared`'s
    /// reference of its method where given (the first element's), else against its own finest
    /// level (or, for an adaptive method, its fixed counterpart's); returns the records, each
    /// method's ladders in order, and the references used.
    ///
    /// # Errors
    /// As [`run_level`] and [`measure_against`].
    fn run(
        &self,
        settings: &BenchSettings,
        shared: Option<&[References]>,
        progress: &mut impl FnMut(&BenchRecord),
    ) -> Result<(Vec<BenchRecord>, Vec<References>), BenchError> {
        let (case, dt) = (self.case, self.dt);
        let shared_of =
            |method: BenchMethod| shared.and_then(|s| s.iter().find(|r| r.method == method));
        let mut references: Vec<References> = Vec::new();
        // per method: its run directory, its time-step levels and its pad-mesh levels
        let mut ladders = Vec::new();
        for &method in &settings.methods {
            let dir = self.dir.join(method.label());
            let mut runs = Vec::new();
            for k in 0..settings.levels {
                let exponent = i32::try_from(settings.coarser).unwrap_or(i32::MAX)
                    - i32::try_from(k).unwrap_or(i32::MAX);
                let factor = settings.ratio.powi(exponent);
                let level = Level {
                    case: level_case(case, factor, method),
                    dir: dir.join(k.to_string()),
                    method,
                    element: self.element,
                    ladder: Ladder::TimeStep,
                    dt: dt * factor,
                    dt_factor: factor,
                    reference: settings.levels > 1 && k + 1 == settings.levels,
                };
                let record = run_level(&level, self.source, settings)?;
                progress(&record);
                runs.push((record, level.dir));
            }
            // the case's own level, which is also the first of the pad-mesh ladder
            let mut meshes = Vec::new();
            if settings.meshes > 0 {
                let (record, dir) = runs[settings.coarser].clone();
                let record = BenchRecord {
                    ladder: Ladder::PadMesh,
                    reference: false,
                    ..record
                };
                progress(&record);
                meshes.push((record, dir));
            }
            let mut time_step = None;
            if settings.levels > 1 {
                let counterpart = method.fixed_counterpart().and_then(|c| {
                    references
                        .iter()
                        .find(|r| r.method == c)
                        .and_then(|r| r.time_step.clone())
                });
                let other = shared_of(method)
                    .and_then(|r| r.time_step.clone())
                    .or(counterpart);
                time_step = measure_ladder(&mut runs, other)?;
            }
            references.push(References {
                method,
                time_step,
                pad_mesh: None,
            });
            ladders.push((method, dir, runs, meshes));
        }
        // The finer pads run after every method's smaller ones, so that no level follows a
        // larger one: its peak memory then holds no allocator leftovers of a larger pad.
        for k in 1..settings.meshes {
            for (method, dir, _, meshes) in &mut ladders {
                let level = Level {
                    case: mesh_case(&level_case(case, 1.0, *method), MESH_RATIO.pow(k as u32)),
                    dir: dir.join(format!("mesh-{k}")),
                    method: *method,
                    element: self.element,
                    ladder: Ladder::PadMesh,
                    dt,
                    dt_factor: 1.0,
                    reference: k + 1 == settings.meshes,
                };
                let record = run_level(&level, self.source, settings)?;
                progress(&record);
                meshes.push((record, level.dir));
            }
        }
        let mut records = Vec::new();
        for ((method, _, runs, mut meshes), refs) in ladders.into_iter().zip(&mut references) {
            records.extend(runs.into_iter().map(|(r, _)| r));
            if settings.meshes > 1 {
                let other = shared_of(method).and_then(|r| r.pad_mesh.clone());
                refs.pad_mesh = measure_ladder(&mut meshes, other)?;
            }
            records.extend(meshes.into_iter().map(|(r, _)| r));
        }
        Ok((records, references))
    }
}

/// Measures the levels `runs` of a ladder against `other` where given (none of them is then
/// its reference), else against their finest (the last); returns the reference used.
///
/// # Errors
/// As [`measure_against`].
fn measure_ladder(
    runs: &mut [RunDir],
    other: Option<RunDir>,
) -> Result<Option<RunDir>, BenchError> {
    let reference = match other {
        Some(other) => {
            for (r, _) in runs.iter_mut() {
                r.reference = false;
            }
            other
        }
        None => match runs.last() {
            Some(last) => last.clone(),
            None => return Ok(None),
        },
    };
    measure_against(runs, &reference.0, &reference.1)?;
    Ok(Some(reference))
}

/// A level of a ladder: the case it runs, where, and what its record says of it.
struct Level {
    /// The case as the level runs it.
    case: Case,
    /// Its run directory.
    dir: PathBuf,
    /// The method it is run by.
    method: BenchMethod,
    /// The pad element the bench set, if it has an element axis.
    element: Option<PadFormulation>,
    /// The ladder it belongs to.
    ladder: Ladder,
    /// Its dynamic time step, s.
    dt: f64,
    /// `dt` over the case's own time step.
    dt_factor: f64,
    /// Whether it is its ladder's reference.
    reference: bool,
}

/// What the bench reads of a run's summary.
#[derive(Debug, Deserialize)]
struct RunOutcome {
    /// `"completed"` or `"failed"`.
    status: String,
    /// The drum's stop time, s.
    t_stop: Option<f64>,
    /// Its sliding deceleration, rad/s^2.
    deceleration: Option<f64>,
    /// The run's cost.
    #[serde(flatten)]
    cost: RunCost,
}

/// How each run of a level starts.
enum Start<'a> {
    /// In this process.
    Here,
    /// As `skid run` of the level's case file `file`, in a process of its own.
    Child {
        /// The `skid` executable.
        skid: &'a Path,
        /// Its `--threads`.
        threads: usize,
        /// The level's case file.
        file: PathBuf,
    },
}

impl<'a> Start<'a> {
    /// How `level`'s runs start under `isolation`; for a process of their own, the level's case
    /// is written beside its run directory (`<dir>.json`) once for all of them.
    ///
    /// # Errors
    /// [`BenchError::Write`] if the case file cannot be written.
    fn prepare(level: &Level, isolation: &'a Isolation) -> Result<Self, BenchError> {
        let Isolation::Process { skid, threads } = isolation else {
            return Ok(Self::Here);
        };
        let file = level.dir.with_extension("json");
        let written = serde_json::to_string_pretty(&level.case)
            .map_err(std::io::Error::other)
            .and_then(|text| {
                std::fs::create_dir_all(&level.dir)?;
                write_atomic(&file, &text)
            });
        written.map_err(|source| BenchError::Write {
            path: file.clone(),
            source,
        })?;
        Ok(Self::Child {
            skid,
            threads: *threads,
            file,
        })
    }

    /// Runs `level` once without restart files (so that the wall time is the solver's).
    ///
    /// # Errors
    /// [`BenchError::Case`] if the case cannot be run in this process, [`BenchError::Process`]
    /// if its own process could not be started or failed without a summary.
    fn run(&self, level: &Level, source: &Path) -> Result<RunOutcome, BenchError> {
        let Self::Child {
            skid,
            threads,
            file,
        } = self
        else {
            let resettable = peak_memory::reset();
            let summary = run_case_with(&level.case, source, &level.dir, 0)?;
            let mut cost = summary.cost;
            if !resettable {
                cost.peak_memory_mb = None;
            }
            return Ok(RunOutcome {
                status: summary.status,
                t_stop: summary.t_stop,
                deceleration: summary.deceleration,
                cost,
            });
        };
        let failure = |message: String| BenchError::Process {
            case: file.clone(),
            message,
        };
        // a summary left by an earlier run must not pass for this one's
        let summary = level.dir.join("summary.json");
        if summary.exists() {
            std::fs::remove_file(&summary).map_err(|source| BenchError::Write {
                path: summary.clone(),
                source,
            })?;
        }
        let output = std::process::Command::new(skid)
            .arg("--threads")
            .arg(threads.to_string())
            .arg("run")
            .arg(file)
            .arg("--out")
            .arg(&level.dir)
            .args(["--restart-every", "0"])
            .stdin(std::process::Stdio::null())
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped())
            .output()
            .map_err(|e| failure(format!("cannot start {}: {e}", skid.display())))?;
        // exit status 1 is a run that stopped early, with its summary
        if !matches!(output.status.code(), Some(0 | 1)) {
            return Err(failure(format!(
                "skid run ended with {}: {}",
                output.status,
                String::from_utf8_lossy(&output.stderr).trim()
            )));
        }
        Ok(read_json(&summary, "a skid run summary")?)
    }
}

/// Runs `level` as the bench times it (a run shorter than [`REPEAT_BELOW_S`] once as a warm-up
/// and then `settings.repeats` times, the median's run reported), with the largest peak
/// resident memory of its runs; returns its record, without errors.
///
/// # Errors
/// As [`Start::prepare`] and [`Start::run`].
fn run_level(
    level: &Level,
    source: &Path,
    settings: &BenchSettings,
) -> Result<BenchRecord, BenchError> {
    let start = Start::prepare(level, &settings.isolation)?;
    let mut peak: Option<f64> = None;
    let mut run = || {
        let outcome = start.run(level, source)?;
        peak = match (peak, outcome.cost.peak_memory_mb) {
            (Some(a), Some(b)) => Some(a.max(b)),
            (a, b) => a.or(b),
        };
        Ok::<_, BenchError>(outcome)
    };
    let mut summary = run()?;
    let mut times = vec![summary.cost.wall_time_s];
    if summary.cost.wall_time_s < REPEAT_BELOW_S {
        times.clear();
        let mut timed = Vec::new();
        for _ in 0..settings.repeats {
            let s = run()?;
            times.push(s.cost.wall_time_s);
            timed.push(s);
        }
        let middle = median(&times);
        if let Some(closest) = timed.into_iter().min_by(|a, b| {
            (a.cost.wall_time_s - middle)
                .abs()
                .total_cmp(&(b.cost.wall_time_s - middle).abs())
        }) {
            summary = closest;
        }
    }
    let cost = &summary.cost;
    Ok(BenchRecord {
        case: level.case.name.clone(),
        method: level.method.label().into(),
        element: level
            .element
            .map(|e| e.formulation().abaqus_name(level.case.dimension).into()),
        dt: level.dt,
        dt_factor: Some(level.dt_factor),
        ladder: level.ladder,
        pad_mesh: Some(crate::convergence::pad_mesh_label(&level.case)),
        equations: Some(cost.equations),
        status: summary.status.clone(),
        wall_time_s: median(&times),
        wall_times_s: times,
        assembly_s: cost.assembly_s,
        linear_solve_s: cost.linear_solve_s,
        factorization_s: Some(cost.factorization_s),
        contact_solve_s: cost.contact_solve_s,
        output_s: Some(cost.output_s),
        peak_memory_mb: peak,
        increments: cost.increments,
        newton_iterations: cost.newton_iterations,
        factorizations: Some(cost.factorizations()),
        contact_fallbacks: cost.contact_fallbacks,
        global_switches: cost.global_switches,
        t_stop: summary.t_stop,
        deceleration: summary.deceleration,
        deceleration_error: None,
        e_slide: None,
        t_stop_difference: None,
        reference: level.reference,
    })
}

/// Fills the errors of every level against the reference run (its record and directory).
fn measure_against(
    runs: &mut [(BenchRecord, PathBuf)],
    reference: &BenchRecord,
    reference_dir: &Path,
) -> Result<(), BenchError> {
    let reference_run = load_run(reference_dir)?;
    for (record, dir) in runs.iter_mut() {
        let relative = |a: Option<f64>, b: Option<f64>| match (a, b) {
            (Some(a), Some(b)) if b != 0.0 => Some((a - b).abs() / b.abs()),
            _ => None,
        };
        record.deceleration_error = relative(record.deceleration, reference.deceleration);
        record.t_stop_difference = relative(record.t_stop, reference.t_stop);
        let run = load_run(dir)?;
        let omega0 = run.summary.omega0;
        record.e_slide = record
            .t_stop
            .and_then(|t| e_slide(&run.history, t, omega0, &reference_run.history));
    }
    Ok(())
}

/// File name of the bench report in the output directory.
pub const BENCH_MD: &str = "bench.md";

/// Writes `bench.md` (the table of every level), `work-precision.svg` (the deceleration
/// error and e_slide of the time-step ladders against the median wall time, one curve each per
/// case and method) and, if there are pad-mesh ladders, `work-precision-mesh.svg` (theirs)
/// into `out`.
///
/// # Errors
/// [`BenchError`] if a file cannot be written.
pub fn write_bench_report(records: &[BenchRecord], out: &Path) -> Result<(), BenchError> {
    use crate::format::{percent, show};
    use std::fmt::Write as _;
    // one plot per ladder: the time steps' (always written) and the pad meshes' (if run)
    let plots = [
        (Ladder::TimeStep, crate::plot::WORK_PRECISION_SVG),
        (Ladder::PadMesh, crate::plot::WORK_PRECISION_MESH_SVG),
    ];
    for (ladder, file) in plots {
        let mut series: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
        for r in records
            .iter()
            .filter(|r| !r.reference && r.ladder == ladder)
        {
            for (quantity, error) in [
                ("deceleration", r.deceleration_error),
                ("e_slide", r.e_slide),
            ] {
                let label = format!("{} ({}): {quantity}", r.case, r.variant());
                let point = (r.wall_time_s, error.unwrap_or(f64::NAN));
                match series.iter_mut().find(|(l, _)| *l == label) {
                    Some((_, points)) => points.push(point),
                    None => series.push((label, vec![point])),
                }
            }
        }
        if ladder == Ladder::PadMesh && series.is_empty() {
            continue;
        }
        crate::plot::plot_log_log(
            &format!("Work-precision: {}", ladder.label()),
            &series,
            (
                "median wall time [s]",
                "error against the finest level (deceleration: relative; e_slide)",
            ),
            &out.join(file),
        )?;
    }
    let mut md = String::from("# Work against error (`skid bench`)\n\n");
    md.push_str(
        "Each case at a ladder of time steps (every dynamic step's dt scaled alike) with each \
         method (`case`: the case as it is, with its own contact solve; `reduced` and \
         `global`: the contact solves on the case as it is; `adaptive`: the case with adaptive \
         increments, dt being the first one and the tolerance 1e-6 times the square of the \
         level's dt ratio to the case's; `quasi-static`: the pad without inertia, global \
         solve; `quasi-static-adaptive`: the same with adaptive increments), and, where asked, \
         at a ladder of pad meshes at its own time step (each level with twice the elements of \
         the last in every direction); the finest level of a case, method and ladder is its \
         reference (with several pad elements, the method's `, CPE4H` etc.: that of the first \
         element, against which the others are measured), and the adaptive methods' time steps are measured against the finest \
         `case` and `quasi-static` levels where the bench runs them. Wall time: the \
         solver's, median of the timed runs (runs under 2 s: one warm-up, then the repeats). \
         Errors against the reference: the deceleration (relative), e_slide (max |omega - \
         omega_ref| / omega0 over t <= 0.9 t_stop) and t_stop (relative; the pad vibration \
         left at the stop moves it by up to 1 %, DRUM.md 2.2, so differences inside that band \
         are not discretisation errors). The time split is the median run's (the factorizations \
         are a part of the linear solves; output: the history written at every increment); \
         peak memory is the largest peak resident memory of the level's runs, each that of \
         the process that ran it (`skid bench` runs every run in a process of its own, whose \
         baseline of a few MB it includes).\n\n",
    );
    let _ = writeln!(
        md,
        "![deceleration error and e_slide against wall time, time-step ladders]({})\n",
        crate::plot::WORK_PRECISION_SVG
    );
    if records.iter().any(|r| r.ladder == Ladder::PadMesh) {
        let _ = writeln!(
            md,
            "![deceleration error and e_slide against wall time, pad-mesh ladders]({})\n",
            crate::plot::WORK_PRECISION_MESH_SVG
        );
    }
    md.push_str(
        "| case | method | ladder | dt [s] | pad mesh | equations | status | wall [s] | runs | assembly / linear (factorization) / contact / output [s] | peak memory, at most [MB] | increments | Newton iterations | factorizations | fallbacks / switches | deceleration [rad/s^2] | deceleration error [%] | e_slide [%] | t_stop [s] | t_stop difference [%] |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let seconds = |t: Option<f64>| t.map_or_else(|| "n/a".into(), |t| format!("{t:.3}"));
    for r in records {
        // the reference is marked at what its ladder refines
        let marked = |ladder: Ladder| {
            if r.reference && r.ladder == ladder {
                " (reference)"
            } else {
                ""
            }
        };
        let _ = writeln!(
            md,
            "| {} | {} | {} | {}{} | {}{} | {} | {} | {:.4} | {} | {:.3} / {:.3} ({}) / {:.3} / {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            r.case,
            r.variant(),
            r.ladder.label(),
            show(Some(r.dt)),
            marked(Ladder::TimeStep),
            r.pad_mesh.as_deref().unwrap_or("n/a"),
            marked(Ladder::PadMesh),
            r.equations.map_or_else(|| "n/a".into(), |n| n.to_string()),
            r.status,
            r.wall_time_s,
            r.wall_times_s.len(),
            r.assembly_s,
            r.linear_solve_s,
            seconds(r.factorization_s),
            r.contact_solve_s,
            seconds(r.output_s),
            r.peak_memory_mb
                .map_or_else(|| "n/a".into(), |mb| format!("{mb:.0}")),
            r.increments,
            r.newton_iterations,
            r.factorizations
                .map_or_else(|| "n/a".into(), |f| f.to_string()),
            format_args!("{} / {}", r.contact_fallbacks, r.global_switches),
            show(r.deceleration),
            percent(r.deceleration_error),
            percent(r.e_slide),
            show(r.t_stop),
            percent(r.t_stop_difference),
        );
    }
    md.push_str(&within_target(records));
    md.push_str(&own_time_step(records));
    md.push_str(&model_change(records));
    let path = out.join(BENCH_MD);
    write_atomic(&path, &md).map_err(|source| BenchError::Write { path, source })
}

/// The accuracy a level is asked for in [`within_target`]: the sliding deceleration within
/// this fraction of its reference.
pub const TARGET_DECELERATION_ERROR: f64 = 1e-3;
/// The accuracy a level is asked for in [`within_target`]: `e_slide` at most this.
pub const TARGET_E_SLIDE: f64 = 2e-3;

/// How far a level is from the error target: the larger of its deceleration error over
/// [`TARGET_DECELERATION_ERROR`] and its e_slide over [`TARGET_E_SLIDE`] (at most 1 within the
/// target; infinite where an error is missing or not finite).
fn target_ratio(r: &BenchRecord) -> f64 {
    let ratio = |error: Option<f64>, limit: f64| match error {
        Some(e) if e.is_finite() => e / limit,
        _ => f64::INFINITY,
    };
    ratio(r.deceleration_error, TARGET_DECELERATION_ERROR).max(ratio(r.e_slide, TARGET_E_SLIDE))
}

/// Whether a level's errors are its own to judge: it completed and is not a reference (whose
/// errors are zero by definition).
fn is_measured(r: &BenchRecord) -> bool {
    r.status == "completed" && !r.reference
}

/// Whether a level is within the error target: measured ([`is_measured`]), with a
/// [`target_ratio`] of at most 1.
fn meets_target(r: &BenchRecord) -> bool {
    is_measured(r) && target_ratio(r) <= 1.0
}

/// For each case and method, the level of least median wall time among those within the error
/// target ([`meets_target`]), the fastest of a case in bold; a method none of whose levels is
/// within it is listed with its most accurate level. The answer to "what does this accuracy
/// cost", read off the ladder.
fn within_target(records: &[BenchRecord]) -> String {
    use crate::format::{percent, plain, show};
    use std::fmt::Write as _;
    if !records.iter().any(|r| r.deceleration_error.is_some()) {
        return String::new();
    }
    let mut md = format!(
        "\n## The cheapest level within the error target\n\nFor each case and method, the \
         level of least wall time whose deceleration is within {} % and whose e_slide is at \
         most {} % of its reference (the method's finest level, or the fixed-step one it is \
         measured against); the fastest of a case in bold. A pad-mesh ladder's levels are \
         measured against its finest mesh, its fastest in bold apart from the time steps'. The \
         quasi-static methods answer a model without the pad's inertia: what that changes is in \
         the last section.\n\n\
         | case | method | level (dt [s] or pad mesh) | wall [s] | deceleration error [%] | e_slide [%] |\n\
         |---|---|---|---|---|---|\n",
        plain(100.0 * TARGET_DECELERATION_ERROR),
        plain(100.0 * TARGET_E_SLIDE)
    );
    let mut cases: Vec<&str> = records.iter().map(|r| r.case.as_str()).collect();
    cases.dedup();
    let ladders = [Ladder::TimeStep, Ladder::PadMesh];
    for (case, ladder) in cases
        .into_iter()
        .flat_map(|case| ladders.map(|ladder| (case, ladder)))
    {
        let of_case: Vec<&BenchRecord> = records
            .iter()
            .filter(|r| r.case == case && r.ladder == ladder)
            .collect();
        if !of_case.iter().any(|r| r.deceleration_error.is_some()) {
            // a ladder of one level, measured against nothing
            continue;
        }
        let fastest = of_case
            .iter()
            .filter(|r| meets_target(r))
            .map(|r| r.wall_time_s)
            .fold(f64::INFINITY, f64::min);
        let mut methods: Vec<String> = of_case.iter().map(|r| r.variant()).collect();
        methods.dedup();
        for method in methods {
            let levels = of_case.iter().filter(|r| r.variant() == method);
            let cheapest = levels
                .clone()
                .filter(|r| meets_target(r))
                .min_by(|a, b| a.wall_time_s.total_cmp(&b.wall_time_s));
            let shown = cheapest.map(|r| (r, "")).or_else(|| {
                levels
                    .filter(|r| is_measured(r))
                    .min_by(|a, b| target_ratio(a).total_cmp(&target_ratio(b)))
                    .map(|r| (r, "none within the target; most accurate: "))
            });
            let name = match ladder {
                Ladder::TimeStep => method.to_string(),
                Ladder::PadMesh => format!("{method}, pad mesh"),
            };
            let line = match shown {
                Some((r, note)) => {
                    let fastest = meets_target(r) && r.wall_time_s == fastest;
                    let bold = if fastest { "**" } else { "" };
                    let level = match ladder {
                        Ladder::TimeStep => show(Some(r.dt)),
                        Ladder::PadMesh => r.pad_mesh.clone().unwrap_or_else(|| "n/a".into()),
                    };
                    format!(
                        "| {case} | {name} | {note}{level} | {bold}{:.4}{bold} | {} | {} |",
                        r.wall_time_s,
                        percent(r.deceleration_error),
                        percent(r.e_slide)
                    )
                }
                None => format!("| {case} | {name} | no completed level with an error | | | |"),
            };
            let _ = writeln!(md, "{line}");
        }
    }
    md
}

/// The cases at their own time step (`dt_factor` 1), method by method, with the sum of their
/// median wall times: what running them one after another costs.
fn own_time_step(records: &[BenchRecord]) -> String {
    use crate::format::show;
    use std::fmt::Write as _;
    let own: Vec<&BenchRecord> = records
        .iter()
        .filter(|r| {
            r.ladder == Ladder::TimeStep && r.dt_factor.is_some_and(|f| (f - 1.0).abs() < 1e-12)
        })
        .collect();
    if own.is_empty() {
        return String::new();
    }
    let mut md = String::from(
        "\n## The cases at their own time step\n\nEach case as written (its own time step), \
         by method; the total is the sum of the median wall times, the cost of running the \
         cases one after another.\n\n\
         | method | case | status | wall [s] | increments | Newton iterations | t_stop [s] |\n\
         |---|---|---|---|---|---|---|\n",
    );
    let mut methods: Vec<String> = own.iter().map(|r| r.variant()).collect();
    methods.sort_unstable();
    methods.dedup();
    for method in methods {
        let rows: Vec<&&BenchRecord> = own.iter().filter(|r| r.variant() == method).collect();
        for r in &rows {
            let _ = writeln!(
                md,
                "| {method} | {} | {} | {:.4} | {} | {} | {} |",
                r.case,
                r.status,
                r.wall_time_s,
                r.increments,
                r.newton_iterations,
                show(r.t_stop)
            );
        }
        let total: f64 = rows.iter().map(|r| r.wall_time_s).sum();
        let completed = rows.iter().all(|r| r.status == "completed");
        let _ = writeln!(
            md,
            "| {method} | **total of {} cases** | {} | **{total:.4}** | {} | {} | |",
            rows.len(),
            if completed { "completed" } else { "failed" },
            rows.iter().map(|r| r.increments).sum::<usize>(),
            rows.iter().map(|r| r.newton_iterations).sum::<usize>(),
        );
    }
    md
}

/// What the quasi-static pad changes in the answer: for every case with both, the quasi-static
/// reference against the dynamic one (the `reduced` reference, else the `global` one, else the `case` one).
fn model_change(records: &[BenchRecord]) -> String {
    use crate::format::percent;
    use std::fmt::Write as _;
    let reference = |case: &str, method: BenchMethod| {
        records.iter().find(|r| {
            r.reference
                && r.ladder == Ladder::TimeStep
                && r.case == case
                && r.method == method.label()
        })
    };
    let mut md = String::new();
    let mut cases: Vec<&str> = records.iter().map(|r| r.case.as_str()).collect();
    cases.dedup();
    for case in cases {
        let Some(qs) = reference(case, BenchMethod::QuasiStatic) else {
            continue;
        };
        let Some(dynamic) = reference(case, BenchMethod::Reduced)
            .or(reference(case, BenchMethod::Global))
            .or(reference(case, BenchMethod::Case))
        else {
            continue;
        };
        let relative = |a: Option<f64>, b: Option<f64>| match (a, b) {
            (Some(a), Some(b)) if b != 0.0 => percent(Some((a - b) / b)),
            _ => "n/a".into(),
        };
        if md.is_empty() {
            md.push_str(
                "\n## What the quasi-static pad changes\n\nEach case's quasi-static reference \
                 against its dynamic one (finest levels, signed):\n\n\
                 | case | deceleration [%] | t_stop [%] |\n|---|---|---|\n",
            );
        }
        let _ = writeln!(
            md,
            "| {case} | {} | {} |",
            relative(qs.deceleration, dynamic.deceleration),
            relative(qs.t_stop, dynamic.t_stop)
        );
    }
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_of_odd_and_even_counts() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), 2.5);
        assert!(median(&[]).is_nan());
    }

    /// A completed level of case `a` with the given errors and wall time.
    fn level(method: &str, dt: f64, wall: f64, errors: Option<(f64, f64)>) -> BenchRecord {
        BenchRecord {
            case: "a".into(),
            method: method.into(),
            element: None,
            dt,
            dt_factor: None,
            ladder: Ladder::TimeStep,
            pad_mesh: None,
            equations: None,
            status: "completed".into(),
            wall_time_s: wall,
            wall_times_s: vec![wall],
            assembly_s: 0.0,
            linear_solve_s: 0.0,
            factorization_s: None,
            contact_solve_s: 0.0,
            output_s: None,
            peak_memory_mb: None,
            increments: 1,
            newton_iterations: 1,
            factorizations: None,
            contact_fallbacks: 0,
            global_switches: 0,
            t_stop: Some(0.1),
            deceleration: Some(600.0),
            deceleration_error: Some(errors.map_or(0.0, |e| e.0)),
            e_slide: Some(errors.map_or(0.0, |e| e.1)),
            t_stop_difference: Some(0.0),
            reference: errors.is_none(),
        }
    }

    /// Of the levels within the error target, the cheapest of each method is listed, the
    /// fastest of the case in bold; neither a reference (no error of its own) nor a level over
    /// either limit counts, and a method with no level within the target shows its most
    /// accurate one.
    #[test]
    fn cheapest_level_within_the_error_target() {
        let records = [
            level("case", 4e-4, 0.02, Some((2e-3, 1e-3))),
            level("case", 2e-4, 0.05, Some((5e-4, 1e-3))),
            level("case", 1e-4, 0.1, Some((1e-4, 5e-4))),
            level("case", 5e-5, 0.2, None),
            level("global", 4e-4, 0.03, Some((3e-3, 1e-3))),
            level("global", 2e-4, 0.06, Some((2e-3, 4e-3))),
            level("global", 1e-4, 0.001, None),
            level("quasi-static-adaptive", 1e-3, 0.01, Some((1e-8, 9e-4))),
        ];
        let md = within_target(&records);
        let rows: Vec<&str> = md.lines().filter(|l| l.starts_with("| a |")).collect();
        assert_eq!(rows.len(), 3, "{md}");
        assert!(
            rows[0].starts_with("| a | case | 2.000e-4 | 0.0500 |"),
            "{md}"
        );
        assert!(
            rows[1].starts_with("| a | global | none within the target; most accurate: 2.000e-4 |"),
            "{md}"
        );
        assert!(
            rows[2].starts_with("| a | quasi-static-adaptive | 0.001000 | **0.0100** |"),
            "{md}"
        );
        assert!(
            md.contains("within 0.1 %") && md.contains("at most 0.2 %"),
            "{md}"
        );
        // a bench of one level has no errors and no such section
        let mut own = level("case", 1e-4, 0.1, None);
        own.deceleration_error = None;
        assert!(within_target(&[own]).is_empty());
    }

    /// `2d-analytic` with 10 ms of spin-down, and its file name.
    fn short_2d_case() -> (Case, PathBuf) {
        let text = include_str!("../../../cases/drum/2d-analytic.json");
        let overrides = ["steps[1].duration=0.01".to_string()];
        let file = PathBuf::from("2d-analytic.json");
        let case = skid_cases::validate::parse_case(text, &file, &overrides).expect("case");
        (case, file)
    }

    /// A short 2D spin-down on two levels and one solve: the finest level is the reference
    /// with zero errors; the coarser one has a positive deceleration error; every run is
    /// timed `repeats` times; the records are written.
    #[test]
    fn ladder_measures_against_its_finest_level() {
        let (case, file) = short_2d_case();
        let dir = tempfile::tempdir().expect("tempdir");
        let settings = BenchSettings {
            levels: 2,
            ratio: 4.0,
            coarser: 1,
            repeats: 3,
            methods: vec![BenchMethod::Reduced],
            meshes: 0,
            elements: Vec::new(),
            isolation: Isolation::InProcess,
        };
        let mut lines = 0;
        let records =
            run_bench(&[(case, file)], &settings, dir.path(), |_| lines += 1).expect("bench");
        assert_eq!((records.len(), lines), (2, 2));
        let (coarse, fine) = (&records[0], &records[1]);
        assert!(fine.reference && !coarse.reference);
        assert!((coarse.dt / fine.dt - 4.0).abs() < 1e-12);
        assert!(
            (coarse.dt / 4e-4 - 1.0).abs() < 1e-12,
            "one level coarser than the case"
        );
        assert_eq!(fine.deceleration_error, Some(0.0));
        assert!(coarse.deceleration_error.is_some_and(|e| e > 0.0));
        assert!(coarse.wall_times_s.len() == 3 && coarse.wall_time_s > 0.0);
        for r in &records {
            // the split is of the median run, whose wall time it cannot exceed
            let factorization = r.factorization_s.expect("factorization time");
            let output = r.output_s.expect("output time");
            assert!(
                factorization > 0.0 && factorization <= r.linear_solve_s,
                "{r:?}"
            );
            let parts = r.assembly_s + r.linear_solve_s + r.contact_solve_s + output;
            assert!(output > 0.0 && parts <= r.wall_time_s, "{r:?}");
            assert!(r.factorizations.is_some_and(|f| f >= 1), "{r:?}");
            if cfg!(target_os = "linux") {
                // the bench process's code and data alone take more than a megabyte
                assert!(r.peak_memory_mb.is_some_and(|mb| mb > 1.0), "{r:?}");
            }
        }
        write_bench_report(&records, dir.path()).expect("report");
        let md = std::fs::read_to_string(dir.path().join(BENCH_MD)).expect("bench.md");
        // a row per level in the table, and one for the method in the error-target section
        let rows = |text: &str| {
            text.lines()
                .filter(|l| l.starts_with("| 2d-analytic"))
                .count()
        };
        let (table, target) = md
            .split_once("## The cheapest level within the error target")
            .expect("error-target section");
        assert_eq!((rows(table), rows(target)), (2, 1), "{md}");
        assert!(dir.path().join(crate::plot::WORK_PRECISION_SVG).is_file());
        // no pad-mesh ladder, no plot of one
        assert!(
            !dir.path()
                .join(crate::plot::WORK_PRECISION_MESH_SVG)
                .exists()
        );
        let written: Vec<BenchRecord> = serde_json::from_str(
            &std::fs::read_to_string(dir.path().join(BENCH_JSON)).expect("bench.json"),
        )
        .expect("records");
        assert_eq!(written, records);
        // as many coarser levels as levels leave no level at the case's time step
        let bad = BenchSettings {
            levels: 1,
            ..settings.clone()
        };
        assert!(matches!(
            run_bench(&[], &bad, dir.path(), |_| ()),
            Err(BenchError::Settings(_))
        ));
    }

    /// With an element axis every method's ladder runs with each pad element, and the later
    /// elements are measured against the first's reference: none of theirs is one.
    #[test]
    fn later_elements_are_measured_against_the_first_elements_reference() {
        let (case, file) = short_2d_case();
        let dir = tempfile::tempdir().expect("tempdir");
        let settings = BenchSettings {
            levels: 2,
            ratio: 4.0,
            coarser: 1,
            repeats: 1,
            methods: vec![BenchMethod::Reduced],
            elements: vec![PadFormulation::Reduced, PadFormulation::Hybrid],
            ..BenchSettings::default()
        };
        let records = run_bench(&[(case, file)], &settings, dir.path(), |_| ()).expect("bench");
        let elements: Vec<_> = records.iter().map(|r| r.element.as_deref()).collect();
        assert_eq!(
            elements,
            [Some("CPE4R"), Some("CPE4R"), Some("CPE4H"), Some("CPE4H")]
        );
        let references: Vec<bool> = records.iter().map(|r| r.reference).collect();
        assert_eq!(references, [false, true, false, false]);
        // the hybrid pad's finest level differs from the one-point pad's reference
        let hybrid_finest = &records[3];
        assert!(hybrid_finest.deceleration_error.is_some_and(|e| e > 0.0));
        assert_eq!(hybrid_finest.variant(), "reduced, CPE4H");
        assert!(
            dir.path()
                .join("runs/2d-analytic/hybrid/reduced/1/summary.json")
                .is_file()
        );
        write_bench_report(&records, dir.path()).expect("report");
        let md = std::fs::read_to_string(dir.path().join(BENCH_MD)).expect("bench.md");
        let (_, target) = md
            .split_once("## The cheapest level within the error target")
            .expect("error-target section");
        assert!(target.contains("| 2d-analytic | reduced, CPE4R |"), "{md}");
        assert!(target.contains("| 2d-analytic | reduced, CPE4H |"), "{md}");
    }

    /// The adaptive method runs the case as it is with adaptive increments, and is measured
    /// against the finest level of the case run as written: none of its levels is a reference.
    #[test]
    fn adaptive_levels_are_measured_against_the_case_as_written() {
        let (case, file) = short_2d_case();
        let adaptive = level_case(&case, 2.0, BenchMethod::Adaptive);
        assert_eq!(adaptive.solver.contact_solve, case.solver.contact_solve);
        assert_eq!(adaptive.pad.quasi_static, case.pad.quasi_static);
        let Some(StepSpec::Dynamic {
            dt,
            adaptive: Some(spec),
            ..
        }) = adaptive.steps.last()
        else {
            panic!("an adaptive dynamic step: {:?}", adaptive.steps.last());
        };
        assert!((dt / 2e-4 - 1.0).abs() < 1e-12);
        assert!((spec.tolerance / (4.0 * ADAPTIVE_TOLERANCE) - 1.0).abs() < 1e-12);
        let dir = tempfile::tempdir().expect("tempdir");
        let settings = BenchSettings {
            levels: 2,
            ratio: 4.0,
            coarser: 1,
            repeats: 1,
            methods: vec![BenchMethod::Case, BenchMethod::Adaptive],
            meshes: 0,
            elements: Vec::new(),
            isolation: Isolation::InProcess,
        };
        let records = run_bench(&[(case, file)], &settings, dir.path(), |_| ()).expect("bench");
        let of = |method: BenchMethod| -> Vec<&BenchRecord> {
            records
                .iter()
                .filter(|r| r.method == method.label())
                .collect()
        };
        let (fixed, adaptive) = (of(BenchMethod::Case), of(BenchMethod::Adaptive));
        assert_eq!((fixed.len(), adaptive.len()), (2, 2));
        assert!(fixed[1].reference && !fixed[0].reference);
        assert!(adaptive.iter().all(|r| !r.reference));
        assert!(adaptive.iter().all(|r| r.status == "completed"));
        // measured against the case's finest level, so not zero at its own finest
        assert!(adaptive[1].deceleration_error.is_some_and(|e| e > 0.0));
        assert_ne!(adaptive[1].increments, fixed[1].increments);
    }

    /// One level: each case at its own time step, by the case's own contact solve, with no
    /// reference and no errors; the report sums the cases' median wall times.
    #[test]
    fn one_level_runs_the_cases_as_written_and_totals_their_cost() {
        let overrides = ["steps[1].duration=0.005".to_string()];
        let mut cases = Vec::new();
        for (name, text) in [
            (
                "2d-analytic",
                include_str!("../../../cases/drum/2d-analytic.json"),
            ),
            ("2d-r2d2", include_str!("../../../cases/drum/2d-r2d2.json")),
        ] {
            let file = PathBuf::from(format!("{name}.json"));
            let case = skid_cases::validate::parse_case(text, &file, &overrides).expect("case");
            cases.push((case, file));
        }
        let dir = tempfile::tempdir().expect("tempdir");
        let settings = BenchSettings {
            levels: 1,
            ratio: 2.0,
            coarser: 0,
            repeats: 3,
            methods: vec![BenchMethod::parse("case").expect("method")],
            meshes: 0,
            elements: Vec::new(),
            isolation: Isolation::InProcess,
        };
        let records = run_bench(&cases, &settings, dir.path(), |_| ()).expect("bench");
        assert_eq!(records.len(), 2);
        for (r, (case, _)) in records.iter().zip(&cases) {
            assert_eq!(r.case, case.name);
            assert_eq!(r.dt_factor, Some(1.0));
            assert!((r.dt - 1e-4).abs() < 1e-15, "{}", r.dt);
            assert!(!r.reference && r.deceleration_error.is_none() && r.e_slide.is_none());
            // 5 preload increments and 50 of 0.1 ms
            assert_eq!((r.status.as_str(), r.increments), ("completed", 55));
        }
        write_bench_report(&records, dir.path()).expect("report");
        let md = std::fs::read_to_string(dir.path().join(BENCH_MD)).expect("bench.md");
        let total = md
            .lines()
            .find(|l| l.starts_with("| case | **total of 2 cases** | completed |"))
            .expect("total line");
        let wall: f64 = total
            .split('|')
            .nth(4)
            .expect("wall column")
            .trim()
            .trim_matches('*')
            .parse()
            .expect("number");
        let sum = records[0].wall_time_s + records[1].wall_time_s;
        assert!((wall - sum).abs() < 1e-4, "{total} against {sum}");
        assert!(total.contains("| 110 |"), "{total}");
        // a record written before dt_factor was kept reads, and counts in no total
        let old = r#"[{"case":"a","method":"reduced","dt":1e-4,"status":"completed",
            "wall_time_s":1.0,"wall_times_s":[1.0],"assembly_s":0.0,"linear_solve_s":0.0,
            "contact_solve_s":0.0,"increments":1,"newton_iterations":1,"contact_fallbacks":0,
            "t_stop":null,"deceleration":null,"deceleration_error":null,"e_slide":null,
            "t_stop_difference":null,"reference":true}]"#;
        let old: Vec<BenchRecord> = serde_json::from_str(old).expect("old record");
        assert!(own_time_step(&old).is_empty());
    }

    /// A run in a process of its own that cannot start is an error naming the level's case
    /// file, which the bench wrote for it; no records are written.
    #[test]
    fn a_run_process_that_cannot_start_is_an_error_naming_the_level() {
        let (case, file) = short_2d_case();
        let dir = tempfile::tempdir().expect("tempdir");
        let settings = BenchSettings {
            levels: 1,
            coarser: 0,
            repeats: 1,
            methods: vec![BenchMethod::Reduced],
            elements: Vec::new(),
            isolation: Isolation::Process {
                skid: dir.path().join("no-such-skid"),
                threads: 1,
            },
            ..BenchSettings::default()
        };
        let error =
            run_bench(&[(case, file)], &settings, dir.path(), |_| ()).expect_err("no executable");
        let level = dir.path().join("runs/2d-analytic/reduced/0.json");
        match &error {
            BenchError::Process { case, message } => {
                assert_eq!(case, &level);
                assert!(message.contains("cannot start"), "{message}");
            }
            other => panic!("expected a process error, got {other:?}"),
        }
        assert!(level.is_file());
        assert!(!dir.path().join(BENCH_JSON).exists());
    }

    /// A pad-mesh ladder: the case's pad, then twice its elements in every direction (the
    /// axial one in 3D only), at the case's time step, its first level the time-step ladder's
    /// run at that step; the finer is the reference with zero error, the case's pad has an
    /// error of its own, and neither counts in the total of the cases at their own time step
    /// or in the time steps' rows of the error target. Every method's smaller pad runs before
    /// any finer one, and the records stay in each method's ladder order.
    #[test]
    fn pad_mesh_ladder_refines_the_pad_and_measures_against_its_finest() {
        let (case, file) = short_2d_case();
        let mut three = case.clone();
        three.dimension = 3;
        assert_eq!(mesh_case(&three, 2).pad.elements.axial, 2);
        assert_eq!(
            mesh_case(&case, 2).pad.elements.axial,
            case.pad.elements.axial
        );
        let dir = tempfile::tempdir().expect("tempdir");
        let settings = BenchSettings {
            levels: 1,
            ratio: 2.0,
            coarser: 0,
            repeats: 1,
            methods: vec![BenchMethod::Reduced, BenchMethod::Global],
            meshes: 2,
            elements: Vec::new(),
            isolation: Isolation::InProcess,
        };
        let mut order = Vec::new();
        let records = run_bench(
            &[(case.clone(), file.clone())],
            &settings,
            dir.path(),
            |r| order.push((r.method.clone(), r.equations)),
        )
        .expect("bench");
        let methods = [
            "reduced", "reduced", "global", "global", "reduced", "global",
        ];
        assert_eq!(
            order.iter().map(|(m, _)| m.as_str()).collect::<Vec<_>>(),
            methods,
            "{order:?}"
        );
        assert!(order.windows(2).all(|w| w[0].1 <= w[1].1), "{order:?}");
        assert_eq!(records.len(), 6);
        let elements = &case.pad.elements;
        let mesh = |factor: usize| {
            format!(
                "{} x {}",
                elements.circumferential * factor,
                elements.radial * factor
            )
        };
        for (ladder, method) in records.chunks(3).zip(["reduced", "global"]) {
            let (own, coarse, fine) = (&ladder[0], &ladder[1], &ladder[2]);
            assert!(ladder.iter().all(|r| r.method == method), "{ladder:?}");
            assert_eq!(own.ladder, Ladder::TimeStep);
            assert!([coarse, fine].iter().all(|r| r.ladder == Ladder::PadMesh));
            assert_eq!(coarse.pad_mesh.as_deref(), Some(mesh(1).as_str()));
            assert_eq!(fine.pad_mesh.as_deref(), Some(mesh(2).as_str()));
            assert!(coarse.equations < fine.equations, "{coarse:?} {fine:?}");
            assert!(fine.reference && !coarse.reference && !own.reference);
            // (10 ms of spin-down: the drum does not stop, so there is no e_slide)
            assert_eq!(fine.deceleration_error, Some(0.0));
            assert!(coarse.deceleration_error.is_some_and(|e| e > 0.0));
            assert!(own.deceleration_error.is_none());
            // the case's pad at its own step is one run, shared by both ladders
            assert_eq!(coarse.wall_times_s, own.wall_times_s);
        }
        assert!(records.iter().all(|r| (r.dt - 1e-4).abs() < 1e-15));
        write_bench_report(&records, dir.path()).expect("report");
        let md = std::fs::read_to_string(dir.path().join(BENCH_MD)).expect("bench.md");
        assert!(md.contains("| **total of 1 cases** |"), "{md}");
        assert!(
            dir.path()
                .join(crate::plot::WORK_PRECISION_MESH_SVG)
                .is_file()
        );
        let target = md
            .split_once("## The cheapest level within the error target")
            .expect("error-target section")
            .1;
        let rows: Vec<&str> = target
            .lines()
            .filter(|l| l.starts_with("| 2d-analytic |"))
            .collect();
        assert_eq!(rows.len(), 2, "{md}");
        assert!(
            rows[0].starts_with("| 2d-analytic | reduced, pad mesh |"),
            "{md}"
        );
        assert!(
            rows[1].starts_with("| 2d-analytic | global, pad mesh |"),
            "{md}"
        );
        // more levels than the bench allows
        let many = BenchSettings {
            meshes: MAX_MESH_LEVELS + 1,
            ..settings
        };
        assert!(matches!(
            run_bench(&[(case, file)], &many, dir.path(), |_| ()),
            Err(BenchError::Settings(_))
        ));
    }
}
