//! Halos: the three splits conform on random meshes, and the independent checker catches
//! every planted fault as its own kind.

use crate::common::{Rng, fixture, fixture_scenes};
use glam::DVec3;
use halo4d::Scene;
use halo4d::internals::tets::{self, Corners, Split, prism};
use halo4d::sample::Sampling;
use halo4d::view::Projected;
use halo4d::{check::CheckStats, check::TetMesh, check::check};
use halo4d::{halo::Fold, halo::Halo, halo::HaloParams, halo::HaloReport, halo::build_halo};

/// A bumpy height field over a jittered grid, its cells cut along random diagonals, its
/// triangles' corners rotated at random (so each triangle's own order, the paper's starting
/// point, is random), and its vertices numbered at random. Counter-clockwise seen from +z.
fn random_surface(rng: &mut Rng, nx: usize, ny: usize) -> (Projected, Vec<[u32; 3]>) {
    let n = (nx + 1) * (ny + 1);
    let mut label: Vec<u32> = (0..n as u32).collect();
    for i in (1..n).rev() {
        label.swap(i, rng.below(i + 1));
    }
    let mut positions = vec![DVec3::ZERO; n];
    for j in 0..=ny {
        for i in 0..=nx {
            let (x, y) = (
                i as f64 + 0.3 * (rng.unit() - 0.5),
                j as f64 + 0.3 * (rng.unit() - 0.5),
            );
            let z = 0.3 * (0.7 * x).sin() * (0.5 * y).cos();
            positions[label[j * (nx + 1) + i] as usize] = DVec3::new(x, y, z);
        }
    }
    let mut triangles = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let v = |a: usize, b: usize| label[(j + b) * (nx + 1) + i + a];
            let (a, b, c, d) = (v(0, 0), v(1, 0), v(1, 1), v(0, 1));
            let pair = if rng.below(2) == 0 {
                [[a, b, c], [a, c, d]]
            } else {
                [[a, b, d], [b, c, d]]
            };
            for t in pair {
                let r = rng.below(3);
                triangles.push([t[r], t[(r + 1) % 3], t[(r + 2) % 3]]);
            }
        }
    }
    // Normals: the normalized sum of the incident face normals.
    let mut normals = vec![DVec3::ZERO; n];
    for t in &triangles {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        for &i in t {
            normals[i as usize] += (b - a).cross(c - a);
        }
    }
    let normals: Vec<DVec3> = normals.iter().map(|v| v.normalize()).collect();
    let projected = Projected {
        w: positions.iter().map(|p| p.x * 0.1).collect(),
        tangent_u: normals.clone(),
        tangent_v: normals.clone(),
        positions,
        normals,
    };
    (projected, triangles)
}

fn halo_of(projected: &Projected, triangles: &[[u32; 3]], split: Split) -> TetMesh {
    let params = HaloParams {
        split,
        ..HaloParams::default()
    };
    build_halo(projected, triangles, 0.05, &params)
        .0
        .tet_mesh(triangles)
}

fn assert_valid(stats: &CheckStats, what: &str) {
    assert!(stats.passes(), "{what}: {stats:?}");
    assert_eq!(stats.quad_mismatches, 0, "{what}");
}

/// The halo of a mesh with each split (rho 0.05), each checked valid by the checker, with
/// no mismatched quad left by the builder: (split, halo, report, checker's statistics).
fn with_each_split(
    projected: &Projected,
    triangles: &[[u32; 3]],
    what: &str,
) -> Vec<(Split, Halo, HaloReport, CheckStats)> {
    [Split::Paper, Split::GlobalOrder, Split::Quality]
        .into_iter()
        .map(|split| {
            let what = format!("{what}, {split:?}");
            let params = HaloParams {
                split,
                ..HaloParams::default()
            };
            let (halo, report) = build_halo(projected, triangles, 0.05, &params);
            let stats = check(&halo.tet_mesh(triangles));
            assert_valid(&stats, &what);
            assert_eq!(report.split_stats.mismatches_final, 0, "{what}");
            assert_eq!(report.inverted, 0, "{what}");
            (split, halo, report, stats)
        })
        .collect()
}

