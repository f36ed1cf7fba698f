//! Seeded fuzzing beyond the parsers, with the runner of [`crate::fuzz`]: formula surfaces
//! built through the whole pipeline, and 4D mesh files read.
//!
//! - formulas: the fixtures' formula surfaces on an 8 x 8 grid, their expressions and
//!   parameters edited (a number set to an extreme, a token inserted, a character removed,
//!   two coordinates swapped, a parameter set to an extreme); each case is parsed, then
//!   sampled, projected and given its halos, curves and verification. Properties: no panic;
//!   an error is a short message (a scene's names the file); a build's every mesh, halo
//!   and curve point is finite, and its verdict names what fails;
//! - 4D mesh files: `fixtures/meshes/` and the broken mesh fixtures, with an OBJ and a PLY of
//!   a tetrahedron; numbers set to extremes, bytes flipped, inserted or cut; each case read
//!   as OFF, OBJ and PLY. Properties: no panic; an error is a short message naming the
//!   file; a mesh read is finite, its indices in range, and written as 4OFF ([`to_4off`])
//!   it reads back bit for bit.
//!
//! The default run tries [`FORMULA_CASES`] and [`MESH_CASES`] cases; the long run of
//! [`crate::fuzz`] (`HALO4D_FUZZ_CASES`) runs a twentieth as many formula builds and as
//! many mesh files.

use crate::common::{fixture, scenes_in};
use crate::fuzz::{
    ByteOp, MAX_MESSAGE, Tally, VTK_NUMBERS, apply_bytes, byte_op_strategy, fuzz, long_cases,
    message_ok,
};
use halo4d::export::to_4off;
use halo4d::import::{MeshFormat, parse_mesh4};
use halo4d::{Sampled, Scene, Stages};
use proptest::collection::vec;
use proptest::prelude::*;
use serde_json::Value;
use std::sync::OnceLock;

/// Formula builds of the default run.
const FORMULA_CASES: u32 = 3000;
/// Mesh files of the default run.
const MESH_CASES: u32 = 6000;

// ---------------------------------------------------------------------------------------
// Formula surfaces, built
// ---------------------------------------------------------------------------------------

/// The seeds: every formula fixture, on an 8 x 8 grid, as JSON.
fn formula_seeds() -> &'static Vec<Value> {
    static SEEDS: OnceLock<Vec<Value>> = OnceLock::new();
    SEEDS.get_or_init(|| {
        let seeds: Vec<Value> = scenes_in("scenes")
            .iter()
            .filter(|p| {
                p.file_name()
                    .unwrap()
                    .to_string_lossy()
                    .starts_with("formula-")
            })
            .map(|p| {
                let mut v: Value =
                    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap();
                v["sampling"] = serde_json::json!({ "method": "uniform", "u": 8, "v": 8 });
                v
            })
            .collect();
        assert!(seeds.len() >= 3, "{} formula fixtures", seeds.len());
        seeds
    })
}

/// Tokens a formula edit inserts.
const TOKENS: &[&str] = &[
    "+",
    "-",
    "*",
    "/",
    "^",
    "(",
    ")",
    ",",
    "u",
    "v",
    "pi",
    "e",
    "sin(",
    "cos(",
    "tan(",
    "exp(",
    "log(",
    "sqrt(",
    "abs(",
    "atan2(",
    "pow(",
    "1e308",
    "1e-308",
    "0",
    "0/0",
    "R",
    "r",
    "x",
    "2",
    "1e9",
    "-1",
    "u*u*u*u*u*u*u*u",
];

/// An edit of a formula scene.
#[derive(Clone, Debug)]
enum FormulaOp {
    /// The `k`-th number in coordinate `field` set to one of [`VTK_NUMBERS`].
    Number { field: u8, k: u32, with: u32 },
    /// A token inserted at a position of coordinate `field`.
    Insert { field: u8, at: u32, token: u32 },
    /// A character removed from coordinate `field`.
    Remove { field: u8, at: u32 },
    /// Two coordinates' expressions swapped.
    Swap(u8, u8),
    /// A parameter, or a parameter range's end, set to one of [`VTK_NUMBERS`].
    Value { k: u32, with: u32 },
}

