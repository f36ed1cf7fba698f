//! The proven tolerance: for every triangle, a bound of its distance from the surface patch
//! it stands for that holds at every point, not only at the audit's.
//!
//! A triangle with corners V_i, computed at the parameters p_i of its patch, stands for the
//! surface f over the parameter triangle T of the p_i: the point of the triangle at the
//! barycentric coordinates λ is L(λ) = Σ λ_i V_i, and the surface point it stands for is
//! f(x) at x = Σ λ_i p_i (as in the [`super::audit`]). Two bounds of |L - f(x)| hold over
//! the whole triangle:
//!
//! - **Second order** (Waldron, *The error in linear interpolation at the vertices of a
//!   simplex*, 1998, for vector-valued f): by Taylor's theorem with the integral remainder
//!   at x, Σ λ_i f(p_i) - f(x) = Σ λ_i ∫ (1 - t) D²f(x + t (p_i - x))(p_i - x, p_i - x) dt,
//!   so its length is at most ½ M Σ λ_i |p_i - x|² ≤ ½ M R², where M bounds |D²f(d, d)|
//!   over T for unit d, and R = max_i |p_i - c| for any centre c (Σ λ_i |p_i - x|² =
//!   Σ λ_i |p_i - c|² - |x - c|²); the centre of the triangle's smallest enclosing circle
//!   gives the least R. M comes from the interval enclosures of the second derivatives
//!   f_uu, f_uv, f_vv over the triangle's bounding box ([`Surface::enclose`]): per
//!   coordinate, |a c² + 2 b c s + e s²| ≤ |a + e| / 2 + √(((a - e) / 2)² + b²). To that
//!   adds the corners' own rounding: |V_i - f(p_i)|, from the enclosure of f at the point
//!   p_i, since L - Σ λ_i f(p_i) = Σ λ_i (V_i - f(p_i)).
//! - **Zero order**: both L (in the box of the corners) and f(x) (in the enclosure of f
//!   over the box) lie in one box, whose diagonal bounds their distance. It is coarse, but
//!   it holds where the second derivatives are unbounded: at a branch point of the Fermat
//!   parametrization, at a kink of a formula (`abs`, `min`, `max`).
//!
//! The triangle's bound is the smaller of the two, computed in interval arithmetic and
//! rounded up. A triangle where neither is finite (a formula undefined on part of its box)
//! has no bound: it is counted, and the mesh's proven error is then unknown, never
//! understated. The distance is Euclidean in R^4, as the audit's.

use super::Mesh4;
use crate::progress::Cancel;
use crate::surfaces::{Interval, Jet, Surface};
use glam::DVec4;
use rayon::prelude::*;
use serde::Serialize;

/// What the proof found over a mesh.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Proof {
    /// The largest proven bound over the triangles: every point of every triangle lies
    /// within it of the surface point it stands for. `None` when some triangle has no
    /// finite bound (`unproven`).
    pub max_error: Option<f64>,
    /// The triangle with the largest bound (or the first without one).
    pub worst_triangle: Option<usize>,
    /// Triangles with no finite bound.
    pub unproven: usize,
}

/// Proves a bound for every triangle of `mesh` (see the module documentation), on every
/// core. A mesh without its triangles' and vertices' parameters (a sampled mesh has them;
/// one read back from a file may not) has no triangle proven.
pub fn prove(surface: &Surface, mesh: &Mesh4) -> Proof {
    prove_until(surface, mesh, Cancel::never())
}

/// [`prove`], stopping once `cancel` is cancelled (with no bound, which the caller drops).
pub fn prove_until(surface: &Surface, mesh: &Mesh4, cancel: &Cancel) -> Proof {
    let n = mesh.triangles.len();
    let v = mesh.positions.len();
    if mesh.triangle_uv.len() != n
        || mesh.triangle_patch.len() != n
        || mesh.uv.len() != v
        || mesh.patch.len() != v
    {
        return Proof {
            max_error: if n == 0 { Some(0.0) } else { None },
            worst_triangle: (n > 0).then_some(0),
            unproven: n,
        };
    }
    // Each vertex's own rounding once, for the corners that stand at its own parameters
    // (all but those across a seam or at a pole, computed where they are met).
    let vertex_error: Vec<f64> = (0..mesh.positions.len())
        .into_par_iter()
        .map(|v| {
            if cancel.is_cancelled() {
                return f64::INFINITY;
            }
            corner_error(
                surface,
                mesh.patch[v] as usize,
                mesh.uv[v],
                mesh.positions[v],
            )
        })
        .collect();
    let bounds: Vec<f64> = (0..mesh.triangles.len())
        .into_par_iter()
        .map(|t| {
            if cancel.is_cancelled() {
                return f64::INFINITY;
            }
            let patch = mesh.triangle_patch[t] as usize;
            let uv = mesh.triangle_uv[t];
            let corners = mesh.triangles[t].map(|i| mesh.positions[i as usize]);
            let errors = std::array::from_fn(|k| {
                let v = mesh.triangles[t][k] as usize;
                if mesh.patch[v] as usize == patch && mesh.uv[v] == uv[k] {
                    vertex_error[v]
                } else {
                    corner_error(surface, patch, uv[k], corners[k])
                }
            });
            triangle_bound(surface, patch, uv, corners, errors)
        })
        .collect();
    let mut proof = Proof {
        max_error: Some(0.0),
        ..Proof::default()
    };
    for (t, &b) in bounds.iter().enumerate() {
        if !b.is_finite() {
            if proof.unproven == 0 {
                proof.worst_triangle = Some(t);
            }
            proof.unproven += 1;
            proof.max_error = None;
        } else if proof.unproven == 0 && proof.max_error.is_some_and(|m| b > m) {
            proof.max_error = Some(b);
            proof.worst_triangle = Some(t);
        }
    }
    proof
}

