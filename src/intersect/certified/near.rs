//! Double points between two boxes of one surface that touch (across a glued side, a
//! corner or a pole included), where p = q is a solution of f(p) = f(q) that is not a
//! double point: such pairs are proven free of double points by divided differences, or
//! left to a finer subdivision.
//!
//! - **Divided differences.** In one chart holding both boxes in a convex region H,
//!   f(q) - f(p) = A (q - p), where each row of A is a row of f's Jacobian somewhere on the
//!   segment (the mean-value theorem row by row), so A's columns lie in the enclosures of
//!   f_u and f_v over H. If the interval cross product f_u × f_v over H excludes 0, every
//!   such A has independent columns, and f(p) = f(q) forces p = q: no double point. The
//!   chart is the patch's own, continued across its glued sides and corners by the glue
//!   rule ([`Surface::chart`]), each piece of H enclosed on the patch it lies on.
//! - **Poles.** A side that is one point of the surface (u = u0, v periodic) leaves f_v = 0
//!   there, so the test above fails in every box that reaches it. Around the pole the
//!   surface is a disc: in the chart (x, y) = ρ (cos φ, sin φ), ρ = u - u0 and
//!   φ = 2π (v - v0) / ev, f̃_x = f_ρ cos φ - (f_φ / ρ) sin φ and f̃_y = f_ρ sin φ + (f_φ / ρ)
//!   cos φ, and f_φ / ρ is enclosed by f_uv (ev / 2π) over the box reaching the pole (f_v is
//!   0 on the pole, and the mean-value theorem does the rest). The same cross-product test
//!   on f̃_x, f̃_y over the disc ρ ≤ r (a convex region of that chart) proves the disc free
//!   of double points.
//! - **Cross-caps.** Where the rank of Df drops at a regular point of the surface the
//!   double curve ends: f_v = λ f_u, three equations in (u, v, λ), proven to have exactly
//!   one solution in a box by Krawczyk's test, with λ's range bounding every λ possible in
//!   the box, so that no other branch point hides there.

use super::system::{I, Image, Krawczyk, Projector, V3, cross, krawczyk, nonzero, regular, scale};
use crate::surfaces::{Side, SideRule, Surface};

/// A box of one patch's parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Rect {
    /// The patch.
    pub patch: usize,
    /// Its u range.
    pub u: I,
    /// Its v range.
    pub v: I,
}

impl Rect {
    /// Whether the two closed boxes share a point (in one chart).
    fn touches(&self, o: &Rect) -> bool {
        self.u.meets(o.u) && self.v.meets(o.v)
    }
}

/// What the near test says of two touching boxes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Near {
    /// They do not touch in any chart: the far test decides.
    Apart,
    /// No double point with one point in each.
    Free,
    /// Not shown at this size.
    Unsure,
}

/// A signed permutation of (u, v): the linear part of a glue map, by rows.
type Linear = [[f64; 2]; 2];

/// The affine map of a piece of a patch's continued chart onto the patch it lies on:
/// x' = to + L (x - from).
#[derive(Clone, Copy, Debug)]
pub(super) struct Glued {
    /// The patch the piece lies on.
    pub patch: usize,
    from: [f64; 2],
    to: [f64; 2],
    /// The linear part.
    pub linear: Linear,
}

impl Glued {
    /// The image of a box of the continued chart, widened by `slack` for the rounding of
    /// the map's points.
    pub fn image(&self, u: I, v: I, slack: f64) -> (I, I) {
        let d = [u - I::point(self.from[0]), v - I::point(self.from[1])];
        let out: [I; 2] = std::array::from_fn(|r| {
            let x = I::point(self.to[r])
                + I::point(self.linear[r][0]) * d[0]
                + I::point(self.linear[r][1]) * d[1];
            I::new(x.lo() - slack, x.hi() + slack)
        });
        (out[0], out[1])
    }

    /// The box of the continued chart whose image is `u × v` (the inverse map).
    fn preimage(&self, u: I, v: I, slack: f64) -> (I, I) {
        let inverse = Glued {
            patch: self.patch,
            from: self.to,
            to: self.from,
            linear: [
                [self.linear[0][0], self.linear[1][0]],
                [self.linear[0][1], self.linear[1][1]],
            ],
        };
        inverse.image(u, v, slack)
    }
}