#[test]
fn every_split_conforms_on_random_meshes_with_a_boundary() {
    let mut rng = Rng(2024);
    for round in 0..12 {
        let (nx, ny) = (2 + rng.below(9), 2 + rng.below(9));
        let (projected, triangles) = random_surface(&mut rng, nx, ny);
        let what = format!("round {round}, {nx}x{ny}");
        for (split, halo, report, stats) in with_each_split(&projected, &triangles, &what) {
            let what = format!("{what}, {split:?}");
            assert_eq!(
                stats.boundary_faces,
                2 * triangles.len() + 4 * 2 * (nx + ny),
                "{what}"
            );
            // The tetrahedra fill the prisms exactly.
            assert!(stats.volume_defect < 1e-12, "{what}: {stats:?}");
            if split == Split::Paper {
                // Random corner orders start with mismatches, which flips (and, where no
                // flip fits, inserted vertices) fix.
                assert!(report.split_stats.mismatches_initial > 0, "{what}");
                assert!(
                    report.split_stats.flips + report.split_stats.inserted_vertices > 0,
                    "{what}"
                );
                assert_eq!(
                    halo.tets.len(),
                    6 * triangles.len() + 5 * report.split_stats.inserted_vertices,
                    "{what}"
                );
            } else {
                assert_eq!(report.split_stats.inserted_vertices, 0, "{what}");
            }
        }
    }
}

#[test]
fn the_checker_catches_each_planted_fault_as_its_own_kind() {
    let mut rng = Rng(7);
    let (projected, triangles) = random_surface(&mut rng, 4, 3);
    let n = projected.positions.len() as u32;
    let good = halo_of(&projected, &triangles, Split::GlobalOrder);
    assert_valid(&check(&good), "good");

    // One quad split two ways: rebuild one prism with one interior edge turned the other
    // way (still splittable), so its neighbour across that edge disagrees.
    let t = (0..triangles.len())
        .find(|&t| {
            let tri = triangles[t];
            let e = (tri[0].min(tri[1]), tri[0].max(tri[1]));
            triangles.iter().enumerate().any(|(u, o)| {
                u != t && (0..3).any(|k| (o[k].min(o[(k + 1) % 3]), o[k].max(o[(k + 1) % 3])) == e)
            })
        })
        .unwrap();
    let tri = triangles[t];
    let global = [0, 1, 2].map(|k| tri[k] < tri[(k + 1) % 3]);
    let mut turned = global;
    turned[0] = !turned[0];
    if turned[0] == turned[1] && turned[1] == turned[2] {
        turned[1] = !turned[1];
    }
    let mut bad = good.clone();
    let replacement = prism(tri, n, turned, [u32::MAX; 2]);
    bad.tets.splice(6 * t..6 * t + 6, replacement);
    let s = check(&bad);
    assert!(s.quad_mismatches > 0 && s.inverted == 0, "{s:?}");

    // A missing tetrahedron opens a hole.
    let mut bad = good.clone();
    bad.tets.remove(4);
    let s = check(&bad);
    assert!(
        s.unexpected_boundary_faces > 0 && s.duplicate_tets == 0,
        "{s:?}"
    );

    // A duplicated tetrahedron.
    let mut bad = good.clone();
    bad.tets.push(bad.tets[2]);
    let s = check(&bad);
    assert_eq!(s.duplicate_tets, 1, "{s:?}");
    assert!(s.overshared_faces >= 1, "{s:?}");

    // An inverted tetrahedron.
    let mut bad = good.clone();
    let tet = bad.tets[5];
    bad.tets[5] = [tet[1], tet[0], tet[2], tet[3]];
    let s = check(&bad);
    assert_eq!((s.inverted, s.duplicate_tets), (1, 0), "{s:?}");
    assert!(!s.passes());

    // A face shared by three tetrahedra: a new vertex joined to an interior face.
    let mut bad = good.clone();
    let interior = {
        let a = bad.tets[0];
        let b = bad.tets[1];
        let shared: Vec<u32> = a.iter().filter(|v| b.contains(v)).copied().collect();
        assert_eq!(
            shared.len(),
            3,
            "the first two tetrahedra of a prism share a face"
        );
        [shared[0], shared[1], shared[2]]
    };
    bad.positions.push([100.0, 100.0, 100.0]);
    let apex = bad.positions.len() as u32 - 1;
    bad.tets.push([interior[0], interior[1], interior[2], apex]);
    let s = check(&bad);
    assert!(s.overshared_faces >= 1, "{s:?}");
    assert!(!s.conforms());

    // A tetrahedron naming a vertex that does not exist.
    let mut bad = good;
    bad.tets[0][3] = 1_000_000;
    assert_eq!(check(&bad).degenerate, 1);
}

