//! Scene files: every fixture parses; broken scenes get errors that name the file and the
//! field; no input panics the parser.

use crate::common::{Rng, fixture, fixture_scenes};
use halo4d::{Scene, SceneError};

#[test]
fn every_fixture_scene_parses_and_the_default_is_the_fixture() {
    for path in fixture_scenes() {
        Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    }
    assert_eq!(
        Scene::default_scene(),
        Scene::load(&fixture("scenes/default.json")).unwrap()
    );
    assert_eq!(
        Scene::default_scene().surfaces[0].surface.type_name(),
        "spun_trefoil"
    );
}

#[test]
fn every_catalogue_surface_has_a_fixture_scene() {
    let used: Vec<&str> = fixture_scenes()
        .iter()
        .flat_map(|p| {
            Scene::load(p)
                .unwrap()
                .surfaces
                .into_iter()
                .map(|s| s.surface.type_name())
        })
        .collect();
    for s in halo4d::surfaces::Surface::catalogue() {
        assert!(
            used.contains(&s.type_name()),
            "no fixture scene uses {}",
            s.type_name()
        );
    }
}

/// Each broken scene with words its error must contain (the field and what is allowed).
const BROKEN: &[(&str, &[&str])] = &[
    (
        "absolute-tolerance-below-rounding.json",
        &[
            "sampling.absolute_tolerance",
            "1e-15 is",
            "of the surface's 4D diagonal",
            "ask for at least",
        ],
    ),
    (
        "spun-trefoil-scale-huge.json",
        &[
            "surfaces[0].surface.scale",
            "reaches a coordinate of",
            "beyond 1e30",
            "make it smaller",
        ],
    ),
    (
        "fermat-y-range-tiny.json",
        &[
            "surfaces[0].surface.y_range",
            "must be 1e-6 to 4",
            "got 5e-324",
        ],
    ),
    (
        "camera-fov-at-its-bound.json",
        &[
            "camera.fov",
            "must be greater than 1 and less than 170 degrees, got 1",
        ],
    ),
    (
        "unknown-surface.json",
        &[
            "surfaces[0].surface",
            "unknown surface type `moebius_strip`",
            "flat_torus",
        ],
    ),
    (
        "fermat-n-out-of-range.json",
        &["surfaces[0].surface.n", "must be 2 to 6", "got 9"],
    ),
    (
        "unknown-surface-key.json",
        &["surfaces[0].surface", "unknown field `raduis`", "r2"],
    ),
    (
        "unknown-halo-key.json",
        &["halo", "unknown field `rhoo`", "rho"],
    ),
    (
        "zero-resolution.json",
        &["sampling.u", "2 to 4096 cells", "got 0"],
    ),
    ("odd-resolution.json", &["sampling.u", "even number", "9"]),
    ("negative-rho.json", &["halo.rho", "1e-6 to 0.49"]),
    ("zero-rho.json", &["halo.rho", "1e-6 to 0.49"]),
    ("rho-below-f32.json", &["halo.rho", "1e-6 to 0.49", "f32"]),
    (
        "html-without-glb.json",
        &["outputs.html", "set `glb` to true as well"],
    ),
    (
        "curve-radius-too-large.json",
        &["outputs.curve_radius", "at most 0.05", "0.5"],
    ),
    (
        "infinite-number.json",
        &["surfaces[0].surface", "out of range"],
    ),
    (
        "nan-literal.json",
        &["surfaces[0].surface", "expected value"],
    ),
    (
        "one-twist.json",
        &["surfaces[0].surface.twists", "unknotted"],
    ),
    (
        "klein-not-embedded.json",
        &[
            "surfaces[0].surface.minor_radius",
            "smaller than major_radius",
        ],
    ),
    ("path-in-name.json", &["name", "../evil", "letters, digits"]),
    ("no-surfaces.json", &["surfaces", "1 to 64"]),
    ("duplicate-names.json", &["surfaces[1].name", "unique"]),
    (
        "negative-eye.json",
        &["view.projection.eye_distance", "greater than 0"],
    ),
    (
        "unknown-plane.json",
        &["view.rotation", "unknown field `xq`"],
    ),
    ("too-many-triangles.json", &["sampling", "limit"]),
    ("trailing-text.json", &["after the scene", "trailing"]),
    (
        "unknown-sampling-method.json",
        &["sampling", "unknown variant `voronoi`"],
    ),
    (
        "unknown-split.json",
        &["halo.split", "unknown variant `random`", "global_order"],
    ),
    (
        "both-tolerances.json",
        &["sampling.absolute_tolerance", "not both"],
    ),
    (
        "tolerance-too-large.json",
        &["sampling.tolerance", "must be 1e-9 to 0.5", "got 2"],
    ),
    (
        "tiny-budget.json",
        &[
            "surfaces[0].sampling.max_triangles",
            "64 to 20000000",
            "got 10",
        ],
    ),
    ("not-an-object.json", &["invalid type"]),
    (
        "negative-count.json",
        &["surfaces[0].surface.count: invalid value"],
    ),
    ("empty.json", &["EOF"]),
    (
        "delta-t-out-of-range.json",
        &["halo.delta_t", "at least 0 and less than 1"],
    ),
    // Found by fuzzing (tests/fuzz.rs), which also wants their messages short.
    (
        "long-unknown-variant.json",
        &["sampling.method", "unknown variant", "adaptive"],
    ),
    ("long-name.json", &["name", "not a usable name"]),
    (
        "long-wide-characters.json",
        &["surfaces[0].surface", "invalid type"],
    ),
    (
        "projective-plane-too-coarse.json",
        &["sampling", "projective_plane needs at least 4 x 6 cells"],
    ),
    (
        "formula-bad-range.json",
        &["surfaces[0].surface.u", "min < max, got [1, 0]"],
    ),
    (
        "formula-bends-too-sharply.json",
        &["surfaces[0].surface.x", "bends too sharply", "(u, v) = ("],
    ),
    (
        "formula-constant.json",
        &["surfaces[0].surface.x", "a single point"],
    ),
    (
        "formula-coordinate-too-large.json",
        &["surfaces[0].surface.x", "beyond the 1e30"],
    ),
    (
        "formula-deep-nesting.json",
        &["surfaces[0].surface.x", "character 257", "deeper than 256"],
    ),
    (
        "formula-divide-by-zero.json",
        &[
            "surfaces[0].surface.x",
            "(u, v) = (0, 0)",
            "`1/(u-u)` divides by zero",
        ],
    ),
    (
        "formula-empty.json",
        &["surfaces[0].surface.w", "character 1", "found the end"],
    ),
    (
        "formula-flip-sides-apart.json",
        &[
            "surfaces[0].surface.sides.u",
            "do not meet",
            "7.654e-1 away",
        ],
    ),
    (
        "formula-function-without-call.json",
        &[
            "surfaces[0].surface.w",
            "write `sin(...)`",
            "\n  sin*v\n  ^",
        ],
    ),
    (
        "formula-half-turn-apart.json",
        &["surfaces[0].surface.sides.v_min", "2.000e0 away"],
    ),
    (
        "formula-huge-power.json",
        &[
            "surfaces[0].surface.x",
            "character 8",
            "exponent 1e9",
            "\n  sin(u)^1e9\n         ^",
        ],
    ),
    (
        "formula-log-of-negative.json",
        &[
            "surfaces[0].surface.z",
            "logarithm of the negative number -10",
        ],
    ),
    (
        "formula-missing-w.json",
        &["surfaces[0].surface", "missing field `w`"],
    ),
    (
        "formula-not-a-number.json",
        &[
            "surfaces[0].surface.w",
            "square root of the negative number -1",
        ],
    ),
    (
        "formula-number-overflow.json",
        &["surfaces[0].surface.y", "`1e999` is too large"],
    ),
    (
        "formula-overflow.json",
        &["surfaces[0].surface.x", "reaches", "beyond the 1e30"],
    ),
    (
        "formula-parameter-shadows-u.json",
        &["surfaces[0].surface.parameters.u", "choose another"],
    ),
    (
        "formula-parse-error.json",
        &[
            "surfaces[0].surface.x",
            "character 7",
            "unmatched `)`",
            "\n  cos(u))\n        ^",
        ],
    ),
    (
        "formula-periodic-sides-apart.json",
        &["surfaces[0].surface.sides.u", "6.283e0 away"],
    ),
    (
        "formula-pole-not-a-point.json",
        &["surfaces[0].surface.sides.u_min", "pole's first point"],
    ),
    (
        "formula-range-with-u.json",
        &["surfaces[0].surface.v[1]", "not u or v"],
    ),
    (
        "formula-sides-conflict.json",
        &["surfaces[0].surface.sides.u_min", "not both"],
    ),
    (
        "formula-too-long.json",
        &["surfaces[0].surface.x", "4199 bytes long"],
    ),
    (
        "formula-trailing-operator.json",
        &["surfaces[0].surface.z", "character 9", "found the end"],
    ),
    (
        "formula-unclosed-parenthesis.json",
        &["surfaces[0].surface.y", "to close the `(` at character 4"],
    ),
    (
        "formula-unknown-function.json",
        &[
            "surfaces[0].surface.y",
            "unknown name `sine`; did you mean `sin`?",
        ],
    ),
    (
        "formula-unknown-key.json",
        &["surfaces[0].surface.t", "unknown field `t`"],
    ),
    (
        "formula-unknown-name.json",
        &[
            "surfaces[0].surface.x",
            "unknown name `R`; did you mean `r`?",
        ],
    ),
    (
        "formula-unknown-side-rule.json",
        &["surfaces[0].surface.sides.u", "unknown variant `periodik`"],
    ),
    (
        "formula-wrong-arity.json",
        &["surfaces[0].surface.z", "`atan2` takes 2 arguments, got 1"],
    ),
    (
        "mesh-3d-off.json",
        &[
            "surfaces[0].surface.path",
            "mesh-3d-off.off:1:",
            "use the header `4OFF`",
        ],
    ),
    (
        "mesh-binary-truncated.json",
        &[
            "surfaces[0].surface.path",
            "mesh-binary-truncated.off: byte 56:",
            "2 of 4 vertices",
        ],
    ),
    (
        "mesh-empty.json",
        &[
            "surfaces[0].surface.path",
            "mesh-empty.off:6:",
            "no triangles",
        ],
    ),
    (
        "mesh-huge-count.json",
        &[
            "surfaces[0].surface.path",
            "mesh-huge-count.off:2:",
            "1000000000000 vertices",
        ],
    ),
    (
        "mesh-index-out-of-range.json",
        &[
            "surfaces[0].surface.path",
            "mesh-index-out-of-range.off:9:",
            "face 2 refers to vertex 40",
        ],
    ),
    (
        "mesh-nan.json",
        &[
            "surfaces[0].surface.path",
            "mesh-nan.off:4:",
            "coordinate w is nan",
        ],
    ),
    (
        "mesh-obj-bad-face.json",
        &[
            "surfaces[0].surface.path",
            "mesh-obj-bad-face.obj:4:",
            "`3/a` is not a vertex reference",
        ],
    ),
    (
        "mesh-obj-three-coords.json",
        &[
            "surfaces[0].surface.path",
            "mesh-obj-three-coords.obj:2:",
            "needs the fourth coordinate w",
        ],
    ),
    (
        "mesh-ply-bad-list.json",
        &[
            "surfaces[0].surface.path",
            "mesh-ply-bad-list.ply:14:",
            "`vertex_indices` is missing",
        ],
    ),
    (
        "mesh-ply-huge-count.json",
        &[
            "surfaces[0].surface.path",
            "mesh-ply-huge-count.ply:3:",
            "1000000000000 vertices",
        ],
    ),
    (
        "mesh-ply-no-w.json",
        &[
            "surfaces[0].surface.path",
            "mesh-ply-no-w.ply:3:",
            "no property `w`",
        ],
    ),
    (
        "mesh-trailing-text.json",
        &[
            "surfaces[0].surface.path",
            "mesh-trailing-text.off:11:",
            "text after the 4 vertices",
        ],
    ),
    (
        "mesh-truncated.json",
        &[
            "surfaces[0].surface.path",
            "mesh-truncated.off:14:",
            "12 of 36 vertices",
        ],
    ),
    (
        "mesh-missing-file.json",
        &[
            "surfaces[0].surface.path",
            "mesh-no-such-file.4off",
            "cannot read",
        ],
    ),
    (
        "mesh-with-sampling.json",
        &["surfaces[0].sampling", "not sampled; remove `sampling`"],
    ),
    (
        "mesh-collapsed-triangle.json",
        &["surfaces[0].surface.path", "two corners at the same point"],
    ),
    (
        "animation-no-frames.json",
        &["animation.frames", "1 to 99999", "got 0"],
    ),
    (
        "animation-times-out-of-order.json",
        &[
            "animation.keyframes[1].time",
            "later than",
            "0.5",
            "order of time",
        ],
    ),
    (
        "animation-elevation.json",
        &[
            "animation.keyframes[1].camera.elevation",
            "-89 to 89",
            "120",
        ],
    ),
    (
        "animation-fitted-and-set-distance.json",
        &[
            "animation.keyframes[1].camera.distance",
            "fitted",
            "in the scene too",
        ],
    ),
    (
        "animation-unknown-plane.json",
        &[
            "animation.keyframes[1].view.rotation.yv",
            "unknown field `yv`",
            "yw",
        ],
    ),
    (
        "animation-projection-type.json",
        &[
            "animation.keyframes[0].view.projection",
            "the scene's view.projection type",
        ],
    ),
    (
        "animation-angle-overflow.json",
        &["animation.keyframes[0].view.rotation.xw", "out of range"],
    ),
    (
        "animation-unknown-key.json",
        &["animation.speed", "unknown field `speed`", "keyframes"],
    ),
];

