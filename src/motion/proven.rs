//! The critical points of a height h = ⟨n, X⟩ proven on the true surface by interval
//! arithmetic: every box of parameters either holds none (its enclosure of ∇h misses 0), or
//! holds exactly one (Krawczyk's operator maps it into itself), or is cut again; what is
//! left at the depth limit or past the budget is named undecided. A mesh finds critical
//! points at its critical vertices and misses a pair (a birth beside a saddle) that falls
//! between its vertices; the proof finds them.
//!
//! **Exclusion.** Over a box the enclosures ([`Surface::enclose`]) of h_u = ⟨n, X_u⟩ and
//! h_v = ⟨n, X_v⟩: where one misses 0 the box holds no critical point. Along a pole side
//! (u = u0 say) the whole side is one point and X_v vanishes there, so h_v holds 0 over any
//! box that touches it; h_v / (u - u0) lies in the enclosure of h_uv over the box (h_v is 0
//! on the side), and the box holds no critical point where that misses 0: not off the
//! side, and not at the pole, where (h_u, h_v / (u - u0)) is h's gradient in the chart
//! (u - u0)(cos v, sin v) up to a turn.
//!
//! **Existence and uniqueness.** Krawczyk's operator K(X) = m - Y ∇h(m) + (I - Y H(X))(X - m)
//! for the box X widened by a quarter of its size on each side (the formula goes on past a
//! glued side, so a point on a seam lies inside it), m its centre, H(X) the enclosure of h's
//! Hessian over it and Y the inverse of the Hessian at m: K(X) inside X proves exactly one
//! critical point in X, in K(X); K(X) missing X proves none. The proven point is iterated
//! down to rounding; a box claims it when it lies in the box (points on a cut are claimed by
//! both boxes and kept once). Its event is proven where the enclosure of the Hessian's
//! determinant over the final K(X) has a sign: negative a saddle, positive a birth or a
//! death by the sign of h_uu.
//!
//! Boxes are cut across the parameter along which their image is longer, at
//! `SPLIT` (0.5371) of the way, so that symmetric points do not fall on the cuts.
//!
//! **The boundary.** On a surface with open sides, the critical points of h along them and
//! its corners are proven as well, by the same tests in one variable
//! ([`super::boundary`]).

use super::{Critical, Event};
use crate::surfaces::{Interval, Jet, Side, SideRule, Surface};
use glam::DVec4;
use serde::Serialize;

/// Where a box is cut along its longer side, as a share of it.
pub(super) const SPLIT: f64 = 0.5371;

/// Cells per side of a patch to start from.
pub(super) const START: usize = 8;

/// Cuts below a starting cell before a box is left undecided.
pub(super) const DEPTH: usize = 40;

/// Boxes examined, at most, per surface.
pub const BUDGET: usize = 400_000;

/// Krawczyk steps that tighten a proven point.
pub(super) const TIGHTEN: usize = 8;

/// A critical point proven on the surface.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ProvenPoint {
    /// The patch.
    pub patch: usize,
    /// Its parameters, enclosed.
    pub u: Interval,
    /// Its parameters, enclosed.
    pub v: Interval,
    /// The surface point at the enclosure's centre.
    pub point: DVec4,
    /// Its level h there.
    pub level: f64,
    /// Its event, where the Hessian's sign is proven (else `None`: degenerate or too close
    /// to call).
    pub event: Option<Event>,
}

/// A box of parameters left undecided.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Undecided {
    /// The patch.
    pub patch: usize,
    /// Its range of u.
    pub u: Interval,
    /// Its range of v.
    pub v: Interval,
}

/// The critical points of h proven on a surface.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ProvenCritical {
    /// Whether every box was decided: then `points` are all the critical points of h.
    pub complete: bool,
    /// The points proven, by level.
    pub points: Vec<ProvenPoint>,
    /// The boxes left undecided (the first 16), and how many there were.
    pub undecided: Vec<Undecided>,
    /// Boxes left undecided.
    pub undecided_boxes: usize,
    /// Boxes examined.
    pub boxes: usize,
    /// Milliseconds the proof took.
    pub ms: f64,
    /// The surface's bounding diagonal, the scale of `SAME`.
    #[serde(skip)]
    pub diagonal: f64,
}

