//! Property tests over everything that reads user input: the case-file parser and validator
//! (with the drum model built from what they accept), the `--set` overrides, the deck keyword
//! reader and the model-file parser (with the scene built from what it accepts).
//!
//! The inputs are the shipped files (`cases/drum`, `cases/hard`, `cases/bad`,
//! `cases/verification`) mutated at random: bytes flipped, inserted, deleted, truncated;
//! fields deleted, retyped, set to huge, tiny, negative or non-finite numbers; arrays emptied or
//! repeated; unknown keys added. The property, for every input: the reader returns, without a
//! panic, within [`TIME_LIMIT`] and without the process's peak memory passing [`MEMORY_LIMIT`],
//! either a value or a typed error whose message is not empty.
//!
//! Each target runs 64 cases by default; `PROPTEST_CASES` sets another count (see
//! `scripts/fuzz.sh` for long campaigns). A failing input's seed is kept in
//! `proptest-regressions/fuzz_inputs/<target>.txt` and replayed first by every later run.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use proptest::prelude::*;
use proptest::test_runner::{Config, FileFailurePersistence, TestCaseError, TestRunner};
use serde_json::Value;
use skid_cases::deck::keywords::{DeckError, parse_text, read_deck};
use skid_cases::model_file::{build, parse_model};
use skid_cases::validate::memory;
use skid_cases::{CaseError, drum, parse_case};

/// Longest time one input may take to be read, validated and (if small) built.
const TIME_LIMIT: Duration = Duration::from_secs(30);

/// Largest peak resident memory of the test process (`VmHWM`, reset before each input) allowed
/// while it reads one input.
const MEMORY_LIMIT: u64 = 2_000_000_000;

/// Accepted cases whose memory estimate is below this are also built into their model.
const BUILD_LIMIT: f64 = 16e6;

/// Cases per target when `PROPTEST_CASES` is not set.
const DEFAULT_CASES: u32 = 64;

fn repository() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The `*.json` files of the `cases/` subdirectories `dirs`, as (file, text).
fn seeds(dirs: &[&str]) -> Vec<(PathBuf, String)> {
    let mut files = Vec::new();
    for dir in dirs {
        let dir = repository().join("cases").join(dir);
        let mut listed: Vec<PathBuf> = std::fs::read_dir(&dir)
            .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
            .map(|entry| entry.expect("entry").path())
            .filter(|p| p.extension().is_some_and(|e| e == "json"))
            .collect();
        listed.sort();
        for path in listed {
            // Some entries of the bad-input corpus are deliberately not UTF-8.
            let text = String::from_utf8_lossy(&std::fs::read(&path).expect("read")).into_owned();
            // sweep files name a base and overrides: their base is a seed of its own
            if !skid_cases::sweep::declares_sweep(&text) {
                files.push((path, text));
            }
        }
    }
    assert!(!files.is_empty(), "no seed files in {dirs:?}");
    files
}

/// Runs `property` on `cases` inputs of `strategy` (`PROPTEST_CASES`, else [`DEFAULT_CASES`]),
/// failures kept in `regressions`, and checks time and memory after each input; prints the
/// count of inputs tried (shrinking included) for `scripts/fuzz.sh`.
fn fuzz<S: Strategy>(
    target: &str,
    regressions: &'static str,
    strategy: S,
    property: impl Fn(S::Value) -> Result<(), TestCaseError>,
) where
    S::Value: std::fmt::Debug,
{
    let mut config = Config::default();
    if std::env::var_os("PROPTEST_CASES").is_none() {
        config.cases = DEFAULT_CASES;
    }
    config.failure_persistence = Some(Box::new(FileFailurePersistence::Direct(regressions)));
    let cases = config.cases;
    let tried = AtomicUsize::new(0);
    let started = Instant::now();
    let mut runner = TestRunner::new(config);
    let result = runner.run(&strategy, |input| {
        tried.fetch_add(1, Ordering::Relaxed);
        // where the peak cannot be reset it stays the largest so far (stricter)
        skid_cases::peak_memory::reset();
        let start = Instant::now();
        property(input)?;
        let elapsed = start.elapsed();
        prop_assert!(elapsed < TIME_LIMIT, "took {elapsed:?}");
        if let Some(peak) = skid_cases::peak_memory::read() {
            prop_assert!(peak < MEMORY_LIMIT, "peak memory {peak} B");
        }
        Ok(())
    });
    eprintln!(
        "fuzz {target}: cases {cases}, inputs tried {}, {:.1} s",
        tried.load(Ordering::Relaxed),
        started.elapsed().as_secs_f64()
    );
    if let Err(e) = result {
        panic!("{target}: {e}");
    }
}

