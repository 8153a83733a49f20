//! `skid`: run braking-drum cases from the command line.
//!
//! Exit codes: 0 the run completed; 1 the run stopped early (its summary says where and why);
//! 2 the case file or the command line is invalid; 3 results could not be written.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use skid_cases::{CaseError, run_case_file};

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
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    // The systems are small: threads inside one factorization cost more than they save.
    faer::set_global_parallelism(faer::Par::Seq);
    match cli.command {
        Command::Run {
            case,
            out,
            overrides,
        } => match run_case_file(&case, &overrides, out.as_deref()) {
            Ok(summary) => {
                match serde_json::to_string(&summary) {
                    Ok(line) => println!("{line}"),
                    Err(e) => eprintln!("skid: cannot print the summary: {e}"),
                }
                if let Some(error) = &summary.error {
                    eprintln!("skid: {}: run stopped early: {error}", case.display());
                    ExitCode::from(1)
                } else {
                    ExitCode::SUCCESS
                }
            }
            Err(e) => {
                eprintln!("skid: {e}");
                ExitCode::from(match e {
                    CaseError::Output { .. } => 3,
                    _ => 2,
                })
            }
        },
    }
}
