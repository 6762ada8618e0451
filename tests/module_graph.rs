//! The module graph of every crate is acyclic: a lower concept never imports a higher one.
//!
//! For each crate under `crates/`, every top-level module (`src/name.rs` or `src/name/`) is a
//! node, and every path `crate::name...` in its code (a `use` or an inline path; comments, the
//! `#[cfg(test)]` module at the end of a file and test modules in files of their own, named
//! `tests.rs` or `*_tests.rs`, excluded) is an edge to module `name`, or to
//! the module an item re-exported at the crate root (`pub use name::{Item}` in `lib.rs`) comes
//! from. The test fails on any cycle among those edges, naming it, unless it is listed in
//! [`KNOWN_CYCLES`]; it also fails when a listed cycle no longer exists, so that the list
//! shrinks as the cycles are broken.
//!
//! Inside `afm`, a module names an item by the module that defines it: no path through the
//! crate root's re-exports (`crate::TappingModel`), so that the imports show which concept
//! builds on which.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

/// Cycles known to remain, as `(crate, modules in the order the test reports them)`, each to
/// be broken by moving the shared piece to the lower concept (issue 22), then removed here.
const KNOWN_CYCLES: &[(&str, &[&str])] = &[];

/// The Rust files under `dir`, recursively, sorted.
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    let mut entries: Vec<PathBuf> = fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("read {}: {e}", dir.display()))
        .map(|entry| entry.expect("directory entry").path())
        .collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            files.extend(rust_files(&path));
        } else if path.extension().is_some_and(|e| e == "rs") {
            files.push(path);
        }
    }
    files
}

/// The code of a source file: without comment lines and trailing comments, and without the
/// `#[cfg(test)]` module that ends it.
fn code_of(text: &str) -> String {
    let mut code = String::new();
    let lines: Vec<&str> = text.lines().collect();
    for (i, line) in lines.iter().enumerate() {
        let trimmed = line.trim_start();
        let next = lines.get(i + 1).map_or("", |l| l.trim_start());
        if trimmed.starts_with("#[cfg(test)]") && next.starts_with("mod ") {
            break;
        }
        if trimmed.starts_with("//") {
            continue;
        }
        let without_comment = match line.find("//") {
            Some(at) if !line[..at].contains('"') => &line[..at],
            _ => line,
        };
        code.push_str(without_comment);
        code.push('\n');
    }
    code
}

/// The leading identifier of `text` (after whitespace).
fn identifier(text: &str) -> String {
    text.trim_start()
        .chars()
        .take_while(|c| c.is_alphanumeric() || *c == '_')
        .collect()
}

/// The first path segment after every `crate::` in `code` (for a group `crate::{a, b::c}`,
/// `a` and `b`).
fn crate_paths(code: &str) -> Vec<String> {
    let mut names = Vec::new();
    let mut rest = code;
    while let Some(at) = rest.find("crate::") {
        let preceded = rest[..at].chars().next_back();
        let after = &rest[at + "crate::".len()..];
        rest = after;
        if preceded.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == '$') {
            continue;
        }
        if let Some(group) = after.strip_prefix('{') {
            let mut depth = 0;
            let mut start = 0;
            for (i, c) in group.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => {
                        names.push(identifier(&group[start..i]));
                        break;
                    }
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        names.push(identifier(&group[start..i]));
                        start = i + 1;
                    }
                    _ => {}
                }
            }
        } else {
            names.push(identifier(after));
        }
    }
    names.retain(|name| !name.is_empty() && name != "self");
    names
}

/// The module of each item the crate root re-exports (`pub use module::{Item, ...}`).
fn root_exports(root: &str, modules: &BTreeSet<String>) -> BTreeMap<String, String> {
    let mut exports = BTreeMap::new();
    let code = code_of(root);
    for statement in code.split(';') {
        let statement = statement.trim();
        let Some(path) = statement.strip_prefix("pub use ") else {
            continue;
        };
        let module = identifier(path);
        if !modules.contains(&module) {
            continue;
        }
        let items = match path.find('{') {
            Some(open) => path[open + 1..].trim_end_matches('}').to_string(),
            None => path.rsplit("::").next().unwrap_or("").to_string(),
        };
        for item in items.split(',') {
            let item = item.trim();
            let name = item.rsplit(" as ").next().unwrap_or(item);
            let name = identifier(name.rsplit("::").next().unwrap_or(name));
            if !name.is_empty() {
                exports.insert(name, module.clone());
            }
        }
    }
    exports
}

/// The module graph of the crate whose sources are in `src`: module -> modules it imports.
fn module_graph(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let mut sources: BTreeMap<String, Vec<PathBuf>> = BTreeMap::new();
    let mut root = String::new();
    for file in rust_files(src) {
        if file
            .file_name()
            .is_some_and(|name| name.to_string_lossy().ends_with("tests.rs"))
        {
            continue;
        }
        let relative = file.strip_prefix(src).expect("under src");
        let first = relative
            .components()
            .next()
            .expect("a path")
            .as_os_str()
            .to_string_lossy()
            .to_string();
        if first == "lib.rs" || first == "main.rs" {
            root.push_str(&fs::read_to_string(&file).expect("readable source"));
            continue;
        }
        if first == "bin" {
            continue;
        }
        let module = first.trim_end_matches(".rs").to_string();
        sources.entry(module).or_default().push(file);
    }
    let modules: BTreeSet<String> = sources.keys().cloned().collect();
    let exports = root_exports(&root, &modules);
    let mut graph = BTreeMap::new();
    for (module, files) in &sources {
        let mut targets = BTreeSet::new();
        for file in files {
            let text = fs::read_to_string(file).expect("readable source");
            for name in crate_paths(&code_of(&text)) {
                let target = if modules.contains(&name) {
                    Some(name)
                } else {
                    exports.get(&name).cloned()
                };
                if let Some(target) = target.filter(|t| t != module) {
                    targets.insert(target);
                }
            }
        }
        graph.insert(module.clone(), targets);
    }
    graph
}