// ---------------------------------------------------------------------------------------------
// Mutations of JSON text.

/// Raw JSON number tokens (and non-JSON ones) written in place of a value.
const RAW_VALUES: &[&str] = &[
    "1e999",
    "-1e999",
    "1e-400",
    "NaN",
    "Infinity",
    "-Infinity",
    "nan",
    "inf",
    "-0",
    "-0.0",
    "0",
    "-1",
    "1e308",
    "-1e308",
    "1.7976931348623157e308",
    "5e-324",
    "1e12",
    "1e300",
    "123456789012345678901234567890",
    "-123456789012345678901234567890",
    "18446744073709551615",
    "18446744073709551616",
    "9007199254740993",
    "4294967296",
    "0.5",
    "2.5",
    "1e-12",
    "1.0",
    "-1e-12",
    "null",
    "true",
    "false",
    "\"\"",
    "\"x\"",
    "\"1e-4\"",
    "\"nan\"",
    "\"a,b\\n\\\"c\\\"\"",
    "\"..\"",
    "\"\\u0000\"",
    "[]",
    "{}",
    "[1,2,3]",
    "[[]]",
    "{\"type\":\"x\"}",
    "[0,0]",
    "[0.0,0.0,0.0]",
];

/// Bytes inserted by a mutation.
const INSERTS: &[&[u8]] = &[
    b"{",
    b"}",
    b"[",
    b"]",
    b",",
    b":",
    b"\"",
    b"\\",
    b"-",
    b"e",
    b"9",
    b"\0",
    b"\xff",
    b"\xc3",
    b"\xe2\x80\xa8",
    b"//",
    b"/*",
    b" ",
    b"\n",
    b"\"\":",
    b"null",
    b"1e999",
];

/// One change to a JSON document; the `usize`s select a byte position, a value in document
/// order or an entry of a table, modulo its length.
#[derive(Clone, Debug)]
enum Mutation {
    FlipBit(usize, u8),
    SetByte(usize, u8),
    Insert(usize, usize),
    Delete(usize, u16),
    Truncate(usize),
    Repeat(usize, u16, u8),
    RemoveField(usize),
    SetRaw(usize, usize),
    Scale(usize, f64),
    AddOne(usize),
    SwapType(usize),
    EmptyContainer(usize),
    RepeatElement(usize, u16),
    UnknownKey(usize, u8),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let scales = prop_oneof![
        Just(-1.0),
        Just(0.0),
        Just(1e-9),
        Just(1e-3),
        Just(0.5),
        Just(2.0),
        Just(10.0),
        Just(1e3),
        Just(1e6),
        Just(1e9),
        Just(1e15),
        Just(1e300),
        Just(-1e300),
        any::<f64>(),
    ];
    prop_oneof![
        (any::<usize>(), 0u8..8).prop_map(|(p, b)| Mutation::FlipBit(p, b)),
        (any::<usize>(), any::<u8>()).prop_map(|(p, b)| Mutation::SetByte(p, b)),
        (any::<usize>(), any::<usize>()).prop_map(|(p, i)| Mutation::Insert(p, i)),
        (any::<usize>(), 1u16..200).prop_map(|(p, n)| Mutation::Delete(p, n)),
        any::<usize>().prop_map(Mutation::Truncate),
        (any::<usize>(), 1u16..64, 2u8..16).prop_map(|(p, n, k)| Mutation::Repeat(p, n, k)),
        any::<usize>().prop_map(Mutation::RemoveField),
        (any::<usize>(), any::<usize>()).prop_map(|(n, i)| Mutation::SetRaw(n, i)),
        (any::<usize>(), scales).prop_map(|(n, f)| Mutation::Scale(n, f)),
        any::<usize>().prop_map(Mutation::AddOne),
        any::<usize>().prop_map(Mutation::SwapType),
        any::<usize>().prop_map(Mutation::EmptyContainer),
        (any::<usize>(), 2u16..1000).prop_map(|(n, k)| Mutation::RepeatElement(n, k)),
        (any::<usize>(), any::<u8>()).prop_map(|(n, k)| Mutation::UnknownKey(n, k)),
    ]
}

