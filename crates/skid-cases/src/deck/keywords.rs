//! The keyword layer of an Abaqus-style input deck: the text split into keyword blocks, each a
//! keyword line (name and parameters) and its data lines, with `*INCLUDE` resolved.
//!
//! Rules, as in the Abaqus keyword reference:
//! - a line starting with `**` is a comment; blank lines are ignored;
//! - a line starting with `*` is a keyword line: `*NAME, PARAM=VALUE, FLAG, ...`; names and
//!   parameter names are case-insensitive (kept here in upper case, inner blanks collapsed:
//!   `*solid  section` is `SOLID SECTION`); parameter values keep their case except where the
//!   semantic layer says otherwise; a keyword line ending with a comma continues on the next
//!   line;
//! - any other line is a data line of the last keyword: comma-separated fields, blanks around
//!   them trimmed; a trailing comma adds no empty field;
//! - `*INCLUDE, INPUT=file` is replaced by the blocks of `file` (relative to the including
//!   file); an include cycle is an error.
//!
//! Every block and data line remembers its file and line, so that the semantic layer names them
//! in its messages.
//!
//! A deck, its includes followed (a file included twice counts twice), may hold at most
//! [`MAX_DECK_LINES`] lines and [`MAX_DECK_BYTES`] bytes; both are checked before the text that
//! would pass them is read, so an oversized deck is refused before it is held in memory.

use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Where a line of a deck is: file and 1-based line number.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Location {
    /// File (shared by every line of it).
    pub file: Arc<Path>,
    /// Line number, from 1 (0: the file as a whole).
    pub line: usize,
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.line == 0 {
            write!(f, "{}", self.file.display())
        } else {
            write!(f, "{}:{}", self.file.display(), self.line)
        }
    }
}

/// A problem in a deck, at a line.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{location}: {message}")]
pub struct DeckError {
    /// Where.
    pub location: Location,
    /// What is wrong and what was expected.
    pub message: String,
}

/// One data line: its fields and where it is.
#[derive(Clone, Debug, PartialEq)]
pub struct DataLine {
    /// Comma-separated fields, trimmed.
    pub fields: Vec<String>,
    /// Where the line is.
    pub location: Location,
}

/// A keyword line and its data lines.
#[derive(Clone, Debug, PartialEq)]
pub struct Block {
    /// Keyword name in upper case, without the `*` (e.g. `SOLID SECTION`).
    pub name: String,
    /// Parameters in order: upper-case name and the value, if any (trimmed, case kept).
    pub parameters: Vec<(String, Option<String>)>,
    /// Data lines.
    pub data: Vec<DataLine>,
    /// Where the keyword line is.
    pub location: Location,
}

impl Block {
    /// The value of parameter `name` (upper case): `None` if absent, `Some(None)` if given
    /// without a value.
    pub fn parameter(&self, name: &str) -> Option<Option<&str>> {
        self.parameters
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_deref())
    }

    /// An error at the keyword line.
    pub fn error(&self, message: impl Into<String>) -> DeckError {
        DeckError {
            location: self.location.clone(),
            message: format!("*{}: {}", self.name, message.into()),
        }
    }
}

/// Largest depth of nested `*INCLUDE`s.
const MAX_INCLUDE_DEPTH: usize = 32;

/// Most lines a deck may hold with its includes: about two million nodes and their elements,
/// some 200 bytes each once read.
pub const MAX_DECK_LINES: usize = 5_000_000;

/// Most bytes of text a deck may hold with its includes.
pub const MAX_DECK_BYTES: u64 = 500_000_000;

/// What has been read of a deck so far, with its includes, and the most it may hold.
struct Read {
    lines: usize,
    bytes: u64,
    max_lines: usize,
    max_bytes: u64,
}

impl Read {
    fn new(max_lines: usize, max_bytes: u64) -> Self {
        Self {
            lines: 0,
            bytes: 0,
            max_lines,
            max_bytes,
        }
    }