#[test]
fn quality_improves_on_the_global_order() {
    let mut rng = Rng(99);
    let (projected, triangles) = random_surface(&mut rng, 8, 8);
    let [global, quality] =
        [Split::GlobalOrder, Split::Quality].map(|s| check(&halo_of(&projected, &triangles, s)));
    assert!(
        quality.min_dihedral_deg >= global.min_dihedral_deg,
        "{} < {}",
        quality.min_dihedral_deg,
        global.min_dihedral_deg
    );
}

#[test]
fn a_single_prism_splits_every_way_into_its_volume() {
    // The six splittable patterns give three tetrahedra in each layer, the two cyclic ones
    // eight around each layer's inserted centre; all positive, the surface triangle a face
    // between the layers, and all filling the same prism.
    let positions = [
        [0.0, 0.0, -0.1],
        [1.0, 0.0, -0.1],
        [0.0, 1.0, -0.1],
        [0.0, 0.0, 0.1],
        [1.0, 0.0, 0.1],
        [0.0, 1.0, 0.1],
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0 / 3.0, 1.0 / 3.0, -0.05],
        [1.0 / 3.0, 1.0 / 3.0, 0.05],
    ];
    for bits in 0..8u8 {
        let f = [bits & 1 != 0, bits & 2 != 0, bits & 4 != 0];
        let mesh = TetMesh {
            positions: positions.to_vec(),
            surface_vertices: 3,
            tets: prism([0, 1, 2], 3, f, [9, 10]),
            surface_triangles: vec![[0, 1, 2]],
        };
        let s = check(&mesh);
        assert_valid(&s, &format!("{f:?}"));
        assert!((s.volume - 0.1).abs() < 1e-15, "{f:?}: {s:?}");
        assert_eq!(s.tets, if bits == 0 || bits == 7 { 16 } else { 6 });
    }
    // One layer of three tetrahedra over the same offsets: a valid shell, but the surface
    // triangle is no face of it, which the checker counts.
    let mesh = TetMesh {
        positions: positions.to_vec(),
        surface_vertices: 3,
        tets: tets::prism_tets([0, 1, 2, 3, 4, 5], [true, true, false], 0).collect(),
        surface_triangles: vec![[0, 1, 2]],
    };
    let s = check(&mesh);
    assert_eq!(s.missing_surface_faces, 1, "{s:?}");
    assert!(s.inverted == 0 && s.volume_defect < 1e-15, "{s:?}");
}

/// A Möbius band: a strip around a circle whose ends are glued with a half turn, so no
/// winding of its triangles is consistent. Each triangle gets a random winding and random
/// corner order, each vertex a random unit "view normal", and the vertices random numbers.
fn random_moebius(rng: &mut Rng, nu: usize, nv: usize) -> (Projected, Vec<[u32; 3]>) {
    let n = nu * (nv + 1);
    let mut label: Vec<u32> = (0..n as u32).collect();
    for i in (1..n).rev() {
        label.swap(i, rng.below(i + 1));
    }
    // Column i, row j; column nu is column 0 turned over (row j -> nv - j).
    let index = |i: usize, j: usize| {
        let (i, j) = if i == nu { (0, nv - j) } else { (i, j) };
        label[i * (nv + 1) + j]
    };
    let mut positions = vec![DVec3::ZERO; n];
    for i in 0..nu {
        for j in 0..=nv {
            let u = std::f64::consts::TAU * i as f64 / nu as f64;
            let v = 0.4 * (2.0 * j as f64 / nv as f64 - 1.0);
            positions[index(i, j) as usize] = DVec3::new(
                (1.0 + v * (u / 2.0).cos()) * u.cos(),
                (1.0 + v * (u / 2.0).cos()) * u.sin(),
                v * (u / 2.0).sin(),
            );
        }
    }
    let mut triangles = Vec::new();
    for i in 0..nu {
        for j in 0..nv {
            let (a, b, c, d) = (
                index(i, j),
                index(i + 1, j),
                index(i + 1, j + 1),
                index(i, j + 1),
            );
            for t in [[a, b, c], [a, c, d]] {
                let t = if rng.below(2) == 0 {
                    t
                } else {
                    [t[0], t[2], t[1]]
                };
                let r = rng.below(3);
                triangles.push([t[r], t[(r + 1) % 3], t[(r + 2) % 3]]);
            }
        }
    }
    let normals: Vec<DVec3> = (0..n)
        .map(|_| {
            DVec3::new(rng.unit() - 0.5, rng.unit() - 0.5, rng.unit() - 0.5)
                .try_normalize()
                .unwrap_or(DVec3::Z)
        })
        .collect();
    let projected = Projected {
        w: positions.iter().map(|p| p.z).collect(),
        tangent_u: normals.clone(),
        tangent_v: normals.clone(),
        positions,
        normals,
    };
    (projected, triangles)
}

