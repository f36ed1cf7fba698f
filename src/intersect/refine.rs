//! Curves on the true surfaces: the mesh's curve points moved by Newton's method onto the
//! double curves of the analytic surfaces.
//!
//! Takes: the mesh [`Curves`], the sheets they were found on, each sheet's surface and 4D
//! mesh (its triangles' patches and corner parameters) and the view. Gives: the same curves,
//! point for point, each point where the projections of its two surfaces truly meet, with
//! the exact w of both; curve ends at cross-caps moved onto them, curve ends on an open
//! boundary onto the boundary; triple points on their three sheets.
//!
//! - A curve point is a pair of parameter points (u1, v1), (u2, v2) with
//!   P(S1(u1, v1)) = P(S2(u2, v2)): three equations in four unknowns, and a fourth that keeps
//!   the point in the plane through the mesh point across the curve (its normal is the cross
//!   product of the two sheets' normals there), or, at a curve's end on an open boundary,
//!   fixes the boundary's parameter. Newton's method starts from the point's barycentric
//!   parameters on its two triangles and uses the exact Jacobians; parameters that step
//!   across a glued side go on, by the glue rule, on the side it is glued to
//!   ([`Surface::chart`]).
//! - A cross-cap (a Whitney umbrella) is where the projected surface's differential drops
//!   rank at a regular point of the surface: f_u × f_v = 0, three equations in two unknowns,
//!   solved by Gauss-Newton with the exact second derivatives of f = P∘S, from the mesh
//!   vertex where a curve ends.
//! - A triple point solves P(S1) = P(S2) = P(S3): six equations in six unknowns.
//!
//! A point is kept where the mesh put it, and counted, when Newton does not reach rounding,
//! or its solution leaves the triangles' neighbourhood (farther in R^4 than twice their
//! longest edge), lies outside the surface's domain, or, on one surface, brings the two
//! parameter points together (the trivial solution of a self-intersection): never a wrong
//! point. Every point is refined on its own, on the cores, so the result does not depend on
//! the number of threads.

use super::{Curve, CurvePoint, Curves, End, Face, Node, Sheet, TriplePoint, exact};
use crate::sample::Mesh4;
use crate::surfaces::{Jet, Side, SideRule, Surface};
use crate::view::{Mapped, View, ViewMap};
use glam::{DVec3, DVec4};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// The scene's `curves`: which curves the files and the picture show.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CurveSettings {
    /// Move the mesh's curve points onto the analytic surfaces' double curves (the files'
    /// and the picture's curves); the halos are verified against the mesh's curves either
    /// way.
    pub refine: bool,
    /// Certify the double curves of the true surfaces ([`super::certified`]): their
    /// components and branch points proven by interval arithmetic, or the regions not
    /// decided named, in `report.json`'s `curves.certified`; a build whose certificate is
    /// complete and disagrees with the mesh's curves is not verified. Off by default: it
    /// costs from a tenth of a second to its budget (4 to 16 s), and leaves the
    /// neighbourhoods of cross-caps undecided.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub certify: bool,
}

impl Default for CurveSettings {
    fn default() -> Self {
        CurveSettings {
            refine: true,
            certify: false,
        }
    }
}

/// `report.json`'s `curves` fields of the refinement.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Refinement {
    /// Curve points moved onto the surfaces' double curve (cross-cap ends included).
    pub refined: usize,
    /// Curve points kept where the mesh put them: Newton did not reach rounding, or reached
    /// it out of the points' triangles' neighbourhood or domain, or at the trivial solution.
    pub not_converged: usize,
    /// The largest |P1 - P2| at the refined curve and triple points, in scene units.
    pub max_residual: f64,
    /// The largest distance from a mesh curve point to its refined point, across the
    /// curve: the mesh curve's error (cross-cap ends not included, see
    /// `max_cross_cap_shift`).
    pub max_shift: f64,
    /// Curve ends moved onto a cross-cap.
    pub cross_caps: usize,
    /// The largest distance a curve end moved onto its cross-cap.
    pub max_cross_cap_shift: f64,
    /// Curve points dropped: they failed between a curve's end moved onto its cross-cap
    /// and the first refined point, beyond the true curve's end.
    pub trimmed: usize,
    /// Curve ends at a mesh vertex on a pole of the parametrization, kept there: a pole is
    /// one point of the surface, and the mesh vertex is exactly on it.
    pub pole_ends: usize,
    /// Triple points moved onto the three surfaces' common point.
    pub triple_points_refined: usize,
    /// Triple points kept where the mesh put them.
    pub triple_points_not_converged: usize,
    /// Refined curve points where the sheet nearer in w is not the one the mesh says
    /// (near-tangential contacts in w).
    pub over_under_changed: usize,
    /// Curve and triple points on a surface read from a mesh file, kept where the mesh
    /// puts them: that mesh is the surface.
    pub on_meshes: usize,
    /// Milliseconds.
    pub refine_ms: f64,
}

