//! The house's rules that code can check (docs/design.md): no import circle among the files of
//! `host/src` or of `kernel/src`, no file over 600 lines in `host/src`, and at most two
//! `too_many_arguments` allowances in the kernel.
//!
//! The import graph is at file level: file A depends on file B when a `use` or a path in A's
//! code (`crate::`, `super::`, `self::`, or a child module's name) names an item B defines.
//! A name that a module only re-exports (`pub use x::Y` in a `mod.rs`) is followed to the file
//! that defines it, so a module that re-exports its children's items is not in a circle with
//! them; declaring a child module (`mod x;`) is not an import. Inline `#[cfg(test)] mod tests`
//! are left out (their `use super::*` is the file itself).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// file -> (file it imports -> the path that names it).
type Graph = BTreeMap<Vec<String>, BTreeMap<Vec<String>, String>>;

/// A crate's source files by module path (`["scene", "toml"]` for `scene/toml/mod.rs`).
struct CrateFiles {
    files: BTreeMap<Vec<String>, String>,
}

impl CrateFiles {
    fn read(src: &Path) -> CrateFiles {
        let mut files = BTreeMap::new();
        for p in rust_files(src) {
            let rel = p.strip_prefix(src).unwrap();
            let mut module: Vec<String> = rel
                .iter()
                .map(|s| s.to_str().unwrap().trim_end_matches(".rs").to_string())
                .collect();
            if matches!(
                module.last().map(String::as_str),
                Some("mod" | "lib" | "main")
            ) {
                module.pop();
            }
            let text = std::fs::read_to_string(&p).unwrap();
            files.insert(module, without_tests_and_comments(&text));
        }
        CrateFiles { files }
    }

    fn is_module(&self, m: &[String]) -> bool {
        self.files.contains_key(m)
    }

    /// The file (module path) that defines the item `path` names, seen from module `from`;
    /// None for paths outside the crate.
    fn resolve(&self, from: &[String], path: &[String], depth: u32) -> Option<Vec<String>> {
        let mut m: Vec<String> = match path.first().map(String::as_str) {
            Some("crate") => vec![],
            Some("super") => from[..from.len().saturating_sub(1)].to_vec(),
            Some("self") => from.to_vec(),
            Some(first) => {
                let mut child = from.to_vec();
                child.push(first.to_string());
                if !self.is_module(&child) {
                    return None; // another crate, or a local name
                }
                from.to_vec()
            }
            None => return None,
        };
        let rest = if matches!(path[0].as_str(), "crate" | "self") {
            &path[1..]
        } else if path[0] == "super" {
            let mut rest = &path[1..];
            while rest.first().is_some_and(|s| s == "super") {
                m.pop();
                rest = &rest[1..];
            }
            rest
        } else {
            path
        };
        let mut i = 0;
        while i < rest.len() {
            let mut child = m.clone();
            child.push(rest[i].clone());
            if self.is_module(&child) {
                m = child;
                i += 1;
            } else {
                break;
            }
        }
        if i < rest.len() && depth < 8 {
            // An item of module m: follow it if m only re-exports it.
            let name = &rest[i];
            for (target, alias) in use_paths(&self.files[&m]) {
                if alias.as_deref() == Some(name.as_str()) || target.last() == Some(name) {
                    // A re-export of another crate's item (`pub use spirv_std::...::Float`)
                    // imports nothing of this crate.
                    return self.resolve(&m, &target, depth + 1);
                }
            }
        }
        Some(m)
    }

    /// Every file's imports: file -> the files it depends on, each with the first path that
    /// names it.
    fn graph(&self) -> Graph {
        let mut graph = BTreeMap::new();
        for (m, text) in &self.files {
            let mut deps = BTreeMap::new();
            let mut paths: Vec<Vec<String>> = use_paths(text).into_iter().map(|u| u.0).collect();
            paths.extend(code_paths(text));
            for p in paths {
                if let Some(f) = self.resolve(m, &p, 0) {
                    if &f != m {
                        deps.entry(f).or_insert_with(|| p.join("::"));
                    }
                }
            }
            graph.insert(m.clone(), deps);
        }
        graph
    }
}