#[test]
fn a_moebius_band_with_random_windings_gets_twisted_prisms_and_stays_valid() {
    let mut rng = Rng(31);
    for round in 0..6 {
        let (nu, nv) = (12 + rng.below(20), 1 + rng.below(4));
        let (projected, triangles) = random_moebius(&mut rng, nu, nv);
        let what = format!("round {round}, {nu}x{nv}");
        for (split, _, report, stats) in with_each_split(&projected, &triangles, &what) {
            let what = format!("{what}, {split:?}");
            // The band cannot be oriented: somewhere the offsets turn over.
            assert!(report.twisted_prisms > 0, "{what}");
            // One boundary circle of 2 nu edges: a side wall of four faces (two per layer) over each.
            assert_eq!(
                stats.boundary_faces,
                2 * triangles.len() + 4 * 2 * nu,
                "{what}"
            );
        }
    }
}

#[test]
fn every_split_conforms_with_holes_and_bowtie_boundary_vertices() {
    // Punching random triangles out leaves boundary vertices whose triangles form several
    // fans (a non-manifold boundary).
    let mut rng = Rng(5);
    for round in 0..10 {
        let (projected, mut triangles) = random_surface(&mut rng, 6, 6);
        let keep = triangles.len() * 2 / 3;
        while triangles.len() > keep {
            let i = rng.below(triangles.len());
            triangles.swap_remove(i);
        }
        with_each_split(&projected, &triangles, &format!("round {round}"));
    }
}

/// The products of a fixture scene with `edit` applied.
fn run_fixture(name: &str, edit: impl FnOnce(&mut Scene)) -> Vec<halo4d::SurfaceProduct> {
    let mut scene = Scene::load(&fixture(&format!("scenes/{name}.json"))).unwrap();
    edit(&mut scene);
    crate::common::built(&scene).unwrap().surfaces
}

#[test]
fn the_flat_torus_cross_caps_are_exactly_its_singular_vertices() {
    // (cos s, sin s, cos t, sin t) turned in the yw plane and projected: the tangents of
    // the projection are parallel where sin s = sin t = 0, four points that the 96 x 96 grid
    // has as vertices. There no direction faces every triangle around; rho collapses there
    // and only there, and nothing inverts.
    let products = run_fixture("flat-torus", |_| {});
    let p = &products[0];
    let r = &p.halo_report;
    assert_eq!(r.singular_vertices, 4, "{r:?}");
    assert_eq!(r.collapsed_vertices, 4, "{r:?}");
    assert_eq!(r.inverted, 0, "{r:?}");
    for (v, &rho) in p.halo.rho.iter().enumerate() {
        let [s, t] = p.mesh.uv[v];
        let cross_cap = s.sin().abs() < 1e-9 && t.sin().abs() < 1e-9;
        assert_eq!(rho == 0.0, cross_cap, "vertex {v} at ({s}, {t}), rho {rho}");
    }
    assert!(r.check.passes(), "{r:?}");
}

#[test]
fn cross_caps_between_vertices_and_rho_beyond_the_curvature_stay_valid() {
    // An odd grid puts the cross-caps inside triangles; a rho of 0.3 of the diagonal is
    // more than the torus's curvature allows almost everywhere.
    for (u, rho) in [(95, 0.01), (31, 0.01), (48, 0.3), (95, 0.3)] {
        let products = run_fixture("flat-torus", |scene| {
            scene.sampling = Sampling::Uniform { u, v: u };
            scene.halo.rho = Some(rho);
        });
        let r = &products[0].halo_report;
        let what = format!("{u}x{u}, rho {rho}: {r:?}");
        assert!(r.check.passes(), "{what}");
        assert_eq!(r.inverted, 0, "{what}");
        if rho > 0.1 {
            assert!(
                r.shrunk_vertices > products[0].mesh.vertex_count() / 2,
                "{what}"
            );
        }
        assert!(
            products[0].halo.positions.iter().all(|p| p.is_finite()),
            "{what}"
        );
    }
    // Without shrinking, the same halo is reported with its inverted tetrahedra.
    let products = run_fixture("flat-torus", |scene| {
        scene.halo.rho = Some(0.3);
        scene.halo.fold = Fold::Report;
    });
    let r = &products[0].halo_report;
    assert!(r.inverted > 0 && r.shrunk_vertices == 0, "{r:?}");
    assert_eq!(r.inverted, r.check.inverted + r.check.flat);
}

