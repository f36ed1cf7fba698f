//! Double curves certified on the true surfaces: exact answers where the crossing is known
//! (a plane and a sphere dipping below it by ε, a paraboloid's small loop against a plane,
//! the flat torus's cross-caps), a tangency left undecided and named, the same answer on
//! any number of threads, and a build whose mesh misses a certified curve refused.

use crate::common::{halo4d, on_threads};
use halo4d::Scene;
use halo4d::intersect::certified::{Certificate, ComponentKind, Reason, certify, certify_within};
use serde_json::json;

/// A plane z = 0 and a unit sphere whose lowest point lies `dip` below it (poles on the x
/// axis, so that the lowest point (u, v) = (π/2, 3π/2 - 0.1) is inside the parameter
/// rectangle), on a uniform grid of `cells` (even) whose vertices miss the lowest point.
fn plane_and_sphere(dip: f64, cells: usize, certify: bool) -> serde_json::Value {
    let mut scene = plane_and_sphere_sampled(dip, certify);
    scene["sampling"] = json!({ "method": "uniform", "u": cells, "v": cells });
    scene
}

/// [`plane_and_sphere`] sampled adaptively at 1e-3 of each surface's diagonal.
fn plane_and_sphere_sampled(dip: f64, certify: bool) -> serde_json::Value {
    json!({
        "name": "plane-sphere",
        "surfaces": [
            { "name": "plane", "surface": { "type": "formula", "x": "u", "y": "v", "z": "0", "w": "0",
                "u": [-1.3, 1.7], "v": [-1.6, 1.4] } },
            { "name": "sphere", "surface": { "type": "formula",
                "x": "cos(u)", "y": "sin(u)*cos(v + 0.1)", "z": "sin(u)*sin(v + 0.1) + 1 - dip", "w": "0",
                "u": [0, "pi"], "v": [0, "2*pi"],
                "sides": { "u_min": "pole", "u_max": "pole", "v": "periodic" },
                "parameters": { "dip": dip } } }
        ],
        "sampling": { "method": "adaptive", "tolerance": 1e-3 },
        "view": { "rotation": {}, "projection": { "type": "orthographic" } },
        "curves": { "certify": certify },
        "outputs": { "glb": true, "ply": false, "obj": false, "report": true, "png": false }
    })
}

fn certificate(scene: &serde_json::Value) -> Certificate {
    let scene: Scene = serde_json::from_value(scene.clone()).unwrap();
    let surfaces: Vec<_> = scene
        .surfaces
        .iter()
        .map(|s| s.surface.parametric())
        .collect();
    certify(&surfaces, &scene.view)
}

#[test]
fn a_plane_and_a_sphere_dipping_below_it_cross_in_the_circle_of_its_radius() {
    for dip in [1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8] {
        let c = certificate(&plane_and_sphere(dip, 22, true));
        assert!(c.complete, "dip {dip}: {}", c.summary());
        assert_eq!((c.closed, c.open, c.unfinished), (1, 0, 0), "dip {dip}");
        assert_eq!(c.branch_points, Some(0), "dip {dip}");
        // Every certified point is on the circle of radius √(2ε - ε²) in the plane.
        let radius = (2.0 * dip - dip * dip).sqrt();
        let circle = &c.components[0];
        assert_eq!(circle.kind, ComponentKind::Closed);
        assert!(
            circle.points.len() >= 6,
            "dip {dip}: {} points",
            circle.points.len()
        );
        for p in &circle.points {
            let r = (p[0] * p[0] + p[1] * p[1]).sqrt();
            let tolerance = 4.0 * circle.width + 1e-12;
            assert!(
                (r - radius).abs() <= tolerance,
                "dip {dip}: r {r} against {radius}"
            );
            assert!(p[2].abs() <= tolerance, "dip {dip}: z {}", p[2]);
        }
    }
}

#[test]
fn a_sphere_above_the_plane_has_no_double_curve_and_says_so() {
    let c = certificate(&plane_and_sphere(-1e-6, 22, true));
    assert!(c.complete, "{}", c.summary());
    assert_eq!((c.closed, c.open, c.undecided), (0, 0, 0));
}

