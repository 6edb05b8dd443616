//! Functions stay short: prints the longest functions in src/ and fails when one is longer than
//! `MAX_LINES` (from its `fn` line to its closing brace).

use std::path::{Path, PathBuf};

const MAX_LINES: usize = 120;

/// `text` with the contents of comments, string and character literals blanked (newlines
/// kept), so that braces in them are not counted.
fn code_only(text: &str) -> Vec<u8> {
    let b = text.as_bytes();
    let mut out = b.to_vec();
    let blank = |out: &mut Vec<u8>, from: usize, to: usize| {
        for c in &mut out[from..to] {
            if *c != b'\n' {
                *c = b' ';
            }
        }
    };
    let mut i = 0;
    while i < b.len() {
        let rest = &b[i..];
        if rest.starts_with(b"//") {
            let end = rest
                .iter()
                .position(|&c| c == b'\n')
                .map_or(b.len(), |k| i + k);
            blank(&mut out, i, end);
            i = end;
        } else if rest.starts_with(b"/*") {
            let mut depth = 0;
            let mut k = i;
            while k < b.len() {
                if b[k..].starts_with(b"/*") {
                    depth += 1;
                    k += 2;
                } else if b[k..].starts_with(b"*/") {
                    depth -= 1;
                    k += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    k += 1;
                }
            }
            blank(&mut out, i, k);
            i = k;
        } else if let Some(end) = raw_string_end(b, i) {
            blank(&mut out, i, end);
            i = end;
        } else if b[i] == b'"' {
            let mut k = i + 1;
            while k < b.len() && b[k] != b'"' {
                k += if b[k] == b'\\' { 2 } else { 1 };
            }
            blank(&mut out, i, k + 1);
            i = k + 1;
        } else if b[i] == b'\'' {
            // A character literal ('x', '\n', '\u{7f}'), or else a lifetime.
            let end = if rest.get(1) == Some(&b'\\') {
                rest.iter()
                    .skip(2)
                    .position(|&c| c == b'\'')
                    .map(|k| i + k + 3)
            } else {
                let width = text[i + 1..].chars().next().map_or(1, char::len_utf8);
                (rest.get(1 + width) == Some(&b'\'')).then_some(i + width + 2)
            };
            match end {
                Some(end) => {
                    blank(&mut out, i, end);
                    i = end;
                }
                None => i += 1,
            }
        } else {
            i += 1;
        }
    }
    out
}

/// The end of a raw string literal (r"…", r#"…"#) starting at `i`, if one does.
fn raw_string_end(b: &[u8], i: usize) -> Option<usize> {
    if b[i] != b'r' || (i > 0 && (b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_')) {
        return None;
    }
    let hashes = b[i + 1..].iter().take_while(|&&c| c == b'#').count();
    if b.get(i + 1 + hashes) != Some(&b'"') {
        return None;
    }
    let mut close = vec![b'"'];
    close.extend(std::iter::repeat_n(b'#', hashes));
    let body = i + 2 + hashes;
    b[body..]
        .windows(close.len())
        .position(|w| w == close)
        .map(|k| body + k + close.len())
}

/// (name, first line, number of lines) of every function with a body in `text`.
fn functions(text: &str) -> Vec<(String, usize, usize)> {
    let code = code_only(text);
    let line_at = |k: usize| code[..k].iter().filter(|&&c| c == b'\n').count() + 1;
    let word = |c: u8| c.is_ascii_alphanumeric() || c == b'_';
    let mut found = Vec::new();
    let mut k = 0;
    while let Some(at) = code[k..].windows(3).position(|w| w == b"fn ") {
        let start = k + at;
        k = start + 3;
        if start > 0 && word(code[start - 1]) {
            continue;
        }
        let name_len = code[k..].iter().take_while(|&&c| word(c)).count();
        if name_len == 0 {
            continue;
        }
        let name = String::from_utf8_lossy(&code[k..k + name_len]).into_owned();
        // The body opens at the first `{` after the signature; `;` first (outside brackets,
        // as in `[f64; 2]`): no body.
        let mut nesting = 0i32;
        let Some(open) = code[k..].iter().position(|&c| {
            match c {
                b'(' | b'[' => nesting += 1,
                b')' | b']' => nesting -= 1,
                _ => {}
            }
            nesting == 0 && (c == b'{' || c == b';')
        }) else {
            break;
        };
        let open = k + open;
        if code[open] == b';' {
            continue;
        }
        let mut depth = 0;
        let mut close = open;
        for (j, &c) in code[open..].iter().enumerate() {
            match c {
                b'{' => depth += 1,
                b'}' => {
                    depth -= 1;
                    if depth == 0 {
                        close = open + j;
                        break;
                    }
                }
                _ => {}
            }
        }
        let first = line_at(start);
        found.push((name, first, line_at(close) - first + 1));
    }
    found
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

#[test]
fn the_counter_sees_bodies_not_braces_in_literals() {
    let text = "fn a(x: [u8; 2]) {\n    let s = \"}\";\n    let c = '}';\n    // }\n    let r = r#\"{\"#;\n}\nfn b<'x>(v: &'x str) -> &'x str {\n    v\n}\ntrait T {\n    fn c();\n}\n";
    let found = functions(text);
    let got: Vec<(&str, usize, usize)> = found.iter().map(|(n, l, c)| (&n[..], *l, *c)).collect();
    assert_eq!(got, [("a", 1, 6), ("b", 7, 3)]);
}

#[test]
fn no_function_in_the_enforced_folders_is_too_long() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    rust_files(&root.join("src"), &mut files);
    let mut all = Vec::new();
    for path in &files {
        let text = std::fs::read_to_string(path).unwrap();
        let rel = path
            .strip_prefix(root)
            .unwrap()
            .to_string_lossy()
            .replace('\\', "/");
        for (name, line, lines) in functions(&text) {
            all.push((lines, format!("{rel}:{line}"), name));
        }
    }
    all.sort_by(|a, b| b.0.cmp(&a.0).then_with(|| a.1.cmp(&b.1)));
    println!("longest functions in src/ (limit {MAX_LINES} lines):");
    for (lines, at, name) in all.iter().take(15) {
        println!("{lines:5}  {at}  {name}");
    }
    let too_long: Vec<String> = all
        .iter()
        .filter(|(lines, _, _)| *lines > MAX_LINES)
        .map(|(lines, at, name)| format!("{at} {name}: {lines} lines"))
        .collect();
    assert!(
        too_long.is_empty(),
        "functions longer than {MAX_LINES} lines:\n{}",
        too_long.join("\n")
    );
}
