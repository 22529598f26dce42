//! The documentation cannot rot (issue 30): every fenced code block of README.md,
//! CONTRIBUTING.md and `docs/*.md` in a runnable language is run here — or, for Python,
//! by `python/tests/test_docs.py` — or covered by an annotation that names what covers it;
//! every `foldsynth` command shown, inline ones included, names a real subcommand and only
//! options its `--help` lists; every relative link resolves; the README stays a front door.
//! CONTRIBUTING.md ("The docs test") states the rules and the annotations for writers.
//!
//! Shell blocks run with the built binary in one temporary directory per page (a copy of
//! `grammar/` and of the repository files a command names), in page order, so later blocks
//! read what earlier ones wrote; the repository is never written. `cc` and the programs it
//! builds run when a C compiler exists; `FOLDSYNTH_REQUIRE_DOCS_TOOLS=1` (set by CI) makes
//! a missing one a failure instead of a skip.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::{Mutex, OnceLock};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");
const BIN: &str = env!("CARGO_BIN_EXE_foldsynth");
/// The issue's goal for the README: at most 15 KB.
const README_MAX_BYTES: usize = 15_360;
/// Info strings whose blocks must be run or covered.
const SHELL: [&str; 4] = ["sh", "bash", "shell", "console"];
const RUNNABLE: [&str; 7] = ["sh", "bash", "shell", "console", "python", "c", "toml"];
/// Repository folders whose files a command may name (copied into the page's directory).
const COPIED: [&str; 4] = ["grammar", "tests", "benches", "docs"];

// ---------------------------------------------------------------------------------------
// The pages and their blocks.

/// One markdown page: its path relative to the repository and its text.
struct Page {
    path: String,
    text: String,
}

fn pages() -> Vec<Page> {
    let mut paths = vec!["README.md".to_owned(), "CONTRIBUTING.md".to_owned()];
    let mut docs: Vec<String> = std::fs::read_dir(Path::new(ROOT).join("docs"))
        .expect("docs/ exists")
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".md"))
        .map(|n| format!("docs/{n}"))
        .collect();
    docs.sort();
    paths.extend(docs);
    paths
        .into_iter()
        .map(|path| {
            let text = std::fs::read_to_string(Path::new(ROOT).join(&path))
                .unwrap_or_else(|e| panic!("{path}: {e}"));
            Page { path, text }
        })
        .collect()
}

/// What an annotation (`<!-- docs-test: … -->` right above a fence) asks.
#[derive(Clone, Debug, PartialEq)]
enum Note {
    /// Run the block with the first string replaced by the second.
    Replace(String, String),
    /// The block's other commands are what CI runs: `.ci/run` holds each string.
    Ci(Vec<String>),
    /// Not run here: the file (a test) exists and mentions each subcommand and string.
    CoveredBy(String, Vec<String>),
    /// Write the block to this file in the page's directory.
    File(String),
    /// A `toml` fragment merged into this task file before loading.
    Base(String),
    /// A `toml` block that must fail to load, naming this field.
    Rejects(String),
}

/// One fenced code block.
struct Block {
    /// Page and line of the opening fence, for messages.
    at: String,
    lang: String,
    body: String,
    notes: Vec<Note>,
}

impl Block {
    fn replacements(&self) -> impl Iterator<Item = (&str, &str)> {
        self.notes.iter().filter_map(|n| match n {
            Note::Replace(a, b) => Some((a.as_str(), b.as_str())),
            _ => None,
        })
    }

    fn covered_by(&self) -> Option<(&str, &[String])> {
        self.notes.iter().find_map(|n| match n {
            Note::CoveredBy(f, s) => Some((f.as_str(), s.as_slice())),
            _ => None,
        })
    }

    fn has_ci(&self) -> bool {
        self.notes.iter().any(|n| matches!(n, Note::Ci(_)))
    }

    fn file(&self) -> Option<&str> {
        self.notes.iter().find_map(|n| match n {
            Note::File(f) => Some(f.as_str()),
            _ => None,
        })
    }
}

/// A page split into its fenced blocks and its prose (paragraphs outside the fences).
#[derive(Default)]
struct Parsed {
    blocks: Vec<Block>,
    prose: Vec<String>,
    errors: Vec<String>,
}

const ANNOTATION: &str = "<!-- docs-test:";

