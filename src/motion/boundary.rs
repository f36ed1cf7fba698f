//! Critical points of a height h = ⟨n, X⟩ on a surface's boundary (its open sides): Morse
//! theory for surfaces with boundary. Where h restricted to the boundary has a minimum or a
//! maximum, the slices change as the gradient of h points into the surface or out of it:
//!
//! | along the boundary | h rises into the surface | h falls into the surface |
//! |---|---|---|
//! | minimum | an arc is born ([`Event::BoundaryBirth`], +1 to χ) | a curve is cut there ([`Event::BoundarySplit`]) |
//! | maximum | two ends of arcs join ([`Event::BoundaryJoin`], −1 to χ) | an arc dies ([`Event::BoundaryDeath`]) |
//!
//! With the interior points, #births − #saddles + #deaths + #boundary births − #boundary
//! joins = χ (the sublevel sets {h ≤ c} change their Euler characteristic only at the
//! interior points and where h rises into the surface). A corner of two open sides is a
//! boundary birth where h rises along both sides away from it, a boundary death where it
//! falls along both, and no critical point otherwise.
//!
//! **Refined** from a boundary vertex of the mesh by Newton's method on the derivative of h
//! along the side (a step past a glued end continues on the patch it is glued to, along
//! that patch's open side); a corner is its own point. **Proven** over the open sides by
//! interval arithmetic as the interior is ([`super::proven`]): a box of the side's
//! parameter holds no point where the enclosure of h's derivative along the side misses 0,
//! exactly one where Krawczyk's operator maps it into itself; its event is proven where the
//! second derivative along the side and the derivative into the surface have a sign.

use super::{CriticalPoint, Event};
use crate::surfaces::{Interval, Side, SideRule, Surface};
use glam::DVec4;

/// A point within this share of its patch's extent from a side lies on it.
const ON_SIDE: f64 = 1e-12;

/// The open sides of `patch` that the parameters `uv` lie on: none inside, one on a side,
/// two at a corner of two open sides.
pub(super) fn open_sides(surface: &Surface, patch: usize, [u, v]: [f64; 2]) -> Vec<Side> {
    let d = surface.domain(patch);
    let near = |x: f64, r: [f64; 2], end: usize| (x - r[end]).abs() <= ON_SIDE * (r[1] - r[0]);
    Side::ALL
        .into_iter()
        .filter(|&s| matches!(d.side(s), SideRule::Open))
        .filter(|&s| match s {
            Side::U0 => near(u, d.u, 0),
            Side::U1 => near(u, d.u, 1),
            Side::V0 => near(v, d.v, 0),
            Side::V1 => near(v, d.v, 1),
        })
        .collect()
}

/// Along side `side`: whether its coordinate is u (a v side), and the sign of the other
/// coordinate's step into the surface.
fn along(side: Side) -> (bool, f64) {
    match side {
        Side::U0 => (false, 1.0),
        Side::U1 => (false, -1.0),
        Side::V0 => (true, 1.0),
        Side::V1 => (true, -1.0),
    }
}

/// The event of a critical point of h along a boundary side, from h's second derivative
/// along it and its derivative into the surface, with their sizes for the degenerate test.
fn event_on_side(second: f64, inward: f64, (size2, size1): (f64, f64)) -> Event {
    if !(second.abs() > super::DEGENERATE * size2 && inward.abs() > super::DEGENERATE * size1) {
        return Event::Degenerate;
    }
    side_event(second > 0.0, inward > 0.0)
}

/// The event of a critical point along a side: a minimum along it (else a maximum) where h
/// rises into the surface (else falls).
fn side_event(minimum: bool, rises: bool) -> Event {
    match (minimum, rises) {
        (true, true) => Event::BoundaryBirth,
        (true, false) => Event::BoundarySplit,
        (false, true) => Event::BoundaryJoin,
        (false, false) => Event::BoundaryDeath,
    }
}

/// The sign of an enclosure: `Some(true)` positive, `Some(false)` negative, `None` where it
/// holds 0.
fn sign(x: Interval) -> Option<bool> {
    if x.lo() > 0.0 {
        Some(true)
    } else if x.hi() < 0.0 {
        Some(false)
    } else {
        None
    }
}

/// The event of a corner from h's derivatives along its two sides away from it: `None`
/// where one rises and the other falls (no critical point).
fn corner_event(a: f64, b: f64) -> Option<Event> {
    if a == 0.0 || b == 0.0 || !(a.is_finite() && b.is_finite()) {
        Some(Event::Degenerate)
    } else if a > 0.0 && b > 0.0 {
        Some(Event::BoundaryBirth)
    } else if a < 0.0 && b < 0.0 {
        Some(Event::BoundaryDeath)
    } else {
        None
    }
}

