//! The uniform sampler: closed surfaces give closed manifold meshes of the right Euler
//! characteristic, welded by rule; open ones have exactly the expected boundary.

use halo4d::{sample::sample_uniform, surfaces::Surface};
use halo4d::{
    surfaces::Fermat, surfaces::Patches, surfaces::ProductPolynomial, surfaces::TwistSpunTrefoil,
};

const GRIDS: [(usize, usize); 4] = [(4, 4), (4, 6), (16, 8), (30, 64)];

#[test]
fn closed_surfaces_are_closed_oriented_manifolds_with_their_euler_characteristic() {
    let mut surfaces = Surface::catalogue();
    surfaces.push(Surface::TwistSpunTrefoil(TwistSpunTrefoil {
        scale: 1.0,
        twists: 3,
    }));
    // Formula surfaces: their topology comes from the side rules, their mesh from the
    // domain those rules build; the two must agree.
    surfaces.extend(crate::common::formula_surfaces());
    for s in surfaces.into_iter().filter(|s| s.topology().closed) {
        let topo = s.topology();
        let [min_u, min_v] = s.min_cells();
        for (nu, nv) in GRIDS.into_iter().chain([(min_u, min_v)]) {
            let (nu, nv) = (nu.max(min_u), nv.max(min_v));
            let stats = sample_uniform(&s, nu, nv).validate();
            let what = format!("{} on a {nu}x{nv} grid: {stats:?}", s.type_name());
            assert!(stats.is_manifold(), "{what}");
            assert_eq!(stats.boundary_edges, 0, "{what}");
            assert_eq!(
                Some(stats.euler_characteristic),
                topo.euler_characteristic,
                "{what}"
            );
            if topo.orientable {
                assert_eq!(stats.orientation_conflicts, 0, "{what}");
            }
        }
    }
}

#[test]
fn non_orientable_surfaces_cannot_be_oriented() {
    // The grid orients every triangle the same way in (u, v); a Klein bottle or projective
    // plane must then show conflicts along its flipped seam, which proves the seam is welded.
    for s in Surface::catalogue()
        .into_iter()
        .chain(crate::common::formula_surfaces())
        .filter(|s| !s.topology().orientable)
    {
        let stats = sample_uniform(&s, 8, 8).validate();
        assert!(
            stats.orientation_conflicts > 0,
            "{}: {stats:?}",
            s.type_name()
        );
    }
}

#[test]
fn fermat_patches_weld_into_the_affine_fermat_curve() {
    // z1^n + z2^n = 1 is a genus (n-1)(n-2)/2 curve with n points at infinity, so the
    // truncated surface has Euler characteristic 2 - 2g - n = 2n - n^2; its boundary is
    // the two open sides y = ±a of every patch.
    for n in 2..=6u32 {
        let s = Surface::Fermat(Fermat { n, y_range: 1.0 });
        for (nu, nv) in GRIDS {
            let stats = sample_uniform(&s, nu, nv).validate();
            let what = format!("Fermat n = {n} on {nu}x{nv}: {stats:?}");
            let n = n as i64;
            assert!(stats.is_manifold(), "{what}");
            assert_eq!(stats.euler_characteristic, 2 * n - n * n, "{what}");
            assert_eq!(stats.boundary_edges as i64, 2 * n * n * nu as i64, "{what}");
            assert_eq!(stats.orientation_conflicts, 0, "{what}");
        }
    }
}

#[test]
fn open_surfaces_have_the_expected_boundary() {
    let product = Surface::ProductPolynomial(ProductPolynomial::default());
    let stats = sample_uniform(&product, 6, 10).validate();
    // Two cylinders: two boundary circles of 10 edges each per sheet.
    assert_eq!(
        (stats.boundary_edges, stats.euler_characteristic),
        (40, 0),
        "{stats:?}"
    );
    let patches = Surface::Patches(Patches {
        count: 3,
        ..Default::default()
    });
    let stats = sample_uniform(&patches, 4, 6).validate();
    // Four disjoint squares.
    assert_eq!(
        (stats.boundary_edges, stats.euler_characteristic),
        (4 * 20, 4),
        "{stats:?}"
    );
}

#[test]
fn poles_make_no_zero_area_triangles_and_finite_tangents_everywhere() {
    for s in Surface::catalogue() {
        let mesh = sample_uniform(&s, 12, 12);
        let stats = mesh.validate();
        assert_eq!(stats.degenerate_triangles, 0, "{}", s.type_name());
        assert_eq!(stats.non_finite_vertices, 0, "{}", s.type_name());
    }
}

#[test]
fn validate_catches_planted_faults() {
    let s = Surface::Patches(Patches {
        count: 1,
        ..Default::default()
    });
    let good = sample_uniform(&s, 4, 4);
    let mut bad = good.clone();
    bad.triangles.push(bad.triangles[0]); // a repeated triangle: edges in 3 triangles... or 2 same-way
    let stats = bad.validate();
    assert!(
        stats.non_manifold_edges > 0 || stats.orientation_conflicts > 0,
        "{stats:?}"
    );
    let mut bad = good.clone();
    bad.triangles[0][1] = bad.triangles[0][0];
    assert_eq!(bad.validate().degenerate_triangles, 1);
    let mut bad = good.clone();
    bad.tangent_u[0].x = f64::NAN;
    assert_eq!(bad.validate().non_finite_vertices, 1);
    let mut bad = good;
    let t = bad.triangles[0];
    bad.triangles[0] = [t[0], t[2], t[1]];
    assert!(bad.validate().orientation_conflicts > 0);
}
