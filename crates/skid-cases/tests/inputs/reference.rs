//! The shipped contract of the input formats (`docs/*.schema.json`, `docs/*-file.md`) is what
//! the types generate now: a change of a format or of its doc comments must regenerate them.

use std::path::Path;

use skid_cases::reference::{Format, markdown, schema_text};

fn shipped(path: &str) -> String {
    let file = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(path);
    std::fs::read_to_string(&file)
        .unwrap_or_else(|e| panic!("{path}: {e}: generate it with the command below"))
}

#[test]
fn shipped_schemas_and_references_are_what_the_types_generate() {
    for format in Format::ALL {
        let (name, schema, reference) =
            (format.name(), format.schema_path(), format.markdown_path());
        assert!(
            shipped(schema) == schema_text(format),
            "{schema} is stale: regenerate it with `cargo run -p skid-cli -- schema {name} -o {schema}`"
        );
        assert!(
            shipped(reference) == markdown(format),
            "{reference} is stale: regenerate it with `cargo run -p skid-cli -- schema {name} --markdown -o {reference}`"
        );
    }
}

#[test]
fn the_shipped_case_schema_accepts_the_shape_of_a_shipped_case() {
    let schema: serde_json::Value =
        serde_json::from_str(&shipped(Format::Case.schema_path())).expect("schema is JSON");
    let case: serde_json::Value =
        serde_json::from_str(&shipped("cases/drum/2d-analytic.json")).expect("case is JSON");
    let properties = schema["properties"].as_object().expect("properties");
    for field in case.as_object().expect("object").keys() {
        assert!(properties.contains_key(field), "{field} in the schema");
    }
    for field in schema["required"].as_array().expect("required") {
        assert!(case.get(field.as_str().expect("name")).is_some(), "{field}");
    }
}
