//! The contract of the input formats, generated from the Rust types that read them: the JSON
//! Schema of case files ([`crate::schema::Case`]), of model files
//! ([`crate::model_spec::ModelSpec`]) and of sweep files ([`crate::sweep::SweepSpec`]), and a markdown reference rendered from that schema (one
//! table per type), so that neither can drift from the code. `skid schema` prints them; the
//! copies shipped in `docs/` are checked against them by a test.

use std::fmt::Write as _;

use schemars::generate::SchemaSettings;
use serde_json::{Map, Value};

use crate::model_spec::ModelSpec;
use crate::schema::Case;
use crate::sweep::SweepSpec;

/// An input format with a schema.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Drum case files.
    Case,
    /// General model files.
    Model,
    /// Sweep files.
    Sweep,
}

impl Format {
    /// Every format, in the order of the documentation.
    pub const ALL: [Format; 3] = [Format::Case, Format::Model, Format::Sweep];

    /// The name on the command line (`skid schema case`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Case => "case",
            Self::Model => "model",
            Self::Sweep => "sweep",
        }
    }

    /// Reads a name given on the command line.
    ///
    /// # Errors
    /// What was expected, for a name that is neither `case` nor `model`.
    pub fn parse(name: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|f| f.name() == name)
            .ok_or_else(|| format!("expected `case`, `model` or `sweep`, got {name:?}"))
    }

    /// Where the repository ships the schema, relative to its root.
    pub fn schema_path(self) -> &'static str {
        match self {
            Self::Case => "docs/case.schema.json",
            Self::Model => "docs/model.schema.json",
            Self::Sweep => "docs/sweep.schema.json",
        }
    }

    /// Where the repository ships the markdown reference, relative to its root.
    pub fn markdown_path(self) -> &'static str {
        match self {
            Self::Case => "docs/case-file.md",
            Self::Model => "docs/model-file.md",
            Self::Sweep => "docs/sweep-file.md",
        }
    }

    fn title(self) -> &'static str {
        match self {
            Self::Case => "Case-file reference",
            Self::Model => "Model-file reference",
            Self::Sweep => "Sweep-file reference",
        }
    }
}

/// The JSON Schema (draft 2020-12) of a format, as the files are read (defaults filled in,
/// unknown fields refused).
pub fn json_schema(format: Format) -> Value {
    let generator = SchemaSettings::draft2020_12()
        .for_deserialize()
        .into_generator();
    let schema = match format {
        Format::Case => generator.into_root_schema_for::<Case>(),
        Format::Model => generator.into_root_schema_for::<ModelSpec>(),
        Format::Sweep => generator.into_root_schema_for::<SweepSpec>(),
    };
    schema.to_value()
}

/// The schema as shipped: pretty JSON ending in a newline.
pub fn schema_text(format: Format) -> String {
    // a JSON value always serializes: its alternate display is the pretty text
    format!("{:#}\n", json_schema(format))
}

/// The markdown reference of a format, rendered from its schema: the root type, then every
/// other type in alphabetical order; an object is a table of its fields (type, whether it is
/// required or its default, description), a tagged variant type one such table per variant,
/// and a set of names a table of the names.
pub fn markdown(format: Format) -> String {
    let schema = json_schema(format);
    let empty = Map::new();
    let defs = schema
        .get("$defs")
        .and_then(Value::as_object)
        .unwrap_or(&empty);
    let root = schema
        .get("title")
        .and_then(Value::as_str)
        .unwrap_or("root");
    let mut out = format!(
        "# {}\n\n<!-- Generated from the Rust types by `skid schema {} --markdown -o {}`; do not \
         edit by hand. -->\n\nThe JSON Schema of the same format is `{}`. Units are SI. Every \
         object refuses fields it does not list.\n",
        format.title(),
        format.name(),
        format.markdown_path(),
        format.schema_path(),
    );
    render_type(&mut out, root, &schema);
    for (name, def) in defs {
        render_type(&mut out, name, def);
    }
    out
}

/// Appends the section of one type.
fn render_type(out: &mut String, name: &str, schema: &Value) {
    let _ = write!(out, "\n## {name}\n");
    if let Some(description) = description(schema) {
        let _ = write!(out, "\n{description}\n");
    }
    if schema.get("properties").is_some() {
        out.push('\n');
        render_fields(out, schema);
        return;
    }
    let variants = schema
        .get("oneOf")
        .or_else(|| schema.get("anyOf"))
        .and_then(Value::as_array);
    if let Some(names) = schema.get("enum").and_then(Value::as_array) {
        out.push_str("\n| value | description |\n|---|---|\n");
        for value in names {
            let _ = writeln!(out, "| {} |  |", code(value));
        }
    } else if let Some(variants) = variants {
        if variants.iter().all(|v| v.get("properties").is_none()) {
            out.push_str("\n| value | description |\n|---|---|\n");
            for variant in variants {
                let value = variant
                    .get("const")
                    .map(code)
                    .unwrap_or_else(|| type_text(variant));
                let _ = writeln!(
                    out,
                    "| {value} | {} |",
                    description(variant).unwrap_or_default()
                );
            }
        } else {
            for variant in variants {
                let tag = variant
                    .pointer("/properties/type/const")
                    .map_or_else(|| "variant".to_string(), |t| format!("type {}", code(t)));
                let _ = write!(out, "\n### {name}: {tag}\n");
                if let Some(description) = description(variant) {
                    let _ = write!(out, "\n{description}\n");
                }
                out.push('\n');
                render_fields(out, variant);
            }
        }
    }
}