/// The number of values of `value` (itself included), in document order.
fn count_values(value: &Value) -> usize {
    1 + match value {
        Value::Array(items) => items.iter().map(count_values).sum(),
        Value::Object(map) => map.values().map(count_values).sum(),
        _ => 0,
    }
}

/// The `index`-th value of `value` in document order (0: `value` itself).
fn nth_value(value: &mut Value, mut index: usize) -> Option<&mut Value> {
    if index == 0 {
        return Some(value);
    }
    index -= 1;
    let children: Vec<&mut Value> = match value {
        Value::Array(items) => items.iter_mut().collect(),
        Value::Object(map) => map.values_mut().collect(),
        _ => return None,
    };
    for child in children {
        let n = count_values(child);
        if index < n {
            return nth_value(child, index);
        }
        index -= n;
    }
    None
}

/// Placeholder written where a raw token goes, replaced after serializing.
const RAW_MARK: &str = "\u{1}raw\u{1}";

/// `text` parsed, `change` applied to its value number `selector` (modulo the count), written
/// back; `text` unchanged if it is not JSON.
fn on_value(text: &[u8], selector: usize, change: impl FnOnce(&mut Value)) -> Vec<u8> {
    let Ok(mut root) = serde_json::from_slice::<Value>(text) else {
        return text.to_vec();
    };
    let index = selector % count_values(&root);
    if let Some(node) = nth_value(&mut root, index) {
        change(node);
    }
    serde_json::to_vec_pretty(&root).unwrap_or_else(|_| text.to_vec())
}

