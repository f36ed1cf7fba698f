//! Seeded, structure-aware fuzzing of the input parsers: scene files ([`Scene::parse`]),
//! `.glb` ([`read_glb`], [`read_scene_glb`]), legacy `.vtk` ([`read_vtk`]) and other
//! programs' tetrahedral meshes (`.vtu`, `.msh`, `.mesh`, `.node`/`.ele`).
//!
//! Each target starts from valid inputs and applies a short list of mutations that know the
//! format. proptest draws the lists from a fixed ChaCha seed (the same cases on every run, no
//! persistence files) and shrinks a failing list to a minimal one:
//! - scenes: the fixture scenes (formula surfaces among them) and animated scenes, the
//!   default scene with every field written out and the surface catalogue, as JSON trees whose numbers are set to extremes (0, -0, 5e-324,
//!   1e308, 1e400, huge integers, `NaN`), whose keys are deleted, duplicated, renamed or
//!   inserted, whose values change type or are grafted from elsewhere; then the text is cut
//!   or given stray characters (formula surfaces built, and 4D mesh files, are fuzzed in
//!   [`crate::fuzz_build`]);
//! - `.glb`: the patches fixture built once (8 x 8 grid); its JSON chunk mutated as a tree
//!   (accessor counts, offsets, component types, buffer lengths, the extras' indices) and
//!   re-packed with correct chunk headers (some cases start from the halo's tetrahedra
//!   accessor cut to none, half or all but one), then words of the headers and of the BIN chunk set
//!   to extremes (NaN, u32::MAX, ...), bits flipped, the file cut or lengthened;
//! - `.vtk`: the same build's binary file and two ASCII renditions (file versions 3.0 and
//!   5.1, with sections halo4d does not write): values in the binary blocks set to extremes,
//!   the header lines' counts, types and keywords changed, lines deleted, duplicated, swapped
//!   or inserted, numbers in the ASCII data changed, bytes flipped, the file cut; also an
//!   ASCII file without halo4d's FIELD data (another program's) and halos cut to half and
//!   to no tetrahedra;
//! - other programs' tetrahedral meshes (`.vtu`, `.msh`, `.mesh`, TetGen's `.node` and
//!   `.ele`): the fixtures of `fixtures/tetmeshes/`, a word replaced by an extreme (huge
//!   counts, -1, NaN, a section's end), bytes flipped, inserted, the file cut.
//!
//! Properties: no input panics a parser; every error message is non-empty and shorter than
//! [`MAX_MESSAGE`] bytes (a scene's starts with the file's name); a scene that parses writes
//! out and parses back equal; whatever a reader returns is finite, its indices in range and
//! its counts consistent, and `read_glb` reads the same halos as `read_scene_glb`; a `.vtk`
//! without the layout is read as plain tetrahedra and checked; a halo cut short (a strict
//! prefix of its tetrahedra, the rest of the file as built) fails `halo4d check`. A failing
//! case is reported as its mutations, and the input they make is written to the temporary
//! directory.
//!
//! The default run (`cargo test --release`) tries [`SCENE_CASES`], [`GLB_CASES`] and
//! [`VTK_CASES`] cases; with [`crate::fuzz_build`]'s, all the fuzzing takes about 30 s on
//! two cores (`cargo test --release --test main fuzz`). A longer run, on another seed
//! (`HALO4D_FUZZ_SEED=N` picks yet another):
//!
//! ```sh
//! HALO4D_FUZZ_CASES=200000 cargo test --release --test main fuzz -- --ignored
//! ```

use crate::common::{fixture, fixture_scenes, pack_glb, scenes_in};
use halo4d::Scene;
use halo4d::{
    import::FileTetrahedra, import::ImportedHalo, import::ImportedScene, import::PlainTetrahedra,
    import::read_glb, import::read_scene_glb, import::read_vtk, import::read_vtk_tetrahedra,
};
use proptest::collection::vec;
use proptest::prelude::*;
use proptest::sample::select;
use proptest::test_runner::{Config, RngAlgorithm, TestError, TestRng, TestRunner};
use serde_json::Value;
use std::cell::RefCell;
use std::collections::BTreeMap;
use std::fmt::Debug;
use std::sync::OnceLock;

/// Every error message must be shorter than this: one line a person can read, not an echo
/// of the input (a malformed VTK once got a 66 KB line back).
pub(crate) const MAX_MESSAGE: usize = 1000;

/// Scene cases of the default run.
const SCENE_CASES: u32 = 20_000;
/// `.glb` cases of the default run (each read by both readers).
const GLB_CASES: u32 = 6000;
/// `.vtk` cases of the default run.
const VTK_CASES: u32 = 8000;
/// Cases of the default run per format of other programs' tetrahedral meshes (`.vtu`,
/// `.msh`, `.mesh`, `.node`, `.ele`).
const MESH_CASES: u32 = 2000;

// ---------------------------------------------------------------------------------------
// The runner
// ---------------------------------------------------------------------------------------

/// A deterministic runner for `target`: ChaCha from a seed made of the target's name (and,
/// in the long run, `HALO4D_FUZZ_SEED`), no failure persistence.
fn runner(target: &str, cases: u32, long: bool) -> TestRunner {
    let extra = if long {
        let seed = std::env::var("HALO4D_FUZZ_SEED").unwrap_or_default();
        format!("long-{seed}")
    } else {
        String::new()
    };
    let mut seed = [0x5au8; 32];
    for (i, b) in format!("halo4d-fuzz-{target}-{extra}").bytes().enumerate() {
        seed[i % 32] = seed[i % 32].wrapping_mul(31).wrapping_add(b);
    }
    let config = Config {
        cases,
        failure_persistence: None,
        rng_algorithm: RngAlgorithm::ChaCha,
        max_shrink_iters: 4096,
        ..Config::default()
    };
    TestRunner::new_with_rng(config, TestRng::from_seed(RngAlgorithm::ChaCha, &seed))
}

/// Runs `cases` cases of `strategy` through `test`; on a failure writes the minimal input
/// (`render`ed) to the temporary directory and panics with it and its mutations.
pub(crate) fn fuzz<S: Strategy>(
    target: &str,
    ext: &str,
    cases: u32,
    long: bool,
    strategy: S,
    render: impl Fn(&S::Value) -> Vec<u8>,
    test: impl Fn(&[u8]) -> Result<(), String>,
) where
    S::Value: Debug,
{
    let mut runner = runner(target, cases, long);
    let result = runner.run(&strategy, |case| {
        test(&render(&case)).map_err(TestCaseError::fail)
    });
    match result {
        Ok(()) => {}
        Err(TestError::Fail(why, case)) => {
            let input = render(&case);
            let path = std::env::temp_dir().join(format!("halo4d-fuzz-{target}.{ext}"));
            let written = std::fs::write(&path, &input).is_ok();
            panic!(
                "fuzz {target}: {why}\nminimal case: {case:#?}\ninput ({} bytes{}): {:.2000}",
                input.len(),
                if written {
                    format!(", written to {}", path.display())
                } else {
                    String::new()
                },
                String::from_utf8_lossy(&input)
            );
        }
        Err(e) => panic!("fuzz {target}: {e}"),
    }
}

/// The number of cases of the long run, from `HALO4D_FUZZ_CASES`.
pub(crate) fn long_cases() -> u32 {
    std::env::var("HALO4D_FUZZ_CASES")
        .ok()
        .map(|s| {
            s.trim()
                .parse()
                .expect("HALO4D_FUZZ_CASES is a number of cases")
        })
        .unwrap_or(100_000)
}

/// An error's message is one line of reasonable size.
pub(crate) fn message_ok(what: &str, message: &str) -> Result<(), String> {
    if message.trim().is_empty() {
        return Err(format!("{what}: empty error message"));
    }
    if message.len() >= MAX_MESSAGE {
        return Err(format!(
            "{what}: error message of {} bytes: {:.300}...",
            message.len(),
            message
        ));
    }
    Ok(())
}

