//! Motion pictures: a surface cut by the hyperplanes ⟨n, x⟩ = c of a height function
//! h = ⟨n, X⟩. Where the slices change: the critical points of h on the surface (births,
//! saddles, deaths), found on the 4D mesh and refined on the exact surface, with the Morse
//! check of their count; the slice at a level ([`slice()`]), whose components change at the
//! mesh's critical vertices as their events say; the hyperplanes' frame
//! ([`hyperplane_frame`]); and the motion picture ([`motion_picture`]): a still in each
//! interval between critical levels, with the checks that its components change as the
//! events say (what `halo4d slice` draws, in `crate::slicing`).
//!
//! **On the mesh** (Banchoff's critical points of a piecewise-linear height): a vertex's
//! link is the cycle of its neighbours; the number of sign changes of h(neighbour) - h(v)
//! around it is 0 at a minimum or maximum, 2 at a regular vertex and 2k at a saddle of
//! multiplicity k - 1. Ties of h are broken by vertex index (simulation of simplicity), so
//! every vertex is one of these. Summed over a closed mesh, 1 - changes / 2 is its Euler
//! characteristic, whatever n is.
//!
//! **On the surface**: from each critical vertex, Newton's method on ∇h = (⟨n, X_u⟩,
//! ⟨n, X_v⟩) = 0 with the exact second derivatives (steps past a glued side continue on the
//! side it is glued to), until the gradient on the surface is at rounding. The index comes
//! from the Hessian of h in (u, v) at the point (its signature is the surface Hessian's):
//! 0 a minimum (a birth as c rises), 1 a saddle, 2 a maximum (a death); a Hessian singular
//! to 1e-8 of its size is *degenerate* (a critical circle, as for the flat torus with n = w,
//! or a point where h is not a Morse function). Points reached from two vertices are one.
//!
//! A coarse mesh can have a pair of critical vertices where the surface has none (a saddle
//! and an extremum side by side, which cancel in the count): Newton's method finds no
//! critical point from them, and they are kept apart ([`Critical::not_converged`]).
//!
//! **The check**: on a closed surface whose critical points are none degenerate,
//! #minima - #saddles + #maxima = χ, the surface's Euler characteristic
//! ([`Critical::morse`]).

pub mod boundary;
pub mod proven;

pub use proven::{ProvenCritical, ProvenPoint};

use crate::limits::{self, FieldError};
use crate::sample::Mesh4;
use crate::surfaces::Surface;
use glam::{DMat4, DVec4};
use serde::{Deserialize, Serialize};

/// Newton steps from a critical vertex before it counts as not converged.
const NEWTON_STEPS: usize = 60;

/// A refined critical point whose surface gradient (dimensionless: n is a unit vector) is
/// above this is not converged.
pub const CRITICAL_RESIDUAL: f64 = 1e-10;

/// A critical vertex whose height is within this share of the mesh's range of heights from
/// its critical point's level stands on it ([`Critical::faithful`]): rounding, where a
/// vertex sampled at the point differs from it by about 1e-16.
const FAITHFUL: f64 = 1e-10;

/// The Hessian's determinant below this share of its squared size is degenerate.
const DEGENERATE: f64 = 1e-8;

/// What happens to the slices at a critical point as the level rises.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Event {
    /// A minimum: a component is born.
    Birth,
    /// A saddle: two components join, one splits, or (on a non-orientable surface) one
    /// passes through itself.
    Saddle,
    /// A maximum: a component dies.
    Death,
    /// On the boundary, a minimum of h where h rises into the surface: an arc is born at
    /// the boundary.
    BoundaryBirth,
    /// On the boundary, a maximum of h where h falls into the surface: an arc dies at the
    /// boundary.
    BoundaryDeath,
    /// A maximum of h along the boundary where h rises into the surface: two ends of arcs
    /// meet there and join (two arcs become one, or an arc closes into a loop).
    BoundaryJoin,
    /// A minimum of h along the boundary where h falls into the surface: a curve is cut
    /// there (an arc becomes two, or a loop opens into an arc).
    BoundarySplit,
    /// The Hessian is singular: no Morse index (a critical circle, a degenerate point).
    Degenerate,
}

impl Event {
    /// The Morse index of an interior point: 0, 1 or 2; `None` when degenerate or on the
    /// boundary.
    pub fn index(self) -> Option<u32> {
        match self {
            Event::Birth => Some(0),
            Event::Saddle => Some(1),
            Event::Death => Some(2),
            _ => None,
        }
    }

    /// Whether it is an event of the boundary.
    pub fn on_boundary(self) -> bool {
        matches!(
            self,
            Event::BoundaryBirth
                | Event::BoundaryDeath
                | Event::BoundaryJoin
                | Event::BoundarySplit
        )
    }

    /// What the point adds to the Euler characteristic in the Morse count (the
    /// [`boundary`] module's notes): `None` when degenerate.
    pub fn euler(self) -> Option<i64> {
        match self {
            Event::Birth | Event::Death | Event::BoundaryBirth => Some(1),
            Event::Saddle | Event::BoundaryJoin => Some(-1),
            Event::BoundaryDeath | Event::BoundarySplit => Some(0),
            Event::Degenerate => None,
        }
    }

    /// Whether the slice's components may change by `change` across the point, on a
    /// surface of `shape`: a birth adds one, a death removes one; a saddle adds or removes
    /// one, or on a non-orientable surface or one with boundary keeps the count (two arcs
    /// that cross and reconnect stay two); a join removes one or closes an arc, a split
    /// adds one or opens a loop.
    pub fn allows(self, change: i64, shape: Shape) -> bool {
        match self {
            Event::Birth | Event::BoundaryBirth => change == 1,
            Event::Death | Event::BoundaryDeath => change == -1,
            Event::Saddle if shape.closed && shape.orientable => change.abs() == 1,
            Event::Saddle => change.abs() <= 1,
            Event::BoundaryJoin => change == -1 || change == 0,
            Event::BoundarySplit => change == 1 || change == 0,
            Event::Degenerate => true,
        }
    }

    /// Its name: birth, saddle, death or degenerate.
    pub fn name(self) -> &'static str {
        match self {
            Event::Birth => "birth",
            Event::Saddle => "saddle",
            Event::Death => "death",
            Event::BoundaryBirth => "boundary birth",
            Event::BoundaryDeath => "boundary death",
            Event::BoundaryJoin => "boundary join",
            Event::BoundarySplit => "boundary split",
            Event::Degenerate => "degenerate point",
        }
    }
}

/// A critical point of h on the surface.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CriticalPoint {
    /// Its event.
    pub event: Event,
    /// Its level c = h.
    pub level: f64,
    /// Its patch and parameters (of the mesh vertex, where it could not be refined).
    pub patch: usize,
    /// Parameters (u, v).
    pub uv: [f64; 2],
    /// The surface point in 4D.
    pub point: DVec4,
    /// The norm of h's gradient on the surface there (0 for a vertex of a mesh without
    /// parameters, where h is piecewise linear).
    pub residual: f64,
    /// The mesh vertex it was found from.
    pub vertex: u32,
    /// Whether Newton's method refined it onto the exact surface (false for a mesh read
    /// from a file, which keeps the mesh's vertex, and where Newton did not converge).
    pub refined: bool,
}