/// Two critical points closer than this share of the surface's diagonal are one.
const SAME: f64 = 1e-6;

impl ProvenCritical {
    /// The points proven that `critical` (found on a mesh) has none at.
    pub fn missed<'a>(&'a self, critical: &'a Critical) -> impl Iterator<Item = &'a ProvenPoint> {
        self.points.iter().filter(move |p| {
            !critical
                .points
                .iter()
                .any(|q| q.point.distance(p.point) <= SAME * self.diagonal)
        })
    }

    /// Whether the critical points found on a mesh are the ones proven: none missed and,
    /// where the proof is complete, none more. Else what differs.
    pub fn agrees(&self, critical: &Critical) -> Result<(), String> {
        let missed: Vec<&ProvenPoint> = self.missed(critical).collect();
        let extra = critical
            .points
            .iter()
            .filter(|q| {
                !self
                    .points
                    .iter()
                    .any(|p| q.point.distance(p.point) <= SAME * self.diagonal)
            })
            .count();
        if !missed.is_empty() {
            let levels: Vec<String> = missed
                .iter()
                .take(4)
                .map(|p| {
                    let event = p.event.map_or("critical point", Event::name);
                    format!("a {event} at level {:.6}", p.level)
                })
                .collect();
            return Err(format!(
                "the surface has {} critical point(s) between the mesh's vertices ({}{}): \
                 the mesh's slices miss their events",
                missed.len(),
                levels.join(", "),
                if missed.len() > 4 { ", …" } else { "" }
            ));
        }
        if self.complete && extra > 0 {
            return Err(format!(
                "{extra} critical point(s) refined on the mesh are not among the {} proven on \
                 the surface",
                self.points.len()
            ));
        }
        Ok(())
    }
}

/// ⟨n, ·⟩ over a jet's four coordinates: h's own jet.
pub(super) fn height(j: &[Jet<Interval>; 4], n: DVec4) -> Jet<Interval> {
    let n = n.to_array().map(Interval::point);
    let dot = |f: fn(&Jet<Interval>) -> Interval| {
        (0..4).fold(Interval::point(0.0), |acc, i| acc + n[i] * f(&j[i]))
    };
    Jet {
        v: dot(|j| j.v),
        du: dot(|j| j.du),
        dv: dot(|j| j.dv),
        duu: dot(|j| j.duu),
        duv: dot(|j| j.duv),
        dvv: dot(|j| j.dvv),
    }
}

/// What Krawczyk's operator proves of a box.
enum Krawczyk {
    /// No critical point in it.
    None,
    /// Exactly one, in these (u, v) enclosures.
    One(Interval, Interval),
    /// Neither.
    Unknown,
}

/// Krawczyk's operator on ∇h over the box `u` x `v` of `patch` (see the module's notes).
fn krawczyk(surface: &Surface, patch: usize, n: DVec4, u: Interval, v: Interval) -> Krawczyk {
    let (mu, mv) = (u.mid(), v.mid());
    let at = height(
        &surface.enclose(patch, Interval::point(mu), Interval::point(mv)),
        n,
    );
    let over = height(&surface.enclose(patch, u, v), n);
    // The inverse of the Hessian at the centre.
    let (a, b, c) = (at.duu.mid(), at.duv.mid(), at.dvv.mid());
    let det = a * c - b * b;
    if !(det.is_finite() && det != 0.0) {
        return Krawczyk::Unknown;
    }
    let y = [[c / det, -b / det], [-b / det, a / det]].map(|r| r.map(Interval::point));
    let one = Interval::point(1.0);
    let h = [[over.duu, over.duv], [over.duv, over.dvv]];
    let g = [at.du, at.dv];
    let d = [u - Interval::point(mu), v - Interval::point(mv)];
    let m = [Interval::point(mu), Interval::point(mv)];
    let k: [Interval; 2] = std::array::from_fn(|i| {
        let yg = y[i][0] * g[0] + y[i][1] * g[1];
        let row: [Interval; 2] = std::array::from_fn(|j| {
            let yh = y[i][0] * h[0][j] + y[i][1] * h[1][j];
            if i == j {
                one - yh
            } else {
                Interval::point(0.0) - yh
            }
        });
        m[i] - yg + row[0] * d[0] + row[1] * d[1]
    });
    if !k.iter().all(|x| x.is_bounded()) {
        return Krawczyk::Unknown;
    }
    if !k[0].meets(u) || !k[1].meets(v) {
        Krawczyk::None
    } else if u.holds_inside(k[0]) && v.holds_inside(k[1]) {
        Krawczyk::One(k[0], k[1])
    } else {
        Krawczyk::Unknown
    }
}

