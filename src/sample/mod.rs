//! Sampling: a surface of the catalogue becomes a triangle mesh in R^4.
//!
//! Takes: a [`Surface`] and sampling settings: a tolerance for the adaptive sampler
//! ([`sample_adaptive`], the default) or a grid ([`sample_uniform`]). Gives: a [`Mesh4`]
//! with, per vertex, the 4D point, the two tangents ∂p/∂u and ∂p/∂v, the parameters
//! (patch, u, v); and triangles oriented counter-clockwise in (u, v), each with its patch and
//! its corners' parameters on that patch.
//!
//! Guarantees: the adaptive sampler, when it reports `complete`, leaves every triangle within
//! the tolerance of the surface as [`audit`] measures it (the audit shares no code with the
//! sampler but the list of points it checks), and with [`ErrorBound::Proven`] as [`prove`]
//! bounds it at every point, by interval arithmetic; seams and poles are welded by the domain rules
//! of the surface, never by distance; closed surfaces give closed manifold meshes (every edge
//! in exactly two triangles) with the surface's Euler characteristic; orientable surfaces
//! give consistently oriented meshes; no triangle repeats a vertex or folds over in (u, v).
//! [`Mesh4::validate`] measures the combinatorics.

mod adaptive;
mod audit;
mod proven;
mod source;
mod uniform;

pub use adaptive::{
    Finer, metric_aspect, sample_adaptive, sample_adaptive_finer, sample_adaptive_through,
    sample_adaptive_to,
};
pub use audit::{AUDIT_POINTS, Audit, audit, audit_until};
pub use proven::{Proof, corner_error, prove, prove_until, triangle_bound};
pub use source::{MeshData4, MeshSurface, Source, mesh_from_data, mesh_tangents, mesh_topology};
pub use uniform::sample_uniform;

use crate::limits::{ABSOLUTE_TOLERANCE, FieldError, GRID_CELLS, RELATIVE_TOLERANCE, TRIANGLES};
use crate::progress::Cancel;
use crate::surfaces::{Eval4, Surface};
use glam::DVec4;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// How to sample a surface.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "method", rename_all = "snake_case", deny_unknown_fields)]
pub enum Sampling {
    /// Adaptive refinement until every triangle is within a tolerance of the surface.
    Adaptive {
        /// Largest distance in R^4 from a triangle to the surface, relative to the diagonal
        /// of the surface's 4D bounding box (default 1e-3 when no tolerance is given).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        tolerance: Option<f64>,
        /// The same bound as an absolute length, instead of `tolerance`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        absolute_tolerance: Option<f64>,
        /// Refinement stops (with a warning, and `complete: false` in the report) before
        /// the mesh exceeds this many triangles.
        #[serde(default = "default_max_triangles")]
        max_triangles: usize,
        /// Which bound of each triangle's error is held to the tolerance: `audited` (the
        /// default: at the audit's points) or `proven` (at every point, by interval
        /// arithmetic: [`triangle_bound`]).
        #[serde(default, skip_serializing_if = "ErrorBound::is_audited")]
        bound: ErrorBound,
    },
    /// A uniform grid of `u` by `v` cells on every patch.
    Uniform {
        /// Cells along u per patch (even, within [`crate::limits::GRID_CELLS`]).
        u: usize,
        /// Cells along v per patch (even, within [`crate::limits::GRID_CELLS`]).
        v: usize,
    },
}

/// Which bound of a triangle's distance from its surface the adaptive sampler holds to the
/// tolerance.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ErrorBound {
    /// The distance measured at the audit's points ([`AUDIT_POINTS`]): strong evidence,
    /// and the cheaper.
    #[default]
    Audited,
    /// The bound proven over the whole triangle by interval arithmetic
    /// ([`triangle_bound`]): the triangles' distance from the true surface is at most the
    /// tolerance everywhere.
    Proven,
}

impl ErrorBound {
    fn is_audited(&self) -> bool {
        *self == ErrorBound::Audited
    }
}

/// Relative tolerance of an adaptive sampling that gives none.
pub const DEFAULT_TOLERANCE: f64 = 1e-3;

/// Triangle budget of an adaptive sampling that gives none.
pub const DEFAULT_MAX_TRIANGLES: usize = 2_000_000;

fn default_max_triangles() -> usize {
    DEFAULT_MAX_TRIANGLES
}

impl Default for Sampling {
    fn default() -> Self {
        Sampling::adaptive(DEFAULT_TOLERANCE)
    }
}

impl Sampling {
    /// Adaptive sampling at a relative tolerance, with the default budget.
    pub fn adaptive(relative: f64) -> Self {
        Sampling::Adaptive {
            tolerance: Some(relative),
            absolute_tolerance: None,
            max_triangles: DEFAULT_MAX_TRIANGLES,
            bound: ErrorBound::Audited,
        }
    }