/// The discrete critical vertices of the mesh, counted.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct DiscreteCounts {
    /// Vertices whose neighbours are all higher.
    pub minima: usize,
    /// Saddles, each counted with its multiplicity.
    pub saddles: usize,
    /// Vertices whose neighbours are all lower.
    pub maxima: usize,
    /// Boundary vertices whose neighbours are all higher.
    pub boundary_minima: usize,
    /// Boundary vertices whose neighbours are all lower.
    pub boundary_maxima: usize,
    /// Boundary vertices whose two boundary neighbours are lower and some other higher.
    pub boundary_joins: usize,
    /// Boundary vertices whose two boundary neighbours are higher and some other lower.
    pub boundary_splits: usize,
    /// Vertices where the mesh is not a manifold with boundary, not classified.
    pub unclassified: usize,
}

/// The critical points of h = ⟨n, X⟩ on one surface.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Critical {
    /// The unit direction n.
    pub direction: DVec4,
    /// The critical points, by level: refined onto the surface (or the mesh's vertices,
    /// for a mesh without parameters).
    pub points: Vec<CriticalPoint>,
    /// The mesh's critical vertices.
    pub discrete: DiscreteCounts,
    /// Critical vertices from which Newton's method found no critical point (`refined`
    /// false), by level: pairs that the mesh's coarseness makes, or points the refinement
    /// cannot reach (then the count fails).
    pub not_converged: Vec<CriticalPoint>,
    /// Critical vertices that Newton's method took onto a point found from another vertex
    /// as well (one of a pair that the mesh makes beside the surface's point): the point,
    /// with the vertex it was reached from. Of the vertices reaching a point, the one
    /// nearest its level is the point's.
    pub merged: Vec<CriticalPoint>,
}

impl Critical {
    /// (minima, saddles, maxima, degenerate) among the points inside the surface.
    pub fn counts(&self) -> [usize; 4] {
        let mut c = [0; 4];
        for p in &self.points {
            match p.event {
                Event::Birth => c[0] += 1,
                Event::Saddle => c[1] += 1,
                Event::Death => c[2] += 1,
                Event::Degenerate => c[3] += 1,
                _ => {}
            }
        }
        c
    }

    /// (births, deaths, joins, splits) among the points on the boundary.
    pub fn boundary_counts(&self) -> [usize; 4] {
        let mut c = [0; 4];
        for p in &self.points {
            match p.event {
                Event::BoundaryBirth => c[0] += 1,
                Event::BoundaryDeath => c[1] += 1,
                Event::BoundaryJoin => c[2] += 1,
                Event::BoundarySplit => c[3] += 1,
                _ => {}
            }
        }
        c
    }

    /// Whether the slices of `mesh` (the one the points were found on) change where the
    /// surface's do: each critical point stands on a critical vertex of its own (its level
    /// the vertex's, to rounding), so that the mesh's critical levels are the surface's, in
    /// its order; and every other critical vertex of the mesh is one of a pair the mesh
    /// makes beside the surface's points: refined onto one of them, or, where the points are
    /// `all` the surface's (proven), refined onto none. Gives the spans of heights where the
    /// mesh's slices can hold a small loop the surface's has not (from each such vertex to
    /// its point, or between two unrefined ones paired by distance): a still's level keeps
    /// clear of them. Else what differs: points off their vertices (a coarse mesh meets two
    /// close critical levels in the other order, and its slice between them is not the
    /// surface's) and vertices refined onto no point.
    pub fn faithful(&self, mesh: &Mesh4, all: bool) -> Result<Vec<[f64; 2]>, String> {
        let height = |p: &CriticalPoint| mesh.positions[p.vertex as usize].dot(self.direction);
        let (lowest, highest) = heights(mesh, self.direction);
        let rounding = FAITHFUL * (highest - lowest).abs().max(f64::MIN_POSITIVE);
        let (off, by) = self
            .points
            .iter()
            .map(|p| (height(p) - p.level).abs())
            .filter(|&d| d > rounding)
            .fold((0, 0.0f64), |(k, m), d| (k + 1, m.max(d)));
        let paired = if all {
            pairs(&self.not_converged)
        } else {
            None
        };
        let unrefined = if paired.is_some() {
            0
        } else {
            self.not_converged.len()
        };
        if off == 0 && unrefined == 0 {
            let merged = self
                .merged
                .iter()
                .map(|p| [p.level.min(height(p)), p.level.max(height(p))]);
            return Ok(merged.chain(paired.into_iter().flatten()).collect());
        }
        let mut what = Vec::new();
        if off > 0 {
            what.push(format!(
                "{off} critical points stand off the mesh's critical vertices (by up to \
                 {by:.3e} in height)"
            ));
        }
        if unrefined > 0 {
            what.push(format!(
                "{unrefined} critical vertices are refined onto no critical point"
            ));
        }
        Err(format!(
            "the mesh's slices change elsewhere than the surface's: {}; a still near them \
             would be the mesh's, not the surface's",
            what.join(", ")
        ))
    }

    /// The Morse check on a surface of Euler characteristic `euler`: no point degenerate,
    /// and #minima - #saddles + #maxima = χ, with a surface's boundary + #boundary births
    /// - #boundary joins; else what fails.
    pub fn morse(&self, euler: i64) -> Result<(), String> {
        let [min, saddle, max, degenerate] = self.counts();
        let [births, _, joins, _] = self.boundary_counts();
        if degenerate > 0 {
            return Err(format!(
                "{degenerate} degenerate critical point(s): the height is not a Morse \
                 function in this direction; tilt the direction a little"
            ));
        }
        let sum: i64 = self.points.iter().filter_map(|p| p.event.euler()).sum();
        if sum != euler {
            let unrefined = match self.not_converged.len() {
                0 => String::new(),
                k => format!(" ({k} critical vertices of the mesh not refined)"),
            };
            let boundary = if births + joins > 0 {
                format!(" + {births} boundary births - {joins} boundary joins")
            } else {
                String::new()
            };
            return Err(format!(
                "{min} minima - {saddle} saddles + {max} maxima{boundary} = {sum}, not the \
                 Euler characteristic {euler}{unrefined}"
            ));
        }
        Ok(())
    }
}