    /// Adds `bytes` about to be read; an error if the deck passes its most bytes.
    fn add_bytes(&mut self, bytes: u64) -> Result<(), String> {
        self.bytes = self.bytes.saturating_add(bytes);
        if self.bytes > self.max_bytes {
            return Err(format!(
                "the deck with its *INCLUDEs passes {} bytes of text, the most skid reads",
                self.max_bytes
            ));
        }
        Ok(())
    }

    /// Adds the lines of `text`; an error if the deck passes its most lines.
    fn add_lines(&mut self, text: &str) -> Result<(), String> {
        self.lines = self.lines.saturating_add(text.lines().count());
        if self.lines > self.max_lines {
            return Err(format!(
                "the deck with its *INCLUDEs passes {} lines, the most skid reads (a file \
                 included again counts again)",
                self.max_lines
            ));
        }
        Ok(())
    }
}

/// Reads the deck `path` into blocks, following `*INCLUDE`s.
///
/// # Errors
/// [`DeckError`] for an unreadable file, data before the first keyword, an empty keyword name,
/// a malformed parameter, an include without `INPUT`, an include cycle, or a deck larger than
/// [`MAX_DECK_LINES`] or [`MAX_DECK_BYTES`].
pub fn read_deck(path: &Path) -> Result<Vec<Block>, DeckError> {
    read_deck_within(path, MAX_DECK_LINES, MAX_DECK_BYTES)
}

/// [`read_deck`] with other limits on the lines and bytes of the deck and its includes.
///
/// # Errors
/// See [`read_deck`].
pub fn read_deck_within(
    path: &Path,
    max_lines: usize,
    max_bytes: u64,
) -> Result<Vec<Block>, DeckError> {
    let mut blocks = Vec::new();
    let mut read = Read::new(max_lines, max_bytes);
    read_into(path, &mut Vec::new(), &mut read, &mut blocks)?;
    Ok(blocks)
}

fn read_into(
    path: &Path,
    stack: &mut Vec<PathBuf>,
    read: &mut Read,
    blocks: &mut Vec<Block>,
) -> Result<(), DeckError> {
    let at = |line| Location {
        file: Arc::from(path),
        line,
    };
    let canonical = path.canonicalize().unwrap_or_else(|_| path.to_path_buf());
    if stack.contains(&canonical) || stack.len() >= MAX_INCLUDE_DEPTH {
        return Err(DeckError {
            location: at(0),
            message: "included again from itself (an *INCLUDE cycle)".into(),
        });
    }
    let size = std::fs::metadata(path).map_or(0, |m| m.len());
    read.add_bytes(size).map_err(|message| DeckError {
        location: at(0),
        message,
    })?;
    let text = std::fs::read_to_string(path).map_err(|e| DeckError {
        location: at(0),
        message: format!("cannot read: {e}"),
    })?;
    read.add_lines(&text).map_err(|message| DeckError {
        location: at(0),
        message,
    })?;
    stack.push(canonical);
    let parsed = parse_text(&text, path)?;
    for block in parsed {
        if block.name != "INCLUDE" {
            blocks.push(block);
            continue;
        }
        let Some(Some(input)) = block.parameter("INPUT") else {
            return Err(block.error("expected INPUT=<file>"));
        };
        if !block.data.is_empty() {
            return Err(block.error("takes no data lines"));
        }
        let included = path.parent().unwrap_or(Path::new("")).join(input);
        read_into(&included, stack, read, blocks).map_err(|e| {
            if e.location.line == 0 && *e.location.file == *included {
                block.error(format!("{}: {}", included.display(), e.message))
            } else {
                e
            }
        })?;
    }
    stack.pop();
    Ok(())
}

