//! What the deck tests share: a deck read from text, and the check that a deck is refused at
//! a given line.

use skid_cases::deck::read_model;
use skid_cases::model_spec::ModelSpec;

/// The model of the deck `text`, written to `deck.inp` in a temporary directory and read; the
/// error as its message, which names `deck.inp:<line>`.
pub fn read_deck_text(text: &str) -> Result<ModelSpec, String> {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("deck.inp");
    std::fs::write(&path, text).expect("write deck");
    read_model(&path)
        .map(|d| d.model)
        .map_err(|e| e.to_string())
}

/// Asserts that the deck `text` is refused at its line that reads `needle`, with a message
/// holding `fragment`.
pub fn assert_refused_at(text: &str, needle: &str, fragment: &str) {
    let line = text
        .lines()
        .position(|l| l == needle)
        .map(|i| i + 1)
        .expect("line in deck");
    let err = read_deck_text(text).expect_err(fragment);
    assert!(
        err.contains(&format!("deck.inp:{line}")) && err.contains(fragment),
        "expected line {line} and '{fragment}', got: {err}"
    );
}
