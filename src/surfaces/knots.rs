//! Knotted 2-spheres in R^4: the Artin spin and the Zeeman twist spin of a knotted trefoil
//! arc (papers 000 and 001).
//!
//! The arc lives in the half-space {(x, y, c) : c >= 0}, touches the plane c = 0 only at
//! its two ends, and meets it there at right angles (so the spun sphere is smooth at its
//! poles). It is made of six pieces joined with continuous second derivatives:
//!
//! 1. a leg up the vertical line x = -d, y = 0 from the plane to height h0;
//! 2. strand A of the two-strand braid σ1^3: three half-turns of radius d about the c axis,
//!    from (-d, 0, h0) to (d, 0, h1);
//! 3. a loop on the side x > d from the top of strand A back down to the bottom of strand B;
//! 4. strand B, opposite strand A at every height, from (d, 0, h0) to (-d, 0, h1);
//! 5. a leg up x = -d from h1 to h2;
//! 6. a long arch on the side x < -d back down to the plane.
//!
//! Closing the arc through c < 0 closes the braid σ1^3 on both sides of the projection
//! plane y = 0: the trefoil. The spin sweeps the arc around the plane c = 0:
//! (x, y, c cos θ, c sin θ). The twist spin also turns the knotted part (pieces 2-4) m times
//! about the vertical line x = -d through its two ends while θ goes once around; the legs lie
//! on that line, and the pieces meet it vertically to second order, so the turned arc stays
//! embedded and the surface stays twice differentiable.

use super::{Domain, Eval4, Interval, Jet, Parametric, Real, Side, SideRule, Topology};
use crate::limits::{FieldError, SURFACE_LENGTH, TWISTS};
use glam::DVec4;
use serde::{Deserialize, Serialize};
use std::f64::consts::{PI, TAU};

/// Radius of the braid.
const D: f64 = 0.5;
/// Heights of the bottom and top of the braid, and of the top of the second leg.
const H0: f64 = 1.0;
const H1: f64 = 2.5;
const H2: f64 = 3.2;
/// Reach and rise of the loop (piece 3).
const LOOP_REACH: f64 = 1.0;
const LOOP_RISE: f64 = 0.6;
/// Reach of the arch (piece 6) beyond the leg, and its starting speed.
const ARCH_REACH: f64 = 3.0;
const ARCH_SPEED: f64 = 3.0;
/// Centre of the arc's x range, subtracted so the surface is centred on the origin.
const X_CENTRE: f64 = (LOOP_REACH - ARCH_REACH) / 2.0;

/// Durations of the six pieces. Each piece climbs at unit vertical speed where it meets its
/// neighbours, which makes the joins C1; the pieces have zero horizontal first and second
/// derivatives and zero vertical acceleration there, which makes them C2.
const PIECES: [f64; 6] = [
    H0,
    H1 - H0,
    TAU * LOOP_RISE - (H1 - H0),
    H1 - H0,
    H2 - H1,
    ARCH_SPEED,
];

fn total() -> f64 {
    PIECES.iter().sum()
}

fn joins() -> Vec<f64> {
    PIECES
        .iter()
        .scan(0.0, |g, len| {
            *g += len;
            Some(*g / total())
        })
        .take(PIECES.len() - 1)
        .collect()
}

/// Quintic smoothstep 6t^5 - 15t^4 + 10t^3: first and second derivatives vanish at 0 and 1.
fn smoothstep<T: Real>(t: T) -> T {
    t.cube() * ((t * 6.0 - 15.0) * t + 10.0)
}

/// The piece of the arc that s in [0, 1] lies on (the first of two at a join).
fn piece_at(s: f64) -> usize {
    let g = s * total();
    let mut start = 0.0;
    for (i, len) in PIECES.iter().enumerate() {
        if g <= start + len {
            return i;
        }
        start += len;
    }
    PIECES.len() - 1
}

/// Where a piece starts along the arc, in the units of [`PIECES`].
fn piece_start(piece: usize) -> f64 {
    PIECES[..piece].iter().fold(0.0, |a, b| a + b)
}

/// The knotted arc at s in [0, 1] by the formula of `piece`: (x, y, c), and whether the
/// point belongs to the knotted part that the twist turns.
fn arc<T: Real>(piece: usize, s: T) -> ([T; 3], bool) {
    let g = s * total();
    let start = piece_start(piece);
    let t = (g - start) * (1.0 / PIECES[piece]);
    let c = T::constant;
    let braid = || smoothstep(t) * (3.0 * PI);
    let climb = t * (H1 - H0) + H0;
    match piece {
        0 => ([c(-D), c(0.0), t * H0], false),
        1 => {
            let (sin, cos) = braid().sin_cos();
            ([cos * -D, sin * -D, climb], true)
        }
        2 => {
            let (sin, cos) = (t * TAU).sin_cos();
            let out = ((c(1.0) - cos) * 0.5).sqr() * LOOP_REACH + D;
            ([out, c(0.0), t * -(H1 - H0) + H1 + sin * LOOP_RISE], true)
        }
        3 => {
            let (sin, cos) = braid().sin_cos();
            ([cos * D, sin * D, climb], true)
        }
        4 => ([c(-D), c(0.0), t * (H2 - H1) + H1], false),
        _ => {
            let height = (t * ARCH_SPEED + H2) * (c(1.0) - t.cube());
            ([smoothstep(t) * -ARCH_REACH - D, c(0.0), height], false)
        }
    }
}

