//! The projected surface over boxes of parameters, and the interval linear algebra of the
//! certificate: enclosures of f = P∘S with its first and second derivatives, the regularity
//! of an interval matrix, and Krawczyk's operator.
//!
//! Krawczyk's test (Krawczyk 1969; Moore, *Interval Analysis*, 1979): for a system G(z) = 0
//! of n equations in n unknowns over a box Z with centre c, an interval matrix M holding
//! every Jacobian of G over Z and a real matrix C (the inverse of M's midpoint),
//! K(Z) = c - C G(c) + (I - C M)(Z - c). Every solution in Z lies in K(Z); so K(Z) ∩ Z = ∅
//! proves there is none, and K(Z) in the interior of Z proves there is exactly one. The
//! Jacobian's rows may come from different points of Z (the mean-value theorem row by
//! row), which is what the enclosures over Z give.

use crate::surfaces::{Interval, Jet, Surface};
use crate::view::{Projection, View};
use glam::{DMat4, DVec4};

pub(super) type I = Interval;
/// An interval vector of R^3.
pub(super) type V3 = [I; 3];
/// An interval 3×3 matrix, by rows.
pub(super) type M3 = [[I; 3]; 3];

/// Enclosures of the projected surface and its derivatives over a box of parameters.
#[derive(Clone, Copy, Debug)]
pub(super) struct Image {
    /// The point.
    pub p: V3,
    /// ∂/∂u.
    pub du: V3,
    /// ∂/∂v.
    pub dv: V3,
    /// ∂²/∂u².
    pub duu: V3,
    /// ∂²/∂u∂v.
    pub duv: V3,
    /// ∂²/∂v².
    pub dvv: V3,
}

/// A surface seen through a view: f = P ∘ (R S + t) over boxes.
pub(super) struct Projector<'a> {
    /// The surface.
    pub surface: &'a Surface,
    rotation: DMat4,
    shift: DVec4,
    eye: Option<f64>,
}

impl<'a> Projector<'a> {
    /// `surface` through `view`.
    pub fn new(surface: &'a Surface, view: &View) -> Self {
        Projector {
            surface,
            rotation: view.rotation.matrix(),
            shift: DVec4::from_array(view.translation),
            eye: match view.projection {
                Projection::Orthographic => None,
                Projection::Perspective { eye_distance } => Some(eye_distance),
            },
        }
    }

    /// The enclosures over the box u × v of `patch`.
    pub fn image(&self, patch: usize, u: I, v: I) -> Image {
        let s = self.surface.enclose(patch, u, v);
        let m = self.rotation;
        let mut x: [Jet<I>; 4] = std::array::from_fn(|k| {
            (0..4).fold(Jet::constant(I::point(self.shift[k])), |acc, j| {
                acc + s[j] * m.col(j)[k]
            })
        });
        if let Some(e) = self.eye {
            let scale = Jet::constant(I::point(e)) / (x[3] + e);
            for c in &mut x[..3] {
                *c = *c * scale;
            }
        }
        let part = |f: fn(&Jet<I>) -> I| [f(&x[0]), f(&x[1]), f(&x[2])];
        Image {
            p: part(|j| j.v),
            du: part(|j| j.du),
            dv: part(|j| j.dv),
            duu: part(|j| j.duu),
            duv: part(|j| j.duv),
            dvv: part(|j| j.dvv),
        }
    }
}

/// a × b.
pub(super) fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Whether some component excludes 0: the vector is proven nonzero.
pub(super) fn nonzero(a: &V3) -> bool {
    a.iter().any(|c| !c.contains(0.0))
}

/// a - b.
pub(super) fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// a ∪ b, component by component.
pub(super) fn union(a: V3, b: V3) -> V3 {
    [a[0].union(b[0]), a[1].union(b[1]), a[2].union(b[2])]
}

/// k a.
pub(super) fn scale(k: I, a: V3) -> V3 {
    [k * a[0], k * a[1], k * a[2]]
}

/// The inverse of a real 3×3 matrix (by rows), `None` when it is singular or nearly so.
fn inverse(m: [[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let c = |r: usize, s: usize| {
        let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
        let (s1, s2) = ((s + 1) % 3, (s + 2) % 3);
        m[r1][s1] * m[r2][s2] - m[r1][s2] * m[r2][s1]
    };
    let det = m[0][0] * c(0, 0) + m[0][1] * c(0, 1) + m[0][2] * c(0, 2);
    let size = m.iter().flatten().fold(0.0f64, |a, x| a.max(x.abs()));
    if !det.is_finite() || det.abs() <= 1e-300 || det.abs() < 1e-14 * size.powi(3) {
        return None;
    }
    let out = std::array::from_fn(|r| std::array::from_fn(|s| c(s, r) / det));
    Some(out)
}

/// A preconditioner of an interval matrix that proves every matrix in it regular: C, the
/// inverse of its midpoint, and E = I - C M with ‖E‖∞ < 1 (then C M, and so every matrix
/// of M, is invertible). `None` when that is not shown.
pub(super) fn regular(m: &M3) -> Option<([[f64; 3]; 3], M3, f64)> {
    let mid = m.map(|row| row.map(I::mid));
    let c = inverse(mid)?;
    let e: M3 = std::array::from_fn(|r| {
        std::array::from_fn(|s| {
            let cm = (0..3).fold(I::point(0.0), |acc, k| acc + I::point(c[r][k]) * m[k][s]);
            I::point(if r == s { 1.0 } else { 0.0 }) - cm
        })
    });
    let norm = e
        .iter()
        .map(|row| row.iter().fold(0.0f64, |a, x| (a + x.mag()).next_up()))
        .fold(0.0f64, f64::max);
    (norm < 1.0).then_some((c, e, norm))
}

/// What Krawczyk's operator says of a box.
#[derive(Clone, Copy, Debug)]
pub(super) enum Krawczyk {
    /// No solution in the box.
    None,
    /// Exactly one, within the returned box (inside the given one).
    One([I; 3]),
    /// Undecided; the returned box still holds every solution.
    Unknown([I; 3]),
}

/// Krawczyk's test on the box `z` with centre `c`, the system's value `gc` at `c`, and the
/// preconditioner `pre` of its Jacobian over `z` (from [`regular`]).
pub(super) fn krawczyk(z: [I; 3], c: [f64; 3], gc: V3, pre: &([[f64; 3]; 3], M3, f64)) -> Krawczyk {
    let (cm, e, _) = pre;
    let k: [I; 3] = std::array::from_fn(|r| {
        let mut acc = I::point(c[r]);
        for s in 0..3 {
            acc = acc - I::point(cm[r][s]) * gc[s] + e[r][s] * (z[s] - I::point(c[s]));
        }
        acc
    });
    if (0..3).any(|r| !k[r].meets(z[r])) {
        return Krawczyk::None;
    }
    if (0..3).all(|r| z[r].holds_inside(k[r])) {
        return Krawczyk::One(k);
    }
    Krawczyk::Unknown(std::array::from_fn(|r| {
        k[r].intersect(z[r]).unwrap_or(z[r])
    }))
}
