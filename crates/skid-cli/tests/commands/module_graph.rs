//! The workspace's modules depend one way: within each crate, at every level, the graph of the
//! sub-modules of one module (an edge `a -> b` where code under `a`, outside comments and its
//! `#[cfg(test)]` module, names something under `b` by a `crate::`, `super::` or `self::`
//! path) has no cycle. A module and its own parent or children are not siblings: a parent
//! declares and re-exports its children, and they use its shared items.

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

/// The module path of a source file (`[]` for the crate root): `deck/loads.rs` is
/// `[deck, loads]`, `deck.rs` and `deck/mod.rs` are `[deck]`.
fn module_of(src: &Path, file: &Path) -> Vec<String> {
    let relative = file.strip_prefix(src).expect("under src");
    let mut path: Vec<String> = relative
        .components()
        .map(|c| {
            c.as_os_str()
                .to_string_lossy()
                .trim_end_matches(".rs")
                .to_string()
        })
        .collect();
    if path.last().is_some_and(|last| last == "mod") {
        path.pop();
    }
    if path.len() == 1 && (path[0] == "lib" || path[0] == "main") {
        path.clear();
    }
    path
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

/// The identifiers of `s`, in order (`::` and other punctuation separate them).
fn words(s: &str) -> Vec<&str> {
    s.split(|c: char| !(c.is_alphanumeric() || c == '_'))
        .filter(|w| !w.is_empty())
        .collect()
}

/// The absolute module paths that the code `text` of the module `module` names through
/// `crate::`, `super::` or `self::` paths, `use` groups (`crate::{a::X, b}`) included; each is
/// the path's leading words, which name modules and then items (the items are cut off by
/// [`sibling_edge`], which only looks at the modules of the graph).
fn mentioned(text: &str, module: &[String]) -> BTreeSet<Vec<String>> {
    let mut found = BTreeSet::new();
    let mut k = 0;
    while let Some(at) = text[k..].find(['c', 's']).map(|i| k + i) {
        k = at + 1;
        if at > 0 && text[..at].ends_with(|c: char| c.is_alphanumeric() || c == '_') {
            continue;
        }
        let rest = &text[at..];
        let mut base: Vec<String> = if let Some(r) = rest.strip_prefix("crate::") {
            k = at + (rest.len() - r.len());
            Vec::new()
        } else if rest.starts_with("super::") || rest.starts_with("self::") {
            let mut base = module.to_vec();
            let mut r = rest;
            loop {
                if let Some(next) = r.strip_prefix("super::") {
                    base.pop();
                    r = next;
                } else if let Some(next) = r.strip_prefix("self::") {
                    r = next;
                } else {
                    break;
                }
            }
            k = at + (rest.len() - r.len());
            base
        } else {
            continue;
        };
        let r = &text[k..];
        // `a::b::{c, d::e}`: the prefix, then each member of the group
        let end = r
            .find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':' || c == '{'))
            .unwrap_or(r.len());
        let head = &r[..end];
        match head.find('{') {
            Some(brace) => {
                base.extend(words(&head[..brace]).into_iter().map(str::to_string));
                let inner = &r[brace + 1..];
                let group = &inner[..inner.find('}').unwrap_or(inner.len())];
                for member in group.split(',') {
                    let mut path = base.clone();
                    path.extend(words(member).into_iter().map(str::to_string));
                    found.insert(path);
                }
            }
            None => {
                base.extend(words(head).into_iter().map(str::to_string));
                found.insert(base);
            }
        }
    }
    found
}

/// The edge that code of `from` naming `to` puts between two sibling modules: the children of
/// their deepest common ancestor that lead to each, keyed by that ancestor; `None` when one
/// path holds the other (a module and its parent or child), or when `to` names no module
/// under that ancestor (an item of it, or another crate's path).
fn sibling_edge(
    from: &[String],
    to: &[String],
    modules: &BTreeSet<Vec<String>>,
) -> Option<(Vec<String>, String, String)> {
    let common = from.iter().zip(to).take_while(|(a, b)| a == b).count();
    if common >= from.len() || common >= to.len() {
        return None;
    }
    let child = to[..=common].to_vec();
    modules.contains(&child).then(|| {
        (
            from[..common].to_vec(),
            from[common].clone(),
            to[common].clone(),
        )
    })
}

