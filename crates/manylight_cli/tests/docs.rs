//! Keeps the docs honest against the code, with the `manylight` binary only (no GPU, no
//! network, nothing rendered):
//!
//! - every `manylight …` command line in README.md and docs/*.md (fenced blocks and inline code,
//!   `cargo run … --bin manylight -- …`, the `manylight` shell helper of docs/benchmarks.md, spans
//!   that start with a subcommand, and flag fragments such as "(and `--shadows off`)" after a
//!   command of the same paragraph) parses: it is run with `--help` appended, which clap accepts
//!   only after every subcommand, flag and value before it parsed;
//! - every alternative of a documented `--flag a|b` is a value the flag takes, and README's lists
//!   of alternatives in "The `manylight` command" are the code's lists, neither more nor fewer;
//! - counts the docs state ("six pipelines", "three G-buffer layouts", …) are the code's counts;
//! - README's command section names every subcommand of `manylight --help`;
//! - every relative link in README.md, CHANGELOG.md and docs/*.md reaches a file, and its
//!   `#anchor` a heading of that file.
//!
//! Doc conventions understood: `a|b` inside a value (alternatives; the first stands for the
//! command, each is checked as a value), placeholders (`N`, `WxH`, `XxYxZ`, `PATH`, `<Name>`;
//! strings such as `OUT.png` pass as they are), `…`, env-var prefixes, redirections, pipes, `;`
//! and `&&`, `for`/`set --` loops and their variables, `\` continuations, and inline code split
//! across the lines of a paragraph.

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, OnceLock};

/// The repository root.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Runs the binary; returns (exit code, stdout, stderr).
fn manylight(args: &[String]) -> (Option<i32>, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_manylight"))
        .args(args)
        .env("NO_COLOR", "1")
        .env_remove("CLICOLOR_FORCE")
        .output()
        .expect("the manylight binary runs");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn strings(args: &[&str]) -> Vec<String> {
    args.iter().map(|s| s.to_string()).collect()
}

// ---------------------------------------------------------------------------------------------
// What the binary says about itself

struct Cli {
    /// Subcommands of `manylight --help`, without `help`.
    subcommands: Vec<String>,
    /// Long flags (`--name`) of each subcommand, and of the top level under "".
    flags: BTreeMap<String, BTreeSet<String>>,
}

fn cli() -> &'static Cli {
    static CLI: OnceLock<Cli> = OnceLock::new();
    CLI.get_or_init(|| {
        let (code, help, err) = manylight(&strings(&["--help"]));
        assert_eq!(code, Some(0), "`manylight --help` failed:\n{err}");
        let mut subcommands = Vec::new();
        let mut in_commands = false;
        for line in help.lines() {
            if line.trim_end() == "Commands:" {
                in_commands = true;
            } else if in_commands {
                if line.trim().is_empty() || !line.starts_with(' ') {
                    break;
                }
                // "  name   description"; wrapped description lines are indented further.
                if line.starts_with("  ") && !line.starts_with("   ") {
                    let name = line.split_whitespace().next().expect("a name");
                    if name != "help" {
                        subcommands.push(name.to_string());
                    }
                }
            }
        }
        assert!(
            subcommands.len() >= 5 && subcommands.iter().any(|s| s == "render"),
            "could not read the subcommands from `manylight --help`:\n{help}"
        );
        let mut flags = BTreeMap::new();
        flags.insert(String::new(), help_flags(&help));
        for sub in &subcommands {
            let (code, help, err) = manylight(&strings(&[sub, "--help"]));
            assert_eq!(code, Some(0), "`manylight {sub} --help` failed:\n{err}");
            flags.insert(sub.clone(), help_flags(&help));
        }
        Cli { subcommands, flags }
    })
}

/// The long flags an option list of `--help` names.
fn help_flags(help: &str) -> BTreeSet<String> {
    let mut flags = BTreeSet::new();
    for line in help.lines() {
        let t = line.trim_start();
        let t =
            if t.starts_with('-') && t.as_bytes().get(2) == Some(&b',') { t[3..].trim_start() } else { t };
        if let Some(rest) = t.strip_prefix("--") {
            let name: String =
                rest.chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '-' || *c == '_').collect();
            if !name.is_empty() {
                flags.insert(format!("--{name}"));
            }
        }
    }
    flags
}

/// The values `manylight <sub> <flag> …` accepts, read from the value parser's error for a value
/// that is none of them ("expected one of: a, b", "[possible values: a, b]" or "expected on or
/// off"); `None` when the error names no list (free strings, numbers).
fn accepted_values(sub: &str, flag: &str) -> Option<Vec<String>> {
    type Cache = Mutex<HashMap<(String, String), Option<Vec<String>>>>;
    static CACHE: OnceLock<Cache> = OnceLock::new();
    let cache = CACHE.get_or_init(Default::default);
    if let Some(v) = cache.lock().unwrap().get(&(sub.to_string(), flag.to_string())) {
        return v.clone();
    }
    let (_, _, err) = manylight(&strings(&[sub, flag, "__not_a_value__", "--help"]));
    // `manylight_app::cli`'s parsers, then clap's own possible values.
    let list =
        [("expected one of: ", ')'), ("[possible values: ", ']')].into_iter().find_map(|(start, end)| {
            let rest = &err[err.find(start)? + start.len()..];
            Some(rest[..rest.find(end).unwrap_or(rest.len())].to_string())
        });
    let values = if let Some(list) = list {
        Some(list.split(',').map(|s| s.trim().to_string()).filter(|s| !s.is_empty()).collect())
    } else if err.contains("expected on or off") {
        Some(strings(&["on", "off"]))
    } else {
        None
    };
    cache.lock().unwrap().insert((sub.to_string(), flag.to_string()), values.clone());
    values
}

// ---------------------------------------------------------------------------------------------
// Markdown

struct Doc {
    /// Path from the repository root, with `/`.
    rel: String,
    lines: Vec<String>,
}

impl Doc {
    fn read(rel: &str) -> Doc {
        let path = root().join(rel);
        let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        Doc { rel: rel.to_string(), lines: text.lines().map(str::to_string).collect() }
    }

