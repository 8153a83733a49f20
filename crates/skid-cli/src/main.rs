//! `skid`: run braking-drum cases from the command line.
//!
//! One module per command, each documenting its exit codes: [`run`], [`batch`], [`report`].

mod batch;
mod report;
mod run;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

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
    /// Compare the runs of a batch with a reference run: a markdown report and two SVG plots.
    Report {
        /// Directory holding one subdirectory per run (summary.json, history.csv).
        #[arg(long, default_value = "out")]
        runs: PathBuf,
        /// Reference run [default: 3d-analytic-fine, else the first 3d-analytic* run].
        #[arg(long)]
        reference: Option<String>,
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
            out,
        } => report::run(&runs, reference.as_deref(), &out),
        Command::Run {
            case,
            out,
            overrides,
        } => run::run(&case, &overrides, out.as_deref()),
    }
}