#[test]
fn a_sphere_exactly_tangent_is_undecided_at_the_tangency_not_certified() {
    let c = certificate(&plane_and_sphere(0.0, 22, true));
    assert!(!c.complete);
    assert_eq!((c.closed, c.open), (0, 0));
    let tangency = c
        .regions
        .iter()
        .find(|r| r.reason == Reason::Tangency)
        .unwrap_or_else(|| panic!("no tangency named: {}", c.summary()));
    // At the plane's origin and the sphere's lowest point (u, v) = (π/2, 3π/2 - 0.1).
    let holds = |r: [f64; 2], x: f64| r[0] - 1e-6 <= x && x <= r[1] + 1e-6;
    assert_eq!(tangency.surfaces, [0, 1]);
    assert!(
        holds(tangency.p[0], 0.0) && holds(tangency.p[1], 0.0),
        "{tangency}"
    );
    let (pi2, pi32) = (
        std::f64::consts::FRAC_PI_2,
        1.5 * std::f64::consts::PI - 0.1,
    );
    assert!(
        holds(tangency.q[0], pi2) && holds(tangency.q[1], pi32),
        "{tangency}"
    );
    assert!(tangency.to_string().starts_with("a tangency"), "{tangency}");
}

#[test]
fn a_loop_of_double_curve_smaller_than_the_triangles_is_found() {
    // A paraboloid cap z = h - k (x² + y²) crossing the plane z = 0 in a circle of radius
    // √(h / k) = 0.01, on triangles 0.2 across.
    let scene = json!({
        "name": "small-loop",
        "surfaces": [
            { "name": "plane", "surface": { "type": "formula", "x": "u", "y": "v", "z": "0", "w": "0",
                "u": [-1, 1], "v": [-1, 1] } },
            { "name": "cap", "surface": { "type": "formula", "x": "u", "y": "v",
                "z": "0.001 - 10*(u*u + v*v)", "w": "1", "u": [-0.9, 1.1], "v": [-1.1, 0.9] } }
        ],
        "sampling": { "method": "uniform", "u": 10, "v": 10 },
        "view": { "rotation": {}, "projection": { "type": "orthographic" } }
    });
    let c = certificate(&scene);
    assert!(c.complete, "{}", c.summary());
    assert_eq!((c.closed, c.open), (1, 0));
    for p in &c.components[0].points {
        let r = (p[0] * p[0] + p[1] * p[1]).sqrt();
        assert!((r - 0.01).abs() < 1e-9, "r {r}");
    }
}

/// The certificate of the flat-torus fixture within `budget` enclosures.
fn flat_torus(budget: usize) -> Certificate {
    let scene = Scene::load(&crate::common::fixture("scenes/flat-torus.json")).unwrap();
    let surfaces: Vec<_> = scene
        .surfaces
        .iter()
        .map(|s| s.surface.parametric())
        .collect();
    certify_within(&surfaces, &scene.view, budget)
}

#[test]
fn the_flat_torus_has_its_four_cross_caps_proven_where_the_mathematics_puts_them() {
    // f = (cos u, cos θ sin u - sin θ sin v, cos v) in the yw view θ: f_u = (-sin u,
    // cos θ cos u, 0) and f_v = (0, -sin θ cos v, -sin v) are parallel exactly where
    // sin u = sin v = 0: four cross-caps at u, v in {0, π}.
    let c = flat_torus(halo4d::intersect::certified::BUDGET);
    assert_eq!(c.branch_points, Some(4), "{}", c.summary());
    let pi = std::f64::consts::PI;
    let on = |x: f64| [0.0, pi, 2.0 * pi].iter().any(|k| (x - k).abs() < 1e-9);
    for b in &c.branch_point_list {
        assert!(on(b.uv[0]) && on(b.uv[1]), "{b:?}");
        assert!(b.width < 1e-6, "{b:?}");
    }
    // The two arcs between them are found; their ends at the cross-caps are not certified.
    assert_eq!(c.components.len(), 2, "{}", c.summary());
    assert!(!c.complete);
    assert!(
        c.regions
            .iter()
            .all(|r| matches!(r.reason, Reason::BranchPoint | Reason::RankDrop))
    );
}

#[test]
fn the_certificate_does_not_depend_on_the_number_of_threads() {
    let scene = plane_and_sphere(1e-4, 22, true);
    let one = on_threads(1, || certificate(&scene));
    let two = on_threads(2, || certificate(&scene));
    let strip = |c: Certificate| Certificate { ms: 0.0, ..c };
    assert_eq!(strip(one), strip(two));
}