fn parse(page: &Page) -> Parsed {
    let lines: Vec<&str> = page.text.lines().collect();
    let mut out = Parsed::default();
    let mut paragraph = String::new();
    // The annotation of the line before, waiting for its fence.
    let mut pending: Option<(usize, Vec<Note>)> = None;
    let mut i = 0;
    while i < lines.len() {
        let (n, line) = (i + 1, lines[i]);
        i += 1;
        let trimmed = line.trim_start();
        let fence = fence_of(trimmed);
        if !fence.is_empty() {
            flush(&mut paragraph, &mut out.prose);
            let indent = line.len() - trimmed.len();
            let body;
            (body, i) = fenced_body(&lines, i, &fence, indent);
            let lang = trimmed[fence.len()..].split_whitespace().next();
            let at = format!("{}:{n}", page.path);
            if lang.is_none() {
                out.errors.push(format!(
                    "{at}: a fence without an info string; say what it is (`text` or `json` for output, `sh` for commands)"
                ));
            }
            out.blocks.push(Block {
                at,
                lang: lang.unwrap_or("").to_lowercase(),
                body,
                notes: pending.take().map(|(_, notes)| notes).unwrap_or_default(),
            });
            continue;
        }
        if let Some((l, _)) = pending.take() {
            out.errors.push(format!(
                "{}:{l}: annotation without a fence right below it",
                page.path
            ));
        }
        if let Some(rest) = trimmed.strip_prefix(ANNOTATION) {
            match rest.trim_end().strip_suffix("-->").map(directives) {
                Some(Ok(notes)) => pending = Some((n, notes)),
                Some(Err(e)) => out.errors.push(format!("{}:{n}: {e}", page.path)),
                None => out.errors.push(format!(
                    "{}:{n}: an annotation is one line ending in -->",
                    page.path
                )),
            }
        } else if line.trim().is_empty() {
            flush(&mut paragraph, &mut out.prose);
        } else {
            paragraph.push_str(line);
            paragraph.push('\n');
        }
    }
    if let Some((l, _)) = pending {
        out.errors.push(format!(
            "{}:{l}: annotation at the end of the page",
            page.path
        ));
    }
    flush(&mut paragraph, &mut out.prose);
    out
}

/// The fence that opens a block on this (left-trimmed) line: three or more backticks or
/// tildes; empty when the line opens none.
fn fence_of(trimmed: &str) -> String {
    let first = trimmed.chars().next().unwrap_or(' ');
    let fence: String = trimmed.chars().take_while(|&c| c == first).collect();
    if (first == '`' || first == '~') && fence.len() >= 3 {
        fence
    } else {
        String::new()
    }
}

/// The lines from `from` up to the closing fence, less the opening fence's indentation,
/// and the index of the line after the closing fence.
fn fenced_body(lines: &[&str], from: usize, fence: &str, indent: usize) -> (String, usize) {
    let mut body = String::new();
    let mut i = from;
    while i < lines.len() && !lines[i].trim().starts_with(fence) {
        let l = lines[i];
        let cut = l.len() - l.trim_start().len();
        body.push_str(&l[cut.min(indent)..]);
        body.push('\n');
        i += 1;
    }
    (body, i + 1)
}

fn flush(paragraph: &mut String, prose: &mut Vec<String>) {
    if !paragraph.is_empty() {
        prose.push(std::mem::take(paragraph));
    }
}

/// The directives of one annotation: `replace "A" with "B"; ci "S"; covered-by FILE "S";
/// file NAME; base FILE; rejects "FIELD"` (a parenthesized remark is a reason for readers).
fn directives(text: &str) -> Result<Vec<Note>, String> {
    let mut notes = Vec::new();
    for part in split_outside_quotes(text, ';') {
        let tokens = annotation_tokens(&part)?;
        let Some((kind, args)) = tokens.split_first() else {
            continue;
        };
        let strings = |args: &[Token]| -> Result<Vec<String>, String> {
            args.iter()
                .map(|t| match t {
                    Token::Quoted(s) => Ok(s.clone()),
                    Token::Bare(w) => Err(format!("{kind:?}: {w:?} should be quoted")),
                })
                .collect()
        };
        let note = match (kind, args) {
            (Token::Bare(k), [Token::Quoted(a), Token::Bare(w), Token::Quoted(b)])
                if k == "replace" && w == "with" =>
            {
                Note::Replace(a.clone(), b.clone())
            }
            (Token::Bare(k), rest) if k == "ci" => Note::Ci(strings(rest)?),
            (Token::Bare(k), [Token::Bare(file), rest @ ..]) if k == "covered-by" => {
                Note::CoveredBy(file.clone(), strings(rest)?)
            }
            (Token::Bare(k), [Token::Bare(name)]) if k == "file" => Note::File(name.clone()),
            (Token::Bare(k), [Token::Bare(file)]) if k == "base" => Note::Base(file.clone()),
            (Token::Bare(k), [Token::Quoted(field)]) if k == "rejects" => {
                Note::Rejects(field.clone())
            }
            _ => {
                return Err(format!(
                    "unknown directive {part:?}: use replace \"A\" with \"B\", ci \"S\", covered-by FILE \"S\", file NAME, base FILE or rejects \"FIELD\""
                ));
            }
        };
        notes.push(note);
    }
    if notes.is_empty() {
        return Err("an empty annotation".into());
    }
    Ok(notes)
}

#[derive(Clone, Debug)]
enum Token {
    Bare(String),
    Quoted(String),
}

fn annotation_tokens(text: &str) -> Result<Vec<Token>, String> {
    let mut tokens = Vec::new();
    let mut chars = text.chars().peekable();
    while let Some(&c) = chars.peek() {
        if c.is_whitespace() {
            chars.next();
        } else if c == '"' {
            chars.next();
            let mut s = String::new();
            loop {
                match chars.next() {
                    Some('"') => break,
                    Some(c) => s.push(c),
                    None => return Err(format!("unclosed quote in {text:?}")),
                }
            }
            tokens.push(Token::Quoted(s));
        } else if c == '(' {
            // A remark for readers: skipped.
            for c in chars.by_ref() {
                if c == ')' {
                    break;
                }
            }
        } else {
            let mut w = String::new();
            while let Some(&c) = chars.peek() {
                if c.is_whitespace() || c == '"' {
                    break;
                }
                w.push(c);
                chars.next();
            }
            tokens.push(Token::Bare(w));
        }
    }
    Ok(tokens)
}