/// Spins the arc: s in [0, 1] along the arc (u), θ in [0, 2π] around the plane (v), with the
/// knotted part turned by `twists` θ about the line x = -d. Over `f64` it gives the point,
/// over [`Jet`]s the point with its derivatives.
fn spin<T: Real>(scale: f64, twists: u32, piece: usize, s: T, theta: T) -> [T; 4] {
    let ([mut x, mut y, c], knotted) = arc(piece, s);
    if knotted && twists > 0 {
        let (sin, cos) = (theta * twists as f64).sin_cos();
        let dx = x + D;
        x = dx * cos - y * sin - D;
        y = dx * sin + y * cos;
    }
    let (sin, cos) = theta.sin_cos();
    [
        (x - X_CENTRE) * scale,
        y * scale,
        c * cos * scale,
        c * sin * scale,
    ]
}

/// [`spin`] with its derivatives in (u, v) = (s, θ).
fn spin_eval(scale: f64, twists: u32, s: f64, theta: f64) -> Eval4 {
    Eval4::from_jets(spin(scale, twists, piece_at(s), Jet::u(s), Jet::v(theta)))
}

/// Enclosures of [`spin`] and its derivatives over a box: each piece of the arc that the
/// box of s meets, over its part of the box, joined. The arc is twice differentiable
/// across the joins, so the join of the pieces' second derivatives holds the arc's over
/// the whole box.
fn spin_enclose(scale: f64, twists: u32, s: Interval, theta: Interval) -> [Jet<Interval>; 4] {
    // Each part reaches a little past its join, so that the parts cover the box whatever
    // the rounding of the joins: a piece's formula is smooth past its ends, and what it
    // gives there only widens the enclosure.
    const PAST: f64 = 1e-9;
    let last = PIECES.len() - 1;
    let mut out: Option<[Jet<Interval>; 4]> = None;
    for piece in 0..=last {
        let from = if piece == 0 {
            f64::NEG_INFINITY
        } else {
            piece_start(piece) / total() - PAST
        };
        let to = if piece == last {
            f64::INFINITY
        } else {
            piece_start(piece + 1) / total() + PAST
        };
        let (lo, hi) = (s.lo().max(from), s.hi().min(to));
        if lo > hi {
            continue;
        }
        let part = spin(
            scale,
            twists,
            piece,
            Jet::u(Interval::new(lo, hi)),
            Jet::v(theta),
        );
        out = Some(match out {
            None => part,
            Some(o) => std::array::from_fn(|k| o[k].union(part[k])),
        });
    }
    out.unwrap_or([Jet::constant(Interval::ENTIRE); 4])
}

/// [`spin`]'s point alone.
fn spin_point(scale: f64, twists: u32, s: f64, theta: f64) -> DVec4 {
    DVec4::from_array(spin(scale, twists, piece_at(s), s, theta))
}

fn sphere_domain() -> Domain {
    Domain::open([0.0, 1.0], [0.0, TAU])
        .glue_v(0)
        .with(Side::U0, SideRule::Pole)
        .with(Side::U1, SideRule::Pole)
}

const SPHERE: Topology = Topology {
    closed: true,
    orientable: true,
    euler_characteristic: Some(2),
};

/// The Artin spin of the knotted trefoil arc: a knotted 2-sphere in R^4. u = s runs along
/// the arc (both ends are poles), v = θ is the spin angle (periodic).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SpunTrefoil {
    /// Uniform scale (the unscaled arc spans 5 units in x and 4.1 in height).
    pub scale: f64,
}

impl Default for SpunTrefoil {
    fn default() -> Self {
        SpunTrefoil { scale: 0.4 }
    }
}

impl SpunTrefoil {
    /// The values of u where two pieces of the knotted arc meet, for the spin and the twist
    /// spin alike: the surface is twice but not three times differentiable across them.
    pub fn joins() -> Vec<f64> {
        joins()
    }
}

impl Parametric for SpunTrefoil {
    fn patch_count(&self) -> usize {
        1
    }
    fn domain(&self, _: usize) -> Domain {
        sphere_domain()
    }
    fn eval(&self, _: usize, u: f64, v: f64) -> Eval4 {
        spin_eval(self.scale, 0, u, v)
    }
    fn point(&self, _: usize, u: f64, v: f64) -> DVec4 {
        spin_point(self.scale, 0, u, v)
    }
    fn enclose(&self, _: usize, u: Interval, v: Interval) -> [Jet<Interval>; 4] {
        spin_enclose(self.scale, 0, u, v)
    }
    fn topology(&self) -> Topology {
        SPHERE
    }
    fn check(&self) -> Result<(), FieldError> {
        SURFACE_LENGTH.check("scale", self.scale)
    }
}

