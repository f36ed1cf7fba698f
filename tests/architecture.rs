//! The module graph: every `crate::` edge in `src/` points down the layers of the ARCHITECTURE
//! table in docs/ARCHITECTURE.md, and that table lists exactly the library's modules.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The ARCHITECTURE table of docs/ARCHITECTURE.md: module -> layer, from its rows
/// `| layer | `module` | ...`.
fn layers(architecture: &str) -> BTreeMap<String, u32> {
    let section = architecture
        .split("\n## ARCHITECTURE")
        .nth(1)
        .expect("docs/ARCHITECTURE.md has an ARCHITECTURE section");
    let mut out = BTreeMap::new();
    for line in section.lines().filter(|l| l.starts_with("| ")) {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        let (Some(layer), Some(module)) = (cells.get(1), cells.get(2)) else {
            continue;
        };
        let Ok(layer) = layer.parse::<u32>() else {
            continue;
        };
        let module = module
            .split('`')
            .nth(1)
            .expect("a module cell names the module in backticks");
        out.insert(module.to_string(), layer);
    }
    out
}

/// The source without comments and without the unit tests at its end (`#[cfg(test)]`
/// followed by `mod tests`): what the library itself uses.
fn code(source: &str) -> String {
    let mut out = String::new();
    let mut lines = source.lines().peekable();
    while let Some(line) = lines.next() {
        let trimmed = line.trim_start();
        if trimmed == "#[cfg(test)]"
            && lines
                .peek()
                .is_some_and(|l| l.trim_start().starts_with("mod tests"))
        {
            break;
        }
        if trimmed.starts_with("//") {
            continue;
        }
        out.push_str(line);
        out.push('\n');
    }
    out
}

/// The top-level modules `code` names through `crate::` paths, grouped imports included
/// (`use crate::{a::X, b};`).
fn uses(code: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = code;
    while let Some(i) = rest.find("crate::") {
        // `$crate::` belongs to a macro; skip it.
        let is_macro = rest[..i].ends_with('$');
        rest = &rest[i + "crate::".len()..];
        if is_macro {
            continue;
        }
        if let Some(group) = rest.strip_prefix('{') {
            let mut depth = 1;
            let end = group
                .char_indices()
                .find(|&(_, c)| {
                    depth += match c {
                        '{' => 1,
                        '}' => -1,
                        _ => 0,
                    };
                    depth == 0
                })
                .map_or(group.len(), |(k, _)| k);
            // The group's items at its own level; nested groups only name submodules.
            let mut flat = String::new();
            let mut depth = 0;
            for c in group[..end].chars() {
                match c {
                    '{' => depth += 1,
                    '}' => depth -= 1,
                    c if depth == 0 => flat.push(c),
                    _ => {}
                }
            }
            out.extend(
                flat.split(',')
                    .filter_map(|item| item.split("::").next())
                    .map(|name| name.trim().to_string()),
            );
            rest = &group[end..];
        } else {
            let name: String = rest
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            out.push(name);
        }
    }
    out.retain(|n| !n.is_empty());
    out
}

/// Every edge `(from, to)` between modules whose layers do not go strictly down, and every
/// edge to a module without a layer. `sources` are (module, source text).
fn upward_edges(
    layers: &BTreeMap<String, u32>,
    sources: &[(String, String)],
) -> Vec<(String, String)> {
    let mut out = Vec::new();
    for (module, source) in sources {
        for to in uses(&code(source)) {
            if &to == module {
                continue;
            }
            let ok = match (layers.get(module), layers.get(&to)) {
                (Some(a), Some(b)) => b < a,
                _ => false,
            };
            if !ok && !out.contains(&(module.clone(), to.clone())) {
                out.push((module.clone(), to));
            }
        }
    }
    out
}

/// Every `.rs` file of the library (not its binaries), with its top-level module.
fn library_sources(src: &Path) -> Vec<(String, String)> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(&path, out);
            } else if path.extension().is_some_and(|e| e == "rs") {
                out.push(path);
            }
        }
    }
    let mut files = Vec::new();
    walk(src, &mut files);
    files.sort();
    files
        .into_iter()
        .filter_map(|path| {
            let rel = path.strip_prefix(src).unwrap();
            let first = rel.components().next()?.as_os_str().to_str()?.to_string();
            let module = first.trim_end_matches(".rs").to_string();
            (module != "main" && module != "lib" && module != "bin")
                .then(|| (module, std::fs::read_to_string(&path).unwrap()))
        })
        .collect()
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn every_edge_between_modules_points_down_the_layers() {
    let architecture = std::fs::read_to_string(root().join("docs/ARCHITECTURE.md")).unwrap();
    let layers = layers(&architecture);
    let sources = library_sources(&root().join("src"));
    let modules: std::collections::BTreeSet<String> =
        sources.iter().map(|(m, _)| m.clone()).collect();
    let listed: std::collections::BTreeSet<String> = layers.keys().cloned().collect();
    assert_eq!(
        modules, listed,
        "the ARCHITECTURE table of docs/ARCHITECTURE.md lists exactly the modules of src/"
    );
    let up = upward_edges(&layers, &sources);
    assert!(
        up.is_empty(),
        "edges that do not point down the layers (from, to): {up:?}"
    );
    // The scan sees the real edges: the pipeline uses the stages.
    let pipeline = &sources.iter().find(|(m, _)| m == "pipeline").unwrap().1;
    let used = uses(&code(pipeline));
    for stage in ["sample", "view", "halo", "intersect", "verify", "export"] {
        assert!(used.iter().any(|u| u == stage), "{stage}: {used:?}");
    }
}

#[test]
fn a_planted_upward_use_is_caught() {
    let architecture = std::fs::read_to_string(root().join("docs/ARCHITECTURE.md")).unwrap();
    let layers = layers(&architecture);
    let mut sources = library_sources(&root().join("src"));
    let sample = sources.iter_mut().find(|(m, _)| m == "sample").unwrap();
    let clean = sample.1.clone();
    for planted in [
        "use crate::pipeline::Built;\n",
        "use crate::{surfaces::Surface, scene::Scene};\n",
        "use crate::{\n    limits::TRIANGLES,\n    export::{self, Staged},\n};\n",
        "fn f() -> usize { crate::render::compare::to_csv(&[]).len() }\n",
    ] {
        sample.1 = format!("{planted}{clean}");
        let up = upward_edges(&layers, std::slice::from_ref(sample));
        assert_eq!(up.len(), 1, "{planted}: {up:?}");
        assert_eq!(up[0].0, "sample");
    }
    // Comments, the unit tests and macros' `$crate` are not edges.
    sample.1 = format!(
        "//! [`crate::pipeline`]\n$crate::pipeline::run\n{clean}\n#[cfg(test)]\nmod tests {{\n    use crate::pipeline::run;\n}}\n"
    );
    assert!(upward_edges(&layers, std::slice::from_ref(sample)).is_empty());
}

#[test]
fn grouped_imports_name_each_module() {
    assert_eq!(
        uses("use crate::{a::X, b, c::{d, e::F}};\nlet x = crate::g::h();"),
        ["a", "b", "c", "g"]
    );
}
