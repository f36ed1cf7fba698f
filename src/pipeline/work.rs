//! The work a build is in for, measured before it is done: the curves, the verification and
//! the picture ask "which triangles or tetrahedra are near this point?" millions of times,
//! and each answer costs as many exact tests as there are boxes piled up at the point. Where
//! the boxes pile up far beyond a sound mesh's (sliver triangles fanning out from a point,
//! halos that keep their folds), the build would run for minutes; it is refused at once,
//! with what to change.
//!
//! The pile-up is measured at [`PROBES`] points spread over each surface by area
//! ([`probes`], the same points for the triangles and the halos), in a BVH over the boxes
//! ([`broad::crowding`]), each point's count cut at four times the limit. The BVHs are most
//! of the cost: 4 ms for the triangles and 30 ms for the halos of the default scene (2.1 s
//! in all).

use super::built::{InView, SurfaceProduct, parts};
use crate::error::Error;
use crate::halo::Fold;
use crate::intersect::{Curves, broad};
use crate::limits::{HALO_CROWDING, SURFACE_CROWDING};
use crate::parts::HaloIndex;
use crate::sample::{Sampling, Source};
use crate::scene::Scene;
use glam::DVec3;

/// Points probed on each surface.
const PROBES: usize = 4096;

/// Per surface, how many triangles' boxes hold a point of it on average; refuses surfaces
/// whose boxes pile up beyond [`SURFACE_CROWDING`]: every ray of the picture and every
/// candidate pair of the curves would test hundreds of them.
pub(super) fn surface_crowding(
    scene: &Scene,
    projections: &[InView],
    probes: &[Vec<DVec3>],
) -> Result<Vec<f64>, Error> {
    let cap = 4 * SURFACE_CROWDING as usize;
    let mut out = Vec::with_capacity(projections.len());
    for (i, (view, probes)) in projections.iter().zip(probes).enumerate() {
        let positions = &view.projected.positions;
        let boxes: Vec<_> = view
            .sample
            .mesh
            .triangles
            .iter()
            .map(|t| {
                let p = t.map(|v| positions[v as usize]);
                broad::outward(p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]))
            })
            .collect();
        let crowding = broad::crowding(&broad::build(&boxes, 4), probes, cap);
        out.push(crowding);
        if crowding <= SURFACE_CROWDING {
            continue;
        }
        let field = match view.entry.sampling {
            Some(_) => format!("surfaces[{i}].sampling"),
            None => "sampling".to_string(),
        };
        let change = match (&view.entry.surface, scene.surface_sampling(i)) {
            (Source::Mesh(_), _) => {
                "they are the mesh file's: remesh it with triangles nearer equilateral".into()
            }
            (_, Sampling::Uniform { u, v }) => format!(
                "its grid of {u} x {v} cells per patch makes them long and thin: choose `{field}.u` and `{field}.v` nearer the patches' proportions, or sample adaptively (`{field}.method: adaptive`)"
            ),
            (_, Sampling::Adaptive { .. }) => {
                format!("ask for a finer `{field}.tolerance`, which splits them")
            }
        };
        return Err(Error::Work {
            scene: scene.name.clone(),
            message: format!(
                "the triangles of surface `{}` are slivers whose boxes pile up: a point on it lies in the boxes of {crowding:.0} triangles on average (counted up to {cap} at each point), more than the {SURFACE_CROWDING} that its curves and picture allow in reasonable time (well-shaped meshes: 2 to 6); {change}",
                view.sample.name
            ),
        });
    }
    Ok(out)
}

/// Per surface, how many halo tetrahedra's boxes (of all the halos) hold a point of it on
/// average; refuses halos so crowded that verifying and drawing them would take far longer
/// than for sound halos of their size ([`HALO_CROWDING`]).
pub(super) fn halo_crowding(
    scene: &Scene,
    products: &[SurfaceProduct],
    probes: &[Vec<DVec3>],
    diagonal: f64,
) -> Result<Vec<f64>, Error> {
    let none = Curves::default();
    let parts = parts(products, &scene.halo, &none);
    let index = HaloIndex::new(&parts.halos);
    let cap = 4 * HALO_CROWDING as usize;
    let mut out = Vec::with_capacity(products.len());
    for (p, probes) in products.iter().zip(probes) {
        let crowding = index.crowding(probes, cap);
        out.push(crowding);
        if crowding <= HALO_CROWDING {
            continue;
        }
        let rho = p.halo_report.rho / diagonal;
        let change = match scene.halo.fold {
            Fold::Report => format!(
                "its half-width is {rho:.3} of the scene's diagonal and `halo.fold: report` keeps its folds: lower `halo.rho` or `halo.gap_px`, or set `halo.fold` to `shrink`"
            ),
            Fold::Shrink => format!(
                "its half-width is {rho:.3} of the scene's diagonal: lower `halo.rho` or `halo.gap_px`"
            ),
        };
        return Err(Error::Work {
            scene: scene.name.clone(),
            message: format!(
                "the halo of surface `{}` overlaps itself: a point on the surface lies in the boxes of {crowding:.0} halo tetrahedra on average (counted up to {cap} at each point), more than the {HALO_CROWDING} that verifying and drawing it in reasonable time allows (halos that do not fold: 11 to 31); {change}",
                p.name
            ),
        });
    }
    Ok(out)
}

/// Per surface, [`PROBES`] points spread over its triangles by area: the centroids of the
/// triangles where the running area passes each of [`PROBES`] evenly spaced shares of the
/// total.
pub(super) fn probes(projections: &[InView]) -> Vec<Vec<DVec3>> {
    projections
        .iter()
        .map(|view| {
            let positions = &view.projected.positions;
            let triangles = &view.sample.mesh.triangles;
            let corners = |t: &[u32; 3]| t.map(|v| positions[v as usize]);
            let mut running = Vec::with_capacity(triangles.len());
            let mut total = 0.0;
            for t in triangles {
                let p = corners(t);
                total += (p[1] - p[0]).cross(p[2] - p[0]).length();
                running.push(total);
            }
            if triangles.is_empty() {
                return Vec::new();
            }
            (0..PROBES)
                .map(|i| {
                    let share = (i as f64 + 0.5) / PROBES as f64 * total;
                    let k = running
                        .partition_point(|&r| r < share)
                        .min(triangles.len() - 1);
                    let p = corners(&triangles[k]);
                    (p[0] + p[1] + p[2]) / 3.0
                })
                .collect()
        })
        .collect()
}
