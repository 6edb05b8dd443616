//! No import circles in src/: read from the `use` declarations of every file, no two modules
//! depend on each other, directly or through others. A module may use its ancestors (a child
//! sees its parent's items by design), so only the other dependencies count: a module on its
//! children, siblings and their descendants, and on other branches of the tree. Names a
//! module brings into scope with `use` are followed to where they are defined, so
//! `use super::Item` counts as a use of the sibling `Item` comes from. Test code (inline
//! `mod tests` blocks, and test files, which nothing uses) may reach anything.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

/// A module path below the crate root (`["stress", "ipm", "kkt"]`).
type Module = Vec<String>;

/// One file's child modules and its `use` declarations (each with the inline
/// module it appears in, relative to the file's).
struct File {
    children: BTreeSet<String>,
    uses: Vec<(Module, String)>,
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

fn module_of(src: &Path, file: &Path) -> Module {
    let rel = file.strip_prefix(src).unwrap().with_extension("");
    let mut parts: Module = rel
        .iter()
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    if matches!(parts.last().map(String::as_str), Some("lib" | "mod")) {
        parts.pop();
    }
    parts
}

/// The source without comments, string and character literals (replaced by spaces), so that
/// braces and `use` can be read from it.
fn code_only(text: &str) -> String {
    let c: Vec<char> = text.chars().collect();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while i < c.len() {
        let next = c.get(i + 1).copied();
        if c[i] == '/' && next == Some('/') {
            while i < c.len() && c[i] != '\n' {
                i += 1;
            }
        } else if c[i] == '/' && next == Some('*') {
            i += 2;
            while i + 1 < c.len() && !(c[i] == '*' && c[i + 1] == '/') {
                i += 1;
            }
            i += 2;
        } else if c[i] == 'r'
            && (next == Some('"') || next == Some('#'))
            && !ident(c.get(i.wrapping_sub(1)))
        {
            let mut j = i + 1;
            let mut hashes = 0;
            while c.get(j) == Some(&'#') {
                hashes += 1;
                j += 1;
            }
            if c.get(j) != Some(&'"') {
                out.push(c[i]);
                i += 1;
                continue;
            }
            j += 1;
            let close: String = std::iter::once('"')
                .chain((0..hashes).map(|_| '#'))
                .collect();
            while j < c.len() && !c[j..].iter().collect::<String>().starts_with(&close) {
                j += 1;
            }
            i = j + close.len();
            out.push(' ');
        } else if c[i] == '"' {
            i += 1;
            while i < c.len() && c[i] != '"' {
                i += if c[i] == '\\' { 2 } else { 1 };
            }
            i += 1;
            out.push(' ');
        } else if c[i] == '\'' && (c.get(i + 2) == Some(&'\'') || next == Some('\\')) {
            // A character literal ('x' or an escape); a lifetime has no closing quote.
            i += 1;
            while i < c.len() && c[i] != '\'' {
                i += if c[i] == '\\' { 2 } else { 1 };
            }
            i += 1;
            out.push(' ');
        } else {
            out.push(c[i]);
            i += 1;
        }
    }
    out
}

fn ident(c: Option<&char>) -> bool {
    c.is_some_and(|c| c.is_alphanumeric() || *c == '_')
}

/// The modules, children and `use` declarations of a file's code.
fn parse(text: &str) -> File {
    let code = code_only(text);
    let mut file = File {
        children: BTreeSet::new(),
        uses: Vec::new(),
    };
    // Inline modules open at a brace depth; `stack` holds (name, depth inside it).
    let mut stack: Vec<(String, usize)> = Vec::new();
    let mut depth = 0usize;
    let tokens = tokenize(&code);
    let mut k = 0;
    while k < tokens.len() {
        let t = tokens[k].as_str();
        match t {
            "{" => depth += 1,
            "}" => {
                depth -= 1;
                if stack.last().is_some_and(|(_, d)| *d > depth) {
                    stack.pop();
                }
            }
            "mod" if k + 1 < tokens.len() => {
                let name = tokens[k + 1].clone();
                match tokens.get(k + 2).map(String::as_str) {
                    Some(";") if stack.is_empty() => {
                        file.children.insert(name);
                    }
                    Some("{") => {
                        if stack.is_empty() {
                            file.children.insert(name.clone());
                        }
                        depth += 1;
                        stack.push((name, depth));
                        k += 3;
                        continue;
                    }
                    _ => {}
                }
            }
            "use" if stack.iter().any(|(name, _)| name == "tests") => {}
            "use" => {
                let end = (k..tokens.len()).find(|&j| tokens[j] == ";").unwrap();
                let inline: Module = stack.iter().map(|(n, _)| n.clone()).collect();
                file.uses.push((inline, join(&tokens[k + 1..end])));
                k = end;
            }
            _ => {}
        }
        k += 1;
    }
    file
}

/// Tokens back into text: a space only between two words (`Y as Why`).
fn join(tokens: &[String]) -> String {
    let word = |t: &String| t.starts_with(|c: char| c.is_alphanumeric() || c == '_');
    let mut out = String::new();
    for (i, t) in tokens.iter().enumerate() {
        if i > 0 && word(t) && word(&tokens[i - 1]) {
            out.push(' ');
        }
        out.push_str(t);
    }
    out
}

fn tokenize(code: &str) -> Vec<String> {
    let mut tokens = Vec::new();
    let mut word = String::new();
    for c in code.chars() {
        if c.is_alphanumeric() || c == '_' {
            word.push(c);
            continue;
        }
        if !word.is_empty() {
            tokens.push(std::mem::take(&mut word));
        }
        if !c.is_whitespace() {
            tokens.push(c.to_string());
        }
    }
    tokens.push(word);
    tokens
}

/// The paths of a use tree (`a::{b, c::d as e, self}`) with the name each brings into scope.
fn expand(tree: &str) -> Vec<(Vec<String>, String)> {
    fn split_top(s: &str) -> Vec<&str> {
        let (mut parts, mut depth, mut start) = (Vec::new(), 0, 0);
        for (i, ch) in s.char_indices() {
            match ch {
                '{' => depth += 1,
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    parts.push(&s[start..i]);
                    start = i + 1;
                }
                _ => {}
            }
        }
        parts.push(&s[start..]);
        parts.into_iter().filter(|p| !p.is_empty()).collect()
    }
    let mut out = Vec::new();
    let tree = tree.trim_start_matches("::");
    if let Some(open) = tree.find('{') {
        let prefix: Vec<String> = tree[..open]
            .split("::")
            .filter(|s| !s.is_empty())
            .map(String::from)
            .collect();
        let inner = &tree[open + 1..tree.len() - 1];
        for part in split_top(inner) {
            for (mut path, name) in expand(part) {
                if path == ["self"] {
                    path = prefix.clone();
                    let name = prefix.last().cloned().unwrap_or_default();
                    out.push((path, name));
                    continue;
                }
                let mut full = prefix.clone();
                full.append(&mut path);
                out.push((full, name));
            }
        }
        return out;
    }
    let (path, alias) = match tree.split_once(" as ") {
        Some((p, a)) => (p, Some(a)),
        None => (tree, None),
    };
    let path: Vec<String> = path.split("::").map(String::from).collect();
    let name = alias.map_or_else(|| path.last().cloned().unwrap(), String::from);
    out.push((path, name));
    out
}

