//! The hourglass control of the one-point elements in every input: a deck's `*SECTION CONTROLS,
//! HOURGLASS=` named by its `*SOLID SECTION, CONTROLS=` (read, written back, run), a model
//! file's `part.section.hourglass` and a case file's `pad.hourglass`, each refused with its line
//! or field where it does not apply.

use std::path::Path;

use skid_cases::deck::read_model;
use skid_cases::deck::write::write_deck;
use skid_cases::model_file::build;
use skid_cases::model_spec::ModelSpec;
use skid_cases::restart::DEFAULT_RESTART_EVERY;
use skid_cases::schema::HourglassControl;
use skid_cases::{CaseError, RunSummary, drum, parse_case, run_file};

/// A 4 x 1 cantilever of `kind` elements, clamped at x = 0, its tip moved down by 0.5 % of its
/// length (bending the elements), with `controls` between the element block and the section
/// and `section` the parameters after the section's material.
fn deck(kind: &str, controls: &str, section: &str) -> String {
    let mut nodes = String::new();
    for (row, y) in [0.0, 0.5].iter().enumerate() {
        for i in 0..5 {
            nodes += &format!("{}, {}, {y}\n", 1 + i + 5 * row, 0.5 * i as f64);
        }
    }
    let elements: String = (1..5)
        .map(|i| format!("{i}, {i}, {}, {}, {}\n", i + 1, i + 6, i + 5))
        .collect();
    format!(
        "*HEADING\ncantilever\n*NODE\n{nodes}*ELEMENT, TYPE={kind}, ELSET=beam\n{elements}\
         *NSET, NSET=tip\n5, 10\n{controls}*SOLID SECTION, ELSET=beam, MATERIAL=rubber{section}\n\
         1.0\n*MATERIAL, NAME=rubber\n*HYPERELASTIC, NEO HOOKE\n1.923e6, 2.4e-7\n*DENSITY\n\
         1000.0\n*BOUNDARY\n1, 1, 2\n6, 1, 2\n*STEP, NAME=bend, NLGEOM=YES\n*STATIC\n0.5, 1.0\n\
         *BOUNDARY\ntip, 2, 2, -0.01\n*END STEP\n"
    )
}

const ENHANCED: &str = "*SECTION CONTROLS, NAME=hg, HOURGLASS=ENHANCED\n";

/// Reads `text` as the deck `scene.inp` of a scratch directory.
fn read_text(text: &str) -> Result<ModelSpec, String> {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("scene.inp");
    std::fs::write(&path, text).expect("write deck");
    read_model(&path)
        .map(|d| d.model)
        .map_err(|e| e.to_string())
}

/// Runs the deck `text`; the strain and hourglass energy in the last row of its history.
fn run(text: &str) -> f64 {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("scene.inp");
    std::fs::write(&path, text).expect("write deck");
    let out = dir.path().join("run");
    let summary = run_file(&path, &[], Some(&out), DEFAULT_RESTART_EVERY).expect("runs");
    let RunSummary::Model(summary) = summary else {
        panic!("a deck runs as a model");
    };
    assert_eq!(summary.error, None);
    let history = std::fs::read_to_string(out.join("history.csv")).expect("history");
    let mut lines = history.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let column = (header.iter().position(|h| *h == "strain_energy")).expect("strain_energy");
    let last = lines.last().expect("a row");
    last.split(',')
        .nth(column)
        .expect("value")
        .parse()
        .expect("number")
}

#[test]
fn section_controls_read_write_back_and_run() {
    let enhanced = deck("CPE4R", ENHANCED, ", CONTROLS=hg");
    let model = read_text(&enhanced).expect("reads");
    assert_eq!(model.part.section.hourglass, HourglassControl::Enhanced);
    let written = write_deck(&model, &Default::default()).expect("writes");
    assert!(written.contains("HOURGLASS=ENHANCED"), "{written}");
    let reread = read_text(&written).expect("rereads");
    assert_eq!(reread.part.section, model.part.section);
    for text in [
        deck("CPE4R", "", ""),
        deck(
            "CPE4R",
            "*SECTION CONTROLS, NAME=hg, HOURGLASS=STIFFNESS\n",
            ", CONTROLS=hg",
        ),
    ] {
        let model = read_text(&text).expect("reads");
        assert_eq!(model.part.section.hourglass, HourglassControl::Stiffness);
        let written = write_deck(&model, &Default::default()).expect("writes");
        assert!(!written.contains("SECTION CONTROLS"), "{written}");
    }
    // the bent cantilever is stiffer with the incompatible-mode element's bending stiffness
    let (stiffness, enhanced) = (run(&deck("CPE4R", "", "")), run(&enhanced));
    assert!(enhanced > 1.2 * stiffness, "{enhanced} vs {stiffness}");
}