/// Counts what the cases came to, to check that the mutations reach every outcome.
#[derive(Default)]
pub(crate) struct Tally(RefCell<BTreeMap<&'static str, usize>>);

impl Tally {
    pub(crate) fn add(&self, what: &'static str) {
        *self.0.borrow_mut().entry(what).or_default() += 1;
    }

    fn get(&self, what: &str) -> usize {
        self.0.borrow().get(what).copied().unwrap_or(0)
    }

    /// At least `share` of the cases came to `what`.
    pub(crate) fn assert_share(&self, what: &str, share: f64) {
        let (count, cases) = (self.get(what), self.get("cases"));
        eprintln!("{count} of {cases} cases {what}");
        assert!(
            count as f64 >= share * cases as f64,
            "only {count} of {cases} cases {what}: the mutations no longer reach it"
        );
    }
}

// ---------------------------------------------------------------------------------------
// JSON trees and their mutations (scenes and the .glb JSON chunk)
// ---------------------------------------------------------------------------------------

/// A JSON value that keeps what `serde_json::Value` cannot: repeated keys, and numbers as
/// any text (`1e400`, `NaN`, `-0`).
#[derive(Clone, Debug, PartialEq)]
enum Node {
    Null,
    Bool(bool),
    Num(String),
    Str(String),
    Arr(Vec<Node>),
    Obj(Vec<(String, Node)>),
}

impl Node {
    fn from_value(v: &Value) -> Node {
        match v {
            Value::Null => Node::Null,
            Value::Bool(b) => Node::Bool(*b),
            Value::Number(n) => Node::Num(n.to_string()),
            Value::String(s) => Node::Str(s.clone()),
            Value::Array(a) => Node::Arr(a.iter().map(Node::from_value).collect()),
            Value::Object(o) => Node::Obj(
                o.iter()
                    .map(|(k, v)| (k.clone(), Node::from_value(v)))
                    .collect(),
            ),
        }
    }

    fn write(&self, out: &mut String) {
        let quoted = |s: &str| serde_json::to_string(s).expect("a string serializes");
        match self {
            Node::Null => out.push_str("null"),
            Node::Bool(b) => out.push_str(if *b { "true" } else { "false" }),
            Node::Num(n) => out.push_str(n),
            Node::Str(s) => out.push_str(&quoted(s)),
            Node::Arr(items) => {
                out.push('[');
                for (i, item) in items.iter().enumerate() {
                    if i > 0 {
                        out.push(',');
                    }
                    item.write(out);
                }
                out.push(']');
            }
            Node::Obj(members) => {
                out.push('{');
                for (i, (k, v)) in members.iter().enumerate() {
                    if i > 0 {
                        out.push(',');
                    }
                    out.push_str(&quoted(k));
                    out.push(':');
                    v.write(out);
                }
                out.push('}');
            }
        }
    }

    fn text(&self) -> String {
        let mut s = String::new();
        self.write(&mut s);
        s
    }

    /// Every node in pre-order: its path (child positions from the root) and the key it
    /// has in its object, if any.
    fn walk(&self, path: &mut Vec<usize>, key: Option<&str>, out: &mut Vec<Place>) {
        out.push(Place {
            path: path.clone(),
            key: key.map(String::from),
        });
        match self {
            Node::Arr(items) => {
                for (i, item) in items.iter().enumerate() {
                    path.push(i);
                    item.walk(path, None, out);
                    path.pop();
                }
            }
            Node::Obj(members) => {
                for (i, (k, v)) in members.iter().enumerate() {
                    path.push(i);
                    v.walk(path, Some(k), out);
                    path.pop();
                }
            }
            _ => {}
        }
    }

    fn places(&self) -> Vec<Place> {
        let mut out = Vec::new();
        self.walk(&mut Vec::new(), None, &mut out);
        out
    }

    fn at(&mut self, path: &[usize]) -> &mut Node {
        match path.split_first() {
            None => self,
            Some((&i, rest)) => match self {
                Node::Arr(items) => items[i].at(rest),
                Node::Obj(members) => members[i].1.at(rest),
                _ => unreachable!("a path goes through containers"),
            },
        }
    }

    fn at_ref(&self, path: &[usize]) -> &Node {
        match path.split_first() {
            None => self,
            Some((&i, rest)) => match self {
                Node::Arr(items) => items[i].at_ref(rest),
                Node::Obj(members) => members[i].1.at_ref(rest),
                _ => unreachable!("a path goes through containers"),
            },
        }
    }

    /// Children of a container.
    fn len(&self) -> usize {
        match self {
            Node::Arr(items) => items.len(),
            Node::Obj(members) => members.len(),
            _ => 0,
        }
    }

    fn remove(&mut self, i: usize) {
        match self {
            Node::Arr(items) => {
                items.remove(i);
            }
            Node::Obj(members) => {
                members.remove(i);
            }
            _ => {}
        }
    }

    fn duplicate(&mut self, i: usize) {
        match self {
            Node::Arr(items) => items.insert(i, items[i].clone()),
            Node::Obj(members) => members.insert(i, members[i].clone()),
            _ => {}
        }
    }

    fn subtrees<'a>(&'a self, out: &mut Vec<&'a Node>) {
        out.push(self);
        match self {
            Node::Arr(items) => items.iter().for_each(|n| n.subtrees(out)),
            Node::Obj(members) => members.iter().for_each(|(_, n)| n.subtrees(out)),
            _ => {}
        }
    }
}

/// A node of a tree: where it is and under which key.
struct Place {
    path: Vec<usize>,
    key: Option<String>,
}

/// Numbers as JSON text, some of them not JSON at all.
const NUMBERS: &[&str] = &[
    "0",
    "-0",
    "0.0",
    "-0.0",
    "1",
    "-1",
    "2",
    "3",
    "4",
    "5",
    "6",
    "7",
    "9",
    "10",
    "64",
    "65",
    "89",
    "90",
    "-90",
    "360",
    "4096",
    "4097",
    "8192",
    "8193",
    "5120",
    "5121",
    "5123",
    "5125",
    "5126",
    "0.5",
    "1.5",
    "0.0001",
    "1e-9",
    "1e-30",
    "1e30",
    "1e31",
    "1e-300",
    "5e-324",
    "-5e-324",
    "2.2250738585072014e-308",
    "1e308",
    "-1e308",
    "1.7976931348623157e308",
    "1e309",
    "-1e400",
    "1e-400",
    "2147483647",
    "2147483648",
    "4294967295",
    "4294967296",
    "9007199254740993",
    "9223372036854775807",
    "-9223372036854775808",
    "-9223372036854775809",
    "18446744073709551615",
    "18446744073709551616",
    "100000000000000000000000000000",
    "NaN",
    "Infinity",
    "-Infinity",
    "nan",
    "01",
    "1.",
    ".5",
    "+1",
    "-",
    "1e",
];

/// Strings beyond those of the seeds: names a scene refuses, and text that is odd.
const STRINGS: &[&str] = &[
    "",
    ".",
    "..",
    "../evil",
    "a/b",
    "a\\b",
    ".hidden",
    "NaN",
    "inf",
    "-inf",
    "1e999",
    "0",
    "\u{0}",
    "\u{7f}",
    "é",
    "\u{1f600}",
    "SCALAR",
    "VEC2",
    "VEC3",
    "VEC4",
    "MAT4",
    "data:application/octet-stream;base64,AAAA",
    "external.bin",
    "uniform",
    "adaptive",
    "orthographic",
    "perspective",
    "global_order",
    "quality",
    "paper",
    "shrink",
    "report",
    "exact",
    "slices",
    "diverging",
    "viridis",
    "gray",
    "u",
    "v",
];

/// Keys beyond those of the seeds.
const KEYS: &[&str] = &[
    "",
    "type",
    "name",
    "extras",
    "x",
    "count",
    "byteOffset",
    "byteLength",
    "byteStride",
    "componentType",
    "bufferView",
    "buffer",
    "uri",
    "sparse",
    "normalized",
    "indices",
    "mode",
    "POSITION",
    "NORMAL",
    "_W",
    "_T",
    "_D",
    "halo",
    "surface",
    "curves",
    "polylines",
    "tetrahedra",
    "surface_vertices",
    "layers",
    "surface_mesh",
    "ribbons",
    "along",
    "gap",
    "absolute_tolerance",
    "tolerance",
    "max_triangles",
    "twists",
];

/// A value to put somewhere in a tree.
#[derive(Clone, Debug)]
enum Gen {
    /// One of [`NUMBERS`].
    Number(u32),
    Int(i64),
    /// An f64 from its bits, as Rust writes it (`NaN` and `inf` included).
    Float(u64),
    /// The node's own number (or string) changed a little: +-1, x2, /2, negated, ...
    Relative(u32),
    /// A string of the vocabulary (the seeds' strings and [`STRINGS`]).
    Str(u32),
    /// A long string: 100, 1,000 or 70,000 characters.
    Long(u32),
    Null,
    Bool(bool),
    Array,
    Object,
    /// The node inside an array.
    WrapArray,
    /// The node inside an object under a key of the vocabulary.
    WrapObject(u32),
    /// A copy of a subtree of the seeds.
    Graft(u32),
}

/// A change to a JSON tree. Indices pick among what is there, modulo its count.
#[derive(Clone, Debug)]
enum TreeOp {
    /// Node `at` (pre-order) replaced.
    Replace { at: u32, with: Gen },
    /// The value of the `nth` member whose key is vocabulary key `key` replaced (a no-op
    /// where no member has it).
    Keyed { key: u32, nth: u32, with: Gen },
    /// The `nth` number (of the tree's numbers) replaced.
    Number { nth: u32, with: Gen },
    /// A child of container `at` removed.
    Delete { at: u32, child: u32 },
    /// The `nth` member whose key is vocabulary key `key` removed.
    DeleteKeyed { key: u32, nth: u32 },
    /// A child of container `at` repeated (an object then has a key twice).
    Duplicate { at: u32, child: u32 },
    /// A member of object `at` renamed.
    Rename { at: u32, child: u32, key: u32 },
    /// A member (or element) added to container `at`.
    Insert { at: u32, key: u32, with: Gen },
}

/// A change to text.
#[derive(Clone, Debug)]
enum TextOp {
    /// Cut at a position (the rest dropped).
    Cut(u32),
    /// Characters inserted at a position.
    Insert(u32, String),
    /// Up to 8 bytes removed at a position.
    Remove(u32, u8),
}

/// What trees are mutated with: the vocabulary of keys and strings, and subtrees to graft.
struct Vocabulary {
    keys: Vec<String>,
    strings: Vec<String>,
    grafts: Vec<Node>,
}

impl Vocabulary {
    /// The vocabulary of `seeds` (their keys, strings and small subtrees) and the lists
    /// above.
    fn of(seeds: &[&Node]) -> Vocabulary {
        let mut keys: Vec<String> = KEYS.iter().map(|s| s.to_string()).collect();
        let mut strings: Vec<String> = STRINGS.iter().map(|s| s.to_string()).collect();
        let mut grafts = Vec::new();
        for seed in seeds {
            let mut all = Vec::new();
            seed.subtrees(&mut all);
            for node in all {
                match node {
                    Node::Str(s) if s.len() < 200 => strings.push(s.clone()),
                    Node::Obj(members) => keys.extend(members.iter().map(|(k, _)| k.clone())),
                    _ => {}
                }
                if node.text().len() < 2000 {
                    grafts.push(node.clone());
                }
            }
        }
        for v in [&mut keys, &mut strings] {
            v.sort();
            v.dedup();
        }
        Vocabulary {
            keys,
            strings,
            grafts,
        }
    }

    /// Key `i`: every other one of [`KEYS`], which the readers look for.
    fn key(&self, i: u32) -> &str {
        let i = i as usize;
        if i.is_multiple_of(2) {
            KEYS[i / 2 % KEYS.len()]
        } else {
            &self.keys[i / 2 % self.keys.len()]
        }
    }

