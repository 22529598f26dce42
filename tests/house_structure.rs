//! The code base stays readable (issue 30): no import circles between source files (a file
//! that uses another, directly or through others, that uses it back makes the two one unit
//! that can only be read and changed together), and no function longer than
//! [`LONG`] lines unless the comment above it says why it must be one piece (a line
//! starting `// One piece:`).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The longest function allowed without a reason.
const LONG: usize = 120;

/// Every `.rs` file under `dir` with its module path (`["search", "run"]`; `mod.rs` and
/// `lib.rs` name their folder).
fn modules(dir: &Path) -> BTreeMap<Vec<String>, PathBuf> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).expect("src is readable") {
            let p = e.expect("entry").path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "rs") {
                let rel = p.strip_prefix(dir).expect("under src");
                let mut m: Vec<String> = rel
                    .with_extension("")
                    .iter()
                    .map(|s| s.to_string_lossy().into_owned())
                    .collect();
                if m.last().is_some_and(|l| l == "mod" || l == "lib") {
                    m.pop();
                }
                if m == ["main"] {
                    m = vec!["<main>".into()];
                }
                out.insert(m, p);
            }
        }
    }
    out
}

/// The text without comments and string literals (so paths in docs and messages do not
/// count), cut before `#[cfg(test)]` (tests may use anything).
fn code(text: &str) -> String {
    let text = text.split("#[cfg(test)]").next().unwrap_or("");
    let b = text.as_bytes();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while i < b.len() {
        if b[i..].starts_with(b"//") {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if b[i..].starts_with(b"/*") {
            let end = text[i + 2..].find("*/").map_or(b.len(), |k| i + 2 + k + 2);
            i = end;
        } else if b[i] == b'"' {
            i += 1;
            while i < b.len() && b[i] != b'"' {
                i += if b[i] == b'\\' { 2 } else { 1 };
            }
            i += 1;
            out.push_str("\"\"");
        } else {
            out.push(b[i] as char);
            i += 1;
        }
    }
    out
}

/// Expand a `use` tree (`a::{b, c::{d, e}}`) into paths.
fn expand(tree: &str) -> Vec<String> {
    let tree = tree.trim();
    if let Some(open) = tree.find('{')
        && tree.ends_with('}')
    {
        let prefix = tree[..open].trim_end_matches("::").to_string();
        let inner = &tree[open + 1..tree.len() - 1];
        let (mut parts, mut depth, mut cur) = (Vec::new(), 0, String::new());
        for ch in inner.chars() {
            match ch {
                '{' => depth += 1,
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    parts.push(std::mem::take(&mut cur));
                    continue;
                }
                _ => {}
            }
            cur.push(ch);
        }
        parts.push(cur);
        return parts
            .iter()
            .filter(|p| !p.trim().is_empty())
            .flat_map(|p| {
                if p.trim() == "self" {
                    vec![prefix.clone()]
                } else {
                    expand(p)
                        .into_iter()
                        .map(|q| format!("{prefix}::{q}"))
                        .collect()
                }
            })
            .collect();
    }
    vec![tree.split(" as ").next().unwrap_or(tree).trim().to_string()]
}

/// Paths a file names: its `use` trees and every `crate::…`/`super::…`/`self::…` path.
fn paths(code: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = code;
    while let Some(k) = rest.find("use ") {
        let before_ok = k == 0
            || !rest.as_bytes()[k - 1].is_ascii_alphanumeric() && rest.as_bytes()[k - 1] != b'_';
        let after = &rest[k + 4..];
        if before_ok && let Some(end) = after.find(';') {
            out.extend(expand(
                &after[..end]
                    .split_whitespace()
                    .collect::<Vec<_>>()
                    .join(" "),
            ));
        }
        rest = after;
    }
    for start in ["crate::", "super::", "self::"] {
        let mut rest = code;
        while let Some(k) = rest.find(start) {
            let before_ok = k == 0
                || !rest.as_bytes()[k - 1].is_ascii_alphanumeric()
                    && rest.as_bytes()[k - 1] != b'_'
                    && rest.as_bytes()[k - 1] != b':';
            let tail = &rest[k..];
            let len = tail
                .find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
                .unwrap_or(tail.len());
            if before_ok {
                out.push(tail[..len].trim_end_matches(':').to_string());
            }
            rest = &rest[k + start.len()..];
        }
    }
    out
}