/// The m-twist spin of the trefoil arc (Zeeman): a knotted 2-sphere for m >= 2 (the 1-twist
/// spin is unknotted).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TwistSpunTrefoil {
    /// Uniform scale.
    pub scale: f64,
    /// Number of twists m, 2 to 12.
    pub twists: u32,
}

impl Default for TwistSpunTrefoil {
    fn default() -> Self {
        TwistSpunTrefoil {
            scale: 0.4,
            twists: 2,
        }
    }
}

impl Parametric for TwistSpunTrefoil {
    fn patch_count(&self) -> usize {
        1
    }
    fn domain(&self, _: usize) -> Domain {
        sphere_domain()
    }
    fn eval(&self, _: usize, u: f64, v: f64) -> Eval4 {
        spin_eval(self.scale, self.twists, u, v)
    }
    fn point(&self, _: usize, u: f64, v: f64) -> DVec4 {
        spin_point(self.scale, self.twists, u, v)
    }
    fn enclose(&self, _: usize, u: Interval, v: Interval) -> [Jet<Interval>; 4] {
        spin_enclose(self.scale, self.twists, u, v)
    }
    fn topology(&self) -> Topology {
        SPHERE
    }
    fn check(&self) -> Result<(), FieldError> {
        SURFACE_LENGTH.check("scale", self.scale)?;
        TWISTS.check_with(
            "twists",
            self.twists,
            "the 0-twist spin is `spun_trefoil`, the 1-twist spin is unknotted",
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Points of the arc on a fine polyline, turned by `angle` where knotted.
    fn polyline(angle: f64, n: usize) -> Vec<[f64; 3]> {
        (0..=n)
            .map(|i| {
                let p = spin_point(1.0, 1, i as f64 / n as f64, angle);
                // Undo the spin: radius in the zw plane is c.
                [p.x, p.y, (p.z * p.z + p.w * p.w).sqrt()]
            })
            .collect()
    }

    #[test]
    fn points_are_the_values_of_the_jets_bit_for_bit() {
        // Every piece of the arc, and parameters on both sides of each join.
        let mut us: Vec<f64> = (0..=997).map(|i| f64::from(i) / 997.0).collect();
        for j in joins() {
            us.extend([j.next_down(), j, j.next_up()]);
        }
        for twists in [0, 2, 5] {
            for &u in &us {
                for k in 0..13 {
                    let v = f64::from(k) * 0.53;
                    let (p, e) = (spin_point(0.4, twists, u, v), spin_eval(0.4, twists, u, v));
                    assert_eq!(
                        p.to_array().map(f64::to_bits),
                        e.p.to_array().map(f64::to_bits)
                    );
                }
            }
        }
    }

    #[test]
    fn arc_touches_the_plane_only_at_its_ends() {
        let pts = polyline(0.0, 4000);
        assert_eq!(pts[0][2], 0.0);
        assert!(pts[4000][2].abs() < 1e-12);
        assert!(pts[1..4000].iter().all(|p| p[2] > 1e-4));
    }

    #[test]
    fn arc_is_embedded_for_every_twist_angle() {
        // Points farther apart than 0.5 along the arc stay at least 0.2 apart in space, for
        // every turn of the knotted part: the twist never passes the arc through itself.
        let n = 1500;
        for k in 0..8 {
            let angle = TAU * k as f64 / 8.0 + 0.1;
            let pts = polyline(angle, n);
            let mut along = vec![0.0];
            for w in pts.windows(2) {
                let d: f64 = (0..3)
                    .map(|i| (w[1][i] - w[0][i]).powi(2))
                    .sum::<f64>()
                    .sqrt();
                along.push(along.last().unwrap() + d);
            }
            for i in 0..pts.len() {
                for j in i + 1..pts.len() {
                    if along[j] - along[i] > 0.5 {
                        let d: f64 = (0..3)
                            .map(|q| (pts[i][q] - pts[j][q]).powi(2))
                            .sum::<f64>()
                            .sqrt();
                        assert!(d > 0.2, "arc passes within {d} of itself at angle {angle}");
                    }
                }
            }
        }
    }

    #[test]
    fn arc_is_twice_differentiable_at_the_joins() {
        for s in joins() {
            let (a, _) = arc(piece_at(s - 1e-12), Jet::u(s - 1e-12));
            let (b, _) = arc(piece_at(s + 1e-12), Jet::u(s + 1e-12));
            for i in 0..3 {
                assert!((a[i].v - b[i].v).abs() < 1e-9);
                assert!(
                    (a[i].du - b[i].du).abs() < 1e-8,
                    "first derivative jumps at s = {s}"
                );
                assert!(
                    (a[i].duu - b[i].duu).abs() < 1e-6,
                    "second derivative jumps at s = {s}"
                );
            }
        }
    }
}