/// The derivative of h away from a corner along each of its two sides `sides`.
fn away(sides: &[Side], du: f64, dv: f64) -> [f64; 2] {
    std::array::from_fn(|k| {
        // Along side k is the other side's inward direction.
        let (on_u, sign) = along(sides[1 - k]);
        sign * if on_u { dv } else { du }
    })
}

/// The critical point of h on the boundary that Newton's method on h's derivative along the
/// side reaches from `start` (a boundary vertex's parameters): `None` where `start` lies on
/// no open side, the step leaves the boundary or it does not converge. A corner of two open
/// sides is its own point, where h rises or falls along both sides away from it.
pub(super) fn newton(surface: &Surface, n: DVec4, start: CriticalPoint) -> Option<CriticalPoint> {
    let (mut patch, [mut u, mut v]) = (start.patch, start.uv);
    let sides = open_sides(surface, patch, [u, v]);
    if sides.len() == 2 {
        let e = surface.eval(patch, u, v);
        let [a, b] = away(&sides, n.dot(e.du), n.dot(e.dv));
        return corner_event(a, b).map(|event| CriticalPoint {
            event,
            level: n.dot(e.p),
            point: e.p,
            residual: 0.0,
            refined: true,
            ..start
        });
    }
    let mut polish = super::Polish::default();
    for _ in 0..super::NEWTON_STEPS {
        let [side] = open_sides(surface, patch, [u, v])[..] else {
            break;
        };
        let (on_u, inward) = along(side);
        let e = surface.eval(patch, u, v);
        let (t, second, normal, d2) = if on_u {
            (e.du, n.dot(e.duu), n.dot(e.dv), e.duu)
        } else {
            (e.dv, n.dot(e.dvv), n.dot(e.du), e.dvv)
        };
        let first = n.dot(t);
        let residual = first.abs() / t.length();
        let across = if on_u { e.dv } else { e.du };
        let done = polish.offer(&start, (patch, [u, v]), n.dot(e.p), e.p, residual, || {
            event_on_side(second, inward * normal, (d2.length(), across.length()))
        });
        if done {
            break;
        }
        if second == 0.0 || !second.is_finite() {
            break;
        }
        let step = -first / second;
        let (nu, nv) = if on_u { (u + step, v) } else { (u, v + step) };
        let (p, nu, nv, inside) = surface.chart(patch, nu, nv);
        if !(inside && nu.is_finite() && nv.is_finite()) {
            break;
        }
        (patch, u, v) = (p, nu, nv);
    }
    polish.best
}

/// The points to sample a surface through for a critical point `uv` of `patch` on its open
/// side `side`: the point, one `distance` away along the side either way (h differs from
/// the point's there by its second derivative along the side) and one `distance` into the
/// surface (by its derivative into it), so that the point is a boundary vertex of its own
/// event.
pub(super) fn beside(
    surface: &Surface,
    patch: usize,
    [u, v]: [f64; 2],
    side: Side,
    distance: f64,
) -> Vec<(usize, [f64; 2])> {
    let e = surface.eval(patch, u, v);
    let (on_u, inward) = along(side);
    let (t, across) = if on_u { (e.du, e.dv) } else { (e.dv, e.du) };
    let (r, r_in) = (distance / t.length(), inward * distance / across.length());
    let mut out = vec![(patch, [u, v])];
    if !(r.is_finite() && r_in.is_finite()) {
        return out;
    }
    let step = |a: f64, b: f64| {
        if on_u {
            (patch, [u + a, v + b])
        } else {
            (patch, [u + b, v + a])
        }
    };
    out.extend([step(r, 0.0), step(-r, 0.0), step(0.0, r_in)]);
    out
}

/// What the proof of the boundary found: points (patch, parameters, event where proven),
/// boxes examined, and the boxes left undecided (patch, parameters).
#[derive(Default)]
pub(super) struct SideProof {
    pub points: Vec<(usize, Interval, Interval, Option<Event>)>,
    pub boxes: usize,
    pub undecided: Vec<(usize, Interval, Interval)>,
    pub undecided_boxes: usize,
}

