//! Critical points of a height function on the surfaces: exact levels on the flat torus,
//! the Morse count on every closed catalogue surface, degenerate directions named.

use glam::{DMat4, DVec4};
use halo4d::motion::{
    Event, Shape, critical_points, hyperplane_frame, motion_picture, slice, tilt, view_direction,
};
use halo4d::sample::{bounding_diagonal, sample_adaptive, sample_uniform};
use halo4d::surfaces::{
    FlatTorus, KleinBottle, ProjectivePlane, SpunTrefoil, Surface, TwistSpunTrefoil,
};

/// A direction in no special position with respect to any catalogue surface.
fn generic() -> DVec4 {
    DVec4::new(1.0, 0.3, 0.7, 0.2)
}

#[test]
fn the_flat_torus_has_its_four_critical_points_at_their_exact_levels() {
    // h = a cos u + b sin u + c cos v + d sin v (unit radii): critical where both
    // circles' parts are, at ±|(a, b)| ± |(c, d)|: one minimum, two saddles, one maximum.
    let surface = Surface::FlatTorus(FlatTorus::default());
    let mesh = sample_uniform(&surface, 48, 48);
    let found = critical_points(&mesh, Some(&surface), generic()).unwrap();
    let n = generic().normalize();
    let (a, c) = (n.x.hypot(n.y), n.z.hypot(n.w));
    let expected = [
        (Event::Birth, -a - c),
        (Event::Saddle, -a + c),
        (Event::Saddle, a - c),
        (Event::Death, a + c),
    ];
    let got: Vec<(Event, f64)> = found.points.iter().map(|p| (p.event, p.level)).collect();
    assert_eq!(got.len(), 4, "{got:?}");
    let mut expected = expected.to_vec();
    expected.sort_by(|x, y| x.1.total_cmp(&y.1));
    for ((e, level), (want, want_level)) in got.iter().zip(&expected) {
        assert_eq!(e, want, "{got:?}");
        assert!(
            (level - want_level).abs() <= 1e-12,
            "{level} against {want_level}"
        );
    }
    assert!(
        found
            .points
            .iter()
            .all(|p| p.refined && p.residual <= 1e-10)
    );
    assert_eq!(found.counts(), [1, 2, 1, 0]);
    assert_eq!(found.morse(0), Ok(()));
    // The count the check takes is the surface's: a wrong characteristic fails.
    assert!(
        found
            .morse(2)
            .unwrap_err()
            .contains("not the Euler characteristic 2")
    );
    // The mesh's own critical vertices add up to its Euler characteristic, 0.
    let d = found.discrete;
    assert_eq!(d.minima as i64 - d.saddles as i64 + d.maxima as i64, 0);
}

#[test]
fn a_direction_with_critical_circles_is_named_degenerate() {
    // h = sin v along w: its maxima and minima are whole circles v = ±π/2.
    let surface = Surface::FlatTorus(FlatTorus::default());
    let mesh = sample_uniform(&surface, 32, 32);
    let found = critical_points(&mesh, Some(&surface), DVec4::W).unwrap();
    assert!(found.counts()[3] > 0, "{:?}", found.counts());
    let err = found.morse(0).unwrap_err();
    assert!(err.contains("degenerate") && err.contains("tilt"), "{err}");
}

#[test]
fn every_closed_catalogue_surface_passes_the_morse_count() {
    let surfaces = [
        (Surface::SpunTrefoil(SpunTrefoil::default()), 2),
        (Surface::TwistSpunTrefoil(TwistSpunTrefoil::default()), 2),
        (Surface::KleinBottle(KleinBottle::default()), 0),
        (Surface::ProjectivePlane(ProjectivePlane::default()), 1),
        (Surface::FlatTorus(FlatTorus::default()), 0),
    ];
    for (surface, euler) in surfaces {
        let d = bounding_diagonal(&surface);
        let mesh = sample_adaptive(&surface, 1e-3 * d, 2_000_000).mesh;
        for n in [generic(), DVec4::new(-0.2, 0.9, 0.1, -0.4)] {
            let found = critical_points(&mesh, Some(&surface), n).unwrap();
            let what = format!("{} along {n}: {:?}", surface.type_name(), found.points);
            assert_eq!(found.morse(euler), Ok(()), "{what}");
            // A saddle missed is seen.
            let mut missing = found.clone();
            let saddle = missing.points.iter().position(|p| p.event == Event::Saddle);
            missing.points.remove(saddle.expect("a saddle"));
            assert!(missing.morse(euler).is_err(), "{what}");
            assert!(found.points.iter().all(|p| p.residual <= 1e-10), "{what}");
            // Each point is where h is: its level is h at its 4D point.
            for p in &found.points {
                assert!(
                    (p.level - p.point.dot(found.direction)).abs() <= 1e-12,
                    "{what}"
                );
            }
        }
    }
}