/// The analytic surface behind a sheet and the 4D mesh the sheet projects.
#[derive(Clone, Copy, Debug)]
pub struct Analytic<'a> {
    /// The surface; `None` for a mesh read from a file, whose curve points stay as they are.
    pub surface: Option<&'a Surface>,
    /// Its 4D mesh (the sheet's triangles, with their patches and corner parameters).
    pub mesh: &'a Mesh4,
}

/// Newton steps at most.
const MAX_STEPS: usize = 24;

/// Accepted residual, a share of the scene's diagonal.
const RESIDUAL: f64 = 1e-13;

/// A residual at rounding, a share of the scene's diagonal: Newton stops there.
const ROUNDING: f64 = 1e-15;

/// Accepted |f_u × f_v| at a cross-cap, a share of |S_u| |S_v| (the surface's own tangents
/// in R^4, which a regular point keeps apart): the projection's rank drops where f_u and
/// f_v are parallel or one of them vanishes.
const CROSS_CAP_RANK: f64 = 1e-12;

/// How far from the mesh vertex where a curve ends its cross-cap may be, in longest edges
/// of the curve point's triangles (in R^4).
const CROSS_CAP_REACH: f64 = 2.0;

/// On one surface, the least distance in R^4 between the two parameter points of a
/// solution, a share of their distance at the start: less is the trivial solution.
const COLLAPSE: f64 = 0.1;

/// The curves `curves` (found on `sheets`) with their points moved onto the analytic
/// surfaces `analytic` (one per sheet, in order) in `view`; `diagonal` is the projected
/// scene's, to which residuals are compared. The report's `refinement` says what was done.
pub fn refine(
    curves: &Curves,
    sheets: &[Sheet],
    analytic: &[Analytic],
    view: &View,
    diagonal: f64,
) -> Curves {
    let start = Instant::now();
    let solver = Solver::new(sheets, analytic, view, diagonal);
    // Only points whose surfaces all have a parametrization move; the rest (on a mesh read
    // from a file) stay, the mesh being the surface.
    let parametric = |faces: &[Face]| {
        faces
            .iter()
            .all(|f| analytic[f.surface as usize].surface.is_some())
    };
    let refinable: Vec<bool> = curves
        .curves
        .iter()
        .map(|c| c.points.iter().all(|p| parametric(&p.faces)))
        .collect();
    // Every point's first try on the cores, then each curve's second tries and trimming.
    let points: Vec<(usize, usize)> = curves
        .curves
        .iter()
        .enumerate()
        .filter(|&(k, _)| refinable[k])
        .flat_map(|(k, c)| (0..c.points.len()).map(move |i| (k, i)))
        .collect();
    let mut tries: Vec<Try> = points
        .par_iter()
        .with_min_len(64)
        .map(|&(k, i)| solver.first_try(&curves.curves[k], i))
        .collect();
    let mut per_curve = Vec::with_capacity(curves.curves.len());
    for (c, &refinable) in curves.curves.iter().zip(&refinable).rev() {
        let rest = tries.len() - if refinable { c.points.len() } else { 0 };
        per_curve.push(tries.split_off(rest));
    }
    per_curve.reverse();
    let done: Vec<(Curve, Refinement)> = curves
        .curves
        .par_iter()
        .zip(per_curve)
        .zip(&refinable)
        .map(|((c, tries), &refinable)| {
            if refinable {
                solver.finish(c, tries)
            } else {
                let r = Refinement {
                    on_meshes: c.points.len(),
                    ..Refinement::default()
                };
                (c.clone(), r)
            }
        })
        .collect();
    let triples: Vec<(TriplePoint, Option<Option<f64>>)> = curves
        .triple_points
        .par_iter()
        .map(|t| {
            if parametric(&t.faces) {
                let (t, residual) = solver.triple(t);
                (t, Some(residual))
            } else {
                (*t, None)
            }
        })
        .collect();
    let mut r = Refinement::default();
    let mut out = Curves {
        curves: Vec::with_capacity(done.len()),
        triple_points: Vec::with_capacity(triples.len()),
        report: curves.report.clone(),
    };
    for (c, t) in done {
        r.add(&t);
        out.curves.push(c);
    }
    for (t, residual) in triples {
        match residual {
            Some(Some(res)) => {
                r.triple_points_refined += 1;
                r.max_residual = r.max_residual.max(res);
            }
            Some(None) => r.triple_points_not_converged += 1,
            None => r.on_meshes += 1,
        }
        out.triple_points.push(t);
    }
    out.report.points -= r.trimmed;
    r.refine_ms = start.elapsed().as_secs_f64() * 1e3;
    out.report.refinement = Some(r);
    out
}

