//! Curves on the true surfaces: the refined curves of the oblique flat torus against the
//! analytic double curve and its four cross-caps, every fixture's residuals, the Roman
//! surface's triple point, and the mesh curves kept for the verification.

use crate::common::{fixture, fixture_scenes};
use glam::DVec3;
use halo4d::sample::sample_uniform;
use halo4d::{
    Scene, intersect::Analytic, intersect::Curves, intersect::End, intersect::Sheet,
    intersect::curves, intersect::refine, sample::Mesh4, view::Projected,
};

/// The mesh curves and the refined ones of one surface in its scene's view.
fn refined(scene: &Scene, mesh: &Mesh4) -> (Curves, Curves) {
    let p: Projected = scene.view.project(mesh).unwrap();
    let sheets = [Sheet {
        positions: &p.positions,
        w: &p.w,
        triangles: &mesh.triangles,
    }];
    let (lo, hi) = p.bounds().unwrap();
    let analytic = [Analytic {
        surface: scene.surfaces[0].surface.parametric(),
        mesh,
    }];
    let mesh_curves = curves(&sheets);
    let refined = refine(
        &mesh_curves,
        &sheets,
        &analytic,
        &scene.view,
        (hi - lo).length(),
    );
    (mesh_curves, refined)
}

fn torus_scene(alpha: f64) -> Scene {
    let text = format!(
        r#"{{"name": "t", "surfaces": [{{"surface": {{"type": "flat_torus"}}}}],
            "view": {{"rotation": {{"yw": {alpha}}}}}}}"#
    );
    Scene::parse(&text, "test").unwrap()
}

/// The distance from `p` to the turned flat torus's double curve: the plane y = 0 with
/// 1 - z^2 = cot^2(alpha) (1 - x^2), the implicit function to first order, exact to far
/// below 1e-10 this near it.
fn analytic_distance(p: DVec3, alpha: f64) -> f64 {
    let c2 = (1.0 / alpha.to_radians().tan()).powi(2);
    let f = 1.0 - p.z * p.z - c2 * (1.0 - p.x * p.x);
    let grad = (2.0 * c2 * p.x).hypot(-2.0 * p.z);
    p.y.hypot(f / grad)
}

/// Checks the refined curves of the flat torus turned by `alpha`: every point on the
/// analytic curve to 1e-10 with the analytic w of both sheets, every curve end at one of
/// the four cross-caps (+-1, 0, +-1) to 1e-12; returns the largest distance of a mesh
/// point from the curve.
fn check_torus(alpha: f64, mesh_curves: &Curves, refined: &Curves, what: &str) -> f64 {
    let r = refined.report.refinement.as_ref().unwrap();
    assert_eq!(r.not_converged, 0, "{what}: {r:?}");
    assert_eq!(r.cross_caps, 4, "{what}: {r:?}");
    assert_eq!(refined.curves.len(), 2, "{what}");
    for c in &refined.curves {
        assert_eq!(c.ends, [End::BranchPoint; 2], "{what}");
        for e in [c.points[0].position, c.points[c.points.len() - 1].position] {
            let off = [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)]
                .iter()
                .map(|&(x, z)| e.distance(DVec3::new(x, 0.0, z)))
                .fold(f64::INFINITY, f64::min);
            assert!(off < 1e-12, "{what}: end {e} is {off:e} from a cross-cap");
        }
        for p in &c.points {
            let d = analytic_distance(p.position, alpha);
            assert!(
                d < 1e-10,
                "{what}: refined point {} is {d:e} off",
                p.position
            );
            // The two sheets' w: +-sqrt(1 - x^2) / sin(alpha), opposite.
            let w = (1.0 - p.position.x.powi(2)).max(0.0).sqrt() / alpha.to_radians().sin();
            assert!((p.w[0] + p.w[1]).abs() < 1e-10, "{what}: {:?}", p.w);
            assert!(
                (p.w[0].abs() - w).abs() < 1e-9,
                "{what}: {:?} against {w}",
                p.w
            );
        }
    }
    let mesh_worst = mesh_curves
        .curves
        .iter()
        .flat_map(|c| &c.points)
        .map(|p| analytic_distance(p.position, alpha))
        .fold(0.0, f64::max);
    assert!(r.max_residual < 1e-14, "{what}: {r:?}");
    mesh_worst
}