/// The critical points of h = ⟨n, X⟩ (n normalized here) on `mesh`, refined on `surface`
/// where the mesh has parameters on it (a catalogue or formula surface); a mesh read from a
/// file (`surface` `None`) keeps its vertices. An error names a direction that is zero or
/// not finite.
pub fn critical_points(
    mesh: &Mesh4,
    surface: Option<&Surface>,
    n: DVec4,
) -> Result<Critical, FieldError> {
    let length = n.length();
    if !(length.is_finite() && length > 0.0) {
        return Err(FieldError::new(
            "direction",
            format!("must be a nonzero, finite 4D vector, got {n}"),
        ));
    }
    let n = n / length;
    let h: Vec<f64> = mesh.positions.iter().map(|p| p.dot(n)).collect();
    let (found, discrete) = critical_vertices(mesh, &h);
    let diagonal = mesh
        .bounds()
        .map_or(1.0, |(lo, hi)| (hi - lo).length().max(f64::MIN_POSITIVE));
    let mut points: Vec<CriticalPoint> = Vec::new();
    let mut not_converged = Vec::new();
    let mut merged = Vec::new();
    for (vertex, event) in found {
        let v = vertex as usize;
        let start = CriticalPoint {
            event,
            level: h[v],
            // A mesh read back from a `.glb` keeps no parameters.
            patch: mesh.patch.get(v).map_or(0, |&p| p as usize),
            uv: mesh.uv.get(v).copied().unwrap_or_default(),
            point: mesh.positions[v],
            residual: 0.0,
            vertex,
            refined: false,
        };
        let refined = match surface {
            None => Some(start),
            // A boundary vertex is refined along its side, an interior one in the plane.
            Some(s) if event.on_boundary() => boundary::newton(s, n, start),
            Some(s) => newton(s, n, start),
        };
        let Some(point) = refined else {
            not_converged.push(start);
            continue;
        };
        // Refined onto a point reached from another vertex already: one point, the vertex
        // nearest its level its own (the one sampled at it, on a mesh sampled through it).
        let off = |p: &CriticalPoint| (h[p.vertex as usize] - p.level).abs();
        let same = points
            .iter_mut()
            .find(|q| point.refined && q.point.distance(point.point) <= 1e-9 * diagonal);
        match same {
            Some(q) if off(&point) < off(q) => merged.push(std::mem::replace(q, point)),
            Some(_) => merged.push(point),
            None => points.push(point),
        }
    }
    let by_level = |a: &CriticalPoint, b: &CriticalPoint| {
        a.level.total_cmp(&b.level).then(a.vertex.cmp(&b.vertex))
    };
    points.sort_by(by_level);
    not_converged.sort_by(by_level);
    merged.sort_by(by_level);
    Ok(Critical {
        direction: n,
        points,
        discrete,
        not_converged,
        merged,
    })
}

/// The mesh's critical vertices with their events (a saddle of multiplicity k once), and
/// their counts. A vertex is above another where its height is, ties broken by index.
fn critical_vertices(mesh: &Mesh4, h: &[f64]) -> (Vec<(u32, Event)>, DiscreteCounts) {
    let nv = mesh.positions.len();
    let above = |a: u32, b: u32| (h[a as usize], a) > (h[b as usize], b);
    let mut changes = vec![0u32; nv];
    let mut lower = vec![false; nv];
    let mut used = vec![false; nv];
    // Each triangle (v, a, b) is one edge of v's link; the sign changes around the link
    // are its edges whose ends lie on opposite sides of h(v).
    let mut edges: std::collections::HashMap<(u32, u32), u32> = std::collections::HashMap::new();
    for t in &mesh.triangles {
        for k in 0..3 {
            let (v, a, b) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
            let (sa, sb) = (above(a, v), above(b, v));
            changes[v as usize] += u32::from(sa != sb);
            lower[v as usize] |= !sa || !sb;
            used[v as usize] = true;
            *edges.entry((v.min(a), v.max(a))).or_default() += 1;
        }
    }
    // A boundary vertex's link is a path between its two neighbours along the boundary.
    let mut links: std::collections::HashMap<u32, Vec<[u32; 2]>> = std::collections::HashMap::new();
    for (&(a, b), &count) in &edges {
        if count != 2 {
            links.entry(a).or_default();
            links.entry(b).or_default();
        }
    }
    for t in &mesh.triangles {
        for k in 0..3 {
            if let Some(link) = links.get_mut(&t[k]) {
                link.push([t[(k + 1) % 3], t[(k + 2) % 3]]);
            }
        }
    }
    let mut counts = DiscreteCounts::default();
    let mut found = Vec::new();
    for v in 0..nv {
        if !used[v] {
            continue;
        }
        let event = if let Some(link) = links.get(&(v as u32)) {
            let Some((event, saddles)) = boundary_event(v as u32, link, &edges, &above) else {
                counts.unclassified += 1;
                continue;
            };
            counts.saddles += saddles;
            let Some(event) = event else {
                continue;
            };
            match event {
                Event::BoundaryBirth => counts.boundary_minima += 1,
                Event::BoundaryDeath => counts.boundary_maxima += 1,
                Event::BoundaryJoin => counts.boundary_joins += 1,
                Event::BoundarySplit => counts.boundary_splits += 1,
                // A saddle beside the boundary is counted with its multiplicity above.
                _ => {}
            }
            event
        } else {
            match changes[v] {
                0 if !lower[v] => {
                    counts.minima += 1;
                    Event::Birth
                }
                0 => {
                    counts.maxima += 1;
                    Event::Death
                }
                2 => continue,
                c => {
                    counts.saddles += (c / 2 - 1) as usize;
                    Event::Saddle
                }
            }
        };
        found.push((v as u32, event));
    }
    (found, counts)
}

/// The event of boundary vertex `v` from its link's edges (its triangles' far sides), with
/// the saddles it holds besides (a link that goes below and above more often than its
/// event needs); `None` where the link is not one path between two boundary neighbours
/// (the mesh is not a manifold there). Walking the path, the runs of lower neighbours
/// decide: both ends higher, none a boundary minimum, one a split; both ends lower, one
/// run a boundary maximum, two a join; the ends apart, one run regular. Each run more is
/// a saddle.
fn boundary_event(
    v: u32,
    link: &[[u32; 2]],
    edges: &std::collections::HashMap<(u32, u32), u32>,
    above: &impl Fn(u32, u32) -> bool,
) -> Option<(Option<Event>, usize)> {
    let ends: Vec<u32> = link
        .iter()
        .flatten()
        .copied()
        .filter(|&a| edges.get(&(v.min(a), v.max(a))) == Some(&1))
        .collect();
    let [start, end] = ends[..] else {
        return None;
    };
    // Walk the path from `start`: each edge used once.
    let mut used = vec![false; link.len()];
    let mut path = vec![start];
    let mut at = start;
    while at != end {
        let k = (0..link.len()).find(|&k| !used[k] && link[k].contains(&at))?;
        used[k] = true;
        at = if link[k][0] == at {
            link[k][1]
        } else {
            link[k][0]
        };
        path.push(at);
    }
    if used.iter().any(|u| !u) {
        return None;
    }
    let below: Vec<bool> = path.iter().map(|&a| !above(a, v)).collect();
    let runs = below
        .iter()
        .enumerate()
        .filter(|&(k, &b)| b && (k == 0 || !below[k - 1]))
        .count();
    let (first, last) = (below[0], below[below.len() - 1]);
    Some(match (first, last) {
        (false, false) if runs == 0 => (Some(Event::BoundaryBirth), 0),
        (false, false) => (Some(Event::BoundarySplit), runs - 1),
        (true, true) if runs == 1 => (Some(Event::BoundaryDeath), 0),
        (true, true) => (Some(Event::BoundaryJoin), runs - 2),
        _ if runs == 1 => (None, 0),
        _ => (Some(Event::Saddle), runs - 1),
    })
}