    /// The method's name, as in scene files.
    pub fn method(&self) -> &'static str {
        match self {
            Sampling::Adaptive { .. } => "adaptive",
            Sampling::Uniform { .. } => "uniform",
        }
    }

    /// The absolute tolerance of an adaptive sampling of a surface whose bounding diagonal
    /// is `diagonal`; `None` for a grid.
    pub fn absolute_tolerance(&self, diagonal: f64) -> Option<f64> {
        match *self {
            Sampling::Adaptive {
                tolerance,
                absolute_tolerance,
                ..
            } => Some(absolute(tolerance, absolute_tolerance, diagonal)),
            Sampling::Uniform { .. } => None,
        }
    }

    /// The bound an adaptive sampling holds its triangles to (a grid's is audited).
    pub fn bound(&self) -> ErrorBound {
        match *self {
            Sampling::Adaptive { bound, .. } => bound,
            Sampling::Uniform { .. } => ErrorBound::Audited,
        }
    }

    /// The most triangles a surface of `patches` patches can get.
    pub fn max_triangles(&self, patches: usize) -> usize {
        match *self {
            Sampling::Adaptive { max_triangles, .. } => max_triangles,
            Sampling::Uniform { u, v } => u.saturating_mul(v).saturating_mul(2 * patches),
        }
    }

    /// Checks the settings: names the first bad field.
    pub fn check(&self) -> Result<(), FieldError> {
        match *self {
            Sampling::Adaptive {
                tolerance,
                absolute_tolerance,
                max_triangles,
                ..
            } => {
                if tolerance.is_some() && absolute_tolerance.is_some() {
                    return Err(FieldError::new(
                        "absolute_tolerance",
                        "give either `tolerance` (relative to the bounding diagonal) or `absolute_tolerance`, not both",
                    ));
                }
                if let Some(t) = tolerance {
                    RELATIVE_TOLERANCE.check("tolerance", t)?;
                }
                if let Some(a) = absolute_tolerance {
                    ABSOLUTE_TOLERANCE.check("absolute_tolerance", a)?;
                }
                TRIANGLES.check("max_triangles", max_triangles)
            }
            Sampling::Uniform { u, v } => {
                for (field, n) in [("u", u), ("v", v)] {
                    GRID_CELLS.check(field, n)?;
                    if n % 2 != 0 {
                        return Err(FieldError::new(
                            field,
                            format!(
                                "must be an even number of cells (seams glued at half a side need a node there), got {n}"
                            ),
                        ));
                    }
                }
                Ok(())
            }
        }
    }
}

/// A sampled surface.
#[derive(Clone, Debug)]
pub struct Sampled {
    /// The mesh.
    pub mesh: Mesh4,
    /// The absolute tolerance the sampler aimed at (adaptive sampling only).
    pub tolerance: Option<f64>,
    /// The diagonal of the surface's 4D bounding box ([`bounding_diagonal`]).
    pub diagonal: f64,
    /// Whether the sampler met its tolerance everywhere (always true for a grid).
    pub complete: bool,
}

/// The absolute tolerance of an adaptive sampling's settings: `absolute` where given, else
/// `relative` (or [`DEFAULT_TOLERANCE`]) of the surface's `diagonal`.
fn absolute(relative: Option<f64>, absolute: Option<f64>, diagonal: f64) -> f64 {
    absolute.unwrap_or(relative.unwrap_or(DEFAULT_TOLERANCE) * diagonal)
}

/// Samples a surface as `sampling` says.
pub fn sample(surface: &Surface, sampling: &Sampling) -> Sampled {
    sample_finer(surface, sampling, &[], Cancel::never())
}

/// [`sample`], an adaptive sampling holding the triangles that meet the rectangles `finer`
/// to their own tolerance ([`sample_adaptive_finer`]); a grid is sampled as it is. Once
/// `cancel` is cancelled the adaptive sampler stops with the mesh it has, which the caller
/// drops.
pub fn sample_finer(
    surface: &Surface,
    sampling: &Sampling,
    finer: &[Finer],
    cancel: &Cancel,
) -> Sampled {
    let diagonal = bounding_diagonal(surface);
    match *sampling {
        Sampling::Uniform { u, v } => Sampled {
            mesh: sample_uniform(surface, u, v),
            tolerance: None,
            diagonal,
            complete: true,
        },
        Sampling::Adaptive {
            tolerance,
            absolute_tolerance,
            max_triangles,
            bound,
        } => {
            let tolerance = absolute(tolerance, absolute_tolerance, diagonal);
            let out =
                sample_adaptive_finer(surface, tolerance, bound, max_triangles, finer, cancel);
            Sampled {
                mesh: out.mesh,
                tolerance: Some(tolerance),
                diagonal,
                complete: out.complete,
            }
        }
    }
}