    fn dir(&self) -> PathBuf {
        root().join(&self.rel).parent().expect("a parent").to_path_buf()
    }
}

/// README.md, CHANGELOG.md (with `changelog`) and docs/*.md, sorted.
fn docs(changelog: bool) -> Vec<Doc> {
    let mut rels = vec!["README.md".to_string()];
    if changelog {
        rels.push("CHANGELOG.md".to_string());
    }
    let mut md: Vec<String> = std::fs::read_dir(root().join("docs"))
        .expect("docs/")
        .map(|e| e.expect("dir entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .map(|p| format!("docs/{}", p.file_name().unwrap().to_string_lossy()))
        .collect();
    md.sort();
    rels.extend(md);
    rels.iter().map(|r| Doc::read(r)).collect()
}

enum Block {
    /// A fenced code block: its info string's first word, (1-based line, text) of its lines and
    /// the level-2 heading above it.
    Code { lang: String, lines: Vec<(usize, String)>, section: String },
    /// A paragraph, list item, table row or heading, its lines joined with spaces.
    Para(Para),
}

struct Para {
    text: String,
    /// (byte offset in `text`, 1-based line) of each joined line.
    starts: Vec<(usize, usize)>,
    /// The level-2 heading above it.
    section: String,
}

impl Para {
    fn line_at(&self, offset: usize) -> usize {
        let i = self.starts.partition_point(|&(o, _)| o <= offset);
        self.starts[i.saturating_sub(1)].1
    }
}

fn fence(line: &str) -> Option<(char, usize, &str)> {
    let t = line.trim_start();
    let c = t.chars().next()?;
    if c != '`' && c != '~' {
        return None;
    }
    let n = t.chars().take_while(|&x| x == c).count();
    (n >= 3).then(|| (c, n, t[n..].trim()))
}

fn blocks(doc: &Doc) -> Vec<Block> {
    let mut out = Vec::new();
    let mut section = String::new();
    let mut para: Option<Para> = None;
    let flush = |para: &mut Option<Para>, out: &mut Vec<Block>| {
        if let Some(p) = para.take() {
            out.push(Block::Para(p));
        }
    };
    let mut i = 0;
    while i < doc.lines.len() {
        let line = &doc.lines[i];
        let t = line.trim_start();
        if let Some((c, n, info)) = fence(line) {
            flush(&mut para, &mut out);
            let lang = info.split_whitespace().next().unwrap_or("").to_lowercase();
            let mut lines = Vec::new();
            i += 1;
            while i < doc.lines.len() {
                if let Some((c2, n2, rest)) = fence(&doc.lines[i])
                    && c2 == c
                    && n2 >= n
                    && rest.is_empty()
                {
                    break;
                }
                lines.push((i + 1, doc.lines[i].clone()));
                i += 1;
            }
            out.push(Block::Code { lang, lines, section: section.clone() });
            i += 1;
            continue;
        }
        if t.is_empty() {
            flush(&mut para, &mut out);
            i += 1;
            continue;
        }
        let heading = t.starts_with('#');
        if heading && t.starts_with("## ") {
            section = t.to_string();
        }
        let item = t.starts_with("- ")
            || t.starts_with("* ")
            || t.starts_with("+ ")
            || t.starts_with('|')
            || t.starts_with('>')
            || (t.chars().next().is_some_and(|c| c.is_ascii_digit())
                && t.trim_start_matches(|c: char| c.is_ascii_digit()).starts_with(". "));
        if heading || item {
            flush(&mut para, &mut out);
        }
        let p = para.get_or_insert_with(|| Para {
            text: String::new(),
            starts: Vec::new(),
            section: section.clone(),
        });
        if !p.text.is_empty() {
            p.text.push(' ');
        }
        p.starts.push((p.text.len(), i + 1));
        p.text.push_str(t.trim_end());
        if heading {
            flush(&mut para, &mut out);
        }
        i += 1;
    }
    flush(&mut para, &mut out);
    out
}

/// Inline code spans of a paragraph: (offset of the opening backticks, end offset after the
/// closing ones, content).
fn code_spans(text: &str) -> Vec<(usize, usize, String)> {
    let b = text.as_bytes();
    let mut spans = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if b[i] != b'`' {
            i += 1;
            continue;
        }
        let n = b[i..].iter().take_while(|&&c| c == b'`').count();
        let mut j = i + n;
        let mut close = None;
        while j < b.len() {
            if b[j] == b'`' {
                let m = b[j..].iter().take_while(|&&c| c == b'`').count();
                if m == n {
                    close = Some(j);
                    break;
                }
                j += m;
            } else {
                j += 1;
            }
        }
        match close {
            Some(j) => {
                let mut content = &text[i + n..j];
                if content.len() >= 2
                    && content.starts_with(' ')
                    && content.ends_with(' ')
                    && !content.trim().is_empty()
                {
                    content = &content[1..content.len() - 1];
                }
                spans.push((i, j + n, content.to_string()));
                i = j + n;
            }
            None => i += n,
        }
    }
    spans
}

// ---------------------------------------------------------------------------------------------
// Shell words

#[derive(Clone, Debug, PartialEq)]
enum Tok {
    Word(String),
    /// `;`, `&&`, `||`, `|`, `&`.
    Sep,
}

/// Splits a command line into words and separators, shell-like: quotes, `$(…)` and `${…}` kept
/// in their word, redirections dropped, `#` starting a word ends the line (the comment is
/// returned). A `|` inside a word is a doc's alternatives, not a pipe.
fn shell_words(s: &str) -> (Vec<Tok>, Option<String>) {
    let c: Vec<char> = s.chars().collect();
    let mut toks = Vec::new();
    let mut word = String::new();
    let mut in_word = false;
    let mut i = 0;
    let end_word = |word: &mut String, in_word: &mut bool, toks: &mut Vec<Tok>| {
        if *in_word {
            toks.push(Tok::Word(std::mem::take(word)));
            *in_word = false;
        }
    };
    while i < c.len() {
        let ch = c[i];
        match ch {
            ' ' | '\t' => {
                end_word(&mut word, &mut in_word, &mut toks);
                i += 1;
            }
            '#' if !in_word => {
                let comment: String = c[i + 1..].iter().collect();
                end_word(&mut word, &mut in_word, &mut toks);
                return (toks, Some(comment));
            }
            '\'' => {
                in_word = true;
                i += 1;
                while i < c.len() && c[i] != '\'' {
                    word.push(c[i]);
                    i += 1;
                }
                i += 1;
            }
            '"' => {
                in_word = true;
                i += 1;
                while i < c.len() && c[i] != '"' {
                    if c[i] == '\\' && i + 1 < c.len() {
                        i += 1;
                    }
                    word.push(c[i]);
                    i += 1;
                }
                i += 1;
            }
            '\\' if i + 1 < c.len() => {
                in_word = true;
                word.push(c[i + 1]);
                i += 2;
            }
            '$' if i + 1 < c.len() && (c[i + 1] == '(' || c[i + 1] == '{') => {
                in_word = true;
                let (open, close) = if c[i + 1] == '(' { ('(', ')') } else { ('{', '}') };
                let mut depth = 0;
                while i < c.len() {
                    word.push(c[i]);
                    if c[i] == open {
                        depth += 1;
                    } else if c[i] == close {
                        depth -= 1;
                        if depth == 0 {
                            i += 1;
                            break;
                        }
                    }
                    i += 1;
                }
            }
            ';' => {
                end_word(&mut word, &mut in_word, &mut toks);
                toks.push(Tok::Sep);
                i += 1;
            }
            '&' | '|' => {
                let double = c.get(i + 1) == Some(&ch);
                let after = if double { i + 2 } else { i + 1 };
                let space_after = after >= c.len() || c[after] == ' ' || c[after] == '\t';
                if double || (!in_word && (ch == '&' || space_after)) {
                    // `&&`, `||`, `&`, a `|` on its own: a pipe, not a doc's alternatives.
                    end_word(&mut word, &mut in_word, &mut toks);
                    toks.push(Tok::Sep);
                    i = after;
                } else {
                    in_word = true;
                    word.push(ch);
                    i += 1;
                }
            }
            '>' | '<' => {
                // `<Name>` placeholders are words; `>`, `>>`, `2>`, `&>`, `< file` redirect.
                let placeholder =
                    ch == '<' && !in_word && c[i + 1..].iter().take_while(|&&x| x != ' ').any(|&x| x == '>');
                if placeholder || (in_word && !word.chars().all(|d| d.is_ascii_digit() || d == '&')) {
                    in_word = true;
                    word.push(ch);
                    i += 1;
                    continue;
                }
                word.clear();
                in_word = false;
                i += 1;
                while i < c.len() && (c[i] == '>' || c[i] == '&' || c[i] == '|') {
                    i += 1;
                }
                while i < c.len() && (c[i] == ' ' || c[i] == '\t') {
                    i += 1;
                }
                // The target (`&1` or a file name).
                while i < c.len() && c[i] != ' ' && c[i] != '\t' && c[i] != ';' {
                    i += 1;
                }
            }
            _ => {
                in_word = true;
                word.push(ch);
                i += 1;
            }
        }
    }
    end_word(&mut word, &mut in_word, &mut toks);
    (toks, None)
}

/// Expands `$name`, `${name}` (from `vars`, else a placeholder) and `$(…)` (a placeholder).
fn expand(word: &str, vars: &HashMap<String, String>) -> String {
    let c: Vec<char> = word.chars().collect();
    let mut out = String::new();
    let mut i = 0;
    while i < c.len() {
        if c[i] != '$' || i + 1 >= c.len() {
            out.push(c[i]);
            i += 1;
            continue;
        }
        let (name, next) = if c[i + 1] == '(' {
            let mut depth = 0;
            let mut j = i + 1;
            while j < c.len() {
                if c[j] == '(' {
                    depth += 1;
                } else if c[j] == ')' {
                    depth -= 1;
                    if depth == 0 {
                        break;
                    }
                }
                j += 1;
            }
            (None, j + 1)
        } else if c[i + 1] == '{' {
            let j = (i + 2..c.len()).find(|&j| c[j] == '}').unwrap_or(c.len());
            (Some(c[i + 2..j].iter().collect::<String>()), j + 1)
        } else if c[i + 1].is_ascii_digit() || c[i + 1] == '@' || c[i + 1] == '*' {
            (Some(c[i + 1].to_string()), i + 2)
        } else {
            let j =
                (i + 1..c.len()).find(|&j| !(c[j].is_ascii_alphanumeric() || c[j] == '_')).unwrap_or(c.len());
            if j == i + 1 {
                out.push('$');
                i += 1;
                continue;
            }
            (Some(c[i + 1..j].iter().collect::<String>()), j)
        };
        match name.and_then(|n| vars.get(&n).cloned()) {
            Some(v) => out.push_str(&v),
            None => out.push('1'),
        }
        i = next;
    }
    out
}

// ---------------------------------------------------------------------------------------------
// Commands in the docs

/// Programs other than `manylight` whose command lines and flag fragments are not checked.
const OTHER_PROGRAMS: &[&str] = &[
    "cargo",
    "stress",
    "python3",
    "python",
    "git",
    "xvfb-run",
    "Xvfb",
    "bash",
    "sh",
    "rustup",
    "apt-get",
    "sudo",
    "scripts/setup.sh",
    "./scripts/setup.sh",
    "time",
    "/usr/bin/time",
];

/// Flags of cargo and the test harness that prose names without their command (a flag named
/// without any command must otherwise be one of `manylight`'s).
const OTHER_PROGRAMS_FLAGS: &[&str] = &[
    "--test",
    "--release",
    "--example",
    "--examples",
    "--workspace",
    "--package",
    "--bin",
    "--lib",
    "--features",
    "--all-targets",
    "--nocapture",
    "--ignored",
    "--include-ignored",
    "--test-threads",
    "--exact",
    "--no-run",
    "--doc",
];

enum Seg {
    /// `manylight` with these arguments.
    Manylight(Vec<String>),
    /// Words that start with a flag.
    Fragment(Vec<String>),
    /// Another program's command line.
    Other,
    Nothing,
}

fn classify(words: &[String], subs: &[String]) -> Seg {
    let Some(first) = words.first() else { return Seg::Nothing };
    if words.iter().any(|w| w.contains("manylight()")) {
        return Seg::Nothing; // the shell helper's definition
    }
    if let Some(c) = words.iter().position(|w| w == "cargo") {
        let words = &words[c..];
        let runs_cli = words.iter().any(|w| w == "run")
            && !words.iter().any(|w| w == "--example")
            && words.windows(2).any(|p| {
                (p[0] == "--bin" && p[1] == "manylight")
                    || ((p[0] == "-p" || p[0] == "--package") && p[1] == "manylight_cli")
            });
        if !runs_cli {
            return Seg::Other;
        }
        return match words.iter().position(|w| w == "--") {
            Some(i) => Seg::Manylight(words[i + 1..].to_vec()),
            None => Seg::Manylight(Vec::new()),
        };
    }
    if let Some(i) = words.iter().position(|w| w == "manylight" || w.ends_with("/manylight")) {
        return Seg::Manylight(words[i + 1..].to_vec());
    }
    if subs.iter().any(|s| s == first) {
        return Seg::Manylight(words.to_vec());
    }
    if first.starts_with("--") {
        return Seg::Fragment(words.to_vec());
    }
    if OTHER_PROGRAMS.contains(&first.as_str()) {
        return Seg::Other;
    }
    Seg::Nothing
}

/// Where a command came from, for messages.
#[derive(Clone, Debug)]
struct Loc {
    file: String,
    line: usize,
    section: String,
}

impl std::fmt::Display for Loc {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}:{}", self.file, self.line)
    }
}