const FIELDS: [&str; 4] = ["x", "y", "z", "w"];

#[derive(Clone, Debug)]
struct FormulaCase {
    seed: u32,
    ops: Vec<FormulaOp>,
}

fn formula_strategy() -> impl Strategy<Value = FormulaCase> {
    let f = || 0u8..4;
    let u = any::<u32>;
    let op = prop_oneof![
        3 => (f(), u(), u()).prop_map(|(field, k, with)| FormulaOp::Number { field, k, with }),
        3 => (f(), u(), u()).prop_map(|(field, at, token)| FormulaOp::Insert { field, at, token }),
        2 => (f(), u()).prop_map(|(field, at)| FormulaOp::Remove { field, at }),
        1 => (f(), f()).prop_map(|(a, b)| FormulaOp::Swap(a, b)),
        2 => (u(), u()).prop_map(|(k, with)| FormulaOp::Value { k, with }),
    ];
    (any::<u32>(), vec(op, 1..4)).prop_map(|(seed, ops)| FormulaCase { seed, ops })
}

/// The byte offsets of the numbers in `text`, each (start, end).
fn numbers(text: &str) -> Vec<(usize, usize)> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let starts = b[i].is_ascii_digit() && (i == 0 || !b[i - 1].is_ascii_alphanumeric());
        if starts {
            let start = i;
            while i < b.len() && (b[i].is_ascii_digit() || b[i] == b'.') {
                i += 1;
            }
            out.push((start, i));
        } else {
            i += 1;
        }
    }
    out
}

/// A position in `text` (a character boundary), from `at`.
fn boundary(text: &str, at: u32) -> usize {
    let mut i = at as usize % (text.len() + 1);
    while !text.is_char_boundary(i) {
        i -= 1;
    }
    i
}

fn render_formula(case: &FormulaCase) -> Vec<u8> {
    let seeds = formula_seeds();
    let mut scene = seeds[case.seed as usize % seeds.len()].clone();
    let surface = &mut scene["surfaces"][0]["surface"];
    let extreme = |with: u32| VTK_NUMBERS[with as usize % VTK_NUMBERS.len()];
    for op in &case.ops {
        let text = |field: u8| {
            surface[FIELDS[field as usize]]
                .as_str()
                .unwrap_or("")
                .to_string()
        };
        match *op {
            FormulaOp::Number { field, k, with } => {
                let mut t = text(field);
                let found = numbers(&t);
                if !found.is_empty() {
                    let (a, b) = found[k as usize % found.len()];
                    t.replace_range(a..b, extreme(with));
                    surface[FIELDS[field as usize]] = t.into();
                }
            }
            FormulaOp::Insert { field, at, token } => {
                let mut t = text(field);
                let at = boundary(&t, at);
                t.insert_str(at, TOKENS[token as usize % TOKENS.len()]);
                surface[FIELDS[field as usize]] = t.into();
            }
            FormulaOp::Remove { field, at } => {
                let mut t = text(field);
                if !t.is_empty() {
                    let at = boundary(&t, at).min(t.len() - 1);
                    if t.is_char_boundary(at) {
                        t.remove(at);
                    }
                    surface[FIELDS[field as usize]] = t.into();
                }
            }
            FormulaOp::Swap(a, b) => {
                let (ta, tb) = (text(a), text(b));
                surface[FIELDS[a as usize]] = tb.into();
                surface[FIELDS[b as usize]] = ta.into();
            }
            FormulaOp::Value { k, with } => {
                // The parameters' values, then the ends of the u and v ranges.
                let mut places: Vec<&mut Value> = Vec::new();
                let Value::Object(o) = surface else { break };
                for (key, v) in o.iter_mut() {
                    match (key.as_str(), v) {
                        ("parameters", Value::Object(p)) => places.extend(p.values_mut()),
                        ("u" | "v", Value::Array(a)) => places.extend(a.iter_mut()),
                        _ => {}
                    }
                }
                if !places.is_empty() {
                    let n = places.len();
                    let number: f64 = extreme(with).parse().unwrap_or(0.0);
                    *places[k as usize % n] = serde_json::json!(number);
                }
            }
        }
    }
    serde_json::to_vec(&scene).unwrap()
}