#[test]
fn section_controls_outside_the_subset_are_errors_at_their_line() {
    for (controls, section, kind, expected) in [
        (
            "*SECTION CONTROLS, NAME=hg, HOURGLASS=RELAX STIFFNESS\n",
            ", CONTROLS=hg",
            "CPE4R",
            "scene.inp:21: *SECTION CONTROLS: HOURGLASS=RELAX STIFFNESS is an Abaqus/Explicit",
        ),
        (
            "*SECTION CONTROLS, NAME=hg, HOURGLASS=COMBINED\n",
            ", CONTROLS=hg",
            "CPE4R",
            "Abaqus/Explicit",
        ),
        (
            "*SECTION CONTROLS, NAME=hg, HOURGLASS=STIFF\n",
            ", CONTROLS=hg",
            "CPE4R",
            "expected ENHANCED or STIFFNESS",
        ),
        (
            "*SECTION CONTROLS, NAME=hg\n",
            ", CONTROLS=hg",
            "CPE4R",
            "HOURGLASS",
        ),
        (
            "*SECTION CONTROLS, NAME=hg, HOURGLASS=ENHANCED\n1.0\n",
            ", CONTROLS=hg",
            "CPE4R",
            "takes no data lines",
        ),
        (
            "*SECTION CONTROLS, NAME=hg, HOURGLASS=ENHANCED, DISTORTION CONTROL=YES\n",
            ", CONTROLS=hg",
            "CPE4R",
            "DISTORTION CONTROL",
        ),
        (
            ENHANCED,
            ", CONTROLS=other",
            "CPE4R",
            "scene.inp:22: *SOLID SECTION, ELSET=beam: CONTROLS=other: no *SECTION CONTROLS",
        ),
        (
            ENHANCED,
            ", CONTROLS=hg",
            "CPE4I",
            "scene.inp:22: *SOLID SECTION, ELSET=beam: HOURGLASS=ENHANCED is for one-point",
        ),
    ] {
        let error = read_text(&deck(kind, controls, section)).expect_err(controls);
        assert!(error.contains(expected), "{controls}: {error}");
    }
}

/// The block deck's model with `edit` applied, built.
fn build_edited(edit: impl Fn(&mut ModelSpec)) -> Result<(), String> {
    let mut model = read_text(&deck("CPE4R", "", "")).expect("reads");
    edit(&mut model);
    build::<2>(&model)
        .map(|_| ())
        .map_err(|e| format!("{}: {}", e.field, e.message))
}

#[test]
fn model_file_enhanced_control_needs_one_point_elements_and_no_scale() {
    build_edited(|m| m.part.section.hourglass = HourglassControl::Enhanced).expect("builds");
    let scaled = build_edited(|m| {
        m.part.section.hourglass = HourglassControl::Enhanced;
        m.part.section.hourglass_scale = 2.0;
    })
    .expect_err("scaled");
    assert!(
        scaled.contains("part.section.hourglass_scale") && scaled.contains("takes no scale"),
        "{scaled}"
    );
    let full = build_edited(|m| {
        m.part.section.hourglass = HourglassControl::Enhanced;
        m.part.elements[0].kind = skid_cases::model_spec::ElementType::Cpe4;
    })
    .expect_err("CPE4");
    assert!(
        full.contains("part.section.hourglass") && full.contains("only CPE4"),
        "{full}"
    );
}

#[test]
fn case_file_enhanced_control_needs_the_reduced_pad() {
    let shipped = include_str!("../../../../cases/drum/2d-analytic.json");
    let parse = |sets: &[&str]| {
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        parse_case(shipped, Path::new("case.json"), &sets)
    };
    let case = parse(&["pad.hourglass=\"enhanced\""]).expect("valid");
    let model = drum::model_spec(&case).expect("model");
    assert_eq!(model.part.section.hourglass, HourglassControl::Enhanced);
    for (sets, field) in [
        (
            ["pad.hourglass=\"enhanced\"", "pad.formulation=\"hybrid\""],
            "pad.hourglass",
        ),
        (
            ["pad.hourglass=\"enhanced\"", "pad.hourglass_scale=2"],
            "pad.hourglass_scale",
        ),
    ] {
        match parse(&sets) {
            Err(CaseError::Invalid { field: named, .. }) => assert_eq!(named, field),
            other => panic!("{sets:?}: expected an error naming {field}, got {other:?}"),
        }
    }
}
