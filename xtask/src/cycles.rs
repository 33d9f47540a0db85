//! No import cycles: a module that names another module's items
//! (`use crate::a::…`, `super::b::…`, a path in code) depends on it, and a
//! cycle of such dependencies fails the test run.
//!
//! A node is a module with its submodules, except that a module made of a
//! folder of submodules (`files/`, `settings/`, the crate root) counts each
//! submodule as a node of its own, and its own file as one more: a child
//! using its parent's items depends on the parent (the parent's file is
//! made of its children: declaring and using them is no dependency).
//! `tests` modules are leaves, left out. Paths are read from the source text; `use` imports and
//! re-exports are followed to the module that defines the item, so a
//! re-export cannot hide a cycle.

use crate::run::{root, Result};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Every crate of the repository, by folder: each root file (`src/lib.rs`,
/// `src/main.rs`, `src/bin/*`, `tests/*`, `examples/*`, `fuzz_targets/*`)
/// is a crate of its own.
const CRATES: &[&str] = &[
    "firmware/logic",
    "firmware/progmem",
    "firmware",
    "simavr",
    "trace",
    "studio",
    "hil-tests",
    "xtask",
    "fuzz",
];

/// Checks every crate; one line when there is no cycle, each cycle's
/// dependencies (with the line that makes each) when there is.
pub fn check() -> Result<()> {
    let (mut crates, mut modules, mut edges, mut found) = (0, 0, 0, Vec::new());
    for dir in CRATES {
        for file in roots(&root().join(dir)) {
            let g = Graph::load(&|p| std::fs::read_to_string(p).ok(), &file);
            crates += 1;
            modules += g.modules.len();
            edges += g.edges.len();
            let name = file
                .strip_prefix(root())
                .unwrap_or(&file)
                .display()
                .to_string();
            found.extend(g.cycles().into_iter().map(|c| format!("{name}: {c}")));
        }
    }
    if found.is_empty() {
        println!(
            "== import cycles: none ({crates} crates, {modules} modules, {edges} dependencies)"
        );
        return Ok(());
    }
    for c in &found {
        eprintln!("import cycle in {c}");
    }
    Err(format!(
        "{} import cycles (docs/architecture.md: no import cycles)",
        found.len()
    )
    .into())
}

fn roots(dir: &Path) -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = ["src/lib.rs", "src/main.rs"]
        .iter()
        .map(|f| dir.join(f))
        .collect();
    for sub in ["src/bin", "tests", "examples", "fuzz_targets"] {
        if let Ok(rd) = std::fs::read_dir(dir.join(sub)) {
            out.extend(rd.filter_map(|e| Some(e.ok()?.path())));
        }
    }
    out.retain(|p| p.is_file() && p.extension().is_some_and(|e| e == "rs"));
    out.sort();
    out
}

type ModPath = Vec<String>;

#[derive(Default)]
struct Module {
    file: PathBuf,
    /// Has submodules in files of their own (other than `tests`).
    folder: bool,
    children: BTreeSet<String>,
    /// Names brought in by `use`, with the path as written.
    imports: BTreeMap<String, ModPath>,
    /// Paths as written, with their line, and whether they are a glob.
    paths: Vec<(ModPath, u32, bool)>,
}

struct Graph {
    modules: BTreeMap<ModPath, Module>,
    /// Node → node, with the first place that makes the dependency.
    edges: BTreeMap<(ModPath, ModPath), String>,
}

impl Graph {
    fn load(read: &dyn Fn(&Path) -> Option<String>, root_file: &Path) -> Graph {
        let mut modules = BTreeMap::new();
        let mut todo = vec![(Vec::new(), root_file.to_path_buf(), true)];
        while let Some((path, file, dir_owner)) = todo.pop() {
            let Some(text) = read(&file) else { continue };
            let dir = file.parent().unwrap_or(Path::new("")).to_path_buf();
            let child_dir = if dir_owner {
                dir.clone()
            } else {
                dir.join(file.file_stem().unwrap_or_default())
            };
            for decl in parse(&lex(&text), &path, &file, &mut modules) {
                let (f, owner) = match decl.attr_path {
                    Some(p) => (dir.join(p), false),
                    None => {
                        let flat = child_dir.join(format!("{}.rs", decl.name));
                        if read(&flat).is_some() {
                            (flat, false)
                        } else {
                            (child_dir.join(&decl.name).join("mod.rs"), true)
                        }
                    }
                };
                todo.push((decl.module, f, owner));
            }
        }
        let mut g = Graph {
            modules,
            edges: BTreeMap::new(),
        };
        g.link();
        g
    }