/// The map of the continued chart of `patch` around the point (u, v) (outside the patch's
/// rectangle): the patch it reaches by the glue rule and the affine map there, `None` past
/// an open side or a pole, or where the glue changes scale.
pub(super) fn glued(surface: &Surface, patch: usize, u: f64, v: f64, step: f64) -> Option<Glued> {
    // The probes step away from the patch, so that none falls back inside it.
    let d = surface.domain(patch);
    let su = if u < d.u[0] { -step } else { step };
    let sv = if v < d.v[0] { -step } else { step };
    let (p0, u0, v0, in0) = surface.chart(patch, u, v);
    let (p1, u1, v1, in1) = surface.chart(patch, u + su, v);
    let (p2, u2, v2, in2) = surface.chart(patch, u, v + sv);
    if !(in0 && in1 && in2) || p1 != p0 || p2 != p0 {
        return None;
    }
    let unit = |x: f64, s: f64| -> Option<f64> {
        let r = x / s;
        [-1.0, 0.0, 1.0].into_iter().find(|k| (r - k).abs() < 1e-6)
    };
    let linear = [
        [unit(u1 - u0, su)?, unit(u2 - u0, sv)?],
        [unit(v1 - v0, su)?, unit(v2 - v0, sv)?],
    ];
    let det = linear[0][0] * linear[1][1] - linear[0][1] * linear[1][0];
    (det.abs() == 1.0).then_some(Glued {
        patch: p0,
        from: [u, v],
        to: [u0, v0],
        linear,
    })
}

/// The pieces of a box of `patch`'s continued chart (cut by the patch's rectangle), each
/// with the map onto the patch it lies on; `None` where a piece lies past an open side or a
/// pole, or is cut by the end of a glued piece.
fn pieces(surface: &Surface, patch: usize, u: I, v: I) -> Option<Vec<(I, I, Option<Glued>)>> {
    let d = surface.domain(patch);
    let cuts = |x: I, range: [f64; 2]| -> Vec<I> {
        let mut edges = vec![x.lo()];
        edges.extend(range.iter().copied().filter(|&c| x.lo() < c && c < x.hi()));
        edges.push(x.hi());
        edges.windows(2).map(|w| I::new(w[0], w[1])).collect()
    };
    let mut out = Vec::new();
    for pu in cuts(u, d.u) {
        for pv in cuts(v, d.v) {
            let inside =
                d.u[0] <= pu.lo() && pu.hi() <= d.u[1] && d.v[0] <= pv.lo() && pv.hi() <= d.v[1];
            if inside {
                out.push((pu, pv, None));
                continue;
            }
            let extent = (d.u[1] - d.u[0]).abs().max((d.v[1] - d.v[0]).abs());
            let step = (1e-3 * pu.width().min(pv.width())).max(1e-9 * extent);
            let g = glued(surface, patch, pu.mid(), pv.mid(), step)?;
            // The whole piece goes by the same map: its corners, a little inside, agree.
            for (cu, cv) in [
                (pu.lo(), pv.lo()),
                (pu.lo(), pv.hi()),
                (pu.hi(), pv.lo()),
                (pu.hi(), pv.hi()),
            ] {
                let (cu, cv) = (cu + (pu.mid() - cu) * 0.01, cv + (pv.mid() - cv) * 0.01);
                let (p, tu, tv, inside) = surface.chart(patch, cu, cv);
                let (eu, ev) = g.image(I::point(cu), I::point(cv), 0.0);
                let off = |a: f64, b: f64| (a - b).abs() > 1e-9 * (1.0 + b.abs());
                if !inside || p != g.patch || off(eu.mid(), tu) || off(ev.mid(), tv) {
                    return None;
                }
            }
            out.push((pu, pv, Some(g)));
        }
    }
    Some(out)
}

/// The slack of a glued piece's image: the rounding of the chart's points.
fn slack(surface: &Surface, patch: usize) -> f64 {
    let d = surface.domain(patch);
    1e-12 * (d.u[1] - d.u[0]).abs().max((d.v[1] - d.v[0]).abs())
}

