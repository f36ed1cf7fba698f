//! Surfaces: exact derivatives against finite differences, and domain rules against
//! geometry.

use crate::common::Rng;
use glam::DVec4;
use halo4d::surfaces::Surface;
use halo4d::{
    surfaces::Fermat, surfaces::Side, surfaces::SideRule, surfaces::SpunTrefoil,
    surfaces::TwistSpunTrefoil,
};
use std::f64::consts::FRAC_PI_2;

fn surfaces_under_test() -> Vec<Surface> {
    let mut all = Surface::catalogue();
    for n in [2, 3, 5, 6] {
        all.push(Surface::Fermat(Fermat { n, y_range: 1.2 }));
    }
    all.push(Surface::TwistSpunTrefoil(TwistSpunTrefoil {
        scale: 0.7,
        twists: 5,
    }));
    all.extend(crate::common::formula_surfaces());
    all
}

/// Parameters too close to where a fourth-order stencil of step h is not valid: the
/// joins of the knotted arc (C2, not C3) and the Fermat branch points.
fn near_trouble(s: &Surface, u: f64, v: f64, h: f64) -> bool {
    match s {
        Surface::SpunTrefoil(_) | Surface::TwistSpunTrefoil(_) => {
            SpunTrefoil::joins().iter().any(|j| (u - j).abs() < 4.0 * h)
        }
        Surface::Fermat(_) => v.abs() < 0.05 && !(0.05..=FRAC_PI_2 - 0.05).contains(&u),
        _ => false,
    }
}

#[test]
fn exact_derivatives_match_fourth_order_finite_differences() {
    let mut rng = Rng(0x4D_5EED);
    let mut worst = 0.0f64;
    for s in surfaces_under_test() {
        for patch in 0..s.patch_count() {
            let d = s.domain(patch);
            let (hu, hv) = ((d.u[1] - d.u[0]) * 2e-4, (d.v[1] - d.v[0]) * 2e-4);
            let mut tested = 0;
            while tested < 12 {
                // Stay 2h inside the domain so the stencil does not leave it.
                let u = d.u[0] + 2.0 * hu + (d.u[1] - d.u[0] - 4.0 * hu) * rng.unit();
                let v = d.v[0] + 2.0 * hv + (d.v[1] - d.v[0] - 4.0 * hv) * rng.unit();
                if near_trouble(&s, u, v, hu) {
                    continue;
                }
                tested += 1;
                let p = |i: i32, j: i32| s.eval(patch, u + i as f64 * hu, v + j as f64 * hv).p;
                let d1 = |f: &dyn Fn(i32) -> DVec4, h: f64| {
                    (-f(2) + f(1) * 8.0 - f(-1) * 8.0 + f(-2)) / (12.0 * h)
                };
                let d2 = |f: &dyn Fn(i32) -> DVec4, h: f64| {
                    (-f(2) + f(1) * 16.0 - f(0) * 30.0 + f(-1) * 16.0 - f(-2)) / (12.0 * h * h)
                };
                let fd = [
                    d1(&|i| p(i, 0), hu),
                    d1(&|j| p(0, j), hv),
                    d2(&|i| p(i, 0), hu),
                    d1(&|i| d1(&|j| p(i, j), hv), hu),
                    d2(&|j| p(0, j), hv),
                ];
                let e = s.eval(patch, u, v);
                let exact = [e.du, e.dv, e.duu, e.duv, e.dvv];
                for (k, (x, y)) in exact.iter().zip(fd).enumerate() {
                    let rel = (*x - y).length() / x.length().max(1.0);
                    worst = worst.max(rel);
                    assert!(
                        rel < 1e-6,
                        "{} patch {patch} at ({u}, {v}): derivative {k} exact {x} vs finite differences {y} (relative {rel:e})",
                        s.type_name()
                    );
                }
            }
        }
    }
    eprintln!("worst relative disagreement: {worst:e}");
}