/// Splits deck text (from `file`, for messages) into blocks; `*INCLUDE` blocks are kept as such.
///
/// # Errors
/// See [`read_deck`].
pub fn parse_text(text: &str, file: &Path) -> Result<Vec<Block>, DeckError> {
    let file: Arc<Path> = Arc::from(file);
    let at = |line| Location {
        file: Arc::clone(&file),
        line,
    };
    let mut blocks: Vec<Block> = Vec::new();
    let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l));
    while let Some((number, raw)) = lines.next() {
        let line = raw.trim();
        if line.is_empty() || line.starts_with("**") {
            continue;
        }
        if let Some(keyword) = line.strip_prefix('*') {
            // continuation: a keyword line ending with a comma goes on
            let mut full = keyword.to_string();
            while full.trim_end().ends_with(',') {
                match lines.next() {
                    Some((_, next)) if !next.trim().starts_with('*') => {
                        full.push_str(next.trim());
                    }
                    _ => {
                        return Err(DeckError {
                            location: at(number),
                            message: "keyword line ends with a comma but no continuation \
                                      line follows"
                                .into(),
                        });
                    }
                }
            }
            blocks.push(keyword_line(&full, at(number))?);
        } else {
            let Some(block) = blocks.last_mut() else {
                return Err(DeckError {
                    location: at(number),
                    message: "data line before the first keyword".into(),
                });
            };
            let mut fields: Vec<String> = line.split(',').map(|f| f.trim().to_string()).collect();
            if fields.len() > 1 && fields.last().is_some_and(String::is_empty) {
                fields.pop();
            }
            block.data.push(DataLine {
                fields,
                location: at(number),
            });
        }
    }
    Ok(blocks)
}

/// `NAME, P1=V1, FLAG` (without the leading `*`).
fn keyword_line(text: &str, location: Location) -> Result<Block, DeckError> {
    let fail = |message: String| DeckError {
        location: location.clone(),
        message,
    };
    let mut parts = text.split(',');
    let name = normalize(parts.next().unwrap_or_default());
    if name.is_empty() {
        return Err(fail("a keyword line needs a keyword name after '*'".into()));
    }
    let mut parameters = Vec::new();
    for part in parts {
        let part = part.trim();
        if part.is_empty() {
            continue;
        }
        let (key, value) = match part.split_once('=') {
            Some((k, v)) => (normalize(k), Some(v.trim().to_string())),
            None => (normalize(part), None),
        };
        if key.is_empty() || value.as_deref() == Some("") {
            return Err(fail(format!(
                "*{name}: malformed parameter '{part}', expected NAME or NAME=VALUE"
            )));
        }
        parameters.push((key, value));
    }
    Ok(Block {
        name,
        parameters,
        data: Vec::new(),
        location,
    })
}

