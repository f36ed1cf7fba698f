//! Builds that would run for minutes are refused at once: every scene in
//! `fixtures/refused/` loads, and its build stops before the slow stages with
//! [`Error::Work`], naming what makes it slow and the fields to change. `.ci/run fixtures`
//! times each refusal with the `halo4d` binary.

use crate::common::{built, fixture, fixture_scenes, hard_scenes};
use halo4d::limits::{HALO_CROWDING, SURFACE_CROWDING};
use halo4d::{Error, Scene};

/// Each refused scene with words its error must contain.
const REFUSED: &[(&str, &[&str])] = &[
    (
        "fermat-quartic-sliver-grid.json",
        &[
            "triangles of surface `fermat` are slivers",
            "grid of 4096 x 8 cells",
            "`sampling.u` and `sampling.v`",
            "`sampling.method: adaptive`",
        ],
    ),
    (
        "halos-keep-wide-folds.json",
        &[
            "halo of surface `spun_trefoil` overlaps itself",
            "0.200 of the scene's diagonal",
            "`halo.rho`",
            "set `halo.fold` to `shrink`",
        ],
    ),
];

#[test]
fn refused_scenes_stop_with_what_to_change() {
    let dir = fixture("refused");
    let mut files: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    files.sort();
    let listed: Vec<&str> = REFUSED.iter().map(|(f, _)| *f).collect();
    assert_eq!(files, listed, "every refused fixture needs its words here");
    for (file, words) in REFUSED {
        let scene = Scene::load(&dir.join(file)).unwrap();
        let err = built(&scene)
            .err()
            .unwrap_or_else(|| panic!("{file} built"));
        assert!(matches!(err, Error::Work { .. }), "{file}: {err}");
        let err = err.to_string();
        for w in *words {
            assert!(err.contains(w), "{file}: error lacks `{w}`: {err}");
        }
    }
}

#[test]
fn every_fixture_is_below_the_crowding_limits() {
    // A probe is a triangle's centroid: its own triangle's box holds it, and so does the
    // box of a tetrahedron of the prism over it (the triangle is a face between the
    // layers). No fixture comes near a limit.
    for path in fixture_scenes().into_iter().chain(hard_scenes()) {
        let scene = Scene::load(&path).unwrap();
        let c = built(&scene).unwrap().crowding;
        let what = format!("{}: {c:?}", path.display());
        assert_eq!(c.triangles.len(), scene.surfaces.len(), "{what}");
        assert_eq!(c.halos.len(), scene.surfaces.len(), "{what}");
        assert!(
            c.triangles
                .iter()
                .all(|&t| (1.0..0.75 * SURFACE_CROWDING).contains(&t)),
            "{what}"
        );
        assert!(
            c.halos
                .iter()
                .all(|&h| (1.0..0.75 * HALO_CROWDING).contains(&h)),
            "{what}"
        );
    }
}
