//! The library's top-level modules import each other without cycles (ARCHITECTURE.md
//! draws the graph). Read from the sources: every `crate::m` path outside comments
//! and test code counts as an edge to `m`.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// The source without comment lines and without test code: a file's inline
/// `#[cfg(test)] mod` ends it, and test files (`tests.rs`, `tests_*.rs`, `*_tests.rs`, and
/// everything in a `tests/` folder) are skipped by the caller.
fn production_code(text: &str) -> String {
    // An inline test module (`#[cfg(test)] mod tests {`) runs to the end of the
    // file by convention; a declaration (`mod tests;`) is only skipped.
    let end = text
        .match_indices("#[cfg(test)]\nmod ")
        .find(|(i, _)| {
            let line = text[*i..].lines().nth(1).unwrap_or("");
            line.trim_end().ends_with('{')
        })
        .map_or(text.len(), |(i, _)| i);
    text[..end]
        .lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n")
}

fn edges(dir: &Path, modules: &BTreeSet<String>, own: &str, out: &mut BTreeSet<String>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy();
        if path.is_dir() {
            if name != "tests" {
                edges(&path, modules, own, out);
            }
            continue;
        }
        if !name.ends_with(".rs")
            || name == "tests.rs"
            || name.starts_with("tests_")
            || name.ends_with("_tests.rs")
        {
            continue;
        }
        let code = production_code(&std::fs::read_to_string(&path).unwrap());
        for (i, _) in code.match_indices("crate::") {
            let rest = &code[i + "crate::".len()..];
            let m: String = rest
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            if modules.contains(&m) && m != own {
                out.insert(m);
            }
        }
    }
}

fn graph() -> BTreeMap<String, BTreeSet<String>> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let modules: BTreeSet<String> = std::fs::read_dir(&src)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    modules
        .iter()
        .map(|m| {
            let mut out = BTreeSet::new();
            edges(&src.join(m), &modules, m, &mut out);
            (m.clone(), out)
        })
        .collect()
}

/// The first cycle found by depth-first search, as a path that returns to its start.
fn cycle(g: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        g: &BTreeMap<String, BTreeSet<String>>,
        n: &str,
        stack: &mut Vec<String>,
        done: &mut BTreeSet<String>,
    ) -> Option<Vec<String>> {
        if let Some(i) = stack.iter().position(|s| s == n) {
            let mut c = stack[i..].to_vec();
            c.push(n.to_owned());
            return Some(c);
        }
        if done.contains(n) {
            return None;
        }
        stack.push(n.to_owned());
        for m in &g[n] {
            if let Some(c) = visit(g, m, stack, done) {
                return Some(c);
            }
        }
        stack.pop();
        done.insert(n.to_owned());
        None
    }
    let mut done = BTreeSet::new();
    g.keys()
        .find_map(|n| visit(g, n, &mut Vec::new(), &mut done))
}

#[test]
fn the_module_graph_has_no_cycles() {
    let g = graph();
    assert!(g.len() >= 10, "modules found: {g:?}");
    assert!(
        g["model"].contains("linear"),
        "the reader sees edges: {g:?}"
    );
    assert_eq!(cycle(&g), None, "graph: {g:#?}");
    if std::env::var_os("TESSERAL_PRINT_GRAPH").is_some() {
        for (m, to) in &g {
            println!("{m} -> {to:?}");
        }
    }
}

#[test]
fn the_cycle_finder_finds_cycles() {
    let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (a, b) in [("a", "b"), ("b", "c"), ("c", "a"), ("d", "a")] {
        g.entry(a.into()).or_default().insert(b.into());
        g.entry(b.into()).or_default();
    }
    let c = cycle(&g).expect("a → b → c → a");
    assert_eq!(c.first(), c.last());
    assert_eq!(c.len(), 4);
}
