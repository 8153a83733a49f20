//! Several deformable parts: the two pads of `2d-two-pads-on-drum.json`, one part there, given
//! as two parts in `2d-two-pads-on-drum-parts.json` (the lower pad numbered from 0 with its own
//! set names) merge into the same mesh and run to the same history, bit for bit; parts that cannot be merged are refused with the
//! field at fault.

use std::path::{Path, PathBuf};

use serde_json::{Value, json};
use skid_cases::model_file::parse_model;
use skid_cases::runner::run_model;

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(path)
}

/// The scene in one part, and in the two parts of `2d-two-pads-on-drum-parts.json` (its lower
/// pad numbered from 0, with its own set names, referred to as `lower.<set>`).
fn two_parts() -> (Value, Value) {
    let read = |file: &str| -> Value {
        let text =
            std::fs::read_to_string(repo(&format!("cases/verification/{file}"))).expect("scene");
        serde_json::from_str(&text).expect("json")
    };
    (
        read("2d-two-pads-on-drum.json"),
        read("2d-two-pads-on-drum-parts.json"),
    )
}

fn history(spec: &Value) -> String {
    let path = Path::new("scene.json");
    let spec =
        parse_model(&spec.to_string(), path, &["steps[1].duration=0.01".into()]).expect("model");
    let dir = tempfile::tempdir().expect("tempdir");
    let summary = run_model(&spec, path, dir.path()).expect("runs");
    assert!(summary.error.is_none(), "{:?}", summary.error);
    std::fs::read_to_string(dir.path().join("history.csv")).expect("history")
}

#[test]
fn two_parts_merge_into_the_mesh_of_one_and_run_alike() {
    let (one, two) = two_parts();
    let merged = parse_model(&two.to_string(), Path::new("scene.json"), &[]).expect("merges");
    assert!(merged.parts.is_empty());
    assert_eq!(merged.part.nodes.len(), 44);
    assert_eq!(merged.part.node_sets["lower"], (22..44).collect::<Vec<_>>());
    assert_eq!(
        merged.part.element_sets["lower"],
        (10..20).collect::<Vec<_>>()
    );
    let single = parse_model(&one.to_string(), Path::new("scene.json"), &[]).expect("one part");
    // a block per part, the same elements in the same order
    let corners = |spec: &skid_cases::model_spec::ModelSpec| {
        spec.part
            .elements
            .iter()
            .flat_map(|b| b.connectivity.clone())
            .collect::<Vec<_>>()
    };
    assert_eq!(merged.part.elements.len(), 2);
    assert_eq!(corners(&merged), corners(&single));
    assert_eq!(
        merged.part.node_sets["lower.front"],
        single.part.node_sets["lower-front"]
    );
    // the same material: no material of its own
    assert!(merged.part.materials.is_empty());
    assert_eq!(history(&one), history(&two));
}

#[test]
fn parts_that_cannot_be_merged_are_refused_with_the_field() {
    let (_, two) = two_parts();
    let refused = |edit: &dyn Fn(&mut Value), field: &str, fragment: &str| {
        let mut spec = two.clone();
        edit(&mut spec);
        let message = parse_model(&spec.to_string(), Path::new("scene.json"), &[])
            .expect_err(field)
            .to_string();
        assert!(
            message.contains(field) && message.contains(fragment),
            "{message}"
        );
    };
    refused(
        &|s| s["parts"][0]["section"]["hourglass_scale"] = json!(2.0),
        "parts[0].section.hourglass_scale",
        "expected the first part's",
    );
    refused(
        &|s| s["parts"][0]["elements"][0]["connectivity"][3][1] = json!(22),
        "parts[0].elements[0].connectivity[3]",
        "no number 22: it has 22",
    );
    refused(
        &|s| s["parts"][0]["name"] = json!("pads"),
        "parts[0].name",
        "a name of its own",
    );
    refused(
        &|s| s["part"]["node_sets"]["lower.back"] = json!([0]),
        "parts[0]",
        "'lower.back' takes a name already in use",
    );
    // a material of its own goes to its element set
    let mut soft = two.clone();
    soft["parts"][0]["section"]["density"] = json!(500.0);
    let merged = parse_model(&soft.to_string(), Path::new("scene.json"), &[]).expect("merges");
    assert_eq!(merged.part.materials.len(), 1);
    assert_eq!(merged.part.materials[0].element_set, "lower");
    assert_eq!(merged.part.materials[0].density, 500.0);
}