    /// `with` made into a node, where `old` is the node it replaces.
    fn make(&self, with: &Gen, old: &Node) -> Node {
        match *with {
            Gen::Number(i) => Node::Num(NUMBERS[i as usize % NUMBERS.len()].to_string()),
            Gen::Int(i) => Node::Num(i.to_string()),
            Gen::Float(bits) => Node::Num(format!("{:?}", f64::from_bits(bits))),
            Gen::Relative(k) => match old {
                Node::Num(n) => Node::Num(relative(n, k)),
                Node::Str(s) => {
                    Node::Str(format!("{s}{}", ["x", " ", "-", ".", "0"][k as usize % 5]))
                }
                _ => Node::Num("0".into()),
            },
            Gen::Str(i) => Node::Str(self.strings[i as usize % self.strings.len()].clone()),
            Gen::Long(k) => Node::Str(long_string(k)),
            Gen::Null => Node::Null,
            Gen::Bool(b) => Node::Bool(b),
            Gen::Array => Node::Arr(Vec::new()),
            Gen::Object => Node::Obj(Vec::new()),
            Gen::WrapArray => Node::Arr(vec![old.clone()]),
            Gen::WrapObject(k) => Node::Obj(vec![(self.key(k).to_string(), old.clone())]),
            Gen::Graft(i) => self.grafts[i as usize % self.grafts.len()].clone(),
        }
    }

    fn apply(&self, tree: &mut Node, op: &TreeOp) {
        let places = tree.places();
        let pick = |at: u32| &places[at as usize % places.len()];
        let keyed = |key: u32, nth: u32| {
            let key = self.key(key);
            let hits: Vec<&Place> = places
                .iter()
                .filter(|p| p.key.as_deref() == Some(key))
                .collect();
            (!hits.is_empty()).then(|| hits[nth as usize % hits.len()])
        };
        match op {
            TreeOp::Replace { at, with } => {
                let node = tree.at(&pick(*at).path);
                *node = self.make(with, node);
            }
            TreeOp::Keyed { key, nth, with } => {
                if let Some(place) = keyed(*key, *nth) {
                    let node = tree.at(&place.path);
                    *node = self.make(with, node);
                }
            }
            TreeOp::Number { nth, with } => {
                let numbers: Vec<&Place> = places
                    .iter()
                    .filter(|p| matches!(tree.at_ref(&p.path), Node::Num(_)))
                    .collect();
                if !numbers.is_empty() {
                    let path = numbers[*nth as usize % numbers.len()].path.clone();
                    let node = tree.at(&path);
                    *node = self.make(with, node);
                }
            }
            TreeOp::Delete { at, child } => {
                let node = tree.at(&pick(*at).path);
                if node.len() > 0 {
                    node.remove(*child as usize % node.len());
                }
            }
            TreeOp::DeleteKeyed { key, nth } => {
                if let Some(place) = keyed(*key, *nth) {
                    let (last, parent) = place.path.split_last().expect("a member has a parent");
                    tree.at(parent).remove(*last);
                }
            }
            TreeOp::Duplicate { at, child } => {
                let node = tree.at(&pick(*at).path);
                if node.len() > 0 {
                    node.duplicate(*child as usize % node.len());
                }
            }
            TreeOp::Rename { at, child, key } => {
                if let Node::Obj(members) = tree.at(&pick(*at).path)
                    && !members.is_empty()
                {
                    let i = *child as usize % members.len();
                    members[i].0 = self.key(*key).to_string();
                }
            }
            TreeOp::Insert { at, key, with } => match tree.at(&pick(*at).path) {
                Node::Obj(members) => {
                    let value = self.make(with, &Node::Null);
                    let i = *key as usize % (members.len() + 1);
                    members.insert(i, (self.key(*key).to_string(), value));
                }
                Node::Arr(items) => {
                    let value = self.make(with, &Node::Null);
                    let i = *key as usize % (items.len() + 1);
                    items.insert(i, value);
                }
                _ => {}
            },
        }
    }
}

/// A number's text changed a little.
fn relative(n: &str, k: u32) -> String {
    match (n.parse::<i64>(), n.parse::<f64>()) {
        (Ok(i), _) => match k % 8 {
            0 => i.saturating_add(1).to_string(),
            1 => i.saturating_sub(1).to_string(),
            2 => i.saturating_mul(2).to_string(),
            3 => (i / 2).to_string(),
            4 => i.saturating_neg().to_string(),
            5 => format!("{i}.5"),
            6 => format!("{i}e300"),
            _ => format!("{i}.0"),
        },
        (_, Ok(x)) => {
            let y = match k % 8 {
                0 => x + 1.0,
                1 => x - 1.0,
                2 => x * 2.0,
                3 => x / 2.0,
                4 => -x,
                5 => x * 1e300,
                6 => x * 1e-300,
                _ => x.next_up(),
            };
            format!("{y:?}")
        }
        _ => "0".into(),
    }
}

/// A long string of `[100, 1000, 70000][k % 3]` characters: of a name's letters, or not,
/// in one run or in words.
fn long_string(k: u32) -> String {
    let len = [100, 1000, 70_000][k as usize % 3];
    let unit = [
        "a",
        "X",
        "-",
        "\u{e9}",
        "ab ",
        "\u{e9}\u{e9} ",
        "\u{1f600} ",
    ][(k as usize / 3) % 7];
    unit.chars().cycle().take(len).collect()
}

fn apply_text(text: &mut String, op: &TextOp) {
    let at = |p: u32| {
        let mut i = p as usize % (text.len() + 1);
        while !text.is_char_boundary(i) {
            i -= 1;
        }
        i
    };
    match op {
        TextOp::Cut(p) => {
            let i = at(*p);
            text.truncate(i);
        }
        TextOp::Insert(p, s) => {
            let i = at(*p);
            text.insert_str(i, s);
        }
        TextOp::Remove(p, n) => {
            let i = at(*p);
            let mut j = (i + 1 + (*n as usize % 8)).min(text.len());
            while !text.is_char_boundary(j) {
                j += 1;
            }
            text.replace_range(i..j, "");
        }
    }
}

fn gen_strategy() -> impl Strategy<Value = Gen> {
    prop_oneof![
        6 => any::<u32>().prop_map(Gen::Number),
        1 => any::<i64>().prop_map(Gen::Int),
        1 => any::<u64>().prop_map(Gen::Float),
        4 => any::<u32>().prop_map(Gen::Relative),
        3 => any::<u32>().prop_map(Gen::Str),
        1 => any::<u32>().prop_map(Gen::Long),
        1 => Just(Gen::Null),
        1 => any::<bool>().prop_map(Gen::Bool),
        1 => Just(Gen::Array),
        1 => Just(Gen::Object),
        1 => Just(Gen::WrapArray),
        1 => any::<u32>().prop_map(Gen::WrapObject),
        2 => any::<u32>().prop_map(Gen::Graft),
    ]
}

/// A number for a number: an extreme, or the old one changed a little.
fn number_strategy() -> impl Strategy<Value = Gen> {
    prop_oneof![
        3 => any::<u32>().prop_map(Gen::Number),
        3 => any::<u32>().prop_map(Gen::Relative),
        1 => any::<u64>().prop_map(Gen::Float),
    ]
}

fn tree_op_strategy() -> impl Strategy<Value = TreeOp> {
    let u = any::<u32>;
    prop_oneof![
        4 => (u(), gen_strategy()).prop_map(|(at, with)| TreeOp::Replace { at, with }),
        5 => (u(), u(), gen_strategy()).prop_map(|(key, nth, with)| TreeOp::Keyed { key, nth, with }),
        10 => (u(), number_strategy()).prop_map(|(nth, with)| TreeOp::Number { nth, with }),
        1 => (u(), u()).prop_map(|(at, child)| TreeOp::Delete { at, child }),
        2 => (u(), u()).prop_map(|(key, nth)| TreeOp::DeleteKeyed { key, nth }),
        1 => (u(), u()).prop_map(|(at, child)| TreeOp::Duplicate { at, child }),
        1 => (u(), u(), u()).prop_map(|(at, child, key)| TreeOp::Rename { at, child, key }),
        1 => (u(), u(), gen_strategy()).prop_map(|(at, key, with)| TreeOp::Insert { at, key, with }),
    ]
}

fn text_op_strategy() -> impl Strategy<Value = TextOp> {
    let chars = prop_oneof![
        3 => select(&['{', '}', '[', ']', '"', ':', ',', '-', '.', '0', '9', 'e', '\\', ' ', '\n', '\u{0}'][..]),
        1 => any::<char>(),
    ];
    prop_oneof![
        1 => any::<u32>().prop_map(TextOp::Cut),
        2 => (any::<u32>(), vec(chars, 1..6))
            .prop_map(|(at, cs)| TextOp::Insert(at, cs.into_iter().collect())),
        1 => (any::<u32>(), any::<u8>()).prop_map(|(at, n)| TextOp::Remove(at, n)),
    ]
}

/// Mostly no text change (so that most cases get past the JSON syntax), sometimes one or
/// two.
fn text_ops_strategy() -> impl Strategy<Value = Vec<TextOp>> {
    prop_oneof![
        4 => Just(Vec::new()),
        1 => vec(text_op_strategy(), 1..3),
    ]
}

// ---------------------------------------------------------------------------------------
// Scenes
// ---------------------------------------------------------------------------------------

/// The scene seeds: every fixture scene, the default scene with every field written out,
/// and one scene per catalogue surface with all its parameters.
struct SceneSeeds {
    trees: Vec<Node>,
    vocabulary: Vocabulary,
}

