//! Surfaces users bring: formulas and 4D meshes from files, built like the catalogue's.

use crate::common::{Rng, fixture};
use halo4d::{Scene, sample::Source};

/// A fixture scene with its pictures off (the builds compare meshes, curves and halos).
fn fixture_scene(name: &str) -> Scene {
    let mut scene = Scene::load(&fixture(&format!("scenes/{name}.json"))).unwrap();
    scene.outputs.png = false;
    scene
}

#[test]
fn catalogue_surfaces_as_formulas_give_the_same_points_derivatives_and_builds() {
    let mut rng = Rng(21);
    for name in ["flat-torus", "klein-bottle", "projective-plane"] {
        let (a, b) = (
            fixture_scene(name),
            fixture_scene(&format!("formula-{name}")),
        );
        let (Source::Parametric(sa), Source::Parametric(sb)) =
            (&a.surfaces[0].surface, &b.surfaces[0].surface)
        else {
            panic!("{name}: parametric surfaces")
        };
        assert_eq!(sb.type_name(), "formula");
        assert_eq!(sa.domain(0), sb.domain(0), "{name}: domain and side rules");
        assert_eq!(sa.topology(), sb.topology(), "{name}");
        assert_eq!(sa.min_cells(), sb.min_cells(), "{name}");
        let d = sa.domain(0);
        for _ in 0..2000 {
            let u = d.u[0] + (d.u[1] - d.u[0]) * rng.unit();
            let v = d.v[0] + (d.v[1] - d.v[0]) * rng.unit();
            let (ea, eb) = (sa.eval(0, u, v), sb.eval(0, u, v));
            for (what, x, y) in [
                ("point", ea.p, eb.p),
                ("d/du", ea.du, eb.du),
                ("d/dv", ea.dv, eb.dv),
                ("d2/du2", ea.duu, eb.duu),
                ("d2/dudv", ea.duv, eb.duv),
                ("d2/dv2", ea.dvv, eb.dvv),
            ] {
                assert!(
                    (x - y).abs().max_element() <= 1e-12,
                    "{name}: {what} at ({u}, {v}): {x} against {y}"
                );
            }
            assert!((sa.point(0, u, v) - sb.point(0, u, v)).abs().max_element() <= 1e-12);
        }

        let (ba, bb) = (
            crate::common::built(&a).unwrap(),
            crate::common::built(&b).unwrap(),
        );
        let (ma, mb) = (&ba.surfaces[0].mesh, &bb.surfaces[0].mesh);
        assert_eq!(ma.triangles, mb.triangles, "{name}: the same mesh");
        for (p, q) in ma.positions.iter().zip(&mb.positions) {
            assert!(
                (*p - *q).abs().max_element() <= 1e-12,
                "{name}: {p} against {q}"
            );
        }
        assert_eq!(ba.surfaces[0].stats, bb.surfaces[0].stats, "{name}");
        for (ca, cb) in [
            (&ba.curves, &bb.curves),
            (ba.shown_curves(), bb.shown_curves()),
        ] {
            assert_eq!(ca.curves.len(), cb.curves.len(), "{name}: curves");
            for (x, y) in ca.curves.iter().zip(&cb.curves) {
                assert_eq!(x.points.len(), y.points.len(), "{name}: curve points");
                for (p, q) in x.points.iter().zip(&y.points) {
                    assert!(p.position.distance(q.position) <= 1e-12, "{name}");
                }
            }
        }
        let (ha, hb) = (&ba.surfaces[0].halo_report, &bb.surfaces[0].halo_report);
        assert_eq!(
            (
                ha.prisms,
                ha.tets,
                ha.inverted,
                ha.shrunk_vertices,
                ha.twisted_prisms
            ),
            (
                hb.prisms,
                hb.tets,
                hb.inverted,
                hb.shrunk_vertices,
                hb.twisted_prisms
            ),
            "{name}: halos"
        );
        assert!((ha.rho - hb.rho).abs() <= 1e-12 * ha.rho, "{name}");
        let (va, vb) = (&ba.verification, &bb.verification);
        assert_eq!(
            (va.curve_samples, va.correct, va.wrong, va.ambiguous),
            (vb.curve_samples, vb.correct, vb.wrong, vb.ambiguous),
            "{name}: verification"
        );
        assert_eq!(vb.wrong, 0, "{name}");
    }
}

/// A scene of one surface in the oblique view the curve tests use, on a grid.
fn scene_json(surface: &str, sampling: &str) -> String {
    format!(
        r#"{{"name": "own", "surfaces": [{{"surface": {surface}}}], {sampling}
            "view": {{"rotation": {{"yw": 30, "xz": 10}}, "projection": {{"type": "orthographic"}}}},
            "outputs": {{"glb": false, "ply": false, "vtk": false, "png": false, "report": false, "verify": true}}}}"#
    )
}