impl Refinement {
    /// Adds the counts of another curve's refinement, keeps the larger maxima.
    fn add(&mut self, o: &Refinement) {
        self.refined += o.refined;
        self.not_converged += o.not_converged;
        self.max_residual = self.max_residual.max(o.max_residual);
        self.max_shift = self.max_shift.max(o.max_shift);
        self.cross_caps += o.cross_caps;
        self.max_cross_cap_shift = self.max_cross_cap_shift.max(o.max_cross_cap_shift);
        self.pole_ends += o.pole_ends;
        self.trimmed += o.trimmed;
        self.over_under_changed += o.over_under_changed;
        self.on_meshes += o.on_meshes;
    }
}

/// A parameter point of a sheet's surface.
#[derive(Clone, Copy, Debug)]
struct Param {
    sheet: usize,
    patch: usize,
    u: f64,
    v: f64,
}

/// Where Newton starts on one sheet: the parameters, the 4D point the mesh gives there and
/// how far the solution may be from it.
#[derive(Clone, Copy, Debug)]
struct Start {
    param: Param,
    mesh_point: DVec4,
    /// The centre of the triangle in R^4.
    centre: DVec4,
    /// Its longest edge.
    reach: f64,
}

/// A solved parameter point: where it maps, and its 4D point.
#[derive(Clone, Copy, Debug)]
struct Solved {
    param: Param,
    mapped: Mapped,
    point: DVec4,
    /// ∂/∂u and ∂/∂v of the 4D point.
    tangents: [DVec4; 2],
}

/// A curve point refined: the point, its residual and its two parameter points.
#[derive(Clone, Copy, Debug)]
struct Pair {
    point: CurvePoint,
    residual: f64,
    params: [Param; 2],
}

/// The equation that completes a curve point's three.
#[derive(Clone, Copy, Debug)]
enum Fourth {
    /// The point of sheet 0 lies in the plane through `origin` across the curve: its normal
    /// is the cross product of the two sheets' normals where Newton starts (`along`, the
    /// curve's direction from its neighbours, where they are parallel).
    Across { origin: DVec3, along: DVec3 },
    /// The point of sheet 0 lies in the plane through `origin` with normal `normal`.
    Plane { origin: DVec3, normal: DVec3 },
    /// Unknown `index` (u1, v1, u2, v2) equals `value` (a boundary's parameter).
    Fixed { index: usize, value: f64 },
}

struct Solver<'a> {
    sheets: &'a [Sheet<'a>],
    analytic: &'a [Analytic<'a>],
    view: ViewMap,
    /// Accepted residual, in scene units.
    residual: f64,
    /// A residual at rounding, in scene units.
    rounding: f64,
    /// First global triangle and vertex of each sheet (as the curves number them).
    tri_start: Vec<u32>,
    vertex_start: Vec<u32>,
}

