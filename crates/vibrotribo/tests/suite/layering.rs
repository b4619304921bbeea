//! The import graph of the sources, read from the files themselves: the library's modules
//! import only from their own layer or the layers below it, and the program's files import
//! each other without a circle.
//!
//! The library's layers, from the bottom (data flows upwards: parameters → engine → run →
//! observers → results → output):
//!
//! 1. parameters and engine: `error`, `random`, `model`, `excitation`, `dynamics`,
//!    `sensitivity`, `electrical`, `coupling` (the parameter types live beside the engine that
//!    reads them);
//! 2. analyses of a trajectory, the observers a run carries: `analysis`, `orbits`, `lyapunov`;
//! 3. runs and studies: `config` (the edge that reads a configuration into a run), `study`,
//!    `sweep` (a study runs the engine with the observers of layer 2 and earns its labels from
//!    them), `merit` (the figures of merit, a run observer);
//! 4. studies of studies: `attractors`, `branch`, `curve`, `bifmap`, `optimize`, `response`;
//! 5. output: `report`.
//!
//! Only code counts: paths in comments and doc links do not.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

/// The library's top-level modules by layer, bottom first.
const LAYERS: &[&[&str]] = &[
    &[
        "error",
        "random",
        "model",
        "excitation",
        "dynamics",
        "sensitivity",
        "electrical",
        "coupling",
    ],
    &["analysis", "orbits", "lyapunov"],
    &["config", "study", "sweep", "merit"],
    &["attractors", "branch", "curve", "bifmap", "optimize", "response"],
    &["report"],
];

/// Every `.rs` file under `dir`, recursively.
fn sources(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                out.push(path);
            }
        }
    }
    out.sort();
    out
}

/// The top-level module a file belongs to (`src/a.rs` and `src/a/…` are `a`).
fn module_of(src: &Path, file: &Path) -> String {
    let rel = file.strip_prefix(src).unwrap();
    let first = rel.components().next().unwrap().as_os_str().to_string_lossy();
    first.trim_end_matches(".rs").to_string()
}

/// The text of a file without its comments (line comments, doc comments, block comments).
fn code_of(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut in_block = 0usize;
    for line in text.lines() {
        let mut rest = line;
        let mut kept = String::new();
        loop {
            if in_block > 0 {
                match rest.find("*/") {
                    Some(i) => {
                        in_block -= 1;
                        rest = &rest[i + 2..];
                    }
                    None => break,
                }
            } else {
                let line_comment = rest.find("//");
                let block = rest.find("/*");
                match (line_comment, block) {
                    (Some(l), b) if b.is_none_or(|b| l < b) => {
                        kept.push_str(&rest[..l]);
                        break;
                    }
                    (_, Some(b)) => {
                        kept.push_str(&rest[..b]);
                        in_block += 1;
                        rest = &rest[b + 2..];
                    }
                    _ => {
                        kept.push_str(rest);
                        break;
                    }
                }
            }
        }
        out.push_str(&kept);
        out.push('\n');
    }
    out
}

/// The top-level names imported through `crate::` in `code`: `crate::a::…` gives `a`,
/// `crate::{a::x, b}` gives `a` and `b` (nested groups are paths inside those modules).
fn crate_imports(code: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    let mut rest = code;
    while let Some(i) = rest.find("crate::") {
        let preceded_by_ident = rest[..i]
            .chars()
            .next_back()
            .is_some_and(|c| c.is_alphanumeric() || c == '_');
        rest = &rest[i + "crate::".len()..];
        if preceded_by_ident {
            continue;
        }
        if let Some(group) = rest.strip_prefix('{') {
            let mut depth = 0usize;
            let mut item = String::new();
            let mut at_start = true;
            for c in group.chars() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => break,
                    '}' => depth -= 1,
                    ',' if depth == 0 => at_start = true,
                    _ => {}
                }
                if depth == 0 && at_start {
                    if c.is_alphanumeric() || c == '_' {
                        item.push(c);
                    } else if !item.is_empty() {
                        out.insert(std::mem::take(&mut item));
                        at_start = false;
                    }
                }
            }
            if !item.is_empty() {
                out.insert(item);
            }
        } else {
            let name: String = rest
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            out.insert(name);
        }
    }
    out
}

