//! The command line, run as a user runs it.

use crate::common::fixture;
use std::process::Command;

fn halo4d(args: &[&str], dir: &std::path::Path) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_halo4d"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap()
}

#[test]
fn build_without_a_scene_writes_the_default_into_exports() {
    let dir = tempfile::tempdir().unwrap();
    let out = halo4d(&["build", "--quiet"], dir.path());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for f in ["spun-trefoil.glb", "spun-trefoil.ply", "report.json"] {
        assert!(
            dir.path().join("exports/spun-trefoil").join(f).is_file(),
            "{f} missing"
        );
    }
}

#[test]
fn a_broken_scene_fails_with_the_file_and_field_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let scene = fixture("broken/fermat-n-out-of-range.json");
    let out = halo4d(
        &["build", scene.to_str().unwrap(), "--out", "o"],
        dir.path(),
    );
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("fermat-n-out-of-range.json") && err.contains("surfaces[0].surface.n"),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
    assert!(!dir.path().join("o").exists());
}

#[test]
fn list_shows_every_surface_with_defaults_and_help_works_everywhere() {
    let dir = tempfile::tempdir().unwrap();
    let out = halo4d(&["list"], dir.path());
    let text = String::from_utf8_lossy(&out.stdout);
    for s in halo4d::Surface::catalogue() {
        assert!(text.contains(s.type_name()), "{text}");
    }
    assert!(
        text.contains("\"twists\":2") && text.contains("\"n\":4"),
        "{text}"
    );
    for args in [&["--help"][..], &["build", "--help"], &["list", "--help"]] {
        let out = halo4d(args, dir.path());
        assert!(out.status.success() && !out.stdout.is_empty(), "{args:?}");
    }
    let out = halo4d(&["build", "--bogus"], dir.path());
    assert_eq!(out.status.code(), Some(2));
}