#[test]
fn broken_scenes_get_errors_naming_file_and_field() {
    let dir = fixture("broken");
    let mut files: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        // The broken mesh files themselves have their test next to the mesh reader.
        .filter(|f| f.ends_with(".json"))
        .collect();
    files.sort();
    let mut listed: Vec<String> = BROKEN.iter().map(|(f, _)| f.to_string()).collect();
    listed.sort();
    assert_eq!(
        files, listed,
        "every broken fixture needs its expected message here"
    );
    for (file, words) in BROKEN {
        let path = dir.join(file);
        let err = Scene::load(&path).expect_err(file).to_string();
        assert!(
            err.starts_with(&path.display().to_string()),
            "{file}: error does not name the file: {err}"
        );
        for w in *words {
            assert!(err.contains(w), "{file}: error lacks `{w}`: {err}");
        }
    }
}

#[test]
fn missing_file_is_an_io_error_naming_it() {
    let err = Scene::load(&fixture("scenes/no-such-scene.json")).unwrap_err();
    assert!(matches!(err, SceneError::Io { .. }));
    assert!(err.to_string().contains("no-such-scene.json"), "{err}");
}

#[test]
fn truncated_and_mutated_scenes_never_panic() {
    // Every prefix of every fixture, and seeded random byte edits: errors or scenes, never a
    // panic (a panic fails the test).
    let mut rng = Rng(2026);
    let alphabet = b"{}[]\":,-.0123456789eE truefalsnul\\x";
    for path in fixture_scenes() {
        let text = std::fs::read_to_string(&path).unwrap();
        for cut in 0..text.len() {
            if text.is_char_boundary(cut) && !text[cut..].trim().is_empty() {
                assert!(
                    Scene::parse(&text[..cut], "cut.json").is_err(),
                    "a cut scene cannot be whole"
                );
            }
        }
        for _ in 0..300 {
            let mut bytes = text.clone().into_bytes();
            for _ in 0..1 + rng.below(4) {
                let i = rng.below(bytes.len());
                match rng.below(3) {
                    0 => bytes[i] = alphabet[rng.below(alphabet.len())],
                    1 => {
                        bytes.remove(i);
                    }
                    _ => bytes.insert(i, alphabet[rng.below(alphabet.len())]),
                }
            }
            if let Ok(text) = String::from_utf8(bytes)
                && let Ok(scene) = Scene::parse(&text, "mutated.json")
            {
                assert!(scene.validate().is_ok());
            }
        }
    }
}