/// The audited max error of a uniform grid of about `triangles` triangles over the whole
/// surface (square grids of an even number of cells on every patch, at least the surface's
/// smallest grid): what budget-stopped adaptive sampling is compared with.
pub fn uniform_error(surface: &Surface, triangles: usize) -> f64 {
    let [min_u, min_v] = surface.min_cells();
    let side = (triangles as f64 / (2 * surface.patch_count().max(1)) as f64).sqrt();
    let even = |min: usize| ((side / 2.0).round() as usize * 2).clamp(min.max(4), GRID_CELLS.hi);
    audit(surface, &sample_uniform(surface, even(min_u), even(min_v))).max_error
}

/// The diagonal of the surface's bounding box in R^4, from its points on a 64 x 64 grid of
/// every patch: the length that relative tolerances and errors refer to.
pub fn bounding_diagonal(surface: &Surface) -> f64 {
    const N: usize = 64;
    let mut lo = DVec4::splat(f64::INFINITY);
    let mut hi = DVec4::splat(f64::NEG_INFINITY);
    for patch in 0..surface.patch_count() {
        let d = surface.domain(patch);
        for j in 0..=N {
            for i in 0..=N {
                let u = d.u[0] + (d.u[1] - d.u[0]) * i as f64 / N as f64;
                let v = d.v[0] + (d.v[1] - d.v[0]) * j as f64 / N as f64;
                let p = surface.point(patch, u, v);
                if p.is_finite() {
                    lo = lo.min(p);
                    hi = hi.max(p);
                }
            }
        }
    }
    let diagonal = (hi - lo).length();
    if diagonal.is_finite() && diagonal > 0.0 {
        diagonal
    } else {
        1.0
    }
}

/// A triangle mesh of a surface in R^4.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh4 {
    /// Vertex positions.
    pub positions: Vec<DVec4>,
    /// ∂p/∂u at each vertex.
    pub tangent_u: Vec<DVec4>,
    /// ∂p/∂v at each vertex.
    pub tangent_v: Vec<DVec4>,
    /// Surface parameters (u, v) of each vertex, on its patch.
    pub uv: Vec<[f64; 2]>,
    /// Patch index of each vertex.
    pub patch: Vec<u32>,
    /// Triangles, counter-clockwise in (u, v).
    pub triangles: Vec<[u32; 3]>,
    /// The patch each triangle was cut from.
    pub triangle_patch: Vec<u32>,
    /// The (u, v) of each triangle's corners on its own patch. A vertex welded across a seam
    /// or collapsed into a pole has other parameters on other patches; the audit compares
    /// each triangle with the surface through these.
    pub triangle_uv: Vec<[[f64; 2]; 3]>,
}

/// Statistics of a mesh's combinatorics, from [`Mesh4::validate`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct MeshStats {
    /// Vertices used by at least one triangle.
    pub vertices: usize,
    /// Triangles.
    pub triangles: usize,
    /// Distinct edges.
    pub edges: usize,
    /// Edges in exactly one triangle.
    pub boundary_edges: usize,
    /// Edges in more than two triangles.
    pub non_manifold_edges: usize,
    /// Interior edges used twice in the same direction (orientation conflicts).
    pub orientation_conflicts: usize,
    /// Triangles that repeat a vertex or have zero area in R^4.
    pub degenerate_triangles: usize,
    /// Vertices never used by a triangle.
    pub unused_vertices: usize,
    /// Vertices with a non-finite position or tangent.
    pub non_finite_vertices: usize,
    /// V - E + F.
    pub euler_characteristic: i64,
}

impl MeshStats {
    /// Whether every edge lies in one or two triangles and nothing is degenerate or NaN.
    pub fn is_manifold(&self) -> bool {
        self.non_manifold_edges == 0
            && self.degenerate_triangles == 0
            && self.unused_vertices == 0
            && self.non_finite_vertices == 0
    }
}

