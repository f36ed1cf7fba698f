//! The lines over a picture: the self-intersection curves and the silhouettes, drawn one
//! pixel wide where they are visible and broadened to an exact width ([`super::lines`]).

use super::camera::Camera;
use super::lines::{Broadener, Coverage, Mask};
use super::{RenderError, Scene};
use crate::limits::FieldError;
use glam::{DVec2, DVec3};

/// The colour of the lines (linear RGB).
pub const INK: DVec3 = DVec3::splat(0.02);

impl Scene<'_> {
    /// The coverage of the scene's lines in the image of `cam`.
    pub(super) fn lines(&self, cam: &Camera) -> Result<Option<Coverage>, RenderError> {
        let s = self.settings;
        if !s.curves && !s.silhouettes {
            return Ok(None);
        }
        let (w, h) = (s.width, s.height);
        let mut mask = Mask::new(w as usize, h as usize).map_err(line_error)?;
        let mut polylines: Vec<Vec<DVec3>> = Vec::new();
        if s.curves {
            for c in &self.input.curves.curves {
                let mut p: Vec<DVec3> = c.points.iter().map(|p| p.position).collect();
                if c.closed && !p.is_empty() {
                    p.push(p[0]);
                }
                polylines.push(p);
            }
        }
        if s.silhouettes {
            polylines.extend(
                self.silhouette_edges(cam)
                    .into_iter()
                    .map(|[a, b]| vec![a, b]),
            );
        }
        let depth_of = |p: DVec3| (p - cam.eye).dot(cam.forward);
        let (near, far) = {
            let c = depth_of(self.centre);
            (c - self.radius, c + self.radius)
        };
        let width_at = |p: DVec3| match s.line_width_far {
            Some(far_width) => {
                let f = ((depth_of(p) - near) / (far - near)).clamp(0.0, 1.0);
                s.line_width + (far_width - s.line_width) * f
            }
            None => s.line_width,
        };
        let mut hits = Vec::new();
        let see_through = s.opacity < 1.0 || s.opacity_far.is_some_and(|o| o < 1.0);
        for line in &polylines {
            let mut run: Vec<(DVec2, f64)> = Vec::new();
            let mut flush = |run: &mut Vec<(DVec2, f64)>| -> Result<(), RenderError> {
                if run.len() >= 2 {
                    mask.draw_polyline(run).map_err(line_error)?;
                }
                run.clear();
                Ok(())
            };
            for pair in line.windows(2) {
                let (a, b) = (pair[0], pair[1]);
                let (Some((pa, _)), Some((pb, _))) = (cam.project(a, w, h), cam.project(b, w, h))
                else {
                    flush(&mut run)?;
                    continue;
                };
                let steps = ((pb[0] - pa[0]).hypot(pb[1] - pa[1]).ceil() as usize).clamp(1, 4096);
                for k in 0..=steps {
                    if k == 0 && !run.is_empty() {
                        continue;
                    }
                    let p = a + (b - a) * (k as f64 / steps as f64);
                    let Some((xy, _)) = cam.project(p, w, h) else {
                        flush(&mut run)?;
                        continue;
                    };
                    let inside = xy[0] >= 0.0
                        && xy[1] >= 0.0
                        && xy[0] < f64::from(w)
                        && xy[1] < f64::from(h);
                    let visible = inside && (see_through || !self.occluded(cam, p, &mut hits));
                    if visible {
                        run.push((DVec2::new(xy[0], xy[1]), width_at(p)));
                    } else {
                        flush(&mut run)?;
                    }
                }
            }
            flush(&mut run)?;
        }
        if mask.is_empty() {
            return Ok(None);
        }
        let mut broadener = Broadener::new();
        let coverage = match s.line_width_far {
            Some(_) => broadener.broaden_varying(&mask),
            None => broadener.broaden(&mask, s.line_width),
        }
        .map_err(line_error)?;
        Ok(Some(coverage))
    }

    /// Whether a surface the halos leave visible lies between the eye and `p` (surfaces
    /// through `p` itself, as both sheets at a curve point, do not count).
    pub(super) fn occluded(
        &self,
        cam: &Camera,
        p: DVec3,
        hits: &mut Vec<super::trace::Hit>,
    ) -> bool {
        let (origin, dir) = self.hits_before(cam, p, hits);
        hits.iter().any(|hit| {
            let surf = &self.input.surfaces[hit.surface as usize];
            let tri = surf.triangles[hit.triangle as usize];
            let x = origin + dir * hit.t;
            let w: f64 = (0..3).map(|i| hit.bary[i] * surf.w[tri[i] as usize]).sum();
            !self
                .halos
                .as_ref()
                .is_some_and(|index| index.hidden(x, w, hit.surface, tri))
        })
    }

    /// Traces the eye ray through `p` and keeps in `hits` the surfaces it meets before `p`
    /// (those through `p` itself do not count); gives the ray (origin, unit direction).
    pub(super) fn hits_before(
        &self,
        cam: &Camera,
        p: DVec3,
        hits: &mut Vec<super::trace::Hit>,
    ) -> (DVec3, DVec3) {
        let (origin, dir) = cam.ray_to(p);
        self.trace(origin, dir, hits);
        let t_p = cam.ray_distance(p);
        let before = t_p - 1e-9 * self.radius.max(t_p);
        let keep = hits.iter().take_while(|hit| hit.t < before).count();
        hits.truncate(keep);
        (origin, dir)
    }

    /// The mesh edges between a triangle facing the eye and one facing away: where the eye
    /// ray lies in the surface's tangent plane (paper 001 section 5.2).
    fn silhouette_edges(&self, cam: &Camera) -> Vec<[DVec3; 2]> {
        let mut out = Vec::new();
        for surf in &self.input.surfaces {
            let facing: Vec<bool> = surf
                .triangles
                .iter()
                .map(|t| {
                    let p = t.map(|v| surf.positions[v as usize]);
                    let n = (p[1] - p[0]).cross(p[2] - p[0]);
                    let towards = match cam.projection {
                        super::CameraProjection::Perspective => cam.eye - p[0],
                        super::CameraProjection::Orthographic => -cam.forward,
                    };
                    n.dot(towards) > 0.0
                })
                .collect();
            for [a, b, i, j] in interior_edges(surf.triangles) {
                // Across a seam of a non-orientable surface the windings disagree, and so
                // do the facings of two triangles on the same side.
                let agree = j & AGREE != 0;
                if (facing[i as usize] != facing[(j & !AGREE) as usize]) == agree {
                    out.push([a, b].map(|v| surf.positions[v as usize]));
                }
            }
        }
        out
    }
}

fn line_error(e: super::lines::LinesError) -> RenderError {
    RenderError::Setting(FieldError::new("render.line_width", e.to_string()))
}

/// The flag of an interior edge whose two triangles' windings agree.
pub(crate) const AGREE: u32 = 1 << 31;

/// The edges between two triangles: (a, b, triangle i, triangle j | 1 << 31 where the two
/// windings agree, that is the triangles run along the edge in opposite directions).
pub(crate) fn interior_edges(triangles: &[[u32; 3]]) -> Vec<[u32; 4]> {
    let mut sides: Vec<([u32; 2], u32, bool)> = triangles
        .iter()
        .enumerate()
        .flat_map(|(i, t)| {
            (0..3).map(move |k| {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                ([a.min(b), a.max(b)], i as u32, a < b)
            })
        })
        .collect();
    sides.sort_unstable();
    sides
        .windows(2)
        .filter(|w| w[0].0 == w[1].0)
        .map(|w| {
            let agree = if w[0].2 != w[1].2 { AGREE } else { 0 };
            [w[0].0[0], w[0].0[1], w[0].1, w[1].1 | agree]
        })
        .collect()
}
