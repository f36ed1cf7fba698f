//! Halos: the three splits conform on random meshes, and the independent checker catches
//! every planted fault as its own kind.

use crate::common::Rng;
use glam::DVec3;
use halo4d::check::{CheckStats, TetMesh, check};
use halo4d::halo::{HaloParams, build_halo};
use halo4d::tets::{Split, prism};
use halo4d::view::Projected;

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
    build_halo(projected, triangles, 0.05, &params).0.tet_mesh()
}

fn assert_valid(stats: &CheckStats, what: &str) {
    assert!(stats.valid(), "{what}: {stats:?}");
    assert_eq!(stats.quad_mismatches, 0, "{what}");
}

#[test]
fn every_split_conforms_on_random_meshes_with_a_boundary() {
    let mut rng = Rng(2024);
    for round in 0..12 {
        let (nx, ny) = (2 + rng.below(9), 2 + rng.below(9));
        let (projected, triangles) = random_surface(&mut rng, nx, ny);
        for split in [Split::Paper, Split::GlobalOrder, Split::Quality] {
            let what = format!("round {round}, {nx}x{ny}, {split:?}");
            let params = HaloParams {
                split,
                ..HaloParams::default()
            };
            let (halo, report) = build_halo(&projected, &triangles, 0.05, &params);
            let stats = check(&halo.tet_mesh());
            assert_valid(&stats, &what);
            assert_eq!(report.split_stats.mismatches_final, 0, "{what}");
            assert_eq!(
                stats.boundary_faces,
                2 * triangles.len() + 2 * 2 * (nx + ny),
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
                    3 * triangles.len() + 5 * report.split_stats.inserted_vertices,
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
    let replacement = prism(tri, n, turned, u32::MAX);
    bad.tets.splice(3 * t..3 * t + 3, replacement);
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
    assert!(!s.valid());

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
    // The six splittable patterns give three tetrahedra, the two cyclic ones eight around
    // the inserted centre; all positive and all filling the same prism.
    let positions = [
        [0.0, 0.0, -0.1],
        [1.0, 0.0, -0.1],
        [0.0, 1.0, -0.1],
        [0.0, 0.0, 0.1],
        [1.0, 0.0, 0.1],
        [0.0, 1.0, 0.1],
        [1.0 / 3.0, 1.0 / 3.0, 0.0],
    ];
    for bits in 0..8u8 {
        let f = [bits & 1 != 0, bits & 2 != 0, bits & 4 != 0];
        let mesh = TetMesh {
            positions: positions.to_vec(),
            surface_vertices: 3,
            tets: prism([0, 1, 2], 3, f, 6),
        };
        let s = check(&mesh);
        assert_valid(&s, &format!("{f:?}"));
        assert!((s.volume - 0.1).abs() < 1e-15, "{f:?}: {s:?}");
    }
}