#[test]
fn glued_sides_and_poles_are_the_same_points() {
    let mut rng = Rng(7);
    for s in surfaces_under_test() {
        let scale = (0..s.patch_count())
            .map(|p| s.eval(p, s.domain(p).u[0], s.domain(p).v[0]).p.length())
            .fold(1.0, f64::max);
        for patch in 0..s.patch_count() {
            let d = s.domain(patch);
            for side in Side::ALL {
                for _ in 0..20 {
                    let sigma = rng.unit();
                    let (u, v) = d.side_point(side, sigma);
                    let here = s.eval(patch, u, v).p;
                    match d.side(side) {
                        SideRule::Open => {}
                        SideRule::Pole => {
                            let (u0, v0) = d.side_point(side, 0.0);
                            assert!((here - s.eval(patch, u0, v0).p).length() < 1e-12 * scale);
                        }
                        SideRule::Glued(pieces) => {
                            let g = pieces
                                .iter()
                                .find(|g| g.from <= sigma && sigma <= g.to)
                                .expect("pieces cover the side");
                            let other = s.domain(g.patch);
                            let (u1, v1) = other.side_point(g.side, g.map(sigma));
                            let there = s.eval(g.patch, u1, v1).p;
                            assert!(
                                (here - there).length() < 1e-12 * scale,
                                "{} patch {patch} side {side:?} at {sigma}: {here} is not {there}",
                                s.type_name()
                            );
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn the_point_alone_is_the_point_of_the_full_evaluation() {
    // `point` is the samplers' fast path; it must agree with `eval` everywhere, branch
    // points and patch corners included.
    let mut rng = Rng(11);
    for s in surfaces_under_test() {
        for patch in 0..s.patch_count() {
            let d = s.domain(patch);
            let corners = [(0.0, 0.0), (1.0, 1.0), (0.0, 0.5), (1.0, 0.5)];
            let random = (0..200).map(|_| (rng.unit(), rng.unit()));
            for (a, b) in corners.into_iter().chain(random) {
                let u = d.u[0] + (d.u[1] - d.u[0]) * a;
                let v = d.v[0] + (d.v[1] - d.v[0]) * b;
                let (fast, full) = (s.point(patch, u, v), s.eval(patch, u, v).p);
                assert!(
                    (fast - full).length() <= 1e-13 * (1.0 + full.length()),
                    "{} patch {patch} at ({u}, {v}): {fast} vs {full}",
                    s.type_name()
                );
            }
        }
    }
}

#[test]
fn parameters_past_a_glued_side_continue_on_the_side_it_is_glued_to() {
    use halo4d::{surfaces::KleinBottle, surfaces::Patches, surfaces::ProjectivePlane};
    let close = |s: &Surface, a: (usize, f64, f64), b: (usize, f64, f64)| {
        let (p, q) = (s.point(a.0, a.1, a.2), s.point(b.0, b.1, b.2));
        assert!(p.distance(q) < 1e-12, "{p} against {q}");
    };
    // The Klein bottle's u sides are glued with a flip of v; its formula continues past
    // them to the same points.
    let klein = Surface::KleinBottle(KleinBottle::default());
    let (patch, u, v, inside) = klein.chart(0, -0.1, 1.0);
    assert!(inside);
    assert!((u - (std::f64::consts::TAU - 0.1)).abs() < 1e-12, "{u}");
    assert!((v - (std::f64::consts::TAU - 1.0)).abs() < 1e-12, "{v}");
    close(&klein, (0, -0.1, 1.0), (patch, u, v));
    // Past a corner: both sides in turn.
    let (patch, u, v, inside) = klein.chart(0, 6.4, -0.2);
    assert!(
        inside && (0.0..=std::f64::consts::TAU).contains(&u),
        "{u} {v}"
    );
    close(&klein, (0, 6.4, -0.2), (patch, u, v));
    // The projective plane's equator is glued to itself by a half turn: past it is the
    // antipodal point, where the formula continues too.
    let plane = Surface::ProjectivePlane(ProjectivePlane::default());
    let (patch, u, v, inside) = plane.chart(0, std::f64::consts::FRAC_PI_2 + 0.05, 1.0);
    assert!(inside && u < std::f64::consts::FRAC_PI_2, "{u}");
    close(
        &plane,
        (0, std::f64::consts::FRAC_PI_2 + 0.05, 1.0),
        (patch, u, v),
    );
    // Past a pole or an open side, nothing to continue on.
    assert!(!plane.chart(0, -0.01, 1.0).3);
    let patches = Surface::Patches(Patches::default());
    let d = patches.domain(0);
    assert!(!patches.chart(0, d.u[1] + 0.01, d.v[0]).3);
    // Inside, or off by rounding, the parameters are returned as they are.
    assert_eq!(klein.chart(0, 1.0, 2.0), (0, 1.0, 2.0, true));
    assert!(patches.chart(0, d.u[0] - 1e-14, d.v[0]).3);
}

#[test]
fn formula_surfaces_pass_their_check_and_count_their_topology() {
    let chi: Vec<Option<i64>> = crate::common::formula_surfaces()
        .iter()
        .map(|s| {
            assert_eq!(s.check(), Ok(()), "{}", serde_json::to_string(s).unwrap());
            s.topology().euler_characteristic
        })
        .collect();
    assert_eq!(chi, [Some(0), Some(0), Some(1), Some(2)]);
}
