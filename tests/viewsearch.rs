//! The view search: `halo4d view`, and `"view": "auto"` in a scene.

use crate::common::{fixture, halo4d};
use halo4d::Scene;

/// The flat torus fixture's text with its `view` replaced by `view`.
fn flat_torus_with_view(view: serde_json::Value) -> String {
    let text = std::fs::read_to_string(fixture("scenes/flat-torus.json")).unwrap();
    let mut json: serde_json::Value = serde_json::from_str(&text).unwrap();
    json["view"] = view;
    serde_json::to_string_pretty(&json).unwrap()
}

#[test]
fn the_view_search_is_deterministic_no_worse_than_the_scenes_view_and_keeps_the_rest_of_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let scene = fixture("scenes/flat-torus.json");
    let scene = scene.to_str().unwrap();
    let mut written = Vec::new();
    for out in ["a.json", "b.json"] {
        let run = halo4d(&["view", scene, "--out", out, "-q"], dir.path());
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(run.status.success(), "{stderr}");
        assert!(stderr.starts_with("view search: "), "{stderr}");
        written.push(std::fs::read_to_string(dir.path().join(out)).unwrap());
    }
    assert_eq!(
        written[0], written[1],
        "the same search finds the same view"
    );
    let original: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(fixture("scenes/flat-torus.json")).unwrap())
            .unwrap();
    let found: serde_json::Value = serde_json::from_str(&written[0]).unwrap();
    for key in ["name", "description", "surfaces", "sampling"] {
        assert_eq!(found[key], original[key], "{key} kept");
    }
    assert_eq!(found["view"]["projection"], original["view"]["projection"]);
    assert_ne!(found["view"]["rotation"], original["view"]["rotation"]);
    // The library's search: the same view, scored no lower than the scene's own.
    let searched = halo4d::search_view(
        &Scene::load(&fixture("scenes/flat-torus.json")).unwrap(),
        halo4d::progress::Job::SILENT,
    )
    .unwrap();
    assert!(searched.score >= searched.start_score);
    assert!(searched.views <= halo4d::limits::SEARCH_VIEWS);
    let again = Scene::parse(&written[0], "a.json").unwrap();
    assert_eq!(again.view.rotation, searched.rotation);
    assert_eq!(
        (again.camera.azimuth, again.camera.elevation),
        (searched.azimuth, searched.elevation)
    );
}

#[test]
fn a_view_is_an_object_or_auto() {
    let auto = Scene::parse(&flat_torus_with_view(serde_json::json!("auto")), "s.json").unwrap();
    assert!(auto.view.auto);
    assert_eq!(auto.view.rotation, halo4d::view::Rotation4::default());
    let from = Scene::parse(
        &flat_torus_with_view(serde_json::json!({ "auto": true, "rotation": { "yw": 30 } })),
        "s.json",
    )
    .unwrap();
    assert!(from.view.auto);
    assert_eq!(from.view.rotation.yw, 30.0);
    let given = Scene::load(&fixture("scenes/flat-torus.json")).unwrap();
    assert!(!given.view.auto);
    // `auto: false` is not written back.
    assert!(!serde_json::to_string(&given.view).unwrap().contains("auto"));
    let err = Scene::parse(
        &flat_torus_with_view(serde_json::json!("sideways")),
        "s.json",
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("s.json") && err.contains("view"), "{err}");
    assert!(
        err.contains("\"auto\"") && err.contains("sideways"),
        "{err}"
    );
}

#[test]
fn a_scene_whose_view_is_auto_builds_in_the_view_the_search_finds() {
    let text = flat_torus_with_view(serde_json::json!("auto"));
    let mut scene = Scene::parse(&text, "auto.json").unwrap();
    // Nothing builds a view not yet found.
    let err = crate::common::built(&scene)
        .expect_err("refused")
        .to_string();
    assert!(
        err.contains("its view is \"auto\"") && err.contains("resolve_view"),
        "{err}"
    );
    let found = halo4d::resolve_view(&mut scene, halo4d::progress::Job::SILENT)
        .unwrap()
        .expect("searched");
    assert!(!scene.view.auto);
    assert_eq!(scene.view.rotation, found.rotation);
    assert!(
        halo4d::resolve_view(&mut scene, halo4d::progress::Job::SILENT)
            .unwrap()
            .is_none()
    );
    // The command line finds it, builds in it and records it.
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("auto.json"), &text).unwrap();
    let run = halo4d(&["build", "auto.json", "--out", "out"], dir.path());
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    assert!(stderr.contains("view search: "), "{stderr}");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("out/report.json")).unwrap())
            .unwrap();
    let recorded = &report["scene"]["view"];
    assert!(recorded.get("auto").is_none(), "{recorded}");
    assert_eq!(
        recorded["rotation"],
        serde_json::to_value(found.rotation).unwrap()
    );
    assert_eq!(report["scene"]["camera"]["azimuth"], found.azimuth);
    assert_eq!(report["verified"], true);
    assert!(report["picture"]["visible_curve_share"].as_f64().unwrap() > 0.3);
}
