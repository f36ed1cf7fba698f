//! The house rules that are easy to break one line at a time, held by the tests so that they
//! do not grow back unnoticed: no production function over [`MAX_FUNCTION_LINES`] lines
//! (anywhere in `src/`, the binaries and the viewer included; unit tests aside), the
//! README under [`MAX_README_LINES`] lines (the rest belongs in `docs/`), and a library
//! that prints nothing: no `print!`, `eprintln!`, `indicatif` or thread of its own outside
//! the binaries (`src/bin/`) and the explorer's window (its background work), no `quiet`
//! flag (it reports to the caller's `halo4d::progress::Observer`).

use std::path::{Path, PathBuf};

/// The longest a production function may be, from its `fn` line to its closing brace.
const MAX_FUNCTION_LINES: usize = 150;

/// The README's most lines.
const MAX_README_LINES: usize = 700;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The source with its comments, string literals and character literals blanked (their
/// lines kept), so that the braces left are the code's.
fn blank_literals(source: &str) -> String {
    let s = source.as_bytes();
    let mut out = Vec::with_capacity(s.len());
    // What a skipped run held of line ends.
    let lines = |run: &[u8], out: &mut Vec<u8>| {
        out.extend(run.iter().filter(|&&b| b == b'\n'));
    };
    let ident = |b: u8| b.is_ascii_alphanumeric() || b == b'_';
    let mut i = 0;
    while i < s.len() {
        let rest = &s[i..];
        if rest.starts_with(b"//") {
            let end = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
            i += end;
        } else if rest.starts_with(b"/*") {
            // Block comments nest.
            let (mut depth, mut k) = (0usize, 0);
            while k < rest.len() {
                if rest[k..].starts_with(b"/*") {
                    depth += 1;
                    k += 2;
                } else if rest[k..].starts_with(b"*/") {
                    depth -= 1;
                    k += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    k += 1;
                }
            }
            lines(&rest[..k], &mut out);
            i += k;
        } else if let Some((open, hashes)) =
            raw_string_open(rest).filter(|_| i == 0 || !ident(s[i - 1]))
        {
            // r"…", r#"…"#, br"…": no escapes, ended by a quote and as many hashes.
            let close: Vec<u8> = std::iter::once(b'"')
                .chain(std::iter::repeat_n(b'#', hashes))
                .collect();
            let end = rest[open..]
                .windows(close.len())
                .position(|w| w == close.as_slice())
                .map_or(rest.len(), |k| open + k + close.len());
            out.extend_from_slice(b"\"\"");
            lines(&rest[..end], &mut out);
            i += end;
        } else if rest[0] == b'"' {
            let mut k = 1;
            while k < rest.len() && rest[k] != b'"' {
                k += if rest[k] == b'\\' { 2 } else { 1 };
            }
            let end = (k + 1).min(rest.len());
            out.extend_from_slice(b"\"\"");
            lines(&rest[..end], &mut out);
            i += end;
        } else if rest[0] == b'\'' {
            // A character literal ('x', '\n', '\u{7b}', '{'), else a lifetime.
            let len = if rest.get(1) == Some(&b'\\') {
                // The escaped character first ('\'' escapes a quote), then the closing quote.
                rest.get(3..)
                    .and_then(|r| r.iter().position(|&b| b == b'\''))
                    .map(|k| k + 4)
            } else {
                // A quote is never inside a character of several bytes: i + 1 is a boundary.
                source[i + 1..]
                    .chars()
                    .next()
                    .map(char::len_utf8)
                    .filter(|&n| rest.get(1 + n) == Some(&b'\''))
                    .map(|n| n + 2)
            };
            match len {
                Some(len) => {
                    out.extend_from_slice(b"' '");
                    i += len;
                }
                None => {
                    out.push(b'\'');
                    i += 1;
                }
            }
        } else {
            out.push(rest[0]);
            i += 1;
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Where the text of a raw string opening `rest` begins and its number of hashes, if one
/// does.
fn raw_string_open(rest: &[u8]) -> Option<(usize, usize)> {
    let after_b = usize::from(rest.first() == Some(&b'b'));
    if rest.get(after_b) != Some(&b'r') {
        return None;
    }
    let hashes = rest[after_b + 1..]
        .iter()
        .take_while(|&&b| b == b'#')
        .count();
    (rest.get(after_b + 1 + hashes) == Some(&b'"')).then_some((after_b + 2 + hashes, hashes))
}

/// The name of the function a line of code declares, if it does.
fn declares(line: &str) -> Option<&str> {
    let mut rest = line.trim_start();
    if let Some(r) = rest.strip_prefix("pub") {
        rest = r.trim_start();
        if rest.starts_with('(') {
            rest = rest[rest.find(')')? + 1..].trim_start();
        }
    }
    for qualifier in ["const ", "async ", "unsafe ", "extern \"\" "] {
        if let Some(r) = rest.strip_prefix(qualifier) {
            rest = r.trim_start();
        }
    }
    let name = rest.strip_prefix("fn ")?;
    let end = name
        .find(|c: char| !(c.is_alphanumeric() || c == '_'))
        .unwrap_or(name.len());
    (end > 0).then_some(&name[..end])
}

/// Each function of `source` with a body, outside its unit tests (`#[cfg(test)]` and
/// `mod tests`): its name, first line (from 1) and length in lines.
fn functions(source: &str) -> Vec<(String, usize, usize)> {
    let code = blank_literals(source);
    let lines: Vec<&str> = code.lines().collect();
    let end = lines
        .windows(2)
        .position(|w| w[0].trim() == "#[cfg(test)]" && w[1].trim_start().starts_with("mod tests"))
        .unwrap_or(lines.len());
    let mut out = Vec::new();
    for (first, line) in lines[..end].iter().enumerate() {
        let Some(name) = declares(line) else {
            continue;
        };
        let mut depth = 0usize;
        let mut last = None;
        'scan: for (k, l) in lines[first..end].iter().enumerate() {
            for c in l.chars() {
                match c {
                    '{' => depth += 1,
                    '}' => {
                        depth = depth.saturating_sub(1);
                        if depth == 0 {
                            last = Some(first + k);
                            break 'scan;
                        }
                    }
                    // A declaration without a body.
                    ';' if depth == 0 => break 'scan,
                    _ => {}
                }
            }
        }
        if let Some(last) = last {
            out.push((name.to_string(), first + 1, last - first + 1));
        }
    }
    out
}

/// Every `.rs` file under `dir` but the unit tests kept in files of their own (`tests.rs`).
fn sources(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            out.extend(sources(&path));
        } else if path.extension().is_some_and(|e| e == "rs")
            && path.file_name().is_some_and(|n| n != "tests.rs")
        {
            out.push(path);
        }
    }
    out.sort();
    out
}

#[test]
fn no_production_function_is_over_150_lines() {
    let mut long = Vec::new();
    let mut count = 0;
    for path in sources(&root().join("src")) {
        let source = std::fs::read_to_string(&path).unwrap();
        for (name, line, length) in functions(&source) {
            count += 1;
            if length > MAX_FUNCTION_LINES {
                let file = path.strip_prefix(root()).unwrap().display();
                long.push(format!("{file}:{line} `{name}` is {length} lines"));
            }
        }
    }
    // The scan sees the functions (a scan that finds none would pass anything).
    assert!(count > 1000, "{count} functions found in src/");
    assert!(
        long.is_empty(),
        "split these into functions of at most {MAX_FUNCTION_LINES} lines:\n{}",
        long.join("\n")
    );
}

#[test]
fn a_planted_long_function_is_caught_and_braces_in_literals_are_not_code() {
    let body = |n: usize| "    let x = 1;\n".repeat(n);
    // 151 lines: the fn line, 149 of body, the closing brace; then one of 150.
    let source = format!(
        "/// A doc {{\npub(crate) fn long() {{\n{}}}\n\nconst fn short() -> u8 {{\n{}    0\n}}\n",
        body(149),
        body(147)
    );
    assert_eq!(
        functions(&source),
        [
            ("long".to_string(), 2, 151),
            ("short".to_string(), 154, 150)
        ]
    );
    // Braces in strings, raw strings, characters and comments; lifetimes; a declaration
    // without a body; the unit tests.
    let tricky = r##"
fn a<'b>(x: &'b str) -> char {
    let _ = "}\"}"; let _ = r#"}"#; let _ = b'{'; let _ = '\u{7d}'; /* } /* } */ */
    let _ = ['\'','}', '{', '\\'];
    '}'
}
fn declared(&self);
#[cfg(test)]
mod tests {
    fn t() {
    }
}
"##;
    assert_eq!(functions(tricky), [("a".to_string(), 2, 5)]);
}

