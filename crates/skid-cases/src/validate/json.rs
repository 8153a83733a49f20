//! Reading case and model text as JSON and then as a case or model file, with the place of every error: the line
//! and column of a syntax error, and the path of the field at fault (`pad.material.d1`) of an
//! error of the schema, also inside the tagged objects (`"type": ...`) whose contents serde
//! reads without tracking the path.

use std::fmt;

use serde::de::{self, Deserialize, DeserializeOwned, Deserializer, MapAccess, SeqAccess, Visitor};
use serde_json::{Map, Number, Value};

/// One step of a field path: an object key or an array index.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(super) enum Segment {
    /// An object key.
    Key(String),
    /// An array index.
    Index(usize),
}

/// Formats a path as case files and overrides write it: `steps[1].adaptive.min_dt`; the empty
/// path is `(top level)`; a key that is empty or holds one of `.[]"`, white space or a control
/// character is written as a JSON string (`pad."".x`), so that every path is readable and
/// unambiguous.
pub(super) fn path_text(path: &[Segment]) -> String {
    if path.is_empty() {
        return "(top level)".into();
    }
    let mut text = String::new();
    for segment in path {
        match segment {
            Segment::Key(key) => {
                if !text.is_empty() {
                    text.push('.');
                }
                let plain = !key.is_empty()
                    && !key
                        .chars()
                        .any(|c| ".[]\"".contains(c) || c.is_whitespace() || c.is_control());
                if plain {
                    text.push_str(key);
                } else {
                    text.push_str(&serde_json::Value::String(key.clone()).to_string());
                }
            }
            Segment::Index(i) => text.push_str(&format!("[{i}]")),
        }
    }
    text
}

fn segments(path: &serde_path_to_error::Path) -> Vec<Segment> {
    path.iter()
        .filter_map(|segment| match segment {
            serde_path_to_error::Segment::Map { key } => Some(Segment::Key(key.clone())),
            serde_path_to_error::Segment::Seq { index } => Some(Segment::Index(*index)),
            serde_path_to_error::Segment::Enum { .. } | serde_path_to_error::Segment::Unknown => {
                None
            }
        })
        .collect()
}

/// A JSON syntax error: where it is and what was expected.
#[derive(Debug)]
pub(super) struct SyntaxError {
    /// `line L column C`, preceded by the field being read if there was one
    /// (`pad.density, line 18 column 20`).
    pub place: String,
    /// What is wrong, and what was expected.
    pub message: String,
}

/// Where invalid UTF-8 begins in `bytes`, as a [`SyntaxError`]; `None` if the bytes are UTF-8.
pub(super) fn utf8_error(bytes: &[u8]) -> Option<SyntaxError> {
    let error = std::str::from_utf8(bytes).err()?;
    let valid = &bytes[..error.valid_up_to()];
    let line = valid.iter().filter(|&&b| b == b'\n').count() + 1;
    let line_start = valid.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
    let column = String::from_utf8_lossy(&valid[line_start..])
        .chars()
        .count()
        + 1;
    Some(SyntaxError {
        place: format!("line {line} column {column}"),
        message: format!(
            "not valid UTF-8 (byte 0x{:02x}): expected text in UTF-8",
            bytes[error.valid_up_to()]
        ),
    })
}

/// Parses `text` as JSON, refusing an object that names a key twice.
///
/// # Errors
/// The line and column, the field being read and what was expected.
pub(super) fn parse_json(text: &str) -> Result<Value, SyntaxError> {
    let mut deserializer = serde_json::Deserializer::from_str(text);
    let parsed = serde_path_to_error::deserialize::<_, Strict>(&mut deserializer)
        .map_err(|error| (segments(error.path()), error.into_inner()))
        .and_then(|strict| {
            // Trailing characters after the value.
            deserializer.end().map_err(|error| (Vec::new(), error))?;
            Ok(strict.0)
        });
    parsed.map_err(|(path, inner)| {
        let place = format!("line {} column {}", inner.line(), inner.column());
        let place = if path.is_empty() {
            place
        } else {
            format!("{}, {place}", path_text(&path))
        };
        // The message without serde_json's own " at line L column C".
        let full = inner.to_string();
        let what = full
            .strip_suffix(&format!(
                " at line {} column {}",
                inner.line(),
                inner.column()
            ))
            .unwrap_or(&full);
        let message = if what.starts_with("number out of range") {
            format!("not valid JSON: {what}: expected a finite number (magnitude below 1.8e308)")
        } else {
            format!("not valid JSON: {what}")
        };
        SyntaxError { place, message }
    })
}

