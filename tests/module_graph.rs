//! The library's modules form no cycle: at the granularity of `src/`'s
//! top-level modules, and among the files of each folder. Edges come from
//! every `crate::` and `super::` path and every `use` line in the code
//! (comments and doc comments excluded), re-exports included.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Every `.rs` file under `dir`.
fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// A file's module path below `src/` (`engine`, `tiling::sphere`, ...).
fn module_of(src: &Path, file: &Path) -> Vec<String> {
    let rel = file.strip_prefix(src).unwrap().with_extension("");
    let mut parts: Vec<String> = rel
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    if parts.last().is_some_and(|p| p == "mod" || p == "lib") {
        parts.pop();
    }
    parts
}

/// The code of a file without comments, string contents or `#[cfg(test)]`
/// modules (tests may reach anywhere).
fn code_of(text: &str) -> String {
    let mut code = String::new();
    let mut skipping_tests = false;
    let mut depth = 0i32;
    for line in text.lines() {
        let trimmed = line.trim_start();
        if trimmed.starts_with("#[cfg(test)]") {
            skipping_tests = true;
            depth = 0;
            continue;
        }
        let line = match line.find("//") {
            Some(k) => &line[..k],
            None => line,
        };
        if skipping_tests {
            depth += line.matches('{').count() as i32 - line.matches('}').count() as i32;
            if depth <= 0 && line.contains('}') {
                skipping_tests = false;
            }
            continue;
        }
        code.push_str(line);
        code.push('\n');
    }
    // string literals may hold `crate::` in messages
    let mut out = String::new();
    let mut in_string = false;
    let mut escaped = false;
    for c in code.chars() {
        if in_string {
            if escaped {
                escaped = false;
            } else if c == '\\' {
                escaped = true;
            } else if c == '"' {
                in_string = false;
            }
            continue;
        }
        if c == '"' {
            in_string = true;
            continue;
        }
        out.push(c);
    }
    out
}

/// The module paths a file's code refers to, resolved to absolute paths
/// below the crate root (as far as they name modules).
fn references(code: &str, module: &[String], is_mod_file: bool) -> Vec<Vec<String>> {
    let mut found = Vec::new();
    let words: Vec<char> = code.chars().collect();
    let text: String = words.iter().collect();
    // the module `super` names: a `mod.rs` is its folder's module
    let parent: Vec<String> = if is_mod_file || module.is_empty() {
        module[..module.len().saturating_sub(1)].to_vec()
    } else {
        module[..module.len() - 1].to_vec()
    };
    for (prefix, base) in [("crate::", Vec::new()), ("super::", parent)] {
        let mut start = 0;
        while let Some(k) = text[start..].find(prefix) {
            let at = start + k;
            start = at + prefix.len();
            // a whole word only
            if at > 0 {
                let before = text[..at].chars().last().unwrap();
                if before.is_alphanumeric() || before == '_' {
                    continue;
                }
            }
            let rest = &text[at + prefix.len()..];
            collect_paths(rest, &base, &mut found);
        }
    }
    // `use` lines naming a sibling module without `crate::` or `super::`
    // are not possible in edition 2021 (they name crates); done
    found
}

/// The paths a `use`-tree or path starting at `rest` names, each prefixed
/// by `base`.
fn collect_paths(rest: &str, base: &[String], found: &mut Vec<Vec<String>>) {
    let mut path = base.to_vec();
    let mut chars = rest.char_indices().peekable();
    let mut segment = String::new();
    while let Some((i, c)) = chars.next() {
        if c.is_alphanumeric() || c == '_' {
            segment.push(c);
            continue;
        }
        if c == ':' && rest[i..].starts_with("::") {
            chars.next();
            if !segment.is_empty() {
                path.push(std::mem::take(&mut segment));
            }
            if rest[i + 2..].starts_with('{') {
                // a group: each member extends `path`
                let inner = &rest[i + 3..];
                let mut level = 0;
                let mut member_start = 0;
                for (j, d) in inner.char_indices() {
                    match d {
                        '{' => level += 1,
                        '}' if level == 0 => {
                            collect_paths(&inner[member_start..j], &path, found);
                            return;
                        }
                        '}' => level -= 1,
                        ',' if level == 0 => {
                            collect_paths(&inner[member_start..j], &path, found);
                            member_start = j + 1;
                        }
                        _ => {}
                    }
                }
                return;
            }
            continue;
        }
        if c.is_whitespace() && segment.is_empty() && path.len() == base.len() {
            continue;
        }
        break;
    }
    if !segment.is_empty() {
        path.push(segment);
    }
    found.push(path);
}