    fn link(&mut self) {
        let mut edges = BTreeMap::new();
        // Tests are leaves: nothing uses them, so they may use anything.
        for (m, module) in self
            .modules
            .iter()
            .filter(|(m, _)| !m.iter().any(|s| s == "tests"))
        {
            let from = self.node(m);
            for (segs, line, glob) in &module.paths {
                let Some(abs) = self.absolute(m, segs, 0) else {
                    continue;
                };
                let (to, item) = self.target(abs, 0);
                // `use crate::a;` names a module, not its items: the paths
                // through it count.
                if !item && !glob {
                    continue;
                }
                let to = self.node(&to);
                // A folder's own file builds it from its children.
                let own_child = to.len() == from.len() + 1 && to.starts_with(&from);
                if to != from && !own_child {
                    let at = format!("{}:{line}", module.file.display());
                    edges.entry((from.clone(), to)).or_insert(at);
                }
            }
        }
        self.edges = edges;
    }

    /// A path as written in module `m`, from the crate root; `None` when it
    /// leaves the crate.
    fn absolute(&self, m: &[String], segs: &[String], depth: u32) -> Option<ModPath> {
        let module = self.modules.get(m)?;
        let first = segs.first()?.as_str();
        let (mut base, rest) = match first {
            "crate" => (Vec::new(), &segs[1..]),
            "self" => (m.to_vec(), &segs[1..]),
            "super" => {
                let mut base = m.to_vec();
                let ups = segs.iter().take_while(|s| *s == "super").count();
                for _ in 0..ups {
                    base.pop()?;
                }
                (base, &segs[ups..])
            }
            _ if module.children.contains(first) => (m.to_vec(), segs),
            _ => {
                let alias = module
                    .imports
                    .get(first)
                    .filter(|p| depth < 8 && p[..] != segs[..1])?;
                let mut abs = self.absolute(m, alias, depth + 1)?;
                abs.extend_from_slice(&segs[1..]);
                return Some(abs);
            }
        };
        base.extend_from_slice(rest);
        Some(base)
    }

    /// The module that defines what an absolute path names (following
    /// re-exports), and whether the path goes past it to an item.
    fn target(&self, abs: ModPath, depth: u32) -> (ModPath, bool) {
        let mut k = 0;
        while k < abs.len() && self.modules.contains_key(&abs[..=k]) {
            k += 1;
        }
        if k < abs.len() && depth < 8 {
            let module = &abs[..k];
            if let Some(p) = self.modules[module].imports.get(&abs[k]) {
                if let Some(mut a) = self.absolute(module, p, 0) {
                    a.extend_from_slice(&abs[k + 1..]);
                    return self.target(a, depth + 1);
                }
            }
        }
        (abs[..k].to_vec(), k < abs.len())
    }

    /// The node a module belongs to: its top-level module, or the child of
    /// a top-level folder module.
    fn node(&self, path: &[String]) -> ModPath {
        let top = &path[..path.len().min(1)];
        let split = self.modules.get(top).is_some_and(|m| m.folder);
        match path.get(1) {
            Some(child) if split && child != "tests" => path[..2].to_vec(),
            _ => top.to_vec(),
        }
    }