fn scene_seeds() -> &'static SceneSeeds {
    static SEEDS: OnceLock<SceneSeeds> = OnceLock::new();
    SEEDS.get_or_init(|| {
        let mut trees: Vec<Node> = fixture_scenes()
            .iter()
            .chain(&scenes_in("animations"))
            .map(|p| {
                let text = std::fs::read_to_string(p).unwrap();
                Node::from_value(&serde_json::from_str(&text).unwrap())
            })
            .collect();
        let full = serde_json::to_value(Scene::default_scene()).unwrap();
        trees.push(Node::from_value(&full));
        for surface in halo4d::surfaces::Surface::catalogue() {
            let mut scene = full.clone();
            scene["surfaces"] = serde_json::json!([{ "surface": surface }]);
            trees.push(Node::from_value(&scene));
        }
        // Every seed is a valid scene: the mutations start from inputs that parse.
        // (Named as in fixtures/scenes/, where a mesh file's relative path is.)
        let file = fixture("scenes/seed.json").display().to_string();
        for t in &trees {
            Scene::parse(&t.text(), &file).unwrap_or_else(|e| panic!("{e}"));
        }
        let vocabulary = Vocabulary::of(&trees.iter().collect::<Vec<_>>());
        SceneSeeds { trees, vocabulary }
    })
}

#[derive(Clone, Debug)]
struct SceneCase {
    seed: u32,
    tree: Vec<TreeOp>,
    text: Vec<TextOp>,
}

fn scene_strategy() -> impl Strategy<Value = SceneCase> {
    (
        any::<u32>(),
        vec(tree_op_strategy(), 0..5),
        text_ops_strategy(),
    )
        .prop_map(|(seed, tree, text)| SceneCase { seed, tree, text })
}

fn render_scene(case: &SceneCase) -> Vec<u8> {
    let seeds = scene_seeds();
    let mut tree = seeds.trees[case.seed as usize % seeds.trees.len()].clone();
    for op in &case.tree {
        seeds.vocabulary.apply(&mut tree, op);
    }
    let mut text = tree.text();
    for op in &case.text {
        apply_text(&mut text, op);
    }
    text.into_bytes()
}

/// The scene properties: an error names the file in a short message; a scene writes out
/// and parses back equal.
fn check_scene(bytes: &[u8], tally: &Tally) -> Result<(), String> {
    let text = std::str::from_utf8(bytes).expect("scene cases are text");
    tally.add("cases");
    match Scene::parse(text, "fuzz.json") {
        Ok(scene) => {
            tally.add("parsed");
            let written = serde_json::to_string(&scene).map_err(|e| e.to_string())?;
            match Scene::parse(&written, "fuzz.json") {
                Ok(again) if again == scene => Ok(()),
                Ok(again) => Err(format!(
                    "the scene parsed back different:\n{scene:?}\n{again:?}"
                )),
                Err(e) => Err(format!("the scene as written does not parse: {e}")),
            }
        }
        Err(e) => {
            tally.add(match &e {
                halo4d::SceneError::Io { .. } => "failed to read",
                halo4d::SceneError::Syntax { .. } => "failed as JSON",
                halo4d::SceneError::Invalid { .. } => "failed validation",
            });
            let message = e.to_string();
            message_ok("scene", &message)?;
            if !message.starts_with("fuzz.json") {
                return Err(format!("the error does not name the file: {message}"));
            }
            Ok(())
        }
    }
}

fn fuzz_scenes(cases: u32, long: bool) {
    let tally = Tally::default();
    fuzz(
        "scene",
        "json",
        cases,
        long,
        scene_strategy(),
        render_scene,
        |bytes| check_scene(bytes, &tally),
    );
    tally.assert_share("parsed", 0.05);
    tally.assert_share("failed as JSON", 0.1);
    tally.assert_share("failed validation", 0.05);
}

#[test]
fn fuzz_scene_parser() {
    fuzz_scenes(SCENE_CASES, false);
}

// ---------------------------------------------------------------------------------------
// Files built once: the patches fixture's .glb and .vtk
// ---------------------------------------------------------------------------------------

struct Built {
    glb: Vec<u8>,
    vtk: Vec<u8>,
}

fn built() -> &'static Built {
    static BUILT: OnceLock<Built> = OnceLock::new();
    BUILT.get_or_init(|| {
        let mut scene = Scene::load(&fixture("scenes/patches.json")).unwrap();
        assert_eq!(
            scene.sampling,
            halo4d::sample::Sampling::Uniform { u: 8, v: 8 },
            "a small build"
        );
        scene.outputs.ply = false;
        scene.outputs.obj = false;
        scene.outputs.png = false;
        scene.outputs.report = false;
        let dir = tempfile::tempdir().unwrap();
        halo4d::build(&scene, dir.path(), halo4d::progress::Job::SILENT).unwrap();
        Built {
            glb: std::fs::read(dir.path().join("patches.glb")).unwrap(),
            vtk: std::fs::read(dir.path().join("patches-halo.vtk")).unwrap(),
        }
    })
}

/// A change to a binary word: one of the special values, random bits, or the word changed
/// a little.
#[derive(Clone, Debug)]
enum Word {
    Special(u32),
    Random(u64),
    Relative(u32),
}

/// The word's new value, `width` (4 or 8) bytes wide; `old` is its value.
fn word_value(word: &Word, width: usize, old: u64) -> u64 {
    let specials4: [u64; 16] = [
        0,
        1,
        2,
        3,
        4,
        0xFFFF_FFFF,
        0x7FFF_FFFF,
        0x8000_0000,
        u64::from(f32::NAN.to_bits()),
        u64::from(f32::INFINITY.to_bits()),
        u64::from(f32::NEG_INFINITY.to_bits()),
        u64::from(f32::MAX.to_bits()),
        u64::from((-0.0f32).to_bits()),
        1, // the smallest subnormal f32
        0x0001_0000,
        5126,
    ];
    let specials8: [u64; 12] = [
        0,
        1,
        u64::MAX,
        i64::MAX as u64,
        0x8000_0000_0000_0000,
        f64::NAN.to_bits(),
        f64::INFINITY.to_bits(),
        f64::NEG_INFINITY.to_bits(),
        f64::MAX.to_bits(),
        (-0.0f64).to_bits(),
        1e300f64.to_bits(),
        0x0000_0000_7FFF_FFFF,
    ];
    let mask = if width == 8 { u64::MAX } else { 0xFFFF_FFFF };
    let value = match *word {
        Word::Special(i) if width == 8 => specials8[i as usize % specials8.len()],
        Word::Special(i) => specials4[i as usize % specials4.len()],
        Word::Random(bits) => bits,
        Word::Relative(k) => match k % 6 {
            0 => old.wrapping_add(1),
            1 => old.wrapping_sub(1),
            2 => old.wrapping_mul(2),
            3 => old / 2,
            4 => !old,
            _ => old ^ (1 << (63 - (old.leading_zeros() % 64))),
        },
    };
    value & mask
}

fn word_strategy() -> impl Strategy<Value = Word> {
    prop_oneof![
        4 => any::<u32>().prop_map(Word::Special),
        1 => any::<u64>().prop_map(Word::Random),
        2 => any::<u32>().prop_map(Word::Relative),
    ]
}

/// Reads and writes a `width`-byte word at `at`, little- or big-endian.
fn get_word(bytes: &[u8], at: usize, width: usize, big: bool) -> u64 {
    let mut b = [0u8; 8];
    b[..width].copy_from_slice(&bytes[at..at + width]);
    if big {
        b[..width].reverse();
    }
    u64::from_le_bytes(b)
}

fn set_word(bytes: &mut [u8], at: usize, width: usize, big: bool, value: u64) {
    let mut b = value.to_le_bytes();
    if big {
        b[..width].reverse();
    }
    bytes[at..at + width].copy_from_slice(&b[..width]);
}

/// A change to a file's bytes.
#[derive(Clone, Debug)]
pub(crate) enum ByteOp {
    /// A bit flipped.
    Flip { at: u32, bit: u8 },
    /// The file cut at a position.
    Cut(u32),
    /// Bytes inserted at a position.
    Insert { at: u32, bytes: Vec<u8> },
}

pub(crate) fn byte_op_strategy() -> impl Strategy<Value = ByteOp> {
    prop_oneof![
        3 => (any::<u32>(), any::<u8>()).prop_map(|(at, bit)| ByteOp::Flip { at, bit }),
        1 => any::<u32>().prop_map(ByteOp::Cut),
        1 => (any::<u32>(), vec(any::<u8>(), 1..9))
            .prop_map(|(at, bytes)| ByteOp::Insert { at, bytes }),
    ]
}

pub(crate) fn apply_bytes(bytes: &mut Vec<u8>, op: &ByteOp) {
    let pos = |at: u32, n: usize| at as usize % (n + 1);
    match op {
        ByteOp::Flip { at, bit } => {
            if !bytes.is_empty() {
                let i = *at as usize % bytes.len();
                bytes[i] ^= 1 << (bit % 8);
            }
        }
        ByteOp::Cut(at) => bytes.truncate(pos(*at, bytes.len())),
        ByteOp::Insert { at, bytes: new } => {
            let i = pos(*at, bytes.len());
            bytes.splice(i..i, new.iter().copied());
        }
    }
}

// ---------------------------------------------------------------------------------------
// .glb
// ---------------------------------------------------------------------------------------

/// The .glb seed: its JSON chunk as a tree, its BIN chunk (with its header) as bytes.
struct GlbSeed {
    /// What the readers read from it.
    halo: ImportedHalo,
    scene: ImportedScene,
    json: Node,
    /// `json` with the halo's tetrahedra accessor cut short.
    cuts: Vec<Node>,
    bin_chunk: Vec<u8>,
    vocabulary: Vocabulary,
}