#[test]
fn a_build_whose_mesh_misses_a_certified_curve_is_not_verified_and_check_agrees() {
    let dir = tempfile::tempdir().unwrap();
    // 2e-4 below the plane: a circle of radius 0.02 that the 22 × 22 grid's chords miss.
    std::fs::write(
        dir.path().join("s.json"),
        plane_and_sphere(2e-4, 22, true).to_string(),
    )
    .unwrap();
    let out = halo4d(&["build", "s.json", "--out", "o", "-q"], dir.path());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{stderr}");
    assert!(
        stderr.contains("the true surfaces cross in 1 closed and 0 open curves (certified), the meshes in 0 closed and 0 open"),
        "{stderr}"
    );
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("o/report.json")).unwrap()).unwrap();
    let certified = &report["curves"]["certified"];
    assert_eq!(certified["complete"], true);
    assert_eq!(certified["closed"], 1);
    assert_eq!(report["curves"]["count"], 0);
    assert!(report["timings_ms"]["certify"].as_f64().unwrap() > 0.0);
    // check re-derives the certificate from the scene the file records.
    let out = halo4d(&["check", "o"], dir.path());
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_ne!(out.status.code(), Some(0), "{stdout}");
    assert!(
        stdout.contains("the true surfaces cross in 1 closed"),
        "{stdout}"
    );
    // Without the certificate the same build passes: the mesh alone cannot see the curve.
    std::fs::write(
        dir.path().join("s.json"),
        plane_and_sphere(2e-4, 22, false).to_string(),
    )
    .unwrap();
    let out = halo4d(&["build", "s.json", "--out", "p", "-q"], dir.path());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn an_adaptive_build_samples_finer_around_a_certified_loop_until_its_mesh_has_it() {
    // The sampler's triangles at 1e-3 of the sphere's diagonal may lie 3.5e-3 off it: at a
    // dip of 1e-6 and below, the mesh of the sphere stays above the plane and its curves
    // miss the circle. Held to the certificate, the build samples finer around the circle
    // until its mesh crosses the plane there; the refined curve is the true circle.
    for dip in [1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8] {
        let scene: Scene = serde_json::from_value(plane_and_sphere_sampled(dip, true)).unwrap();
        let built = halo4d::Sampled::of(&scene)
            .build(&scene, halo4d::Stages::of(&scene))
            .unwrap();
        assert!(
            built.failures().is_empty(),
            "dip {dip}: {:?}",
            built.failures()
        );
        let report = &built.curves.report;
        assert_eq!((report.closed, report.open), (1, 0), "dip {dip}");
        let radius = (2.0 * dip - dip * dip).sqrt();
        let circle = &built.shown_curves().curves[0];
        assert!(circle.closed);
        for p in &circle.points {
            let r = p.position.x.hypot(p.position.y);
            // A point off the circle by δ in z is off by δ / R in r near the sphere's bottom.
            assert!(
                (r - radius).abs() <= 1e-14 / radius + 1e-12,
                "dip {dip}: r {r} against {radius}"
            );
            assert!(p.position.z.abs() <= 1e-12, "dip {dip}: z {}", p.position.z);
        }
        if dip <= 1e-6 {
            assert!(
                report.sampled_finer > 0,
                "dip {dip}: no round of sampling finer"
            );
            // Planted: the same build without the certificate misses the circle.
            let plain: Scene =
                serde_json::from_value(plane_and_sphere_sampled(dip, false)).unwrap();
            let built = halo4d::Sampled::of(&plain)
                .build(&plain, halo4d::Stages::of(&plain))
                .unwrap();
            assert_eq!(built.curves.report.count, 0, "dip {dip}");
        }
    }
}

#[test]
fn a_budget_that_runs_out_claims_no_count() {
    // Planted: the flat torus's certificate cut short leaves regions undecided, and then
    // neither its curves nor its branch points are counted as proven.
    let c = flat_torus(2_000);
    assert!(!c.complete);
    assert_eq!(c.branch_points, None, "{}", c.summary());
    assert!(
        c.regions.iter().any(|r| r.reason == Reason::Budget),
        "{}",
        c.summary()
    );
    assert!(c.undecided > 0);
}
