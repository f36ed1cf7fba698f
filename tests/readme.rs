//! Every `halo4d` command the README and `docs/` show parses against the command line as it
//! is (its flags, their values), and every fixture it names exists.

use clap::{CommandFactory, Parser};
use std::path::PathBuf;

#[allow(dead_code)]
#[path = "../src/bin/halo4d/cli.rs"]
mod cli;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The README and every page of `docs/`.
fn pages() -> Vec<PathBuf> {
    let mut out = vec![root().join("README.md")];
    let mut docs: Vec<PathBuf> = std::fs::read_dir(root().join("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    docs.sort();
    out.extend(docs);
    out
}

/// The lines of a page's fenced code blocks, with their line numbers.
fn code_lines(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut fenced = false;
    for (i, line) in text.lines().enumerate() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
        } else if fenced {
            out.push((i + 1, line.trim().to_string()));
        }
    }
    out
}

/// The arguments of a shell line that runs halo4d (`halo4d ...`, `target/release/halo4d
/// ...`, `cargo run --release -- ...`), without the program: None for any other line.
/// Comments are cut, shell variables stand for 0 (`--shard $SLURM_ARRAY_TASK_ID/40`), and
/// quotes group words.
fn halo4d_args(line: &str) -> Option<Vec<String>> {
    let line = line.strip_prefix("$ ").unwrap_or(line);
    let command = line.split(" #").next()?.trim();
    let rest = [
        "halo4d ",
        "./target/release/halo4d ",
        "target/release/halo4d ",
    ]
    .iter()
    .find_map(|p| command.strip_prefix(p))
    .or_else(|| {
        let cargo = command.strip_prefix("cargo run --release")?;
        // The viewer and the examples are other programs; halo4d is the default one.
        (!cargo.contains("--bin") && !cargo.contains("--example"))
            .then(|| cargo.split_once("-- ").map_or("", |(_, a)| a))
    })?;
    let mut words = Vec::new();
    let mut word = String::new();
    let mut quote = None;
    let mut chars = rest.chars().peekable();
    while let Some(c) = chars.next() {
        match (quote, c) {
            (None, '"' | '\'') => quote = Some(c),
            (Some(q), c) if c == q => quote = None,
            (None, ' ') => {
                if !word.is_empty() {
                    words.push(std::mem::take(&mut word));
                }
            }
            (_, '$') => {
                while chars.peek().is_some_and(|c| {
                    c.is_ascii_alphanumeric() || *c == '_' || *c == '{' || *c == '}'
                }) {
                    chars.next();
                }
                word.push('0');
            }
            (_, c) => word.push(c),
        }
    }
    if !word.is_empty() {
        words.push(word);
    }
    // A line that continues (`\`) or pipes on is cut there.
    let end = words
        .iter()
        .position(|w| ["\\", "|", "&&", ";", ">", "2>"].contains(&w.as_str()))
        .unwrap_or(words.len());
    words.truncate(end);
    Some(words)
}

/// What is wrong with a line that runs halo4d: flags the command line refuses, fixtures
/// that do not exist. None for a line that does not run halo4d. A synopsis (`halo4d build
/// [SCENE] [--out DIR]`, `halo4d --help, ...`) names its command's flags: each must be one.
fn problems(line: &str) -> Option<Vec<String>> {
    let args = halo4d_args(line)?;
    let mut out = Vec::new();
    if args
        .iter()
        .any(|a| a.starts_with('[') || a.ends_with(',') || a == "...")
    {
        let command = cli::Cli::command();
        let sub = args.first().and_then(|a| command.find_subcommand(a));
        for flag in args
            .iter()
            .filter_map(|a| a.trim_start_matches('[').strip_prefix("--"))
        {
            let flag = flag.trim_end_matches([']', ',', '.']);
            let known = ["help", "version"].contains(&flag)
                || sub.is_some_and(|s| s.get_arguments().any(|a| a.get_long() == Some(flag)));
            if !known {
                out.push(format!("--{flag} is not a flag of this command"));
            }
        }
        return Some(out);
    }
    let argv = std::iter::once("halo4d".to_string()).chain(args.iter().cloned());
    if let Err(e) = cli::Cli::try_parse_from(argv) {
        out.push(e.to_string().lines().next().unwrap_or("").to_string());
    }
    for arg in args.iter().filter(|a| a.starts_with("fixtures/")) {
        if !root().join(arg).exists() {
            out.push(format!("{arg} does not exist"));
        }
    }
    Some(out)
}

#[test]
fn every_halo4d_command_the_docs_show_parses_and_names_fixtures_that_exist() {
    let mut commands = 0;
    let mut failures = Vec::new();
    for page in pages() {
        let text = std::fs::read_to_string(&page).unwrap();
        let name = page.strip_prefix(root()).unwrap().display().to_string();
        for (line_no, line) in code_lines(&text) {
            let Some(found) = problems(&line) else {
                continue;
            };
            commands += 1;
            failures.extend(
                found
                    .into_iter()
                    .map(|p| format!("{name}:{line_no}: `{line}`: {p}")),
            );
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert!(
        commands >= 20,
        "only {commands} halo4d commands found in the docs"
    );
}

#[test]
fn the_docs_commands_test_catches_a_wrong_flag_and_a_missing_fixture() {
    // A planted fault for each check above, and lines it must read right.
    assert_eq!(
        problems("halo4d build fixtures/scenes/default.json"),
        Some(vec![])
    );
    assert_eq!(
        problems("halo4d build fixtures/scenes/default.json --outt x").map(|p| p.len()),
        Some(1)
    );
    assert_eq!(
        problems("halo4d build fixtures/scenes/no-such-scene.json"),
        Some(vec![
            "fixtures/scenes/no-such-scene.json does not exist".to_string()
        ])
    );
    assert_eq!(
        halo4d_args("cargo run --release -- render --style stipple # a comment").unwrap(),
        ["render", "--style", "stipple"]
    );
    assert_eq!(
        halo4d_args(r#"halo4d animate s.json --shard "$SLURM_ARRAY_TASK_ID/40""#).unwrap(),
        ["animate", "s.json", "--shard", "0/40"]
    );
    assert_eq!(
        problems("cargo run --release --features viewer --bin halo4d-view -- x.glb"),
        None
    );
    assert_eq!(problems("ls exports"), None);
    assert_eq!(
        problems("halo4d build [SCENE] [--out DIR] [--quiet]"),
        Some(vec![])
    );
    assert_eq!(
        problems("halo4d render [SCENE] [--outt FILE.png]"),
        Some(vec!["--outt is not a flag of this command".to_string()])
    );
}