#[test]
fn a_mesh_without_parameters_keeps_its_critical_vertices() {
    // A tetrahedron's boundary in 4D: the highest and lowest vertices are the maximum and
    // minimum, the other two regular; nothing is refined.
    let mesh = halo4d::sample::mesh_from_data(halo4d::sample::MeshData4 {
        positions: vec![
            DVec4::new(0.0, 0.0, 0.0, 0.0),
            DVec4::new(1.0, 0.0, 0.0, 0.1),
            DVec4::new(0.0, 1.0, 0.0, 0.2),
            DVec4::new(0.0, 0.0, 1.0, 0.3),
        ],
        triangles: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    });
    let found = critical_points(&mesh, None, DVec4::W).unwrap();
    assert_eq!(found.counts(), [1, 0, 1, 0]);
    assert_eq!(
        found.points.iter().map(|p| p.vertex).collect::<Vec<_>>(),
        [0, 3]
    );
    assert!(found.points.iter().all(|p| !p.refined));
    assert_eq!(found.morse(2), Ok(()));
    // As a `.glb` reads back: positions and triangles, no parameters at all.
    let bare = halo4d::sample::Mesh4 {
        positions: mesh.positions.clone(),
        triangles: mesh.triangles.clone(),
        ..Default::default()
    };
    assert_eq!(critical_points(&bare, None, DVec4::W).unwrap(), found);
    assert_eq!(
        halo4d::motion::slice(&bare, None, DVec4::W, 0.15),
        halo4d::motion::slice(&mesh, None, DVec4::W, 0.15)
    );
}

#[test]
fn a_direction_that_is_zero_or_not_finite_is_refused() {
    let surface = Surface::FlatTorus(FlatTorus::default());
    let mesh = sample_uniform(&surface, 8, 8);
    for n in [
        DVec4::ZERO,
        DVec4::new(f64::NAN, 0.0, 0.0, 1.0),
        DVec4::splat(1e300),
    ] {
        let err = critical_points(&mesh, Some(&surface), n).unwrap_err();
        assert_eq!(err.field, "direction");
        assert!(
            err.message.contains("nonzero, finite 4D vector"),
            "{}",
            err.message
        );
    }
}

#[test]
fn the_flat_torus_slices_have_the_components_its_critical_points_say() {
    // Between the minimum and the first saddle the slice is one circle, between the saddles
    // two, then one again, and nothing outside; at every level a closed mesh's slice is
    // closed curves, each point on the hyperplane.
    let surface = Surface::FlatTorus(FlatTorus::default());
    let mesh = sample_uniform(&surface, 64, 64);
    let found = critical_points(&mesh, Some(&surface), generic()).unwrap();
    let n = found.direction;
    let levels: Vec<f64> = found.points.iter().map(|p| p.level).collect();
    let components = |c: f64| {
        let cut = slice(&mesh, Some(&surface), n, c);
        assert_eq!(cut.not_converged, 0);
        assert!(cut.max_residual <= 1e-14, "{}", cut.max_residual);
        for curve in &cut.curves {
            assert!(curve.closed);
            for p in &curve.points {
                // On the hyperplane, and on the torus |(x, y)| = |(z, w)| = 1.
                assert!((p.dot(n) - c).abs() <= 1e-14);
                assert!(
                    (p.x.hypot(p.y) - 1.0).abs() <= 1e-14 && (p.z.hypot(p.w) - 1.0).abs() <= 1e-14
                );
            }
        }
        // The mesh's own slice has the same curves, its points on the mesh.
        let on_mesh = slice(&mesh, None, n, c);
        assert_eq!(on_mesh.curves.len(), cut.curves.len());
        assert_eq!(on_mesh.max_residual, 0.0);
        cut.curves.len()
    };
    assert_eq!(components(levels[0] - 0.1), 0);
    assert_eq!(components(levels[3] + 0.1), 0);
    for (k, want) in [1, 2, 1].into_iter().enumerate() {
        let (lo, hi) = (levels[k], levels[k + 1]);
        for share in [0.25, 0.5, 0.75] {
            assert_eq!(
                components(lo + (hi - lo) * share),
                want,
                "between {lo} and {hi}"
            );
        }
    }
}