/// Module → the other top-level modules its files import.
fn import_graph(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let files = sources(src);
    let modules: BTreeSet<String> = files.iter().map(|f| module_of(src, f)).collect();
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for file in &files {
        let from = module_of(src, file);
        let code = code_of(&fs::read_to_string(file).unwrap());
        let entry = graph.entry(from.clone()).or_default();
        for to in crate_imports(&code) {
            if to != from && modules.contains(&to) {
                entry.insert(to);
            }
        }
    }
    graph
}

/// A circle in `graph`, if there is one (as the list of modules around it).
fn find_circle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    #[derive(Clone, Copy, PartialEq)]
    enum Mark {
        New,
        Open,
        Done,
    }
    fn visit(
        node: &str,
        graph: &BTreeMap<String, BTreeSet<String>>,
        marks: &mut BTreeMap<String, Mark>,
        path: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        marks.insert(node.to_string(), Mark::Open);
        path.push(node.to_string());
        for next in graph.get(node).into_iter().flatten() {
            match marks.get(next).copied().unwrap_or(Mark::New) {
                Mark::Open => {
                    let start = path.iter().position(|p| p == next).unwrap();
                    let mut circle = path[start..].to_vec();
                    circle.push(next.clone());
                    return Some(circle);
                }
                Mark::New => {
                    if let Some(c) = visit(next, graph, marks, path) {
                        return Some(c);
                    }
                }
                Mark::Done => {}
            }
        }
        path.pop();
        marks.insert(node.to_string(), Mark::Done);
        None
    }
    let mut marks = BTreeMap::new();
    for node in graph.keys() {
        if marks.get(node).copied().unwrap_or(Mark::New) == Mark::New
            && let Some(c) = visit(node, graph, &mut marks, &mut Vec::new())
        {
            return Some(c);
        }
    }
    None
}

fn crate_src(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(name)
        .join("src")
}

#[test]
fn the_reader_sees_imports_and_skips_comments() {
    let code = code_of(
        "use crate::a::X;\n/// [link](crate::b::Y)\nuse crate::{c::{D, E}, f};\n\
         let x = crate::g::h(); /* crate::i */ // crate::j\nuse other_crate::k;\n",
    );
    let seen: Vec<String> = crate_imports(&code).into_iter().collect();
    assert_eq!(seen, ["a", "c", "f", "g"]);
    let mut graph = BTreeMap::new();
    graph.insert("a".to_string(), BTreeSet::from(["b".to_string()]));
    graph.insert("b".to_string(), BTreeSet::from(["c".to_string()]));
    assert_eq!(find_circle(&graph), None);
    graph.insert("c".to_string(), BTreeSet::from(["a".to_string()]));
    assert_eq!(
        find_circle(&graph).unwrap(),
        ["a", "b", "c", "a"].map(String::from)
    );
}

#[test]
fn library_modules_import_only_their_layer_and_below() {
    let graph = import_graph(&crate_src("vibrotribo"));
    let layer_of = |m: &str| LAYERS.iter().position(|l| l.contains(&m));
    let mut unplaced = Vec::new();
    let mut upward = Vec::new();
    for (from, targets) in &graph {
        let Some(lf) = layer_of(from) else {
            if from != "lib" {
                unplaced.push(from.clone());
            }
            continue;
        };
        for to in targets {
            match layer_of(to) {
                Some(lt) if lt > lf => upward.push(format!(
                    "{from} (layer {}) imports {to} (layer {})",
                    lf + 1,
                    lt + 1
                )),
                Some(_) => {}
                None => unplaced.push(to.clone()),
            }
        }
    }
    assert!(
        unplaced.is_empty(),
        "modules in no layer (add them to LAYERS): {unplaced:?}"
    );
    assert!(
        upward.is_empty(),
        "imports from a layer above:\n{}",
        upward.join("\n")
    );
}

#[test]
fn program_files_import_each_other_without_a_circle() {
    let graph = import_graph(&crate_src("vibrotribo-cli"));
    assert!(graph.len() > 10, "the program's files were not found: {graph:?}");
    if let Some(circle) = find_circle(&graph) {
        panic!(
            "an import circle among the program's files: {}",
            circle.join(" → ")
        );
    }
}