/// Builds a case as `halo4d build` does, but for the picture and the files.
fn check_formula(bytes: &[u8], tally: &Tally) -> Result<(), String> {
    tally.add("cases");
    let text = std::str::from_utf8(bytes).expect("formula cases are JSON");
    let scene = match Scene::parse(text, "fuzz.json") {
        Ok(scene) => scene,
        Err(e) => {
            tally.add("refused by the scene");
            let message = e.to_string();
            message_ok("scene", &message)?;
            if !message.starts_with("fuzz.json") {
                return Err(format!("the error does not name the file: {message}"));
            }
            return Ok(());
        }
    };
    let stages = Stages {
        halos: true,
        curves: true,
        verify: true,
        stipples: false,
    };
    let built = match Sampled::of(&scene).into_built(&scene, stages) {
        Ok(built) => built,
        Err(e) => {
            tally.add("refused by the build");
            return message_ok("build", &e.to_string());
        }
    };
    tally.add("built");
    for p in &built.surfaces {
        let finite = p.mesh.positions.iter().all(|x| x.is_finite())
            && p.projected.positions.iter().all(|x| x.is_finite())
            && p.projected.w.iter().all(|x| x.is_finite())
            && p.halo.positions.iter().all(|x| x.is_finite())
            && p.halo.d_orig.iter().all(|x| x.is_finite());
        if !finite {
            return Err(format!(
                "surface `{}` built with a non-finite value",
                p.name
            ));
        }
    }
    if let Some(c) = built.curves.curves.iter().find(|c| {
        c.points
            .iter()
            .any(|p| !p.position.is_finite() || !p.w.iter().all(|w| w.is_finite()))
    }) {
        return Err(format!(
            "a curve of {} points is not finite",
            c.points.len()
        ));
    }
    let failures = built.failures();
    if failures.is_empty() {
        tally.add("built verified");
    }
    for f in &failures {
        if f.is_empty() || f.len() > MAX_MESSAGE {
            return Err(format!("a failure of {} bytes: {f:.200}", f.len()));
        }
    }
    Ok(())
}

fn fuzz_formulas(cases: u32, long: bool) {
    let tally = Tally::default();
    fuzz(
        "formula",
        "json",
        cases,
        long,
        formula_strategy(),
        render_formula,
        |bytes| check_formula(bytes, &tally),
    );
    tally.assert_share("refused by the scene", 0.1);
    tally.assert_share("built", 0.1);
    tally.assert_share("built verified", 0.02);
}

#[test]
fn fuzz_formula_builds() {
    fuzz_formulas(FORMULA_CASES, false);
}

#[test]
#[ignore = "long: HALO4D_FUZZ_CASES=200000 cargo test --release --test main fuzz -- --ignored"]
fn fuzz_long_formula_builds() {
    fuzz_formulas(long_cases() / 20, true);
}

// ---------------------------------------------------------------------------------------
// 4D mesh files, read
// ---------------------------------------------------------------------------------------

/// The seeds: each file's bytes and format (every case is read in every format).
fn mesh_seeds() -> &'static Vec<(Vec<u8>, MeshFormat)> {
    static SEEDS: OnceLock<Vec<(Vec<u8>, MeshFormat)>> = OnceLock::new();
    SEEDS.get_or_init(|| {
        let mut seeds = Vec::new();
        for folder in ["meshes", "broken"] {
            let mut paths: Vec<_> = std::fs::read_dir(fixture(folder))
                .unwrap()
                .map(|e| e.unwrap().path())
                .collect();
            paths.sort();
            for path in paths {
                if let Ok(format) = MeshFormat::from_path(&path) {
                    seeds.push((std::fs::read(&path).unwrap(), format));
                }
            }
        }
        let corners = "0 0 0 0\n1 0 0 0.5\n0 1 0 -0.5\n0 0 1 0.25\n";
        let obj = format!(
            "o tetrahedron\n{}f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
            corners.lines().map(|l| format!("v {l}\n")).collect::<String>()
        );
        let ply = format!(
            "ply\nformat ascii 1.0\nelement vertex 4\nproperty double x\nproperty double y\nproperty double z\nproperty double w\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n{corners}3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n"
        );
        for (bytes, format) in [(obj, MeshFormat::Obj), (ply, MeshFormat::Ply)] {
            parse_mesh4(bytes.as_bytes(), "seed", format).unwrap();
            seeds.push((bytes.into_bytes(), format));
        }
        assert!(seeds.len() >= 15, "{} mesh seeds", seeds.len());
        seeds
    })
}

