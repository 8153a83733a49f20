//! The workspace's modules depend one way: within each crate, the graph of its top-level
//! modules (an edge `a -> b` where code of `a`, outside comments and its `#[cfg(test)]`
//! module, names `crate::b`) has no cycle.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Every `.rs` file under `dir`.
fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("read source dir") {
        let path = entry.expect("entry").path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The top-level module a source file belongs to (`None` for the crate root).
fn module_of(src: &Path, file: &Path) -> Option<String> {
    let relative = file.strip_prefix(src).expect("under src");
    let first = relative.components().next()?.as_os_str().to_string_lossy();
    let name = first.trim_end_matches(".rs").to_string();
    (name != "lib" && name != "main").then_some(name)
}

/// The code of `text` without line comments and without the `#[cfg(test)]` module at its end.
fn code(text: &str) -> String {
    let text = text
        .find("#[cfg(test)]\nmod tests")
        .map_or(text, |k| &text[..k]);
    text.lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The names `m` such that `text` mentions `crate::m` or `use crate::{..., m::...}`.
fn mentioned(text: &str, modules: &BTreeSet<String>) -> BTreeSet<String> {
    let mut found = BTreeSet::new();
    let words = |s: &str| -> Vec<String> {
        s.split(|c: char| !(c.is_alphanumeric() || c == '_'))
            .filter(|w| !w.is_empty())
            .map(str::to_string)
            .collect()
    };
    for (k, _) in text.match_indices("crate::") {
        let rest = &text[k + "crate::".len()..];
        if let Some(inner) = rest.strip_prefix('{') {
            let group = &inner[..inner.find('}').unwrap_or(inner.len())];
            found.extend(words(group).into_iter().filter(|w| modules.contains(w)));
        } else if let Some(first) = words(rest).into_iter().next()
            && modules.contains(&first)
        {
            found.insert(first);
        }
    }
    found
}

/// The module graph of the crate at `dir`.
fn graph(dir: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let src = dir.join("src");
    let mut files = Vec::new();
    sources(&src, &mut files);
    let modules: BTreeSet<String> = files.iter().filter_map(|f| module_of(&src, f)).collect();
    let mut edges: BTreeMap<String, BTreeSet<String>> = modules
        .iter()
        .map(|m| (m.clone(), BTreeSet::new()))
        .collect();
    for file in &files {
        let Some(module) = module_of(&src, file) else {
            continue;
        };
        let text = std::fs::read_to_string(file).expect("read source");
        let targets = mentioned(&code(&text), &modules);
        let entry = edges.get_mut(&module).expect("module");
        entry.extend(targets.into_iter().filter(|t| *t != module));
    }
    edges
}

/// A cycle of `edges`, if there is one, as the modules along it.
fn cycle(edges: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    #[derive(Clone, Copy, PartialEq)]
    enum Mark {
        New,
        Open,
        Done,
    }
    fn visit(
        m: &str,
        edges: &BTreeMap<String, BTreeSet<String>>,
        marks: &mut BTreeMap<String, Mark>,
        path: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        marks.insert(m.to_string(), Mark::Open);
        path.push(m.to_string());
        for next in &edges[m] {
            match marks[next] {
                Mark::Open => {
                    let start = path.iter().position(|p| p == next).expect("on path");
                    let mut found = path[start..].to_vec();
                    found.push(next.clone());
                    return Some(found);
                }
                Mark::New => {
                    if let Some(found) = visit(next, edges, marks, path) {
                        return Some(found);
                    }
                }
                Mark::Done => {}
            }
        }
        path.pop();
        marks.insert(m.to_string(), Mark::Done);
        None
    }
    let mut marks: BTreeMap<String, Mark> = edges.keys().map(|k| (k.clone(), Mark::New)).collect();
    for m in edges.keys() {
        if marks[m] == Mark::New
            && let Some(found) = visit(m, edges, &mut marks, &mut Vec::new())
        {
            return Some(found);
        }
    }
    None
}

#[test]
fn no_crate_has_a_module_cycle() {
    let crates = workspace().join("crates");
    let mut checked = 0;
    for entry in std::fs::read_dir(&crates).expect("crates") {
        let dir = entry.expect("entry").path();
        let name = dir.file_name().expect("name").to_string_lossy().to_string();
        let found = cycle(&graph(&dir));
        assert!(
            found.is_none(),
            "{name} has a module cycle: {}",
            found.unwrap_or_default().join(" -> ")
        );
        checked += 1;
    }
    assert!(checked >= 5, "found {checked} crates");
}

/// The check finds a cycle where there is one, and only there.
#[test]
fn a_cycle_is_found_and_a_chain_is_not() {
    let modules: BTreeSet<String> = ["a", "b", "c"].iter().map(|s| s.to_string()).collect();
    let text = "use crate::{b::X, c};\n// crate::a in a comment\nfn f() { crate::b::g(); }";
    let found = mentioned(&code(text), &modules);
    assert_eq!(found, ["b", "c"].iter().map(|s| s.to_string()).collect());

    let edges = |pairs: &[(&str, &str)]| {
        let mut e: BTreeMap<String, BTreeSet<String>> = modules
            .iter()
            .map(|m| (m.clone(), BTreeSet::new()))
            .collect();
        for (a, b) in pairs {
            e.get_mut(*a).expect("module").insert(b.to_string());
        }
        e
    };
    assert_eq!(cycle(&edges(&[("a", "b"), ("b", "c")])), None);
    assert_eq!(
        cycle(&edges(&[("a", "b"), ("b", "c"), ("c", "a")])),
        Some(vec!["a".into(), "b".into(), "c".into(), "a".into()])
    );
    let tests_only = "fn f() {}\n#[cfg(test)]\nmod tests {\n    use crate::a;\n}\n";
    assert!(mentioned(&code(tests_only), &modules).is_empty());
}