fn split_outside_quotes(text: &str, sep: char) -> Vec<String> {
    let (mut parts, mut cur, mut quoted) = (Vec::new(), String::new(), false);
    for c in text.chars() {
        if c == '"' {
            quoted = !quoted;
        }
        if c == sep && !quoted {
            parts.push(std::mem::take(&mut cur));
        } else {
            cur.push(c);
        }
    }
    parts.push(cur);
    parts.into_iter().filter(|p| !p.trim().is_empty()).collect()
}

// ---------------------------------------------------------------------------------------
// Shell command lines.

/// One command line of a shell block: its `&&`-separated commands (as words) and the exit
/// status its trailing `# exit N` comment expects (0 without one).
struct CommandLine {
    text: String,
    commands: Vec<Vec<String>>,
    /// `|`, `>`, `;` and the like: not run here.
    operators: Vec<String>,
    expect: i32,
}

fn command_lines(body: &str, console: bool) -> Result<Vec<CommandLine>, String> {
    let mut joined: Vec<String> = Vec::new();
    let mut cur = String::new();
    for line in body.lines() {
        let line = if console {
            match line.strip_prefix("$ ") {
                Some(l) => l,
                None if cur.is_empty() => continue,
                None => line,
            }
        } else {
            line
        };
        match line.trim_end().strip_suffix('\\') {
            Some(head) => {
                cur.push_str(head);
                cur.push(' ');
            }
            None => {
                cur.push_str(line);
                joined.push(std::mem::take(&mut cur));
            }
        }
    }
    if !cur.is_empty() {
        joined.push(cur);
    }
    let mut out = Vec::new();
    for line in joined {
        let (code, comment) = split_comment(&line);
        if code.trim().is_empty() {
            continue;
        }
        let expect = comment
            .and_then(|c| {
                let c = c.trim();
                let rest = c
                    .strip_prefix("exits ")
                    .or_else(|| c.strip_prefix("exit "))?;
                rest.split(|ch: char| !ch.is_ascii_digit())
                    .next()?
                    .parse()
                    .ok()
            })
            .unwrap_or(0);
        let (commands, operators) = shell_words(code)?;
        out.push(CommandLine {
            text: code.trim().to_owned(),
            commands,
            operators,
            expect,
        });
    }
    Ok(out)
}

/// The code of a line and its comment (a `#` outside quotes at the start or after a space).
fn split_comment(line: &str) -> (&str, Option<&str>) {
    let (mut single, mut double, mut prev) = (false, false, ' ');
    for (i, c) in line.char_indices() {
        match c {
            '\'' if !double => single = !single,
            '"' if !single => double = !double,
            '#' if !single && !double && prev.is_whitespace() => {
                return (&line[..i], Some(&line[i + 1..]));
            }
            _ => {}
        }
        prev = c;
    }
    (line, None)
}

/// Words of a command line, split into `&&`-separated commands; other operators are
/// returned so the caller can refuse them where it runs the line.
fn shell_words(code: &str) -> Result<(Vec<Vec<String>>, Vec<String>), String> {
    let mut commands = vec![Vec::new()];
    let mut operators = Vec::new();
    let mut word = String::new();
    let mut in_word = false;
    let mut chars = code.chars().peekable();
    let end_word = |word: &mut String, in_word: &mut bool, commands: &mut Vec<Vec<String>>| {
        if *in_word {
            commands
                .last_mut()
                .expect("one command at least")
                .push(std::mem::take(word));
            *in_word = false;
        }
    };
    while let Some(c) = chars.next() {
        match c {
            '\'' => {
                in_word = true;
                loop {
                    match chars.next() {
                        Some('\'') => break,
                        Some(c) => word.push(c),
                        None => return Err(format!("unclosed ' in {code:?}")),
                    }
                }
            }
            '"' => {
                in_word = true;
                loop {
                    match chars.next() {
                        Some('"') => break,
                        Some('\\') => match chars.next() {
                            Some(c @ ('"' | '\\' | '$' | '`')) => word.push(c),
                            Some(c) => {
                                word.push('\\');
                                word.push(c);
                            }
                            None => return Err(format!("unclosed \" in {code:?}")),
                        },
                        Some(c) => word.push(c),
                        None => return Err(format!("unclosed \" in {code:?}")),
                    }
                }
            }
            '\\' => {
                in_word = true;
                if let Some(c) = chars.next() {
                    word.push(c);
                }
            }
            c if c.is_whitespace() => end_word(&mut word, &mut in_word, &mut commands),
            '&' | '|' | ';' | '>' | '<' => {
                end_word(&mut word, &mut in_word, &mut commands);
                let mut op = c.to_string();
                while let Some(&n) = chars.peek() {
                    if matches!(n, '&' | '|' | '>' | '<') {
                        op.push(n);
                        chars.next();
                    } else {
                        break;
                    }
                }
                if op == "&&" {
                    commands.push(Vec::new());
                } else {
                    operators.push(op);
                }
            }
            c => {
                in_word = true;
                word.push(c);
            }
        }
    }
    end_word(&mut word, &mut in_word, &mut commands);
    commands.retain(|c| !c.is_empty());
    Ok((commands, operators))
}