#[derive(Clone, Debug)]
struct DocCommand {
    loc: Loc,
    /// The text as the doc writes it.
    text: String,
    /// The arguments as the doc writes them (variables expanded, redirections dropped).
    raw: Vec<String>,
    /// For a fragment (`raw` starts with a flag): the subcommands it may belong to (that of the
    /// command before it in its paragraph, else each that has its flags); it must parse under
    /// one of them.
    under: Vec<String>,
    /// The doc says the argument parser refuses it ("exit 2"): it must be refused for a value
    /// of a flag that exists, not parse.
    refused: bool,
}

/// Flags named without a command to check them against (in prose without a command before
/// them, or in a comment under one): each must be a flag of `sub` (or of any subcommand).
#[derive(Clone, Debug)]
struct FlagMention {
    loc: Loc,
    text: String,
    sub: Option<String>,
    flags: Vec<String>,
}

#[derive(Default)]
struct Found {
    commands: Vec<DocCommand>,
    mentions: Vec<FlagMention>,
}

fn flags_in(text: &str) -> Vec<String> {
    let mut flags = Vec::new();
    for w in text.split(|c: char| c.is_whitespace() || c == '(' || c == '`' || c == '"' || c == '\'') {
        if let Some(rest) = w.strip_prefix("--") {
            let name: String = rest.chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '-').collect();
            let name = name.trim_end_matches('-');
            if !name.is_empty() {
                flags.push(format!("--{name}"));
            }
        }
    }
    flags
}