#[test]
fn the_poles_of_a_spun_knot_sampled_on_a_grid_get_a_valid_halo() {
    // A uniform grid puts a whole row of parameters on each pole.
    let products = run_fixture("default", |scene| {
        scene.sampling = Sampling::Uniform { u: 64, v: 48 };
    });
    let r = &products[0].halo_report;
    assert!(r.check.passes(), "{r:?}");
    assert!(products[0].halo.positions.iter().all(|p| p.is_finite()));
}

#[test]
fn the_paper_split_fixes_every_fixture() {
    // The per-triangle start disagrees on many shared quads; flips and inserted vertices
    // leave none, and the halo is valid.
    for path in fixture_scenes() {
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        for p in run_fixture(&name, |scene| scene.halo.split = Split::Paper) {
            let r = &p.halo_report;
            let s = r.split_stats;
            let what = format!("{name}/{}: {r:?}", p.name);
            assert!(s.mismatches_initial > 0, "{what}");
            assert!(s.flips > 0, "{what}");
            assert_eq!(s.mismatches_final, 0, "{what}");
            assert!(r.check.passes() && r.inverted == 0, "{what}");
        }
    }
}

#[test]
fn the_checker_catches_faults_at_twisted_and_collapsed_prisms() {
    // A twisted prism rebuilt untwisted: its quads no longer match its neighbours'.
    let mut rng = Rng(77);
    let (projected, triangles) = random_moebius(&mut rng, 16, 2);
    let (halo, report) = build_halo(&projected, &triangles, 0.05, &HaloParams::default());
    assert!(check(&halo.tet_mesh(&triangles)).passes() && report.collapsed_vertices == 0);
    let n = halo.surface_vertices as u32;
    // Twisted prisms: their offset faces on the boundary mix the two sides.
    let mut uses = std::collections::HashMap::new();
    for tet in &halo.tets {
        for skip in 0..4 {
            let mut f: Vec<u32> = (0..4).filter(|&i| i != skip).map(|i| tet[i]).collect();
            f.sort_unstable();
            *uses.entry(f).or_insert(0) += 1;
        }
    }
    let twisted = |t: usize| {
        halo.tets[6 * t..6 * t + 6].iter().any(|tet| {
            (0..4).any(|skip| {
                let mut f: Vec<u32> = (0..4).filter(|&i| i != skip).map(|i| tet[i]).collect();
                f.sort_unstable();
                let surface: std::collections::HashSet<u32> = f.iter().map(|v| v % n).collect();
                let sides: std::collections::HashSet<bool> = f.iter().map(|&v| v < n).collect();
                uses[&f] == 1 && surface.len() == 3 && sides.len() == 2
            })
        })
    };
    let mut caught = 0;
    for (t, &tri) in triangles.iter().enumerate().filter(|&(t, _)| twisted(t)) {
        let mut bad = halo.tet_mesh(&triangles);
        let plain = Corners::plain(tri)
            .layers(n)
            .into_iter()
            .flat_map(|layer| tets::prism_tets(layer, [true, true, false], 0));
        bad.tets.splice(6 * t..6 * t + 6, plain);
        let s = check(&bad);
        assert!(!s.conforms(), "prism {t}: {s:?}");
        caught += 1;
    }
    assert_eq!(caught, report.twisted_prisms);

    // A collapsed vertex whose two offsets are told apart: the prisms around it use one of
    // them, so the other offset surface has a hole there.
    let products = run_fixture("flat-torus", |_| {});
    let halo = &products[0].halo;
    let v = halo.rho.iter().position(|&r| r == 0.0).unwrap();
    let mut bad = halo.tet_mesh(&products[0].mesh.triangles);
    bad.positions[halo.surface_vertices + v][2] += 1e-3;
    let s = check(&bad);
    assert_eq!(s.collapsed_vertices, 3, "{s:?}");
    assert!(s.missing_offset_faces > 0 && s.quad_mismatches > 0, "{s:?}");
}