fn glb_seed() -> &'static GlbSeed {
    static SEED: OnceLock<GlbSeed> = OnceLock::new();
    SEED.get_or_init(|| {
        let glb = &built().glb;
        let json_len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
        let value: Value = serde_json::from_slice(&glb[20..20 + json_len]).unwrap();
        let json = Node::from_value(&value);
        let bin_chunk = glb[20 + json_len..].to_vec();
        assert_eq!(&bin_chunk[4..8], b"BIN\0");
        // Re-packed unchanged, the file reads as the original.
        let (packed, _) = pack(json.text().as_bytes(), &bin_chunk);
        assert_eq!(read_glb(&packed).unwrap(), read_glb(glb).unwrap());
        assert_eq!(
            read_scene_glb(&packed).unwrap(),
            read_scene_glb(glb).unwrap()
        );
        let vocabulary = Vocabulary::of(&[&json]);
        let halo = read_glb(glb).unwrap().remove(0);
        // The halo's tetrahedra accessor cut to none, half and all but one.
        let tets = halo.mesh.tets.len() as u64;
        let cuts = [0, tets / 2, tets - 1]
            .map(|keep| {
                let mut v = value.clone();
                let mesh = v["meshes"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .find(|m| m["extras"].get("halo").is_some())
                    .unwrap();
                let k = mesh["extras"]["halo"]["tetrahedra"].as_u64().unwrap() as usize;
                let count = &mut v["accessors"][k]["count"];
                let per = count.as_u64().unwrap() / tets;
                *count = (per * keep).into();
                Node::from_value(&v)
            })
            .to_vec();
        GlbSeed {
            halo,
            cuts,
            scene: read_scene_glb(glb).unwrap(),
            json,
            bin_chunk,
            vocabulary,
        }
    })
}

/// A .glb of this JSON and BIN chunk, and the offset of the BIN chunk's header.
fn pack(json: &[u8], bin_chunk: &[u8]) -> (Vec<u8>, usize) {
    let glb = pack_glb(json, bin_chunk);
    let bin_header = glb.len() - bin_chunk.len();
    (glb, bin_header)
}

/// A word of a packed .glb to change.
#[derive(Clone, Debug)]
enum GlbWord {
    /// Of the file header and the JSON chunk's header: magic, version, length, chunk
    /// length, chunk type.
    Header(u32),
    /// Of the BIN chunk's header: length, type.
    BinHeader(u32),
    /// The `at`-th 4-byte word of the BIN chunk's data (a float, an index).
    Bin(u32),
}

#[derive(Clone, Debug)]
struct GlbCase {
    /// Start from the seed with its halo's tetrahedra cut short (`GlbSeed::cuts`).
    cut: Option<u32>,
    tree: Vec<TreeOp>,
    json_text: Vec<TextOp>,
    words: Vec<(GlbWord, Word)>,
    bytes: Vec<ByteOp>,
}

fn glb_strategy() -> impl Strategy<Value = GlbCase> {
    let place = prop_oneof![
        1 => any::<u32>().prop_map(GlbWord::Header),
        1 => any::<u32>().prop_map(GlbWord::BinHeader),
        4 => any::<u32>().prop_map(GlbWord::Bin),
    ];
    (
        prop_oneof![6 => Just(None), 1 => any::<u32>().prop_map(Some)],
        vec(tree_op_strategy(), 0..5),
        prop_oneof![8 => Just(Vec::new()), 1 => vec(text_op_strategy(), 1..3)],
        prop_oneof![2 => Just(Vec::new()), 1 => vec((place, word_strategy()), 1..4)],
        prop_oneof![4 => Just(Vec::new()), 1 => vec(byte_op_strategy(), 1..3)],
    )
        .prop_map(|(cut, tree, json_text, words, bytes)| GlbCase {
            cut,
            tree,
            json_text,
            words,
            bytes,
        })
}

fn render_glb(case: &GlbCase) -> Vec<u8> {
    let seed = glb_seed();
    let mut tree = match case.cut {
        Some(k) => seed.cuts[k as usize % seed.cuts.len()].clone(),
        None => seed.json.clone(),
    };
    for op in &case.tree {
        seed.vocabulary.apply(&mut tree, op);
    }
    let mut text = tree.text();
    for op in &case.json_text {
        apply_text(&mut text, op);
    }
    let (mut glb, bin_header) = pack(text.as_bytes(), &seed.bin_chunk);
    for (place, word) in &case.words {
        let at = match *place {
            GlbWord::Header(k) => 4 * (k as usize % 5),
            GlbWord::BinHeader(k) => bin_header + 4 * (k as usize % 2),
            GlbWord::Bin(k) => {
                let words = (glb.len() - bin_header - 8) / 4;
                bin_header + 8 + 4 * (k as usize % words)
            }
        };
        let old = get_word(&glb, at, 4, false);
        set_word(&mut glb, at, 4, false, word_value(word, 4, old));
    }
    for op in &case.bytes {
        apply_bytes(&mut glb, op);
    }
    glb
}

/// A halo as read is finite, its indices in range, its counts consistent.
fn halo_ok(h: &ImportedHalo) -> Result<(), String> {
    let nv = h.mesh.positions.len();
    let bad = |m: String| Err(format!("halo `{}` read back {m}", h.name));
    if let Some(p) = h
        .mesh
        .positions
        .iter()
        .find(|p| !p.iter().all(|x| x.is_finite()))
    {
        return bad(format!("with a non-finite position {p:?}"));
    }
    if let Some(t) = h
        .mesh
        .tets
        .iter()
        .find(|t| t.iter().any(|&i| i as usize >= nv))
    {
        return bad(format!(
            "with tetrahedron {t:?} out of range of {nv} vertices"
        ));
    }
    if h.mesh
        .surface_vertices
        .checked_mul(3)
        .is_none_or(|n| n > nv)
    {
        return bad(format!(
            "with surface_vertices {} for {nv} vertices",
            h.mesh.surface_vertices
        ));
    }
    for (what, values) in [("t", &h.t), ("d_orig", &h.d_orig)] {
        if let Some(values) = values {
            if values.len() != nv {
                return bad(format!(
                    "with {} values of {what} for {nv} vertices",
                    values.len()
                ));
            }
            if values.iter().any(|x| !x.is_finite()) {
                return bad(format!("with a non-finite {what}"));
            }
        }
    }
    Ok(())
}

/// A scene as read is finite, its indices in range, its counts consistent.
fn scene_ok(s: &ImportedScene) -> Result<(), String> {
    if s.surfaces.is_empty() {
        return Err("a scene read back with no surface".into());
    }
    for surface in &s.surfaces {
        let nv = surface.positions.len();
        let bad = |m: String| Err(format!("surface `{}` read back {m}", surface.name));
        if surface.positions.iter().any(|p| !p.is_finite()) {
            return bad("with a non-finite position".into());
        }
        if surface.w.len() != nv || surface.w.iter().any(|x| !x.is_finite()) {
            return bad(format!(
                "with {} w values, or a non-finite one, for {nv}",
                surface.w.len()
            ));
        }
        if let Some(t) = surface.triangles.iter().find(|t| {
            t.iter().any(|&i| i as usize >= nv) || t[0] == t[1] || t[1] == t[2] || t[0] == t[2]
        }) {
            return bad(format!("with triangle {t:?} (for {nv} vertices)"));
        }
        if surface.normals.len() != nv || surface.normals.iter().any(|n| !n.is_finite()) {
            return bad("with normals of the wrong count or not finite".into());
        }
        if let Some(halo) = &surface.halo {
            halo_ok(halo)?;
            if halo.mesh.surface_vertices != nv
                || halo.t.is_none()
                || halo.d_orig.is_none()
                || halo.params.delta_d.is_none()
                || halo.params.delta_t.is_none()
            {
                return bad(format!(
                    "with halo `{}` missing what verification needs",
                    halo.name
                ));
            }
        }
    }
    if let Some(c) = &s.curves {
        let nv = c.positions.len();
        if c.positions.iter().any(|p| !p.is_finite())
            || c.w.len() != nv
            || c.w.iter().any(|x| !x.is_finite())
            || c.segments.iter().flatten().any(|&i| i as usize >= nv)
        {
            return Err("curves read back non-finite or out of range".into());
        }
    }
    Ok(())
}

fn check_glb(bytes: &[u8], tally: &Tally) -> Result<(), String> {
    tally.add("cases");
    let halos = read_glb(bytes);
    let scene = read_scene_glb(bytes);
    match &halos {
        Ok(halos) => {
            tally.add("read halos");
            if halos.is_empty() {
                return Err("read_glb read no halo and no error".into());
            }
            for h in halos {
                halo_ok(h)?;
                check_changed(h, &glb_seed().halo, tally)?;
            }
        }
        Err(e) => {
            tally.add("failed read_glb");
            message_ok("read_glb", &e.to_string())?;
        }
    }
    match &scene {
        Ok(scene) => {
            tally.add("read as a scene");
            scene_ok(scene)?;
            // What `halo4d check DIR` does next, on every scene that differs from the
            // seed: it must not panic.
            if scene.surfaces != glb_seed().scene.surfaces {
                tally.add("verified a changed scene");
                let _ = halo4d::verify_scene(scene);
            }
            // The scene's halos are the file's halos.
            let mut in_scene: Vec<&ImportedHalo> = scene
                .surfaces
                .iter()
                .filter_map(|s| s.halo.as_ref())
                .collect();
            match &halos {
                Ok(halos) => {
                    for h in halos {
                        let Some(i) = in_scene.iter().position(|s| *s == h) else {
                            return Err(format!(
                                "read_glb read halo `{}`, which read_scene_glb does not have",
                                h.name
                            ));
                        };
                        in_scene.remove(i);
                    }
                    if let Some(h) = in_scene.first() {
                        return Err(format!(
                            "read_scene_glb read halo `{}`, which read_glb does not have",
                            h.name
                        ));
                    }
                }
                Err(e) if !in_scene.is_empty() => {
                    return Err(format!(
                        "read_scene_glb read {} halos, read_glb none: {e}",
                        in_scene.len()
                    ));
                }
                Err(_) => {}
            }
        }
        Err(e) => {
            tally.add("failed read_scene_glb");
            message_ok("read_scene_glb", &e.to_string())?;
        }
    }
    Ok(())
}