/// Newton's method on ∇h = 0 from `start`'s parameters; the refined point with its event
/// from the Hessian, or `None` when it leaves the surface's domain, meets a singular step
/// or does not converge.
fn newton(surface: &Surface, n: DVec4, start: CriticalPoint) -> Option<CriticalPoint> {
    let (mut patch, [mut u, mut v]) = (start.patch, start.uv);
    let mut polish = Polish::default();
    for _ in 0..NEWTON_STEPS {
        let e = surface.eval(patch, u, v);
        let g = [n.dot(e.du), n.dot(e.dv)];
        let hess = [n.dot(e.duu), n.dot(e.duv), n.dot(e.dvv)];
        let residual = surface_gradient(e.du, e.dv, g);
        let done = polish.offer(&start, (patch, [u, v]), n.dot(e.p), e.p, residual, || {
            event_of(hess)
        });
        if done {
            break;
        }
        let det = hess[0] * hess[2] - hess[1] * hess[1];
        if det == 0.0 || !det.is_finite() {
            break;
        }
        let du = -(hess[2] * g[0] - hess[1] * g[1]) / det;
        let dv = -(hess[0] * g[1] - hess[1] * g[0]) / det;
        let (p, nu, nv, inside) = surface.chart(patch, u + du, v + dv);
        if !(inside && nu.is_finite() && nv.is_finite()) {
            break;
        }
        (patch, u, v) = (p, nu, nv);
    }
    polish.best
}

/// The best converged point of a Newton iteration: once one converges, a few more steps
/// take the residual down to rounding, and the best point is kept.
#[derive(Default)]
struct Polish {
    best: Option<CriticalPoint>,
    steps: usize,
}

impl Polish {
    /// Offers this step's point for `start`: at `patch` and `uv`, the surface point `point`
    /// at height `level`, of residual `residual`, its event made only where it converged and
    /// beats the best; whether to stop.
    fn offer(
        &mut self,
        start: &CriticalPoint,
        (patch, uv): (usize, [f64; 2]),
        level: f64,
        point: DVec4,
        residual: f64,
        event: impl FnOnce() -> Event,
    ) -> bool {
        if residual <= CRITICAL_RESIDUAL && self.best.is_none_or(|b| residual < b.residual) {
            self.best = Some(CriticalPoint {
                event: event(),
                level,
                patch,
                uv,
                point,
                residual,
                refined: true,
                ..*start
            });
        }
        if self.best.is_none() {
            return false;
        }
        self.steps += 1;
        self.steps > 3 || residual == 0.0
    }
}

/// The norm of h's gradient on the surface from its coordinate gradient `g` (with the
/// metric of the tangents: g^T G^-1 g); the coordinate gradient's norm where the tangents
/// are degenerate.
fn surface_gradient(du: DVec4, dv: DVec4, g: [f64; 2]) -> f64 {
    let (a, b, c) = (du.dot(du), du.dot(dv), dv.dot(dv));
    let det = a * c - b * b;
    if det > 0.0 && det.is_finite() {
        ((c * g[0] * g[0] - 2.0 * b * g[0] * g[1] + a * g[1] * g[1]) / det)
            .max(0.0)
            .sqrt()
    } else {
        g[0].hypot(g[1])
    }
}

/// The event of a critical point from h's Hessian `[h_uu, h_uv, h_vv]`.
fn event_of(hess: [f64; 3]) -> Event {
    let det = hess[0] * hess[2] - hess[1] * hess[1];
    let size = hess[0] * hess[0] + 2.0 * hess[1] * hess[1] + hess[2] * hess[2];
    if det.abs() <= DEGENERATE * size || !det.is_finite() {
        Event::Degenerate
    } else if det < 0.0 {
        Event::Saddle
    } else if hess[0] + hess[2] > 0.0 {
        Event::Birth
    } else {
        Event::Death
    }
}

/// A curve of a slice: its points in 4D, on the hyperplane, in order.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SliceCurve {
    /// The points, one where each mesh edge crosses the level, moved onto the surface
    /// where it has parameters.
    pub points: Vec<DVec4>,
    /// Whether the curve closes on itself (else it ends on the mesh's boundary).
    pub closed: bool,
}

/// The slice of a surface by a hyperplane.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Slice {
    /// The level c.
    pub level: f64,
    /// The curves: on a closed surface all closed, as many as the slice has components.
    pub curves: Vec<SliceCurve>,
    /// The largest |⟨n, x⟩ - c| of the points moved onto the surface (0 where none was).
    pub max_residual: f64,
    /// Points Newton's method could not move onto the surface (they keep the mesh's).
    pub not_converged: usize,
}

/// Newton steps moving a slice point onto the surface.
const SLICE_STEPS: usize = 60;