/// The module file a path lands in: the longest prefix that is a module.
fn resolve(
    from: &[String],
    is_dir_module: bool,
    path: &str,
    mods: &BTreeMap<Vec<String>, PathBuf>,
) -> Option<Vec<String>> {
    let mut segs: Vec<&str> = path.split("::").filter(|s| !s.is_empty()).collect();
    let mut base: Vec<String> = match segs.first() {
        Some(&"crate") => {
            segs.remove(0);
            Vec::new()
        }
        Some(&"self") | Some(&"super") => {
            // `self` is the module itself; for a file `a/b.rs` that is `a::b`, whose
            // `super` is `a`.
            let _ = is_dir_module;
            let mut b = from.to_vec();
            if segs[0] == "self" {
                segs.remove(0);
            }
            while segs.first() == Some(&"super") {
                b.pop();
                segs.remove(0);
            }
            b
        }
        _ => return None,
    };
    base.extend(segs.iter().map(|s| s.to_string()));
    (0..=base.len())
        .rev()
        .map(|k| base[..k].to_vec())
        .find(|m| mods.contains_key(m))
}

/// Strongly connected components with more than one file (Tarjan).
fn circles(edges: &BTreeMap<Vec<String>, BTreeSet<Vec<String>>>) -> Vec<Vec<String>> {
    struct T<'a> {
        edges: &'a BTreeMap<Vec<String>, BTreeSet<Vec<String>>>,
        index: BTreeMap<Vec<String>, usize>,
        low: BTreeMap<Vec<String>, usize>,
        stack: Vec<Vec<String>>,
        on: BTreeSet<Vec<String>>,
        out: Vec<Vec<String>>,
    }
    fn visit(t: &mut T<'_>, v: &Vec<String>) {
        let i = t.index.len();
        t.index.insert(v.clone(), i);
        t.low.insert(v.clone(), i);
        t.stack.push(v.clone());
        t.on.insert(v.clone());
        for w in t.edges.get(v).into_iter().flatten() {
            if !t.index.contains_key(w) {
                visit(t, w);
                let lw = t.low[w];
                let lv = t.low.get_mut(v).expect("visited");
                *lv = (*lv).min(lw);
            } else if t.on.contains(w) {
                let iw = t.index[w];
                let lv = t.low.get_mut(v).expect("visited");
                *lv = (*lv).min(iw);
            }
        }
        if t.low[v] == t.index[v] {
            let mut comp = Vec::new();
            while let Some(w) = t.stack.pop() {
                t.on.remove(&w);
                let done = &w == v;
                comp.push(if w.is_empty() {
                    "lib".into()
                } else {
                    w.join("/")
                });
                if done {
                    break;
                }
            }
            if comp.len() > 1 {
                comp.sort();
                t.out.push(comp);
            }
        }
    }
    let mut t = T {
        edges,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on: BTreeSet::new(),
        out: Vec::new(),
    };
    for v in edges.keys() {
        if !t.index.contains_key(v) {
            visit(&mut t, v);
        }
    }
    t.out
}

fn import_edges(src: &Path) -> BTreeMap<Vec<String>, BTreeSet<Vec<String>>> {
    let mods = modules(src);
    let mut edges = BTreeMap::new();
    for (m, p) in &mods {
        let text = std::fs::read_to_string(p).expect("readable");
        let dir_module = p.ends_with("mod.rs") || p.ends_with("lib.rs");
        let targets: BTreeSet<Vec<String>> = paths(&code(&text))
            .iter()
            .filter_map(|path| resolve(m, dir_module, path, &mods))
            .filter(|t| t != m)
            .collect();
        edges.insert(m.clone(), targets);
    }
    edges
}