#[test]
fn the_scene_files_page_lists_the_limits_of_the_code() {
    let page =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/SCENES.md")).unwrap();
    let table = halo4d::limits::table();
    assert!(
        page.contains(&table),
        "the table of limits in docs/SCENES.md is not the code's; it should read:\n{table}"
    );
}

#[test]
fn the_scenes_halo4d_list_prints_are_whole_scenes_that_load() {
    // Pasted into a file in halo4d's folder, each builds as it is.
    let listing = halo4d::sample::Source::listing();
    let scenes: Vec<&str> = listing
        .lines()
        .filter_map(|l| l.split_once("a scene: ").map(|(_, json)| json))
        .collect();
    assert_eq!(scenes.len(), 2, "{listing}");
    let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("listed.json");
    for json in scenes {
        let scene = Scene::parse(json, &file.display().to_string())
            .unwrap_or_else(|e| panic!("{json}: {e}"));
        assert!(scene.name.starts_with("my-"));
    }
}

#[test]
fn text_that_is_not_json_from_its_start_is_named_at_the_top_level() {
    for text in ["{not json", "nonsense", "{,}"] {
        match Scene::parse(text, "x.json") {
            Err(halo4d::SceneError::Syntax { field, .. }) => {
                assert_eq!(field, "(top level)", "{text}")
            }
            other => panic!("{text}: {other:?}"),
        }
    }
}