/// Enclosures of f and its derivatives over a box of `patch`'s continued chart (each piece
/// on the patch it lies on, its derivatives turned by the glue map), `None` where a piece
/// cannot be followed.
pub(super) fn image_continued(proj: &Projector, patch: usize, u: I, v: I) -> Option<Image> {
    let s = slack(proj.surface, patch);
    let mut acc: Option<Image> = None;
    for (pu, pv, g) in pieces(proj.surface, patch, u, v)? {
        let im = match g {
            None => proj.image(patch, pu, pv),
            Some(g) => {
                let (iu, iv) = g.image(pu, pv, s);
                let im = proj.image(g.patch, iu, iv);
                // ∂f/∂x_k = Σ_r f_r L[r][k]; ∂²f/∂x_k∂x_l = Σ_rs f_rs L[r][k] L[s][l].
                let l = |r: usize, k: usize| I::point(g.linear[r][k]);
                let first = |k: usize| -> V3 {
                    std::array::from_fn(|c| l(0, k) * im.du[c] + l(1, k) * im.dv[c])
                };
                let second = |k: usize, m: usize| -> V3 {
                    std::array::from_fn(|c| {
                        l(0, k) * l(0, m) * im.duu[c]
                            + (l(0, k) * l(1, m) + l(1, k) * l(0, m)) * im.duv[c]
                            + l(1, k) * l(1, m) * im.dvv[c]
                    })
                };
                Image {
                    p: im.p,
                    du: first(0),
                    dv: first(1),
                    duu: second(0, 0),
                    duv: second(0, 1),
                    dvv: second(1, 1),
                }
            }
        };
        acc = Some(match acc {
            None => im,
            Some(a) => {
                let un = super::system::union;
                Image {
                    p: un(a.p, im.p),
                    du: un(a.du, im.du),
                    dv: un(a.dv, im.dv),
                    duu: un(a.duu, im.duu),
                    duv: un(a.duv, im.duv),
                    dvv: un(a.dvv, im.dvv),
                }
            }
        });
    }
    acc
}

/// Enclosures of f_u and f_v over a box of `patch`'s continued chart.
fn tangents(proj: &Projector, patch: usize, u: I, v: I) -> Option<(V3, V3)> {
    image_continued(proj, patch, u, v).map(|im| (im.du, im.dv))
}

/// Whether f_u × f_v over the region excludes 0.
fn immersed(du: V3, dv: V3) -> bool {
    nonzero(&cross(du, dv))
}

/// The near test of two boxes of one surface (see the module documentation).
pub(super) fn near(proj: &Projector, a: &Rect, b: &Rect, poles: &Poles) -> Near {
    let surface = proj.surface;
    let mut touching = false;
    if a.patch == b.patch {
        if let Some(free) = poles.disc(proj, a, b) {
            if free {
                return Near::Free;
            }
            touching = true;
        }
        if a.touches(b) {
            touching = true;
            let (u, v) = (a.u.union(b.u), a.v.union(b.v));
            if tangents(proj, a.patch, u, v).is_some_and(|(du, dv)| immersed(du, dv)) {
                return Near::Free;
            }
        }
    }
    // b as seen from a's chart continued past each side and corner that a reaches.
    let d = surface.domain(a.patch);
    let (eu, ev) = (d.u[1] - d.u[0], d.v[1] - d.v[0]);
    let reach_u = [
        (a.u.lo() == d.u[0], -1.0),
        (a.u.hi() == d.u[1], 1.0),
        (true, 0.0),
    ];
    let reach_v = [
        (a.v.lo() == d.v[0], -1.0),
        (a.v.hi() == d.v[1], 1.0),
        (true, 0.0),
    ];
    for &(ru, su) in &reach_u {
        for &(rv, sv) in &reach_v {
            if !(ru && rv) || (su == 0.0 && sv == 0.0) {
                continue;
            }
            // A point just past that side or corner, by a's own size.
            let past = |side: f64, range: [f64; 2], x: I| {
                if side < 0.0 {
                    range[0] - 0.25 * x.width()
                } else if side > 0.0 {
                    range[1] + 0.25 * x.width()
                } else {
                    x.mid()
                }
            };
            let (pu, pv) = (past(su, d.u, a.u), past(sv, d.v, a.v));
            let step = 1e-3 * a.u.width().min(a.v.width());
            let Some(g) = glued(surface, a.patch, pu, pv, step) else {
                continue;
            };

            if g.patch != b.patch {
                continue;
            }
            let (bu, bv) = g.preimage(b.u, b.v, slack(surface, a.patch));
            let seen = Rect {
                patch: a.patch,
                u: bu,
                v: bv,
            };
            // Only the copy of b beyond this side or corner counts here.
            let beyond = (su == 0.0
                || (su < 0.0 && bu.lo() < d.u[0])
                || (su > 0.0 && bu.hi() > d.u[1]))
                && (sv == 0.0 || (sv < 0.0 && bv.lo() < d.v[0]) || (sv > 0.0 && bv.hi() > d.v[1]));
            if !beyond || !a.touches(&seen) || (bu.width() > eu) || (bv.width() > ev) {
                continue;
            }
            touching = true;
            let (u, v) = (a.u.union(bu), a.v.union(bv));
            if tangents(proj, a.patch, u, v).is_some_and(|(du, dv)| immersed(du, dv)) {
                return Near::Free;
            }
        }
    }
    if touching { Near::Unsure } else { Near::Apart }
}

