//! Bad case files are rejected with the file, the field and what was expected; never a panic.

use std::path::Path;

use skid_cases::{CaseError, load_case, parse_case};

const SHIPPED: &str = include_str!("../../../../cases/drum/2d-analytic.json");

fn with(edit: impl Fn(&mut serde_json::Value)) -> String {
    let mut v: serde_json::Value = serde_json::from_str(SHIPPED).expect("shipped case is JSON");
    edit(&mut v);
    v.to_string()
}

fn error(text: &str) -> (String, String) {
    match parse_case(text, Path::new("case.json"), &[]) {
        Err(CaseError::Parse { field, message, .. })
        | Err(CaseError::Invalid { field, message, .. }) => (field, message),
        other => panic!("expected a field error, got {other:?}"),
    }
}

#[test]
fn shipped_drum_case_is_valid() {
    let case = parse_case(SHIPPED, Path::new("2d-analytic.json"), &[]).expect("valid");
    assert_eq!(case.name, "2d-analytic");
    assert_eq!(case.dimension, 2);
}

#[test]
fn unknown_field_is_named_with_its_path() {
    let (field, message) = error(&with(|v| v["pad"]["densty"] = 1.0.into()));
    assert_eq!(field, "pad.densty");
    assert!(message.contains("unknown field `densty`"), "{message}");
}

#[test]
fn missing_field_is_named() {
    let (field, message) = error(&with(|v| {
        v["pad"].as_object_mut().expect("object").remove("density");
    }));
    assert_eq!(field, "pad");
    assert!(message.contains("missing field `density`"), "{message}");
}

#[test]
fn wrong_type_is_named_with_its_path() {
    let (field, message) = error(&with(|v| v["drum"]["radius"] = "large".into()));
    assert_eq!(field, "drum.radius");
    assert!(message.contains("expected f64"), "{message}");
}

#[test]
fn non_physical_values_are_rejected_with_the_expected_range() {
    for (edit, expected_field) in [
        (with(|v| v["pad"]["density"] = (-5.0).into()), "pad.density"),
        (
            with(|v| v["pad"]["material"]["d1"] = 0.0.into()),
            "pad.material.d1",
        ),
        (with(|v| v["contact"]["mu"] = (-0.1).into()), "contact.mu"),
        (
            with(|v| v["steps"][1]["alpha"] = 0.2.into()),
            "steps[1].alpha",
        ),
        (with(|v| v["steps"][1]["dt"] = 1.0.into()), "steps[1].dt"),
        (
            with(|v| v["steps"][0]["increments"] = 0.into()),
            "steps[0].increments",
        ),
        (
            with(|v| v["pad"]["elements"]["circumferential"] = 0.into()),
            "pad.elements.circumferential",
        ),
        (
            with(|v| v["steps"][0]["hold"][0] = "wheel".into()),
            "steps[0].hold",
        ),
        (with(|v| v["dimension"] = 4.into()), "dimension"),
        (with(|v| v["pad"]["length"] = 0.5.into()), "pad.length"),
        (
            with(|v| {
                v["drum"]["surface"] =
                    serde_json::json!({"type": "facets", "element": "r3d4", "count": 72})
            }),
            "drum.surface.element",
        ),
        (
            with(|v| {
                v["drum"]["surface"] =
                    serde_json::json!({"type": "facets", "element": "r2d2", "count": 2})
            }),
            "drum.surface.count",
        ),
        (
            with(|v| {
                v["dimension"] = 3.into();
                v["drum"]["surface"] = serde_json::json!({"type": "tetrahedra", "sectors": 72, "rings": 2, "layers": 1, "inner_radius": 0.3});
            }),
            "drum.surface.inner_radius",
        ),
        (
            with(|v| {
                v["contact"]["formulation"] =
                    serde_json::json!({"type": "general", "search_distance": 0.0})
            }),
            "contact.formulation.search_distance",
        ),
        (
            with(|v| {
                v["steps"][1]["adaptive"] =
                    serde_json::json!({"tolerance": 0.0, "min_dt": 1e-7, "max_dt": 5e-3})
            }),
            "steps[1].adaptive.tolerance",
        ),
        (
            with(|v| {
                v["steps"][1]["adaptive"] =
                    serde_json::json!({"tolerance": 1e-6, "min_dt": 1e-3, "max_dt": 5e-3})
            }),
            "steps[1].adaptive.min_dt",
        ),
        (
            with(|v| {
                v["steps"][1]["adaptive"] =
                    serde_json::json!({"tolerance": 1e-6, "min_dt": 1e-7, "max_dt": 1.0})
            }),
            "steps[1].adaptive.max_dt",
        ),
        (
            with(|v| {
                v["pad"]["quasi_static"] = true.into();
                v["back_plate"]["mass"] = 2.0.into();
            }),
            "back_plate.mass",
        ),
    ] {
        let (field, message) = error(&edit);
        assert_eq!(field, expected_field, "{message}");
        assert!(message.starts_with("expected"), "{message}");
    }
}