/// What `halo4d check FILE` does next, on every halo whose mesh differs from the seed's:
/// the checker must not panic, and a halo cut short (the seed's vertices and surface, a
/// strict prefix of its tetrahedra, as a cut accessor or CELLS count leaves it, down to
/// none) no longer covers its surface and must fail.
fn check_changed(h: &ImportedHalo, seed: &ImportedHalo, tally: &Tally) -> Result<(), String> {
    let (m, s) = (&h.mesh, &seed.mesh);
    if m == s {
        return Ok(());
    }
    tally.add("checked a changed halo");
    let stats = halo4d::check::check(m);
    if m.positions == s.positions
        && m.surface_vertices == s.surface_vertices
        && m.surface_triangles == s.surface_triangles
        && m.tets.len() < s.tets.len()
        && s.tets.starts_with(&m.tets)
    {
        tally.add("checked a cut halo");
        if stats.passes() {
            return Err(format!(
                "halo `{}` cut to {} of its {} tetrahedra passes the check",
                h.name,
                m.tets.len(),
                s.tets.len()
            ));
        }
    }
    Ok(())
}

fn fuzz_glb(cases: u32, long: bool) {
    let tally = Tally::default();
    fuzz(
        "glb",
        "glb",
        cases,
        long,
        glb_strategy(),
        render_glb,
        |bytes| check_glb(bytes, &tally),
    );
    tally.assert_share("read halos", 0.1);
    tally.assert_share("read as a scene", 0.1);
    tally.assert_share("failed read_glb", 0.2);
    tally.assert_share("failed read_scene_glb", 0.2);
    tally.assert_share("checked a changed halo", 0.01);
    tally.assert_share("verified a changed scene", 0.01);
    tally.assert_share("checked a cut halo", 0.02);
}

#[test]
fn fuzz_glb_reader() {
    fuzz_glb(GLB_CASES, false);
}

// ---------------------------------------------------------------------------------------
// .vtk
// ---------------------------------------------------------------------------------------

/// The halo as ASCII legacy VTK of file version 3.0 (field data right after DATASET, cell
/// data and a lookup table halo4d does not write) or 5.1 (OFFSETS and CONNECTIVITY, METADATA,
/// t and d_orig as FIELD arrays of the point data).
fn ascii_vtk(h: &ImportedHalo, version5: bool) -> String {
    use std::fmt::Write;
    let m = &h.mesh;
    let (np, nt) = (m.positions.len(), m.tets.len());
    let mut s = String::new();
    let version = if version5 { "5.1" } else { "3.0" };
    let _ = write!(
        s,
        "# vtk DataFile Version {version}\n{}: ascii copy\nASCII\nDATASET UNSTRUCTURED_GRID\n",
        h.name
    );
    let field = |s: &mut String| {
        let _ = write!(
            s,
            "FIELD FieldData 6\nsurface_vertices 1 1 int\n{}\nlayers 1 1 int\n2\n",
            m.surface_vertices
        );
        for (name, value) in [
            ("rho", h.params.rho),
            ("delta_d", h.params.delta_d),
            ("delta_t", h.params.delta_t),
        ] {
            let _ = write!(s, "{name} 1 1 double\n{}\n", value.unwrap());
        }
        let triangles = &m.surface_triangles;
        let _ = writeln!(s, "surface_triangles 3 {} int", triangles.len());
        for t in triangles {
            let _ = writeln!(s, "{} {} {}", t[0], t[1], t[2]);
        }
    };
    if !version5 {
        field(&mut s);
    }
    let _ = writeln!(s, "POINTS {np} double");
    for p in &m.positions {
        let _ = writeln!(s, "{} {} {}", p[0], p[1], p[2]);
    }
    let tets: Vec<[u32; 4]> = m
        .tets
        .iter()
        .map(|&t| halo4d::internals::file_order(t))
        .collect();
    if version5 {
        s += "METADATA\nINFORMATION 0\n\n";
        let _ = writeln!(s, "CELLS {} {}\nOFFSETS vtktypeint64", nt + 1, 4 * nt);
        for k in 0..=nt {
            let _ = writeln!(s, "{}", 4 * k);
        }
        s += "CONNECTIVITY vtktypeint64\n";
        for t in &tets {
            let _ = writeln!(s, "{} {} {} {}", t[0], t[1], t[2], t[3]);
        }
    } else {
        let _ = writeln!(s, "CELLS {nt} {}", 5 * nt);
        for t in &tets {
            let _ = writeln!(s, "4 {} {} {} {}", t[0], t[1], t[2], t[3]);
        }
    }
    let _ = writeln!(s, "CELL_TYPES {nt}");
    s += &"10\n".repeat(nt);
    if version5 {
        field(&mut s);
    } else {
        let _ = writeln!(
            s,
            "CELL_DATA {nt}\nSCALARS quality float 1\nLOOKUP_TABLE table"
        );
        s += &"0.5\n".repeat(nt);
        s += "LOOKUP_TABLE table 2\n0 0 0 1\n1 1 1 1\n";
    }
    let _ = writeln!(s, "POINT_DATA {np}");
    let values = [
        ("t", h.t.as_ref().unwrap()),
        ("d_orig", h.d_orig.as_ref().unwrap()),
    ];
    if version5 {
        s += "FIELD FieldData 2\n";
        for (name, values) in values {
            let _ = writeln!(s, "{name} 1 {np} double");
            for x in values {
                let _ = writeln!(s, "{x}");
            }
        }
    } else {
        for (name, values) in values {
            let _ = writeln!(s, "SCALARS {name} double\nLOOKUP_TABLE default");
            for x in values {
                let _ = writeln!(s, "{x}");
            }
        }
        let _ = writeln!(s, "NORMALS n float");
        s += &"0 0 1\n".repeat(np);
    }
    s
}

/// The .vtk seeds: the built binary file and its ASCII renditions, and where the binary
/// file's blocks of values are.
struct VtkSeeds {
    /// The halo they hold.
    halo: ImportedHalo,
    files: Vec<Vec<u8>>,
    /// (start, value width, values) of each block of the binary file.
    blocks: Vec<(usize, usize, usize)>,
}

fn vtk_seeds() -> &'static VtkSeeds {
    static SEEDS: OnceLock<VtkSeeds> = OnceLock::new();
    SEEDS.get_or_init(|| {
        let binary = built().vtk.clone();
        let halo = read_vtk(&binary).unwrap();
        // Cut short: half the tetrahedra, and none (what `check` must fail).
        let cut = |keep: usize| {
            let mut h = halo.clone();
            h.mesh.tets.truncate(keep);
            ascii_vtk(&h, false).into_bytes()
        };
        // Another program's: no FIELD data, so no halo layout.
        let text = ascii_vtk(&halo, false);
        let (field, points) = (
            text.find("FIELD FieldData").unwrap(),
            text.find("POINTS").unwrap(),
        );
        let plain = format!("{}{}", &text[..field], &text[points..]).into_bytes();
        let files = vec![
            binary.clone(),
            ascii_vtk(&halo, false).into_bytes(),
            ascii_vtk(&halo, true).into_bytes(),
            plain,
            cut(halo.mesh.tets.len() / 2),
            cut(0),
        ];
        for f in &files[1..3] {
            let again = read_vtk(f).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(again.mesh, halo.mesh);
            assert_eq!((&again.t, &again.d_orig), (&halo.t, &halo.d_orig));
        }
        let (np, nt) = (halo.mesh.positions.len(), halo.mesh.tets.len());
        let find = |header: &str| {
            let h = header.as_bytes();
            binary
                .windows(h.len())
                .position(|w| w == h)
                .unwrap_or_else(|| panic!("`{header}` in the .vtk"))
                + h.len()
        };
        let mut blocks = vec![
            (find(&format!("POINTS {np} double\n")), 8, 3 * np),
            (find(&format!("CELLS {nt} {}\n", 5 * nt)), 4, 5 * nt),
            (find(&format!("CELL_TYPES {nt}\n")), 4, nt),
            (find("surface_vertices 1 1 int\n"), 4, 1),
            (find("layers 1 1 int\n"), 4, 1),
        ];
        for name in ["rho", "delta_d", "delta_t"] {
            blocks.push((find(&format!("{name} 1 1 double\n")), 8, 1));
        }
        for name in ["t", "d_orig"] {
            blocks.push((
                find(&format!("SCALARS {name} double 1\nLOOKUP_TABLE default\n")),
                8,
                np,
            ));
        }
        VtkSeeds {
            halo,
            files,
            blocks,
        }
    })
}

/// Words of VTK header lines.
const VTK_WORDS: &[&str] = &[
    "double",
    "float",
    "int",
    "unsigned_int",
    "long",
    "unsigned_long",
    "vtktypeint64",
    "vtkidtype",
    "char",
    "unsigned_char",
    "short",
    "bit",
    "string",
    "ASCII",
    "BINARY",
    "UNSTRUCTURED_GRID",
    "POLYDATA",
    "DATASET",
    "POINTS",
    "CELLS",
    "CELL_TYPES",
    "OFFSETS",
    "CONNECTIVITY",
    "POINT_DATA",
    "CELL_DATA",
    "FIELD",
    "SCALARS",
    "LOOKUP_TABLE",
    "METADATA",
    "VECTORS",
    "NORMALS",
    "TENSORS",
    "TEXTURE_COORDINATES",
    "COLOR_SCALARS",
    "surface_vertices",
    "layers",
    "rho",
    "delta_d",
    "delta_t",
    "t",
    "d_orig",
    "default",
    "#",
    "vtk",
    "DataFile",
    "Version",
    "2.0",
    "4.2",
    "5.1",
    "6.0",
    "",
];

/// Numbers for VTK text, some of them not numbers to every reader.
pub(crate) const VTK_NUMBERS: &[&str] = &[
    "0",
    "-0",
    "1",
    "-1",
    "2",
    "3",
    "4",
    "5",
    "9",
    "10",
    "12",
    "0.5",
    "4.5",
    "1e-300",
    "5e-324",
    "1e308",
    "1e400",
    "-1e400",
    "nan",
    "NaN",
    "inf",
    "-inf",
    "infinity",
    "2147483647",
    "2147483648",
    "4294967295",
    "4294967296",
    "9223372036854775807",
    "9223372036854775808",
    "18446744073709551615",
    "18446744073709551616",
    "1e19",
    "+1",
    "1e",
    "--1",
    "0x10",
];

