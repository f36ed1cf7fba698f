//! The arcs of the boxes joined into curves: each arc end lies on a face of its box, and the
//! same double point is the end of exactly one arc of the box beyond that face (or, on a
//! glued side of a patch, of the box beyond the side it is glued to; on an open side the
//! curve ends there).
//!
//! Two ends are one point when their enclosures meet and one lies in the box of the other's
//! face where that other is proven the only solution: both solve the same three equations
//! in that face's hyperplane, which have one solution there. The same pair of points may
//! be written (p, q) or (q, p) on one surface; both are tried, and the glue map of a side.

use super::far::End;
use super::near::Glued;
use super::system::{I, Projector, V3};
use crate::surfaces::{Side, SideRule, Surface};

/// An arc of double points, between two ends.
#[derive(Clone, Copy, Debug)]
pub(super) struct Arc {
    /// The two surfaces (indices into the certificate's list).
    pub surfaces: [usize; 2],
    /// Their patches.
    pub patches: [usize; 2],
    /// Its ends.
    pub ends: [End; 2],
}

/// A component of double curve.
#[derive(Clone, Debug, PartialEq)]
pub struct Component {
    /// How it ends.
    pub kind: ComponentKind,
    /// The arcs it is made of (one per box it crosses).
    pub arcs: usize,
    /// Its points where it crosses the boxes' faces, in 3D (midpoints of their enclosures,
    /// each within `width` of the true point).
    pub points: Vec<[f64; 3]>,
    /// The widest enclosure of those points.
    pub width: f64,
    /// Where it passes on the two sheets that cross there: for each of its points, the box
    /// of parameters on each sheet in which its arc's end was proven the only one (for the
    /// sampler to refine around a curve a mesh missed).
    pub boxes: Vec<[SheetBox; 2]>,
}

/// A box of parameters on a patch of one of the certificate's surfaces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SheetBox {
    /// The surface (its index in the certificate's list).
    pub surface: usize,
    /// The patch.
    pub patch: usize,
    /// The range of u.
    pub u: [f64; 2],
    /// The range of v.
    pub v: [f64; 2],
}

/// How a component of double curve ends.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ComponentKind {
    /// A closed curve: every end met the next arc.
    Closed,
    /// Both ends on an open side of a patch (the surface's boundary).
    Open,
    /// An end that runs into a region the certificate did not decide.
    Unfinished,
}

/// Where an end lies: inside the parameter domain, or on a side of a patch.
enum Place {
    Inside,
    Open,
    Pole,
    Glued(Glued),
}

/// Which side of the patch a face point lies on, and its rule.
fn place(surface: &Surface, patch: usize, e: &End, coord: usize) -> Place {
    let d = surface.domain(patch);
    let x = e.x[e.face];
    let local = coord % 2;
    let range = if local == 0 { d.u } else { d.v };
    let side = match (local, x.lo() == range[0], x.hi() == range[1]) {
        (0, true, _) => Side::U0,
        (0, _, true) => Side::U1,
        (1, true, _) => Side::V0,
        (1, _, true) => Side::V1,
        _ => return Place::Inside,
    };
    match d.side(side) {
        SideRule::Open => Place::Open,
        SideRule::Pole => Place::Pole,
        SideRule::Glued(_) => {
            let base = if coord < 2 { 0 } else { 2 };
            let (u, v) = (e.x[base].mid(), e.x[base + 1].mid());
            let extent = (d.u[1] - d.u[0]).abs().max((d.v[1] - d.v[0]).abs());
            let step = 1e-6 * extent;
            let (pu, pv) = match side {
                Side::U0 => (range[0] - step, v),
                Side::U1 => (range[1] + step, v),
                Side::V0 => (u, range[0] - step),
                Side::V1 => (u, range[1] + step),
            };
            match super::near::glued(surface, patch, pu, pv, step) {
                Some(g) => Place::Glued(g),
                None => Place::Pole,
            }
        }
    }
}

/// One way of writing an end: its patches and enclosure, in a frame another end may share.
#[derive(Clone, Copy)]
struct Written {
    surfaces: [usize; 2],
    patches: [usize; 2],
    x: [I; 4],
    face: usize,
}

impl Written {
    fn swapped(self) -> Written {
        Written {
            surfaces: [self.surfaces[1], self.surfaces[0]],
            patches: [self.patches[1], self.patches[0]],
            x: [self.x[2], self.x[3], self.x[0], self.x[1]],
            face: (self.face + 2) % 4,
        }
    }
}

/// Whether `w` (another end's writing) is the point `e` proves unique in its face box.
fn same(w: &Written, e: &Written, unique: &[I; 4]) -> bool {
    w.surfaces == e.surfaces
        && w.patches == e.patches
        && w.face == e.face
        && (0..4).all(|k| w.x[k].meets(e.x[k]))
        && (0..4)
            .filter(|&k| k != e.face)
            .all(|k| unique[k].holds(w.x[k]))
}

