//! The side rules of the parameter rectangle: which sides are open, glued to each other or
//! to themselves, or collapsed to a pole; and what follows from them alone, without
//! evaluating a formula: the [`Domain`] the sampler walks, the surface's [`Topology`] and the
//! fewest cells across each parameter. Apart from the language: the same rules would serve
//! any surface given on one rectangle.

use super::{FormulaEdge, FormulaSeam, FormulaSides};
use crate::surfaces::{Domain, Glue, Side, SideRule, Topology};
use glam::DVec4;

/// The rule of one side once the keys are resolved.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Kind {
    Open,
    Pole,
    HalfTurn,
    Periodic,
    Flip,
}

impl FormulaSides {
    /// The rule of each side, in the order of [`Side::ALL`].
    pub(super) fn kinds(&self) -> [Kind; 4] {
        let pair = |both: Option<FormulaSeam>, lo: Option<FormulaEdge>, hi: Option<FormulaEdge>| {
            let one = |e: Option<FormulaEdge>| match e {
                None | Some(FormulaEdge::Open) => Kind::Open,
                Some(FormulaEdge::Pole) => Kind::Pole,
                Some(FormulaEdge::HalfTurn) => Kind::HalfTurn,
            };
            match both {
                Some(FormulaSeam::Periodic) => [Kind::Periodic; 2],
                Some(FormulaSeam::Flip) => [Kind::Flip; 2],
                Some(FormulaSeam::Open) => [Kind::Open; 2],
                None => [one(lo), one(hi)],
            }
        };
        let [u0, u1] = pair(self.u, self.u_min, self.u_max);
        let [v0, v1] = pair(self.v, self.v_min, self.v_max);
        [u0, u1, v0, v1]
    }

    /// The key that set the rule of `side`, as a path from the surface.
    pub(super) fn field(&self, side: Side) -> &'static str {
        match side {
            Side::U0 | Side::U1 if self.u.is_some() => "sides.u",
            Side::V0 | Side::V1 if self.v.is_some() => "sides.v",
            Side::U0 => "sides.u_min",
            Side::U1 => "sides.u_max",
            Side::V0 => "sides.v_min",
            Side::V1 => "sides.v_max",
        }
    }
}

/// The domain of the rectangle `ranges` (u, then v) with the sides' rules.
pub(super) fn domain(ranges: [[f64; 2]; 2], kinds: [Kind; 4]) -> Domain {
    let mut d = Domain::open(ranges[0], ranges[1]);
    for (side, kind) in Side::ALL.into_iter().zip(kinds) {
        let partner = match side {
            Side::U0 => Side::U1,
            Side::U1 => Side::U0,
            Side::V0 => Side::V1,
            Side::V1 => Side::V0,
        };
        let half = |from: f64, offset: f64| Glue {
            from,
            to: from + 0.5,
            patch: 0,
            side,
            offset,
            reversed: false,
        };
        let rule = match kind {
            Kind::Open => SideRule::Open,
            Kind::Pole => SideRule::Pole,
            Kind::HalfTurn => SideRule::Glued(vec![half(0.0, 0.5), half(0.5, -0.5)]),
            Kind::Periodic => SideRule::Glued(vec![Glue::whole(0, partner, false)]),
            Kind::Flip => SideRule::Glued(vec![Glue::whole(0, partner, true)]),
        };
        d = d.with(side, rule);
    }
    d
}

/// 4 cells across a seam or a pole as the catalogue, 6 along a side glued to itself by
/// a half turn (the projective plane's equator), which 4 cells would fold onto 2
/// vertices.
pub(super) fn min_cells(kinds: [Kind; 4]) -> [usize; 2] {
    let along = |a: Kind, b: Kind| {
        if a == Kind::HalfTurn || b == Kind::HalfTurn {
            6
        } else {
            4
        }
    };
    [along(kinds[2], kinds[3]), along(kinds[0], kinds[1])]
}

/// Closedness, orientability and Euler characteristic of the rectangle under the side
/// rules, counted on its cell complex: 4 corners, one edge per side (two, with a vertex at
/// the middle, for a half turn), one face; glued edges and their ends are identified, a
/// pole's edge collapses and its ends become one vertex.
pub(super) fn topology(kinds: [Kind; 4]) -> Topology {
    // Corners: 0 = (u0, v0), 1 = (u1, v0), 2 = (u0, v1), 3 = (u1, v1); the middle of side
    // s is vertex 4 + s. Side s runs (with its coordinate) from ENDS[s].0 to ENDS[s].1; its
    // edges are 2s (the first half, or the whole side) and 2s + 1 (the second half).
    const ENDS: [(usize, usize); 4] = [(0, 2), (1, 3), (0, 1), (2, 3)];
    let mut vertex: Vec<usize> = (0..8).collect();
    let mut edge: Vec<usize> = (0..8).collect();
    fn find(p: &mut [usize], mut a: usize) -> usize {
        while p[a] != a {
            p[a] = p[p[a]];
            a = p[a];
        }
        a
    }
    fn union(p: &mut [usize], a: usize, b: usize) {
        let (a, b) = (find(p, a), find(p, b));
        p[a] = b;
    }
    let mut vertices = vec![0, 1, 2, 3];
    let mut edges = Vec::new();
    for (s, kind) in kinds.iter().enumerate() {
        let (a, b) = ENDS[s];
        match kind {
            Kind::Open => edges.push(2 * s),
            Kind::Pole => union(&mut vertex, a, b),
            Kind::HalfTurn => {
                vertices.push(4 + s);
                union(&mut vertex, a, 4 + s);
                union(&mut vertex, 4 + s, b);
                union(&mut edge, 2 * s, 2 * s + 1);
                edges.extend([2 * s, 2 * s + 1]);
            }
            Kind::Periodic | Kind::Flip => {
                edges.push(2 * s);
                // The first side of the pair glues both.
                if s % 2 == 0 {
                    let (c, d) = ENDS[s + 1];
                    let (c, d) = if *kind == Kind::Flip { (d, c) } else { (c, d) };
                    union(&mut vertex, a, c);
                    union(&mut vertex, b, d);
                    union(&mut edge, 2 * s, 2 * s + 2);
                }
            }
        }
    }
    let count = |p: &mut Vec<usize>, items: &[usize]| {
        let mut roots: Vec<usize> = items.iter().map(|&i| find(p, i)).collect();
        roots.sort_unstable();
        roots.dedup();
        roots.len() as i64
    };
    let closed = !kinds.contains(&Kind::Open);
    let v = count(&mut vertex, &vertices);
    let e = count(&mut edge, &edges);
    Topology {
        closed,
        orientable: !kinds.contains(&Kind::Flip) && !kinds.contains(&Kind::HalfTurn),
        euler_characteristic: Some(v - e + 1),
    }
}

