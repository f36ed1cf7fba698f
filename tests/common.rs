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

/// Runs the `halo4d` binary with `args` in `dir`.
pub fn halo4d(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_halo4d"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("the halo4d binary runs")
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