/// The critical points of h = ⟨n, X⟩ (n a unit vector) on `surface`, proven (see the
/// module's notes), within `budget` boxes.
pub fn prove(surface: &Surface, n: DVec4, budget: usize) -> ProvenCritical {
    let started = std::time::Instant::now();
    let mut out = ProvenCritical {
        complete: true,
        points: Vec::new(),
        undecided: Vec::new(),
        undecided_boxes: 0,
        boxes: 0,
        ms: 0.0,
        diagonal: crate::sample::bounding_diagonal(surface),
    };
    let diagonal = out.diagonal;
    for patch in 0..surface.patch_count() {
        let domain = surface.domain(patch);
        let pole = |s: Side| matches!(domain.side(s), SideRule::Pole);
        let cell = |r: [f64; 2], k: usize| {
            Interval::new(
                r[0] + (r[1] - r[0]) * k as f64 / START as f64,
                if k + 1 == START {
                    r[1]
                } else {
                    r[0] + (r[1] - r[0]) * (k + 1) as f64 / START as f64
                },
            )
        };
        let mut stack: Vec<(Interval, Interval, usize)> = (0..START * START)
            .map(|k| (cell(domain.u, k % START), cell(domain.v, k / START), 0))
            .collect();
        while let Some((u, v, depth)) = stack.pop() {
            // Past the budget every box left is counted undecided, once.
            if out.boxes >= budget {
                out.complete = false;
                out.undecided_boxes += 1;
                continue;
            }
            out.boxes += 1;
            let j = height(&surface.enclose(patch, u, v), n);
            // Along a pole side the gradient's part along the side is divided by the
            // distance from it (the module's notes).
            let on_u_pole = (pole(Side::U0) && u.lo() <= domain.u[0])
                || (pole(Side::U1) && u.hi() >= domain.u[1]);
            let on_v_pole = (pole(Side::V0) && v.lo() <= domain.v[0])
                || (pole(Side::V1) && v.hi() >= domain.v[1]);
            let gu = if on_v_pole { j.duv } else { j.du };
            let gv = if on_u_pole { j.duv } else { j.dv };
            if !gu.contains(0.0) || !gv.contains(0.0) {
                continue;
            }
            if !on_u_pole && !on_v_pole {
                let widen = |x: Interval| {
                    let w = 0.25 * x.width();
                    Interval::new(x.lo() - w, x.hi() + w)
                };
                match krawczyk(surface, patch, n, widen(u), widen(v)) {
                    Krawczyk::None => continue,
                    Krawczyk::One(ku, kv) => {
                        let (ku, kv) = tighten(surface, patch, n, ku, kv);
                        // Claimed where it meets this box (both boxes at a cut) and its
                        // centre is on the patch (past an open side the formula's points
                        // are not the surface's; past a glued one the other patch claims).
                        let on_patch = Interval::hull(domain.u[0], domain.u[1]).contains(ku.mid())
                            && Interval::hull(domain.v[0], domain.v[1]).contains(kv.mid());
                        if u.meets(ku) && v.meets(kv) && on_patch {
                            claim(&mut out.points, surface, patch, n, (ku, kv), diagonal);
                        }
                        continue;
                    }
                    Krawczyk::Unknown => {}
                }
            }
            if depth >= DEPTH {
                out.complete = false;
                out.undecided_boxes += 1;
                if out.undecided.len() < 16 {
                    out.undecided.push(Undecided { patch, u, v });
                }
                continue;
            }
            // Cut across the parameter whose image is longer.
            let e = surface.eval(patch, u.mid(), v.mid());
            let cut = |x: Interval| {
                let at = x.lo() + SPLIT * x.width();
                (Interval::new(x.lo(), at), Interval::new(at, x.hi()))
            };
            if e.du.length() * u.width() >= e.dv.length() * v.width() {
                let (a, b) = cut(u);
                stack.push((a, v, depth + 1));
                stack.push((b, v, depth + 1));
            } else {
                let (a, b) = cut(v);
                stack.push((u, a, depth + 1));
                stack.push((u, b, depth + 1));
            }
        }
    }
    // The boundary's points, proven along the open sides, within what is left of the
    // budget.
    let sides = super::boundary::prove(surface, n, budget.saturating_sub(out.boxes));
    out.boxes += sides.boxes;
    out.undecided_boxes += sides.undecided_boxes;
    if sides.undecided_boxes > 0 {
        out.complete = false;
    }
    for (patch, u, v) in sides.undecided {
        if out.undecided.len() < 16 {
            out.undecided.push(Undecided { patch, u, v });
        }
    }
    for (patch, u, v, event) in sides.points {
        let p = surface.eval(patch, u.mid(), v.mid()).p;
        if !out
            .points
            .iter()
            .any(|q| q.point.distance(p) <= 1e-9 * diagonal)
        {
            out.points.push(ProvenPoint {
                patch,
                u,
                v,
                point: p,
                level: p.dot(n),
                event,
            });
        }
    }
    out.points.sort_by(|a, b| a.level.total_cmp(&b.level));
    out.ms = started.elapsed().as_secs_f64() * 1e3;
    out
}

