//! The verification section of the report on runs of the verification scenes: the Hertz scene
//! (`cases/verification/2d-hertz-n4.json`, the coarsest level: a rigid cylinder pressed
//! frictionlessly on an elastic block in plane strain) against Hertz's answer, a block sliding
//! on a flat, a block dragged over a flat by a prescribed motion, and a block that sticks just below the Coulomb threshold beside one that slides
//! just above it: the section passes them, and flags them once their outputs are made wrong.

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
    run_scene_as(name, &[], name, dir)
}

/// Runs the shipped verification scene `name` with the overrides `sets` into `dir/run`.
fn run_scene_as(name: &str, sets: &[&str], run: &str, dir: &Path) -> PathBuf {
    let out = dir.join(run);
    let path = repo(&format!("cases/verification/{name}.json"));
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    let RunSummary::Model(summary) =
        run_file(&path, &sets, Some(&out), DEFAULT_RESTART_EVERY).expect("runs")
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

/// Sets column `column` of the last row of the CSV file `path` to `value`.
fn set_last(path: &Path, column: &str, value: &str) {
    let text = std::fs::read_to_string(path).expect("read");
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let k = lines[0]
        .split(',')
        .position(|c| c == column)
        .unwrap_or_else(|| panic!("no column {column}"));
    let last = lines.last_mut().expect("rows");
    let mut fields: Vec<&str> = last.split(',').collect();
    fields[k] = value;
    *last = fields.join(",");
    std::fs::write(path, lines.join("\n") + "\n").expect("write");
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

/// The block dragged over a flat by its plate: the plate's reaction along the flat balances
/// the friction in every increment and is mu N while every contact slides (measured 2.4e-7 and
/// 2.4e-8 of mu N); the report passes it, and flags a reaction 1e-4 too large on both counts.
#[test]
fn the_report_checks_that_the_reactions_of_a_dragged_block_balance_its_friction() {
    let dir = tempfile::tempdir().expect("tempdir");
    let run = run_scene("2d-block-dragged-on-flat", dir.path());
    let (text, failed) = report(dir.path());
    assert_eq!(failed, 0, "{text}");
    let balance = "- **PASS** 2d-block-dragged-on-flat (block-ground): the reactions along the \
                   flat balance the friction in every increment";
    assert!(text.contains(balance), "{text}");
    scale_column(&run.join("history.csv"), "plate.reaction_x", 1.0001);
    let (text, failed) = report(dir.path());
    assert_eq!(failed, 2, "{text}");
    for what in [
        "balance the friction in every increment",
        "are mu N while every contact slides",
    ] {
        let fail = format!(
            "- **FAIL** 2d-block-dragged-on-flat (block-ground): the reactions along the flat {what}"
        );
        assert!(text.contains(&fail), "{text}");
    }
}

/// The block pushed on a flat at 0.995 mu N sticks once its loads are held, with resultants
/// that balance them, and at 1.005 mu N it slides: the report passes both and the threshold
/// they bracket, flags a history in which a contact of the sticking block slides at its end
/// (and so the bracket), and one whose last friction resultant no longer balances the push.
#[test]
fn the_report_checks_stick_below_the_threshold_and_slip_above_it() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scene = "2d-block-pushed-on-flat";
    let stick = run_scene_as(scene, &["loads[1].force=[5.97, 0.0]"], "below", dir.path());
    run_scene_as(scene, &["loads[1].force=[6.03, 0.0]"], "above", dir.path());
    let (text, failed) = report(dir.path());
    assert_eq!(failed, 0, "{text}");
    for passed in [
        "- **PASS** below (block-ground): held loads at r = T / (mu N) = 0.9950: no contact slides",
        "- **PASS** below (block-ground): the friction and normal resultants balance the held loads",
        "- **PASS** above (block-ground): held loads at r = T / (mu N) = 1.005: every closed contact slides",
        "- **PASS** below and above: the stick/slip threshold lies at r = 1",
    ] {
        assert!(text.contains(passed), "{passed} in {text}");
    }

    let history = stick.join("history.csv");
    let original = std::fs::read_to_string(&history).expect("history");
    set_last(&history, "block-ground.sliding", "1");
    let (text, failed) = report(dir.path());
    assert_eq!(failed, 2, "{text}");
    assert!(
        text.contains("- **FAIL** below (block-ground): held loads"),
        "{text}"
    );
    assert!(
        text.contains("- **FAIL** below and above: the stick/slip threshold"),
        "{text}"
    );

    std::fs::write(&history, &original).expect("restore");
    // the last increment's friction 1e-4 larger: the mean of the last two off by 5e-5
    let k = original
        .lines()
        .next()
        .and_then(|h| {
            h.split(',')
                .position(|c| c == "block-ground.tangential_force_1")
        })
        .expect("friction column");
    let last = original.lines().last().expect("rows").split(',').nth(k);
    let friction: f64 = last.and_then(|v| v.parse().ok()).expect("friction");
    set_last(
        &history,
        "block-ground.tangential_force_1",
        &format!("{:.9e}", 1.0001 * friction),
    );
    let (text, failed) = report(dir.path());
    assert_eq!(failed, 1, "{text}");
    assert!(
        text.contains("- **FAIL** below (block-ground): the friction and normal resultants"),
        "{text}"
    );
}