#[derive(Clone, Debug)]
struct MeshCase {
    seed: u32,
    /// Numbers of the text set to one of [`VTK_NUMBERS`]: (which, with).
    numbers: Vec<(u32, u32)>,
    bytes: Vec<ByteOp>,
}

fn mesh_strategy() -> impl Strategy<Value = MeshCase> {
    (
        any::<u32>(),
        vec((any::<u32>(), any::<u32>()), 0..4),
        prop_oneof![2 => Just(Vec::new()), 1 => vec(byte_op_strategy(), 1..3)],
    )
        .prop_map(|(seed, numbers, bytes)| MeshCase {
            seed,
            numbers,
            bytes,
        })
}

fn render_mesh(case: &MeshCase) -> Vec<u8> {
    let seeds = mesh_seeds();
    let (bytes, _) = &seeds[case.seed as usize % seeds.len()];
    let mut bytes = bytes.clone();
    // Numbers in a text file (or a binary file's header); binary data is left to the byte
    // edits.
    let text_end = bytes
        .iter()
        .position(|&b| b == 0 || b >= 0x80)
        .unwrap_or(bytes.len());
    let mut text = String::from_utf8_lossy(&bytes[..text_end]).into_owned();
    for &(k, with) in &case.numbers {
        let found = numbers(&text);
        if !found.is_empty() {
            let (a, b) = found[k as usize % found.len()];
            text.replace_range(a..b, VTK_NUMBERS[with as usize % VTK_NUMBERS.len()]);
        }
    }
    if !case.numbers.is_empty() {
        bytes.splice(..text_end, text.into_bytes());
    }
    for op in &case.bytes {
        apply_bytes(&mut bytes, op);
    }
    bytes
}

/// Reads `bytes` as `format`.
fn check_mesh(bytes: &[u8], format: MeshFormat, tally: &Tally) -> Result<(), String> {
    tally.add("cases");
    let mesh = match parse_mesh4(bytes, "fuzz.mesh", format) {
        Ok(mesh) => mesh,
        Err(e) => {
            tally.add("failed");
            let message = e.to_string();
            message_ok("mesh", &message)?;
            if !message.starts_with("fuzz.mesh") {
                return Err(format!("the error does not name the file: {message}"));
            }
            return Ok(());
        }
    };
    tally.add("read");
    let n = mesh.positions.len();
    if mesh.positions.iter().any(|p| !p.is_finite()) {
        return Err("a mesh read with a non-finite position".into());
    }
    if mesh.triangles.iter().flatten().any(|&v| v as usize >= n) {
        return Err("a mesh read with an index out of range".into());
    }
    let written = to_4off(&mesh.positions, &mesh.triangles, "fuzz");
    match parse_mesh4(written.as_bytes(), "again.4off", MeshFormat::Off) {
        Ok(again) if again == mesh => Ok(()),
        Ok(_) => Err("the mesh written as 4OFF reads back different".into()),
        Err(e) => Err(format!("the mesh written as 4OFF does not read: {e}")),
    }
}

fn fuzz_meshes(cases: u32, long: bool) {
    let tally = Tally::default();
    fuzz(
        "mesh",
        "mesh",
        cases,
        long,
        mesh_strategy(),
        render_mesh,
        // Every case in every format: a file read as another format must fail as cleanly.
        |bytes| {
            [MeshFormat::Off, MeshFormat::Obj, MeshFormat::Ply]
                .into_iter()
                .try_for_each(|f| check_mesh(bytes, f, &tally))
        },
    );
    tally.assert_share("read", 0.02);
    tally.assert_share("failed", 0.3);
}

#[test]
fn fuzz_mesh_readers() {
    fuzz_meshes(MESH_CASES, false);
}

#[test]
#[ignore = "long: HALO4D_FUZZ_CASES=200000 cargo test --release --test main fuzz -- --ignored"]
fn fuzz_long_mesh_readers() {
    fuzz_meshes(long_cases(), true);
}