impl<'a> Solver<'a> {
    fn new(
        sheets: &'a [Sheet<'a>],
        analytic: &'a [Analytic<'a>],
        view: &View,
        diagonal: f64,
    ) -> Self {
        let starts = |len: &dyn Fn(&Sheet) -> usize| {
            sheets
                .iter()
                .scan(0u32, |acc, s| {
                    let at = *acc;
                    *acc += len(s) as u32;
                    Some(at)
                })
                .collect()
        };
        Solver {
            sheets,
            analytic,
            view: view.map(),
            residual: RESIDUAL * diagonal,
            rounding: ROUNDING * diagonal,
            tri_start: starts(&|s| s.triangles.len()),
            vertex_start: starts(&|s| s.positions.len()),
        }
    }

    /// The first try at point `i` of curve `c`: a curve end at a mesh vertex looks for its
    /// cross-cap, any other point starts Newton from its own triangles.
    fn first_try(&self, c: &Curve, i: usize) -> Try {
        let p = &c.points[i];
        match (end(c, i), p.node) {
            (Some(End::BranchPoint), Node::Vertex(v)) => Try::CrossCap(self.cross_cap(v, p)),
            _ => Try::Pair(self.curve_point(c, i, None)),
        }
    }

    /// Point `i` of curve `c` refined from `from` (its own triangles when `None`).
    fn curve_point(&self, c: &Curve, i: usize, from: Option<[Param; 2]>) -> Option<Pair> {
        let p = &c.points[i];
        // The curve's direction from its neighbours, where the sheets' normals give none.
        let at = |j: Option<usize>| j.map_or(p.position, |j| c.points[j].position);
        let along = at(neighbour(c, i, true)) - at(neighbour(c, i, false));
        let boundary = (end(c, i) == Some(End::Boundary))
            .then(|| self.boundary(p))
            .flatten();
        self.pair(p, along, boundary, from)
    }

    /// A curve with its points refined from the first tries `tries` (one per point), and
    /// what was done. A point whose first try failed starts again from the solution of a
    /// neighbour along the curve, both ways (near a cross-cap, where the two sheets meet at
    /// a small angle and the mesh's point is far off, the neighbour's solution is the
    /// better guess).
    fn finish(&self, c: &Curve, tries: Vec<Try>) -> (Curve, Refinement) {
        let mut r = Refinement::default();
        let n = c.points.len();
        let mut out = c.clone();
        let mut found: Vec<Option<Pair>> = vec![None; n];
        let mut pairs = Vec::new();
        for (i, t) in tries.into_iter().enumerate() {
            match t {
                Try::CrossCap(CrossCap::Found(q)) => {
                    r.refined += 1;
                    r.cross_caps += 1;
                    r.max_cross_cap_shift = r
                        .max_cross_cap_shift
                        .max(q.position.distance(c.points[i].position));
                    out.points[i] = q;
                }
                Try::CrossCap(CrossCap::Pole) => r.pole_ends += 1,
                Try::CrossCap(CrossCap::NotFound) => r.not_converged += 1,
                Try::Pair(pair) => {
                    pairs.push(i);
                    found[i] = pair;
                }
            }
        }
        for forward in [true, false] {
            for k in 0..pairs.len() {
                let i = if forward {
                    pairs[k]
                } else {
                    pairs[pairs.len() - 1 - k]
                };
                if found[i].is_some() {
                    continue;
                }
                let from = neighbour(c, i, !forward).and_then(|j| found[j].map(|f| f.params));
                if from.is_some() {
                    found[i] = self.curve_point(c, i, from);
                }
            }
        }
        // Points that failed next to an end moved onto its cross-cap lie beyond the true
        // curve's end (the mesh's cross-cap is at a vertex, up to a triangle away from the
        // true one): they are dropped, and the curve goes from its last refined point to
        // the cross-cap.
        let mut keep = vec![true; n];
        if !c.closed {
            for (first, step) in [(0usize, 1isize), (n - 1, -1)] {
                if out.points[first] == c.points[first] {
                    continue;
                }
                let mut i = first as isize + step;
                while (1..n as isize - 1).contains(&i) && found[i as usize].is_none() {
                    keep[i as usize] = false;
                    i += step;
                }
            }
        }
        for &i in &pairs {
            let p = &c.points[i];
            match found[i] {
                Some(f) => {
                    r.refined += 1;
                    r.max_residual = r.max_residual.max(f.residual);
                    r.max_shift = r.max_shift.max(f.point.position.distance(p.position));
                    r.over_under_changed +=
                        usize::from(f.point.near() != p.near() && f.point.w[0] != f.point.w[1]);
                    out.points[i] = f.point;
                }
                None if !keep[i] => r.trimmed += 1,
                None => r.not_converged += 1,
            }
        }
        if r.trimmed > 0 {
            let mut k = 0;
            out.points.retain(|_| {
                k += 1;
                keep[k - 1]
            });
        }
        (out, r)
    }

    /// The parametric surface of sheet `s`: [`refine`] only hands the solver points whose
    /// sheets all have one.
    fn surface(&self, s: usize) -> &'a Surface {
        self.analytic[s]
            .surface
            .expect("only points on parametric surfaces are refined")
    }

    /// The sheet and local index of a global vertex.
    fn vertex(&self, global: u32) -> (usize, usize) {
        let s = self.vertex_start.partition_point(|&v| v <= global) - 1;
        (s, (global - self.vertex_start[s]) as usize)
    }

    /// Where Newton starts on `face` for the 3D point `x` of it.
    fn start(&self, face: Face, x: DVec3) -> Start {
        let (s, t) = (face.surface as usize, face.triangle as usize);
        let tri = self.sheets[s].triangles[t];
        let mesh = self.analytic[s].mesh;
        let l = exact::barycentric(x, tri.map(|v| self.sheets[s].positions[v as usize]));
        let uv = mesh.triangle_uv[t];
        let corners = tri.map(|v| mesh.positions[v as usize]);
        let longest = (0..3)
            .map(|k| corners[k].distance(corners[(k + 1) % 3]))
            .fold(0.0, f64::max);
        Start {
            param: Param {
                sheet: s,
                patch: mesh.triangle_patch[t] as usize,
                u: (0..3).map(|k| l[k] * uv[k][0]).sum(),
                v: (0..3).map(|k| l[k] * uv[k][1]).sum(),
            },
            mesh_point: (0..3).map(|k| corners[k] * l[k]).sum(),
            centre: (corners[0] + corners[1] + corners[2]) / 3.0,
            reach: longest,
        }
    }

    /// The surface at a parameter point, mapped by the view.
    fn eval(&self, p: &Param) -> Option<Solved> {
        let e = self.surface(p.sheet).eval(p.patch, p.u, p.v);
        let mapped = self.view.map(&e)?;
        mapped.position.is_finite().then_some(Solved {
            param: *p,
            mapped,
            point: e.p,
            tangents: [e.du, e.dv],
        })
    }

    /// At a curve end on a mesh boundary: the parameter of the boundary its edge lies on,
    /// as the fourth equation.
    fn boundary(&self, p: &CurvePoint) -> Option<Fourth> {
        let Node::Crossing { edge, face } = p.node else {
            return None;
        };
        let label = p
            .faces
            .iter()
            .position(|f| self.tri_start[f.surface as usize] + f.triangle != face)?;
        let f = p.faces[label];
        let (s, t) = (f.surface as usize, f.triangle as usize);
        let base = self.vertex_start[s];
        let tri = self.sheets[s].triangles[t].map(|v| v + base);
        let mesh = self.analytic[s].mesh;
        let uv = mesh.triangle_uv[t];
        let corner = |g: u32| tri.iter().position(|&v| v == g);
        let (a, b) = (uv[corner(edge[0])?], uv[corner(edge[1])?]);
        let d = self.surface(s).domain(mesh.triangle_patch[t] as usize);
        let on = |k: usize, ends: [f64; 2]| {
            ends.into_iter()
                .find(|&e| a[k] == e && b[k] == e)
                .map(|value| Fourth::Fixed {
                    index: 2 * label + k,
                    value,
                })
        };
        on(0, d.u).or_else(|| on(1, d.v))
    }

    /// A curve point refined: the point where its two surfaces' projections meet, with
    /// the fourth equation `boundary` or the plane across the curve (`along` where the
    /// sheets' normals give no direction), and the residual; `None` where Newton fails.
    fn pair(
        &self,
        p: &CurvePoint,
        along: DVec3,
        boundary: Option<Fourth>,
        from: Option<[Param; 2]>,
    ) -> Option<Pair> {
        let mut starts = p.faces.map(|f| self.start(f, p.position));
        if let Some(from) = from {
            starts[0].param = from[0];
            starts[1].param = from[1];
        }
        let fourth = boundary.unwrap_or(Fourth::Across {
            origin: p.position,
            along,
        });
        let (solved, residual) = match self.newton::<4>(&starts, Some(fourth)) {
            Ok(found) => found,
            Err(Failure::Outside(edge)) if boundary.is_none() => {
                self.newton::<4>(&starts, Some(edge)).ok()?
            }
            Err(_) => return None,
        };
        let [a, b] = [solved[0], solved[1]];
        Some(Pair {
            point: CurvePoint {
                position: (a.mapped.position + b.mapped.position) * 0.5,
                w: [a.mapped.w, b.mapped.w],
                ..*p
            },
            residual,
            params: [a.param, b.param],
        })
    }

    /// A triple point refined, with its residual; as it was, with `None`, where Newton
    /// fails.
    fn triple(&self, t: &TriplePoint) -> (TriplePoint, Option<f64>) {
        let starts = t.faces.map(|f| self.start(f, t.position));
        match self.newton::<6>(&starts, None) {
            Ok((s, residual)) => (
                TriplePoint {
                    position: (s[0].mapped.position + s[1].mapped.position + s[2].mapped.position)
                        / 3.0,
                    w: [s[0].mapped.w, s[1].mapped.w, s[2].mapped.w],
                    ..*t
                },
                Some(residual),
            ),
            Err(_) => (*t, None),
        }
    }

    /// Newton's method for `N / 2` parameter points (2 or 3) whose projections coincide,
    /// from `starts`, with `fourth` completing the equations of two: the solved points and
    /// the largest distance between their projections, or why not (see the module
    /// documentation).
    ///
    /// Two points on one surface also meet trivially, wherever they coincide; the
    /// equations are deflated there (Farrell, Birkisson and Funke 2015): multiplied by
    /// 1 + (s / d)^2, d the points' distance in R^4 and s its value at the start, whose
    /// Jacobian pushes Newton away from d = 0 and keeps every other root. A step is
    /// shortened to move no point by more than half its reach.
    fn newton<const N: usize>(
        &self,
        starts: &[Start],
        mut fourth: Option<Fourth>,
    ) -> Result<(Vec<Solved>, f64), Failure> {
        let k = N / 2;
        let mut params: Vec<Param> = starts.iter().map(|s| s.param).collect();
        let mut inside = vec![true; k];
        let mut solved: Vec<Solved> = Vec::with_capacity(k);
        let mut residual = f64::INFINITY;
        let mut previous = f64::INFINITY;
        // The pairs of points on one surface, with their distance at the start.
        let same: Vec<(usize, usize, f64)> = (0..k)
            .flat_map(|i| (i + 1..k).map(move |j| (i, j)))
            .filter(|&(i, j)| starts[i].param.sheet == starts[j].param.sheet)
            .map(|(i, j)| (i, j, starts[i].mesh_point.distance(starts[j].mesh_point)))
            .collect();
        for step in 0..=MAX_STEPS {
            solved.clear();
            for p in &params {
                solved.push(self.eval(p).ok_or(Failure::Other)?);
            }
            let x0 = solved[0].mapped.position;
            residual = (1..k)
                .map(|i| x0.distance(solved[i].mapped.position))
                .fold(0.0, f64::max);
            let mut system = Linear::<N>::coincidence(&solved);
            let fourth_ok = self.fourth_equation(&mut system, &mut fourth, &solved, &params)?;
            // Within the limit: done at rounding, or when a step no longer gains much
            // (Newton's quadratic convergence gains orders of magnitude until rounding).
            if residual <= self.residual
                && fourth_ok
                && (residual <= self.rounding || residual > 0.25 * previous)
            {
                break;
            }
            previous = residual;
            if step == MAX_STEPS {
                break;
            }
            system.deflate(&same, &solved);
            let Some(mut delta) = solve(system.jac, system.rhs) else {
                break;
            };
            limit_step(&mut delta, &solved, starts);
            self.take_step(&mut params, &mut inside, &delta, fourth);
        }
        let near = |i: usize| solved[i].point.distance(starts[i].centre) <= starts[i].reach;
        let apart = |&(i, j, s): &(usize, usize, f64)| {
            solved[i].point.distance(solved[j].point) >= COLLAPSE * s
        };
        if !(residual <= self.residual && (0..k).all(near) && same.iter().all(apart)) {
            return Err(Failure::Other);
        }
        // A point past an open side or a pole: on the surface's extension, not on it.
        if let Some(i) = inside.iter().position(|&ok| !ok) {
            let p = &params[i];
            let d = self.surface(p.sheet).domain(p.patch);
            let past = [
                (p.u < d.u[0], 2 * i, d.u[0]),
                (p.u > d.u[1], 2 * i, d.u[1]),
                (p.v < d.v[0], 2 * i + 1, d.v[0]),
                (p.v > d.v[1], 2 * i + 1, d.v[1]),
            ];
            return Err(match past.iter().find(|p| p.0) {
                Some(&(_, index, value)) => Failure::Outside(Fourth::Fixed { index, value }),
                None => Failure::Other,
            });
        }
        Ok((solved.clone(), residual))
    }

    /// Puts the fourth equation, if any, in the last row of `system`, at the points `solved`
    /// (of parameters `params`); `Across` becomes the plane across the curve there. Gives
    /// whether the equation holds, to within the accepted residual.
    fn fourth_equation<const N: usize>(
        &self,
        system: &mut Linear<N>,
        fourth: &mut Option<Fourth>,
        solved: &[Solved],
        params: &[Param],
    ) -> Result<bool, Failure> {
        if let Some(Fourth::Across { origin, along }) = *fourth {
            let normal = |s: &Solved| s.mapped.tangents[0].cross(s.mapped.tangents[1]);
            let (na, nb) = (normal(&solved[0]), normal(&solved[1]));
            let across = na.cross(nb);
            let normal = if across.length() > 1e-8 * na.length() * nb.length() {
                across
            } else {
                along
            };
            *fourth = Some(Fourth::Plane {
                origin,
                normal: normal.try_normalize().ok_or(Failure::Other)?,
            });
        }
        let mut fourth_ok = true;
        if let Some(f) = *fourth {
            let (jac, rhs) = (&mut system.jac, &mut system.rhs);
            let last = N - 1;
            match f {
                Fourth::Across { .. } => unreachable!("made a plane above"),
                Fourth::Plane { origin, normal } => {
                    let c = normal.dot(solved[0].mapped.position - origin);
                    rhs[last] = -c;
                    jac[last][0] = normal.dot(solved[0].mapped.tangents[0]);
                    jac[last][1] = normal.dot(solved[0].mapped.tangents[1]);
                    fourth_ok = c.abs() <= self.residual;
                }
                Fourth::Fixed { index, value } => {
                    let p = &params[index / 2];
                    let current = if index % 2 == 0 { p.u } else { p.v };
                    rhs[last] = value - current;
                    jac[last][index] = 1.0;
                    fourth_ok = current == value;
                }
            }
        }
        Ok(fourth_ok)
    }

    /// Moves the parameter points by the Newton step `delta`, across patches where the
    /// surface's charts do, and records which stay inside their patch; a point with a
    /// `Fixed` fourth equation is put exactly on its boundary.
    fn take_step(
        &self,
        params: &mut [Param],
        inside: &mut [bool],
        delta: &[f64],
        fourth: Option<Fourth>,
    ) {
        for (i, p) in params.iter_mut().enumerate() {
            let (patch, u, v, ok) =
                self.surface(p.sheet)
                    .chart(p.patch, p.u + delta[2 * i], p.v + delta[2 * i + 1]);
            (p.patch, p.u, p.v) = (patch, u, v);
            inside[i] = ok;
        }
        if let Some(Fourth::Fixed { index, value }) = fourth {
            // Exactly on the boundary, not a rounding off it.
            let p = &mut params[index / 2];
            if index % 2 == 0 {
                p.u = value;
            } else {
                p.v = value;
            }
        }
    }

    /// The cross-cap near the mesh vertex `global` where the curve point `p` ends its
    /// curve.
    fn cross_cap(&self, global: u32, p: &CurvePoint) -> CrossCap {
        let (s, v) = self.vertex(global);
        let (mesh, surface) = (self.analytic[s].mesh, self.surface(s));
        let (mut patch, [mut u, mut w]) = (mesh.patch[v] as usize, mesh.uv[v]);
        let d = surface.domain(patch);
        let on_pole = |side: Side, at: bool| at && matches!(d.side(side), SideRule::Pole);
        if on_pole(Side::U0, u == d.u[0])
            || on_pole(Side::U1, u == d.u[1])
            || on_pole(Side::V0, w == d.v[0])
            || on_pole(Side::V1, w == d.v[1])
        {
            return CrossCap::Pole;
        }
        // How far the cross-cap may be: in longest edges of the faces at the vertex.
        let reach = p
            .faces
            .iter()
            .map(|f| self.start(*f, p.position).reach)
            .fold(0.0, f64::max);
        let origin = mesh.positions[v];
        let mut inside = true;
        for _ in 0..MAX_STEPS {
            let e = surface.eval(patch, u, w);
            let Some(j) = self.view.jets(&e) else {
                return CrossCap::NotFound;
            };
            let f = |g: fn(&Jet) -> f64| DVec3::new(g(&j[0]), g(&j[1]), g(&j[2]));
            let (fu, fv) = (f(|c| c.du), f(|c| c.dv));
            let (fuu, fuv, fvv) = (f(|c| c.duu), f(|c| c.duv), f(|c| c.dvv));
            let g = fu.cross(fv);
            let scale = e.du.length() * e.dv.length();
            // The surface itself must be regular here (not a parametrization singularity).
            let area2 = e.du.length_squared() * e.dv.length_squared() - e.du.dot(e.dv).powi(2);
            if area2.partial_cmp(&(1e-12 * e.du.length_squared() * e.dv.length_squared()))
                != Some(std::cmp::Ordering::Greater)
            {
                return CrossCap::NotFound;
            }
            if g.length() <= 1e-3 * CROSS_CAP_RANK * scale {
                break;
            }
            let gu = fuu.cross(fv) + fu.cross(fuv);
            let gv = fuv.cross(fv) + fu.cross(fvv);
            let Some([du, dw]) = solve(
                [[gu.dot(gu), gu.dot(gv)], [gu.dot(gv), gv.dot(gv)]],
                [-gu.dot(g), -gv.dot(g)],
            ) else {
                return CrossCap::NotFound;
            };
            let moved = (du.abs() / (1.0 + u.abs())).max(dw.abs() / (1.0 + w.abs()));
            let next = surface.chart(patch, u + du, w + dw);
            (patch, u, w, inside) = next;
            if moved < 1e-15 {
                break;
            }
        }
        let e = surface.eval(patch, u, w);
        let (Some(m), Some(j)) = (self.view.map(&e), self.view.jets(&e)) else {
            return CrossCap::NotFound;
        };
        let fu = DVec3::new(j[0].du, j[1].du, j[2].du);
        let fv = DVec3::new(j[0].dv, j[1].dv, j[2].dv);
        let rank = fu.cross(fv).length() / (e.du.length() * e.dv.length());
        if inside && rank <= CROSS_CAP_RANK && e.p.distance(origin) <= CROSS_CAP_REACH * reach {
            CrossCap::Found(CurvePoint {
                position: m.position,
                w: [m.w, m.w],
                ..*p
            })
        } else {
            CrossCap::NotFound
        }
    }
}