/// `text` with `mutation` applied.
fn mutate(mut text: Vec<u8>, mutation: &Mutation) -> Vec<u8> {
    let at = |p: usize, len: usize| if len == 0 { 0 } else { p % len };
    match *mutation {
        Mutation::FlipBit(p, bit) => {
            if !text.is_empty() {
                let i = at(p, text.len());
                text[i] ^= 1 << bit;
            }
            text
        }
        Mutation::SetByte(p, byte) => {
            if !text.is_empty() {
                let i = at(p, text.len());
                text[i] = byte;
            }
            text
        }
        Mutation::Insert(p, i) => {
            let pos = at(p, text.len() + 1);
            let bytes = INSERTS[i % INSERTS.len()];
            text.splice(pos..pos, bytes.iter().copied());
            text
        }
        Mutation::Delete(p, n) => {
            let pos = at(p, text.len() + 1);
            let end = (pos + usize::from(n)).min(text.len());
            text.drain(pos..end);
            text
        }
        Mutation::Truncate(p) => {
            text.truncate(at(p, text.len() + 1));
            text
        }
        Mutation::Repeat(p, n, k) => {
            let pos = at(p, text.len() + 1);
            let end = (pos + usize::from(n)).min(text.len());
            let chunk: Vec<u8> = text[pos..end].to_vec();
            for _ in 1..k {
                text.splice(end..end, chunk.iter().copied());
            }
            text
        }
        Mutation::RemoveField(n) => on_value(&text, n, |node| match node {
            Value::Object(map) if !map.is_empty() => {
                let key = map.keys().nth(n % map.len()).cloned().unwrap_or_default();
                map.remove(&key);
            }
            Value::Array(items) if !items.is_empty() => {
                items.remove(n % items.len());
            }
            _ => {}
        }),
        Mutation::SetRaw(n, i) => {
            let raw = RAW_VALUES[i % RAW_VALUES.len()];
            let marked = on_value(&text, n, |node| *node = Value::String(RAW_MARK.into()));
            let marked = String::from_utf8_lossy(&marked).into_owned();
            let quoted = serde_json::to_string(RAW_MARK).unwrap_or_default();
            marked.replacen(&quoted, raw, 1).into_bytes()
        }
        Mutation::Scale(n, factor) => on_value(&text, n, |node| {
            if let Some(x) = node.as_f64() {
                let scaled = x * factor;
                *node = if node.is_u64() && (0.0..1.8e19).contains(&scaled) {
                    Value::from(scaled as u64)
                } else {
                    serde_json::Number::from_f64(scaled).map_or(Value::Null, Value::Number)
                };
            }
        }),
        Mutation::AddOne(n) => on_value(&text, n, |node| {
            if let Some(x) = node.as_u64() {
                *node = Value::from(x.wrapping_add(1));
            } else if let Some(x) = node.as_i64() {
                *node = Value::from(x.wrapping_sub(1));
            } else if let Some(x) = node.as_f64() {
                *node = serde_json::Number::from_f64(-x).map_or(Value::Null, Value::Number);
            }
        }),
        Mutation::SwapType(n) => on_value(&text, n, |node| {
            *node = match node.take() {
                Value::Number(x) => Value::String(x.to_string()),
                Value::String(s) => s
                    .parse::<f64>()
                    .ok()
                    .and_then(serde_json::Number::from_f64)
                    .map_or(Value::Array(vec![Value::String(s)]), Value::Number),
                Value::Bool(b) => Value::from(u8::from(b)),
                Value::Null => Value::Bool(false),
                Value::Array(items) => Value::Object(
                    items
                        .into_iter()
                        .enumerate()
                        .map(|(i, v)| (i.to_string(), v))
                        .collect(),
                ),
                Value::Object(map) => Value::Array(map.into_iter().map(|(_, v)| v).collect()),
            }
        }),
        Mutation::EmptyContainer(n) => on_value(&text, n, |node| match node {
            Value::Array(items) => items.clear(),
            Value::Object(map) => map.clear(),
            Value::String(s) => s.clear(),
            _ => {}
        }),
        Mutation::RepeatElement(n, k) => on_value(&text, n, |node| {
            if let Value::Array(items) = node
                && let Some(first) = items.first().cloned()
            {
                items.extend(std::iter::repeat_n(first, usize::from(k)));
            }
        }),
        Mutation::UnknownKey(n, k) => on_value(&text, n, |node| {
            if let Value::Object(map) = node {
                map.insert(format!("unknown_{k}"), Value::from(k));
            }
        }),
    }
}

/// A seed (by index, modulo the count) and the mutations applied to it in order.
fn mutated_seed() -> impl Strategy<Value = (usize, Vec<Mutation>)> {
    (any::<usize>(), prop::collection::vec(mutation(), 1..8))
}

fn apply_all(seed: &str, mutations: &[Mutation]) -> Vec<u8> {
    mutations.iter().fold(seed.as_bytes().to_vec(), mutate)
}

// ---------------------------------------------------------------------------------------------
// Checks of the outcomes.

/// A case error names its file and says what is wrong.
fn check_case_error(error: &CaseError, path: &Path) -> Result<(), TestCaseError> {
    let (message, detail) = match error {
        CaseError::Parse { field, message, .. } | CaseError::Invalid { field, message, .. } => {
            (message.as_str(), field.as_str())
        }
        // The override is quoted as given, which may be empty (`--set ''`).
        CaseError::Override { message, .. } => (message.as_str(), "--set"),
        CaseError::Model { message, .. } => (message.as_str(), "model"),
        other => {
            return Err(TestCaseError::fail(format!(
                "unexpected error kind: {other}"
            )));
        }
    };
    prop_assert!(!message.trim().is_empty(), "empty message: {error:?}");
    prop_assert!(!detail.is_empty(), "no field: {error:?}");
    let text = error.to_string();
    prop_assert!(
        text.starts_with(&path.display().to_string()),
        "does not name the file: {text}"
    );
    Ok(())
}