/// Resolves the modules every file depends on, through names brought into scope by `use`.
struct Crate {
    files: BTreeMap<Module, File>,
    /// Per file module: the names its `use` declarations bring into scope, as absolute paths.
    scope: BTreeMap<Module, BTreeMap<String, Vec<String>>>,
}

impl Crate {
    /// `path` as written in module `at` (a file's module plus inline modules), made absolute.
    fn absolute(&self, at: &Module, path: &[String]) -> Option<Vec<String>> {
        let mut base = at.clone();
        let mut rest = path;
        match rest.first().map(String::as_str) {
            Some("crate") => {
                base.clear();
                rest = &rest[1..];
            }
            Some("self") => rest = &rest[1..],
            Some("super") => {
                while rest.first().map(String::as_str) == Some("super") {
                    base.pop()?;
                    rest = &rest[1..];
                }
            }
            Some(first) => {
                // A child module of `at` (a file's or an inline one's), else another crate.
                let file = self.files.get(at)?;
                if !file.children.contains(first)
                    && !self
                        .files
                        .contains_key(&[at.clone(), vec![first.to_string()]].concat())
                {
                    return None;
                }
            }
            None => return None,
        }
        Some([base, rest.to_vec()].concat())
    }

    /// The file module that defines the item at absolute `path`, following `use` names.
    fn defining(&self, path: &[String], hops: usize) -> Option<Module> {
        let mut module: Module = Vec::new();
        for (i, seg) in path.iter().enumerate() {
            let mut deeper = module.clone();
            deeper.push(seg.clone());
            if self.files.contains_key(&deeper) {
                module = deeper;
                continue;
            }
            // `seg` is an item of `module`, maybe one it imports from elsewhere.
            if hops < 8 {
                if let Some(target) = self.scope.get(&module).and_then(|s| s.get(seg)) {
                    let mut next = target.clone();
                    next.extend(path[i + 1..].iter().cloned());
                    return self.defining(&next, hops + 1).or(Some(module));
                }
            }
            return Some(module);
        }
        Some(module)
    }
}

