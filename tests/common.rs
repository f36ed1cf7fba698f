//! Shared helpers: fixture paths and a seeded generator.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A path under `fixtures/`.
pub fn fixture(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures")
        .join(rel)
}

/// Every scene in `fixtures/scenes/`, sorted.
pub fn fixture_scenes() -> Vec<PathBuf> {
    let v = scenes_in("scenes");
    assert!(
        v.len() >= 9,
        "expected a scene per catalogue surface, found {}",
        v.len()
    );
    v
}

/// Every scene in `fixtures/hard/` (hard cases that must build verified), sorted.
pub fn hard_scenes() -> Vec<PathBuf> {
    let v = scenes_in("hard");
    assert!(!v.is_empty(), "fixtures/hard has no scene");
    v
}

/// The `.json` files directly in `fixtures/<folder>`, sorted.
pub fn scenes_in(folder: &str) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(fixture(folder))
        .unwrap_or_else(|e| panic!("fixtures/{folder}: {e}"))
        .map(|e| e.expect("readable entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    v.sort();
    v
}

/// SplitMix64: reproducible pseudo-random numbers.
pub struct Rng(pub u64);

impl Rng {
    /// The next 64 random bits.
    pub fn bits(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// A number in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.bits() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// An index in 0..n.
    pub fn below(&mut self, n: usize) -> usize {
        (self.bits() % n as u64) as usize
    }
}

/// The name of each failure of a verdict: its first word that is a name (`3
/// self_intersections (...)` is `self_intersections`, `volume_defect 1e-3 (...)` is
/// `volume_defect`).
pub fn failure_names(failures: &[String]) -> Vec<String> {
    failures
        .iter()
        .map(|f| {
            let word = f
                .split_whitespace()
                .find(|w| w.starts_with(char::is_alphabetic));
            word.unwrap_or("").to_string()
        })
        .collect()
}

/// Runs the `halo4d` binary with `args` in `dir`.
pub fn halo4d(args: &[&str], dir: &Path) -> Output {
    halo4d_with(args, dir, &[])
}

/// [`halo4d`] with environment variables set.
pub fn halo4d_with(args: &[&str], dir: &Path, env: &[(&str, &str)]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_halo4d"))
        .args(args)
        .envs(env.iter().copied())
        .current_dir(dir)
        .output()
        .expect("the halo4d binary runs")
}

/// A .glb of this JSON text (padded with spaces) followed by `bin_chunk` as it is (its
/// header included, whatever it says), with a correct file header and JSON chunk header.
pub fn pack_glb(json: &[u8], bin_chunk: &[u8]) -> Vec<u8> {
    let mut json = json.to_vec();
    json.resize(json.len().next_multiple_of(4), b' ');
    let total = 20 + json.len() + bin_chunk.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(bin_chunk);
    out
}

/// The .glb with its JSON chunk edited.
pub fn with_json(glb: &[u8], edit: impl FnOnce(&mut serde_json::Value)) -> Vec<u8> {
    let json_len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    let mut json: serde_json::Value = serde_json::from_slice(&glb[20..20 + json_len]).unwrap();
    edit(&mut json);
    pack_glb(&serde_json::to_vec(&json).unwrap(), &glb[20 + json_len..])
}

/// `out` failed on unreadable input (exit 2) with an `error: ` line containing `words`,
/// and no panic.
pub fn assert_unreadable(out: &Output, what: &str, words: &[&str]) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{what}: {err}");
    assert!(err.starts_with("error: "), "{err}");
    for w in words {
        assert!(err.contains(w), "{what}: `{w}` not in {err}");
    }
    assert!(!err.contains("panicked"), "{err}");
}

/// Formula surfaces with every kind of side rule, each with a geometry those rules fit:
/// the example torus, a Klein bottle flipped across v, a projective plane with its pole
/// and half turn on the v sides, and a round sphere with two poles.
pub fn formula_surfaces() -> Vec<halo4d::surfaces::Surface> {
    let tau = std::f64::consts::TAU;
    let read = |json: serde_json::Value| -> halo4d::surfaces::Surface {
        serde_json::from_value(json).unwrap_or_else(|e| panic!("{e}"))
    };
    vec![
        halo4d::surfaces::Surface::Formula(halo4d::surfaces::Formula::example()),
        read(serde_json::json!({
            "type": "formula",
            "x": "(1 + 0.5*cos(u))*cos(v)", "y": "(1 + 0.5*cos(u))*sin(v)",
            "z": "0.5*sin(u)*cos(v/2)", "w": "0.5*sin(u)*sin(v/2)",
            "u": [0.0, tau], "v": [0.0, tau],
            "sides": {"u": "periodic", "v": "flip"}
        })),
        read(serde_json::json!({
            "type": "formula",
            "x": "cos(v)*sin(v)*cos(u)", "y": "cos(v)*sin(v)*sin(u)",
            "z": "(sin(v)*cos(u))^2 - (sin(v)*sin(u))^2", "w": "2*sin(v)^2*cos(u)*sin(u)",
            "u": [0.0, tau], "v": [0.0, std::f64::consts::FRAC_PI_2],
            "sides": {"u": "periodic", "v_min": "pole", "v_max": "half_turn"}
        })),
        read(serde_json::json!({
            "type": "formula",
            "x": "sin(u)*cos(v)", "y": "sin(u)*sin(v)", "z": "cos(u)", "w": "0.3*sin(u)^2*cos(v)",
            "u": [0.0, std::f64::consts::PI], "v": [0.0, tau],
            "sides": {"u_min": "pole", "u_max": "pole", "v": "periodic"}
        })),
    ]
}

/// The build of `scene` in its view: sampled once, then the stages its outputs need.
pub fn built(scene: &halo4d::Scene) -> Result<halo4d::Built, halo4d::Error> {
    halo4d::Sampled::of(scene).into_built(scene, halo4d::Stages::of(scene))
}

/// What `work` gives on a pool of `threads` threads (for tests that results do not depend on
/// the number of threads).
pub fn on_threads<T: Send>(threads: usize, work: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool")
        .install(work)
}