    /// Each strongly connected set of nodes, as its dependencies.
    fn cycles(&self) -> Vec<String> {
        let mut next: BTreeMap<&ModPath, Vec<&ModPath>> = BTreeMap::new();
        for (a, b) in self.edges.keys() {
            next.entry(a).or_default().push(b);
        }
        let reach = |start: &ModPath| {
            let mut seen = BTreeSet::new();
            let mut stack = vec![start];
            while let Some(n) = stack.pop() {
                for &m in next.get(n).into_iter().flatten() {
                    if seen.insert(m) {
                        stack.push(m);
                    }
                }
            }
            seen
        };
        let reached: BTreeMap<&ModPath, BTreeSet<&ModPath>> =
            next.keys().map(|&n| (n, reach(n))).collect();
        let mut done = BTreeSet::new();
        let mut out = Vec::new();
        for (&n, r) in &reached {
            if done.contains(n) || !r.contains(n) {
                continue;
            }
            let set: BTreeSet<&ModPath> = r
                .iter()
                .copied()
                .filter(|m| reached.get(m).is_some_and(|r| r.contains(n)))
                .collect();
            let deps: Vec<String> = self
                .edges
                .iter()
                .filter(|((a, b), _)| set.contains(a) && set.contains(b))
                .map(|((a, b), at)| format!("{} → {} ({at})", show(a), show(b)))
                .collect();
            done.extend(set);
            out.push(deps.join(", "));
        }
        out
    }
}

fn show(p: &[String]) -> String {
    if p.is_empty() {
        "crate".into()
    } else {
        p.join("::")
    }
}

struct Decl {
    module: ModPath,
    name: String,
    attr_path: Option<String>,
}

/// Records a file's modules, imports and paths; returns the submodules
/// declared in files of their own.
fn parse(
    toks: &[Token],
    path: &[String],
    file: &Path,
    modules: &mut BTreeMap<ModPath, Module>,
) -> Vec<Decl> {
    let mut decls = Vec::new();
    // Inline modules open at a brace depth.
    let mut stack: Vec<(ModPath, usize)> = vec![(path.to_vec(), 0)];
    let mut depth = 0;
    let mut attr_path = None;
    let entry = |m: &ModPath, modules: &mut BTreeMap<ModPath, Module>| {
        modules.entry(m.clone()).or_insert_with(|| Module {
            file: file.to_path_buf(),
            ..Module::default()
        });
    };
    entry(&path.to_vec(), modules);
    modules.get_mut(path).unwrap().file = file.to_path_buf();
    let mut i = 0;
    while i < toks.len() {
        let cur = stack.last().unwrap().0.clone();
        let at = |k: usize| toks.get(k).map(|t| &t.tok);
        match &toks[i].tok {
            Tok::Punct('#') => {
                if let (
                    Some(Tok::Punct('[')),
                    Some(Tok::Ident(p)),
                    Some(Tok::Punct('=')),
                    Some(Tok::Str(s)),
                ) = (at(i + 1), at(i + 2), at(i + 3), at(i + 4))
                {
                    if p == "path" {
                        attr_path = Some(s.clone());
                    }
                }
            }
            Tok::Ident(k) if k == "mod" => {
                if let Some(Tok::Ident(name)) = at(i + 1) {
                    let mut child = cur.clone();
                    child.push(name.clone());
                    entry(&child, modules);
                    let m = modules.get_mut(&cur).unwrap();
                    m.children.insert(name.clone());
                    match at(i + 2) {
                        Some(Tok::Punct('{')) => {
                            depth += 1;
                            stack.push((child, depth));
                            i += 3;
                            continue;
                        }
                        _ => {
                            m.folder |= name != "tests";
                            decls.push(Decl {
                                module: child,
                                name: name.clone(),
                                attr_path: attr_path.take(),
                            });
                        }
                    }
                    i += 2;
                    continue;
                }
            }
            Tok::Ident(k) if k == "use" => {
                let line = toks[i].line;
                i += 1;
                let mut trees = Vec::new();
                use_tree(toks, &mut i, Vec::new(), &mut trees);
                let m = modules.get_mut(&cur).unwrap();
                for (segs, name) in trees {
                    m.paths.push((segs.clone(), line, name.is_none()));
                    if let Some(n) = name.filter(|n| n != "_") {
                        m.imports.insert(n, segs);
                    }
                }
                continue;
            }
            Tok::Punct('{') => depth += 1,
            Tok::Punct('}') => {
                if stack.len() > 1 && stack.last().unwrap().1 == depth {
                    stack.pop();
                }
                depth = depth.saturating_sub(1);
            }
            Tok::Ident(first)
                if (i == 0 || toks[i - 1].tok != Tok::Colons)
                    && at(i + 1) == Some(&Tok::Colons) =>
            {
                let line = toks[i].line;
                let mut segs = vec![first.clone()];
                let mut j = i + 1;
                while let (Some(Tok::Colons), Some(Tok::Ident(s))) = (at(j), at(j + 1)) {
                    segs.push(s.clone());
                    j += 2;
                }
                modules
                    .get_mut(&cur)
                    .unwrap()
                    .paths
                    .push((segs, line, false));
                i = j;
                continue;
            }
            _ => {}
        }
        i += 1;
    }
    decls
}