#[test]
fn a_4off_of_a_catalogue_mesh_builds_the_same_curves_and_verifies() {
    let dir = tempfile::tempdir().unwrap();
    for (surface, folder) in [
        (r#"{"type": "flat_torus"}"#, "torus"),
        (r#"{"type": "klein_bottle"}"#, "klein"),
    ] {
        // The build writes its 4D mesh (`outputs.off4`), and nothing else.
        let grid = r#""sampling": {"method": "uniform", "u": 48, "v": 48},"#;
        let mut scene = Scene::parse(&scene_json(surface, grid), "catalogue.json").unwrap();
        scene.outputs.off4 = true;
        let catalogue = crate::common::built(&scene).unwrap();
        let mesh = &catalogue.surfaces[0].mesh;
        let written = halo4d::write(&scene, &catalogue, &dir.path().join(folder)).unwrap();
        let file = format!("{folder}/{}.4off", scene.name);
        assert_eq!(written.files, [format!("{}.4off", scene.name)]);
        let path = dir.path().join("scene.json");
        let text = scene_json(&format!(r#"{{"type": "mesh", "path": "{file}"}}"#), "");
        std::fs::write(&path, text).unwrap();
        let scene = Scene::load(&path).unwrap();
        let Source::Mesh(m) = &scene.surfaces[0].surface else {
            panic!("a mesh source")
        };
        assert_eq!(m.mesh.positions, mesh.positions, "{file}: points read back");
        assert_eq!(
            m.mesh.triangles, mesh.triangles,
            "{file}: triangles read back"
        );
        let built = crate::common::built(&scene).unwrap();

        // The curves depend on the projected mesh only: the same, point for point.
        let (a, b) = (&catalogue.curves, &built.curves);
        assert!(a.report.points > 20, "{file}: the view has curves");
        assert_eq!(a.curves.len(), b.curves.len(), "{file}");
        for (ca, cb) in a.curves.iter().zip(&b.curves) {
            let pa: Vec<_> = ca.points.iter().map(|p| p.position).collect();
            let pb: Vec<_> = cb.points.iter().map(|p| p.position).collect();
            assert_eq!(pa, pb, "{file}");
        }
        // The halos' normals come from the mesh instead of the parametrization: the
        // verification passes as the catalogue's does, on as many samples.
        for (what, v) in [
            ("catalogue", &catalogue.verification),
            ("file", &built.verification),
        ] {
            assert_eq!(v.wrong, 0, "{file} ({what}): {v:?}");
            assert!(v.correct > 0, "{file} ({what})");
        }
        assert_eq!(
            catalogue.verification.curve_samples,
            built.verification.curve_samples
        );
        // The file's curves are not moved: that mesh is the surface.
        let r = built
            .refined
            .as_ref()
            .and_then(|c| c.report.refinement.clone())
            .unwrap();
        assert_eq!((r.refined, r.not_converged), (0, 0), "{file}");
        assert_eq!(
            r.on_meshes,
            b.report.points + b.triple_points.len(),
            "{file}"
        );
        // The topology the mesh's combinatorics give is the catalogue surface's.
        assert_eq!(
            scene.surfaces[0].surface.topology(),
            catalogue.surfaces[0].surface.topology(),
            "{file}"
        );
    }
}

#[test]
fn a_mesh_surface_refuses_sampling_and_names_a_missing_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.json");
    std::fs::write(
        &path,
        scene_json(r#"{"type": "mesh", "path": "nowhere.4off"}"#, ""),
    )
    .unwrap();
    let err = Scene::load(&path).unwrap_err().to_string();
    assert!(
        err.contains("surfaces[0].surface.path") && err.contains("nowhere.4off"),
        "{err}"
    );
    std::fs::copy(
        fixture("meshes/tetrahedron.4off"),
        dir.path().join("t.4off"),
    )
    .unwrap();
    let text = r#"{"name": "own", "surfaces": [{"surface": {"type": "mesh", "path": "t.4off"},
        "sampling": {"method": "uniform", "u": 8, "v": 8}}]}"#;
    std::fs::write(&path, text).unwrap();
    let err = Scene::load(&path).unwrap_err().to_string();
    assert!(
        err.contains("surfaces[0].sampling") && err.contains("not sampled"),
        "{err}"
    );
}

#[test]
fn tangents_from_a_mesh_approach_the_surface_s_and_keep_its_orientation() {
    // The Klein bottle's tangent plane against the planes the mesh gives, on grids of
    // growing size: the largest angle about halves with the cells (first order: a grid's
    // cells split along one diagonal make one-rings that are not symmetric), and u ∧ v
    // points the way the parametrization's does wherever the mesh's winding agrees.
    let surface = halo4d::surfaces::Surface::KleinBottle(Default::default());
    let mut worst = Vec::new();
    for n in [16, 32, 64] {
        let mesh = halo4d::sample::sample_uniform(&surface, n, n);
        let (tu, tv) = halo4d::sample::mesh_tangents(&mesh.positions, &mesh.triangles);
        let mut largest = 0.0f64;
        for i in 0..mesh.positions.len() {
            let e1 = mesh.tangent_u[i].normalize();
            let e2 = (mesh.tangent_v[i] - e1 * e1.dot(mesh.tangent_v[i])).normalize();
            for t in [tu[i], tv[i]] {
                let off = (t - e1 * e1.dot(t) - e2 * e2.dot(t)).length();
                largest = largest.max(off);
            }
            let orient = tu[i].dot(e1) * tv[i].dot(e2) - tu[i].dot(e2) * tv[i].dot(e1);
            // On the seam glued with a flip the triangles on its two sides wind against each
            // other: either way is right there.
            let u = mesh.uv[i][0];
            let seam = u == 0.0 || u == std::f64::consts::TAU;
            assert!(
                orient > 0.99 || (seam && orient < -0.99),
                "{n}: vertex {i} at u = {u}: {orient}"
            );
        }
        worst.push(largest);
    }
    assert!(worst[2] < 0.02, "{worst:?}");
    assert!(
        worst[0] > 1.8 * worst[1] && worst[1] > 1.8 * worst[2],
        "{worst:?}"
    );
}

#[test]
fn a_mesh_file_that_is_not_a_manifold_builds_with_a_warning() {
    // Edge 0-1 in three triangles, and triangle 0 1 2 along one line.
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("bad.4off"),
        "4OFF\n5 4 0\n0 0 0 0\n1 0 0 0\n2 0 0 0\n0 1 0 0\n0 0 1 0.5\n3 0 1 3\n3 0 1 2\n3 0 1 4\n3 1 3 4\n",
    )
    .unwrap();
    std::fs::write(
        dir.path().join("s.json"),
        r#"{"name": "edge", "surfaces": [{"surface": {"type": "mesh", "path": "bad.4off"}}],
            "outputs": {"png": false}}"#,
    )
    .unwrap();
    let out = crate::common::halo4d(&["build", "s.json", "--out", "out", "--quiet"], dir.path());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains(
            "not a manifold: 1 edges in more than two triangles, 1 triangles of zero area"
        ),
        "{stderr}"
    );
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("out/report.json")).unwrap())
            .unwrap();
    assert_eq!(
        report["warnings"].as_array().map(Vec::len),
        Some(1),
        "{report}"
    );
    assert_eq!(report["surfaces"][0]["sampling"]["method"], "file");
}

