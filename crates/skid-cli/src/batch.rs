//! `skid batch`: runs case files, model files and decks in parallel with a progress bar and lists the outcomes.
//!
//! Exit codes: 0 every case completed; 1 some case could not be run or stopped early; 2 no case
//! files were found, or `--shard` is invalid; 3 `batch.json` could not be written.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use skid_cases::{
    BatchEntry, BatchError, BatchStatus, RunSummary, Shard, collect_case_files, run_batch,
};

/// The progress bar on stderr, its length set as the runs end; indicatif hides it when stderr
/// is not a terminal.
fn progress_bar() -> ProgressBar {
    let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
    if let Ok(style) =
        ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {pos}/{len} cases {msg}")
    {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.enable_steady_tick(Duration::from_millis(250));
    bar
}

/// One line of the final listing.
fn line(entry: &BatchEntry, width: usize) -> String {
    let t_stop = match &entry.summary {
        Some(RunSummary::Case(s)) => s.t_stop,
        _ => None,
    }
    .map_or_else(|| "-".to_string(), |t| format!("{t:.6}"));
    format!(
        "{:<width$}  {:<18}  t_stop {:>8} s  wall {:>8.2} s",
        entry.name,
        entry.status.as_str(),
        t_stop,
        entry.wall_time_s,
    )
}

/// The shard `--shard` names: `I/N`, or `slurm` for the Slurm array task's; all runs without it.
fn shard(option: Option<&str>) -> Result<Shard, String> {
    match option {
        None => Ok(Shard::ALL),
        Some("slurm") => Shard::from_slurm(|name| std::env::var(name).ok()),
        Some(text) => Shard::parse(text).map_err(|e| format!("--shard: {e}")),
    }
}

/// Runs `paths` (the runs of shard `shard_option`, all without it) into `out` on `jobs`
/// threads (0: one per core).
pub fn run(paths: &[PathBuf], out: &Path, jobs: usize, shard_option: Option<&str>) -> ExitCode {
    let shard = match shard(shard_option) {
        Ok(shard) => shard,
        Err(e) => {
            eprintln!("skid: {e}");
            return ExitCode::from(2);
        }
    };
    let files = match collect_case_files(paths) {
        Ok(files) => files,
        Err(e) => {
            eprintln!("skid: {e}");
            return ExitCode::from(2);
        }
    };
    let bar = progress_bar();
    let entries = run_batch(&files, out, jobs, shard, |entry, total| {
        bar.set_length(total as u64);
        if let Some(error) = &entry.error {
            bar.suspend(|| {
                eprintln!(
                    "skid: {} ({}): {}: {error}",
                    entry.name,
                    entry.case_file.display(),
                    entry.status.as_str()
                );
            });
        }
        bar.set_message(format!("{} {}", entry.name, entry.status.as_str()));
        bar.inc(1);
    });
    bar.finish_and_clear();
    let entries = match entries {
        Ok(entries) => entries,
        Err(e) => {
            eprintln!("skid: {e}");
            return ExitCode::from(match e {
                BatchError::Output { .. } => 3,
                _ => 2,
            });
        }
    };
    let width = entries.iter().map(|e| e.name.len()).max().unwrap_or(0);
    for entry in &entries {
        println!("{}", line(entry, width));
    }
    let count = |status| entries.iter().filter(|e| e.status == status).count();
    let expected_failures = count(BatchStatus::FailedAsExpected);
    let as_expected = entries.iter().filter(|e| e.status.as_expected()).count();
    let expected = if expected_failures > 0 {
        format!(", {expected_failures} stopped with the failure their case expects")
    } else {
        String::new()
    };
    let of_shard = if shard == Shard::ALL {
        String::new()
    } else {
        format!(" (shard {shard})")
    };
    println!(
        "{} of {} cases{of_shard} completed{expected}; see {}",
        count(BatchStatus::Completed),
        entries.len(),
        out.join("batch.json").display()
    );
    if as_expected == entries.len() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    }
}