/// The strongly connected components of `graph` with more than one module (its cycles), each
/// sorted, in sorted order (Tarjan's algorithm).
fn cycles(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    struct Search<'g> {
        graph: &'g BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<&'g str, usize>,
        low: BTreeMap<&'g str, usize>,
        stack: Vec<&'g str>,
        on_stack: BTreeSet<&'g str>,
        components: Vec<Vec<String>>,
    }
    impl<'g> Search<'g> {
        fn visit(&mut self, node: &'g str) {
            let index = self.index.len();
            self.index.insert(node, index);
            self.low.insert(node, index);
            self.stack.push(node);
            self.on_stack.insert(node);
            for next in self.graph.get(node).into_iter().flatten() {
                let next = next.as_str();
                if !self.index.contains_key(next) {
                    self.visit(next);
                    let low = self.low[node].min(self.low[next]);
                    self.low.insert(node, low);
                } else if self.on_stack.contains(next) {
                    let low = self.low[node].min(self.index[next]);
                    self.low.insert(node, low);
                }
            }
            if self.low[node] == self.index[node] {
                let mut component = Vec::new();
                while let Some(top) = self.stack.pop() {
                    self.on_stack.remove(top);
                    component.push(top.to_string());
                    if top == node {
                        break;
                    }
                }
                if component.len() > 1 {
                    component.sort();
                    self.components.push(component);
                }
            }
        }
    }
    let mut search = Search {
        graph,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        components: Vec::new(),
    };
    for node in graph.keys() {
        if !search.index.contains_key(node.as_str()) {
            search.visit(node);
        }
    }
    search.components.sort();
    search.components
}

#[test]
fn the_cycle_finder_sees_a_planted_cycle_and_a_grouped_import() {
    let paths = crate_paths("use crate::{a::{b, c}, d};\nlet x = crate::e::f();\n$crate::g");
    assert_eq!(paths, ["a", "d", "e"]);
    let graph: BTreeMap<String, BTreeSet<String>> = [
        ("a", &["b"][..]),
        ("b", &["c"][..]),
        ("c", &["a"][..]),
        ("d", &["a"][..]),
    ]
    .into_iter()
    .map(|(m, t)| (m.to_string(), t.iter().map(|s| s.to_string()).collect()))
    .collect();
    assert_eq!(cycles(&graph), [["a", "b", "c"]]);
}

#[test]
fn every_crate_has_an_acyclic_module_graph() {
    let crates = Path::new(env!("CARGO_MANIFEST_DIR")).join("crates");
    let mut found = Vec::new();
    let mut names: Vec<PathBuf> = fs::read_dir(&crates)
        .expect("crates/")
        .map(|entry| entry.expect("directory entry").path())
        .collect();
    names.sort();
    for dir in names {
        let src = dir.join("src");
        if !src.is_dir() {
            continue;
        }
        let name = dir.file_name().expect("name").to_string_lossy().to_string();
        for cycle in cycles(&module_graph(&src)) {
            found.push((name.clone(), cycle));
        }
    }
    let known: Vec<(String, Vec<String>)> = KNOWN_CYCLES
        .iter()
        .map(|(c, m)| (c.to_string(), m.iter().map(|s| s.to_string()).collect()))
        .collect();
    let new: Vec<_> = found.iter().filter(|c| !known.contains(c)).collect();
    let gone: Vec<_> = known.iter().filter(|c| !found.contains(c)).collect();
    assert!(
        new.is_empty(),
        "import cycles (crate, modules): {new:?}; move the shared piece to the lower module"
    );
    assert!(
        gone.is_empty(),
        "these cycles are broken: remove them from KNOWN_CYCLES: {gone:?}"
    );
}

#[test]
fn afm_imports_no_name_through_the_crate_root() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("crates/afm/src");
    let root = fs::read_to_string(src.join("lib.rs")).expect("lib.rs");
    let modules: BTreeSet<String> = fs::read_dir(&src)
        .expect("afm/src")
        .map(|entry| entry.expect("directory entry").path())
        .filter_map(|path| {
            let stem = path.file_stem()?.to_string_lossy().to_string();
            (stem != "lib").then_some(stem)
        })
        .collect();
    let exports = root_exports(&root, &modules);
    assert!(!exports.is_empty(), "lib.rs re-exports the public API");
    let mut through_root = Vec::new();
    for file in rust_files(&src) {
        if file.file_name().is_some_and(|name| name == "lib.rs") {
            continue;
        }
        let text = fs::read_to_string(&file).expect("readable source");
        for name in crate_paths(&code_of(&text)) {
            if exports.contains_key(&name) && !modules.contains(&name) {
                through_root.push(format!("{}: crate::{name}", file.display()));
            }
        }
    }
    assert!(
        through_root.is_empty(),
        "import these from the module that defines them: {through_root:#?}"
    );
}