/// The slice of `mesh` by the hyperplane ⟨n, x⟩ = `c` (n a unit vector): the curves where
/// its triangles cross the level, each point where a mesh edge does, then moved onto
/// `surface` where the mesh has parameters on it (Newton's method on h = c from the point's
/// parameters along its edge, each step the smallest in (u, v)). A vertex exactly at the
/// level counts as above it, so every triangle crosses the level in one segment or not at
/// all and the curves are simple: their topology is the mesh's, which changes at the mesh's
/// critical vertices. Near a critical level the mesh's slice can hold a small loop that the
/// surface's has not yet (or no longer): points Newton's method cannot move keep the mesh's
/// place and are counted ([`Slice::not_converged`]).
pub fn slice(mesh: &Mesh4, surface: Option<&Surface>, n: DVec4, c: f64) -> Slice {
    let h: Vec<f64> = mesh.positions.iter().map(|p| p.dot(n)).collect();
    let above = |v: u32| h[v as usize] >= c;
    let key = |a: u32, b: u32| (a.min(b), a.max(b));
    // Each crossing triangle is one segment between its two crossing edges; an edge is in
    // at most two segments (one per triangle on it).
    let mut at_edge: std::collections::HashMap<(u32, u32), Vec<usize>> =
        std::collections::HashMap::new();
    let mut segments: Vec<([(u32, u32); 2], usize)> = Vec::new();
    for (ti, t) in mesh.triangles.iter().enumerate() {
        let crossing: Vec<(u32, u32)> = (0..3)
            .map(|k| (t[k], t[(k + 1) % 3]))
            .filter(|&(a, b)| above(a) != above(b))
            .map(|(a, b)| key(a, b))
            .collect();
        if let [e, f] = crossing[..] {
            for edge in [e, f] {
                at_edge.entry(edge).or_default().push(segments.len());
            }
            segments.push(([e, f], ti));
        }
    }
    let mut out = Slice {
        level: c,
        curves: Vec::new(),
        max_residual: 0.0,
        not_converged: 0,
    };
    // Where edge (a, b) of triangle `ti` crosses the level, on the surface where it can be.
    let mut point = |(a, b): (u32, u32), ti: usize| {
        let (ha, hb) = (h[a as usize], h[b as usize]);
        let t = (c - ha) / (hb - ha);
        let on_mesh = mesh.positions[a as usize].lerp(mesh.positions[b as usize], t);
        let Some(surface) = surface else {
            return on_mesh;
        };
        let corner = |v: u32| {
            let k = mesh.triangles[ti].iter().position(|&x| x == v).unwrap_or(0);
            mesh.triangle_uv[ti][k]
        };
        let (ua, ub) = (corner(a), corner(b));
        let uv = [ua[0] + (ub[0] - ua[0]) * t, ua[1] + (ub[1] - ua[1]) * t];
        match onto_level(surface, mesh.triangle_patch[ti] as usize, uv, n, c) {
            Some((p, residual)) => {
                out.max_residual = out.max_residual.max(residual);
                p
            }
            None => {
                out.not_converged += 1;
                on_mesh
            }
        }
    };
    let mut used = vec![false; segments.len()];
    // Open curves first, from edges in one segment (on the boundary), then the loops.
    let mut starts: Vec<(u32, u32)> = at_edge
        .iter()
        .filter(|(_, s)| s.len() == 1)
        .map(|(&e, _)| e)
        .collect();
    starts.sort_unstable();
    let loops: Vec<(u32, u32)> = segments.iter().map(|s| s.0[0]).collect();
    for (start, open) in starts
        .into_iter()
        .map(|e| (e, true))
        .chain(loops.into_iter().map(|e| (e, false)))
    {
        let Some(&first) = at_edge[&start].iter().find(|&&s| !used[s]) else {
            continue;
        };
        let mut points = vec![point(start, segments[first].1)];
        let (mut edge, mut seg) = (start, first);
        loop {
            used[seg] = true;
            let ([e, f], ti) = segments[seg];
            edge = if e == edge { f } else { e };
            if edge == start {
                break;
            }
            points.push(point(edge, ti));
            match at_edge[&edge].iter().find(|&&s| !used[s]) {
                Some(&next) => seg = next,
                None => break,
            }
        }
        out.curves.push(SliceCurve {
            points,
            closed: !open && edge == start,
        });
    }
    out
}

/// The point of `surface` at level `c` of h = ⟨n, X⟩ that Newton's method reaches from
/// `uv` on `patch` (each step the smallest in (u, v) that zeroes the linearized h - c),
/// with its |h - c|; `None` when the residual does not come under 1e-12 of the surface's
/// size (a step that cannot stay on the surface, a vanishing gradient).
fn onto_level(
    surface: &Surface,
    mut patch: usize,
    [mut u, mut v]: [f64; 2],
    n: DVec4,
    c: f64,
) -> Option<(DVec4, f64)> {
    // The surface's own rounding (about 1e-15 of its size where its formula is long) can
    // keep the residual above f64's: once under 1e-12 of the size, a few more steps keep
    // the best point.
    let (mut best, mut polish): (Option<(DVec4, f64)>, usize) = (None, 0);
    for _ in 0..SLICE_STEPS {
        let e = surface.eval(patch, u, v);
        let r = c - n.dot(e.p);
        let size = c.abs() + e.p.length();
        if r.abs() <= 1e-12 * size && best.is_none_or(|b| r.abs() < b.1) {
            best = Some((e.p, r.abs()));
        }
        if best.is_some() {
            polish += 1;
            if polish > 3 || r.abs() <= 2.0 * f64::EPSILON * size {
                break;
            }
        }
        let g = [n.dot(e.du), n.dot(e.dv)];
        let g2 = g[0] * g[0] + g[1] * g[1];
        if g2 == 0.0 || !g2.is_finite() {
            break;
        }
        // A step past a pole or an open side, or one that does not bring h nearer to c
        // (near a critical point, where h bends away), is halved until it does.
        let mut step = [g[0] * r / g2, g[1] * r / g2];
        let moved = (0..16).find_map(|_| {
            let (p, nu, nv, inside) = surface.chart(patch, u + step[0], v + step[1]);
            step = [step[0] / 2.0, step[1] / 2.0];
            (inside
                && nu.is_finite()
                && nv.is_finite()
                && (c - n.dot(surface.point(p, nu, nv))).abs() < r.abs())
            .then_some((p, nu, nv))
        });
        let Some(next) = moved else { break };
        (patch, u, v) = next;
    }
    best
}

/// The direction a view turns onto w, in the surface's own coordinates: Rᵀ e_w for the
/// view's rotation R (the default direction of a motion picture, so that its slices are
/// the view's levels of w).
pub fn view_direction(rotation: DMat4) -> DVec4 {
    rotation.transpose() * DVec4::W
}

/// An orthonormal frame of the hyperplanes ⟨n, x⟩ = c (n a unit vector): the view's x, y
/// and z axes (Rᵀ e_x, Rᵀ e_y, Rᵀ e_z) turned by the smallest rotation that takes the
/// view's w axis onto n (for n opposite to it, the half turn in the view's zw plane). For
/// n the view's own w axis this is the view's x, y, z, so a slice is seen as the build's
/// picture sees that level of w. A point x of the slice at level c has coordinates
/// (⟨e_1, x⟩, ⟨e_2, x⟩, ⟨e_3, x⟩), its origin the point c n.
pub fn hyperplane_frame(rotation: DMat4, n: DVec4) -> [DVec4; 3] {
    let rt = rotation.transpose();
    let axis = |k: usize| rt * DVec4::AXES[k];
    let a = axis(3);
    let cos = a.dot(n).clamp(-1.0, 1.0);
    // The turn's plane: a and the unit vector u perpendicular to a towards n (the view's z
    // where n is along ±a, for the half turn; any u serves the identity).
    let across = n - a * cos;
    let sin = across.length();
    let u = if sin > 1e-12 { across / sin } else { axis(2) };
    let turn = |x: DVec4| {
        let (xa, xu) = (x.dot(a), x.dot(u));
        x + (a * xa + u * xu) * (cos - 1.0) + (u * xa - a * xu) * sin
    };
    [0, 1, 2].map(|k| {
        let e = turn(axis(k));
        // Rounding of the turn taken off: exactly perpendicular to n.
        (e - n * e.dot(n)).normalize()
    })
}

