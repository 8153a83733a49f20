//! `skid bench`: the cost of each case beside its error over a ladder of time steps and the
//! contact solves (see `skid_report::bench`).
//!
//! Every run is a `skid run` in a process of its own (see `skid_report::bench::Isolation`).
//!
//! Exit codes: 0 every run completed; 1 some run stopped early; 2 a case file or the settings
//! are invalid; 3 results could not be written or read back, or a run's process failed.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use skid_cases::load_case;
use skid_report::bench::{BenchError, BenchSettings, run_bench, write_bench_report};

/// Runs the bench of `cases` into `out` with `settings`; a line per level on stderr when it is
/// a terminal.
pub fn run(cases: &[PathBuf], settings: &BenchSettings, out: &Path) -> ExitCode {
    let mut loaded = Vec::new();
    for path in cases {
        match load_case(path, &[]) {
            Ok(case) => loaded.push((case, path.clone())),
            Err(e) => {
                eprintln!("skid: {e}");
                return ExitCode::from(2);
            }
        }
    }
    let terminal = std::io::stderr().is_terminal();
    let total = loaded.len()
        * (settings.levels + settings.meshes)
        * settings.methods.len()
        * settings.elements.len().max(1);
    let mut done = 0;
    let progress = |r: &skid_report::bench::BenchRecord| {
        done += 1;
        if terminal {
            eprintln!(
                "[{done}/{total}] {} {} dt {:.3e}, pad {}: {} in {:.3} s ({} runs)",
                r.case,
                r.variant(),
                r.dt,
                r.pad_mesh.as_deref().unwrap_or("?"),
                r.status,
                r.wall_time_s,
                r.wall_times_s.len()
            );
        }
    };
    let records = match run_bench(&loaded, settings, out, progress)
        .and_then(|records| write_bench_report(&records, out).map(|()| records))
    {
        Ok(records) => records,
        Err(e) => {
            eprintln!("skid: {e}");
            return ExitCode::from(match e {
                BenchError::Settings(_) | BenchError::Case(_) => 2,
                BenchError::Report(_) | BenchError::Write { .. } | BenchError::Process { .. } => 3,
            });
        }
    };
    println!(
        "{} levels benchmarked; see {}",
        records.len(),
        out.join(skid_report::bench::BENCH_MD).display()
    );
    if records.iter().all(|r| r.status == "completed") {
        ExitCode::SUCCESS
    } else {
        eprintln!("skid: some runs stopped early (status \"failed\" in bench.json)");
        ExitCode::from(1)
    }
}