fn words_of(toks: &[Tok]) -> Vec<Vec<String>> {
    let mut segs = vec![Vec::new()];
    for t in toks {
        match t {
            Tok::Sep => segs.push(Vec::new()),
            Tok::Word(w) => segs.last_mut().unwrap().push(w.clone()),
        }
    }
    segs.retain(|s| !s.is_empty());
    segs
}

fn is_assignment(w: &str) -> bool {
    match w.split_once('=') {
        Some((name, _)) => {
            !name.is_empty()
                && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
                && !name.starts_with(|c: char| c.is_ascii_digit())
        }
        None => false,
    }
}

/// Strips keywords and env-var prefixes from a simple command; handles `for` and `set --`.
/// Returns the words left to classify.
fn simple_command(mut seg: Vec<String>, vars: &mut HashMap<String, String>) -> Vec<String> {
    while seg.first().is_some_and(|w| matches!(w.as_str(), "do" | "then" | "else" | "{" | "(" | "!")) {
        seg.remove(0);
    }
    match seg.first().map(String::as_str) {
        None | Some("done" | "fi" | "}" | ")") => return Vec::new(),
        Some("for") => {
            if seg.len() >= 4 && seg[2] == "in" {
                vars.insert(seg[1].clone(), expand(&seg[3], vars));
            }
            return Vec::new();
        }
        Some("set") if seg.get(1).is_some_and(|w| w == "--") => {
            let values: Vec<String> = seg[2..].iter().map(|w| expand(w, vars)).collect();
            for (i, v) in values.join(" ").split_whitespace().enumerate() {
                vars.insert((i + 1).to_string(), v.to_string());
            }
            return Vec::new();
        }
        _ => {}
    }
    while seg.first().is_some_and(|w| is_assignment(w)) {
        seg.remove(0);
    }
    seg.iter().map(|w| expand(w, vars)).collect()
}