/// One `use` tree from `toks[*i]` to its end: each imported path, with the
/// name it binds (`None` for a glob).
fn use_tree(
    toks: &[Token],
    i: &mut usize,
    mut segs: ModPath,
    out: &mut Vec<(ModPath, Option<String>)>,
) {
    let at = |k: usize| toks.get(k).map(|t| &t.tok);
    loop {
        match at(*i) {
            Some(Tok::Colons) => *i += 1,
            Some(Tok::Ident(s)) => {
                *i += 1;
                if s != "self" || segs.is_empty() {
                    segs.push(s.clone());
                }
                if at(*i) == Some(&Tok::Colons) {
                    continue;
                }
                let mut name = segs.last().cloned();
                if let (Some(Tok::Ident(a)), Some(Tok::Ident(n))) = (at(*i), at(*i + 1)) {
                    if a == "as" {
                        name = Some(n.clone());
                        *i += 2;
                    }
                }
                out.push((segs, name));
                return;
            }
            Some(Tok::Punct('*')) => {
                *i += 1;
                out.push((segs, None));
                return;
            }
            Some(Tok::Punct('{')) => {
                *i += 1;
                while !matches!(at(*i), None | Some(Tok::Punct('}'))) {
                    let before = *i;
                    use_tree(toks, i, segs.clone(), out);
                    if at(*i) == Some(&Tok::Punct(',')) || *i == before {
                        *i += 1;
                    }
                }
                *i += 1;
                return;
            }
            _ => return,
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
enum Tok {
    Ident(String),
    Str(String),
    Colons,
    Punct(char),
}

struct Token {
    tok: Tok,
    line: u32,
}

/// Identifiers, `::`, string contents and punctuation; comments, literals'
/// insides and lifetimes skipped.
fn lex(src: &str) -> Vec<Token> {
    let b = src.as_bytes();
    let (mut i, mut line, mut out) = (0, 1u32, Vec::new());
    let newlines = |s: &[u8]| s.iter().filter(|&&c| c == b'\n').count() as u32;
    let ident_char = |c: u8| c == b'_' || c.is_ascii_alphanumeric() || c >= 0x80;
    while i < b.len() {
        let c = b[i];
        let start = i;
        let next = b.get(i + 1).copied();
        if c == b'/' && next == Some(b'/') {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if c == b'/' && next == Some(b'*') {
            let mut nest = 0;
            while i < b.len() {
                if b[i..].starts_with(b"/*") {
                    nest += 1;
                    i += 2;
                } else if b[i..].starts_with(b"*/") {
                    nest -= 1;
                    i += 2;
                    if nest == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
        } else if c == b'"' {
            i = string_end(b, i + 1, 0);
            out.push(Token {
                tok: Tok::Str(src[start + 1..i.saturating_sub(1)].into()),
                line,
            });
        } else if c == b'\'' {
            i += 1;
            if next == Some(b'\\') {
                i += 2;
                while i < b.len() && b[i] != b'\'' {
                    i += 1;
                }
                i += 1;
            } else if let Some(ch) = src[i..].chars().next() {
                if b.get(i + ch.len_utf8()) == Some(&b'\'') {
                    i += ch.len_utf8() + 1;
                }
            }
        } else if ident_char(c) {
            while i < b.len() && ident_char(b[i]) {
                i += 1;
            }
            let word = &src[start..i];
            let raw = matches!(word, "r" | "br" | "cr");
            let hashes = b[i..].iter().take_while(|&&h| h == b'#').count();
            if (raw || matches!(word, "b" | "c")) && b.get(i) == Some(&b'"')
                || raw && hashes > 0 && b.get(i + hashes) == Some(&b'"')
            {
                let body = i + hashes + 1;
                i = string_end(b, body, if raw { hashes + 1 } else { 0 });
            } else if word == "r" && hashes == 1 {
                continue; // r#ident: the identifier follows
            } else {
                out.push(Token {
                    tok: Tok::Ident(word.into()),
                    line,
                });
            }
        } else if c == b':' && next == Some(b':') {
            out.push(Token {
                tok: Tok::Colons,
                line,
            });
            i += 2;
        } else {
            if !c.is_ascii_whitespace() {
                out.push(Token {
                    tok: Tok::Punct(c as char),
                    line,
                });
            }
            i += 1;
        }
        line += newlines(&b[start..i.min(b.len())]);
        if i == start {
            i += 1;
        }
    }
    out
}

/// The index past a string's closing quote: escapes count unless the
/// string is raw (`raw` = number of `#` + 1).
fn string_end(b: &[u8], mut i: usize, raw: usize) -> usize {
    while i < b.len() {
        if raw == 0 && b[i] == b'\\' {
            i += 2;
        } else if b[i] == b'"'
            && b[i + 1..]
                .iter()
                .take(raw.saturating_sub(1))
                .filter(|&&h| h == b'#')
                .count()
                == raw.saturating_sub(1)
        {
            return i + raw.max(1);
        } else {
            i += 1;
        }
    }
    b.len()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn graph(files: &[(&str, &str)]) -> Graph {
        let files: BTreeMap<PathBuf, String> = files
            .iter()
            .map(|(p, t)| (PathBuf::from(p), t.to_string()))
            .collect();
        Graph::load(&|p| files.get(p).cloned(), Path::new("src/lib.rs"))
    }

    const FOLDER: &str = "// a folder module\npub mod a;\npub mod b;\npub use a::Thing;\n";

    #[test]
    fn a_grouped_use_and_a_child_using_its_parent_make_a_cycle() {
        let g = graph(&[
            ("src/lib.rs", "mod f;\nmod g;"),
            ("src/f/mod.rs", FOLDER),
            (
                "src/f/a.rs",
                "pub struct Thing;\nuse crate::{g::Other, f::b::Y};",
            ),
            (
                "src/f/b.rs",
                "pub struct Y; fn x() -> super::super::g::Other { todo!() }",
            ),
            (
                "src/g.rs",
                "pub struct Other(crate::f::Thing, crate::f::b::Y);",
            ),
        ]);
        let c = g.cycles();
        assert_eq!(c.len(), 1, "{c:?}");
        // The re-export `f::Thing` is followed to `f::a`, where it is defined.
        assert!(c[0].contains("f::a → g (src/f/a.rs:2)"), "{c:?}");
        assert!(c[0].contains("g → f::a (src/g.rs:1)"), "{c:?}");
        assert!(c[0].contains("f::b → g (src/f/b.rs:1)"), "{c:?}");
    }

    #[test]
    fn strings_comments_tests_and_module_imports_make_no_cycle() {
        let g = graph(&[
            ("src/lib.rs", "mod f;\nmod g;"),
            ("src/f/mod.rs", FOLDER),
            ("src/f/a.rs", "use crate::g; pub struct Thing; fn t() { g::go(); let _ = '\"'; }"),
            ("src/f/b.rs", "/* crate::f::a::Thing */ const S: &str = r#\"crate::f::a\"#;"),
            ("src/g.rs", "// crate::f::Thing\npub fn go() {}\n#[cfg(test)]\n#[path = \"g_tests.rs\"]\nmod tests;"),
            ("src/g_tests.rs", "use super::*;"),
        ]);
        assert!(g.cycles().is_empty(), "{:?}", g.cycles());
        let edges: Vec<String> = g
            .edges
            .keys()
            .map(|(a, b)| format!("{} → {}", show(a), show(b)))
            .collect();
        // `f`'s re-export of its own child is no dependency.
        assert_eq!(edges, ["f::a → g"]);
    }
}
