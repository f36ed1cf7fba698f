//! The 4D view: rotation, projection, the Jacobian of the projection, and the eye.

use crate::common::Rng;
use glam::{DVec3, DVec4};
use halo4d::{sample::Mesh4, surfaces::Surface, view::Projection, view::Rotation4, view::View};

fn one_vertex(s: &Surface, u: f64, v: f64) -> Mesh4 {
    let e = s.eval(0, u, v);
    Mesh4 {
        positions: vec![e.p],
        tangent_u: vec![e.du],
        tangent_v: vec![e.dv],
        uv: vec![[u, v]],
        patch: vec![0],
        ..Mesh4::default()
    }
}

fn random_view(rng: &mut Rng, projection: Projection) -> View {
    let mut a = || 360.0 * rng.unit() - 180.0;
    View {
        auto: false,
        rotation: Rotation4 {
            xy: a(),
            xz: a(),
            xw: a(),
            yz: a(),
            yw: a(),
            zw: a(),
        },
        translation: [0.1, -0.2, 0.3, 0.5],
        projection,
    }
}

#[test]
fn rotation_is_orthonormal_and_keeps_w_as_depth() {
    let mut rng = Rng(11);
    for _ in 0..20 {
        let view = random_view(&mut rng, Projection::Orthographic);
        let m = view.rotation.matrix();
        assert!(
            (m.transpose() * m - glam::DMat4::IDENTITY)
                .to_cols_array()
                .iter()
                .all(|x| x.abs() < 1e-14)
        );
        assert!((m.determinant() - 1.0).abs() < 1e-12);
        let p = DVec4::new(0.3, -1.0, 2.0, 0.7);
        let s = Surface::Patches(Default::default());
        let mut mesh = one_vertex(&s, 0.0, 0.0);
        mesh.positions[0] = p;
        let out = view.project(&mesh).unwrap();
        let q = view.transform(p);
        // Stored at f32, the precision of the files.
        assert_eq!(out.w[0], f64::from(q.w as f32));
        assert_eq!(out.positions[0], q.truncate().as_vec3().as_dvec3());
    }
}

#[test]
fn projected_tangents_are_the_jacobian_of_the_projection() {
    // Central differences of the projected surface along u and v against the tangents the
    // view pushes through the Jacobian, in both projections.
    let mut rng = Rng(12);
    let torus = Surface::FlatTorus(Default::default());
    for projection in [
        Projection::Orthographic,
        Projection::Perspective { eye_distance: 3.0 },
    ] {
        for _ in 0..20 {
            let view = random_view(&mut rng, projection);
            let (u, v) = (6.0 * rng.unit(), 6.0 * rng.unit());
            let out = view.project(&one_vertex(&torus, u, v)).unwrap();
            // The exact projection: `project` rounds positions to f32.
            let at = |u: f64, v: f64| {
                let p = view.transform(one_vertex(&torus, u, v).positions[0]);
                view.projection.apply(p).unwrap().0
            };
            let h = 1e-5;
            let fu = (at(u + h, v) - at(u - h, v)) / (2.0 * h);
            let fv = (at(u, v + h) - at(u, v - h)) / (2.0 * h);
            assert!(
                (fu - out.tangent_u[0]).length() < 1e-8,
                "{projection:?}: {fu} vs {}",
                out.tangent_u[0]
            );
            assert!(
                (fv - out.tangent_v[0]).length() < 1e-8,
                "{projection:?}: {fv} vs {}",
                out.tangent_v[0]
            );
        }
    }
}

#[test]
fn perspective_scales_by_eye_distance_over_depth() {
    let s = Surface::Patches(Default::default());
    let mut mesh = one_vertex(&s, 0.0, 0.0);
    mesh.positions[0] = DVec4::new(1.0, 2.0, 3.0, 1.0);
    let view = View {
        projection: Projection::Perspective { eye_distance: 3.0 },
        ..Default::default()
    };
    let out = view.project(&mesh).unwrap();
    assert_eq!(out.positions[0], DVec3::new(0.75, 1.5, 2.25));
    assert_eq!(out.w[0], 1.0);
}