fn dependencies(src: &Path) -> BTreeMap<Module, BTreeSet<Module>> {
    let mut paths = Vec::new();
    rust_files(src, &mut paths);
    let files: BTreeMap<Module, File> = paths
        .iter()
        .map(|p| {
            let text = fs::read_to_string(p).unwrap();
            (module_of(src, p), parse(&text))
        })
        .collect();
    let mut krate = Crate {
        files,
        scope: BTreeMap::new(),
    };
    let mut scope = BTreeMap::new();
    for (module, file) in &krate.files {
        let names: &mut BTreeMap<String, Vec<String>> = scope.entry(module.clone()).or_default();
        for (inline, tree) in file.uses.iter().filter(|(i, _)| i.is_empty()) {
            let _ = inline;
            for (path, name) in expand(tree) {
                if name == "*" {
                    continue;
                }
                if let Some(abs) = krate.absolute(module, &path) {
                    names.insert(name, abs);
                }
            }
        }
    }
    krate.scope = scope;
    let mut deps: BTreeMap<Module, BTreeSet<Module>> = BTreeMap::new();
    for (module, file) in &krate.files {
        let entry = deps.entry(module.clone()).or_default();
        for (inline, tree) in &file.uses {
            let at = [module.clone(), inline.clone()].concat();
            for (path, _) in expand(tree) {
                let path: Vec<String> = path.into_iter().filter(|s| s != "*").collect();
                // Inline modules are not files: resolve from the file's module upwards.
                let Some(abs) = krate
                    .absolute(&at, &path)
                    .or_else(|| krate.absolute(module, &path))
                else {
                    continue;
                };
                let Some(target) = krate.defining(&abs, 0) else {
                    continue;
                };
                let ancestor = module.starts_with(&target);
                if !ancestor {
                    entry.insert(target);
                }
            }
        }
    }
    deps
}