/// Whether f_u × f_v over the box excludes 0: no branch point in it.
pub(super) fn regular_box(proj: &Projector, r: &Rect) -> bool {
    let im = proj.image(r.patch, r.u, r.v);
    immersed(im.du, im.dv)
}

/// The pole discs of a surface's patches, their tests remembered.
pub(super) struct Poles {
    /// Per patch, its pole sides.
    sides: Vec<Vec<Side>>,
    tested: std::sync::Mutex<std::collections::HashMap<(usize, u8, u64), bool>>,
}

/// Pieces around the pole for the disc test, at most (doubled from 16 until it passes).
const DISC_PIECES: usize = 1024;

impl Poles {
    /// The pole sides of `surface` whose along direction is periodic.
    pub fn new(surface: &Surface) -> Self {
        let sides = (0..surface.patch_count())
            .map(|k| {
                let d = surface.domain(k);
                Side::ALL
                    .into_iter()
                    .filter(|&s| {
                        let along = match s {
                            Side::U0 | Side::U1 => [Side::V0, Side::V1],
                            Side::V0 | Side::V1 => [Side::U0, Side::U1],
                        };
                        matches!(d.side(s), SideRule::Pole)
                            && matches!(d.side(along[0]), SideRule::Glued(g) if g.len() == 1
                                && g[0].patch == k && g[0].side == along[1] && !g[0].reversed
                                && g[0].from == 0.0 && g[0].to == 1.0 && g[0].offset == 0.0)
                    })
                    .collect()
            })
            .collect();
        Poles {
            sides,
            tested: Default::default(),
        }
    }

    /// When a and b both lie in a disc around a pole of their patch (at most half the
    /// patch across) and one of them reaches it: whether that disc is proven free of
    /// double points.
    fn disc(&self, proj: &Projector, a: &Rect, b: &Rect) -> Option<bool> {
        let d = proj.surface.domain(a.patch);
        for &side in &self.sides[a.patch] {
            let (reach, extent) = match side {
                Side::U0 => (a.u.hi().max(b.u.hi()) - d.u[0], d.u[1] - d.u[0]),
                Side::U1 => (d.u[1] - a.u.lo().min(b.u.lo()), d.u[1] - d.u[0]),
                Side::V0 => (a.v.hi().max(b.v.hi()) - d.v[0], d.v[1] - d.v[0]),
                Side::V1 => (d.v[1] - a.v.lo().min(b.v.lo()), d.v[1] - d.v[0]),
            };
            let at_pole = |r: &Rect| match side {
                Side::U0 => r.u.lo() == d.u[0],
                Side::U1 => r.u.hi() == d.u[1],
                Side::V0 => r.v.lo() == d.v[0],
                Side::V1 => r.v.hi() == d.v[1],
            };
            if reach <= 0.5 * extent && (at_pole(a) || at_pole(b)) {
                let key = (a.patch, side as u8, reach.to_bits());
                if let Some(&known) = self.tested.lock().unwrap().get(&key) {
                    return Some(known);
                }
                let free = disc_free(proj, a.patch, side, reach);
                self.tested.lock().unwrap().insert(key, free);
                return Some(free);
            }
        }
        None
    }
}

