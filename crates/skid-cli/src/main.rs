//! `skid`: run braking-drum cases from the command line.
//!
//! One module per command, each documenting its exit codes: [`run`], [`batch`], [`report`],
//! [`bench`], [`convert`], [`check`], [`schema`].

mod batch;
mod bench;
mod check;
mod convert;
mod report;
mod run;
mod schema;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use skid_cases::reference::Format;
use skid_cases::schema::PadFormulation;
use skid_report::ReportSources;
use skid_report::bench::{BenchMethod, BenchSettings, Isolation};

#[derive(Parser)]
#[command(
    name = "skid",
    version,
    about = "Implicit FE solver for frictional contact with rigid bodies"
)]
struct Cli {
    /// Threads of each sparse factorization and solve: 1 sequential (the default; the
    /// systems are small, so threads inside one factorization cost more than they save), 0 one
    /// per core, N that many. Results at 1 thread are bit-identical from run to run; with more,
    /// the factorizations sum in another order and results agree to round-off only. `skid
    /// batch --jobs` sets how many cases run at once.
    #[arg(long, global = true, default_value_t = 1, value_name = "N")]
    threads: usize,
    #[command(subcommand)]
    command: Command,
}

/// The parallelism of faer's factorizations for `--threads threads`: [`faer::Par::Seq`] for 1,
/// [`faer::Par::Rayon`] with one thread per core for 0, with `threads` threads otherwise (the
/// work runs on rayon's pool: the global one, or the batch's pool within `skid batch`).
fn factorization_parallelism(threads: usize) -> faer::Par {
    match threads {
        1 => faer::Par::Seq,
        0 => faer::Par::rayon(std::thread::available_parallelism().map_or(1, |n| n.get())),
        n => faer::Par::rayon(n),
    }
}

