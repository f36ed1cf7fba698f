//! The classical closed surfaces of Fourphront (paper 001) and the planar test scene of
//! paper 000 fig. 1.

use super::{
    Domain, Eval4, Glue, Interval, Jet, Parametric, Real, Scalar, Side, SideRule, Topology,
};
use crate::limits::{Bound, FieldError, PATCH_COUNT, SURFACE_LENGTH};
use serde::{Deserialize, Serialize};
use std::f64::consts::{FRAC_PI_2, TAU};

/// Flat (Clifford) torus (r1 cos s, r1 sin s, r2 cos t, r2 sin t), s, t in [0, 2π), both
/// periodic.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FlatTorus {
    /// Radius of the circle in the xy plane.
    pub r1: f64,
    /// Radius of the circle in the zw plane.
    pub r2: f64,
}

impl Default for FlatTorus {
    fn default() -> Self {
        FlatTorus { r1: 1.0, r2: 1.0 }
    }
}

impl FlatTorus {
    fn jets<S: Scalar>(&self, _: usize, s: Jet<S>, t: Jet<S>) -> [Jet<S>; 4] {
        let ((sin_s, cos_s), (sin_t, cos_t)) = (s.sin_cos(), t.sin_cos());
        [
            cos_s * self.r1,
            sin_s * self.r1,
            cos_t * self.r2,
            sin_t * self.r2,
        ]
    }
}

impl Parametric for FlatTorus {
    fn patch_count(&self) -> usize {
        1
    }
    fn domain(&self, _: usize) -> Domain {
        Domain::open([0.0, TAU], [0.0, TAU])
            .glue_u(0, false)
            .glue_v(0)
    }
    fn eval(&self, patch: usize, u: f64, v: f64) -> Eval4 {
        Eval4::from_jets(self.jets(patch, Jet::u(u), Jet::v(v)))
    }
    fn enclose(&self, patch: usize, u: Interval, v: Interval) -> [Jet<Interval>; 4] {
        self.jets(patch, Jet::u(u), Jet::v(v))
    }
    fn topology(&self) -> Topology {
        Topology {
            closed: true,
            orientable: true,
            euler_characteristic: Some(0),
        }
    }
    fn check(&self) -> Result<(), FieldError> {
        SURFACE_LENGTH.check("r1", self.r1)?;
        SURFACE_LENGTH.check("r2", self.r2)
    }
}

/// Klein bottle ((R + r cos v) cos u, (R + r cos v) sin u, r sin v cos(u/2), r sin v sin(u/2)),
/// u, v in [0, 2π]. v is periodic; the u sides are glued with a flip of v, since
/// (u + 2π, v) and (u, -v) are the same point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct KleinBottle {
    /// Radius R of the core circle.
    pub major_radius: f64,
    /// Radius r of the tube; must be smaller than R.
    pub minor_radius: f64,
}

impl Default for KleinBottle {
    fn default() -> Self {
        KleinBottle {
            major_radius: 1.0,
            minor_radius: 0.5,
        }
    }
}

impl KleinBottle {
    fn jets<S: Scalar>(&self, _: usize, u: Jet<S>, v: Jet<S>) -> [Jet<S>; 4] {
        let ((sin_u, cos_u), (sin_v, cos_v)) = (u.sin_cos(), v.sin_cos());
        let (sin_half, cos_half) = (u * 0.5).sin_cos();
        let ring = cos_v * self.minor_radius + self.major_radius;
        let lift = sin_v * self.minor_radius;
        [ring * cos_u, ring * sin_u, lift * cos_half, lift * sin_half]
    }
}

impl Parametric for KleinBottle {
    fn patch_count(&self) -> usize {
        1
    }
    fn domain(&self, _: usize) -> Domain {
        Domain::open([0.0, TAU], [0.0, TAU])
            .glue_u(0, true)
            .glue_v(0)
    }
    fn eval(&self, patch: usize, u: f64, v: f64) -> Eval4 {
        Eval4::from_jets(self.jets(patch, Jet::u(u), Jet::v(v)))
    }
    fn enclose(&self, patch: usize, u: Interval, v: Interval) -> [Jet<Interval>; 4] {
        self.jets(patch, Jet::u(u), Jet::v(v))
    }
    fn topology(&self) -> Topology {
        Topology {
            closed: true,
            orientable: false,
            euler_characteristic: Some(0),
        }
    }
    fn check(&self) -> Result<(), FieldError> {
        SURFACE_LENGTH.check("major_radius", self.major_radius)?;
        SURFACE_LENGTH.check("minor_radius", self.minor_radius)?;
        Bound::open(0.0, self.major_radius, "").check_with(
            "minor_radius",
            self.minor_radius,
            "a minor_radius smaller than major_radius keeps the surface embedded",
        )
    }
}

/// Real projective plane as the image of the unit sphere under
/// (x, y, z) -> (xy, xz, y² - z², 2yz), scaled by `radius`. Parametrized by the hemisphere
/// x = cos θ, y = sin θ cos φ, z = sin θ sin φ with θ in [0, π/2] (u) and φ in [0, 2π] (v):
/// θ = 0 is a pole, φ is periodic, and the equator θ = π/2 is glued to itself with
/// φ -> φ + π (antipodal points).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ProjectivePlane {
    /// Scale of the embedding.
    pub radius: f64,
}

