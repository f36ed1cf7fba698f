//! The command line, run as a user runs it.

use crate::common::{fixture, halo4d};

#[test]
fn build_without_a_scene_writes_the_default_into_exports() {
    let dir = tempfile::tempdir().unwrap();
    let out = halo4d(&["build", "--quiet"], dir.path());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for f in [
        "spun-trefoil.glb",
        "spun-trefoil.ply",
        "spun-trefoil-halo.vtk",
        "report.json",
    ] {
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

#[test]
fn a_budget_too_small_for_the_tolerance_warns_and_reports_incomplete() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("tight.json");
    std::fs::write(
        &scene,
        r#"{ "name": "tight", "surfaces": [ { "surface": { "type": "spun_trefoil" } } ],
             "sampling": { "method": "adaptive", "tolerance": 1e-7, "max_triangles": 2000 },
             "outputs": { "glb": false, "ply": false } }"#,
    )
    .unwrap();
    let out = halo4d(&["build", "tight.json", "--out", "o", "-q"], dir.path());
    assert!(out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("warning") && err.contains("max_triangles = 2000"),
        "{err}"
    );
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("o/report.json")).unwrap()).unwrap();
    let sampling = &report["surfaces"][0]["sampling"];
    assert_eq!(sampling["complete"], false, "{sampling}");
    assert!(sampling["triangles"].as_u64().unwrap() <= 2000);
    assert!(sampling["max_error"].as_f64().unwrap() > sampling["tolerance"].as_f64().unwrap());
    assert_eq!(report["warnings"].as_array().unwrap().len(), 1);
}

#[test]
fn sweep_writes_csv_and_plot_for_a_scene() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("two.json");
    std::fs::write(
        &scene,
        r#"{ "name": "two", "surfaces": [
             { "name": "torus", "surface": { "type": "flat_torus" } },
             { "name": "knot", "surface": { "type": "spun_trefoil" } } ] }"#,
    )
    .unwrap();
    let out = halo4d(
        &["sweep", "two.json", "--tolerances", "1e-2,3e-3", "-q"],
        dir.path(),
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv =
        std::fs::read_to_string(dir.path().join("exports/reports/speed_vs_error.csv")).unwrap();
    let mut lines = csv.lines();
    assert!(
        lines
            .next()
            .unwrap()
            .starts_with("surface,method,tolerance,triangles,ms,max_error,rms_error")
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 2 * 2 * 2, "{csv}");
    for r in &rows {
        let (tol, max): (f64, f64) = (r[2].parse().unwrap(), r[5].parse().unwrap());
        assert_eq!(r[7], "true", "{csv}");
        assert!(max <= tol && max > 0.0, "{csv}");
    }
    let png = image::open(dir.path().join("exports/reports/speed_vs_error.png")).unwrap();
    assert_eq!((png.width(), png.height()), (1200, 800));
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(table.contains("ratio") && table.contains("knot"), "{table}");
    // A bad flag value names the flag.
    let out = halo4d(&["sweep", "--tolerances", "2"], dir.path());
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--tolerances"));
}