/// How curve point `i` of `c` ends the curve, if it does.
fn end(c: &Curve, i: usize) -> Option<End> {
    match (c.closed, i) {
        (true, _) => None,
        (false, 0) => Some(c.ends[0]),
        (false, i) if i + 1 == c.points.len() => Some(c.ends[1]),
        _ => None,
    }
}

/// The point after (`forward`) or before point `i` along curve `c`, round a closed curve.
fn neighbour(c: &Curve, i: usize, forward: bool) -> Option<usize> {
    let n = c.points.len();
    match (forward, i) {
        (true, i) if i + 1 < n => Some(i + 1),
        (true, _) => c.closed.then_some(0),
        (false, 0) => c.closed.then(|| n - 1),
        (false, i) => Some(i - 1),
    }
}

/// A curve point's first try.
enum Try {
    /// At a curve end on a mesh vertex: the search for its cross-cap.
    CrossCap(CrossCap),
    /// Elsewhere: Newton from the point's own triangles.
    Pair(Option<Pair>),
}

/// Why Newton's method gave no point.
enum Failure {
    /// The solution lies past an open side or a pole of its patch: on the boundary, with
    /// this equation, is where the curve leaves the surface.
    Outside(Fourth),
    /// Anything else: no convergence, out of reach, or the trivial solution.
    Other,
}