#[test]
fn the_readme_is_under_700_lines() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let lines = readme.lines().count();
    assert!(
        lines < MAX_README_LINES,
        "README.md has {lines} lines: move the detail to docs/ and link it (at most {})",
        MAX_README_LINES - 1
    );
}

/// What `source` (a library file) does that only a program may: prints, draws a bar, starts
/// a thread, takes a `quiet` flag; as (line, what), comments, literals and unit tests aside.
fn printing(source: &str, threads_allowed: bool) -> Vec<(usize, &'static str)> {
    let code = blank_literals(source);
    let code = code
        .split("#[cfg(test)]\nmod tests")
        .next()
        .unwrap_or_default();
    let mut out = Vec::new();
    let words: &[&str] = &[
        "print!",
        "println!",
        "eprint!",
        "eprintln!",
        "indicatif",
        "quiet",
    ];
    for (n, line) in code.lines().enumerate() {
        let starts = |at: usize| {
            at == 0
                || !line.as_bytes()[at - 1].is_ascii_alphanumeric()
                    && line.as_bytes()[at - 1] != b'_'
        };
        for &word in words {
            let found = line.match_indices(word).any(|(at, _)| {
                let end = at + word.len();
                let whole = word.ends_with('!')
                    || !line[end..].starts_with(|c: char| c.is_ascii_alphanumeric() || c == '_');
                starts(at) && whole
            });
            if found {
                out.push((n + 1, word));
            }
        }
        if !threads_allowed && (line.contains("thread::spawn") || line.contains("thread::Builder"))
        {
            out.push((n + 1, "a thread"));
        }
    }
    out
}