/// The strongly connected components with more than one module (Tarjan).
fn circles(deps: &BTreeMap<Module, BTreeSet<Module>>) -> Vec<Vec<Module>> {
    struct State<'a> {
        deps: &'a BTreeMap<Module, BTreeSet<Module>>,
        index: BTreeMap<&'a Module, usize>,
        low: BTreeMap<&'a Module, usize>,
        stack: Vec<&'a Module>,
        on_stack: BTreeSet<&'a Module>,
        out: Vec<Vec<Module>>,
    }
    fn visit<'a>(s: &mut State<'a>, v: &'a Module) {
        let i = s.index.len();
        s.index.insert(v, i);
        s.low.insert(v, i);
        s.stack.push(v);
        s.on_stack.insert(v);
        for w in s.deps.get(v).into_iter().flatten() {
            let Some((w, _)) = s.deps.get_key_value(w) else {
                continue;
            };
            if !s.index.contains_key(w) {
                visit(s, w);
                let low = s.low[v].min(s.low[w]);
                s.low.insert(v, low);
            } else if s.on_stack.contains(w) {
                let low = s.low[v].min(s.index[w]);
                s.low.insert(v, low);
            }
        }
        if s.low[v] == s.index[v] {
            let mut component = Vec::new();
            while let Some(w) = s.stack.pop() {
                s.on_stack.remove(w);
                component.push(w.clone());
                if w == v {
                    break;
                }
            }
            if component.len() > 1 {
                s.out.push(component);
            }
        }
    }
    let mut s = State {
        deps,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        out: Vec::new(),
    };
    for v in deps.keys() {
        if !s.index.contains_key(v) {
            visit(&mut s, v);
        }
    }
    s.out
}

fn name(m: &Module) -> String {
    if m.is_empty() {
        "crate".into()
    } else {
        m.join("::")
    }
}

#[test]
fn src_has_no_import_circles() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let deps = dependencies(&src);
    let found: Vec<String> = circles(&deps)
        .iter()
        .map(|c| c.iter().map(name).collect::<Vec<_>>().join(" <-> "))
        .collect();
    if std::env::var_os("VSR_CIRCLE_EDGES").is_some() {
        for c in circles(&deps) {
            for m in &c {
                for d in deps[m].iter().filter(|d| c.contains(d)) {
                    println!("{} -> {}", name(m), name(d));
                }
            }
        }
    }
    assert!(found.is_empty(), "import circles:\n{}", found.join("\n"));
}

#[test]
fn the_reader_sees_circles_and_the_module_tree() {
    let dir = std::env::temp_dir().join(format!("voussoir-circles-{}", std::process::id()));
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(dir.join("a")).unwrap();
    let write = |p: &str, t: &str| fs::write(dir.join(p), t).unwrap();
    write("lib.rs", "mod a;\nmod b;\npub use b::Thing;\n");
    write("a/mod.rs", "mod x;\nmod y;\nuse x::X; // use y::Y;\n");
    // x uses its parent (allowed) and, through the parent's re-export, b.
    write(
        "a/x.rs",
        "use super::super::Thing;\nuse super::y::{self, Y as Why};\n",
    );
    write(
        "a/y.rs",
        "#[cfg(test)]\nmod tests {\n    use crate::a::x::X;\n}\nfn f() { let s = \"use crate::a::x;\"; }\n",
    );
    write("b.rs", "pub struct Thing;\n");
    let deps = dependencies(&dir);
    let set = |names: &[&str]| -> BTreeSet<Module> {
        names
            .iter()
            .map(|n| n.split("::").map(String::from).collect())
            .collect()
    };
    assert_eq!(deps[&vec!["a".to_string()]], set(&["a::x"]));
    assert_eq!(
        deps[&vec!["a".to_string(), "x".to_string()]],
        set(&["a::y", "b"])
    );
    assert!(deps[&vec!["a".to_string(), "y".to_string()]].is_empty());
    assert!(circles(&deps).is_empty());
    // y using x back closes a circle.
    write("a/y.rs", "use super::x;\n");
    let found = circles(&dependencies(&dir));
    assert_eq!(found.len(), 1);
    assert_eq!(
        found[0].iter().map(name).collect::<BTreeSet<_>>(),
        ["a::x", "a::y"].map(String::from).into()
    );
    let _ = fs::remove_dir_all(&dir);
}
