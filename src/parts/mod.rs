//! The hand-off: what a scene produced, in the one shape every reader takes.
//!
//! Takes: borrowed slices of the products of a build ([`crate::pipeline::Built::parts`]) or
//! of a scene's `.glb` read back ([`crate::import::ImportedScene::parts`]). Gives: [`Parts`],
//! per surface its projected mesh ([`SurfacePart`]) and its halo ([`HaloPart`], none where
//! the surface has none), and the intersection curves of all surfaces together; and
//! [`HaloIndex`], the halos' tetrahedra in one BVH, for the question the verification and the
//! renderer both ask (is this point of a sheet hidden?). The verification, the renderer and
//! the viewer read nothing else.
//! Guarantees: nothing is copied; a [`HaloPart`] is only made of a halo with tetrahedra and
//! with every per-vertex value its readers need.

mod index;
mod near;

pub use index::HaloIndex;
pub(crate) use index::{inserted_sets, tet_box};
pub(crate) use near::TriangleHiders;

use crate::intersect::{Curves, Sheet};
use crate::stipple::Stipples;
use glam::DVec3;

/// One surface after the view, as its readers take it.
#[derive(Clone, Copy, Debug)]
pub struct SurfacePart<'a> {
    /// Vertex positions.
    pub positions: &'a [DVec3],
    /// w-depth of each vertex.
    pub w: &'a [f64],
    /// Unit normal of each vertex (for shading).
    pub normals: &'a [DVec3],
    /// Surface parameters (u, v) of each vertex (for ribbons), when known.
    pub uv: Option<&'a [[f64; 2]]>,
    /// Triangles.
    pub triangles: &'a [[u32; 3]],
    /// The stipples fixed to the surface's 4D mesh (for the stipple style), when made.
    pub stipples: Option<&'a Stipples>,
}

/// A surface's halo as its readers take it.
#[derive(Clone, Copy, Debug)]
pub struct HaloPart<'a> {
    /// Vertex positions: offsets 0..n (t = 0), n..2n (t = 1), the surface 2n..3n (t = 1/2),
    /// inserted vertices after.
    pub positions: &'a [DVec3],
    /// t of each vertex.
    pub t: &'a [f64],
    /// d_orig of each vertex.
    pub d_orig: &'a [f64],
    /// Positively oriented tetrahedra.
    pub tets: &'a [[u32; 4]],
    /// Surface vertices n.
    pub surface_vertices: usize,
    /// Depth increment delta_d of eq. 3.
    pub delta_d: f64,
    /// Dead zone delta_t of eq. 3.
    pub delta_t: f64,
}

impl HaloPart<'_> {
    /// Surface vertex v's half-width rho: half the distance between its two offsets.
    pub(crate) fn half_width(&self, v: usize) -> f64 {
        let n = self.surface_vertices;
        (self.positions[v + n] - self.positions[v]).length() * 0.5
    }
}

/// What a scene produced: its surfaces, their halos (one per surface, `None` where a
/// surface has none) and the intersection curves of all surfaces together.
#[derive(Clone, Debug)]
pub struct Parts<'a> {
    /// The surfaces.
    pub surfaces: Vec<SurfacePart<'a>>,
    /// Their halos, one per surface.
    pub halos: Vec<Option<HaloPart<'a>>>,
    /// The intersection curves.
    pub curves: &'a Curves,
}

impl<'a> Parts<'a> {
    /// The surfaces as the intersection stage reads them.
    pub fn sheets(&self) -> Vec<Sheet<'a>> {
        self.surfaces
            .iter()
            .map(|s| Sheet {
                positions: s.positions,
                w: s.w,
                triangles: s.triangles,
            })
            .collect()
    }
}