#[test]
fn a_view_given_as_json_is_checked_under_view_and_keeps_the_surfaces() {
    let scene = Scene::load(&fixture("scenes/mesh-clifford-torus.json")).unwrap();
    let mut view = serde_json::to_value(scene.view).unwrap();
    view["rotation"]["xw"] = 12.5.into();
    let turned = scene.with_view(&view.to_string(), "v").unwrap();
    assert_eq!(turned.view.rotation.xw, 12.5);
    assert_eq!(turned.surfaces, scene.surfaces);
    // The mesh is the same one, not read again.
    let mesh = |s: &Scene| match &s.surfaces[0].surface {
        halo4d::sample::Source::Mesh(m) => std::sync::Arc::clone(&m.mesh),
        other => panic!("{other:?}"),
    };
    assert!(std::sync::Arc::ptr_eq(&mesh(&turned), &mesh(&scene)));
    assert!(scene.with_view("\"auto\"", "v").unwrap().view.auto);
    for (text, field) in [
        (r#"{"rotation": {"xw": "ten"}}"#, "view.rotation.xw"),
        (r#"{"rotation": {"xq": 1}}"#, "view.rotation.xq"),
        ("{not json", "view"),
        (
            r#"{"projection": {"type": "perspective", "eye_distance": -1}}"#,
            "view.projection.eye_distance",
        ),
    ] {
        let e = scene.with_view(text, "v").unwrap_err();
        match &e {
            SceneError::Syntax { field: f, .. } | SceneError::Invalid { field: f, .. } => {
                assert_eq!(f, field, "{text}: {e}")
            }
            other => panic!("{other:?}"),
        }
    }
}