#[test]
fn invalid_json_reports_line_and_column() {
    let (field, message) = error("{\n  \"name\": \"x\",\n  oops\n}");
    assert!(field.starts_with("line 3"), "{field}");
    assert!(message.contains("not valid JSON"), "{message}");
}

#[test]
fn unreadable_file_is_a_read_error() {
    let err = load_case(Path::new("/nonexistent/skid/case.json"), &[]).expect_err("missing");
    assert!(matches!(err, CaseError::Read { .. }));
    assert!(err.to_string().contains("/nonexistent/skid/case.json"));
}

#[test]
fn overrides_set_nested_fields_and_reject_bad_paths() {
    let case = parse_case(
        SHIPPED,
        Path::new("c.json"),
        &[
            "steps[1].dt=5e-5".into(),
            "solver.max_cutbacks=3".into(),
            "name=variant".into(),
        ],
    )
    .expect("valid overrides");
    assert_eq!(case.name, "variant");
    assert_eq!(case.solver.max_cutbacks, 3);
    match &case.steps[1] {
        skid_cases::schema::StepSpec::Dynamic { dt, .. } => assert_eq!(*dt, 5e-5),
        other => panic!("unexpected step {other:?}"),
    }
    for bad in ["steps[7].dt=1", "no-equals-sign", "steps[x].dt=1"] {
        assert!(matches!(
            parse_case(SHIPPED, Path::new("c.json"), &[bad.into()]),
            Err(CaseError::Override { .. })
        ));
    }
    // A misspelt key is created by the override, then rejected as an unknown field.
    let (field, message) = match parse_case(SHIPPED, Path::new("c.json"), &["pad.densty=1".into()])
    {
        Err(CaseError::Parse { field, message, .. }) => (field, message),
        other => panic!("{other:?}"),
    };
    assert_eq!(field, "pad.densty");
    assert!(message.contains("unknown field"));
}

#[test]
fn shipped_cases_are_valid_described_and_named_after_their_files() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../cases");
    let mut seen = 0;
    for dir in ["drum", "hard"] {
        for entry in std::fs::read_dir(root.join(dir)).expect("cases directory") {
            let path = entry.expect("entry").path();
            if path.extension().is_none_or(|e| e != "json") {
                continue;
            }
            let case = load_case(&path, &[]).unwrap_or_else(|e| panic!("{e}"));
            let stem = path.file_stem().expect("stem").to_string_lossy();
            assert_eq!(case.name, stem, "{}", path.display());
            assert!(!case.description.is_empty(), "{}", path.display());
            assert!(
                stem.starts_with(&format!("{}d-", case.dimension)),
                "{}: the prefix names the dimension",
                path.display()
            );
            seen += 1;
        }
    }
    assert!(seen >= 27, "{seen} shipped cases");
}