#[test]
fn no_import_circles_between_files() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let found = circles(&import_edges(&src));
    assert!(
        found.is_empty(),
        "files that import each other (directly or in a loop), so they can only be read \
         and changed together: {found:#?}"
    );
}

#[test]
fn the_circle_finder_finds_a_circle() {
    // The checker itself: a two-file loop and a three-file loop are found, a chain is not.
    let e = |pairs: &[(&str, &str)]| {
        let mut m: BTreeMap<Vec<String>, BTreeSet<Vec<String>>> = BTreeMap::new();
        for (a, b) in pairs {
            m.entry(vec![a.to_string()])
                .or_default()
                .insert(vec![b.to_string()]);
            m.entry(vec![b.to_string()]).or_default();
        }
        m
    };
    assert_eq!(circles(&e(&[("a", "b"), ("b", "a")])).len(), 1);
    assert_eq!(
        circles(&e(&[("a", "b"), ("b", "c"), ("c", "a")]))[0].len(),
        3
    );
    assert!(circles(&e(&[("a", "b"), ("b", "c")])).is_empty());
    assert_eq!(
        expand("crate::a::{b, c::{d, e as f}, self}"),
        [
            "crate::a::b",
            "crate::a::c::d",
            "crate::a::c::e",
            "crate::a"
        ]
    );
}

/// Functions of `text` longer than [`LONG`] lines without a `// One piece:` reason: (name,
/// first line, length).
fn long_functions(text: &str) -> Vec<(String, usize, usize)> {
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        let t = lines[i].trim_start();
        let is_fn = [
            "fn ",
            "pub fn ",
            "pub(crate) fn ",
            "pub(super) fn ",
            "const fn ",
            "pub const fn ",
            "unsafe fn ",
            "pub unsafe fn ",
            "async fn ",
        ]
        .iter()
        .any(|p| t.starts_with(p));
        if !is_fn {
            i += 1;
            continue;
        }
        let name: String = t[t.find("fn ").expect("fn") + 3..]
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        // Find the body: braces counted on code (strings and comments removed).
        let (mut depth, mut started, mut k) = (0i64, false, i);
        while k < lines.len() {
            let c = code(lines[k]);
            if !started && c.trim_end().ends_with(';') && !c.contains('{') {
                break; // a declaration without a body
            }
            for ch in c.chars() {
                match ch {
                    '{' => {
                        depth += 1;
                        started = true
                    }
                    '}' => depth -= 1,
                    _ => {}
                }
            }
            if started && depth <= 0 {
                break;
            }
            k += 1;
        }
        let len = k + 1 - i;
        if started && len > LONG {
            let reason = lines[..i]
                .iter()
                .rev()
                .take_while(|l| {
                    let l = l.trim_start();
                    l.starts_with("//") || l.starts_with("#[")
                })
                .any(|l| {
                    l.trim_start()
                        .trim_start_matches('/')
                        .trim_start()
                        .starts_with("One piece:")
                });
            if !reason {
                out.push((name, i + 1, len));
            }
        }
        i += 1;
    }
    out
}

#[test]
fn no_function_is_longer_than_a_reader_can_hold() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut long = Vec::new();
    for dir in ["src", "python/src"] {
        for p in modules(&root.join(dir)).values() {
            let text = std::fs::read_to_string(p).expect("readable");
            for (name, line, len) in long_functions(&text) {
                long.push(format!("{}:{line} {name} ({len} lines)", p.display()));
            }
        }
    }
    assert!(
        long.is_empty(),
        "functions over {LONG} lines without a `// One piece:` comment saying why: {long:#?}"
    );
}

#[test]
fn the_length_counter_counts() {
    let body = "    x += 1;\n".repeat(LONG);
    let f = format!("fn big() {{\n{body}}}\nfn small() {{ 1 }}\n");
    assert_eq!(long_functions(&f), [("big".to_string(), 1, LONG + 2)]);
    let excused = format!("// One piece: a table.\n{f}");
    assert!(long_functions(&excused).is_empty());
}