/// The critical points of h on the open sides of every patch of `surface`, and its corners
/// of two open sides, proven (the module's notes), within `budget` boxes.
pub(super) fn prove(surface: &Surface, n: DVec4, budget: usize) -> SideProof {
    let mut out = SideProof::default();
    for patch in 0..surface.patch_count() {
        let d = surface.domain(patch);
        let open = |s: Side| matches!(d.side(s), SideRule::Open);
        for side in Side::ALL.into_iter().filter(|&s| open(s)) {
            let (on_u, inward) = along(side);
            let (range, fixed) = match side {
                Side::U0 => (d.v, d.u[0]),
                Side::U1 => (d.v, d.u[1]),
                Side::V0 => (d.u, d.v[0]),
                Side::V1 => (d.u, d.v[1]),
            };
            let at = |t: Interval| {
                let f = Interval::point(fixed);
                let j = super::proven::height(
                    &if on_u {
                        surface.enclose(patch, t, f)
                    } else {
                        surface.enclose(patch, f, t)
                    },
                    n,
                );
                let [first, second, normal] = if on_u {
                    [j.du, j.duu, j.dv]
                } else {
                    [j.dv, j.dvv, j.du]
                };
                (first, second, Interval::point(inward) * normal)
            };
            let box_of = |t: Interval| {
                let f = Interval::point(fixed);
                if on_u { (t, f) } else { (f, t) }
            };
            let cells = super::proven::START;
            let mut stack: Vec<(Interval, usize)> = (0..cells)
                .map(|k| {
                    let x = |k: usize| range[0] + (range[1] - range[0]) * k as f64 / cells as f64;
                    let hi = if k + 1 == cells { range[1] } else { x(k + 1) };
                    (Interval::new(x(k), hi), 0)
                })
                .collect();
            while let Some((t, depth)) = stack.pop() {
                if out.boxes >= budget {
                    out.undecided_boxes += 1;
                    continue;
                }
                out.boxes += 1;
                if !at(t).0.contains(0.0) {
                    continue;
                }
                let w = 0.25 * t.width();
                let wide = Interval::new(t.lo() - w, t.hi() + w);
                match krawczyk(&at, wide) {
                    Some(None) => continue,
                    Some(Some(k)) => {
                        let k = tighten(&at, k);
                        if t.meets(k) && Interval::hull(range[0], range[1]).contains(k.mid()) {
                            let (_, second, normal) = at(k);
                            let event = sign(second)
                                .zip(sign(normal))
                                .map(|(minimum, rises)| side_event(minimum, rises));
                            let (u, v) = box_of(k);
                            out.points.push((patch, u, v, event));
                        }
                        continue;
                    }
                    None => {}
                }
                if depth >= super::proven::DEPTH {
                    out.undecided_boxes += 1;
                    let (u, v) = box_of(t);
                    out.undecided.push((patch, u, v));
                    continue;
                }
                let cut = t.lo() + super::proven::SPLIT * t.width();
                stack.push((Interval::new(t.lo(), cut), depth + 1));
                stack.push((Interval::new(cut, t.hi()), depth + 1));
            }
        }
        // The corners of two open sides.
        for (su, sv) in [
            (Side::U0, Side::V0),
            (Side::U1, Side::V0),
            (Side::U0, Side::V1),
            (Side::U1, Side::V1),
        ] {
            if !(open(su) && open(sv)) {
                continue;
            }
            out.boxes += 1;
            let u = Interval::point(if su == Side::U0 { d.u[0] } else { d.u[1] });
            let v = Interval::point(if sv == Side::V0 { d.v[0] } else { d.v[1] });
            let j = super::proven::height(&surface.enclose(patch, u, v), n);
            // Away from the corner along the v side is into the surface from the u side.
            let a = Interval::point(along(su).1) * j.du;
            let b = Interval::point(along(sv).1) * j.dv;
            let unit = |x: bool| if x { 1.0 } else { -1.0 };
            match (sign(a), sign(b)) {
                (Some(a), Some(b)) => {
                    if let Some(event) = corner_event(unit(a), unit(b)) {
                        out.points.push((patch, u, v, Some(event)));
                    }
                }
                _ => out.points.push((patch, u, v, None)),
            }
        }
    }
    out
}

/// Krawczyk's operator in one variable for the zero of h's derivative along the side over
/// `t` (`at` gives its enclosures): `Some(None)` proves none there, `Some(Some(k))` exactly
/// one, in k; `None` neither.
fn krawczyk(
    at: &impl Fn(Interval) -> (Interval, Interval, Interval),
    t: Interval,
) -> Option<Option<Interval>> {
    let m = t.mid();
    let (first, second, _) = at(Interval::point(m));
    let y = 1.0 / second.mid();
    if !(y.is_finite() && y != 0.0) {
        return None;
    }
    let (_, over, _) = at(t);
    let y = Interval::point(y);
    let m = Interval::point(m);
    let k = m - y * first + (Interval::point(1.0) - y * over) * (t - m);
    if !k.is_bounded() {
        None
    } else if !k.meets(t) {
        Some(None)
    } else if t.holds_inside(k) {
        Some(Some(k))
    } else {
        None
    }
}

/// Krawczyk's operator applied again to its own result while it shrinks.
fn tighten(at: &impl Fn(Interval) -> (Interval, Interval, Interval), mut t: Interval) -> Interval {
    for _ in 0..super::proven::TIGHTEN {
        let Some(Some(k)) = krawczyk(at, t) else {
            break;
        };
        let Some(k) = k.intersect(t) else {
            break;
        };
        if k.width() >= t.width() {
            break;
        }
        t = k;
    }
    t
}