/// `n` tilted by `degrees` towards the diagonal (e_1 + e_2 + e_3) / √3 of its hyperplane's
/// `frame` (`--perturb`): a direction near n in no special position, the same on every run.
pub fn tilt(n: DVec4, frame: &[DVec4; 3], degrees: f64) -> DVec4 {
    let toward = (frame[0] + frame[1] + frame[2]).normalize();
    let angle = degrees.to_radians();
    (n * angle.cos() + toward * angle.sin()).normalize()
}

/// The lowest and the highest of h = ⟨n, x⟩ over the mesh's vertices.
pub fn heights(mesh: &Mesh4, n: DVec4) -> (f64, f64) {
    mesh.positions
        .iter()
        .map(|p| p.dot(n))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), h| {
            (lo.min(h), hi.max(h))
        })
}

/// A scene's `slicing`: what `halo4d slice` cuts its surfaces along (its flags override
/// these).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Slicing {
    /// The direction n in the surfaces' own 4D coordinates, any nonzero length; absent:
    /// the direction the scene's view turns onto w ([`view_direction`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub direction: Option<[f64; 4]>,
    /// Evenly spaced stills besides one per interval between critical levels.
    pub levels: usize,
    /// Degrees to tilt the direction by ([`tilt`]), 0 for none.
    pub perturb: f64,
    /// Frames of a film through the levels, from the surface's lowest point to its
    /// highest, 0 for none.
    pub film: u32,
}

impl Slicing {
    /// Checks every value; names the first bad field.
    pub fn check(&self) -> Result<(), FieldError> {
        if let Some(d) = self.direction {
            let length = DVec4::from_array(d).length();
            if !(length.is_finite() && length > 0.0) {
                return Err(FieldError::new(
                    "direction",
                    format!("must be a nonzero, finite 4D vector [x, y, z, w]; got {d:?}"),
                ));
            }
        }
        limits::MOTION_LEVELS.check("levels", self.levels)?;
        limits::PERTURB.check("perturb", self.perturb)?;
        limits::FILM_FRAMES.check("film", self.film)
    }

    /// The unit direction n it cuts along for a view of 4D rotation `rotation` (its
    /// `direction`, else [`view_direction`], tilted by `perturb` degrees), with the frame of
    /// its hyperplanes ([`hyperplane_frame`]). Takes a checked `Slicing`.
    pub fn direction_and_frame(&self, rotation: DMat4) -> (DVec4, [DVec4; 3]) {
        let mut n = self
            .direction
            .map_or_else(|| view_direction(rotation), DVec4::from_array)
            .normalize();
        if self.perturb > 0.0 {
            n = tilt(n, &hyperplane_frame(rotation, n), self.perturb);
        }
        (n, hyperplane_frame(rotation, n))
    }
}

/// A curve in 3D: its points, and whether it closes (its last point joined to its first).
pub type Polyline = (Vec<glam::DVec3>, bool);

/// What is known of a surface's topology for the motion picture's checks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shape {
    /// The Euler characteristic the critical points are counted against; `None` where it is
    /// not known (a mesh that is not a manifold), and nothing is counted.
    pub euler: Option<i64>,
    /// Whether the surface is closed (else the critical points of its boundary count too).
    pub closed: bool,
    /// Whether it is orientable (a saddle of a non-orientable surface may keep the slice's
    /// number of components).
    pub orientable: bool,
}

impl From<crate::surfaces::Topology> for Shape {
    /// A catalogue or formula surface's own topology.
    fn from(t: crate::surfaces::Topology) -> Shape {
        Shape {
            euler: t.euler_characteristic,
            closed: t.closed,
            orientable: t.orientable,
        }
    }
}

/// One still of a motion picture: the slice at a regular level.
#[derive(Clone, Debug)]
pub struct Still {
    /// The slice, its curves in 4D.
    pub slice: Slice,
    /// The interval of critical levels it lies in: 0 below the lowest critical point, k
    /// between the k-th and the (k + 1)-th.
    pub interval: usize,
    /// Whether it is the interval's own still (else one of the evenly spaced ones asked).
    pub between: bool,
}

/// A motion picture: the critical points of h = ⟨n, X⟩ and a still in every interval
/// between them, with the checks of Morse theory.
#[derive(Clone, Debug)]
pub struct MotionPicture {
    /// The critical points, by level.
    pub critical: Critical,
    /// The frame of the hyperplanes, in which the stills' 3D coordinates are taken.
    pub frame: [DVec4; 3],
    /// The stills, by level.
    pub stills: Vec<Still>,
    /// The critical points in the order the mesh's slices meet them (by their vertices'
    /// levels, which can differ from the refined levels' order where two lie close):
    /// interval k lies between the (k - 1)-th and the k-th.
    pub sequence: Vec<CriticalPoint>,
    /// The number of slice components in each interval (one more than the critical points).
    pub components: Vec<usize>,
    /// Each check that failed, saying what it found.
    pub failures: Vec<String>,
    /// The surface's topology the checks took.
    pub shape: Shape,
    /// The critical points proven on the surface ([`proven::prove`]), where it has one.
    pub proven: Option<ProvenCritical>,
}

impl Still {
    /// The still's curves in the frame's 3D coordinates, each with whether it is closed.
    pub fn in_frame(&self, frame: &[DVec4; 3]) -> Vec<Polyline> {
        self.slice
            .curves
            .iter()
            .map(|c| {
                let points = c
                    .points
                    .iter()
                    .map(|p| glam::DVec3::new(p.dot(frame[0]), p.dot(frame[1]), p.dot(frame[2])))
                    .collect();
                (points, c.closed)
            })
            .collect()
    }
}

/// The motion picture of `mesh` (its `surface` where it has one) along `n`, its
/// hyperplanes' coordinates in `frame`: the critical points ([`critical_points`]), one
/// still in each interval between consecutive critical levels and `extra` more at evenly
/// spaced levels between the lowest and the highest, and the checks:
///
/// - #minima - #saddles + #maxima = χ, on a surface with boundary + #boundary births -
///   #boundary joins ([`Critical::morse`]);
/// - across each critical level the slice's number of components changes as the event
///   says ([`Event::allows`]);
/// - each evenly spaced still has its interval's number of components;
/// - the mesh is faithful to the surface ([`Critical::faithful`]): its slices change at the
///   surface's critical levels and nowhere else (sample it through the critical points,
///   [`through_points`]);
/// - its critical points are the ones proven on the surface ([`proven::prove`],
///   [`ProvenCritical::agrees`]): none missed between the mesh's vertices.
///
/// The mesh's slice changes where its critical vertices are: on a mesh that is not
/// faithful, the refined levels lie near them, a still's level keeps clear of both (the
/// middle of the gap between one critical point's higher and the next one's lower level),
/// and an evenly spaced level that falls between a critical point's two levels is not
/// checked. A surface whose χ is unknown (its shape's `euler` `None`: a mesh that is not a
/// manifold) gets the stills and only the last two checks.
pub fn motion_picture(
    mesh: &Mesh4,
    surface: Option<&Surface>,
    n: DVec4,
    frame: [DVec4; 3],
    shape: Shape,
    extra: usize,
) -> Result<MotionPicture, FieldError> {
    motion_picture_proven(mesh, surface, None, n, frame, shape, extra)
}