/// A JSON value read with duplicate keys refused (serde_json's `Value` keeps the last one).
struct Strict(Value);

impl<'de> Deserialize<'de> for Strict {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_any(StrictVisitor).map(Strict)
    }
}

struct StrictVisitor;

impl<'de> Visitor<'de> for StrictVisitor {
    type Value = Value;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a JSON value")
    }

    fn visit_bool<E>(self, v: bool) -> Result<Value, E> {
        Ok(Value::Bool(v))
    }

    fn visit_i64<E>(self, v: i64) -> Result<Value, E> {
        Ok(Value::Number(v.into()))
    }

    fn visit_u64<E>(self, v: u64) -> Result<Value, E> {
        Ok(Value::Number(v.into()))
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<Value, E> {
        Number::from_f64(v)
            .map(Value::Number)
            .ok_or_else(|| E::custom(format!("expected a finite number, got {v}")))
    }

    fn visit_str<E>(self, v: &str) -> Result<Value, E> {
        Ok(Value::String(v.to_owned()))
    }

    fn visit_string<E>(self, v: String) -> Result<Value, E> {
        Ok(Value::String(v))
    }

    fn visit_unit<E>(self) -> Result<Value, E> {
        Ok(Value::Null)
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Value, A::Error> {
        let mut items = Vec::new();
        while let Some(Strict(item)) = seq.next_element()? {
            items.push(item);
        }
        Ok(Value::Array(items))
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Value, A::Error> {
        let mut object = Map::new();
        while let Some(key) = map.next_key::<String>()? {
            if object.contains_key(&key) {
                return Err(de::Error::custom(format!(
                    "duplicate field `{key}`: expected each field once"
                )));
            }
            let Strict(value) = map.next_value()?;
            object.insert(key, value);
        }
        Ok(Value::Object(object))
    }
}

/// Objects and arrays with more members than this are not searched for the member at fault.
const NARROW_LIMIT: usize = 64;

/// Deserializes a `T` (a case or a model file) from `value`.
///
/// # Errors
/// The path of the field at fault and serde's message.
pub(super) fn to_typed<T: DeserializeOwned>(value: &Value) -> Result<T, (Vec<Segment>, String)> {
    let error = match serde_path_to_error::deserialize::<_, T>(value) {
        Ok(case) => return Ok(case),
        Err(error) => error,
    };
    let mut path = segments(error.path());
    let message = error.into_inner().to_string();
    let mut probe = value.clone();
    while let Some(member) = member_at_fault::<T>(&mut probe, &path, &message) {
        path.push(member);
    }
    Err((path, message))
}

fn message_of<T: DeserializeOwned>(value: &Value) -> Option<String> {
    serde_path_to_error::deserialize::<_, T>(value)
        .err()
        .map(|e| e.into_inner().to_string())
}

fn node_mut<'a>(value: &'a mut Value, path: &[Segment]) -> Option<&'a mut Value> {
    path.iter().try_fold(value, |node, segment| match segment {
        Segment::Key(key) => node.get_mut(key.as_str()),
        Segment::Index(i) => node.get_mut(*i),
    })
}