/// Appends the table of an object's fields, in the schema's order.
fn render_fields(out: &mut String, schema: &Value) {
    let required: Vec<&str> = schema
        .get("required")
        .and_then(Value::as_array)
        .map(|r| r.iter().filter_map(Value::as_str).collect())
        .unwrap_or_default();
    out.push_str("| field | type | required / default | description |\n|---|---|---|---|\n");
    let empty = Map::new();
    let properties = schema
        .get("properties")
        .and_then(Value::as_object)
        .unwrap_or(&empty);
    for (field, property) in properties {
        let presence = if required.contains(&field.as_str()) {
            "required".to_string()
        } else {
            match property.get("default") {
                Some(value @ Value::Object(_)) if value.to_string().len() > 40 => {
                    "optional (the defaults of its fields)".to_string()
                }
                Some(value) => format!("default {}", code(value)),
                None => "optional".to_string(),
            }
        };
        let description = match description(property) {
            Some(text) => text,
            None if property.get("const").is_some() => "Names this variant.".to_string(),
            None => String::new(),
        };
        let _ = writeln!(
            out,
            "| `{field}` | {} | {presence} | {description} |",
            type_text(property)
        );
    }
}

/// A schema's description on one line, fit for a table cell.
fn description(schema: &Value) -> Option<String> {
    let text = schema.get("description")?.as_str()?;
    Some(cell(&text.split_whitespace().collect::<Vec<_>>().join(" ")))
}

/// Text fit for a table cell: `|` escaped.
fn cell(text: &str) -> String {
    text.replace('|', "\\|")
}

/// A JSON value as inline code.
fn code(value: &Value) -> String {
    format!("`{}`", cell(&value.to_string()))
}

/// The type a schema describes, in words, with links to the sections of named types.
fn type_text(schema: &Value) -> String {
    if let Some(reference) = schema.get("$ref").and_then(Value::as_str) {
        let name = reference.rsplit('/').next().unwrap_or(reference);
        return format!("[{name}](#{})", name.to_lowercase());
    }
    if let Some(value) = schema.get("const") {
        return code(value);
    }
    if let Some(names) = schema.get("enum").and_then(Value::as_array) {
        let names: Vec<String> = names.iter().map(code).collect();
        return format!("one of {}", names.join(", "));
    }
    if let Some(alternatives) = schema
        .get("anyOf")
        .or_else(|| schema.get("oneOf"))
        .and_then(Value::as_array)
    {
        let names: Vec<String> = alternatives.iter().map(type_text).collect();
        return names.join(" or ");
    }
    match schema.get("type") {
        Some(Value::String(kind)) => kind_text(kind, schema),
        Some(Value::Array(kinds)) => kinds
            .iter()
            .filter_map(Value::as_str)
            .map(|kind| kind_text(kind, schema))
            .collect::<Vec<_>>()
            .join(" or "),
        _ => "any".to_string(),
    }
}

/// One JSON type of a schema in words (`kind` is one of the names in its `type`).
fn kind_text(kind: &str, schema: &Value) -> String {
    match kind {
        "integer" => match schema.get("minimum").and_then(Value::as_f64) {
            Some(min) => format!("integer ≥ {min}"),
            None => "integer".to_string(),
        },
        "array" => {
            if let Some(prefix) = schema.get("prefixItems").and_then(Value::as_array) {
                let items: Vec<String> = prefix.iter().map(type_text).collect();
                return format!("array [{}]", items.join(", "));
            }
            let items = schema
                .get("items")
                .map_or_else(|| "any".to_string(), type_text);
            let fixed = schema
                .get("minItems")
                .filter(|&n| Some(n) == schema.get("maxItems"));
            match fixed {
                Some(n) => format!("array of {n} {items}"),
                None => format!("array of {items}"),
            }
        }
        "object" => match schema.get("additionalProperties") {
            Some(Value::Bool(false)) | None => "object".to_string(),
            Some(values) => format!("map of string to {}", type_text(values)),
        },
        other => other.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_case_schema_lists_the_required_fields_and_refuses_unknown_ones() {
        let schema = json_schema(Format::Case);
        let required = schema["required"].as_array().expect("required");
        for field in ["name", "dimension", "drum", "pad", "steps"] {
            assert!(required.contains(&Value::from(field)), "{field}");
        }
        assert!(!required.contains(&Value::from("solver")));
        assert_eq!(schema["additionalProperties"], Value::Bool(false));
        assert_eq!(
            schema.pointer("/$defs/PadSpec/properties/hourglass_scale/default"),
            Some(&Value::from(1.0))
        );
    }

    #[test]
    fn the_reference_has_a_table_per_type_with_the_field_docs() {
        let text = markdown(Format::Model);
        assert!(text.contains("\n## ModelSpec\n"));
        assert!(text.contains("\n## RigidBodySpec\n"));
        assert!(text.contains("\n### RigidSurfaceSpec: type `\"cylinder\"`\n"));
        assert!(text.contains("| `mass` | number | default `0.0` | Point mass, kg. |"));
        assert!(text.contains("| `\"CPE4R\"` | 4-node plane-strain quadrilateral"));
    }

    #[test]
    fn format_names_are_read_back_and_others_refused() {
        for format in Format::ALL {
            assert_eq!(Format::parse(format.name()), Ok(format));
        }
        assert!(Format::parse("deck").is_err_and(|e| e.contains("`case`, `model` or `sweep`")));
    }
}