/// The disc test around the pole `side` of `patch`, of radius `reach` in the radial
/// parameter (see the module documentation).
fn disc_free(proj: &Projector, patch: usize, side: Side, reach: f64) -> bool {
    let d = proj.surface.domain(patch);
    let radial_u = matches!(side, Side::U0 | Side::U1);
    let (radial, along) = if radial_u { (d.u, d.v) } else { (d.v, d.u) };
    let band = match side {
        Side::U0 | Side::V0 => I::new(radial[0], radial[0] + reach),
        Side::U1 | Side::V1 => I::new(radial[1] - reach, radial[1]),
    };
    let extent = along[1] - along[0];
    // f_φ / ρ = (ev / 2π) f_v / ρ.
    let per_radian = I::point(extent) / (I::PI * I::point(2.0));
    let mut n = 16;
    while n <= DISC_PIECES {
        let mut hull: Option<(V3, V3)> = None;
        for k in 0..n {
            let lo = along[0] + extent * k as f64 / n as f64;
            let hi = if k + 1 == n {
                along[1]
            } else {
                along[0] + extent * (k + 1) as f64 / n as f64
            };
            let piece = I::new(lo, hi);
            let im: Image = if radial_u {
                proj.image(patch, band, piece)
            } else {
                proj.image(patch, piece, band)
            };
            let (radial_d, cross_d) = if radial_u {
                (im.du, im.duv)
            } else {
                (im.dv, im.duv)
            };
            let phi = (piece - I::point(along[0])) * (I::PI * I::point(2.0)) / I::point(extent);
            let (s, c) = phi.sin_cos();
            let b = scale(per_radian, cross_d);
            let x: V3 = std::array::from_fn(|i| c * radial_d[i] - s * b[i]);
            let y: V3 = std::array::from_fn(|i| s * radial_d[i] + c * b[i]);
            hull = Some(match hull {
                None => (x, y),
                Some((hx, hy)) => (super::system::union(hx, x), super::system::union(hy, y)),
            });
        }
        let (x, y) = hull.expect("16 pieces or more");
        if immersed(x, y) {
            return true;
        }
        n *= 2;
    }
    false
}

/// A branch point (cross-cap) proven the only one in its box.
#[derive(Clone, Copy, Debug)]
pub(super) struct BranchPoint {
    /// The patch whose continued chart the box is in.
    pub patch: usize,
    /// Its parameters in that chart, enclosed.
    pub u: I,
    /// See `u`.
    pub v: I,
    /// The box (in that chart) in which it is the only point where the rank of Df drops.
    pub unique: Rect,
    /// Its 3D point, enclosed.
    pub point: V3,
}