impl Default for ProjectivePlane {
    fn default() -> Self {
        ProjectivePlane { radius: 1.0 }
    }
}

impl ProjectivePlane {
    fn jets<S: Scalar>(&self, _: usize, theta: Jet<S>, phi: Jet<S>) -> [Jet<S>; 4] {
        let ((sin_t, x), (sin_p, cos_p)) = (theta.sin_cos(), phi.sin_cos());
        let y = sin_t * cos_p;
        let z = sin_t * sin_p;
        let r = self.radius;
        [
            x * y * r,
            x * z * r,
            (y.sqr() - z.sqr()) * r,
            y * z * (2.0 * r),
        ]
    }
}

impl Parametric for ProjectivePlane {
    fn patch_count(&self) -> usize {
        1
    }
    fn domain(&self, _: usize) -> Domain {
        let half_turn = |from: f64, offset: f64| Glue {
            from,
            to: from + 0.5,
            patch: 0,
            side: Side::U1,
            offset,
            reversed: false,
        };
        Domain::open([0.0, FRAC_PI_2], [0.0, TAU])
            .glue_v(0)
            .with(Side::U0, SideRule::Pole)
            .with(
                Side::U1,
                SideRule::Glued(vec![half_turn(0.0, 0.5), half_turn(0.5, -0.5)]),
            )
    }
    fn eval(&self, patch: usize, u: f64, v: f64) -> Eval4 {
        Eval4::from_jets(self.jets(patch, Jet::u(u), Jet::v(v)))
    }
    fn enclose(&self, patch: usize, u: Interval, v: Interval) -> [Jet<Interval>; 4] {
        self.jets(patch, Jet::u(u), Jet::v(v))
    }
    fn topology(&self) -> Topology {
        Topology {
            closed: true,
            orientable: false,
            euler_characteristic: Some(1),
        }
    }
    /// The equator is glued to itself by a half turn: 4 cells along it would fold into 2
    /// vertices joined by one edge four times over.
    fn min_cells(&self) -> [usize; 2] {
        [4, 6]
    }
    fn check(&self) -> Result<(), FieldError> {
        SURFACE_LENGTH.check("radius", self.radius)
    }
}

/// Paper 000 fig. 1: a white square in the plane z = w = 0 (patch 0) and `count` coloured
/// rectangles (patches 1..=count), each standing in a plane y = const across the white
/// square, at w-depth ±spacing, ±2 spacing, ... (alternating, never 0), so that their 3D
/// projections cut the white square while in 4D they pass in front of or behind it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Patches {
    /// Number of coloured patches (1 to 16).
    pub count: usize,
    /// Half the side of the white square.
    pub size: f64,
    /// Step in w between coloured patches.
    pub spacing: f64,
}

impl Default for Patches {
    fn default() -> Self {
        Patches {
            count: 5,
            size: 1.0,
            spacing: 0.3,
        }
    }
}

impl Patches {
    /// The w-depth of coloured patch k (1-based): -s, +s, -2s, +2s, ...
    pub fn depth(&self, k: usize) -> f64 {
        let step = k.div_ceil(2) as f64 * self.spacing;
        if k % 2 == 1 { -step } else { step }
    }

    /// The y of the plane of coloured patch k (1-based), spread across the white square.
    pub fn offset(&self, k: usize) -> f64 {
        if self.count == 1 {
            return 0.0;
        }
        self.size * 0.8 * (2.0 * (k - 1) as f64 / (self.count - 1) as f64 - 1.0)
    }
}

impl Patches {
    fn jets<S: Scalar>(&self, patch: usize, u: Jet<S>, v: Jet<S>) -> [Jet<S>; 4] {
        let s = self.size;
        let c = |x: f64| Jet::from(x);
        if patch == 0 {
            [u * s, v * s, c(0.0), c(0.0)]
        } else {
            [
                u * (0.8 * s),
                c(self.offset(patch)),
                v * (0.6 * s),
                c(self.depth(patch)),
            ]
        }
    }
}

impl Parametric for Patches {
    fn patch_count(&self) -> usize {
        self.count + 1
    }
    fn domain(&self, _: usize) -> Domain {
        Domain::open([-1.0, 1.0], [-1.0, 1.0])
    }
    fn eval(&self, patch: usize, u: f64, v: f64) -> Eval4 {
        Eval4::from_jets(self.jets(patch, Jet::u(u), Jet::v(v)))
    }
    fn enclose(&self, patch: usize, u: Interval, v: Interval) -> [Jet<Interval>; 4] {
        self.jets(patch, Jet::u(u), Jet::v(v))
    }
    /// Discs apart.
    fn topology(&self) -> Topology {
        Topology {
            closed: false,
            orientable: true,
            euler_characteristic: Some(self.patch_count() as i64),
        }
    }
    fn check(&self) -> Result<(), FieldError> {
        PATCH_COUNT.check("count", self.count)?;
        SURFACE_LENGTH.check("size", self.size)?;
        SURFACE_LENGTH.check("spacing", self.spacing)
    }
}