#[test]
fn across_each_critical_level_the_components_change_as_its_event_says() {
    // A birth adds a component, a death removes one, a saddle joins two or splits one
    // (or, on a non-orientable surface, may keep the count), on the knotted spheres and
    // the Klein bottle.
    for (surface, orientable) in [
        (Surface::SpunTrefoil(SpunTrefoil::default()), true),
        (Surface::TwistSpunTrefoil(TwistSpunTrefoil::default()), true),
        (Surface::KleinBottle(KleinBottle::default()), false),
    ] {
        let d = bounding_diagonal(&surface);
        let mesh = sample_adaptive(&surface, 1e-4 * d, 2_000_000).mesh;
        let found = critical_points(&mesh, Some(&surface), generic()).unwrap();
        assert!(found.not_converged.is_empty(), "{}", surface.type_name());
        let n = found.direction;
        // The mesh's slice changes where its critical vertices are (the refined levels lie
        // near them, not at them): the intervals are taken between the vertices' levels.
        let mut points: Vec<(f64, Event)> = found
            .points
            .iter()
            .map(|p| (mesh.positions[p.vertex as usize].dot(n), p.event))
            .collect();
        points.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut below = 0;
        for (k, &(level, event)) in points.iter().enumerate() {
            let above_level = points
                .get(k + 1)
                .map_or(level + 1.0, |&(next, _)| (level + next) / 2.0);
            let cut = slice(&mesh, Some(&surface), n, above_level);
            // Near a critical level the mesh's slice can hold a small loop that the
            // surface's does not yet (or no longer) have: such points stay on the mesh.
            let points: usize = cut.curves.iter().map(|c| c.points.len()).sum();
            assert!(cut.not_converged * 100 <= points, "{}", surface.type_name());
            assert!(cut.max_residual <= 1e-14, "{}", surface.type_name());
            let above = cut.curves.len() as i64;
            let change = above - below;
            let what = format!(
                "{} at {level} ({event:?}): {below} then {above}",
                surface.type_name()
            );
            match event {
                Event::Birth => assert_eq!(change, 1, "{what}"),
                Event::Death => assert_eq!(change, -1, "{what}"),
                Event::Saddle if orientable => assert_eq!(change.abs(), 1, "{what}"),
                Event::Saddle => assert!(change.abs() <= 1, "{what}"),
                Event::Degenerate => panic!("{what}"),
            }
            below = above;
        }
        assert_eq!(
            below,
            0,
            "{}: nothing above the highest point",
            surface.type_name()
        );
    }
}

/// Two directions from a seed, in no special position (SplitMix64 numbers in [-1, 1)).
fn seeded(seed: u64) -> [DVec4; 2] {
    let mut state = seed;
    let mut next = || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        2.0 * ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64 - 1.0
    };
    [0, 1].map(|_| DVec4::new(next(), next(), next(), next()))
}

#[test]
fn every_closed_catalogue_surface_has_a_motion_picture_that_passes_its_checks() {
    // In two seeded directions each: the Morse count is χ, and across every critical level
    // the components change as its event says; a wrong χ is caught.
    for (k, (surface, euler, orientable)) in [
        (Surface::SpunTrefoil(SpunTrefoil::default()), 2, true),
        (
            Surface::TwistSpunTrefoil(TwistSpunTrefoil::default()),
            2,
            true,
        ),
        (Surface::KleinBottle(KleinBottle::default()), 0, false),
        (
            Surface::ProjectivePlane(ProjectivePlane::default()),
            1,
            false,
        ),
        (Surface::FlatTorus(FlatTorus::default()), 0, true),
    ]
    .into_iter()
    .enumerate()
    {
        let d = bounding_diagonal(&surface);
        let mesh = sample_adaptive(&surface, 2.5e-4 * d, 4_000_000).mesh;
        for n in seeded(k as u64 + 40) {
            let n = n.normalize();
            let frame = hyperplane_frame(DMat4::IDENTITY, n);
            let shape = Shape {
                euler: Some(euler),
                orientable,
            };
            let what = format!("{} along {n}", surface.type_name());
            let picture = motion_picture(&mesh, Some(&surface), n, frame, shape, 3).unwrap();
            assert_eq!(picture.failures, Vec::<String>::new(), "{what}");
            let points = picture.critical.points.len();
            assert_eq!(picture.components.len(), points + 1, "{what}");
            assert!(picture.stills.len() >= points - 1, "{what}");
            for still in &picture.stills {
                assert!(still.slice.max_residual <= 1e-12, "{what}");
                assert!(still.slice.curves.iter().all(|c| c.closed), "{what}");
                // A still between critical levels has its interval's components.
                if still.between {
                    assert_eq!(
                        still.slice.curves.len(),
                        picture.components[still.interval],
                        "{what}"
                    );
                }
            }
            let wrong = Shape {
                euler: Some(euler + 2),
                orientable,
            };
            let picture = motion_picture(&mesh, Some(&surface), n, frame, wrong, 0).unwrap();
            assert!(
                picture
                    .failures
                    .iter()
                    .any(|f| f.contains("Euler characteristic")),
                "{what}: {:?}",
                picture.failures
            );
        }
    }
}

