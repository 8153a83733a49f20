//! A run's CSV outputs read back through the report's readers when a step name holds a comma
//! and quotes: the writer quotes the name, so every number stays in its column.

use std::path::Path;

use skid_cases::csv_out::CsvTable;
use skid_cases::{parse_case, run_case};
use skid_report::convergence::hardest_increment;
use skid_report::load_run;

const CASE_2D: &str = include_str!("../../../../cases/drum/2d-analytic.json");
const ODD_NAME: &str = "spin, down \"fast\"";

/// Runs the 2D drum for 5 ms with its dynamic step called `name`.
fn run_with_step_name(name: &str) -> tempfile::TempDir {
    let overrides = [
        "steps[1].duration=0.005".to_string(),
        format!("steps[1].name={}", serde_json::Value::from(name)),
    ];
    let case = parse_case(CASE_2D, Path::new("case.json"), &overrides).expect("case");
    let dir = tempfile::tempdir().expect("tempdir");
    let summary = run_case(&case, Path::new("case.json"), dir.path()).expect("run");
    assert_eq!(summary.status, "completed", "{:?}", summary.error);
    dir
}

fn read(dir: &Path, file: &str) -> String {
    std::fs::read_to_string(dir.join(file)).expect(file)
}

#[test]
fn a_step_name_with_commas_and_quotes_leaves_every_column_in_place() {
    let plain = run_with_step_name("spin-down");
    let odd = run_with_step_name(ODD_NAME);

    // history.csv: the report reads the same drum_omega as with a plain name.
    let history = read(odd.path(), "history.csv");
    assert!(
        history.contains(",\"spin, down \"\"fast\"\"\","),
        "not quoted"
    );
    let (expected, got) = (
        load_run(plain.path()).expect("plain run").history,
        load_run(odd.path()).expect("odd run").history,
    );
    assert!(expected.omega.len() > 40, "{} rows", expected.omega.len());
    assert!(expected.omega[0] == 60.0 && expected.omega.iter().all(|w| *w < 60.5));
    assert!(
        *expected.omega.last().expect("rows") < 59.0,
        "the drum slows"
    );
    assert_eq!(got, expected);
    let path = odd.path().join("history.csv");
    let table = CsvTable::new(&history, &path).expect("header");
    let step = table.column("step").expect("step column");
    let dynamic_rows = table
        .map(|row| row.expect("record").text(step).expect("step").to_string())
        .filter(|s| s == ODD_NAME)
        .count();
    assert_eq!(dynamic_rows, 50, "one row per 0.1 ms increment");

    // newton.csv: the hardest increment of the oddly named step is the plain run's.
    let newton_path = odd.path().join("newton.csv");
    let newton = read(odd.path(), "newton.csv");
    let got = hardest_increment(&newton, &newton_path, &[ODD_NAME])
        .expect("parses")
        .expect("a dynamic increment");
    let plain_newton = read(plain.path(), "newton.csv");
    let expected = hardest_increment(&plain_newton, Path::new("newton.csv"), &["spin-down"])
        .expect("parses")
        .expect("a dynamic increment");
    assert_eq!(got.step, ODD_NAME);
    assert!(expected.force.len() >= 2, "{expected:?}");
    assert_eq!(
        (got.increment, got.time, got.force, got.contact),
        (
            expected.increment,
            expected.time,
            expected.force,
            expected.contact
        )
    );
}