/// The member of the object or array at `path` that the error `message` is about, if one is
/// alone responsible: serde reads a tagged object (`{"type": ...}`) as a whole, so its errors
/// carry the object's path, not the member's. A member is at fault if the object reduced to it
/// (and its `type`) gives the same error, and the object without it does not (a missing field
/// passes neither test). `probe` is the document's value, restored on return.
fn member_at_fault<T: DeserializeOwned>(
    probe: &mut Value,
    path: &[Segment],
    message: &str,
) -> Option<Segment> {
    let node = node_mut(probe, path)?;
    let members: Vec<Segment> = match node {
        Value::Object(object) if object.len() <= NARROW_LIMIT => {
            object.keys().cloned().map(Segment::Key).collect()
        }
        Value::Array(items) if items.len() <= NARROW_LIMIT => {
            (0..items.len()).map(Segment::Index).collect()
        }
        _ => return None,
    };
    let original = node.clone();
    let tag = Segment::Key("type".into());
    // A tag is at fault only if no other member is (an object with a bad member is also
    // incomplete without its tag).
    let (others, tags): (Vec<_>, Vec<_>) = members.into_iter().partition(|m| *m != tag);
    for member in others.into_iter().chain(tags) {
        let reduced = reduce(&original, &member, true);
        let without = reduce(&original, &member, false);
        let node = node_mut(probe, path)?;
        *node = reduced;
        let alone = message_of::<T>(probe);
        let node = node_mut(probe, path)?;
        *node = without;
        let absent = message_of::<T>(probe);
        let node = node_mut(probe, path)?;
        *node = original.clone();
        if alone.as_deref() == Some(message) && absent.as_deref() != Some(message) {
            return Some(member);
        }
    }
    None
}

/// `node` with only `member` (and an object's `type`) if `keep`, or without `member`.
fn reduce(node: &Value, member: &Segment, keep: bool) -> Value {
    match (node, member) {
        (Value::Object(object), Segment::Key(key)) => Value::Object(
            object
                .iter()
                .filter(|(k, _)| (k.as_str() == key.as_str()) == keep || (keep && *k == "type"))
                .map(|(k, v)| (k.clone(), v.clone()))
                .collect(),
        ),
        (Value::Array(items), Segment::Index(i)) => Value::Array(
            items
                .iter()
                .enumerate()
                .filter(|(j, _)| (j == i) == keep)
                .map(|(_, v)| v.clone())
                .collect(),
        ),
        _ => node.clone(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_are_written_as_case_files_name_fields() {
        let path = [
            Segment::Key("steps".into()),
            Segment::Index(1),
            Segment::Key("adaptive".into()),
            Segment::Key("min_dt".into()),
        ];
        assert_eq!(path_text(&path), "steps[1].adaptive.min_dt");
        assert_eq!(path_text(&[]), "(top level)");
    }

    #[test]
    fn keys_that_are_empty_or_not_plain_are_quoted() {
        // Found by fuzzing: an unknown empty key at the top level had the empty path.
        assert_eq!(path_text(&[Segment::Key(String::new())]), "\"\"");
        let path = [
            Segment::Key("pad".into()),
            Segment::Key("a.b".into()),
            Segment::Key("x y".into()),
        ];
        assert_eq!(path_text(&path), "pad.\"a.b\".\"x y\"");
        let e = to_typed::<crate::schema::ElementCounts>(
            &parse_json("{\"circumferential\": 1, \"radial\": 1, \"\": 1}").expect("json"),
        )
        .expect_err("unknown field");
        assert_eq!(path_text(&e.0), "\"\"");
    }

    #[test]
    fn duplicate_keys_are_refused_with_their_object() {
        let e = parse_json("{\"a\": {\"b\": 1,\n \"b\": 2}}").expect_err("duplicate");
        assert_eq!(e.place, "a, line 2 column 4");
        assert!(e.message.contains("duplicate field `b`"), "{}", e.message);
        assert!(parse_json("{\"a\": [1, 1], \"b\": {\"a\": 1}}").is_ok());
    }

    #[test]
    fn numbers_out_of_range_name_their_field_and_the_finite_range() {
        let e = parse_json("{\"pad\": {\"density\": -1e999}}").expect_err("infinite");
        assert_eq!(e.place, "pad.density, line 1 column 26");
        assert!(
            e.message.contains("expected a finite number"),
            "{}",
            e.message
        );
    }

    #[test]
    fn trailing_characters_are_a_syntax_error_at_their_place() {
        let e = parse_json("{}\n}").expect_err("trailing");
        assert_eq!(e.place, "line 2 column 1");
        assert!(e.message.contains("trailing characters"), "{}", e.message);
    }

    #[test]
    fn invalid_utf8_is_placed_by_line_and_character() {
        assert!(utf8_error("{\"é\": 1}".as_bytes()).is_none());
        let e = utf8_error(b"{\n  \"\xc3\xa9\xe9\"").expect("invalid");
        assert_eq!(e.place, "line 2 column 5");
        assert!(e.message.contains("0xe9"), "{}", e.message);
    }
}