/// [`motion_picture`] with the critical points proven on the surface already (by
/// [`proven::prove`] along the same direction, normalized): the proof does not depend on
/// the mesh, and a surface sampled again keeps it.
pub fn motion_picture_proven(
    mesh: &Mesh4,
    surface: Option<&Surface>,
    proven: Option<ProvenCritical>,
    n: DVec4,
    frame: [DVec4; 3],
    shape: Shape,
    extra: usize,
) -> Result<MotionPicture, FieldError> {
    let critical = critical_points(mesh, surface, n)?;
    let n = critical.direction;
    // Each critical point's band, from the lower to the higher of its refined level and
    // its mesh vertex's, in the order of the vertices' levels: the mesh's slice changes
    // where its critical vertices are.
    struct Band {
        lo: f64,
        hi: f64,
        vertex: f64,
        point: CriticalPoint,
    }
    let mut bands: Vec<Band> = critical
        .points
        .iter()
        .map(|&point| {
            let vertex = mesh.positions[point.vertex as usize].dot(n);
            Band {
                lo: point.level.min(vertex),
                hi: point.level.max(vertex),
                vertex,
                point,
            }
        })
        .collect();
    bands.sort_by(|a, b| a.vertex.total_cmp(&b.vertex));
    let cut = |c: f64| slice(mesh, surface, n, c);
    let (lowest, highest) = heights(mesh, n);
    let mut stills = Vec::new();
    let mut components = Vec::with_capacity(bands.len() + 1);
    let proven = proven.or_else(|| surface.map(|s| proven::prove(s, n, proven::BUDGET)));
    let agrees = proven.as_ref().map(|p| p.agrees(&critical));
    // Where the points found are all the surface's, a vertex refined onto none is one of
    // a pair the mesh makes.
    let all = proven.as_ref().is_some_and(|p| p.complete) && matches!(agrees, Some(Ok(())));
    let (spans, mut failures) = match critical.faithful(mesh, all) {
        Ok(spans) => (spans, Vec::new()),
        Err(e) => (Vec::new(), vec![e]),
    };
    failures.extend(agrees.and_then(Result::err));
    for k in 0..=bands.len() {
        // Critical points whose vertices stand at one height (a symmetry ties them) pass
        // together: no level lies between them, and the slice at theirs is the one below.
        if k > 0 && k < bands.len() && bands[k - 1].vertex == bands[k].vertex {
            components.push(components[k - 1]);
            continue;
        }
        // The mesh's lowest and highest vertices are critical (inside or on the boundary):
        // nothing lies below the lowest critical point or above the highest. Where they
        // were not refined (a pair the mesh makes, a mesh that is not a manifold), the end
        // intervals of a surface with boundary get stills too, between the critical levels
        // and the mesh's extreme heights.
        let (lo, hi) = (
            if k == 0 { lowest } else { bands[k - 1].hi },
            if k == bands.len() {
                highest
            } else {
                bands[k].lo
            },
        );
        let count = if (k == 0 || k == bands.len()) && (shape.closed || lo >= hi) {
            0
        } else {
            let level = if lo < hi || k == 0 || k == bands.len() {
                clear_of(lo, hi, &spans)
            } else {
                0.5 * (bands[k - 1].vertex + bands[k].vertex)
            };
            // A vertex at the level counts as above it: the mesh's slice is the interval's
            // at a level past the lower vertex and up to the higher one, which two
            // vertices one float apart leave no middle to.
            let mut level = level;
            if k > 0 && level <= bands[k - 1].vertex {
                level = bands[k - 1].vertex.next_up();
            }
            if k < bands.len() && level > bands[k].vertex {
                level = bands[k].vertex;
            }
            let slice = cut(level);
            let count = slice.curves.len();
            stills.push(Still {
                slice,
                interval: k,
                between: true,
            });
            count
        };
        components.push(count);
    }
    if let Some(euler) = shape.euler {
        if let Err(e) = critical.morse(euler) {
            failures.push(e);
        }
        let sequence: Vec<(CriticalPoint, f64)> =
            bands.iter().map(|b| (b.point, b.vertex)).collect();
        failures.extend(event_failures(&sequence, &components, shape));
    }
    let mut picture = MotionPicture {
        sequence: bands.iter().map(|b| b.point).collect(),
        critical,
        frame,
        stills,
        components,
        failures,
        shape,
        proven,
    };
    if extra > 0 && bands.len() >= 2 {
        let (lo, hi) = (bands[0].lo, bands[bands.len() - 1].hi);
        for i in 0..extra {
            let level = lo + (hi - lo) * (i as f64 + 0.5) / extra as f64;
            // One still at a level is enough.
            if picture
                .stills
                .iter()
                .any(|s| (s.slice.level - level).abs() <= 1e-9 * (hi - lo))
            {
                continue;
            }
            let (still, failure) = picture.still_at(mesh, surface, level);
            picture.failures.extend(failure);
            picture.stills.push(still);
        }
        picture
            .stills
            .sort_by(|a, b| a.slice.level.total_cmp(&b.slice.level));
    }
    Ok(picture)
}

/// What fails where the slice's components change otherwise than the events allow
/// ([`Event::allows`]): across each run of critical points of `sequence` (each with its mesh
/// vertex's height, in their order) whose vertices stand at one height, from the interval
/// below the run to the one above (one point, unless a symmetry ties several: their
/// changes add up). `components` has one count per interval.
fn event_failures(
    sequence: &[(CriticalPoint, f64)],
    components: &[usize],
    shape: Shape,
) -> Vec<String> {
    let mut failures = Vec::new();
    let mut k = 0;
    while k < sequence.len() {
        let run = sequence[k..]
            .iter()
            .take_while(|(_, v)| *v == sequence[k].1)
            .count();
        let (below, above) = (components[k] as i64, components[k + run] as i64);
        let change = above - below;
        // The changes the run's events allow together.
        let mut sums = std::collections::BTreeSet::from([0i64]);
        for (p, _) in &sequence[k..k + run] {
            sums = sums
                .iter()
                .flat_map(|s| {
                    (-1..=1)
                        .filter(|&c| p.event.allows(c, shape))
                        .map(move |c| s + c)
                })
                .collect();
        }
        let degenerate = sequence[k..k + run]
            .iter()
            .any(|(p, _)| p.event == Event::Degenerate);
        if !degenerate && !sums.contains(&change) {
            let (p, vertex) = sequence[k];
            let what = if run == 1 {
                format!("the {}", p.event.name())
            } else {
                let names: Vec<&str> = sequence[k..k + run]
                    .iter()
                    .map(|(p, _)| p.event.name())
                    .collect();
                format!("{run} points tied ({})", names.join(", "))
            };
            failures.push(format!(
                "across {what} at level {} (mesh vertex at {vertex}): {below} component(s) \
                 below, {above} above",
                p.level
            ));
        }
        k += run;
    }
    failures
}