fn find_commands(doc: &Doc) -> Found {
    let subs = &cli().subcommands;
    let mut found = Found::default();
    for block in blocks(doc) {
        match block {
            Block::Code { lang, lines, section } => {
                if !matches!(lang.as_str(), "" | "sh" | "bash" | "shell" | "console" | "zsh") {
                    continue;
                }
                let mut vars = HashMap::new();
                let mut context: Option<String> = None;
                let mut k = 0;
                while k < lines.len() {
                    let (line_no, mut text) = lines[k].clone();
                    while text.trim_end().ends_with('\\') && k + 1 < lines.len() {
                        let t = text.trim_end();
                        text = format!("{} {}", &t[..t.len() - 1], lines[k + 1].1.trim_start());
                        k += 1;
                    }
                    k += 1;
                    let text = text.trim().trim_start_matches("$ ").to_string();
                    let loc = Loc { file: doc.rel.clone(), line: line_no, section: section.clone() };
                    let (toks, comment) = shell_words(&text);
                    for seg in words_of(&toks) {
                        let words = simple_command(seg, &mut vars);
                        // A block without a language may be a diagram: there a command must
                        // start the line.
                        let starts_a_command = words.first().is_some_and(|w| {
                            w == "manylight"
                                || w.ends_with("/manylight")
                                || OTHER_PROGRAMS.contains(&w.as_str())
                        });
                        if (!lang.is_empty() || starts_a_command)
                            && let Seg::Manylight(args) = classify(&words, subs)
                            && !args.is_empty()
                        {
                            context = args.first().filter(|a| subs.contains(a)).cloned();
                            found.commands.push(DocCommand {
                                loc: loc.clone(),
                                text: text.clone(),
                                raw: args,
                                under: Vec::new(),
                                refused: false,
                            });
                        }
                    }
                    // Flags named in a comment under a `manylight` command of this block.
                    if let (Some(comment), Some(sub)) = (comment, &context) {
                        let flags = flags_in(&comment);
                        if !flags.is_empty() {
                            found.mentions.push(FlagMention {
                                loc,
                                text: format!("# {}", comment.trim()),
                                sub: Some(sub.clone()),
                                flags,
                            });
                        }
                    }
                }
            }
            Block::Para(p) => {
                let mut segs = Vec::new();
                for (offset, _, span) in code_spans(&p.text) {
                    let loc =
                        Loc { file: doc.rel.clone(), line: p.line_at(offset), section: p.section.clone() };
                    let (toks, _) = shell_words(&span);
                    let mut vars = HashMap::new();
                    for seg in words_of(&toks) {
                        let words = simple_command(seg, &mut vars);
                        segs.push((loc.clone(), span.clone(), classify(&words, subs)));
                    }
                }
                // What a fragment belongs to: `Some(Some(sub))` after a `manylight sub` command
                // of the paragraph ("(and `--shadows off`)"), `Some(None)` after another
                // program's command, `None` without a command before it.
                let mut context: Option<Option<String>> = None;
                // "refused by the argument parser (exit 2)": hostile arguments.
                let refused = p.text.contains("exit 2");
                for (loc, span, seg) in segs {
                    match seg {
                        Seg::Manylight(args) if !args.is_empty() => {
                            context = Some(args.first().filter(|a| subs.contains(a)).cloned());
                            found.commands.push(DocCommand {
                                loc,
                                text: span,
                                raw: args,
                                under: Vec::new(),
                                refused,
                            });
                        }
                        Seg::Other => context = Some(None),
                        Seg::Fragment(mut frag) => {
                            if context == Some(None)
                                || flags_in(&span).iter().all(|f| OTHER_PROGRAMS_FLAGS.contains(&f.as_str()))
                            {
                                continue;
                            }
                            // "`report` with `--plot`": a flag named, its value left out; its
                            // name is checked.
                            if frag.last().is_some_and(|w| w.starts_with("--")) {
                                let last = frag.pop().expect("a word");
                                found.mentions.push(FlagMention {
                                    loc: loc.clone(),
                                    text: span.clone(),
                                    sub: context.clone().flatten(),
                                    flags: flags_in(&last),
                                });
                            }
                            if frag.is_empty() {
                                continue;
                            }
                            // Without a command before it: any subcommand that has its flags.
                            let under = match &context {
                                Some(Some(sub)) => vec![sub.clone()],
                                _ => {
                                    let flags = flags_in(&frag.join(" "));
                                    subs.iter()
                                        .filter(|s| flags.iter().all(|f| cli().flags[*s].contains(f)))
                                        .cloned()
                                        .collect()
                                }
                            };
                            found.commands.push(DocCommand { loc, text: span, raw: frag, under, refused });
                        }
                        _ => {}
                    }
                }
            }
        }
    }
    found
}

fn all_commands() -> &'static Found {
    static FOUND: OnceLock<Found> = OnceLock::new();
    FOUND.get_or_init(|| {
        let mut all = Found::default();
        for doc in docs(false) {
            let f = find_commands(&doc);
            all.commands.extend(f.commands);
            all.mentions.extend(f.mentions);
        }
        all
    })
}

/// A doc's placeholder for a value (`N`, `WxH`, `XxYxZ`, `80x45xZ`, `PATH`, `<Name>`) made a
/// value of the same shape; other words unchanged.
fn fill_placeholder(w: &str) -> String {
    if w.len() > 2 && w.starts_with('<') && w.ends_with('>') {
        return "1".to_string();
    }
    let shaped = w.chars().all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || c == 'x')
        && w.chars().any(|c| c.is_ascii_uppercase());
    if !shaped || w.starts_with('-') {
        return w.to_string();
    }
    let mut out = String::new();
    let mut in_run = false;
    for c in w.chars() {
        if c.is_ascii_uppercase() {
            if !in_run {
                out.push('1');
            }
            in_run = true;
        } else {
            out.push(c);
            in_run = false;
        }
    }
    out
}

fn is_ellipsis(w: &str) -> bool {
    matches!(w, "…" | "..." | "[…]" | "[...]")
}

/// The argument lists a documented command stands for: the first alternative of every `a|b`,
/// then each other alternative of each word in turn.
fn variants(raw: &[String]) -> Vec<Vec<String>> {
    let words: Vec<&String> = raw.iter().filter(|w| !is_ellipsis(w)).collect();
    let alts: Vec<Vec<String>> = words
        .iter()
        .map(|w| {
            if w.contains('|') && !w.starts_with('|') && !w.ends_with('|') {
                w.split('|').map(fill_placeholder).collect()
            } else {
                vec![fill_placeholder(w)]
            }
        })
        .collect();
    let first: Vec<String> = alts.iter().map(|a| a[0].clone()).collect();
    let mut out = vec![first.clone()];
    for (i, a) in alts.iter().enumerate() {
        for alt in &a[1..] {
            let mut v = first.clone();
            v[i] = alt.clone();
            if !out.contains(&v) {
                out.push(v);
            }
        }
    }
    out
}

fn first_error_line(stderr: &str) -> String {
    stderr.lines().find(|l| l.starts_with("error")).unwrap_or(stderr.lines().next().unwrap_or("")).to_string()
}

fn short(s: &str) -> String {
    let s: String = s.split_whitespace().collect::<Vec<_>>().join(" ");
    if s.chars().count() > 150 { format!("{}…", s.chars().take(150).collect::<String>()) } else { s }
}

// ---------------------------------------------------------------------------------------------
// Tests