#[derive(Subcommand)]
enum Command {
    /// Run one case file, model file or input deck (.inp); writes history.csv and
    /// summary.json, and prints the summary as one line of JSON.
    Run {
        /// The case file or model file (JSON), or the input deck (.inp); with --resume,
        /// optional (if given, it must be the input the run was started with).
        #[arg(required_unless_present = "resume")]
        case: Option<PathBuf>,
        /// Output directory [default: out/<case name>].
        #[arg(long, conflicts_with = "resume")]
        out: Option<PathBuf>,
        /// Override a field of the case, e.g. `--set steps[1].dt=1e-4` (repeatable).
        #[arg(long = "set", value_name = "FIELD=VALUE")]
        overrides: Vec<String>,
        /// Continue the interrupted run in DIR from its restart file (restart.json) with the
        /// input stored there; the outputs are those of the uninterrupted run.
        #[arg(long, value_name = "DIR")]
        resume: Option<PathBuf>,
        /// Write the restart file every N converged increments, and at the start and the end
        /// of each step (0: no restart file) [default: 100; with --resume, the run's own].
        /// Each restart file ends the reuse of the global contact solve's preconditioner, so
        /// on large models N changes results at the level of the solver's tolerances.
        #[arg(long, value_name = "N")]
        restart_every: Option<usize>,
    },
    /// Write a case file, model file or deck as a model file (.json) or a deck (.inp), by the
    /// output's extension: the same run in another form.
    Convert {
        /// The case file or model file (JSON), or the input deck (.inp).
        case: PathBuf,
        /// The model file (.json) or deck (.inp) to write.
        #[arg(long, short)]
        out: PathBuf,
        /// Override a field of the input (repeatable; a deck's fields are its model file's).
        #[arg(long = "set", value_name = "FIELD=VALUE")]
        overrides: Vec<String>,
    },
    /// Run case files, model files, decks and sweep files in parallel, each run into
    /// <out>/<name>/; writes <out>/batch.json. A sweep file runs one run per combination of its
    /// parameters, each with its parameters.json.
    Batch {
        /// Files, or directories whose *.json and *.inp files are run (sorted by name).
        #[arg(required = true)]
        paths: Vec<PathBuf>,
        /// Output directory.
        #[arg(long, default_value = "out")]
        out: PathBuf,
        /// Cases run at once [default: one per core].
        #[arg(long)]
        jobs: Option<usize>,
        /// Run shard I of N only (I from 1): the runs whose position in the batch, counted
        /// from 0, is I-1 modulo N. `slurm` takes I and N from the Slurm job array task
        /// (SLURM_ARRAY_TASK_ID and the array's bounds). Give each shard its own --out and
        /// merge them with `skid report --sweep`.
        #[arg(long, value_name = "I/N|slurm")]
        shard: Option<String>,
    },
    /// The validation report (markdown with SVG plots): the benchmark runs against a reference
    /// run, the hard-case checks, the convergence study, the cost against problem size, the
    /// verification scenes against their analytic answers, the stress sweep, the pad
    /// formulations' failure loads; each section from its own directory or file. With none of
    /// --runs, --hard, --convergence, --scaling, --verification, --stress, --pressure-limit,
    /// --sweep: the benchmark section of `out`.
    /// With --sweep: the sweep report instead, merged from batch directories.
    Report {
        /// Benchmark runs: one subdirectory per run (summary.json, history.csv).
        #[arg(long)]
        runs: Option<PathBuf>,
        /// Reference run among --runs [default: 3d-analytic-fine, else the first 3d-analytic*].
        #[arg(long)]
        reference: Option<String>,
        /// Hard-case runs (`skid batch cases/hard`): one subdirectory per run with its
        /// case.json.
        #[arg(long)]
        hard: Option<PathBuf>,
        /// Convergence study (`scripts/convergence.sh`): one subdirectory per series, holding
        /// one run per level.
        #[arg(long)]
        convergence: Option<PathBuf>,
        /// Cost against problem size: the scaling.json of `scripts/scaling.py`.
        #[arg(long)]
        scaling: Option<PathBuf>,
        /// The stress sweep of the solver: the stress.json of `scripts/stress.py`.
        #[arg(long, value_name = "FILE")]
        stress: Option<PathBuf>,
        /// The load at which each pad formulation fails: the pressure-limit.json of
        /// `scripts/pressure_limit.py`.
        #[arg(long, value_name = "FILE")]
        pressure_limit: Option<PathBuf>,
        /// Verification scenes (`skid batch cases/verification`): one subdirectory per
        /// run, each checked against the analytic answer of its model (Hertz contact, Coulomb
        /// friction).
        #[arg(long, value_name = "DIR")]
        verification: Option<PathBuf>,
        /// Sweep report: the sweep runs listed by the batch.json of each directory (one
        /// `skid batch` of sweep files, or its shards), one table per sweep in run order.
        #[arg(long, num_args = 1.., value_name = "DIR",
              conflicts_with_all = ["runs", "reference", "hard", "convergence", "scaling", "stress",
                                    "pressure_limit", "verification"])]
        sweep: Vec<PathBuf>,
        /// The markdown report; the plots are written beside it [default: validation/report.md,
        /// with --sweep out/sweep.md].
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Cost against error: each case at a ladder of time steps (coarser than the case, the
    /// case, then finer) and, with --meshes, of pad meshes, with each contact solve, errors
    /// against the finest level of each ladder, every run a `skid run` in a process of its own;
    /// writes <out>/bench.json, <out>/bench.md and <out>/work-precision.svg (with --meshes also
    /// <out>/work-precision-mesh.svg).
    Bench {
        /// Case files (JSON).
        #[arg(required = true)]
        cases: Vec<PathBuf>,
        /// Output directory (the runs go to <out>/runs/).
        #[arg(long, default_value = "out/bench")]
        out: PathBuf,
        /// Time-step levels per case and method (1: each case at its own time step only,
        /// with the cases' total cost and no errors).
        #[arg(long, default_value_t = 5)]
        levels: usize,
        /// Ratio of successive time steps.
        #[arg(long, default_value_t = 2.0)]
        ratio: f64,
        /// Levels coarser than the case's own time step.
        #[arg(long, default_value_t = 2)]
        coarser: usize,
        /// Timed repetitions of runs shorter than 2 s (after one warm-up).
        #[arg(long, default_value_t = 5)]
        repeats: usize,
        /// Methods to compare (comma-separated): case (the case's own contact solve setting),
        /// reduced, global (the contact solves), adaptive (the case with adaptive increments,
        /// tolerance 1e-6 scaled by the square of the level's factor), quasi-static (the pad
        /// without inertia, global solve), quasi-static-adaptive (the same with adaptive
        /// increments). An adaptive method is measured against the finest level of its fixed
        /// one (case, quasi-static) where that is listed before it.
        #[arg(long, value_delimiter = ',', default_value = "reduced,global")]
        methods: Vec<String>,
        /// Pad-mesh levels per case and method, at the case's own time step (0: none, at most
        /// 4): the case's pad, then each level with twice the last's elements in every
        /// direction; errors against the finest.
        #[arg(long, default_value_t = 0)]
        meshes: usize,
        /// Pad elements to compare (comma-separated `pad.formulation` names: reduced, full,
        /// hybrid, incompatible; absent: the cases' own): every ladder runs with each, measured
        /// against the first element's references.
        #[arg(long, value_delimiter = ',')]
        elements: Vec<String>,
    },
    /// Check case files, model files, decks and sweep files without running them: each (each
    /// run of a sweep) is read, validated and built into its model (mesh, bodies, contact
    /// candidates); prints `FILE: ok (...)` or the message `skid run` would give.
    Check {
        /// The case files, model files, sweep files (JSON) or decks (.inp).
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// Override a field of every file (repeatable), as in `skid run`.
        #[arg(long = "set", value_name = "FIELD=VALUE")]
        overrides: Vec<String>,
    },
    /// Print the JSON Schema of case files or model files, generated from the types that read
    /// them, or with --markdown their reference (one table per type).
    Schema {
        /// Which format: `case`, `model` or `sweep`.
        #[arg(default_value = "case", value_parser = Format::parse)]
        format: Format,
        /// The markdown reference instead of the JSON Schema.
        #[arg(long)]
        markdown: bool,
        /// Write to this file instead of standard output.
        #[arg(long, short)]
        out: Option<PathBuf>,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    // The library reads faer's parallelism wherever it factorizes; it is set once, here, from
    // the command line, before any run starts.
    faer::set_global_parallelism(factorization_parallelism(cli.threads));
    match cli.command {
        Command::Batch {
            paths,
            out,
            jobs,
            shard,
        } => batch::run(&paths, &out, jobs.unwrap_or(0), shard.as_deref()),
        Command::Report {
            runs,
            reference,
            hard,
            convergence,
            scaling,
            stress,
            pressure_limit,
            verification,
            sweep,
            out,
        } => {
            if !sweep.is_empty() {
                let out = out.unwrap_or_else(|| PathBuf::from("out/sweep.md"));
                return report::run_sweep(&sweep, &out);
            }
            let out = out.unwrap_or_else(|| PathBuf::from("validation/report.md"));
            let given = [
                &hard,
                &convergence,
                &scaling,
                &stress,
                &pressure_limit,
                &verification,
            ];
            let runs = match (&runs, given.iter().all(|g| g.is_none())) {
                (None, true) => Some(PathBuf::from("out")),
                _ => runs,
            };
            let sources = ReportSources {
                runs: runs.as_deref(),
                reference: reference.as_deref(),
                hard: hard.as_deref(),
                convergence: convergence.as_deref(),
                scaling: scaling.as_deref(),
                stress: stress.as_deref(),
                pressure_limit: pressure_limit.as_deref(),
                verification: verification.as_deref(),
            };
            report::run(&sources, &out)
        }
        Command::Run {
            case,
            overrides,
            resume: Some(dir),
            restart_every,
            ..
        } => {
            if case.is_none() && !overrides.is_empty() {
                eprintln!("skid: --set needs the input it applies to");
                return ExitCode::from(2);
            }
            run::resume(&dir, case.as_deref(), &overrides, restart_every)
        }
        Command::Run {
            case: Some(case),
            out,
            overrides,
            resume: None,
            restart_every,
        } => run::run(&case, &overrides, out.as_deref(), restart_every),
        Command::Run { case: None, .. } => {
            eprintln!("skid run: the input file is missing");
            ExitCode::from(2)
        }
        Command::Convert {
            case,
            out,
            overrides,
        } => convert::run(&case, &overrides, &out),
        Command::Check { files, overrides } => check::run(&files, &overrides),
        Command::Schema {
            format,
            markdown,
            out,
        } => schema::run(format, markdown, out.as_deref()),
        Command::Bench {
            cases,
            out,
            levels,
            ratio,
            coarser,
            repeats,
            methods,
            meshes,
            elements,
        } => {
            let mut solves = Vec::new();
            for method in &methods {
                match BenchMethod::parse(method) {
                    Ok(method) => solves.push(method),
                    Err(message) => {
                        eprintln!("skid: --methods: {message}");
                        return ExitCode::from(2);
                    }
                }
            }
            let mut pads = Vec::new();
            for element in &elements {
                match PadFormulation::parse(element) {
                    Ok(element) => pads.push(element),
                    Err(message) => {
                        eprintln!("skid: --elements: {message}");
                        return ExitCode::from(2);
                    }
                }
            }
            // every run in a process of its own (see `Isolation::Process`)
            let skid = match std::env::current_exe() {
                Ok(skid) => skid,
                Err(e) => {
                    eprintln!("skid: cannot find the skid executable for the bench's runs: {e}");
                    return ExitCode::from(3);
                }
            };
            let settings = BenchSettings {
                levels,
                ratio,
                coarser,
                repeats,
                methods: solves,
                meshes,
                elements: pads,
                isolation: Isolation::Process {
                    skid,
                    threads: cli.threads,
                },
            };
            bench::run(&cases, &settings, &out)
        }
    }
}