/// Krawczyk's operator applied again to its own result (within it: the point stays
/// there), while it shrinks.
fn tighten(
    surface: &Surface,
    patch: usize,
    n: DVec4,
    mut u: Interval,
    mut v: Interval,
) -> (Interval, Interval) {
    for _ in 0..TIGHTEN {
        let Krawczyk::One(a, b) = krawczyk(surface, patch, n, u, v) else {
            break;
        };
        let (Some(a), Some(b)) = (a.intersect(u), b.intersect(v)) else {
            break;
        };
        if a.width() >= u.width() && b.width() >= v.width() {
            break;
        }
        (u, v) = (a, b);
    }
    (u, v)
}

/// Adds the point proven in `(u, v)` of `patch`, unless one at its place is there already
/// (a point on a cut or a seam, proven from both sides).
fn claim(
    points: &mut Vec<ProvenPoint>,
    surface: &Surface,
    patch: usize,
    n: DVec4,
    (u, v): (Interval, Interval),
    diagonal: f64,
) {
    let e = surface.eval(patch, u.mid(), v.mid());
    if points
        .iter()
        .any(|p| p.point.distance(e.p) <= 1e-9 * diagonal)
    {
        return;
    }
    let h = height(&surface.enclose(patch, u, v), n);
    let det = h.duu * h.dvv - h.duv * h.duv;
    let event = if det.hi() < 0.0 {
        Some(Event::Saddle)
    } else if det.lo() > 0.0 && h.duu.lo() > 0.0 {
        Some(Event::Birth)
    } else if det.lo() > 0.0 && h.duu.hi() < 0.0 {
        Some(Event::Death)
    } else {
        None
    };
    points.push(ProvenPoint {
        patch,
        u,
        v,
        point: e.p,
        level: e.p.dot(n),
        event,
    });
}
