//! The Hertz verification scene (`cases/verification/2d-hertz-n4.json`, the coarsest level:
//! a rigid cylinder pressed frictionlessly on an elastic block in plane strain) against
//! Hertz's answer, and the verification section of the report on its run directory and on
//! that of a block sliding on a flat: it passes them, and flags them once their outputs are
//! made wrong.

use std::path::{Path, PathBuf};

use skid_cases::restart::DEFAULT_RESTART_EVERY;
use skid_cases::{RunSummary, run_file};
use skid_report::hertz::{self, HertzScene};
use skid_report::verification;

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(path)
}

/// Runs the shipped verification scene `name` into `dir/name`.
fn run_scene(name: &str, dir: &Path) -> PathBuf {
    let out = dir.join(name);
    let path = repo(&format!("cases/verification/{name}.json"));
    let RunSummary::Model(summary) =
        run_file(&path, &[], Some(&out), DEFAULT_RESTART_EVERY).expect("runs")
    else {
        panic!("a model file gives a model summary");
    };
    assert_eq!(summary.error, None);
    out
}

/// The report's verification section of the runs in `dir`: its text and failed checks.
fn report(dir: &Path) -> (String, usize) {
    let runs = verification::load(dir).expect("runs load");
    let (text, counts, _) = verification::section(dir, &runs, dir).expect("section");
    (text, counts.failed)
}

/// Multiplies the numbers of column `column` in the CSV file `path` by `factor`.
fn scale_column(path: &Path, column: &str, factor: f64) {
    let text = std::fs::read_to_string(path).expect("read");
    let mut lines = text.lines();
    let header = lines.next().expect("header");
    let k = header
        .split(',')
        .position(|c| c == column)
        .unwrap_or_else(|| panic!("no column {column}"));
    let mut out = vec![header.to_string()];
    for line in lines {
        let mut fields: Vec<String> = line.split(',').map(String::from).collect();
        let v: f64 = fields[k].parse().expect("number");
        fields[k] = format!("{:.9e}", v * factor);
        out.push(fields.join(","));
    }
    std::fs::write(path, out.join("\n") + "\n").expect("write");
}

/// The coarsest level (elements of a / 4.5 at the contact): its peak pressure p_FE(0) lies
/// within 1.5 % of Hertz's p0 (measured +0.60 %), its outermost nodes in contact within one
/// element of Hertz's half-width a (measured half an element inside: the computed edge lies in
/// the element that holds x = a), and the normal forces balance the load to 0.1 % (measured
/// 0.03 %: they act along the cylinder's normals, tilted by up to a / R = 0.05). The report
/// passes the run, and fails it once its normal forces are 5 % too large.
#[test]
fn the_coarse_hertz_level_matches_hertz_and_the_report_flags_wrong_pressures() {
    let dir = tempfile::tempdir().expect("tempdir");
    let run = run_scene("2d-hertz-n4", dir.path());
    let text = std::fs::read_to_string(run.join("model.json")).expect("model.json");
    let spec = serde_json::from_str(&text).expect("model");
    let scene = HertzScene::recognise(&spec).expect("a Hertz scene");
    let csv = run.join("contact_nodes.csv");
    let nodes = hertz::read_candidates(
        &std::fs::read_to_string(&csv).expect("contact_nodes.csv"),
        &csv,
        &scene.pair,
    )
    .expect("candidates");
    let m = hertz::measure(&nodes, scene.thickness).expect("measurable");
    let (a, p0) = (scene.half_width(), scene.peak_pressure());
    let peak = m.peak_pressure / p0 - 1.0;
    assert!(peak.abs() < 0.015, "p_FE(0) / p0 - 1 = {peak}");
    assert!(
        (m.half_width - a).abs() <= m.edge_element,
        "a_FE = {} m, a = {a} m, h_edge = {} m",
        m.half_width,
        m.edge_element
    );
    assert!(m.half_width <= a && a <= m.half_width + m.edge_element);
    let balance = m.resultant / scene.load - 1.0;
    assert!(balance.abs() < 1e-3, "resultant / P - 1 = {balance}");

    let (text, failed) = report(dir.path());
    assert_eq!(failed, 0, "{text}");
    assert!(text.contains("- **PASS** 2d-hertz-n4 (finest): peak pressure within 3 %"));
    assert!(text.contains("SKIPPED Hertz: convergence with refinement"));
    scale_column(&csv, "normal_force", 1.05);
    let (text, failed) = report(dir.path());
    assert_eq!(failed, 1, "{text}");
    assert!(
        text.contains("- **FAIL** 2d-hertz-n4 (finest): peak pressure within 3 %"),
        "{text}"
    );
}

/// The block pushed on a flat at 1.5 mu N ends sliding with a friction resultant of exactly
/// mu N: the report passes it, and flags a history whose friction is 1 % too large.
#[test]
fn the_report_flags_friction_beyond_coulomb() {
    let dir = tempfile::tempdir().expect("tempdir");
    let run = run_scene("2d-block-pushed-on-flat", dir.path());
    let (text, failed) = report(dir.path());
    assert_eq!(failed, 0, "{text}");
    scale_column(
        &run.join("history.csv"),
        "block-ground.tangential_force_1",
        1.01,
    );
    let (text, failed) = report(dir.path());
    assert_eq!(failed, 2, "{text}");
    assert!(text.contains("- **FAIL** 2d-block-pushed-on-flat (block-ground): |T| <= mu N"));
}