/// Lines to insert into a VTK file.
const VTK_LINES: &[&str] = &[
    "",
    "METADATA",
    "INFORMATION 0",
    "FIELD FieldData 1",
    "FIELD FieldData 0",
    "surface_vertices 1 1 int",
    "layers 1 1 int",
    "rho 1 1 double",
    "0",
    "POINT_DATA 972",
    "CELL_DATA 2304",
    "SCALARS x double 1",
    "SCALARS t float 4",
    "LOOKUP_TABLE default",
    "LOOKUP_TABLE t 2",
    "VECTORS v double",
    "NORMALS n float",
    "TENSORS t double",
    "TEXTURE_COORDINATES tc 2 float",
    "COLOR_SCALARS c 3",
    "OFFSETS vtktypeint64",
    "CONNECTIVITY vtktypeint64",
    "POINTS 1 double",
    "POINTS 0 float",
    "CELLS 1 5",
    "CELLS 0 0",
    "CELL_TYPES 1",
    "DATASET UNSTRUCTURED_GRID",
    "ASCII",
    "BINARY",
    "1 2 3",
    "nan inf -inf",
];

/// A changed token of a VTK text line.
#[derive(Clone, Debug)]
enum Tok {
    Number(u32),
    Int(i64),
    Float(u64),
    Relative(u32),
    Word(u32),
    Long(u32),
    Remove,
    /// Another token added after it.
    Extra(u32),
}

/// A change to a VTK file's lines. `header` picks among header lines (those that start
/// with a letter or `#`), else among the other text lines (ASCII data).
#[derive(Clone, Debug)]
enum LineOp {
    Token {
        header: bool,
        line: u32,
        token: u32,
        with: Tok,
    },
    Delete {
        header: bool,
        line: u32,
    },
    Duplicate {
        header: bool,
        line: u32,
    },
    Swap {
        a: u32,
        b: u32,
    },
    Insert {
        header: bool,
        line: u32,
        text: u32,
    },
}

#[derive(Clone, Debug)]
struct VtkCase {
    seed: u32,
    /// Values of the binary file's blocks set: (block, index, word).
    values: Vec<(u32, u32, Word)>,
    lines: Vec<LineOp>,
    bytes: Vec<ByteOp>,
}

fn vtk_strategy() -> impl Strategy<Value = VtkCase> {
    let tok = prop_oneof![
        4 => any::<u32>().prop_map(Tok::Number),
        1 => any::<i64>().prop_map(Tok::Int),
        1 => any::<u64>().prop_map(Tok::Float),
        3 => any::<u32>().prop_map(Tok::Relative),
        3 => any::<u32>().prop_map(Tok::Word),
        1 => any::<u32>().prop_map(Tok::Long),
        1 => Just(Tok::Remove),
        1 => any::<u32>().prop_map(Tok::Extra),
    ];
    let header = prop_oneof![1 => Just(true), 1 => Just(false)];
    let u = any::<u32>;
    let line_op = prop_oneof![
        6 => (header.clone(), u(), u(), tok)
            .prop_map(|(header, line, token, with)| LineOp::Token { header, line, token, with }),
        1 => (header.clone(), u()).prop_map(|(header, line)| LineOp::Delete { header, line }),
        1 => (header.clone(), u()).prop_map(|(header, line)| LineOp::Duplicate { header, line }),
        1 => (u(), u()).prop_map(|(a, b)| LineOp::Swap { a, b }),
        1 => (header, u(), u()).prop_map(|(header, line, text)| LineOp::Insert { header, line, text }),
    ];
    (
        any::<u32>(),
        prop_oneof![1 => Just(Vec::new()), 1 => vec((u(), u(), word_strategy()), 1..4)],
        vec(line_op, 0..4),
        prop_oneof![4 => Just(Vec::new()), 1 => vec(byte_op_strategy(), 1..3)],
    )
        .prop_map(|(seed, values, lines, bytes)| VtkCase {
            seed,
            values,
            lines,
            bytes,
        })
}

fn is_text(line: &[u8]) -> bool {
    !line.is_empty()
        && line
            .iter()
            .all(|&b| b.is_ascii_graphic() || b == b' ' || b == b'\t' || b == b'\r')
}

fn is_header(line: &[u8]) -> bool {
    is_text(line) && (line[0].is_ascii_alphabetic() || line[0] == b'#')
}

fn token_value(old: &str, with: &Tok) -> Option<String> {
    Some(match *with {
        Tok::Number(i) => VTK_NUMBERS[i as usize % VTK_NUMBERS.len()].to_string(),
        Tok::Int(i) => i.to_string(),
        Tok::Float(bits) => format!("{:?}", f64::from_bits(bits)),
        Tok::Relative(k) => relative(old, k),
        Tok::Word(i) => VTK_WORDS[i as usize % VTK_WORDS.len()].to_string(),
        Tok::Long(k) => long_string(k),
        Tok::Remove => return None,
        Tok::Extra(i) => format!("{old} {}", VTK_WORDS[i as usize % VTK_WORDS.len()]),
    })
}

fn apply_line(lines: &mut Vec<Vec<u8>>, op: &LineOp) {
    let pick = |lines: &Vec<Vec<u8>>, header: bool, k: u32| {
        let pool: Vec<usize> = (0..lines.len())
            .filter(|&i| {
                if header {
                    is_header(&lines[i])
                } else {
                    is_text(&lines[i]) && !is_header(&lines[i])
                }
            })
            .collect();
        (!pool.is_empty()).then(|| pool[k as usize % pool.len()])
    };
    match *op {
        LineOp::Token {
            header,
            line,
            token,
            ref with,
        } => {
            let Some(i) = pick(lines, header, line) else {
                return;
            };
            let text = String::from_utf8_lossy(&lines[i]).into_owned();
            let mut words: Vec<String> = text.split_whitespace().map(String::from).collect();
            if words.is_empty() {
                return;
            }
            let t = token as usize % words.len();
            match token_value(&words[t], with) {
                Some(w) => words[t] = w,
                None => {
                    words.remove(t);
                }
            }
            lines[i] = words.join(" ").into_bytes();
        }
        LineOp::Delete { header, line } => {
            if let Some(i) = pick(lines, header, line) {
                lines.remove(i);
            }
        }
        LineOp::Duplicate { header, line } => {
            if let Some(i) = pick(lines, header, line) {
                lines.insert(i, lines[i].clone());
            }
        }
        LineOp::Swap { a, b } => {
            if let (Some(a), Some(b)) = (pick(lines, true, a), pick(lines, true, b)) {
                lines.swap(a, b);
            }
        }
        LineOp::Insert { header, line, text } => {
            let i = pick(lines, header, line).unwrap_or(0);
            lines.insert(
                i,
                VTK_LINES[text as usize % VTK_LINES.len()]
                    .as_bytes()
                    .to_vec(),
            );
        }
    }
}

fn render_vtk(case: &VtkCase) -> Vec<u8> {
    let seeds = vtk_seeds();
    let k = case.seed as usize % seeds.files.len();
    let mut bytes = seeds.files[k].clone();
    if k == 0 {
        for (block, index, word) in &case.values {
            let (start, width, count) = seeds.blocks[*block as usize % seeds.blocks.len()];
            let at = start + width * (*index as usize % count);
            let old = get_word(&bytes, at, width, true);
            set_word(&mut bytes, at, width, true, word_value(word, width, old));
        }
    }
    if !case.lines.is_empty() {
        let mut lines: Vec<Vec<u8>> = bytes.split(|&b| b == b'\n').map(<[u8]>::to_vec).collect();
        for op in &case.lines {
            apply_line(&mut lines, op);
        }
        bytes = lines.join(&b'\n');
    }
    for op in &case.bytes {
        apply_bytes(&mut bytes, op);
    }
    bytes
}

fn check_vtk(bytes: &[u8], tally: &Tally) -> Result<(), String> {
    tally.add("cases");
    let tetrahedra = read_vtk_tetrahedra(bytes);
    match read_vtk(bytes) {
        Ok(halo) => {
            tally.add("read");
            halo_ok(&halo)?;
            check_changed(&halo, &vtk_seeds().halo, tally)?;
            // `halo4d check` reads the same halo.
            match tetrahedra {
                Ok(FileTetrahedra::Halos(h)) if h.len() == 1 && h[0] == halo => Ok(()),
                other => Err(format!(
                    "read_vtk read halo `{}`, read_vtk_tetrahedra {other:?}",
                    halo.name
                )),
            }
        }
        Err(e) => {
            tally.add("failed");
            message_ok("read_vtk", &e.to_string())?;
            match tetrahedra {
                // Without halo4d's layout: tetrahedra alone, which the checks that need no
                // layout take.
                Ok(FileTetrahedra::Plain(plain)) => {
                    tally.add("read as plain tetrahedra");
                    plain_ok(&plain)?;
                    let _ = halo4d::certify::certify(&plain.positions, &plain.tets);
                    Ok(())
                }
                Ok(FileTetrahedra::Halos(_)) => Err(format!(
                    "read_vtk_tetrahedra read a halo where read_vtk failed: {e}"
                )),
                Err(e) => message_ok("read_vtk_tetrahedra", &e.to_string()),
            }
        }
    }
}

/// Tetrahedra read without a halo layout are finite, their indices in range.
fn plain_ok(m: &PlainTetrahedra) -> Result<(), String> {
    let nv = m.positions.len();
    if m.positions.iter().any(|p| !p.iter().all(|x| x.is_finite())) {
        return Err(format!("mesh `{}` read with a non-finite position", m.name));
    }
    if m.tets.iter().any(|t| t.iter().any(|&i| i as usize >= nv)) {
        return Err(format!("mesh `{}` read with an index out of range", m.name));
    }
    Ok(())
}