/// The text without `//` comments and without a trailing `#[cfg(test)] mod tests { ... }`.
fn without_tests_and_comments(text: &str) -> String {
    let text = match text.find("#[cfg(test)]\nmod tests {") {
        Some(i) => &text[..i],
        None => text,
    };
    text.lines()
        .map(|l| match l.find("//") {
            Some(i) if !l[..i].contains('"') => &l[..i],
            _ => l,
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// The paths of every `use` item (`a::b::{c, d::e as f, g::*}` -> a::b::c, a::b::d::e as f,
/// a::b::g), each with its alias.
fn use_paths(text: &str) -> Vec<(Vec<String>, Option<String>)> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(i) = find_use(rest) {
        let after = &rest[i..];
        let end = after.find(';').unwrap_or(after.len());
        let tree: String = after[..end]
            .split_whitespace()
            .collect::<Vec<_>>()
            .join(" ");
        expand_tree(&[], &tree, &mut out);
        rest = &after[end..];
    }
    out
}

/// Where the next `use` item's tree begins (after `use `, `pub use `, `pub(crate) use `...).
fn find_use(text: &str) -> Option<usize> {
    let mut from = 0;
    while let Some(i) = text[from..].find("use ") {
        let at = from + i;
        let before = text[..at].trim_end_matches([' ', '\t']);
        let line_start = before.is_empty()
            || before.ends_with('\n')
            || before.ends_with("pub")
            || before.ends_with(')')
            || before.ends_with('{')
            || before.ends_with(';')
            || before.ends_with(']');
        if line_start && (at == 0 || !text.as_bytes()[at - 1].is_ascii_alphanumeric()) {
            return Some(at + 4);
        }
        from = at + 4;
    }
    None
}

fn expand_tree(prefix: &[String], tree: &str, out: &mut Vec<(Vec<String>, Option<String>)>) {
    let tree = tree.trim();
    if let Some(open) = tree.find('{') {
        let base: Vec<String> = tree[..open]
            .trim_end_matches(':')
            .split("::")
            .filter(|s| !s.trim().is_empty())
            .map(|s| s.trim().to_string())
            .collect();
        let mut p = prefix.to_vec();
        p.extend(base);
        let inner = &tree[open + 1..tree.rfind('}').unwrap()];
        let (mut depth, mut start) = (0, 0);
        for (i, c) in inner.char_indices() {
            match c {
                '{' => depth += 1,
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    expand_tree(&p, &inner[start..i], out);
                    start = i + 1;
                }
                _ => {}
            }
        }
        expand_tree(&p, &inner[start..], out);
        return;
    }
    if tree.is_empty() {
        return;
    }
    let (path, alias) = match tree.split_once(" as ") {
        Some((p, a)) => (p, Some(a.trim().to_string())),
        None => (tree, None),
    };
    let mut p = prefix.to_vec();
    p.extend(
        path.split("::")
            .map(|s| s.trim().to_string())
            .filter(|s| !s.is_empty() && s != "*"),
    );
    if p.last().is_some_and(|s| s == "self") {
        p.pop();
    }
    if !p.is_empty() {
        out.push((p, alias));
    }
}

/// Paths written in code: `crate::a::b`, `super::a`, `self::a` (outside `use` items too).
fn code_paths(text: &str) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    let bytes = text.as_bytes();
    for start in ["crate::", "super::", "self::"] {
        let mut from = 0;
        while let Some(i) = text[from..].find(start) {
            let at = from + i;
            from = at + start.len();
            if at > 0 && (bytes[at - 1].is_ascii_alphanumeric() || bytes[at - 1] == b'_') {
                continue; // `$crate::`, or part of a longer name
            }
            if at > 0 && bytes[at - 1] == b'$' {
                continue;
            }
            let end = text[at..]
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == ':'))
                .map_or(text.len(), |e| at + e);
            if text[end..].starts_with('{') {
                continue; // a `use` tree's prefix: `use_paths` reads the tree
            }
            let path: Vec<String> = text[at..end]
                .split("::")
                .filter(|s| !s.is_empty())
                .map(str::to_string)
                .collect();
            out.push(path);
        }
    }
    out
}