/// A bound of |V - f(p)| for a vertex `corner` computed at the parameters `uv` of `patch`:
/// its rounding, from the enclosure of the surface at that point (infinite where there is
/// none).
pub fn corner_error(surface: &Surface, patch: usize, uv: [f64; 2], corner: DVec4) -> f64 {
    let at = surface.enclose(patch, Interval::point(uv[0]), Interval::point(uv[1]));
    upper(length(std::array::from_fn(|k| {
        (at[k].v - Interval::point(corner[k])).abs()
    })))
}

/// A bound of the distance between the triangle with corners `corners`, computed at the
/// parameters `uv` of `patch`, and the surface patch it stands for, given the corners'
/// own errors ([`corner_error`]): infinite when none can be proven.
pub fn triangle_bound(
    surface: &Surface,
    patch: usize,
    uv: [[f64; 2]; 3],
    corners: [DVec4; 3],
    corner_errors: [f64; 3],
) -> f64 {
    let range = |k: usize| {
        let [a, b, c] = uv.map(|p| p[k]);
        Interval::new(a.min(b).min(c), a.max(b).max(c))
    };
    let over = surface.enclose(patch, range(0), range(1));
    let rounding = corner_errors.into_iter().fold(0.0, f64::max);
    let isotropic = upper(half_squared_radius(uv) * curvature(&over));
    let second = Interval::point(isotropic.min(upper(along_axes(&over, range(0), range(1)))))
        + Interval::point(rounding);
    let zero = length(std::array::from_fn(|k| {
        let box_k = corners
            .iter()
            .fold(over[k].v, |b, c| b.union(Interval::point(c[k])));
        Interval::point(box_k.width())
    }));
    upper(second).min(upper(zero))
}

/// The upper bound of an enclosure, infinite where it is unbounded.
fn upper(x: Interval) -> f64 {
    if x.is_bounded() {
        x.hi()
    } else {
        f64::INFINITY
    }
}

/// The length of a vector of enclosures: an enclosure of the largest length.
fn length(x: [Interval; 4]) -> Interval {
    root(x.iter().fold(Interval::point(0.0), |s, c| s + c.sqr()))
}

/// The square root of a sum of squares, which is not below 0 whatever the rounding moved
/// its lower bound to.
fn root(squares: Interval) -> Interval {
    Interval::new(squares.lo().max(0.0), squares.hi()).sqrt()
}

/// An enclosure of M = max |D²f(d, d)| over unit directions d and the box of `jets`.
fn curvature(jets: &[Jet<Interval>; 4]) -> Interval {
    let half = Interval::point(0.5);
    length(jets.map(|j| {
        let (a, b, e) = (j.duu, j.duv, j.dvv);
        let mean = ((a + e) * half).abs();
        let swing = root(((a - e) * half).sqr() + b.sqr());
        Interval::new(0.0, (mean + swing).hi())
    }))
}

/// The second-order bound along the parameter axes, for triangles long in one parameter
/// and short in the other (where the sampler's warp makes them): with d = p_i - x,
/// |D²f(d, d)| <= |f_uu| d_u² + 2 |f_uv| |d_u d_v| + |f_vv| d_v², and Σ λ_i d_u² <= R_u²,
/// R_u half the triangle's extent in u (Σ λ_i |d_u d_v| <= R_u R_v by Cauchy-Schwarz), so
/// the error is at most ½ (|f_uu| R_u² + 2 |f_uv| R_u R_v + |f_vv| R_v²).
fn along_axes(jets: &[Jet<Interval>; 4], u: Interval, v: Interval) -> Interval {
    let half = Interval::point(0.5);
    let (ru, rv) = (
        Interval::point(u.width()) * half,
        Interval::point(v.width()) * half,
    );
    let norm = |part: fn(&Jet<Interval>) -> Interval| length(jets.map(|j| part(&j)));
    let (a, b, e) = (norm(|j| j.duu), norm(|j| j.duv), norm(|j| j.dvv));
    half * (a * ru.sqr() + Interval::point(2.0) * b * ru * rv + e * rv.sqr())
}

/// ½ R², R the largest distance from the corners to a centre near that of their smallest
/// enclosing circle (any centre gives a valid bound; this one the least).
fn half_squared_radius(uv: [[f64; 2]; 3]) -> Interval {
    let [a, b, c] = uv.map(glam::DVec2::from_array);
    let edges = [(a, b, c), (b, c, a), (c, a, b)];
    // An obtuse or right corner opposite the longest edge: the circle on that edge.
    let centre = edges
        .iter()
        .find(|(p, q, r)| (*p - *r).dot(*q - *r) <= 0.0)
        .map(|(p, q, _)| (*p + *q) * 0.5)
        .unwrap_or_else(|| circumcentre(a, b, c));
    let centre = if centre.is_finite() {
        centre
    } else {
        (a + b + c) / 3.0
    };
    let squared = |p: glam::DVec2| {
        (Interval::point(p.x) - Interval::point(centre.x)).sqr()
            + (Interval::point(p.y) - Interval::point(centre.y)).sqr()
    };
    let r2 = [a, b, c]
        .map(squared)
        .into_iter()
        .fold(Interval::point(0.0), Interval::max);
    r2 * Interval::point(0.5)
}

/// The centre of the circle through three points.
fn circumcentre(a: glam::DVec2, b: glam::DVec2, c: glam::DVec2) -> glam::DVec2 {
    let (ab, ac) = (b - a, c - a);
    let d = 2.0 * ab.perp_dot(ac);
    let (l1, l2) = (ab.length_squared(), ac.length_squared());
    a + glam::DVec2::new(ac.y * l1 - ab.y * l2, ab.x * l2 - ac.x * l1) / d
}