fn fuzz_vtk(cases: u32, long: bool) {
    let tally = Tally::default();
    fuzz(
        "vtk",
        "vtk",
        cases,
        long,
        vtk_strategy(),
        render_vtk,
        |bytes| check_vtk(bytes, &tally),
    );
    tally.assert_share("read", 0.1);
    tally.assert_share("failed", 0.3);
    tally.assert_share("checked a changed halo", 0.01);
    tally.assert_share("read as plain tetrahedra", 0.02);
    tally.assert_share("checked a cut halo", 0.02);
}

#[test]
fn fuzz_vtk_reader() {
    fuzz_vtk(VTK_CASES, false);
}

// ---------------------------------------------------------------------------------------
// Other programs' tetrahedral meshes: .vtu, .msh, .mesh, TetGen's .node/.ele
// ---------------------------------------------------------------------------------------

/// The words a text mutation puts in place of a word of a mesh file.
const MESH_WORDS: [&str; 12] = [
    "0",
    "-1",
    "1",
    "13",
    "4294967295",
    "18446744073709551616",
    "1000000000000",
    "nan",
    "inf",
    "1e400",
    "$EndNodes",
    "End",
];

/// A mutation of a tetrahedral mesh file: a word replaced (text formats and the text of
/// binary ones), then bytes changed.
#[derive(Clone, Debug)]
struct MeshCase {
    seed: u32,
    words: Vec<(u32, u8)>,
    bytes: Vec<ByteOp>,
}

fn mesh_strategy() -> impl Strategy<Value = MeshCase> {
    (
        any::<u32>(),
        vec((any::<u32>(), any::<u8>()), 0..3),
        vec(byte_op_strategy(), 0..3),
    )
        .prop_map(|(seed, words, bytes)| MeshCase { seed, words, bytes })
}

/// The fixtures of `fixtures/tetmeshes/` whose name ends with `ext`.
fn mesh_seeds(ext: &str) -> Vec<Vec<u8>> {
    let mut names: Vec<_> = std::fs::read_dir(fixture("tetmeshes"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.to_string_lossy().ends_with(ext))
        .collect();
    names.sort();
    assert!(!names.is_empty(), "no fixtures/tetmeshes/*{ext}");
    names.iter().map(|p| std::fs::read(p).unwrap()).collect()
}

fn render_mesh(seeds: &[Vec<u8>], case: &MeshCase) -> Vec<u8> {
    let mut bytes = seeds[case.seed as usize % seeds.len()].clone();
    for &(index, word) in &case.words {
        let starts: Vec<usize> = (0..bytes.len())
            .filter(|&i| {
                !bytes[i].is_ascii_whitespace() && (i == 0 || bytes[i - 1].is_ascii_whitespace())
            })
            .collect();
        if starts.is_empty() {
            break;
        }
        let start = starts[index as usize % starts.len()];
        let end = (start..bytes.len())
            .find(|&i| bytes[i].is_ascii_whitespace())
            .unwrap_or(bytes.len());
        let new = MESH_WORDS[word as usize % MESH_WORDS.len()].as_bytes();
        bytes.splice(start..end, new.iter().copied());
    }
    for op in &case.bytes {
        apply_bytes(&mut bytes, op);
    }
    bytes
}

fn check_mesh(
    read: impl Fn(&[u8]) -> Result<PlainTetrahedra, halo4d::import::ImportError>,
    bytes: &[u8],
    tally: &Tally,
) -> Result<(), String> {
    tally.add("cases");
    match read(bytes) {
        Ok(m) => {
            tally.add("read");
            plain_ok(&m)?;
            let _ = halo4d::certify::certify(&m.positions, &m.tets);
            Ok(())
        }
        Err(e) => {
            tally.add("failed");
            let message = e.to_string();
            message_ok("tetrahedral mesh", &message)?;
            if !(message.contains(", line ") || message.contains(", byte ")) {
                tally.add("failed without a line or byte");
            }
            Ok(())
        }
    }
}

fn fuzz_meshes(cases: u32, long: bool) {
    let node = std::fs::read(fixture("tetmeshes/cube.node")).unwrap();
    let ele = std::fs::read(fixture("tetmeshes/cube.ele")).unwrap();
    type Read<'a> = Box<dyn Fn(&[u8]) -> Result<PlainTetrahedra, halo4d::import::ImportError> + 'a>;
    let targets: [(&str, Read); 5] = [
        ("vtu", Box::new(|b: &[u8]| halo4d::import::read_vtu(b, "m"))),
        (
            "msh",
            Box::new(|b: &[u8]| halo4d::import::read_gmsh(b, "m")),
        ),
        (
            "mesh",
            Box::new(|b: &[u8]| halo4d::import::read_medit(b, "m")),
        ),
        (
            "node",
            Box::new(|b: &[u8]| halo4d::import::read_tetgen(b, &ele, "m")),
        ),
        (
            "ele",
            Box::new(|b: &[u8]| halo4d::import::read_tetgen(&node, b, "m")),
        ),
    ];
    for (ext, read) in targets {
        let seeds = mesh_seeds(&format!(".{ext}"));
        let tally = Tally::default();
        fuzz(
            &format!("tetmesh-{ext}"),
            ext,
            cases,
            long,
            mesh_strategy(),
            |case| render_mesh(&seeds, case),
            |bytes| check_mesh(&read, bytes, &tally),
        );
        eprintln!("{ext}:");
        tally.assert_share("read", 0.05);
        tally.assert_share("failed", 0.2);
        // Nearly every error names its line or byte (those that cannot: a file without
        // tetrahedra, or without a section it needs).
        let named = tally.get("failed") - tally.get("failed without a line or byte");
        assert!(
            named as f64 >= 0.8 * tally.get("failed") as f64,
            "{ext}: only {named} of {} errors name a line or byte",
            tally.get("failed")
        );
    }
}

#[test]
fn fuzz_tetrahedral_mesh_readers() {
    fuzz_meshes(MESH_CASES, false);
}

// The long runs: `HALO4D_FUZZ_CASES` cases (default 100,000) per target, on another seed.

#[test]
#[ignore = "long: HALO4D_FUZZ_CASES=200000 cargo test --release --test main fuzz -- --ignored"]
fn fuzz_long_scene_parser() {
    fuzz_scenes(long_cases(), true);
}

#[test]
#[ignore = "long: HALO4D_FUZZ_CASES=200000 cargo test --release --test main fuzz -- --ignored"]
fn fuzz_long_glb_reader() {
    fuzz_glb(long_cases(), true);
}

#[test]
#[ignore = "long: HALO4D_FUZZ_CASES=200000 cargo test --release --test main fuzz -- --ignored"]
fn fuzz_long_vtk_reader() {
    fuzz_vtk(long_cases(), true);
}

#[test]
#[ignore = "long: HALO4D_FUZZ_CASES=200000 cargo test --release --test main fuzz -- --ignored"]
fn fuzz_long_tetrahedral_mesh_readers() {
    fuzz_meshes(long_cases(), true);
}

// ---------------------------------------------------------------------------------------
// What the fuzzing found, kept as fixtures
// ---------------------------------------------------------------------------------------

/// Which reader a broken file is for.
#[derive(Clone, Copy, Debug)]
enum Reader {
    Glb,
    SceneGlb,
    Vtk,
}

/// Files in `fixtures/broken-files/` that the fuzzing minimised: each quotes a
/// 2,000-character string, which the reader's error once echoed whole. With the words its
/// error must contain.
const BROKEN_FILES: &[(&str, Reader, &[&str])] = &[
    (
        "long-index-value.glb",
        Reader::Glb,
        &["attributes.POSITION", "invalid type"],
    ),
    (
        "long-mesh-name.glb",
        Reader::Glb,
        &["has no POSITION attribute"],
    ),
    (
        "long-accessor-type.glb",
        Reader::Glb,
        &["accessors[0]", "expected VEC3 of FLOAT"],
    ),
    (
        "long-accessor-name.glb",
        Reader::Glb,
        &["no tetrahedra for triangle", "is named"],
    ),
    (
        "long-camera-projection.glb",
        Reader::SceneGlb,
        &["camera", "unknown variant"],
    ),
    (
        "long-field-name.vtk",
        Reader::Vtk,
        &["lacks the halo layout", "fields present"],
    ),
    (
        "long-field-array-value.vtk",
        Reader::Vtk,
        &["FIELD array", "not a number"],
    ),
    (
        "long-scalars-name.vtk",
        Reader::Vtk,
        &["SCALARS", "LOOKUP_TABLE"],
    ),
    ("long-title.vtk", Reader::Vtk, &["halo layout (`layers`)"]),
];

#[test]
fn broken_files_found_by_fuzzing_get_short_errors() {
    let dir = fixture("broken-files");
    let mut files: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    files.sort();
    let mut listed: Vec<&str> = BROKEN_FILES.iter().map(|(f, ..)| *f).collect();
    listed.sort();
    assert_eq!(files, listed, "every broken file needs its entry here");
    let mut failures = Vec::new();
    for &(file, reader, words) in BROKEN_FILES {
        let bytes = std::fs::read(dir.join(file)).unwrap();
        let err = match reader {
            Reader::Glb => read_glb(&bytes).map(drop),
            Reader::SceneGlb => read_scene_glb(&bytes).map(drop),
            Reader::Vtk => read_vtk(&bytes).map(drop),
        }
        .expect_err(file)
        .to_string();
        for w in words {
            if !err.contains(w) {
                failures.push(format!("{file}: `{w}` not in {err:.300}"));
            }
        }
        if let Err(e) = message_ok(file, &err) {
            failures.push(e);
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn broken_scenes_found_by_fuzzing_get_short_errors() {
    let mut failures = Vec::new();
    for file in [
        "long-unknown-variant.json",
        "long-name.json",
        // 4-byte characters between spaces: 400 of them are 1,000 bytes.
        "long-wide-characters.json",
    ] {
        let path = fixture("broken").join(file);
        let err = Scene::load(&path).expect_err(file).to_string();
        if let Err(e) = message_ok(file, &err) {
            failures.push(e);
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