/// The strongly connected components of more than one file (Tarjan's algorithm).
fn circles(graph: &Graph) -> Vec<Vec<String>> {
    struct State<'a> {
        graph: &'a Graph,
        index: BTreeMap<&'a Vec<String>, (usize, usize)>,
        stack: Vec<&'a Vec<String>>,
        on_stack: BTreeSet<&'a Vec<String>>,
        next: usize,
        found: Vec<Vec<String>>,
    }
    fn visit<'a>(s: &mut State<'a>, v: &'a Vec<String>) {
        s.index.insert(v, (s.next, s.next));
        s.next += 1;
        s.stack.push(v);
        s.on_stack.insert(v);
        for w in s.graph[v].keys() {
            let Some((w_key, _)) = s.graph.get_key_value(w) else {
                continue;
            };
            if !s.index.contains_key(w_key) {
                visit(s, w_key);
                let low = s.index[w_key].1.min(s.index[v].1);
                s.index.get_mut(v).unwrap().1 = low;
            } else if s.on_stack.contains(w_key) {
                let low = s.index[w_key].0.min(s.index[v].1);
                s.index.get_mut(v).unwrap().1 = low;
            }
        }
        if s.index[v].0 == s.index[v].1 {
            let mut component = Vec::new();
            while let Some(w) = s.stack.pop() {
                s.on_stack.remove(w);
                component.push(w.join("::"));
                if w == v {
                    break;
                }
            }
            if component.len() > 1 {
                s.found.push(component);
            }
        }
    }
    let mut s = State {
        graph,
        index: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        next: 0,
        found: Vec::new(),
    };
    for v in graph.keys() {
        if !s.index.contains_key(v) {
            visit(&mut s, v);
        }
    }
    s.found
}

/// Every `.rs` file below `dir`.
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let p = entry.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|e| e == "rs") {
                out.push(p);
            }
        }
    }
    out
}

fn src(dir: &str) -> PathBuf {
    twinpath_tests::repo_root().join(dir)
}

#[test]
fn no_import_circle_in_host_or_kernel() {
    for dir in ["host/src", "kernel/src"] {
        let files = CrateFiles::read(&src(dir));
        let graph = files.graph();
        let edges: usize = graph.values().map(BTreeMap::len).sum();
        println!("{dir}: {} files, {edges} imports between them", graph.len());
        assert!(
            graph.len() > 20 && edges > 50,
            "{dir}: too few files or imports seen"
        );
        let found = circles(&graph);
        let mut report = String::new();
        for circle in &found {
            report.push_str("\n  circle:");
            for (from, deps) in &graph {
                let from_name = from.join("::");
                if !circle.contains(&from_name) {
                    continue;
                }
                for (to, path) in deps {
                    if circle.contains(&to.join("::")) {
                        report
                            .push_str(&format!("\n    {from_name} -> {} ({path})", to.join("::")));
                    }
                }
            }
        }
        assert!(found.is_empty(), "{dir}: import circles:{report}");
    }
}

#[test]
fn the_circle_finder_finds_a_circle() {
    // Two files that import each other, one through a re-export of its parent, and a third
    // that only re-exports: the first two are a circle, the third is not in it.
    let mut files = BTreeMap::new();
    let m = |s: &str| -> Vec<String> {
        s.split("::")
            .filter(|x| !x.is_empty())
            .map(str::to_string)
            .collect()
    };
    files.insert(m(""), "mod a;\nmod b;\npub use a::Thing;\n".to_string());
    files.insert(
        m("a"),
        "use crate::b::helper;\npub struct Thing;\n".to_string(),
    );
    files.insert(
        m("b"),
        "pub fn helper() -> crate::Thing { todo!() }\n".to_string(),
    );
    let files = CrateFiles { files };
    let graph = files.graph();
    assert_eq!(
        circles(&graph),
        vec![vec!["b".to_string(), "a".to_string()]]
    );
    // Without b's path back, no circle.
    let mut files = files;
    files
        .files
        .insert(m("b"), "pub fn helper() -> u32 { 0 }\n".to_string());
    assert!(circles(&files.graph()).is_empty());
}

#[test]
fn no_host_file_over_600_lines() {
    let files = rust_files(&src("host/src"));
    assert!(files.len() > 20, "too few files seen");
    let long: Vec<String> = files
        .iter()
        .filter_map(|p| {
            let lines = std::fs::read_to_string(p).unwrap().lines().count();
            (lines > 600).then(|| format!("{} ({lines} lines)", p.display()))
        })
        .collect();
    assert!(long.is_empty(), "files over 600 lines: {long:?}");
}

#[test]
fn at_most_two_too_many_arguments_in_the_kernel() {
    let files = CrateFiles::read(&src("kernel/src"));
    let allows: Vec<String> = files
        .files
        .iter()
        .flat_map(|(m, text)| {
            text.matches("too_many_arguments")
                .map(move |_| m.join("::"))
        })
        .collect();
    assert!(
        allows.len() <= 2,
        "{} too_many_arguments allowances: {allows:?}",
        allows.len()
    );
}