/// `text` as a case file with `overrides`: parsed and validated; if accepted and small, the
/// drum model is built too.
fn check_case_text(text: &str, path: &Path, overrides: &[String]) -> Result<(), TestCaseError> {
    match parse_case(text, path, overrides) {
        Ok(case) => {
            let bytes = memory::needed(&case);
            prop_assert!(
                bytes.is_finite() && bytes <= memory::available() as f64,
                "accepted a case of {bytes} B"
            );
            if bytes < BUILD_LIMIT {
                let built = match case.dimension {
                    2 => drum::build::<2>(&case).map(drop),
                    3 => drum::build::<3>(&case).map(drop),
                    d => return Err(TestCaseError::fail(format!("accepted dimension {d}"))),
                };
                if let Err(message) = built {
                    prop_assert!(!message.trim().is_empty(), "empty build message");
                }
            }
            Ok(())
        }
        Err(error) => check_case_error(&error, path),
    }
}

/// `text` as a model file with `overrides`: parsed; if accepted, the scene is built.
fn check_model_text(text: &str, path: &Path, overrides: &[String]) -> Result<(), TestCaseError> {
    match parse_model(text, path, overrides) {
        Ok(spec) => {
            let built = match spec.dimension {
                2 => build::<2>(&spec).map(drop),
                3 => build::<3>(&spec).map(drop),
                _ => return Ok(()),
            };
            if let Err(e) = built {
                prop_assert!(!e.message.trim().is_empty(), "empty message: {e:?}");
                prop_assert!(!e.field.is_empty(), "no field: {e:?}");
            }
            Ok(())
        }
        Err(error) => check_case_error(&error, path),
    }
}

// ---------------------------------------------------------------------------------------------
// Targets.

#[test]
fn case_files() {
    let seeds = seeds(&["drum", "hard", "bad"]);
    let dir = tempfile::tempdir().expect("tempdir");
    let file = dir.path().join("fuzzed.json");
    fuzz(
        "case_files",
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/proptest-regressions/fuzz_inputs/case_files.txt"
        ),
        mutated_seed(),
        |(seed, mutations)| {
            let (source, text) = &seeds[seed % seeds.len()];
            let bytes = apply_all(text, &mutations);
            match String::from_utf8(bytes) {
                Ok(text) => check_case_text(&text, source, &[]),
                Err(e) => {
                    // Not UTF-8: read from a file, the way `skid run` reads it.
                    std::fs::write(&file, e.as_bytes()).expect("write");
                    match skid_cases::load_case(&file, &[]) {
                        Ok(_) => Err(TestCaseError::fail("accepted text that is not UTF-8")),
                        Err(error) => check_case_error(&error, &file),
                    }
                }
            }
        },
    );
}

/// Parts of override field paths: the fields of the shipped files and some that are not.
const OVERRIDE_KEYS: &[&str] = &[
    "name",
    "description",
    "dimension",
    "drum",
    "radius",
    "width",
    "mass",
    "rotary_inertia",
    "omega0",
    "surface",
    "type",
    "pad",
    "length",
    "thickness",
    "elements",
    "circumferential",
    "radial",
    "axial",
    "density",
    "material",
    "c10",
    "c01",
    "d1",
    "back_plate",
    "pressure",
    "contact",
    "mu",
    "formulation",
    "search_distance",
    "steps",
    "increments",
    "hold",
    "duration",
    "dt",
    "alpha",
    "adaptive",
    "min_dt",
    "solver",
    "output",
    "field_interval",
    "expect",
    "skid_model",
    "part",
    "nodes",
    "section",
    "rigid_bodies",
    "moments_of_inertia",
    "products_of_inertia",
    "initial_angular_velocity",
    "boundary",
    "dofs",
    "boundaries",
    "contact_pairs",
    "",
    " ",
    "x",
    "[",
    "]",
    "[0]",
    "[1]",
    "[-1]",
    "[99999999999999999999]",
    "[a]",
    "][",
    "=",
    "é",
    "\0",
];

/// Override values: JSON, words, non-finite spellings, malformed JSON.
const OVERRIDE_VALUES: &[&str] = &[
    "1",
    "0",
    "-1",
    "1e-4",
    "1e999",
    "-1e999",
    "nan",
    "NaN",
    "inf",
    "-inf",
    "+inf",
    "infinity",
    " inf ",
    "1e308",
    "1e-320",
    "1e12",
    "4294967297",
    "18446744073709551616",
    "true",
    "null",
    "\"nan\"",
    "[]",
    "{}",
    "[1,2]",
    "[0.01,0.01,0.02]",
    "[1,1,3]",
    "[\"x\",\"y\"]",
    "{\"type\":\"analytic\"}",
    "{",
    "[",
    "\"",
    "",
    "=",
    "a=b",
    "drum",
    "analytic",
    "polynomial_n1",
    "dynamic",
    "static",
    "2d-analytic",
    "a,b",
    "a\nb",
    "..",
    "/",
    "-x",
];