/// Points compared along each pair of sides.
const SIDE_SAMPLES: usize = 16;

impl super::Formula {
    /// What the open sides of the rectangle would be glued by, where they meet: for u and
    /// for v whose two sides are both open, the points along them compared at
    /// 17 values of the other parameter; equal (within 1e-9 of the largest
    /// coordinate there) they meet as `periodic`, equal with the other parameter reversed
    /// as `flip`. Gives a warning for each: such a surface builds as an open one, its
    /// boundary edges and curve ends where the sides meet.
    pub fn meeting_sides(&self) -> Vec<String> {
        use crate::surfaces::Parametric;
        let kinds = self.kinds();
        let d = self.domain(0);
        let mut out = Vec::new();
        for (along_u, key, [lo, hi], [a, b]) in [(true, "u", d.u, d.v), (false, "v", d.v, d.u)] {
            let (k0, k1) = if along_u {
                (kinds[0], kinds[1])
            } else {
                (kinds[2], kinds[3])
            };
            if k0 != Kind::Open || k1 != Kind::Open {
                continue;
            }
            let at = |side: f64, t: f64| {
                if along_u {
                    self.point(0, side, t)
                } else {
                    self.point(0, t, side)
                }
            };
            let ts: Vec<f64> = (0..=SIDE_SAMPLES)
                .map(|k| a + (b - a) * k as f64 / SIDE_SAMPLES as f64)
                .collect();
            // Each side's points once; "meet" within 1e-9 of the largest coordinate along
            // both, whatever the surface's size.
            let (first, last): (Vec<DVec4>, Vec<DVec4>) =
                ts.iter().map(|&t| (at(lo, t), at(hi, t))).unzip();
            let extent = first
                .iter()
                .chain(&last)
                .map(|p| p.abs().max_element())
                .fold(0.0, f64::max);
            let meets = |reversed: bool| {
                let across = |k: usize| {
                    if reversed {
                        &last[ts.len() - 1 - k]
                    } else {
                        &last[k]
                    }
                };
                (0..ts.len()).all(|k| (first[k] - *across(k)).abs().max_element() <= 1e-9 * extent)
            };
            let rule = if meets(false) {
                "periodic"
            } else if meets(true) {
                "flip"
            } else {
                continue;
            };
            out.push(format!(
                "its sides {key} = {lo} and {key} = {hi} meet point for point{}, but are open: it builds as a surface with a boundary there (boundary edges, curves that end on it); `\"sides\": {{\"{key}\": \"{rule}\"}}` glues them",
                if rule == "flip" { ", the other parameter reversed" } else { "" }
            ));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn topology_follows_the_side_rules() {
        use Kind::*;
        let t = |kinds| {
            let t = topology(kinds);
            (t.closed, t.orientable, t.euler_characteristic)
        };
        assert_eq!(
            t([Periodic, Periodic, Periodic, Periodic]),
            (true, true, Some(0))
        );
        assert_eq!(t([Flip, Flip, Periodic, Periodic]), (true, false, Some(0)));
        assert_eq!(t([Periodic, Periodic, Flip, Flip]), (true, false, Some(0)));
        assert_eq!(
            t([Pole, HalfTurn, Periodic, Periodic]),
            (true, false, Some(1))
        );
        assert_eq!(t([Pole, Pole, Periodic, Periodic]), (true, true, Some(2)));
        assert_eq!(t([Periodic, Periodic, Pole, Pole]), (true, true, Some(2)));
        // Both pairs flipped: the boundary word abab, a projective plane.
        assert_eq!(t([Flip, Flip, Flip, Flip]), (true, false, Some(1)));
        // Two half turns: two cross-caps, a Klein bottle.
        assert_eq!(
            t([HalfTurn, HalfTurn, Periodic, Periodic]),
            (true, false, Some(0))
        );
        // With a boundary: an annulus, a Möbius band, a square and a disc (a cap).
        assert_eq!(t([Open, Open, Periodic, Periodic]), (false, true, Some(0)));
        assert_eq!(t([Open, Open, Flip, Flip]), (false, false, Some(0)));
        assert_eq!(t([Open; 4]), (false, true, Some(1)));
        assert_eq!(t([Pole, Open, Periodic, Periodic]), (false, true, Some(1)));
    }
}