/// Cycles of a directed graph (each reported once, as a list of nodes).
fn a_cycle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    // depth-first search with colours
    fn visit(
        node: &str,
        graph: &BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<String, u8>,
        stack: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        state.insert(node.to_string(), 1);
        stack.push(node.to_string());
        for next in graph.get(node).into_iter().flatten() {
            match state.get(next.as_str()).copied().unwrap_or(0) {
                0 => {
                    if let Some(c) = visit(next, graph, state, stack) {
                        return Some(c);
                    }
                }
                1 => {
                    let from = stack.iter().position(|n| n == next).unwrap();
                    let mut cycle = stack[from..].to_vec();
                    cycle.push(next.clone());
                    return Some(cycle);
                }
                _ => {}
            }
        }
        stack.pop();
        state.insert(node.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for node in graph.keys() {
        if state.get(node.as_str()).copied().unwrap_or(0) == 0 {
            if let Some(c) = visit(node, graph, &mut state, &mut Vec::new()) {
                return Some(c);
            }
        }
    }
    None
}

#[test]
fn modules_form_no_cycle() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    sources(&src, &mut files);
    files.retain(|f| !f.starts_with(src.join("bin")));
    let modules: BTreeSet<Vec<String>> = files.iter().map(|f| module_of(&src, f)).collect();
    // edges between the files' modules: a reference names the longest
    // module it starts with
    let mut edges: BTreeSet<(Vec<String>, Vec<String>)> = BTreeSet::new();
    for file in &files {
        let module = module_of(&src, file);
        let is_mod = file.file_name().is_some_and(|n| n == "mod.rs");
        let code = code_of(&std::fs::read_to_string(file).unwrap());
        for path in references(&code, &module, is_mod) {
            let target = (0..=path.len())
                .rev()
                .map(|k| path[..k].to_vec())
                .find(|p| modules.contains(p));
            if let Some(target) = target {
                if target != module && !target.is_empty() {
                    edges.insert((module.clone(), target));
                }
            }
        }
    }
    let mut failures = Vec::new();
    // top level: each module's first segment
    let mut top: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (a, b) in &edges {
        if !a.is_empty() && a[0] != b[0] {
            top.entry(a[0].clone()).or_default().insert(b[0].clone());
        }
    }
    if let Some(cycle) = a_cycle(&top) {
        failures.push(format!("top-level modules: {}", cycle.join(" -> ")));
    }
    // each folder: its files (a reference into a subfolder counts as the
    // subfolder's module)
    let folders: BTreeSet<Vec<String>> = modules
        .iter()
        .filter(|m| !m.is_empty())
        .map(|m| m[..m.len() - 1].to_vec())
        .collect();
    for folder in folders {
        let depth = folder.len();
        let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
        for (a, b) in &edges {
            let inside = |m: &Vec<String>| m.len() > depth && m[..depth] == folder[..];
            if inside(a) && inside(b) && a[depth] != b[depth] {
                graph
                    .entry(a[depth].clone())
                    .or_default()
                    .insert(b[depth].clone());
            }
        }
        if let Some(cycle) = a_cycle(&graph) {
            failures.push(format!("in {}/: {}", folder.join("/"), cycle.join(" -> ")));
        }
    }
    assert!(
        failures.is_empty(),
        "module cycles:\n{}",
        failures.join("\n")
    );
}

#[test]
fn the_checker_finds_paths() {
    let code = code_of("use crate::a::{b, c::d};\nfn f() { crate::e::g(); }\n// crate::z\n");
    let found = references(&code, &["x".to_string()], false);
    let names: Vec<String> = found.iter().map(|p| p.join("::")).collect();
    assert!(names.contains(&"a::b".to_string()), "{names:?}");
    assert!(names.contains(&"a::c::d".to_string()), "{names:?}");
    assert!(names.contains(&"e::g".to_string()), "{names:?}");
    assert!(!names.iter().any(|n| n.starts_with('z')), "{names:?}");
    let mut graph = BTreeMap::new();
    graph.insert("a".to_string(), BTreeSet::from(["b".to_string()]));
    graph.insert("b".to_string(), BTreeSet::from(["a".to_string()]));
    assert!(a_cycle(&graph).is_some());
    graph.insert("b".to_string(), BTreeSet::new());
    assert!(a_cycle(&graph).is_none());
}
