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
    /// The Hessian is singular: no Morse index (a critical circle, a degenerate point).
    Degenerate,
}

impl Event {
    /// The Morse index: 0, 1 or 2; `None` when degenerate.
    pub fn index(self) -> Option<u32> {
        match self {
            Event::Birth => Some(0),
            Event::Saddle => Some(1),
            Event::Death => Some(2),
            Event::Degenerate => None,
        }
    }

    /// Its name: birth, saddle, death or degenerate.
    pub fn name(self) -> &'static str {
        match self {
            Event::Birth => "birth",
            Event::Saddle => "saddle",
            Event::Death => "death",
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
    /// Vertices on the mesh's boundary, not classified.
    pub boundary: usize,
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
}

impl Critical {
    /// (minima, saddles, maxima, degenerate) among the points.
    pub fn counts(&self) -> [usize; 4] {
        let mut c = [0; 4];
        for p in &self.points {
            c[p.event.index().map_or(3, |i| i as usize)] += 1;
        }
        c
    }

    /// The Morse check on a closed surface of Euler characteristic `euler`: no point
    /// degenerate, and #minima - #saddles + #maxima = χ; else what fails.
    pub fn morse(&self, euler: i64) -> Result<(), String> {
        let [min, saddle, max, degenerate] = self.counts();
        if degenerate > 0 {
            return Err(format!(
                "{degenerate} degenerate critical point(s): the height is not a Morse \
                 function in this direction; tilt the direction a little"
            ));
        }
        let sum = min as i64 - saddle as i64 + max as i64;
        if sum != euler {
            let unrefined = match self.not_converged.len() {
                0 => String::new(),
                k => format!(" ({k} critical vertices of the mesh not refined)"),
            };
            return Err(format!(
                "{min} minima - {saddle} saddles + {max} maxima = {sum}, not the Euler \
                 characteristic {euler}{unrefined}"
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
        let point = match surface {
            None => start,
            Some(s) => match newton(s, n, start) {
                Some(p) => p,
                None => {
                    not_converged.push(start);
                    continue;
                }
            },
        };
        // Refined onto a point reached from another vertex already: one point.
        let same = point.refined
            && points
                .iter()
                .any(|q| q.point.distance(point.point) <= 1e-9 * diagonal);
        if !same {
            points.push(point);
        }
    }
    let by_level = |a: &CriticalPoint, b: &CriticalPoint| {
        a.level.total_cmp(&b.level).then(a.vertex.cmp(&b.vertex))
    };
    points.sort_by(by_level);
    not_converged.sort_by(by_level);
    Ok(Critical {
        direction: n,
        points,
        discrete,
        not_converged,
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
    let mut boundary = vec![false; nv];
    for (&(a, b), &count) in &edges {
        if count != 2 {
            boundary[a as usize] = true;
            boundary[b as usize] = true;
        }
    }
    let mut counts = DiscreteCounts::default();
    let mut found = Vec::new();
    for v in 0..nv {
        if !used[v] {
            continue;
        }
        if boundary[v] {
            counts.boundary += 1;
            continue;
        }
        let event = match changes[v] {
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
        };
        found.push((v as u32, event));
    }
    (found, counts)
}

/// Newton's method on ∇h = 0 from `start`'s parameters; the refined point with its event
/// from the Hessian, or `None` when it leaves the surface's domain, meets a singular step
/// or does not converge.
fn newton(surface: &Surface, n: DVec4, start: CriticalPoint) -> Option<CriticalPoint> {
    let (mut patch, [mut u, mut v]) = (start.patch, start.uv);
    // Once converged, a few more steps take the residual down to rounding; the best point
    // is kept.
    let (mut best, mut polish): (Option<CriticalPoint>, usize) = (None, 0);
    for _ in 0..NEWTON_STEPS {
        let e = surface.eval(patch, u, v);
        let g = [n.dot(e.du), n.dot(e.dv)];
        let hess = [n.dot(e.duu), n.dot(e.duv), n.dot(e.dvv)];
        let residual = surface_gradient(e.du, e.dv, g);
        if residual <= CRITICAL_RESIDUAL && best.is_none_or(|b| residual < b.residual) {
            best = Some(CriticalPoint {
                event: event_of(hess),
                level: n.dot(e.p),
                patch,
                uv: [u, v],
                point: e.p,
                residual,
                refined: true,
                ..start
            });
        }
        if best.is_some() {
            polish += 1;
            if polish > 3 || residual == 0.0 {
                break;
            }
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
    best
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
    /// The Euler characteristic of a closed surface; `None` for a surface with boundary,
    /// whose counts are not checked.
    pub euler: Option<i64>,
    /// Whether it is orientable (a saddle of a non-orientable surface may keep the slice's
    /// number of components).
    pub orientable: bool,
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
/// - on a closed surface, #minima - #saddles + #maxima = χ ([`Critical::morse`]);
/// - across each critical level the slice's number of components changes as the event
///   says: a birth adds one, a death removes one, a saddle adds or removes one (or, on a
///   non-orientable surface, keeps the count);
/// - each evenly spaced still has its interval's number of components.
///
/// The mesh's slice changes where its critical vertices are, and the refined levels lie
/// near them: a still's level keeps clear of both (the middle of the gap between one
/// critical point's higher and the next one's lower level), and an evenly spaced level
/// that falls between a critical point's two levels is not checked. A surface with
/// boundary (its shape's `euler` `None`) gets the stills, its end intervals' too, without the checks.
pub fn motion_picture(
    mesh: &Mesh4,
    surface: Option<&Surface>,
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
    let closed = shape.euler.is_some();
    let (lowest, highest) = heights(mesh, n);
    let mut stills = Vec::new();
    let mut components = Vec::with_capacity(bands.len() + 1);
    let mut failures = Vec::new();
    for k in 0..=bands.len() {
        // On a closed surface the mesh's lowest and highest vertices are critical: nothing
        // lies below the lowest critical point or above the highest. A surface with
        // boundary reaches past them: its end intervals have stills too, between the
        // critical levels and the mesh's extreme heights.
        let (lo, hi) = (
            if k == 0 { lowest } else { bands[k - 1].hi },
            if k == bands.len() {
                highest
            } else {
                bands[k].lo
            },
        );
        let count = if closed && (k == 0 || k == bands.len()) {
            0
        } else {
            let level = if lo < hi || k == 0 || k == bands.len() {
                0.5 * (lo + hi)
            } else {
                0.5 * (bands[k - 1].vertex + bands[k].vertex)
            };
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
        for (k, band) in bands.iter().enumerate() {
            let (below, above) = (components[k] as i64, components[k + 1] as i64);
            let change = above - below;
            let event = band.point.event;
            let ok = match event {
                Event::Birth => change == 1,
                Event::Death => change == -1,
                Event::Saddle if shape.orientable => change.abs() == 1,
                Event::Saddle => change.abs() <= 1,
                Event::Degenerate => true,
            };
            if !ok {
                failures.push(format!(
                    "across the {} at level {} (its mesh vertex at {}): {below} component(s) \
                     below, {above} above",
                    event.name(),
                    band.point.level,
                    band.vertex
                ));
            }
        }
    }
    let mut picture = MotionPicture {
        sequence: bands.iter().map(|b| b.point).collect(),
        critical,
        frame,
        stills,
        components,
        failures,
        shape,
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

impl MotionPicture {
    /// The slice of `mesh` (the one the picture was made of, with its `surface`) at
    /// `level`, as a still of this picture: its interval (by the levels of the critical
    /// points' mesh vertices), and what fails when it does not have its interval's number
    /// of components (not checked on a surface with boundary, nor at a level between a
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