#[test]
fn the_hyperplane_frame_is_the_views_axes_turned_onto_the_direction() {
    let rotation = halo4d::view::Rotation4 {
        xy: 20.0,
        xz: -35.0,
        xw: 70.0,
        yz: 10.0,
        yw: -50.0,
        zw: 125.0,
    }
    .matrix();
    let w = view_direction(rotation);
    // Along the view's own w: the view's x, y and z.
    let frame = hyperplane_frame(rotation, w);
    for (k, e) in frame.iter().enumerate() {
        let axis = rotation.transpose() * DVec4::AXES[k];
        assert!(e.distance(axis) <= 1e-14, "{e} against {axis}");
    }
    // Any direction, the opposite one included: orthonormal, perpendicular to n, and with
    // n a frame of R^4 turned as the view's (determinant +1).
    for n in seeded(7).into_iter().chain([-w, w + DVec4::X * 1e-13]) {
        let n = n.normalize();
        let [a, b, c] = hyperplane_frame(rotation, n);
        for (i, e) in [a, b, c].iter().enumerate() {
            assert!((e.length() - 1.0).abs() <= 1e-14);
            assert!(e.dot(n).abs() <= 1e-14);
            for f in &[a, b, c][i + 1..] {
                assert!(e.dot(*f).abs() <= 1e-14);
            }
        }
        let det = DMat4::from_cols(a, b, c, n).determinant();
        assert!((det - 1.0).abs() <= 1e-12, "{det}");
    }
    // A tilt turns n by its angle, within the hyperplane's frame.
    let tilted = tilt(w, &frame, 3.0);
    assert!((tilted.dot(w).acos().to_degrees() - 3.0).abs() <= 1e-9);
}

#[test]
fn slice_points_lie_on_the_surface_and_within_the_meshs_error_of_the_meshs_slice() {
    // The spun trefoil at 1e-3 of its diagonal, cut between critical levels: every point
    // of the refined slice is on the hyperplane to 1e-12, on the surface (it is a surface
    // point), and near the mesh's own slice (brute force: its distance to every segment of
    // the mesh's slice curves) within a few times the sampling tolerance.
    let surface = Surface::SpunTrefoil(SpunTrefoil::default());
    let tolerance = 1e-3 * bounding_diagonal(&surface);
    let mesh = sample_adaptive(&surface, tolerance, 2_000_000).mesh;
    let n = generic().normalize();
    let frame = hyperplane_frame(DMat4::IDENTITY, n);
    let shape = Shape {
        euler: Some(2),
        orientable: true,
    };
    let picture = motion_picture(&mesh, Some(&surface), n, frame, shape, 0).unwrap();
    let mut checked = 0;
    for still in &picture.stills {
        let c = still.slice.level;
        let on_mesh = slice(&mesh, None, n, c);
        let segments: Vec<(DVec4, DVec4)> = on_mesh
            .curves
            .iter()
            .flat_map(|curve| {
                let p = &curve.points;
                (0..p.len()).map(move |k| (p[k], p[(k + 1) % p.len()]))
            })
            .collect();
        let distance = |x: DVec4| {
            segments
                .iter()
                .map(|&(a, b)| {
                    let t = ((x - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
                    x.distance(a + (b - a) * t)
                })
                .fold(f64::INFINITY, f64::min)
        };
        for curve in &still.slice.curves {
            for &p in &curve.points {
                assert!((p.dot(n) - c).abs() <= 1e-12);
                let d = distance(p);
                assert!(
                    d <= 4.0 * tolerance,
                    "at level {c}: {d} from the mesh's slice, tolerance {tolerance}"
                );
                checked += 1;
            }
        }
    }
    assert!(checked > 1000, "{checked}");
}