#[test]
fn refined_flat_torus_curves_lie_on_the_analytic_curve_at_every_grid_and_angle() {
    for alpha in [20.0, 30.0, 60.0, 75.0] {
        let scene = torus_scene(alpha);
        let mut previous = f64::INFINITY;
        for n in [24, 48, 96, 192] {
            let mesh = sample_uniform(scene.surfaces[0].surface.parametric().unwrap(), n, n);
            let (mesh_curves, refined) = refined(&scene, &mesh);
            let what = format!("alpha {alpha}, {n} x {n}");
            let mesh_error = check_torus(alpha, &mesh_curves, &refined, &what);
            // Every point refined, none dropped: the grid has the cross-caps as vertices.
            let r = refined.report.refinement.as_ref().unwrap();
            assert_eq!(r.trimmed, 0, "{what}: {r:?}");
            assert_eq!(r.refined, mesh_curves.report.points, "{what}: {r:?}");
            assert!(r.max_cross_cap_shift < 1e-12, "{what}: {r:?}");
            // The shift is a distance to the curve in a plane across it: at least the
            // distance to the curve (to first order), which it measures.
            assert!(
                r.max_shift >= 0.95 * mesh_error && r.max_shift < 2.0 * mesh_error,
                "{what}: shift {:e}, mesh error {mesh_error:e}",
                r.max_shift
            );
            // The mesh's error falls with the grid; the refined curve's does not grow.
            assert!(
                mesh_error < previous,
                "{what}: {mesh_error:e} after {previous:e}"
            );
            previous = mesh_error;
        }
    }
}

#[test]
fn refined_flat_torus_curves_of_adaptive_meshes_end_at_the_true_cross_caps() {
    let scene = torus_scene(30.0);
    for tolerance in [1e-2, 1e-3, 1e-4] {
        let sampled = scene.surfaces[0]
            .surface
            .sample(&halo4d::sample::Sampling::adaptive(tolerance));
        let (mesh_curves, refined) = refined(&scene, &sampled.mesh);
        check_torus(
            30.0,
            &mesh_curves,
            &refined,
            &format!("tolerance {tolerance}"),
        );
    }
}

fn points_of(c: &Curves) -> usize {
    c.curves.iter().map(|c| c.points.len()).sum()
}

#[test]
fn every_fixture_refines_to_rounding_and_keeps_its_curves() {
    for path in fixture_scenes() {
        let scene = Scene::load(&path).unwrap();
        let built = crate::common::built(&scene).unwrap();
        let what = path.display().to_string();
        let (Some(refined), mesh) = (&built.refined, &built.curves) else {
            panic!("{what}: no refined curves");
        };
        let r = refined.report.refinement.as_ref().unwrap();
        if r.on_meshes > 0 {
            // A mesh file is the surface: its curve points are kept as they are.
            assert_eq!((r.refined, r.on_meshes), (0, points_of(mesh)), "{what}");
            continue;
        }
        assert!(
            r.max_residual < 1e-12 * built.diagonal,
            "{what}: residual {:e} of a diagonal {}",
            r.max_residual,
            built.diagonal
        );
        // Point for point the mesh's curves, but for the points dropped beyond a cross-cap.
        assert_eq!(refined.curves.len(), mesh.curves.len(), "{what}");
        let points = |c: &Curves| c.curves.iter().map(|c| c.points.len()).sum::<usize>();
        assert_eq!(points(refined) + r.trimmed, points(mesh), "{what}");
        assert_eq!(
            r.refined + r.not_converged + r.trimmed + r.pole_ends,
            points(mesh),
            "{what}: {r:?}"
        );
        // Most points refine; those that do not are the cases the README lists.
        assert!(r.not_converged * 20 <= points(mesh), "{what}: {r:?}");
        // The verification checked the halos against the mesh's curves, the files show
        // the refined ones.
        assert!(std::ptr::eq(built.shown_curves(), refined), "{what}");
        for (a, b) in refined.curves.iter().zip(&mesh.curves) {
            assert_eq!((a.closed, a.ends), (b.closed, b.ends), "{what}");
        }
    }
}

#[test]
fn without_refinement_the_files_show_the_mesh_curves() {
    let mut scene = Scene::load(&fixture("scenes/flat-torus.json")).unwrap();
    scene.curves.refine = false;
    let built = crate::common::built(&scene).unwrap();
    assert!(built.refined.is_none());
    assert!(std::ptr::eq(built.shown_curves(), &built.curves));
    assert!(built.curves.report.refinement.is_none());
}

