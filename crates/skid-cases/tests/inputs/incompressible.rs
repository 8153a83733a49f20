//! The literal reading of D1 (K/mu = 1e7, DRUM.md section 2.1): the first 2 ms of the
//! spin-down, where friction sets the nearly incompressible pad vibrating, must run at the
//! nominal time step. With the displacement formulation's tangent the Newton iterates carried
//! pressures `U'(J)` far above the shear modulus and the tangent turned indefinite: the 2D case
//! needed cutbacks from the second dynamic increment on (698 over the whole run).

use std::path::Path;

use skid_cases::{Summary, parse_case, run_case};

const CASE_2D: &str = include_str!("../../../../cases/hard/2d-incompressible.json");

fn run_briefly(text: &str) -> (Summary, tempfile::TempDir) {
    let overrides = vec!["steps[1].duration=0.002".to_string()];
    let case = parse_case(text, Path::new("case.json"), &overrides).expect("case");
    let dir = tempfile::tempdir().expect("tempdir");
    let summary = run_case(&case, Path::new("case.json"), dir.path()).expect("run");
    (summary, dir)
}

fn assert_no_cutbacks(text: &str) {
    let (s, _dir) = run_briefly(text);
    assert_eq!(s.status, "completed", "{:?}", s.error);
    assert_eq!(
        s.cost.cutbacks, 0,
        "cutbacks by cause: {:?}",
        s.cost.cutback_causes
    );
    // Sliding from the start: omega falls at mu p A R / I = 600 rad/s^2 (the side contacts'
    // tilt and the vibration that friction sets off add about 1 %).
    let decel = s.deceleration.expect("deceleration");
    assert!((decel - 600.0).abs() < 0.02 * 600.0, "deceleration {decel}");
}

#[test]
fn nearly_incompressible_pad_starts_sliding_without_cutbacks() {
    assert_no_cutbacks(CASE_2D);
}