impl Mesh4 {
    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Measures the combinatorics of the mesh (see [`MeshStats`]).
    pub fn validate(&self) -> MeshStats {
        let mut stats = MeshStats {
            triangles: self.triangles.len(),
            ..MeshStats::default()
        };
        // Every directed edge as (low, high, direction), sorted so the uses of an undirected
        // edge are adjacent; on the cores (the order is the same whatever the threads).
        let mut directed: Vec<(u32, u32, bool)> = self
            .triangles
            .par_iter()
            .flat_map_iter(|&[a, b, c]| {
                [(a, b), (b, c), (c, a)].map(|(x, y)| (x.min(y), x.max(y), x > y))
            })
            .collect();
        directed.par_sort_unstable();
        stats.degenerate_triangles = self
            .triangles
            .par_iter()
            .filter(|&&[a, b, c]| {
                let [pa, pb, pc] = [a, b, c].map(|i| self.positions[i as usize]);
                a == b || b == c || a == c || gram_area2(pb - pa, pc - pa) <= 0.0
            })
            .count();
        // A vertex is used when an edge ends at it.
        let mut used = vec![false; self.positions.len()];
        for uses in directed.chunk_by(|p, q| (p.0, p.1) == (q.0, q.1)) {
            stats.edges += 1;
            match uses.len() {
                1 => stats.boundary_edges += 1,
                2 => stats.orientation_conflicts += usize::from(uses[0].2 == uses[1].2),
                _ => stats.non_manifold_edges += 1,
            }
            used[uses[0].0 as usize] = true;
            used[uses[0].1 as usize] = true;
        }
        stats.vertices = used.iter().filter(|u| **u).count();
        stats.unused_vertices = used.len() - stats.vertices;
        stats.non_finite_vertices = (0..self.positions.len())
            .into_par_iter()
            .filter(|&i| {
                !(self.positions[i].is_finite()
                    && self.tangent_u[i].is_finite()
                    && self.tangent_v[i].is_finite())
            })
            .count();
        stats.euler_characteristic =
            stats.vertices as i64 - stats.edges as i64 + stats.triangles as i64;
        stats
    }

    /// Appends the vertices at `at`, (patch, u, v) each (see [`eval_vertex`]), in that order,
    /// evaluated on the cores.
    fn push_vertices(&mut self, surface: &Surface, at: &[(usize, f64, f64)]) {
        let start = self.positions.len();
        let end = start + at.len();
        self.positions.resize(end, DVec4::ZERO);
        self.tangent_u.resize(end, DVec4::ZERO);
        self.tangent_v.resize(end, DVec4::ZERO);
        self.positions[start..]
            .par_iter_mut()
            .zip(&mut self.tangent_u[start..])
            .zip(&mut self.tangent_v[start..])
            .zip(at)
            .for_each(|(((p, du), dv), &(patch, u, v))| {
                let e = eval_vertex(surface, patch, u, v);
                (*p, *du, *dv) = (e.p, e.du, e.dv);
            });
        self.uv.extend(at.iter().map(|&(_, u, v)| [u, v]));
        self.patch
            .extend(at.iter().map(|&(patch, _, _)| patch as u32));
    }

    /// Appends a triangle cut from `patch` with its corners' parameters, unless welding made
    /// it repeat a vertex (a triangle with an edge on a pole).
    fn push_triangle(&mut self, t: [u32; 3], patch: usize, uv: [[f64; 2]; 3]) {
        if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
            self.triangles.push(t);
            self.triangle_patch.push(patch as u32);
            self.triangle_uv.push(uv);
        }
    }

    /// Axis-aligned bounding box of the positions, or `None` for an empty mesh.
    pub fn bounds(&self) -> Option<(DVec4, DVec4)> {
        let first = *self.positions.first()?;
        Some(
            self.positions
                .iter()
                .fold((first, first), |(lo, hi), p| (lo.min(*p), hi.max(*p))),
        )
    }
}

/// Union-find over sample points, for welding by the domain rules.
pub(super) struct Classes(pub(super) Vec<usize>);

impl Classes {
    pub(super) fn find(&mut self, mut i: usize) -> usize {
        while self.0[i] != i {
            self.0[i] = self.0[self.0[i]];
            i = self.0[i];
        }
        i
    }

    /// Joins two classes, keeping the smaller node as the representative.
    pub(super) fn union(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        let (lo, hi) = (ra.min(rb), ra.max(rb));
        self.0[hi] = lo;
    }
}

/// Squared area (times 4) of the parallelogram spanned by a and b, by the Gram determinant.
fn gram_area2(a: DVec4, b: DVec4) -> f64 {
    a.length_squared() * b.length_squared() - a.dot(b).powi(2)
}

/// Evaluates a surface for a mesh vertex. At a branch point of the parametrization (the
/// only places where a catalogue surface's derivatives are not finite) the tangents are
/// taken at a point moved 1e-6 of the way towards the patch centre: the surface's tangent
/// plane there is the limit of those planes, and the halo stage only needs directions.
pub(crate) fn eval_vertex(surface: &Surface, patch: usize, u: f64, v: f64) -> Eval4 {
    let e = surface.eval(patch, u, v);
    if e.tangents_finite() {
        return e;
    }
    let d = surface.domain(patch);
    let (cu, cv) = ((d.u[0] + d.u[1]) / 2.0, (d.v[0] + d.v[1]) / 2.0);
    let inner = surface.eval(patch, u + (cu - u) * 1e-6, v + (cv - v) * 1e-6);
    Eval4 {
        p: e.p,
        du: inner.du,
        dv: inner.dv,
        duu: inner.duu,
        duv: inner.duv,
        dvv: inner.dvv,
    }
}