/// Upper case with runs of blanks collapsed to one space.
fn normalize(s: &str) -> String {
    s.split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
        .to_uppercase()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Vec<Block> {
        parse_text(text, Path::new("t.inp")).expect("parses")
    }

    #[test]
    fn keywords_parameters_and_data_lines_are_split_case_insensitively() {
        let blocks = parse(
            "** a comment\n*Heading\nbraking drum\n\n*solid   Section, elset=Pad, \
             MATERIAL=rubber\n1.0,\n*Node\n 1, 0.0, 0.2\n2,0.1 , 0.2\n",
        );
        let names: Vec<&str> = blocks.iter().map(|b| b.name.as_str()).collect();
        assert_eq!(names, ["HEADING", "SOLID SECTION", "NODE"]);
        let section = &blocks[1];
        assert_eq!(section.parameter("ELSET"), Some(Some("Pad")));
        assert_eq!(section.parameter("MATERIAL"), Some(Some("rubber")));
        assert_eq!(section.parameter("ORIENTATION"), None);
        assert_eq!(
            section.data[0].fields,
            ["1.0"],
            "a trailing comma adds no field"
        );
        assert_eq!(blocks[2].data[1].fields, ["2", "0.1", "0.2"]);
        assert_eq!(blocks[2].data[1].location.line, 9);
        assert_eq!(blocks[0].data[0].fields, ["braking drum"]);
    }

    #[test]
    fn a_keyword_line_ending_with_a_comma_continues() {
        let blocks = parse("*Surface Interaction,\n  name=Rough\n*Friction\n0.15\n");
        assert_eq!(blocks[0].name, "SURFACE INTERACTION");
        assert_eq!(blocks[0].parameter("NAME"), Some(Some("Rough")));
        assert_eq!(blocks[1].data[0].fields, ["0.15"]);
        let flags = parse("*Dynamic, ALPHA=-0.3, NOHAF\n1e-4, 0.15\n");
        assert_eq!(flags[0].parameter("NOHAF"), Some(None));
    }

    #[test]
    fn malformed_lines_are_errors_with_their_line() {
        let err = |text: &str| parse_text(text, Path::new("bad.inp")).expect_err(text);
        let e = err("1, 2, 3\n*NODE\n");
        assert_eq!(e.location.line, 1);
        assert!(e.message.contains("before the first keyword"), "{e}");
        let e = err("*NODE\n1, 0, 0\n*\n");
        assert_eq!(e.location.line, 3);
        let e = err("*SOLID SECTION, ELSET=\n");
        assert!(e.to_string().starts_with("bad.inp:1: "), "{e}");
        assert!(e.message.contains("NAME=VALUE"), "{e}");
        let e = err("*STEP,\n*STATIC\n");
        assert!(e.message.contains("continuation"), "{e}");
    }

    #[test]
    fn a_deck_that_passes_its_lines_or_bytes_with_its_includes_is_refused_at_the_include() {
        let dir = tempfile::tempdir().expect("tempdir");
        let main = dir.path().join("main.inp");
        // 3 lines of main and the 4 of a part included three times: 15 lines
        let part = "*NODE\n1, 0.0\n2, 1.0\n3, 2.0\n";
        std::fs::write(dir.path().join("part.inp"), part).expect("write");
        let include = "*INCLUDE, INPUT=part.inp\n";
        std::fs::write(&main, include.repeat(3)).expect("write");
        let text_bytes = 3 * (include.len() + part.len()) as u64;
        assert_eq!(
            read_deck_within(&main, 15, text_bytes).expect("fits").len(),
            3
        );
        let e = read_deck_within(&main, 14, text_bytes).expect_err("one line too many");
        assert_eq!(
            (e.location.line, &*e.location.file),
            (3, main.as_path()),
            "{e}"
        );
        assert!(e.message.contains("passes 14 lines"), "{e}");
        let e = read_deck_within(&main, 15, text_bytes - 1).expect_err("one byte too many");
        assert_eq!(e.location.line, 3, "{e}");
        assert!(e.message.contains("bytes of text"), "{e}");
        // a deck too large by itself is refused as a whole, before it is read
        let e = read_deck_within(&main, 15, 10).expect_err("main too large");
        assert_eq!(e.location.line, 0, "{e}");
    }

    #[test]
    fn includes_are_read_in_place_and_cycles_are_refused() {
        let dir = tempfile::tempdir().expect("tempdir");
        let main = dir.path().join("main.inp");
        std::fs::write(
            &main,
            "*HEADING\n*INCLUDE, INPUT=mesh/nodes.inp\n*ELEMENT, TYPE=CPE4R\n",
        )
        .expect("write");
        std::fs::create_dir(dir.path().join("mesh")).expect("mkdir");
        std::fs::write(dir.path().join("mesh/nodes.inp"), "*NODE\n1, 0., 0.\n").expect("write");
        let blocks = read_deck(&main).expect("reads");
        let names: Vec<&str> = blocks.iter().map(|b| b.name.as_str()).collect();
        assert_eq!(names, ["HEADING", "NODE", "ELEMENT"]);
        assert!(blocks[1].location.file.ends_with("mesh/nodes.inp"));

        std::fs::write(
            dir.path().join("mesh/nodes.inp"),
            "*INCLUDE, INPUT=../main.inp\n",
        )
        .expect("write");
        let e = read_deck(&main).expect_err("cycle");
        assert!(e.message.contains("cycle"), "{e}");
        std::fs::write(&main, "*INCLUDE, INPUT=missing.inp\n").expect("write");
        let e = read_deck(&main).expect_err("missing");
        assert_eq!(e.location.line, 1, "{e}");
        assert!(
            e.message.contains("missing.inp") && e.message.contains("cannot read"),
            "{e}"
        );
    }
}