/// One override: a field path of `parts` (each a key and optional indices) and a value.
fn override_spec() -> impl Strategy<Value = String> {
    let part = (
        any::<usize>(),
        prop::option::of(0usize..4),
        prop::option::of(any::<usize>()),
    )
        .prop_map(|(k, index, junk)| {
            let mut part = OVERRIDE_KEYS[k % OVERRIDE_KEYS.len()].to_string();
            if let Some(i) = index {
                part.push_str(&format!("[{i}]"));
            }
            if let Some(j) = junk {
                part.push_str(OVERRIDE_KEYS[j % OVERRIDE_KEYS.len()]);
            }
            part
        });
    let value = prop_oneof![
        4 => any::<usize>().prop_map(|i| OVERRIDE_VALUES[i % OVERRIDE_VALUES.len()].to_string()),
        1 => any::<f64>().prop_map(|x| x.to_string()),
        1 => ".{0,12}",
    ];
    let separator = prop_oneof![8 => Just("="), 1 => Just(""), 1 => Just("=="), 1 => Just(" = ")];
    (prop::collection::vec(part, 1..24), separator, value)
        .prop_map(|(parts, separator, value)| format!("{}{separator}{value}", parts.join(".")))
}

#[test]
fn overrides() {
    let cases = seeds(&["drum", "hard"]);
    let models = seeds(&["verification"]);
    fuzz(
        "overrides",
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/proptest-regressions/fuzz_inputs/overrides.txt"
        ),
        (
            any::<usize>(),
            any::<bool>(),
            prop::collection::vec(override_spec(), 1..5),
        ),
        |(seed, model, overrides)| {
            if model {
                let (source, text) = &models[seed % models.len()];
                check_model_text(text, source, &overrides)
            } else {
                let (source, text) = &cases[seed % cases.len()];
                check_case_text(text, source, &overrides)
            }
        },
    );
}

#[test]
fn model_files() {
    let seeds = seeds(&["verification"]);
    fuzz(
        "model_files",
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/proptest-regressions/fuzz_inputs/model_files.txt"
        ),
        mutated_seed(),
        |(seed, mutations)| {
            let (source, text) = &seeds[seed % seeds.len()];
            let bytes = apply_all(text, &mutations);
            let text = String::from_utf8_lossy(&bytes);
            check_model_text(&text, source, &[])
        },
    );
}

/// A deck in the style of the drum's: heading, nodes, elements, sets, a section, a material,
/// an include, contact and two steps.
const SEED_DECK: &str = "\
** braking drum, 2D
*HEADING
braking drum pad
*NODE, NSET=ALL
1, 0.0, 0.2
2, 0.01, 0.2
3, 0.01, 0.25
4, 0.0, 0.25
*ELEMENT, TYPE=CPE4R, ELSET=PAD
1, 1, 2, 3, 4
*NSET, NSET=BACK, GENERATE
3, 4, 1
*SOLID SECTION, ELSET=PAD, MATERIAL=RUBBER
1.0,
*MATERIAL, NAME=RUBBER
*HYPERELASTIC, POLYNOMIAL, N=1
0.552e6, 0.138e6, 0.145e-6
*DENSITY
1000.
*INCLUDE, INPUT=part.inp
*SURFACE INTERACTION,
  NAME=ROUGH
*FRICTION
0.15
*STEP, NAME=PRELOAD, NLGEOM
*STATIC
0.2, 1.0
*DSLOAD
BACK, P, 0.35e6
*END STEP
*STEP, NAME=SPIN-DOWN
*DYNAMIC, ALPHA=-0.3, NOHAF
1e-4, 0.15
*END STEP
";