/// What a command is, for the docs test.
enum Kind<'a> {
    /// `foldsynth ARGS` or `cargo run --release -- ARGS`: run with the built binary.
    Foldsynth(&'a [String]),
    /// A C compiler.
    Compiler,
    /// `./program`, built by an earlier command.
    Program,
    /// Anything else (cargo test, python3, bash …): covered by an annotation.
    Other,
}

fn kind(words: &[String]) -> Kind<'_> {
    match words {
        [first, args @ ..] if first == "foldsynth" => Kind::Foldsynth(args),
        [cargo, run, release, dashes, args @ ..]
            if cargo == "cargo" && run == "run" && release == "--release" && dashes == "--" =>
        {
            Kind::Foldsynth(args)
        }
        [first, ..] if first == "cc" || first == "gcc" => Kind::Compiler,
        [first, ..] if first.starts_with("./") => Kind::Program,
        _ => Kind::Other,
    }
}

/// A command as a reader would type it with the binary on PATH, for matching inline spans.
fn normalized(words: &[String]) -> Option<String> {
    match kind(words) {
        Kind::Foldsynth(args) => {
            let mut s = String::from("foldsynth");
            for a in args {
                s.push(' ');
                if a.contains([' ', ',', '(', '\'']) {
                    s.push('"');
                    s.push_str(a);
                    s.push('"');
                } else {
                    s.push_str(a);
                }
            }
            Some(s)
        }
        _ => None,
    }
}

