//! Typed reading of keyword parameters and data-line fields, each failure an error at its line
//! naming the keyword, the field and what was expected.

use super::keywords::{Block, DataLine, DeckError};

/// An error at a data line of `block`.
pub fn line_error(block: &Block, line: &DataLine, message: impl Into<String>) -> DeckError {
    DeckError {
        location: line.location.clone(),
        message: format!("*{}: {}", block.name, message.into()),
    }
}

/// Refuses any parameter of `block` not in `allowed` (upper case).
pub fn allow_parameters(block: &Block, allowed: &[&str]) -> Result<(), DeckError> {
    for (name, _) in &block.parameters {
        if !allowed.contains(&name.as_str()) {
            let expected = if allowed.is_empty() {
                "it takes no parameters".to_string()
            } else {
                format!("expected one of {}", allowed.join(", "))
            };
            return Err(block.error(format!(
                "parameter {name} is outside the keyword subset skid reads ({expected})"
            )));
        }
    }
    Ok(())
}

/// The value of a parameter that must have one (`None` if the parameter is absent).
pub fn valued<'a>(block: &'a Block, name: &str) -> Result<Option<&'a str>, DeckError> {
    match block.parameter(name) {
        None => Ok(None),
        Some(Some(v)) if !v.is_empty() => Ok(Some(v)),
        Some(_) => Err(block.error(format!("parameter {name} needs a value ({name}=...)"))),
    }
}

/// The value of a required parameter.
pub fn required<'a>(block: &'a Block, name: &str) -> Result<&'a str, DeckError> {
    valued(block, name)?.ok_or_else(|| block.error(format!("parameter {name}= is required")))
}

/// Whether a flag parameter (no value, or `YES`) is present; `NO` counts as absent.
pub fn flag(block: &Block, name: &str) -> Result<bool, DeckError> {
    match block.parameter(name) {
        None => Ok(false),
        Some(None) => Ok(true),
        Some(Some(v)) if v.eq_ignore_ascii_case("YES") => Ok(true),
        Some(Some(v)) if v.eq_ignore_ascii_case("NO") => Ok(false),
        Some(Some(v)) => Err(block.error(format!("parameter {name}={v}: expected YES or NO"))),
    }
}

/// A real number parameter.
pub fn real_parameter(block: &Block, name: &str) -> Result<Option<f64>, DeckError> {
    valued(block, name)?
        .map(|v| {
            parse_real(v)
                .ok_or_else(|| block.error(format!("parameter {name}={v}: expected a number")))
        })
        .transpose()
}

/// Field `i` (from 0) of a data line, if present and not blank.
pub fn field(line: &DataLine, i: usize) -> Option<&str> {
    line.fields
        .get(i)
        .map(String::as_str)
        .filter(|s| !s.is_empty())
}

/// Field `i` as a finite real number (`what` names it in messages).
pub fn real(block: &Block, line: &DataLine, i: usize, what: &str) -> Result<f64, DeckError> {
    let text = field(line, i)
        .ok_or_else(|| line_error(block, line, format!("field {} ({what}) is missing", i + 1)))?;
    parse_real(text).ok_or_else(|| {
        line_error(
            block,
            line,
            format!(
                "field {} ({what}): expected a finite number, got '{text}'",
                i + 1
            ),
        )
    })
}

/// Field `i` as a real number, `default` if absent or blank.
pub fn real_or(
    block: &Block,
    line: &DataLine,
    i: usize,
    what: &str,
    default: f64,
) -> Result<f64, DeckError> {
    if field(line, i).is_some() {
        real(block, line, i, what)
    } else {
        Ok(default)
    }
}

/// Field `i` as a positive integer label (node, element, degree of freedom).
pub fn label(block: &Block, line: &DataLine, i: usize, what: &str) -> Result<u64, DeckError> {
    let text = field(line, i)
        .ok_or_else(|| line_error(block, line, format!("field {} ({what}) is missing", i + 1)))?;
    parse_label(text).ok_or_else(|| {
        line_error(
            block,
            line,
            format!(
                "field {} ({what}): expected a positive integer, got '{text}'",
                i + 1
            ),
        )
    })
}

/// Refuses a data line with more than `n` fields.
pub fn at_most(block: &Block, line: &DataLine, n: usize) -> Result<(), DeckError> {
    if line.fields.len() > n {
        Err(line_error(
            block,
            line,
            format!(
                "expected at most {n} fields, got {}: '{}'",
                line.fields.len(),
                line.fields.join(", ")
            ),
        ))
    } else {
        Ok(())
    }
}

/// A finite real number in deck notation (`1.`, `.5`, `1e-4`, `1.0D3`).
pub fn parse_real(text: &str) -> Option<f64> {
    let normal = text.replace(['d', 'D'], "e");
    normal.parse::<f64>().ok().filter(|v| v.is_finite())
}

/// A positive integer label.
pub fn parse_label(text: &str) -> Option<u64> {
    text.parse::<u64>().ok().filter(|&v| v > 0)
}

/// The key under which a name is looked up: deck names are case-insensitive.
pub fn key(name: &str) -> String {
    name.trim().to_ascii_uppercase()
}
