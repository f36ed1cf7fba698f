//! The audit: how far a mesh is from its surface, measured without trusting the sampler.
//!
//! For every triangle, the linear interpolant of its three vertex positions is compared with
//! the surface evaluated at the same barycentric combination of the triangle's corner
//! parameters ([`Mesh4::triangle_uv`]), at the fixed points [`AUDIT_POINTS`]: the corners
//! (which catch a vertex welded to the wrong place), the edge midpoints, the centroid and
//! three points halfway between the centroid and the corners. The distance is Euclidean in
//! R^4; orthographic projection never lengthens it, so the bound holds in every view.

use super::Mesh4;
use crate::progress::Cancel;
use crate::surfaces::Surface;
use glam::DVec4;
use rayon::prelude::*;
use serde::Serialize;

/// Barycentric coordinates of the points where every triangle is compared with the surface:
/// 3 corners, 3 edge midpoints, the centroid, and the midpoints from the centroid to the
/// corners.
pub const AUDIT_POINTS: [[f64; 3]; 10] = [
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [0.5, 0.5, 0.0],
    [0.0, 0.5, 0.5],
    [0.5, 0.0, 0.5],
    [1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0],
    [2.0 / 3.0, 1.0 / 6.0, 1.0 / 6.0],
    [1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0],
    [1.0 / 6.0, 1.0 / 6.0, 2.0 / 3.0],
];

/// The corners are the first three [`AUDIT_POINTS`]: they enter the maximum (as a check of
/// the welding) but not the RMS, which would otherwise count the exact zeros at vertices.
const CORNERS: usize = 3;

/// What the audit measured.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Audit {
    /// Largest distance, triangle to surface, over all audit points.
    pub max_error: f64,
    /// Root mean square of the distance over the edge and interior audit points.
    pub rms_error: f64,
    /// The triangle where the largest distance was found.
    pub worst_triangle: Option<usize>,
    /// Points compared with the surface.
    pub points: usize,
    /// Audit points where the surface or the mesh is not finite (they count as failures:
    /// `max_error` is then infinite).
    pub non_finite: usize,
}

impl Audit {
    /// The errors relative to a length (the bounding diagonal): `(max, rms)`.
    pub fn relative(&self, length: f64) -> (f64, f64) {
        (self.max_error / length, self.rms_error / length)
    }
}

/// Triangles per parallel task of the audit: a fixed number, so that the sum of squares
/// (added task after task) comes out the same on any number of threads.
const AUDIT_RUN: usize = 1024;

/// Partial sums of one slice of triangles.
#[derive(Default)]
struct Partial {
    max: f64,
    worst: Option<usize>,
    sum_sq: f64,
    counted: usize,
    points: usize,
    non_finite: usize,
}

/// Measures the distance between `mesh` and `surface` (see the module documentation). Uses
/// every core of the machine.
pub fn audit(surface: &Surface, mesh: &Mesh4) -> Audit {
    audit_until(surface, mesh, Cancel::never())
}

/// [`audit`], stopping early once `cancel` is cancelled (its figures then partial: the
/// caller drops them).
pub fn audit_until(surface: &Surface, mesh: &Mesh4, cancel: &Cancel) -> Audit {
    let n = mesh.triangles.len();
    // Runs of AUDIT_RUN triangles on the cores, summed in order.
    let partials: Vec<Partial> = (0..n)
        .into_par_iter()
        .step_by(AUDIT_RUN)
        .map(|start| {
            if cancel.is_cancelled() {
                return Partial::default();
            }
            audit_range(surface, mesh, start..(start + AUDIT_RUN).min(n))
        })
        .collect();
    let mut total = Partial::default();
    for p in partials {
        if total.worst.is_none() || p.max > total.max {
            total.max = p.max;
            total.worst = p.worst;
        }
        total.sum_sq += p.sum_sq;
        total.counted += p.counted;
        total.points += p.points;
        total.non_finite += p.non_finite;
    }
    Audit {
        max_error: if total.non_finite > 0 {
            f64::INFINITY
        } else {
            total.max
        },
        rms_error: if total.counted > 0 {
            (total.sum_sq / total.counted as f64).sqrt()
        } else {
            0.0
        },
        worst_triangle: total.worst,
        points: total.points,
        non_finite: total.non_finite,
    }
}

fn audit_range(surface: &Surface, mesh: &Mesh4, range: std::ops::Range<usize>) -> Partial {
    let mut out = Partial::default();
    for t in range {
        let corners: [DVec4; 3] = mesh.triangles[t].map(|i| mesh.positions[i as usize]);
        let uv = mesh.triangle_uv[t];
        let patch = mesh.triangle_patch[t] as usize;
        for (k, b) in AUDIT_POINTS.iter().enumerate() {
            let u = b[0] * uv[0][0] + b[1] * uv[1][0] + b[2] * uv[2][0];
            let v = b[0] * uv[0][1] + b[1] * uv[1][1] + b[2] * uv[2][1];
            let chord = corners[0] * b[0] + corners[1] * b[1] + corners[2] * b[2];
            let d = (surface.point(patch, u, v) - chord).length();
            out.points += 1;
            if !d.is_finite() {
                out.non_finite += 1;
                continue;
            }
            if out.worst.is_none() || d > out.max {
                out.max = d;
                out.worst = Some(t);
            }
            if k >= CORNERS {
                out.sum_sq += d * d;
                out.counted += 1;
            }
        }
    }
    out
}
