//! `skid`: run braking-drum cases from the command line.
//!
//! One module per command, each documenting its exit codes: [`run`], [`batch`], [`report`].

mod batch;
mod report;
mod run;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use skid_cases::ReportSources;

#[derive(Parser)]
#[command(
    name = "skid",
    version,
    about = "Implicit FE solver for frictional contact with rigid bodies"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run one case file; writes history.csv and summary.json, and prints the summary as one
    /// line of JSON.
    Run {
        /// The case file (JSON).
        case: PathBuf,
        /// Output directory [default: out/<case name>].
        #[arg(long)]
        out: Option<PathBuf>,
        /// Override a field of the case, e.g. `--set steps[1].dt=1e-4` (repeatable).
        #[arg(long = "set", value_name = "FIELD=VALUE")]
        overrides: Vec<String>,
    },
    /// Run case files in parallel, each into <out>/<case name>/; writes <out>/batch.json.
    Batch {
        /// Case files, or directories whose *.json files are run (sorted by name).
        #[arg(required = true)]
        paths: Vec<PathBuf>,
        /// Output directory.
        #[arg(long, default_value = "out")]
        out: PathBuf,
        /// Cases run at once [default: one per core].
        #[arg(long)]
        jobs: Option<usize>,
    },
    /// The validation report (markdown with SVG plots): the benchmark runs against a reference
    /// run, the hard-case checks, the convergence study; each section from its own directory.
    /// With none of --runs, --hard, --convergence: the benchmark section of `out`.
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
        /// The markdown report; the plots are written beside it.
        #[arg(long, default_value = "validation/report.md")]
        out: PathBuf,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    // The systems are small: threads inside one factorization cost more than they save.
    faer::set_global_parallelism(faer::Par::Seq);
    match cli.command {
        Command::Batch { paths, out, jobs } => batch::run(&paths, &out, jobs.unwrap_or(0)),
        Command::Report {
            runs,
            reference,
            hard,
            convergence,
            out,
        } => {
            let runs = match (&runs, &hard, &convergence) {
                (None, None, None) => Some(PathBuf::from("out")),
                _ => runs,
            };
            let sources = ReportSources {
                runs: runs.as_deref(),
                reference: reference.as_deref(),
                hard: hard.as_deref(),
                convergence: convergence.as_deref(),
            };
            report::run(&sources, &out)
        }
        Command::Run {
            case,
            out,
            overrides,
        } => run::run(&case, &overrides, out.as_deref()),
    }
}