#[test]
fn the_roman_surface_refines_to_its_axes_six_cross_caps_and_one_triple_point() {
    // The projective plane (xy, xz, y^2 - z^2, 2yz) of the unit sphere, turned 90 degrees
    // in zw, projects to Steiner's Roman surface (xy, xz, -2yz): its double curves are
    // three segments of the axes, ending at six cross-caps (+-1/2, 0, 0), (0, +-1/2, 0),
    // (0, 0, +-1), and crossing at the origin, a triple point whose three sheets have
    // w = y^2 - z^2 = 0, 1 and -1.
    let scene = Scene::parse(
        r#"{"name": "roman", "surfaces": [{"surface": {"type": "projective_plane"}}],
            "sampling": {"method": "uniform", "u": 20, "v": 38},
            "view": {"rotation": {"zw": 90}}}"#,
        "test",
    )
    .unwrap();
    let sampled = scene.surfaces[0].surface.sample(&scene.sampling);
    let (mesh_curves, refined) = refined(&scene, &sampled.mesh);
    let r = refined.report.refinement.as_ref().unwrap();
    assert_eq!((r.not_converged, r.cross_caps), (0, 6), "{r:?}");
    assert_eq!(mesh_curves.report.triple_points, 1);
    let mut caps = Vec::new();
    for c in &refined.curves {
        for p in &c.points {
            let zeros = p
                .position
                .to_array()
                .iter()
                .filter(|v| v.abs() < 1e-12)
                .count();
            assert!(zeros >= 2, "{} is on no axis", p.position);
        }
        caps.extend([c.points[0].position, c.points[c.points.len() - 1].position]);
    }
    for cap in [
        DVec3::X * 0.5,
        DVec3::X * -0.5,
        DVec3::Y * 0.5,
        DVec3::Y * -0.5,
        DVec3::Z,
        -DVec3::Z,
    ] {
        let off = caps
            .iter()
            .map(|c| c.distance(cap))
            .fold(f64::INFINITY, f64::min);
        assert!(off < 1e-12, "cross-cap {cap} missed by {off:e}");
    }
    // A v grid of 38 cells has no vertex at phi = pi/2: the mesh's sheet there, and its w
    // at the triple point, are off (the place itself is on the axes by symmetry).
    let mesh_w = mesh_curves.triple_points[0].w;
    assert!(
        mesh_w.iter().any(|w| (w.abs() - 1.0).abs() > 1e-3),
        "{mesh_w:?}"
    );
    assert_eq!(refined.triple_points.len(), 1);
    let t = refined.triple_points[0];
    assert!(t.position.length() < 1e-12, "{}", t.position);
    let mut w = t.w;
    w.sort_by(f64::total_cmp);
    for (got, want) in w.iter().zip([-1.0, 0.0, 1.0]) {
        assert!((got - want).abs() < 1e-12, "{w:?}");
    }
}

#[test]
fn the_curves_ply_keeps_the_refined_points_on_the_analytic_curve() {
    // Written as double, the curve points a reader gets are the refined ones, on the true
    // double curve of the turned flat torus to rounding (as f32 they were 4e-8 off).
    let dir = tempfile::tempdir().unwrap();
    for alpha in [47.0, 71.0] {
        let mut scene = torus_scene(alpha);
        scene.outputs = serde_json::from_str(
            r#"{"glb": false, "ply": true, "vtk": false, "png": false, "report": false}"#,
        )
        .unwrap();
        let built = crate::common::built(&scene).unwrap();
        halo4d::write(&scene, &built, dir.path()).unwrap();
        let bytes = std::fs::read(dir.path().join("t-curves.ply")).unwrap();
        let parser = ply_rs::parser::Parser::<ply_rs::ply::DefaultElement>::new();
        let ply = parser.read_ply(&mut bytes.as_slice()).unwrap();
        let vertices = &ply.payload["vertex"];
        assert!(vertices.len() > 100, "{alpha}: {} points", vertices.len());
        let worst = vertices
            .iter()
            .map(|v| {
                let [x, y, z] = ["x", "y", "z"].map(|k| match v[k] {
                    ply_rs::ply::Property::Double(x) => x,
                    ref other => panic!("{k} is {other:?}, not a double"),
                });
                analytic_distance(DVec3::new(x, y, z), alpha)
            })
            .fold(0.0, f64::max);
        assert!(
            worst < 1e-12,
            "{alpha}°: a point {worst:e} off the analytic curve"
        );
    }
}