/// The branch point in `r` grown by a quarter of its size on each side (into the patch's
/// continued chart past a glued side), if one is proven the only point of the grown box
/// where Df's rank drops.
pub(super) fn branch_point(proj: &Projector, r: &Rect) -> Option<BranchPoint> {
    let grow = |x: I| {
        let m = 0.25 * x.width();
        I::new(x.lo() - m, x.hi() + m)
    };
    let d = proj.surface.domain(r.patch);
    let clip = |x: I, range: [f64; 2]| I::new(x.lo().max(range[0]), x.hi().min(range[1]));
    let grown = Rect {
        patch: r.patch,
        u: grow(r.u),
        v: grow(r.v),
    };
    // Past an open side or a pole the box stays in the patch.
    let bx = if image_continued(proj, r.patch, grown.u, grown.v).is_some() {
        grown
    } else {
        Rect {
            patch: r.patch,
            u: clip(grown.u, d.u),
            v: clip(grown.v, d.v),
        }
    };
    let im = image_continued(proj, bx.patch, bx.u, bx.v)?;
    // f_v = λ f_u where f_u is nonzero over the box (else f_u = λ f_v): λ's range over the
    // box, so that every rank drop in the box has its λ there.
    let swap = if nonzero(&im.du) {
        false
    } else if nonzero(&im.dv) {
        true
    } else {
        return None;
    };
    let lead_other = |im: &Image| if swap { (im.dv, im.du) } else { (im.du, im.dv) };
    let (lead, other) = lead_other(&im);
    let dot = |a: V3, b: V3| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let lambda = dot(other, lead) / dot(lead, lead);
    if !lambda.is_bounded() {
        return None;
    }
    // Widened, so that Krawczyk's image can fall inside it (a wider range still holds
    // every λ of the box).
    let r = 2.0 * lambda.width() + 1e-6 * (1.0 + lambda.mag());
    let lambda = I::new(lambda.lo() - r, lambda.hi() + r);
    let mut z = [bx.u, bx.v, lambda];
    for _ in 0..8 {
        let im = image_continued(proj, bx.patch, z[0], z[1])?;
        let (lead, _) = lead_other(&im);
        let lam = z[2];
        // h = other - λ lead in (u, v, λ): ∂h/∂u, ∂h/∂v from the second derivatives.
        let (hu, hv): (V3, V3) = if swap {
            (
                std::array::from_fn(|i| im.duu[i] - lam * im.duv[i]),
                std::array::from_fn(|i| im.duv[i] - lam * im.dvv[i]),
            )
        } else {
            (
                std::array::from_fn(|i| im.duv[i] - lam * im.duu[i]),
                std::array::from_fn(|i| im.dvv[i] - lam * im.duv[i]),
            )
        };
        let m = std::array::from_fn(|row| [hu[row], hv[row], -lead[row]]);
        let pre = regular(&m)?;
        let c = z.map(I::mid);
        let at = image_continued(proj, bx.patch, I::point(c[0]), I::point(c[1]))?;
        let (la, oa) = lead_other(&at);
        let g: V3 = std::array::from_fn(|i| oa[i] - I::point(c[2]) * la[i]);
        match krawczyk(z, c, g, &pre) {
            Krawczyk::None => return None,
            Krawczyk::One(k) => {
                // Its 3D point: the image of its box, or (a box too small to follow across
                // a glued corner) the mean-value form about the box's middle, moved onto its
                // patch by the glue rule.
                let point = match image_continued(proj, bx.patch, k[0], k[1]) {
                    Some(at) => at.p,
                    None => {
                        let (p, u, v, _) = proj.surface.chart(bx.patch, k[0].mid(), k[1].mid());
                        let at = proj.image(p, I::point(u), I::point(v));
                        let (du, dv) = (k[0] - I::point(k[0].mid()), k[1] - I::point(k[1].mid()));
                        let slack = I::new(-1e-12, 1e-12);
                        std::array::from_fn(|c| {
                            at.p[c]
                                + im.du[c] * du
                                + im.dv[c] * dv
                                + slack * (I::point(1.0) + at.p[c].abs())
                        })
                    }
                };
                return Some(BranchPoint {
                    patch: bx.patch,
                    u: k[0],
                    v: k[1],
                    unique: bx,
                    point,
                });
            }
            Krawczyk::Unknown(k) => z = k,
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::view::View;

    #[test]
    fn seam_pairs_of_the_flat_torus_are_free() {
        let s: Surface =
            serde_json::from_value(serde_json::json!({"type": "flat_torus", "r1": 1.0, "r2": 1.0}))
                .unwrap();
        let mut view = View::default();
        view.rotation.yw = 30.0;
        let proj = Projector::new(&s, &view);
        let poles = Poles::new(&s);
        let tau = std::f64::consts::TAU;
        let h = 0.01;
        let a = Rect {
            patch: 0,
            u: I::new(tau - h, tau),
            v: I::new(1.0, 1.0 + h),
        };
        let b = Rect {
            patch: 0,
            u: I::new(0.0, h),
            v: I::new(1.0, 1.0 + h),
        };
        let c = Rect {
            patch: 0,
            u: I::new(1.0, 1.0 + h),
            v: I::new(tau - h, tau),
        };
        let d = Rect {
            patch: 0,
            u: I::new(1.0, 1.0 + h),
            v: I::new(0.0, h),
        };
        let e = Rect {
            patch: 0,
            u: I::new(tau - h, tau),
            v: I::new(tau - h, tau),
        };
        let f = Rect {
            patch: 0,
            u: I::new(0.0, h),
            v: I::new(0.0, h),
        };
        assert_eq!(near(&proj, &a, &b, &poles), Near::Free);
        assert_eq!(near(&proj, &b, &a, &poles), Near::Free);
        assert_eq!(near(&proj, &c, &d, &poles), Near::Free);
        for (u, v) in [
            (0.0, 0.0),
            (std::f64::consts::PI, 0.0),
            (0.0, 3.0),
            (3.0, 0.0),
            (3.0, 3.0),
        ] {
            let r = Rect {
                patch: 0,
                u: I::new(u - 1e-3, u + 1e-3),
                v: I::new(v - 1e-3, v + 1e-3),
            };
            let r = Rect {
                patch: 0,
                u: I::new(r.u.lo().max(0.0), r.u.hi()),
                v: I::new(r.v.lo().max(0.0), r.v.hi()),
            };
            let near_pi = |x: f64| x == 0.0 || x == std::f64::consts::PI;
            assert_eq!(
                branch_point(&proj, &r).is_some(),
                near_pi(u) && near_pi(v),
                "({u}, {v})"
            );
        }
        // The corner (0, 0) is a cross-cap of this view: seen as touching, not shown free.
        assert_eq!(near(&proj, &e, &f, &poles), Near::Unsure);
        assert_eq!(near(&proj, &f, &e, &poles), Near::Unsure);
    }
}