#[test]
fn the_library_prints_nothing_and_starts_no_thread() {
    let src = root().join("src");
    let mut found = Vec::new();
    for path in sources(&src) {
        let rel = path
            .strip_prefix(root())
            .unwrap()
            .to_string_lossy()
            .replace('\\', "/");
        if rel.starts_with("src/bin/") {
            continue;
        }
        let source = std::fs::read_to_string(&path).unwrap();
        for (line, what) in printing(&source, rel == "src/viewer/window.rs") {
            found.push(format!("{rel}:{line}: {what}"));
        }
    }
    assert!(
        found.is_empty(),
        "the library reports to its caller's observer (halo4d::progress) and prints nothing:\n{}",
        found.join("\n")
    );
}

#[test]
fn a_planted_print_is_caught_and_one_in_a_literal_or_a_test_is_not() {
    let planted = r#"
fn a(quiet: bool) {
    let s = "eprintln!(\"x\") and quiet";
    // eprintln! in a comment
    eprintln!("{s}");
    std::thread::spawn(|| ());
    let quietly = 1;
}
#[cfg(test)]
mod tests {
    fn t() { println!("fine in a test"); }
}
"#;
    assert_eq!(
        printing(planted, false),
        [(2, "quiet"), (5, "eprintln!"), (6, "a thread")]
    );
    assert_eq!(printing(planted, true), [(2, "quiet"), (5, "eprintln!")]);
}
