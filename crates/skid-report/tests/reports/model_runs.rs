//! Model runs of the drum scene in the benchmark: the deck of `2d-analytic` and its case file,
//! run alike, read to the same spin-down (the deck's histories are the case file's, bit for
//! bit, and its deceleration is measured on them to 1e-9 of the case summary's), so that the benchmark section compares deck and model-file runs with case runs; a
//! model run in which no body turns is refused, naming its history.

use std::path::{Path, PathBuf};

use skid_cases::restart::DEFAULT_RESTART_EVERY;
use skid_cases::run_file;
use skid_report::load_run;

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(path)
}

/// Runs `input` (repository path) for the first 30 ms of its spin-down into `dir`.
fn run_into(input: &str, dir: &Path) {
    run_file(
        &repo(input),
        &["steps[1].duration=0.03".to_string()],
        Some(dir),
        DEFAULT_RESTART_EVERY,
    )
    .expect("runs");
}

#[test]
fn a_deck_of_the_drum_reads_to_its_case_files_spin_down() {
    let (case, deck) = (
        tempfile::tempdir().expect("tempdir"),
        tempfile::tempdir().expect("tempdir"),
    );
    run_into("cases/drum/2d-analytic.json", case.path());
    run_into("cases/inp/2d-analytic.inp", deck.path());
    let (case, deck) = (
        load_run(case.path()).expect("case run"),
        load_run(deck.path()).expect("deck run"),
    );
    assert!(deck.case.is_none() && case.case.is_some());
    assert_eq!(deck.summary.status, "completed");
    // the same spin-down (the drum case's history also has the contact resultants)
    assert_eq!(deck.history.time, case.history.time);
    assert_eq!(deck.history.omega, case.history.omega);
    assert_eq!(deck.history.non_finite, case.history.non_finite);
    assert_eq!(deck.summary.omega0, 60.0);
    // 30 ms of a 0.1 s spin-down: no stop, the deceleration over the whole of it
    assert_eq!(deck.summary.t_stop, None);
    // measured on the history's printed digits (10 significant), the case summary's on the
    // states themselves
    let (d, c) = (
        deck.summary.deceleration.expect("deceleration"),
        case.summary.deceleration.expect("deceleration"),
    );
    assert!(
        (d - c).abs() < 1e-9 * c && d > 550.0 && d < 650.0,
        "{d} against {c}"
    );
    assert_eq!(
        (deck.summary.increments, deck.summary.newton_iterations),
        (case.summary.increments, case.summary.newton_iterations)
    );
    assert_eq!(deck.summary.deceleration_analytic, None);
}

#[test]
fn a_model_run_in_which_no_body_turns_is_refused() {
    let dir = tempfile::tempdir().expect("tempdir");
    run_file(
        &repo("cases/verification/2d-block-dragged-on-flat.json"),
        &[],
        Some(dir.path()),
        DEFAULT_RESTART_EVERY,
    )
    .expect("runs");
    let message = load_run(dir.path()).expect_err("no drum").to_string();
    assert!(
        message.contains("history.csv") && message.contains("no body turns"),
        "{message}"
    );
}