#[test]
fn points_at_or_behind_the_eye_are_errors_not_nans() {
    let s = Surface::Patches(Default::default());
    let view = View {
        projection: Projection::Perspective { eye_distance: 2.0 },
        ..Default::default()
    };
    for w in [-2.0, -2.5, -1e300, f64::NEG_INFINITY] {
        let mut mesh = one_vertex(&s, 0.0, 0.0);
        mesh.positions[0] = DVec4::new(0.1, 0.2, 0.3, w);
        let err = view.project(&mesh).unwrap_err();
        assert!(err.to_string().contains("behind the 4D eye"), "{err}");
    }
    // Through the pipeline the error names the scene and the surface.
    let text = r#"{ "name": "near", "surfaces": [ { "name": "ring", "surface": { "type": "flat_torus" } } ],
        "view": { "translation": [0, 0, 0, -1.5], "projection": { "type": "perspective", "eye_distance": 2 } } }"#;
    let scene = halo4d::Scene::parse(text, "near.json").unwrap();
    let err = crate::common::built(&scene).unwrap_err().to_string();
    assert!(
        err.contains("`ring`") && err.contains("`near`") && err.contains("eye_distance"),
        "{err}"
    );
}

#[test]
fn normals_are_unit_and_fall_back_where_tangents_degenerate() {
    // The spun trefoil has poles where ∂/∂θ = 0: the normal there must still be unit.
    let s = Surface::SpunTrefoil(Default::default());
    let mesh = halo4d::sample::sample_uniform(&s, 40, 16);
    let out = View::default().project(&mesh).unwrap();
    for n in &out.normals {
        assert!((n.length() - 1.0).abs() < 1e-12, "{n}");
    }
}

#[test]
fn the_view_maps_points_and_jets_with_the_exact_derivatives_of_the_projection() {
    // A perspective view of the spun trefoil: the jets' first derivatives are the mapped
    // tangents, and their second derivatives the tangents' own, by central differences.
    let scene = halo4d::Scene::parse(
        r#"{"name": "v", "surfaces": [{"surface": {"type": "spun_trefoil"}}],
            "view": {"rotation": {"xw": 25, "yz": 40, "zw": -15}, "translation": [0.1, 0, 0, 0.3],
                     "projection": {"type": "perspective", "eye_distance": 3.0}}}"#,
        "test",
    )
    .unwrap();
    let surface = scene.surfaces[0].surface.parametric().unwrap();
    let map = scene.view.map();
    let (u, v, h) = (0.7, 1.9, 1e-5);
    let jets = map.jets(&surface.eval(0, u, v)).unwrap();
    let mapped = map.map(&surface.eval(0, u, v)).unwrap();
    let at =
        |f: fn(&halo4d::surfaces::Jet) -> f64| DVec3::new(f(&jets[0]), f(&jets[1]), f(&jets[2]));
    assert!(at(|j| j.v).distance(mapped.position) < 1e-15);
    assert!(at(|j| j.du).distance(mapped.tangents[0]) < 1e-14);
    assert!(at(|j| j.dv).distance(mapped.tangents[1]) < 1e-14);
    assert!((jets[3].v - mapped.w).abs() < 1e-15);
    let tangent =
        |du: f64, dv: f64, k: usize| map.map(&surface.eval(0, u + du, v + dv)).unwrap().tangents[k];
    let duu = (tangent(h, 0.0, 0) - tangent(-h, 0.0, 0)) / (2.0 * h);
    let duv = (tangent(0.0, h, 0) - tangent(0.0, -h, 0)) / (2.0 * h);
    let dvv = (tangent(0.0, h, 1) - tangent(0.0, -h, 1)) / (2.0 * h);
    assert!(
        at(|j| j.duu).distance(duu) < 1e-6,
        "{} {duu}",
        at(|j| j.duu)
    );
    assert!(
        at(|j| j.duv).distance(duv) < 1e-6,
        "{} {duv}",
        at(|j| j.duv)
    );
    assert!(
        at(|j| j.dvv).distance(dvv) < 1e-6,
        "{} {dvv}",
        at(|j| j.dvv)
    );
}