#[test]
fn every_surface_point_is_in_its_own_prism_at_t_one_half() {
    // The surface triangle is the face where a prism's two layers meet, so the point of a
    // triangle is in a tetrahedron of its own prism with t = 1/2 and d_orig its w, however
    // the corners' directions and rho differ (or, on an edge, in its neighbour's, with the
    // same t and d_orig): here on the default scene with rho shrunk in
    // many places, and on a sliver grid whose thin prisms are sheared and twisted. (With one
    // layer of three tetrahedra, the product polynomial's sliver grid had points outside
    // their own prism, and 38 crossings the halo did not explain.)
    type Edit = fn(&mut Scene);
    let cases: [(&str, Edit); 2] = [
        ("default", |s| s.halo.rho = Some(0.05)),
        ("product-polynomial", |s| {
            s.sampling = Sampling::Uniform { u: 4, v: 1024 }
        }),
    ];
    for (name, edit) in cases {
        for p in run_fixture(name, edit) {
            let (halo, n) = (&p.halo, p.halo.surface_vertices as u32);
            assert!(p.halo_report.shrunk_vertices > 0, "{name}: nothing shrunk");
            // The tetrahedra over each pair of surface vertices: those of the prisms of the
            // triangles on that edge (a point on an edge may round into either).
            let mut by_edge: std::collections::HashMap<(u32, u32), Vec<usize>> =
                std::collections::HashMap::new();
            for (k, tet) in halo.tets.iter().enumerate() {
                let mut vs: Vec<u32> = tet.iter().map(|&i| i % n).collect();
                vs.sort_unstable();
                vs.dedup();
                for i in 0..vs.len() {
                    for j in i + 1..vs.len() {
                        by_edge.entry((vs[i], vs[j])).or_default().push(k);
                    }
                }
            }
            let mut checked = 0;
            for tri in &p.mesh.triangles {
                if tri.iter().all(|&v| halo.rho[v as usize] == 0.0) {
                    continue;
                }
                let own: Vec<usize> = (0..3)
                    .flat_map(|k| {
                        let (a, b) = (tri[k], tri[(k + 1) % 3]);
                        by_edge.get(&(a.min(b), a.max(b))).into_iter().flatten()
                    })
                    .copied()
                    .collect();
                let corners = tri.map(|v| halo.positions[(2 * n + v) as usize]);
                for b in [
                    [1.0 / 3.0; 3],
                    [0.6, 0.3, 0.1],
                    [0.5, 0.5, 0.0],
                    [0.05, 0.05, 0.9],
                ] {
                    let x = corners[0] * b[0] + corners[1] * b[1] + corners[2] * b[2];
                    let w: f64 = (0..3).map(|k| b[k] * p.projected.w[tri[k] as usize]).sum();
                    let found = own.iter().find_map(|&k| {
                        let tet = halo.tets[k];
                        let q = tet.map(|i| halo.positions[i as usize]);
                        let c = |v: DVec3| robust::Coord3D {
                            x: v.x,
                            y: v.y,
                            z: v.z,
                        };
                        let l = [
                            robust::orient3d(c(x), c(q[1]), c(q[2]), c(q[3])),
                            robust::orient3d(c(q[0]), c(x), c(q[2]), c(q[3])),
                            robust::orient3d(c(q[0]), c(q[1]), c(x), c(q[3])),
                            robust::orient3d(c(q[0]), c(q[1]), c(q[2]), c(x)),
                        ];
                        let total: f64 = l.iter().sum();
                        (l.iter().all(|&v| v >= 0.0) && total > 0.0).then(|| {
                            let at = |f: &[f64]| {
                                (0..4).map(|i| l[i] * f[tet[i] as usize]).sum::<f64>() / total
                            };
                            (at(&halo.t), at(&halo.d_orig))
                        })
                    });
                    let (t, d) = found.unwrap_or_else(|| {
                        panic!("{name}: {x} of triangle {tri:?} is in no tetrahedron of its prism")
                    });
                    assert!((t - 0.5).abs() < 1e-6, "{name}: t = {t} at {x} of {tri:?}");
                    assert!((d - w).abs() < 1e-6, "{name}: d_orig {d}, w {w} at {x}");
                    checked += 1;
                }
            }
            assert!(checked > 4 * 1000, "{name}: {checked}");
        }
    }
}

#[test]
fn shrinking_leaves_no_inverted_tetrahedron_on_a_sliver_grid() {
    // 4 x 1024 cells of the product polynomial: prisms so thin and sheared that shrinking and
    // grading take turns many times; the last word is the shrinking's.
    let products = run_fixture("product-polynomial", |scene| {
        scene.sampling = Sampling::Uniform { u: 4, v: 1024 };
    });
    let r = &products[0].halo_report;
    assert!(r.shrunk_vertices > 0, "{r:?}");
    assert_eq!(r.inverted, 0, "{r:?}");
    assert!(r.check.passes(), "{r:?}");
}