/// The module graphs of the crate at `dir`: for every module with sub-modules (the crate root
/// included), the edges `a -> b` between its children where code under `a`, outside comments
/// and its `#[cfg(test)]` module, names something under `b`.
fn graphs(dir: &Path) -> BTreeMap<Vec<String>, BTreeMap<String, BTreeSet<String>>> {
    let src = dir.join("src");
    let mut files = Vec::new();
    sources(&src, &mut files);
    let modules: BTreeSet<Vec<String>> = files.iter().map(|f| module_of(&src, f)).collect();
    let mut graphs: BTreeMap<Vec<String>, BTreeMap<String, BTreeSet<String>>> = BTreeMap::new();
    for m in modules.iter().filter(|m| !m.is_empty()) {
        let (parent, name) = m.split_at(m.len() - 1);
        graphs
            .entry(parent.to_vec())
            .or_default()
            .insert(name[0].clone(), BTreeSet::new());
    }
    for file in &files {
        let module = module_of(&src, file);
        let text = std::fs::read_to_string(file).expect("read source");
        for target in mentioned(&code(&text), &module) {
            if let Some((parent, a, b)) = sibling_edge(&module, &target, &modules) {
                let graph = graphs.get_mut(&parent).expect("parent of a module");
                graph.get_mut(&a).expect("module").insert(b);
            }
        }
    }
    graphs
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
    let (mut checked, mut levels, mut cycles) = (0, 0, Vec::new());
    for entry in std::fs::read_dir(&crates).expect("crates") {
        let dir = entry.expect("entry").path();
        let name = dir.file_name().expect("name").to_string_lossy().to_string();
        for (parent, graph) in graphs(&dir) {
            if let Some(found) = cycle(&graph) {
                cycles.push(format!(
                    "{name}, under `crate::{}`: {}",
                    parent.join("::"),
                    found.join(" -> ")
                ));
            }
            levels += 1;
        }
        checked += 1;
    }
    assert!(cycles.is_empty(), "module cycles: {}", cycles.join("; "));
    assert!(checked >= 5, "found {checked} crates");
    assert!(levels > checked, "found no sub-modules: {levels} levels");
}

/// The check finds a cycle where there is one, and only there.
#[test]
fn a_cycle_is_found_and_a_chain_is_not() {
    let path = |s: &str| -> Vec<String> {
        s.split("::")
            .filter(|w| !w.is_empty())
            .map(str::to_string)
            .collect()
    };
    let text = "use crate::{b::X, c};\n// crate::a in a comment\nfn f() { crate::b::g(); }\n\
                use super::{read::Y, loads};\nfn g() { super::super::top::h(); self::inner::k() }";
    let found = mentioned(&code(text), &path("deck::write"));
    let expected: BTreeSet<Vec<String>> = [
        "b::X",
        "c",
        "b::g",
        "deck::read::Y",
        "deck::loads",
        "top::h",
        "deck::write::inner::k",
    ]
    .iter()
    .map(|s| path(s))
    .collect();
    assert_eq!(found, expected);

    let modules: BTreeSet<Vec<String>> = ["deck", "deck::read", "deck::loads", "report"]
        .iter()
        .map(|s| path(s))
        .collect();
    assert_eq!(
        sibling_edge(&path("deck::read"), &path("deck::loads::f"), &modules),
        Some((path("deck"), "read".into(), "loads".into()))
    );
    assert_eq!(
        sibling_edge(&path("deck::read"), &path("report::Item"), &modules),
        Some((Vec::new(), "deck".into(), "report".into()))
    );
    // a child using its parent's items, a parent its child's, an item of the parent: no edge
    assert_eq!(
        sibling_edge(&path("deck::read"), &path("deck::Deck"), &modules),
        None
    );
    assert_eq!(
        sibling_edge(&path("deck"), &path("deck::read::f"), &modules),
        None
    );
    assert_eq!(
        sibling_edge(&path("deck::read"), &path("deck"), &modules),
        None
    );

    let names: BTreeSet<String> = ["a", "b", "c"].iter().map(|s| s.to_string()).collect();
    let edges = |pairs: &[(&str, &str)]| {
        let mut e: BTreeMap<String, BTreeSet<String>> =
            names.iter().map(|m| (m.clone(), BTreeSet::new())).collect();
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
    assert!(mentioned(&code(tests_only), &path("x")).is_empty());
}