/// Lines inserted into decks.
const DECK_LINES: &[&str] = &[
    "*",
    "**",
    "***",
    "* ",
    "*NODE",
    "*node, nset=a",
    "*ELEMENT, TYPE=C3D8R, ELSET=X",
    "*STEP,",
    "*STEP, NAME=",
    "*STEP, =X",
    "*STEP, ,, ,",
    "*INCLUDE",
    "*INCLUDE, INPUT",
    "*INCLUDE, INPUT=",
    "*INCLUDE, INPUT=part.inp",
    "*INCLUDE, INPUT=main.inp",
    "*INCLUDE, INPUT=missing.inp",
    "*INCLUDE, INPUT=.",
    "*INCLUDE, INPUT=/",
    "*INCLUDE, INPUT=part.inp\n1, 2",
    ",",
    ",,,,",
    "1,",
    "1, 2, 3,",
    "1e999, nan, -inf",
    "=",
    "a=b=c",
    " \t ",
    "",
    "\r",
    "\u{feff}*NODE",
    "\u{2028}",
    "é, ü",
];

/// One change to a deck: a line inserted, deleted, repeated or replaced, or a byte changed.
#[derive(Clone, Debug)]
enum DeckMutation {
    InsertLine(usize, usize),
    DeleteLine(usize),
    RepeatLine(usize, u16),
    ReplaceLine(usize, String),
    Bytes(Mutation),
}

fn deck_mutation() -> impl Strategy<Value = DeckMutation> {
    prop_oneof![
        3 => (any::<usize>(), any::<usize>()).prop_map(|(at, i)| DeckMutation::InsertLine(at, i)),
        1 => any::<usize>().prop_map(DeckMutation::DeleteLine),
        1 => (any::<usize>(), 1u16..2000).prop_map(|(at, k)| DeckMutation::RepeatLine(at, k)),
        2 => (any::<usize>(), "[*,= a-zA-Z0-9.\\-\t]{0,40}")
            .prop_map(|(at, s)| DeckMutation::ReplaceLine(at, s)),
        1 => (any::<usize>(), "\\PC{0,40}")
            .prop_map(|(at, s)| DeckMutation::ReplaceLine(at, s)),
        2 => mutation().prop_map(DeckMutation::Bytes),
    ]
}

fn mutate_deck(text: String, mutation: &DeckMutation) -> String {
    let mut lines: Vec<String> = text.split('\n').map(str::to_string).collect();
    let at = |p: usize, len: usize| if len == 0 { 0 } else { p % len };
    match mutation {
        DeckMutation::InsertLine(p, i) => {
            let pos = at(*p, lines.len() + 1);
            lines.insert(pos, DECK_LINES[i % DECK_LINES.len()].to_string());
        }
        DeckMutation::DeleteLine(p) => {
            if !lines.is_empty() {
                let pos = at(*p, lines.len());
                lines.remove(pos);
            }
        }
        DeckMutation::RepeatLine(p, k) => {
            if !lines.is_empty() {
                let pos = at(*p, lines.len());
                let line = lines[pos].clone();
                lines.splice(pos..pos, std::iter::repeat_n(line, usize::from(*k)));
            }
        }
        DeckMutation::ReplaceLine(p, s) => {
            if !lines.is_empty() {
                let pos = at(*p, lines.len());
                lines[pos].clone_from(s);
            }
        }
        DeckMutation::Bytes(m) => {
            let bytes = mutate(text.into_bytes(), m);
            return String::from_utf8_lossy(&bytes).into_owned();
        }
    }
    lines.join("\n")
}

/// A deck error names its file, a line of it (0: the file as a whole) and what is wrong.
fn check_deck_error(
    error: &DeckError,
    files: &[(&Path, usize)],
    fallback: &Path,
) -> Result<(), TestCaseError> {
    prop_assert!(!error.message.trim().is_empty(), "empty message: {error:?}");
    let lines = files
        .iter()
        .find(|(file, _)| *file == &*error.location.file)
        .map(|&(_, lines)| lines);
    match lines {
        Some(lines) => prop_assert!(
            error.location.line <= lines,
            "line {} of a {lines}-line file: {error}",
            error.location.line
        ),
        None => prop_assert!(
            error
                .location
                .file
                .starts_with(fallback.parent().unwrap_or(fallback)),
            "an error in an unknown file: {error}"
        ),
    }
    Ok(())
}