/// What the search for a cross-cap at a curve's end found.
enum CrossCap {
    /// The curve end at the cross-cap.
    Found(CurvePoint),
    /// The end is a pole of the parametrization.
    Pole,
    /// Nothing within reach: the end stays.
    NotFound,
}

/// Solves a x = b by Gaussian elimination with partial pivoting; `None` when `a` is
/// singular or the solution is not finite.
fn solve<const N: usize>(mut a: [[f64; N]; N], mut b: [f64; N]) -> Option<[f64; N]> {
    for col in 0..N {
        let pivot = (col..N).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[pivot][col] == 0.0 || !a[pivot][col].is_finite() {
            return None;
        }
        a.swap(col, pivot);
        b.swap(col, pivot);
        for row in col + 1..N {
            let f = a[row][col] / a[col][col];
            let pivot_row = a[col];
            for (x, p) in a[row][col..].iter_mut().zip(&pivot_row[col..]) {
                *x -= f * p;
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = [0.0; N];
    for row in (0..N).rev() {
        let s: f64 = (row + 1..N).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - s) / a[row][row];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// The linear system of one Newton step for `N / 2` points: the Jacobian and the
/// right-hand side, minus the equations' values.
struct Linear<const N: usize> {
    jac: [[f64; N]; N],
    rhs: [f64; N],
}

impl<const N: usize> Linear<N> {
    /// The equations that the points `solved` project to one point, x0 - xi for each other
    /// point, three rows each; the last row is left for the fourth equation.
    fn coincidence(solved: &[Solved]) -> Self {
        let k = N / 2;
        let x0 = solved[0].mapped.position;
        let mut jac = [[0.0; N]; N];
        let mut rhs = [0.0; N];
        for i in 1..k {
            let d = x0 - solved[i].mapped.position;
            for r in 0..3 {
                let row = 3 * (i - 1) + r;
                rhs[row] = -d[r];
                jac[row][0] = solved[0].mapped.tangents[0][r];
                jac[row][1] = solved[0].mapped.tangents[1][r];
                jac[row][2 * i] = -solved[i].mapped.tangents[0][r];
                jac[row][2 * i + 1] = -solved[i].mapped.tangents[1][r];
            }
        }
        Linear { jac, rhs }
    }

    /// Deflates the equations at the trivial solutions of the pairs of points on one
    /// surface (`same`, with their distance at the start; see [`Solver::newton`]).
    fn deflate(&mut self, same: &[(usize, usize, f64)], solved: &[Solved]) {
        // Deflation: G = M F with M the product of the factors, so
        // dG = M dF + F (dM)^T and dM = M sum(dm / m). -F is the right-hand side.
        let mut grad = [0.0; N];
        let mut factor = 1.0;
        for &(i, j, s) in same {
            let d = solved[i].point - solved[j].point;
            let d2 = d.length_squared();
            if d2 == 0.0 || s == 0.0 {
                continue;
            }
            let m = 1.0 + s * s / d2;
            // dm = -(s^2 / d2^2) d(d2), d(d2) = 2 d . (dPi, -dPj).
            let c = -s * s / (d2 * d2) * 2.0 / m;
            for t in 0..2 {
                grad[2 * i + t] += c * d.dot(solved[i].tangents[t]);
                grad[2 * j + t] -= c * d.dot(solved[j].tangents[t]);
            }
            factor *= m;
        }
        if factor != 1.0 {
            // dG / M = dF + F grad^T (grad holding dM / M); G / M = F.
            let Linear { jac, rhs } = self;
            for r in 0..N {
                for c in 0..N {
                    jac[r][c] -= rhs[r] * grad[c];
                }
            }
        }
    }
}

/// Shortens the Newton step `delta` so that no point (of `solved`, from `starts`) moves by
/// more than half its reach.
fn limit_step<const N: usize>(delta: &mut [f64; N], solved: &[Solved], starts: &[Start]) {
    let k = N / 2;
    let longest = (0..k)
        .map(|i| {
            let t = solved[i].tangents;
            (t[0] * delta[2 * i] + t[1] * delta[2 * i + 1]).length() / (0.5 * starts[i].reach)
        })
        .fold(0.0, f64::max);
    if longest > 1.0 {
        delta.iter_mut().for_each(|d| *d /= longest);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solve_gives_the_exact_answer_of_a_small_system_and_refuses_a_singular_one() {
        let a = [[2.0, 1.0, 0.0], [1.0, 3.0, 1.0], [0.0, 1.0, 4.0]];
        let x = [1.0, -2.0, 0.5];
        let b = [0, 1, 2].map(|r| (0..3).map(|c| a[r][c] * x[c]).sum::<f64>());
        let got = solve(a, b).unwrap();
        for k in 0..3 {
            assert!((got[k] - x[k]).abs() < 1e-15, "{got:?}");
        }
        assert!(solve([[1.0, 2.0], [2.0, 4.0]], [1.0, 2.0]).is_none());
    }
}
