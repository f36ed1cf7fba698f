//! The stipple style on the GPU (paper 003): each surface's ranked blue-noise set, made
//! once on the CPU from the 4D mesh ([`crate::Stipples`]), uploaded as (triangle, rank,
//! barycentric coordinates) per stipple and, per triangle, the surface's 4D area over the
//! triangle's.
//!
//! Per frame the vertex shader (`stipple_vs` in `viewer.wgsl`) places each stipple from its
//! triangle's vertices as they are drawn now (after a 4D turn, the turned ones), so the
//! stipples stay fixed to the mesh, and decides as the CPU renderer does
//! (`render::stipple`): the tone of a white surface under the shaded style's lights, the
//! density of [`crate::internals::density`], the triangle's screen area over its 4D area;
//! the stipple is drawn when its rank is below that prefix of the ranking, and when it lies
//! on the first surface the halos leave visible at its pixel (the surfaces' depth buffer,
//! written by the shaded style's pass with the halos' discards). A drawn stipple is a disc
//! of the stipple size in pixels.

use super::ViewerError;
use crate::limits::FieldError;
use crate::stipple::Stipples;
use glam::DVec4;
use rayon::prelude::*;

/// A stipple as the GPU reads it (16 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct StippleInstance {
    /// Its triangle, in the asset's numbering (all surfaces).
    pub triangle: u32,
    /// Its rank in its surface's set.
    pub rank: u32,
    /// Its first two barycentric coordinates (the third is one minus their sum).
    pub bary: [f32; 2],
}

/// Every surface's stipples, ready for the GPU.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StippleSet {
    /// All surfaces' stipples, each surface's in rank order.
    pub(crate) instances: Vec<StippleInstance>,
    /// Per triangle of the asset: its surface's 4D area over its own (0 where it has none),
    /// the factor from a triangle's screen area to the prefix of the ranking per stipple per
    /// square pixel.
    pub(crate) area_ratio: Vec<f32>,
}

impl StippleSet {
    /// Ranks `count` stipples with `seed` on each of `meshes` (4D positions and triangles,
    /// in the asset's order of surfaces), as a build does for the stipple style.
    pub fn generate(meshes: &[(&[DVec4], &[[u32; 3]])], count: usize, seed: u64) -> StippleSet {
        let sets: Vec<Stipples> = meshes
            .par_iter()
            .map(|(positions, triangles)| Stipples::generate(positions, triangles, count, seed))
            .collect();
        let mut out = StippleSet::default();
        let mut first_triangle = 0u32;
        for ((_, triangles), set) in meshes.iter().zip(&sets) {
            out.instances
                .extend(
                    set.triangle
                        .iter()
                        .zip(&set.bary)
                        .enumerate()
                        .map(|(rank, (&t, b))| StippleInstance {
                            triangle: t + first_triangle,
                            rank: rank as u32,
                            bary: [b[0] as f32, b[1] as f32],
                        }),
                );
            out.area_ratio.extend(
                set.triangle_area.iter().map(
                    |&a| {
                        if a > 0.0 { (set.area / a) as f32 } else { 0.0 }
                    },
                ),
            );
            first_triangle += triangles.len() as u32;
        }
        out
    }

    /// Stipples, all surfaces.
    pub fn len(&self) -> usize {
        self.instances.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.instances.is_empty()
    }

    /// Triangles, all surfaces.
    pub fn triangle_count(&self) -> usize {
        self.area_ratio.len()
    }
}

/// The error of the stipple style asked of a source that cannot have stipples: `why`.
pub(crate) fn refused(why: String) -> ViewerError {
    ViewerError::Setting(FieldError::new(
        "style",
        format!(
            "stipple: {why}; stipples are fixed to the 4D mesh: open the scene file, or a .glb that `halo4d build` wrote with it, or use --style shaded"
        ),
    ))
}