#[test]
fn deck_keywords() {
    let dir = tempfile::tempdir().expect("tempdir");
    let main = dir.path().join("main.inp");
    let part = dir.path().join("part.inp");
    fuzz(
        "deck_keywords",
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/proptest-regressions/fuzz_inputs/deck_keywords.txt"
        ),
        (
            prop::collection::vec(deck_mutation(), 1..10),
            prop::collection::vec(deck_mutation(), 0..4),
        ),
        |(main_changes, part_changes)| {
            let text = main_changes.iter().fold(SEED_DECK.to_string(), mutate_deck);
            let part_text = part_changes
                .iter()
                .fold("*NODE\n5, 0.0, 0.3\n".to_string(), mutate_deck);
            let lines = |t: &str| t.lines().count();
            let files = [
                (main.as_path(), lines(&text)),
                (part.as_path(), lines(&part_text)),
            ];
            match parse_text(&text, &main) {
                Ok(blocks) => {
                    for block in &blocks {
                        prop_assert!(!block.name.is_empty(), "empty keyword name");
                        prop_assert_eq!(block.name.to_uppercase(), block.name.clone());
                        prop_assert!(block.location.line >= 1 && block.location.line <= files[0].1);
                        for line in &block.data {
                            prop_assert!(line.location.line > block.location.line);
                        }
                    }
                }
                Err(error) => check_deck_error(&error, &files, &main)?,
            }
            // The same text as a file, with its includes (of itself, of a second file, of a
            // missing one) followed.
            std::fs::write(&main, &text).expect("write");
            std::fs::write(&part, &part_text).expect("write");
            if let Err(error) = read_deck(&main) {
                check_deck_error(&error, &files, &main)?;
            }
            Ok(())
        },
    );
}

#[test]
fn mutations_change_the_seeds_and_keep_them_readable_when_structural() {
    let text =
        std::fs::read_to_string(repository().join("cases/drum/2d-analytic.json")).expect("seed");
    let removed = mutate(text.clone().into_bytes(), &Mutation::RemoveField(0));
    assert_ne!(removed, text.as_bytes());
    assert!(serde_json::from_slice::<Value>(&removed).is_ok());
    let raw = String::from_utf8(mutate(text.clone().into_bytes(), &Mutation::SetRaw(3, 0)))
        .expect("utf8");
    assert!(raw.contains("1e999"), "{raw}");
    let case = check_case_text(&raw, Path::new("t.json"), &[]);
    assert!(case.is_ok(), "{case:?}");
    assert!(parse_case(&raw, Path::new("t.json"), &[]).is_err());
}

/// The shipped decks (the hand-written 2D one with its mesh inlined, the faceted 2D and 3D
/// ones) mutated and read into a model by the keyword subset's semantics, and the model built:
/// a model, or a deck error at a line of the file, or a model error naming a field.
#[test]
fn deck_models() {
    let inp = repository().join("cases/inp");
    let read = |name: &str| std::fs::read_to_string(inp.join(name)).expect("deck");
    let seeds = [
        read("2d-analytic-by-hand.inp").replace(
            "*include, input=2d-pad-mesh.inc\n",
            &read("2d-pad-mesh.inc"),
        ),
        read("2d-r2d2.inp"),
        read("3d-r3d4.inp"),
    ];
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("scene.inp");
    fuzz(
        "deck_models",
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/proptest-regressions/fuzz_inputs/deck_models.txt"
        ),
        (0..seeds.len(), prop::collection::vec(deck_mutation(), 1..6)),
        |(seed, changes)| {
            let text = changes.iter().fold(seeds[seed].clone(), mutate_deck);
            std::fs::write(&path, &text).expect("write");
            match skid_cases::deck::read_model(&path) {
                Ok(deck) => {
                    let spec = deck.model;
                    let built = match spec.dimension {
                        2 => build::<2>(&spec).map(drop),
                        _ => build::<3>(&spec).map(drop),
                    };
                    if let Err(e) = built {
                        prop_assert!(!e.message.trim().is_empty(), "empty message: {e:?}");
                    }
                }
                Err(error) => {
                    check_deck_error(&error, &[(path.as_path(), text.lines().count())], &path)?;
                }
            }
            Ok(())
        },
    );
}