fn collapse(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

// ---------------------------------------------------------------------------------------
// Static checks: subcommands, options, cargo targets.

/// `foldsynth SUB --help` (with `bench X`, two words), cached: the options it lists.
fn help(sub: &[String]) -> Result<String, String> {
    static CACHE: OnceLock<Mutex<HashMap<String, Result<String, String>>>> = OnceLock::new();
    let key = sub.join(" ");
    let cache = CACHE.get_or_init(Default::default);
    if let Some(h) = cache.lock().unwrap_or_else(|e| e.into_inner()).get(&key) {
        return h.clone();
    }
    let out = Command::new(BIN)
        .args(sub)
        .arg("--help")
        .output()
        .map_err(|e| format!("cannot run {BIN}: {e}"))?;
    let result = if out.status.success() {
        Ok(String::from_utf8_lossy(&out.stdout).into_owned())
    } else {
        Err(format!("`foldsynth {key}` is not a subcommand"))
    };
    cache
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .insert(key, result.clone());
    result
}

/// The subcommand words of `args` (`bench` takes a second one).
fn subcommand(args: &[String]) -> &[String] {
    let n = match args.first().map(String::as_str) {
        Some("bench") if args.len() > 1 && !args[1].starts_with('-') => 2,
        Some(_) => 1,
        None => 0,
    };
    &args[..n]
}

/// A foldsynth command names a real subcommand and only options its `--help` lists.
fn check_options(args: &[String]) -> Result<(), String> {
    let sub = subcommand(args);
    if sub.is_empty() || sub[0].starts_with('-') {
        return Ok(());
    }
    let text = help(sub)?;
    for a in &args[sub.len()..] {
        if a == "--" {
            break;
        }
        let Some(name) = a.strip_prefix("--") else {
            continue;
        };
        let flag = format!("--{}", name.split('=').next().unwrap_or(name));
        let listed = text.match_indices(&flag).any(|(i, _)| {
            !text[i + flag.len()..]
                .chars()
                .next()
                .is_some_and(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
        });
        if !listed {
            return Err(format!(
                "`foldsynth {}` has no option {flag} (see its --help)",
                sub.join(" ")
            ));
        }
    }
    Ok(())
}

/// A cargo command names tests, benches, features and packages that exist.
fn check_cargo(words: &[String]) -> Result<(), String> {
    let Some(sub) = words.get(1) else {
        return Err("`cargo` alone".into());
    };
    let known = [
        "build", "check", "test", "clippy", "fmt", "doc", "bench", "run",
    ];
    if !known.contains(&sub.as_str()) {
        return Err(format!(
            "`cargo {sub}`: not a cargo command the docs expect"
        ));
    }
    let root = Path::new(ROOT);
    let manifests = [
        std::fs::read_to_string(root.join("Cargo.toml")).unwrap_or_default(),
        std::fs::read_to_string(root.join("python/Cargo.toml")).unwrap_or_default(),
    ];
    let mut it = words[2..].iter();
    while let Some(w) = it.next() {
        if w == "--" {
            break;
        }
        let value = |it: &mut std::slice::Iter<'_, String>| it.next().cloned().unwrap_or_default();
        match w.as_str() {
            "--test" => {
                let name = value(&mut it);
                if !root.join(format!("tests/{name}.rs")).exists() {
                    return Err(format!("`--test {name}`: there is no tests/{name}.rs"));
                }
            }
            "--bench" => {
                let name = value(&mut it);
                if !root.join(format!("benches/{name}.rs")).exists() {
                    return Err(format!("`--bench {name}`: there is no benches/{name}.rs"));
                }
            }
            "--features" => {
                for f in value(&mut it).split(',') {
                    if !manifests[0].contains(&format!("\n{f} = [")) {
                        return Err(format!("`--features {f}`: Cargo.toml has no such feature"));
                    }
                }
            }
            "-p" | "--package" => {
                let p = value(&mut it);
                if !manifests
                    .iter()
                    .any(|m| m.contains(&format!("name = \"{p}\"")))
                {
                    return Err(format!("`-p {p}`: no such package in the workspace"));
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// Static checks of one command (fenced or inline).
fn check_command(words: &[String]) -> Result<(), String> {
    match (kind(words), words.first().map(String::as_str)) {
        (Kind::Foldsynth(args), _) => check_options(args),
        (_, Some("cargo")) => check_cargo(words),
        _ => Ok(()),
    }
}

// ---------------------------------------------------------------------------------------
// Running a page.

/// The outcome of one page: failures, and what was skipped and why.
#[derive(Default)]
struct Report {
    failures: Vec<String>,
    skipped: Vec<String>,
    /// Commands run and blocks loaded or written.
    ran: usize,
}

fn require_tools() -> bool {
    std::env::var_os("FOLDSYNTH_REQUIRE_DOCS_TOOLS").is_some_and(|v| v == "1")
}

fn tool_exists(name: &str) -> bool {
    Command::new(name)
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success())
}

/// The C compiler `foldsynth compile` links with: `$CC`, else `cc`.
fn c_compiler() -> bool {
    tool_exists(&std::env::var("CC").unwrap_or_else(|_| "cc".into()))
}

/// `foldsynth compile` writing the shared library (its default `--emit all`, or `so`).
fn links_a_library(args: &[String]) -> bool {
    args.first().is_some_and(|s| s == "compile")
        && args
            .iter()
            .position(|a| a == "--emit")
            .and_then(|i| args.get(i + 1))
            .is_none_or(|e| e.split(',').any(|x| x == "so" || x == "all"))
}

fn copy_tree(from: &Path, to: &Path) -> std::io::Result<()> {
    if from.is_dir() {
        std::fs::create_dir_all(to)?;
        for entry in std::fs::read_dir(from)? {
            let entry = entry?;
            copy_tree(&entry.path(), &to.join(entry.file_name()))?;
        }
    } else {
        if let Some(parent) = to.parent() {
            std::fs::create_dir_all(parent)?;
        }
        std::fs::copy(from, to)?;
    }
    Ok(())
}

/// The argument as the page's directory sees it: absolute paths move inside it, and a
/// repository file it names is copied in first.
fn localize(arg: &str, work: &Path) -> String {
    if let Some(rest) = arg.strip_prefix('/') {
        let moved = work.join(rest);
        return moved.to_string_lossy().into_owned();
    }
    let first = arg.split('/').next().unwrap_or("");
    let source = Path::new(ROOT).join(arg);
    if COPIED.contains(&first) && source.exists() && !work.join(arg).exists() {
        let _ = copy_tree(&source, &work.join(arg));
    }
    arg.to_owned()
}

fn tail(bytes: &[u8]) -> String {
    let s = String::from_utf8_lossy(bytes);
    let lines: Vec<&str> = s.lines().collect();
    lines[lines.len().saturating_sub(12)..].join("\n")
}

/// Run one command in `work`; `Err` with the reason when its exit status is not `expect`.
fn run(program: &str, args: &[String], work: &Path, expect: i32) -> Result<(), String> {
    let args: Vec<String> = args.iter().map(|a| localize(a, work)).collect();
    let out = Command::new(program)
        .args(&args)
        .current_dir(work)
        .env_remove("FOLDSYNTH_BIN")
        .output()
        .map_err(|e| format!("cannot run {program}: {e}"))?;
    let code = out.status.code().unwrap_or(-1);
    if code == expect {
        Ok(())
    } else {
        Err(format!(
            "exit status {code}, expected {expect}\n--- stdout (end)\n{}\n--- stderr (end)\n{}",
            tail(&out.stdout),
            tail(&out.stderr)
        ))
    }
}

struct PageRun<'a> {
    page: &'a str,
    work: PathBuf,
    report: Report,
    /// C files written by blocks and not yet compiled by a later shell block.
    c_files: Vec<(String, String)>,
    /// Whether a compile in this page was skipped (its programs are skipped too).
    compiler_missing: bool,
}

impl PageRun<'_> {
    fn fail(&mut self, at: &str, message: impl std::fmt::Display) {
        self.report.failures.push(format!("{at}: {message}"));
    }

    fn block(&mut self, b: &Block) {
        if let Some(name) = b.file() {
            let path = self.work.join(name);
            if let Err(e) = std::fs::write(&path, &b.body) {
                self.fail(&b.at, format!("cannot write {name}: {e}"));
            }
        }
        match b.lang.as_str() {
            l if SHELL.contains(&l) => self.shell(b),
            "toml" => self.toml(b),
            "c" => match b.file() {
                Some(name) => self.c_files.push((name.to_owned(), b.at.clone())),
                None => self.fail(
                    &b.at,
                    "a C block needs `file NAME.c`, compiled and run by a later shell block",
                ),
            },
            "python" if b.notes.iter().any(|n| !matches!(n, Note::Replace(..))) => {
                self.fail(&b.at, "python blocks take only `replace` annotations");
            }
            _ => {}
        }
    }

    fn toml(&mut self, b: &Block) {
        let base = b.notes.iter().find_map(|n| match n {
            Note::Base(f) => Some(f.clone()),
            _ => None,
        });
        let text = match &base {
            None => b.body.clone(),
            Some(file) => match merged(file, &b.body) {
                Ok(t) => t,
                Err(e) => return self.fail(&b.at, e),
            },
        };
        self.report.ran += 1;
        // A fragment of a task file reads its mesh files from that file's folder.
        let dir = match &base {
            Some(file) => Path::new(ROOT)
                .join(file)
                .parent()
                .map_or_else(|| PathBuf::from(ROOT), Path::to_path_buf),
            None => PathBuf::from(ROOT),
        };
        let loaded = foldsynth::task::Task::from_toml_str_in(&text, &b.at, &dir);
        let rejects = b.notes.iter().find_map(|n| match n {
            Note::Rejects(f) => Some(f.clone()),
            _ => None,
        });
        match (loaded, rejects) {
            (Ok(_), None) => {}
            (Err(e), None) => self.fail(&b.at, format!("the task does not load: {e}")),
            (Ok(_), Some(field)) => self.fail(
                &b.at,
                format!("loads, but should be refused naming {field}"),
            ),
            (Err(e), Some(field)) if e.field == field => {}
            (Err(e), Some(field)) => self.fail(
                &b.at,
                format!("refused naming {}, not {field}: {e}", e.field),
            ),
        }
    }

    fn shell(&mut self, b: &Block) {
        let mut body = b.body.clone();
        for (from, to) in b.replacements() {
            if !body.contains(from) {
                return self.fail(&b.at, format!("replace: {from:?} is not in the block"));
            }
            body = body.replace(from, to);
        }
        let lines = match command_lines(&body, b.lang == "console") {
            Ok(l) => l,
            Err(e) => return self.fail(&b.at, e),
        };
        // A C file this block names is compiled here.
        self.c_files
            .retain(|(name, _)| !body.contains(name.as_str()));
        if let Some((file, strings)) = b.covered_by() {
            return self.covered(b, file, strings, &lines);
        }
        let others = lines
            .iter()
            .flat_map(|l| &l.commands)
            .any(|w| matches!(kind(w), Kind::Other));
        for note in &b.notes {
            if let Note::Ci(strings) = note {
                self.ci(b, strings, others);
            }
        }
        for line in &lines {
            self.line(b, line);
        }
    }

    /// `ci "S" …`: the block has commands the test does not run, and `.ci/run` holds each S.
    fn ci(&mut self, b: &Block, strings: &[String], others: bool) {
        if !others {
            return self.fail(&b.at, "`ci`, but every command of the block runs here");
        }
        let script = std::fs::read_to_string(Path::new(ROOT).join(".ci/run")).unwrap_or_default();
        for s in strings {
            if !script.contains(s.as_str()) {
                self.fail(&b.at, format!("ci: .ci/run never says {s:?}"));
            }
        }
    }

    fn covered(&mut self, b: &Block, file: &str, strings: &[String], lines: &[CommandLine]) {
        let text = match std::fs::read_to_string(Path::new(ROOT).join(file)) {
            Ok(t) => t,
            Err(e) => return self.fail(&b.at, format!("covered-by {file}: {e}")),
        };
        let mut wanted: Vec<String> = strings.to_vec();
        for line in lines {
            for words in &line.commands {
                if let Kind::Foldsynth(args) = kind(words) {
                    wanted.extend(subcommand(args).iter().cloned());
                }
            }
        }
        for s in wanted {
            if !text.contains(&s) {
                self.fail(&b.at, format!("covered-by {file}: it never mentions {s:?}"));
            }
        }
    }

    fn line(&mut self, b: &Block, line: &CommandLine) {
        let last = line.commands.len().saturating_sub(1);
        for (k, words) in line.commands.iter().enumerate() {
            let expect = if k == last { line.expect } else { 0 };
            let at = format!("{} `{}`", b.at, line.text);
            match kind(words) {
                Kind::Other => {
                    if !b.has_ci() {
                        return self.fail(
                            &at,
                            format!(
                                "`{}` is not run by the docs test: annotate the block with ci \"…\" or covered-by FILE",
                                words[0]
                            ),
                        );
                    }
                }
                _ if !line.operators.is_empty() => {
                    return self.fail(
                        &at,
                        format!(
                            "{:?}: the docs test runs no pipes, redirections or `;`",
                            line.operators
                        ),
                    );
                }
                Kind::Foldsynth(args) if links_a_library(args) && !c_compiler() => {
                    self.compiler_missing = true;
                    return self.skip_or_fail(&at, "no C compiler ($CC or cc) to link the library");
                }
                Kind::Foldsynth(args) => {
                    self.report.ran += 1;
                    if let Err(e) = run(BIN, args, &self.work, expect) {
                        return self.fail(&at, e);
                    }
                }
                Kind::Compiler => {
                    if !tool_exists(&words[0]) {
                        self.compiler_missing = true;
                        return self.skip_or_fail(&at, &format!("no `{}` on PATH", words[0]));
                    }
                    self.report.ran += 1;
                    if let Err(e) = run(&words[0], &words[1..], &self.work, expect) {
                        return self.fail(&at, e);
                    }
                }
                Kind::Program => {
                    if self.compiler_missing {
                        return self.skip_or_fail(&at, "its compile was skipped");
                    }
                    let program = self.work.join(&words[0]);
                    let program = program.to_string_lossy().into_owned();
                    self.report.ran += 1;
                    if let Err(e) = run(&program, &words[1..], &self.work, expect) {
                        return self.fail(&at, e);
                    }
                }
            }
        }
    }

    fn skip_or_fail(&mut self, at: &str, why: &str) {
        if require_tools() {
            self.fail(at, format!("{why} (FOLDSYNTH_REQUIRE_DOCS_TOOLS=1)"));
        } else {
            self.report.skipped.push(format!("{at}: skipped: {why}"));
        }
    }
}

/// `fragment` merged into the task file `base` (tables merged key by key, other values
/// replaced), as TOML text.
fn merged(base: &str, fragment: &str) -> Result<String, String> {
    let text = std::fs::read_to_string(Path::new(ROOT).join(base))
        .map_err(|e| format!("base {base}: {e}"))?;
    let mut table: toml::Table = text.parse().map_err(|e| format!("base {base}: {e}"))?;
    let part: toml::Table = fragment.parse().map_err(|e| format!("not TOML: {e}"))?;
    fn merge(into: &mut toml::Table, from: toml::Table) {
        for (k, v) in from {
            match (into.get_mut(&k), v) {
                (Some(toml::Value::Table(a)), toml::Value::Table(b)) => merge(a, b),
                (_, v) => {
                    into.insert(k, v);
                }
            }
        }
    }
    merge(&mut table, part);
    toml::to_string(&table).map_err(|e| e.to_string())
}

fn run_page(page: &Page) -> Report {
    let parsed = parse(page);
    let dir = tempfile::tempdir().expect("a temporary directory");
    let mut r = PageRun {
        page: &page.path,
        work: dir.path().to_owned(),
        report: Report::default(),
        c_files: Vec::new(),
        compiler_missing: false,
    };
    r.report.failures.extend(parsed.errors);
    if let Err(e) = copy_tree(&Path::new(ROOT).join("grammar"), &r.work.join("grammar")) {
        r.fail(r.page, format!("cannot copy grammar/: {e}"));
    }
    for b in &parsed.blocks {
        r.block(b);
    }
    for (name, at) in std::mem::take(&mut r.c_files) {
        let at = if at.is_empty() { r.page.to_owned() } else { at };
        r.fail(
            &at,
            format!("{name} is never compiled by a later shell block"),
        );
    }
    r.report
}

// ---------------------------------------------------------------------------------------
// The tests.

#[test]
fn the_readme_is_a_front_door() {
    let n = std::fs::metadata(Path::new(ROOT).join("README.md"))
        .expect("README.md")
        .len() as usize;
    assert!(
        n <= README_MAX_BYTES,
        "README.md is {n} bytes; the goal is at most {README_MAX_BYTES}: move detail to docs/"
    );
}

#[test]
fn every_code_block_is_run_or_covered() {
    let pages = pages();
    let reports: Vec<(String, Report)> = std::thread::scope(|s| {
        let handles: Vec<_> = pages
            .iter()
            .map(|p| (p.path.clone(), s.spawn(move || run_page(p))))
            .collect();
        handles
            .into_iter()
            .map(|(path, h)| (path, h.join().expect("a page's thread")))
            .collect()
    });
    let mut failures = Vec::new();
    for (path, report) in reports {
        for s in &report.skipped {
            eprintln!("docs: {s}");
        }
        if report.failures.is_empty() {
            eprintln!(
                "docs: {path}: every block ran or is covered ({} commands and task files)",
                report.ran
            );
        }
        failures.extend(report.failures);
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n\n"));
}

/// Inline code spans of a paragraph (backticks; a span may cross a line break).
fn inline_spans(paragraph: &str) -> Vec<String> {
    let mut spans = Vec::new();
    let mut rest = paragraph;
    while let Some(open) = rest.find('`') {
        let ticks = rest[open..].chars().take_while(|&c| c == '`').count();
        let fence = "`".repeat(ticks);
        let after = &rest[open + ticks..];
        let Some(close) = after.find(&fence) else {
            break;
        };
        spans.push(collapse(&after[..close].replace('\n', " ")));
        rest = &after[close + ticks..];
    }
    spans
}

/// A word that stands for a value the reader supplies (`TASK`, `OUT/…`, `K/N`) or a
/// synopsis' brackets, alternatives and ellipses.
fn is_placeholder(word: &str) -> bool {
    word.contains(['…', '[', ']', '|', '<', '>'])
        || word
            .split(['/', ',', '.', '=', ':'])
            .any(|p| !p.is_empty() && p.chars().all(|c| c.is_ascii_uppercase()))
}

#[test]
fn every_command_shown_names_real_options_and_runs() {
    let mut failures = Vec::new();
    let mut run_commands: Vec<String> = Vec::new();
    let mut inline: Vec<(String, String)> = Vec::new();
    for page in pages() {
        let parsed = parse(&page);
        for b in parsed
            .blocks
            .iter()
            .filter(|b| SHELL.contains(&b.lang.as_str()))
        {
            let lines = match command_lines(&b.body, b.lang == "console") {
                Ok(l) => l,
                Err(e) => {
                    failures.push(format!("{}: {e}", b.at));
                    continue;
                }
            };
            for line in &lines {
                for words in &line.commands {
                    if let Err(e) = check_command(words) {
                        failures.push(format!("{} `{}`: {e}", b.at, line.text));
                    }
                    if b.covered_by().is_none()
                        && let Some(n) = normalized(words)
                    {
                        run_commands.push(collapse(&n));
                    }
                }
            }
        }
        for p in &parsed.prose {
            for span in inline_spans(p) {
                if span.starts_with("foldsynth ") || span.starts_with("cargo ") {
                    inline.push((page.path.clone(), span));
                }
            }
        }
    }
    for (path, span) in inline {
        let words: Vec<String> = match shell_words(&span) {
            Ok((mut c, _)) if c.len() == 1 => c.remove(0),
            _ => span.split_whitespace().map(str::to_owned).collect(),
        };
        let synopsis = words.iter().any(|w| is_placeholder(w));
        let words: Vec<String> = words.into_iter().filter(|w| !is_placeholder(w)).collect();
        // A synopsis' options are checked; its cargo targets are placeholders.
        let checked = match kind(&words) {
            Kind::Foldsynth(args) => check_options(args),
            _ if synopsis => Ok(()),
            _ => check_command(&words),
        };
        if let Err(e) = checked {
            failures.push(format!("{path}: `{span}`: {e}"));
        }
        if !synopsis && span.starts_with("foldsynth ") {
            let shown = normalized(&words).map(|s| collapse(&s)).unwrap_or_default();
            if !run_commands.iter().any(|c| c.contains(&shown)) {
                failures.push(format!(
                    "{path}: `{span}` is a complete command that no run block of the docs contains: show it in a block (or write its placeholders in capitals)"
                ));
            }
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

#[test]
fn python_blocks_are_run_by_pytest() {
    let script = Path::new(ROOT).join("python/tests/test_docs.py");
    let text = std::fs::read_to_string(&script).unwrap_or_default();
    let mut failures = Vec::new();
    if !["README.md", "CONTRIBUTING.md", "docs"]
        .iter()
        .all(|n| text.contains(n))
    {
        failures.push(format!(
            "{}: must read README.md, CONTRIBUTING.md and docs/ (it runs every python block)",
            script.display()
        ));
    }
    let blocks: usize = pages()
        .iter()
        .map(|p| {
            parse(p)
                .blocks
                .iter()
                .filter(|b| b.lang == "python")
                .count()
        })
        .sum();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert!(
        blocks > 0,
        "the docs show the Python package: at least one python block"
    );
}

#[test]
fn every_block_has_a_known_kind() {
    // Fences in runnable languages are handled above; an unknown spelling of one (`shell`
    // is fine, `Bash` is lowered) would slip through as an output sample.
    let aliases = ["py", "python3", "zsh", "toml-fragment", "cpp", "h"];
    let mut failures = Vec::new();
    for page in pages() {
        for b in parse(&page).blocks {
            if aliases.contains(&b.lang.as_str()) {
                failures.push(format!(
                    "{}: `{}`: write it as one of {RUNNABLE:?}",
                    b.at, b.lang
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// GitHub's anchor of a heading.
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
            _ => None,
        })
        .collect()
}

fn anchors(text: &str) -> Vec<String> {
    let mut seen: HashMap<String, usize> = HashMap::new();
    let mut out = Vec::new();
    let mut in_fence = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            in_fence = !in_fence;
            continue;
        }
        if in_fence {
            continue;
        }
        let Some(h) = line.strip_prefix('#') else {
            continue;
        };
        let base = slug(h.trim_start_matches('#'));
        let n = seen.entry(base.clone()).or_insert(0);
        out.push(if *n == 0 {
            base.clone()
        } else {
            format!("{base}-{n}")
        });
        *n += 1;
    }
    out
}

/// `[text](target)` links of a paragraph, code spans left out.
fn links(paragraph: &str) -> Vec<String> {
    let mut text = String::new();
    let mut code = false;
    for c in paragraph.chars() {
        if c == '`' {
            code = !code;
        } else if !code {
            text.push(c);
        }
    }
    let mut out = Vec::new();
    let mut rest = text.as_str();
    while let Some(i) = rest.find("](") {
        let after = &rest[i + 2..];
        let Some(end) = after.find(')') else {
            break;
        };
        out.push(after[..end].trim().to_owned());
        rest = &after[end..];
    }
    out
}

#[test]
fn relative_links_resolve() {
    let mut failures = Vec::new();
    let root = Path::new(ROOT);
    for page in pages() {
        let dir = root.join(&page.path);
        let dir = dir.parent().unwrap_or(root);
        for p in parse(&page).prose {
            for link in links(&p) {
                if link.contains("://") || link.starts_with("mailto:") {
                    continue;
                }
                let (file, anchor) = match link.split_once('#') {
                    Some((f, a)) => (f, Some(a)),
                    None => (link.as_str(), None),
                };
                let target = if file.is_empty() {
                    root.join(&page.path)
                } else {
                    dir.join(file)
                };
                if !target.exists() {
                    failures.push(format!("{}: link {link}: no such file", page.path));
                    continue;
                }
                if let Some(a) = anchor
                    && target.extension().is_some_and(|e| e == "md")
                {
                    let text = std::fs::read_to_string(&target).unwrap_or_default();
                    if !anchors(&text).iter().any(|h| h == a) {
                        failures.push(format!("{}: link {link}: no heading #{a}", page.path));
                    }
                }
            }
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}