/// The distance (a share of the surface's bounding diagonal) from a critical point of the
/// four points beside it that [`through_points`] gives.
const RING: f64 = 1e-5;

/// The points (patch, parameters) to sample `surface` through so that each critical point
/// of `picture` (found on its mesh, or proven where the mesh has none) is a critical vertex
/// of the mesh, of its own event: the point itself, and four beside it, `RING` (1e-5) of
/// the surface's `diagonal` away along the axes of h's Hessian in (u, v), or within half
/// the distance to the patch's nearest side where that is closer (down to a hundredth of
/// it; one past a seam then taken onto the patch beyond). Their heights differ from the
/// point's by λ r² with the sign of each axis's eigenvalue λ, so the vertex's link changes
/// sign four times around a saddle and never around an extremum, however thin the saddle's
/// sectors. A point on the boundary has two beside it along its side and one into the
/// surface; a corner is a vertex of every mesh. Gives the number of critical points and
/// the points.
pub fn through_points(
    surface: &Surface,
    picture: &MotionPicture,
    diagonal: f64,
) -> (usize, Vec<(usize, [f64; 2])>) {
    let n = picture.critical.direction;
    let found = picture.critical.points.iter().filter(|p| p.refined);
    let missed = picture
        .proven
        .iter()
        .flat_map(|p| p.missed(&picture.critical));
    let points: Vec<(usize, [f64; 2])> = found
        .map(|p| (p.patch, p.uv))
        .chain(missed.map(|p| (p.patch, [p.u.mid(), p.v.mid()])))
        .collect();
    let mut out = Vec::new();
    for &(patch, uv) in &points {
        match boundary::open_sides(surface, patch, uv)[..] {
            [] => {}
            [side] => {
                out.extend(boundary::beside(surface, patch, uv, side, RING * diagonal));
                continue;
            }
            // A corner is a vertex of every mesh.
            _ => continue,
        }
        out.push((patch, uv));
        let e = surface.eval(patch, uv[0], uv[1]);
        let [a, b, c] = [n.dot(e.duu), n.dot(e.duv), n.dot(e.dvv)];
        // The symmetric 2 x 2 Hessian's eigenvectors: at angle θ with tan 2θ = 2b / (a - c).
        let theta = 0.5 * (2.0 * b).atan2(a - c);
        // Within half the distance to the patch's nearest side, where that leaves room: a
        // vertex of the side between the point and a point beside it would be its
        // neighbour instead (its link then not the Hessian's).
        let d = surface.domain(patch);
        let room = (uv[0] - d.u[0])
            .min(d.u[1] - uv[0])
            .min(uv[1] - d.v[0])
            .min(d.v[1] - uv[1]);
        for axis in [[theta.cos(), theta.sin()], [-theta.sin(), theta.cos()]] {
            let length = (e.du * axis[0] + e.dv * axis[1]).length();
            let mut r = RING * diagonal / length;
            if !(r.is_finite() && r > 0.0) {
                continue;
            }
            if 0.5 * room < r && 0.5 * room >= 0.01 * r {
                r = 0.5 * room;
            }
            for sign in [1.0, -1.0] {
                out.push((
                    patch,
                    [uv[0] + sign * r * axis[0], uv[1] + sign * r * axis[1]],
                ));
            }
        }
    }
    // A point beside one near a seam can lie past it: it is taken onto the patch it lies
    // on (the sampler inserts points of a patch's own rectangle).
    let out = out
        .into_iter()
        .filter_map(|(patch, [u, v])| {
            let (patch, u, v, inside) = surface.chart(patch, u, v);
            inside.then_some((patch, [u, v]))
        })
        .collect();
    (points.len(), out)
}

/// The critical vertices refined onto no critical point, paired each with the nearest one
/// left (they come in pairs that cancel, a birth or a death beside a saddle): the span of
/// heights between each pair's two; `None` when one is left without a pair.
fn pairs(unrefined: &[CriticalPoint]) -> Option<Vec<[f64; 2]>> {
    let mut left: Vec<&CriticalPoint> = unrefined.iter().collect();
    let mut spans = Vec::new();
    while let Some(a) = left.pop() {
        let (k, b) = left
            .iter()
            .enumerate()
            .min_by(|x, y| {
                let d = |p: &CriticalPoint| p.point.distance(a.point);
                d(x.1).total_cmp(&d(y.1))
            })
            .map(|(k, b)| (k, *b))?;
        left.swap_remove(k);
        spans.push([a.level.min(b.level), a.level.max(b.level)]);
    }
    Some(spans)
}

/// The middle of the longest part of (`lo`, `hi`) outside every span of `spans`; the
/// middle of (`lo`, `hi`) where they cover it.
fn clear_of(lo: f64, hi: f64, spans: &[[f64; 2]]) -> f64 {
    let mut cuts: Vec<[f64; 2]> = spans
        .iter()
        .filter(|s| s[1] > lo && s[0] < hi)
        .copied()
        .collect();
    cuts.sort_by(|a, b| a[0].total_cmp(&b[0]));
    let (mut best, mut from) = ([lo, lo], lo);
    for [a, b] in cuts.into_iter().chain([[hi, hi]]) {
        if a.min(hi) - from > best[1] - best[0] {
            best = [from, a.min(hi)];
        }
        from = from.max(b);
    }
    if best[1] > best[0] {
        0.5 * (best[0] + best[1])
    } else {
        0.5 * (lo + hi)
    }
}

impl MotionPicture {
    /// The slice of `mesh` (the one the picture was made of, with its `surface`) at
    /// `level`, as a still of this picture: its interval (by the levels of the critical
    /// points' mesh vertices), and what fails when it does not have its interval's number
    /// of components (not checked where χ is unknown, nor at a level between a
    /// critical point's refined level and its vertex's).
    pub fn still_at(
        &self,
        mesh: &Mesh4,
        surface: Option<&Surface>,
        level: f64,
    ) -> (Still, Option<String>) {
        let n = self.critical.direction;
        let vertex = |p: &CriticalPoint| mesh.positions[p.vertex as usize].dot(n);
        let interval = self.sequence.iter().filter(|p| vertex(p) < level).count();
        let clear = self.sequence.iter().all(|p| {
            let v = vertex(p);
            level < p.level.min(v) || level > p.level.max(v)
        });
        let slice = slice(mesh, surface, n, level);
        let (count, expected) = (slice.curves.len(), self.components[interval]);
        let failure = (self.shape.euler.is_some() && clear && count != expected).then(|| {
            format!(
                "the slice at level {level} has {count} component(s), its interval {interval} \
                 {expected}"
            )
        });
        let still = Still {
            slice,
            interval,
            between: false,
        };
        (still, failure)
    }
}