/// The premise of the command check: clap parses every word before `--help` and refuses an
/// unknown subcommand, flag or value with exit 2, but prints help (exit 0) after valid ones.
#[test]
fn help_after_the_arguments_validates_them() {
    let run = |args: &[&str]| manylight(&strings(args)).0;
    assert_eq!(run(&["render", "--lights", "5", "--pipeline", "naive", "--help"]), Some(0));
    assert_eq!(run(&["rendr", "--help"]), Some(2), "a misspelled subcommand must fail");
    assert_eq!(run(&["render", "--no-such-flag", "--help"]), Some(2), "an unknown flag must fail");
    assert_eq!(run(&["render", "--pipeline", "no-such", "--help"]), Some(2), "a bad value must fail");
    assert_eq!(run(&["render", "--lights", "many", "--help"]), Some(2), "a non-number must fail");
    assert_eq!(run(&["bench", "--shadows", "off,maybe", "--help"]), Some(2), "a bad list item must fail");
}

#[test]
fn documented_commands_parse() {
    let found = all_commands();
    let commands = &found.commands;
    assert!(
        commands.len() >= 30,
        "only {} commands found in the docs: is the extraction broken?",
        commands.len()
    );
    if std::env::var_os("MANYLIGHT_DOCS_LIST").is_some() {
        for c in commands {
            println!("{} {:?} [{}] {}", c.loc, c.under, c.raw.join(" "), short(&c.text));
        }
        for m in &found.mentions {
            println!("{} mention of {:?} in {:?}: {}", m.loc, m.flags, m.sub, short(&m.text));
        }
    }
    // Each distinct argument list runs once. Per command: per variant, the runs of which one
    // must pass (one, or one per subcommand a fragment may belong to).
    let mut runs: Vec<Vec<String>> = Vec::new();
    let mut index: HashMap<Vec<String>, usize> = HashMap::new();
    let mut per_command: Vec<Vec<Vec<usize>>> = Vec::new();
    for c in commands {
        let mut per_variant = Vec::new();
        for v in variants(&c.raw) {
            let prefixes: Vec<Vec<String>> = if c.under.is_empty() {
                vec![Vec::new()]
            } else {
                c.under.iter().map(|s| vec![s.clone()]).collect()
            };
            let mut ids = Vec::new();
            for prefix in prefixes {
                let mut run = prefix;
                run.extend(v.iter().cloned());
                run.push("--help".to_string());
                let id = *index.entry(run.clone()).or_insert_with(|| {
                    runs.push(run);
                    runs.len() - 1
                });
                ids.push(id);
            }
            per_variant.push(ids);
        }
        per_command.push(per_variant);
    }
    // (exit code, first error line) of each run.
    type Outcome = Mutex<Option<(Option<i32>, String)>>;
    let results: Vec<Outcome> = runs.iter().map(|_| Mutex::new(None)).collect();
    let next = AtomicUsize::new(0);
    std::thread::scope(|s| {
        for _ in 0..4 {
            s.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    if i >= runs.len() {
                        break;
                    }
                    let (code, _, err) = manylight(&runs[i]);
                    *results[i].lock().unwrap() = Some((code, first_error_line(&err)));
                }
            });
        }
    });
    let mut failures = Vec::new();
    for (c, per_variant) in commands.iter().zip(&per_command) {
        for ids in per_variant {
            let outcome = |id: usize| results[id].lock().unwrap().clone().expect("ran");
            let passes = |id: usize| {
                let (code, err) = outcome(id);
                if c.refused { code == Some(2) && err.contains("invalid value") } else { code == Some(0) }
            };
            if ids.iter().any(|&id| passes(id)) {
                continue;
            }
            let id = ids[0];
            let (code, err) = outcome(id);
            let args = runs[id][..runs[id].len() - 1].join(" ");
            let under = if ids.len() > 1 {
                format!(" (and under each of {:?} that has its flags)", c.under)
            } else {
                String::new()
            };
            let expected = if c.refused { " (the doc says exit 2, an invalid value)" } else { "" };
            failures.push(format!(
                "  {}: `{}`\n      ran `manylight {args} --help`{under}: exit {code:?}{expected}: {err}",
                c.loc,
                short(&c.text)
            ));
        }
    }
    // Flags named without a whole command: each must exist.
    let cli = cli();
    let any: BTreeSet<&String> = cli.flags.values().flatten().collect();
    let mut mentions = 0;
    for m in &found.mentions {
        for f in &m.flags {
            mentions += 1;
            let ok = match &m.sub {
                Some(sub) => cli.flags[sub].contains(f),
                None => any.contains(f),
            };
            if !ok {
                let of = m.sub.as_deref().map_or("any subcommand".to_string(), |s| format!("`{s}`"));
                failures.push(format!("  {}: `{}`: {f} is not a flag of {of}", m.loc, short(&m.text)));
            }
        }
    }
    let fragments = commands.iter().filter(|c| !c.under.is_empty() || c.raw[0].starts_with("--")).count();
    let bare = commands.iter().filter(|c| c.under.is_empty() && c.raw.len() == 1).count();
    println!(
        "{} documented commands ({} command lines, {bare} bare subcommand names, {fragments} flag \
         fragments; {} distinct argument lists with each alternative) and {mentions} flag names checked",
        commands.len(),
        commands.len() - fragments - bare,
        runs.len()
    );
    assert!(
        failures.is_empty(),
        "{} documented command(s) or flag(s) that `manylight` does not accept:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

fn in_command_section(loc: &Loc) -> bool {
    loc.file == "README.md" && loc.section.starts_with("## The `manylight` command")
}

#[test]
fn readme_command_section_names_every_subcommand_and_value() {
    let cli = cli();
    let section: Vec<&DocCommand> =
        all_commands().commands.iter().filter(|c| in_command_section(&c.loc)).collect();
    assert!(!section.is_empty(), "README.md has no commands under \"## The `manylight` command\"");
    let mut failures = Vec::new();
    let named: BTreeSet<&String> = section.iter().filter_map(|c| c.under.first().or(c.raw.first())).collect();
    for sub in &cli.subcommands {
        if !named.contains(sub) {
            failures.push(format!(
                "  README.md, \"The `manylight` command\": no `{sub}` (a subcommand of `manylight --help`)"
            ));
        }
    }
    // Every `--flag a|b|…` listed there is the code's whole list, where the flag has one.
    let mut lists = 0;
    for c in &section {
        let Some(sub) = c.under.first().or(c.raw.first()) else { continue };
        for w in c.raw.windows(2) {
            if !(w[0].starts_with("--") && w[1].contains('|')) {
                continue;
            }
            let Some(code) = accepted_values(sub, &w[0]) else { continue };
            lists += 1;
            let doc: BTreeSet<&str> = w[1].split('|').collect();
            let code: BTreeSet<&str> = code.iter().map(String::as_str).collect();
            let missing: Vec<_> = code.difference(&doc).collect();
            let extra: Vec<_> = doc.difference(&code).collect();
            if !missing.is_empty() || !extra.is_empty() {
                failures.push(format!(
                    "  {}: `{} {}` lists {}; `manylight {sub}` takes {}{}{}",
                    c.loc,
                    w[0],
                    w[1],
                    doc.len(),
                    code.len(),
                    if missing.is_empty() { String::new() } else { format!(", missing {missing:?}") },
                    if extra.is_empty() { String::new() } else { format!(", not taken {extra:?}") },
                ));
            }
        }
    }
    println!(
        "{} subcommands and {lists} value lists checked in README's command section",
        cli.subcommands.len()
    );
    assert!(lists >= 5, "only {lists} value lists found in README's command section");
    // The debug views and pipelines in particular (the lists above include them).
    for flag in ["--debug-view", "--pipeline"] {
        let values = accepted_values("render", flag).unwrap_or_default();
        assert!(!values.is_empty(), "`render {flag} __not_a_value__` names no values");
        let listed = section.iter().any(|c| c.raw.windows(2).any(|w| w[0] == flag && w[1].contains('|')));
        if !listed {
            failures.push(format!("  README.md, \"The `manylight` command\": no `{flag} a|b|…` list"));
        }
    }
    assert!(failures.is_empty(), "README's command section and the CLI differ:\n{}", failures.join("\n"));
}

const NUMBERS: &[&str] = &[
    "zero",
    "one",
    "two",
    "three",
    "four",
    "five",
    "six",
    "seven",
    "eight",
    "nine",
    "ten",
    "eleven",
    "twelve",
    "thirteen",
    "fourteen",
    "fifteen",
    "sixteen",
    "seventeen",
    "eighteen",
    "nineteen",
    "twenty",
];

/// "six pipelines", "3 G-buffer layouts", … anywhere in the docs: the count the code has.
#[test]
fn counts_in_the_docs_are_the_codes() {
    let kinds: Vec<(&str, Vec<String>)> = [
        ("pipelines", "--pipeline"),
        ("g-buffer layouts", "--gbuffer"),
        ("normal codecs", "--normal-codec"),
        ("debug views", "--debug-view"),
        ("shading models", "--shading"),
        ("culling tests", "--cull"),
    ]
    .into_iter()
    .map(|(noun, flag)| {
        let values =
            accepted_values("render", flag).unwrap_or_else(|| panic!("`render {flag}` names no values"));
        (noun, values)
    })
    .collect();
    let mut failures = Vec::new();
    let mut checked = 0;
    for doc in docs(true) {
        for block in blocks(&doc) {
            let Block::Para(p) = block else { continue };
            let lower = p.text.to_lowercase();
            for (noun, values) in &kinds {
                let mut from = 0;
                while let Some(i) = lower[from..].find(noun) {
                    let at = from + i;
                    from = at + noun.len();
                    let before = lower[..at].trim_end_matches(' ');
                    if before.len() == lower[..at].len() {
                        continue; // no space before the noun
                    }
                    let word = before.rsplit(|c: char| !c.is_alphanumeric()).next().unwrap_or("");
                    let n = match word.parse::<usize>() {
                        Ok(n) => n,
                        Err(_) => match NUMBERS.iter().position(|w| *w == word) {
                            Some(n) => n,
                            None => continue,
                        },
                    };
                    checked += 1;
                    if n != values.len() {
                        failures.push(format!(
                            "  {}:{}: \"{word} {noun}\", but the CLI has {}: {}",
                            doc.rel,
                            p.line_at(at),
                            values.len(),
                            values.join(", ")
                        ));
                    }
                }
            }
        }
    }
    println!("{checked} stated counts checked");
    assert!(failures.is_empty(), "counts in the docs differ from the code's:\n{}", failures.join("\n"));
}

// ---------------------------------------------------------------------------------------------
// Links

/// GitHub's anchors of a markdown file's headings.
fn anchors(path: &Path) -> BTreeSet<String> {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    let doc = Doc { rel: String::new(), lines: text.lines().map(str::to_string).collect() };
    let mut seen: HashMap<String, usize> = HashMap::new();
    let mut out = BTreeSet::new();
    for block in blocks(&doc) {
        let Block::Para(p) = block else { continue };
        let t = p.text.trim();
        // Explicit anchors: <a name="x"> / id="x".
        for key in ["name=\"", "id=\""] {
            let mut rest = t;
            while let Some(i) = rest.find(key) {
                rest = &rest[i + key.len()..];
                if let Some(j) = rest.find('"') {
                    out.insert(rest[..j].to_string());
                }
            }
        }
        if !t.starts_with('#') {
            continue;
        }
        let level = t.chars().take_while(|&c| c == '#').count();
        if level > 6 || !t[level..].starts_with(' ') {
            continue;
        }
        let title = t[level..].trim().trim_end_matches('#').trim();
        let title = strip_links(title);
        let mut slug = String::new();
        for c in title.to_lowercase().chars() {
            if c.is_alphanumeric() || c == '-' || c == '_' {
                slug.push(c);
            } else if c == ' ' {
                slug.push('-');
            }
        }
        let n = seen.entry(slug.clone()).or_insert(0);
        out.insert(if *n == 0 { slug.clone() } else { format!("{slug}-{n}") });
        *n += 1;
    }
    out
}

/// `[text](target)` → `text`.
fn strip_links(s: &str) -> String {
    let mut out = String::new();
    let mut rest = s;
    while let Some(i) = rest.find("](") {
        let open = rest[..i].rfind('[');
        let close = rest[i + 2..].find(')');
        match (open, close) {
            (Some(o), Some(c)) => {
                out.push_str(&rest[..o]);
                out.push_str(&rest[o + 1..i]);
                rest = &rest[i + 2 + c + 1..];
            }
            _ => {
                out.push_str(&rest[..i + 2]);
                rest = &rest[i + 2..];
            }
        }
    }
    out.push_str(rest);
    out
}

fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() && b[i + 1].is_ascii_hexdigit() && b[i + 2].is_ascii_hexdigit() {
            out.push(u8::from_str_radix(&s[i + 1..i + 3], 16).expect("hex digits"));
            i += 3;
            continue;
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Link targets of a paragraph (inline links and images outside code spans, and reference
/// definitions): (line, target).
fn link_targets(p: &Para) -> Vec<(usize, String)> {
    let mut text = p.text.clone().into_bytes();
    for (start, end, _) in code_spans(&p.text) {
        for b in &mut text[start..end] {
            *b = b'x';
        }
    }
    let text = String::from_utf8(text).expect("spans replaced whole");
    let mut out = Vec::new();
    let mut from = 0;
    while let Some(i) = text[from..].find("](") {
        let at = from + i + 2;
        from = at;
        let rest = &text[at..];
        let target = if let Some(r) = rest.strip_prefix('<') {
            r.split('>').next().unwrap_or("").to_string()
        } else {
            let mut depth = 0;
            let end = rest
                .char_indices()
                .find(|&(_, c)| {
                    if c == '(' {
                        depth += 1;
                    } else if c == ')' {
                        if depth == 0 {
                            return true;
                        }
                        depth -= 1;
                    }
                    c == ' '
                })
                .map_or(rest.len(), |(j, _)| j);
            rest[..end].to_string()
        };
        out.push((p.line_at(at), target));
    }
    // [label]: target, one a line
    for (k, &(start, line)) in p.starts.iter().enumerate() {
        let end = p.starts.get(k + 1).map_or(text.len(), |&(o, _)| o);
        let t = text[start..end].trim();
        if t.starts_with('[')
            && let Some(i) = t.find("]: ")
            && !t[..i].contains("](")
        {
            let target = t[i + 3..].split_whitespace().next().unwrap_or("").to_string();
            out.push((line, target));
        }
    }
    out
}

#[test]
fn relative_links_resolve() {
    let mut failures = Vec::new();
    let mut checked = 0;
    let mut anchor_cache: HashMap<PathBuf, BTreeSet<String>> = HashMap::new();
    for doc in docs(true) {
        for block in blocks(&doc) {
            let Block::Para(p) = block else { continue };
            for (line, target) in link_targets(&p) {
                if target.is_empty() || target.contains("://") || target.starts_with("mailto:") {
                    continue;
                }
                checked += 1;
                let (path, anchor) = match target.split_once('#') {
                    Some((p, a)) => (p, Some(a)),
                    None => (target.as_str(), None),
                };
                let file = if path.is_empty() {
                    root().join(&doc.rel)
                } else if let Some(abs) = path.strip_prefix('/') {
                    root().join(percent_decode(abs))
                } else {
                    doc.dir().join(percent_decode(path))
                };
                if !file.exists() {
                    failures.push(format!("  {}:{line}: ({target}): no such file or folder", doc.rel));
                    continue;
                }
                let Some(anchor) = anchor.filter(|a| !a.is_empty()) else { continue };
                if file.extension().is_none_or(|e| e != "md") {
                    continue; // line anchors of source files are not checked
                }
                let file = file.canonicalize().unwrap_or(file);
                let set = anchor_cache.entry(file.clone()).or_insert_with(|| anchors(&file));
                let anchor = percent_decode(anchor);
                if !set.contains(&anchor) {
                    failures.push(format!(
                        "  {}:{line}: ({target}): no heading with the anchor #{anchor} in {}",
                        doc.rel,
                        file.strip_prefix(root().canonicalize().unwrap()).unwrap_or(&file).display()
                    ));
                }
            }
        }
    }
    println!("{checked} relative links checked");
    assert!(checked >= 100, "only {checked} relative links found: is the extraction broken?");
    assert!(failures.is_empty(), "{} broken relative link(s):\n{}", failures.len(), failures.join("\n"));
}

/// The extraction itself, on the conventions the docs use.
#[test]
fn extraction_understands_the_doc_conventions() {
    let (toks, comment) =
        shell_words("MANYLIGHT_X=1 manylight render --lights 1024|100000 > out.txt 2>&1 # note");
    assert_eq!(comment.as_deref(), Some(" note"));
    let segs = words_of(&toks);
    assert_eq!(segs.len(), 1);
    let mut vars = HashMap::new();
    let words = simple_command(segs[0].clone(), &mut vars);
    let Seg::Manylight(args) = classify(&words, &strings(&["render", "bench"])) else { panic!("{words:?}") };
    assert_eq!(args, strings(&["render", "--lights", "1024|100000"]));
    assert_eq!(
        variants(&args),
        vec![strings(&["render", "--lights", "1024"]), strings(&["render", "--lights", "100000"])]
    );
    assert_eq!(
        variants(&strings(&[
            "render",
            "--size",
            "WxH",
            "--grid",
            "80x45xZ",
            "--scene",
            "assets/<Name>/<f>",
            "…"
        ])),
        vec![strings(&["render", "--size", "1x1", "--grid", "80x45x1", "--scene", "assets/<Name>/<f>"])]
    );
    let (toks, _) =
        shell_words("for d in off on; do manylight bench --depth-bounds $d --out a_${d}.csv | tee x");
    let mut vars = HashMap::new();
    let segs: Vec<Vec<String>> =
        words_of(&toks).into_iter().map(|s| simple_command(s, &mut vars)).filter(|s| !s.is_empty()).collect();
    assert_eq!(segs[0], strings(&["manylight", "bench", "--depth-bounds", "off", "--out", "a_off.csv"]));
    assert_eq!(segs[1], strings(&["tee", "x"]));
    let spans =
        code_spans("see `cargo run -p manylight_cli --bin manylight --\n report --shadows` and ``a ` b``");
    assert_eq!(spans.len(), 2);
    assert_eq!(spans[1].2, "a ` b");
}
