//! Sampling: a surface of the catalogue becomes a triangle mesh in R^4.
//!
//! Takes: a [`Surface`] and sampling settings. Gives: a [`Mesh4`] with, per vertex, the
//! 4D point, the two tangents ∂p/∂u and ∂p/∂v, the parameters (patch, u, v); and triangles
//! oriented counter-clockwise in (u, v).
//!
//! Guarantees: seams and poles are welded by the domain rules of the surface, never by
//! distance; closed surfaces give closed manifold meshes (every edge in exactly two
//! triangles) with the surface's Euler characteristic; orientable surfaces give consistently
//! oriented meshes; no triangle repeats a vertex. [`Mesh4::validate`] measures all of this.

mod uniform;

pub use uniform::sample_uniform;

use crate::surfaces::{Eval4, Surface};
use glam::DVec4;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;

/// How to sample a surface.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "method", rename_all = "snake_case", deny_unknown_fields)]
pub enum Sampling {
    /// A uniform grid of `u` by `v` cells on every patch.
    Uniform {
        /// Cells along u per patch (even, 4 to 4096).
        u: usize,
        /// Cells along v per patch (even, 4 to 4096).
        v: usize,
    },
}

impl Default for Sampling {
    fn default() -> Self {
        Sampling::Uniform { u: 64, v: 64 }
    }
}

impl Sampling {
    /// Checks the settings: `Err((field, message))` names the first bad one.
    pub fn check(&self) -> Result<(), (&'static str, String)> {
        match *self {
            Sampling::Uniform { u, v } => {
                for (field, n) in [("u", u), ("v", v)] {
                    if !(2..=4096).contains(&n) || n % 2 != 0 {
                        return Err((
                            field,
                            format!(
                                "must be an even number of cells from 2 to 4096 (seams glued at half a side need a node there), got {n}"
                            ),
                        ));
                    }
                }
                Ok(())
            }
        }
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
        // For each undirected edge: number of uses in each direction.
        let mut edges: HashMap<(u32, u32), [usize; 2]> = HashMap::new();
        let mut used = vec![false; self.positions.len()];
        for t in &self.triangles {
            let [a, b, c] = *t;
            let (pa, pb, pc) = (
                self.positions[a as usize],
                self.positions[b as usize],
                self.positions[c as usize],
            );
            if a == b || b == c || a == c || gram_area2(pb - pa, pc - pa) <= 0.0 {
                stats.degenerate_triangles += 1;
            }
            for (x, y) in [(a, b), (b, c), (c, a)] {
                let key = (x.min(y), x.max(y));
                edges.entry(key).or_default()[usize::from(x > y)] += 1;
            }
            for i in t {
                used[*i as usize] = true;
            }
        }
        stats.edges = edges.len();
        for uses in edges.values() {
            match uses[0] + uses[1] {
                1 => stats.boundary_edges += 1,
                2 => stats.orientation_conflicts += usize::from(uses[0] != 1),
                _ => stats.non_manifold_edges += 1,
            }
        }
        stats.vertices = used.iter().filter(|u| **u).count();
        stats.unused_vertices = used.len() - stats.vertices;
        stats.non_finite_vertices = (0..self.positions.len())
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