#[test]
fn a_formula_whose_open_sides_meet_builds_with_a_warning_naming_the_rule_that_glues_them() {
    let grid = r#""sampling": {"method": "uniform", "u": 24, "v": 24},"#;
    let torus = |sides: &str| {
        format!(
            r#"{{"type": "formula", "x": "cos(u)", "y": "sin(u)", "z": "cos(v)", "w": "sin(v)",
                "u": [0, "2*pi"], "v": [0, "2*pi"]{sides}}}"#
        )
    };
    // The flat torus with open sides: u and v both meet point for point.
    let (open, glued, half) = (
        torus(""),
        torus(r#", "sides": {"u": "periodic", "v": "periodic"}"#),
        torus(r#", "sides": {"u": "periodic"}"#),
    );
    let warnings = |surface: &str| {
        let scene = Scene::parse(&scene_json(surface, grid), "own.json").unwrap();
        let built = crate::common::built(&scene).unwrap();
        let dir = tempfile::tempdir().unwrap();
        halo4d::write(&scene, &built, dir.path()).unwrap().warnings
    };
    let w = warnings(&open);
    assert_eq!(w.len(), 2, "{w:?}");
    assert!(
        w[0].contains("u = 0") && w[0].contains(r#""sides": {"u": "periodic"}"#),
        "{w:?}"
    );
    assert!(w[1].contains(r#""sides": {"v": "periodic"}"#), "{w:?}");
    assert!(warnings(&glued).is_empty());
    let w = warnings(&half);
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(w[0].contains(r#"{"v": "periodic"}"#), "{w:?}");
    // A Klein bottle's u sides meet with v reversed: `flip`.
    let klein = r#"{"type": "formula",
        "x": "(1 + 0.5*cos(v))*cos(u)", "y": "(1 + 0.5*cos(v))*sin(u)",
        "z": "0.5*sin(v)*cos(u/2)", "w": "0.5*sin(v)*sin(u/2)",
        "u": [0, "2*pi"], "v": [0, "2*pi"], "sides": {"v": "periodic"}}"#;
    let w = warnings(klein);
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].contains(r#"{"u": "flip"}"#) && w[0].contains("reversed"),
        "{w:?}"
    );
}