/// The components of the arcs, by their matched ends; `surfaces[i]` is the certificate's
/// surface i with its projector.
pub(super) fn components(arcs: &[Arc], surfaces: &[&Projector]) -> Vec<Component> {
    let n = arcs.len() * 2;
    let end = |i: usize| &arcs[i / 2].ends[i % 2];
    let own = |i: usize| Written {
        surfaces: arcs[i / 2].surfaces,
        patches: arcs[i / 2].patches,
        x: end(i).x,
        face: end(i).face,
    };
    // Every writing of every end: as found, swapped (one surface), across its glued side.
    let mut places = Vec::with_capacity(n);
    let mut writings: Vec<Vec<Written>> = Vec::with_capacity(n);
    for i in 0..n {
        let w = own(i);
        let sheet = w.face / 2;
        let surface = surfaces[w.surfaces[sheet]].surface;
        let p = place(surface, w.patches[sheet], end(i), w.face);
        let mut list = vec![w];
        if let Place::Glued(g) = &p {
            let base = 2 * sheet;
            let slack = 1e-12 * (1.0 + w.x[base].mag().max(w.x[base + 1].mag()));
            let (u, v) = g.image(w.x[base], w.x[base + 1], slack);
            let mut m = w;
            m.patches[sheet] = g.patch;
            m.x[base] = u;
            m.x[base + 1] = v;
            // The glued side may run along the other coordinate.
            let across_u = g.linear[0][w.face % 2] != 0.0;
            m.face = base + if across_u { 0 } else { 1 };
            list.push(m);
        }
        if w.surfaces[0] == w.surfaces[1] {
            let more: Vec<Written> = list.iter().map(|w| w.swapped()).collect();
            list.extend(more);
        }
        places.push(p);
        writings.push(list);
    }
    // Candidates by the 3D point: sorted by its x.
    let keys: Vec<V3> = (0..n)
        .map(|i| {
            let w = own(i);
            let proj = surfaces[w.surfaces[0]];
            proj.image(w.patches[0], w.x[0], w.x[1]).p
        })
        .collect();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| keys[a][0].lo().total_cmp(&keys[b][0].lo()));
    let mut matches: Vec<Vec<usize>> = vec![Vec::new(); n];
    let pad = |k: &V3| k.iter().fold(0.0f64, |m, c| m.max(c.width())) + 1e-12;
    for (s, &i) in order.iter().enumerate() {
        let reach = keys[i][0].hi() + pad(&keys[i]);
        for &j in order[s + 1..]
            .iter()
            .take_while(|&&j| keys[j][0].lo() <= reach)
        {
            let near = (0..3).all(|c| {
                let m = pad(&keys[i]).max(pad(&keys[j]));
                keys[i][c].lo() - m <= keys[j][c].hi() && keys[j][c].lo() - m <= keys[i][c].hi()
            });
            if !near {
                continue;
            }
            let (wi, wj) = (own(i), own(j));
            let one = writings[i].iter().any(|w| same(w, &wj, &end(j).unique))
                || writings[j].iter().any(|w| same(w, &wi, &end(i).unique));
            if one {
                matches[i].push(j);
                matches[j].push(i);
            }
        }
    }
    // Union of arcs by their matched ends.
    let mut parent: Vec<usize> = (0..arcs.len()).collect();
    fn root(parent: &mut [usize], mut a: usize) -> usize {
        while parent[a] != a {
            parent[a] = parent[parent[a]];
            a = parent[a];
        }
        a
    }
    for (i, found) in matches.iter().enumerate() {
        for &j in found {
            let (a, b) = (root(&mut parent, i / 2), root(&mut parent, j / 2));
            if a != b {
                parent[a.max(b)] = a.min(b);
            }
        }
    }
    let mut by_root: std::collections::BTreeMap<usize, Component> = Default::default();
    for i in 0..n {
        let r = root(&mut parent, i / 2);
        let c = by_root.entry(r).or_insert(Component {
            kind: ComponentKind::Closed,
            arcs: 0,
            points: Vec::new(),
            width: 0.0,
            boxes: Vec::new(),
        });
        if i % 2 == 0 {
            c.arcs += 1;
        }
        let k = keys[i];
        c.points.push(k.map(I::mid));
        let (w, unique) = (own(i), end(i).unique);
        c.boxes.push([0, 1].map(|sheet| SheetBox {
            surface: w.surfaces[sheet],
            patch: w.patches[sheet],
            u: [unique[2 * sheet].lo(), unique[2 * sheet].hi()],
            v: [unique[2 * sheet + 1].lo(), unique[2 * sheet + 1].hi()],
        }));
        c.width = c.width.max(pad(&k));
        let ok = match (&places[i], matches[i].len()) {
            (Place::Open, 0) => {
                if c.kind == ComponentKind::Closed {
                    c.kind = ComponentKind::Open;
                }
                true
            }
            (Place::Inside | Place::Glued(_), 1) => true,
            _ => false,
        };
        if !ok {
            c.kind = ComponentKind::Unfinished;
        }
    }
    by_root.into_values().collect()
}
