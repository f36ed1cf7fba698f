//! What a picture shows of the double curves, and where its camera stands.
//!
//! The share of the curves in view is measured along their projected length: every segment
//! of every curve is cut into pieces at most one pixel long in the picture, and each piece
//! counts with the transmittance of the eye ray to its middle, cast against the surfaces as
//! they are drawn: the product of 1 - opacity (by w, as the picture composites it) over the
//! surfaces the ray meets before the point and the halos leave visible, 0 when one of them
//! is opaque. Pieces outside the picture count 0; pieces behind a perspective eye are left
//! out of the length too, and pieces a cutaway removes ([`super::clip`]) count 0. The point a
//! ray aims at is the curve's point on the mesh
//! ([`crate::CurvePoint::on_mesh`]), as for the drawn lines, so that the sheets through it
//! never hide it.

use super::camera::Camera;
use super::trace::{Hit, Primary};
use super::{CameraProjection, CameraSettings, RenderError, Scene};
use crate::parts::Parts;
use glam::DVec3;
use rayon::prelude::*;
use serde::Serialize;

/// The double curves' projected length and how much of it a picture shows.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct CurveVisibility {
    /// The curves' length in the picture's pixels, in view or not (without what lies
    /// behind a perspective eye).
    pub curves_projected_px: f64,
    /// The length the picture shows, each piece weighted by the transmittance of the eye ray
    /// to it.
    pub curves_visible_px: f64,
    /// `curves_visible_px / curves_projected_px`; 0 without curves.
    pub visible_curve_share: f64,
    /// The visible length with each piece weighted also by the sine of the angle between
    /// the two sheets there (1 where they cross at right angles, 0 where they touch): how
    /// much of the picture's crossings read as crossings.
    pub transversal_visible_px: f64,
    /// The gap the halos cut along the visible curves, in pixels: the half-width of the
    /// halo of the sheet passing over (the mean of its face's corners, less where the
    /// build shrank it) over the side of a pixel at the curve's depth; the value a tenth of
    /// the visible length lies below (0 without a halo or a visible curve).
    pub gap_px_p10: f64,
    /// The same, the median.
    pub gap_px_median: f64,
    /// Curve ends at branch points (cross-caps of the projection).
    pub branch_points: usize,
    /// Those the picture shows (the transmittance to them above one half).
    pub branch_points_visible: usize,
    /// Points where three sheets cross.
    pub triple_points: usize,
    /// Those the picture shows.
    pub triple_points_visible: usize,
}

/// The camera of a picture in the coordinates of the projected scene (the `.ply` files'
/// frame), so that any program can reproduce it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct PictureCamera {
    /// Width in pixels (of one eye).
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Perspective or orthographic.
    pub projection: CameraProjection,
    /// Where the eye stands.
    pub eye: [f64; 3],
    /// The point at the picture's centre.
    pub target: [f64; 3],
    /// The picture's up direction (unit).
    pub up: [f64; 3],
    /// Vertical field of view in degrees (perspective).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fov_deg: Option<f64>,
    /// Half the picture's height in scene units (orthographic).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub half_height: Option<f64>,
    /// The side of a pixel in scene units at the target's depth.
    pub pixel_size: f64,
}

impl PictureCamera {
    /// The camera `cam` of a picture of `width` x `height` looking at `target`.
    pub(super) fn of(cam: &Camera, target: DVec3, width: u32, height: u32) -> Self {
        let depth = (target - cam.eye).dot(cam.forward);
        let perspective = cam.projection == CameraProjection::Perspective;
        PictureCamera {
            width,
            height,
            projection: cam.projection,
            eye: cam.eye.to_array(),
            target: (cam.eye + cam.forward * depth).to_array(),
            up: cam.up.to_array(),
            fov_deg: perspective.then(|| 2.0 * cam.half_height.atan().to_degrees()),
            half_height: (!perspective).then_some(cam.half_height),
            pixel_size: pixel_size(cam, depth, height),
        }
    }
}

/// The side of a pixel of a picture `height` pixels high, in scene units, at `depth` along
/// the view direction.
pub(crate) fn pixel_size(cam: &Camera, depth: f64, height: u32) -> f64 {
    let half = match cam.projection {
        CameraProjection::Perspective => depth * cam.half_height,
        CameraProjection::Orthographic => cam.half_height,
    };
    2.0 * half / f64::from(height)
}

/// The camera of the picture of `input` (its first eye) and how much of the curves it shows.
pub fn curve_visibility(
    input: &Parts,
    settings: &super::RenderSettings,
    camera: &CameraSettings,
) -> Result<(PictureCamera, CurveVisibility), RenderError> {
    let (placement, scene) = super::prepare(input, settings, camera)?;
    let cam = super::first_camera(settings, camera, &placement)?;
    Ok((
        PictureCamera::of(&cam, placement.target, settings.width, settings.height),
        scene.curve_visibility(&scene.primary(&cam)),
    ))
}

/// [`curve_visibility`] through each of `cameras`, the scene indexed once; `None` for a
/// camera that cannot see it (an orthographic eye inside it).
pub fn curve_visibility_each(
    input: &Parts,
    settings: &super::RenderSettings,
    cameras: &[CameraSettings],
) -> Result<Vec<Option<CurveVisibility>>, RenderError> {
    let Some(first) = cameras.first() else {
        return Ok(Vec::new());
    };
    let (_, scene) = super::prepare(input, settings, first)?;
    let surfaces = input.surfaces.iter().map(|s| (s.positions, s.triangles));
    cameras
        .iter()
        .map(|camera| {
            let (placement, _) = super::place(surfaces.clone(), settings, camera)?;
            Ok(super::first_camera(settings, camera, &placement)
                .ok()
                .map(|cam| scene.curve_visibility(&scene.primary(&cam))))
        })
        .collect()
}

/// A segment of a curve (each end's point and its point on the mesh), with the sine of
/// the sheets' angle and the halo's half-width of the sheet passing over at its first end.
#[derive(Clone, Copy)]
struct Segment {
    ends: [(DVec3, DVec3); 2],
    sine: f64,
    rho: f64,
}

impl Scene<'_> {
    /// How much of the curves the picture of `primary`'s camera shows.
    pub(super) fn curve_visibility(&self, primary: &Primary) -> CurveVisibility {
        let segments = self.curve_segments();
        // Per segment on the cores, summed in order: the same total on any number of threads.
        let pieces: Vec<(f64, f64, f64, f64)> = segments
            .par_iter()
            .map_init(Vec::new, |hits, segment| {
                self.segment_seen(primary, segment, hits)
            })
            .collect();
        let (projected, visible, transversal) = pieces
            .iter()
            .fold((0.0, 0.0, 0.0), |(p, v, t), &(a, b, c, _)| {
                (p + a, v + b, t + c)
            });
        // The gap in pixels along the visible curves, weighted by the length seen.
        let mut gaps: Vec<(f64, f64)> = pieces
            .iter()
            .filter(|p| p.1 > 0.0)
            .map(|p| (p.3, p.1))
            .collect();
        gaps.sort_by(|a, b| a.0.total_cmp(&b.0));
        let quantile = |q: f64| {
            let mut left = q * visible;
            for &(gap, weight) in &gaps {
                left -= weight;
                if left <= 0.0 {
                    return gap;
                }
            }
            gaps.last().map_or(0.0, |g| g.0)
        };
        let (gap_p10, gap_median) = (quantile(0.1), quantile(0.5));
        let (branch_points, seen) = self.marks_seen(primary);
        let count = |s: &[bool]| s.iter().filter(|&&v| v).count();
        CurveVisibility {
            gap_px_p10: gap_p10,
            gap_px_median: gap_median,
            branch_points,
            branch_points_visible: count(&seen[..branch_points]),
            triple_points: seen.len() - branch_points,
            triple_points_visible: count(&seen[branch_points..]),
            curves_projected_px: projected,
            curves_visible_px: visible,
            visible_curve_share: if projected > 0.0 {
                visible / projected
            } else {
                0.0
            },
            transversal_visible_px: transversal,
        }
    }

    /// The curves' segments, each with the sine of the sheets' angle and the halo's
    /// half-width of the sheet passing over, at its first point.
    fn curve_segments(&self) -> Vec<Segment> {
        let mut segments: Vec<Segment> = Vec::new();
        for c in &self.input.curves.curves {
            let points: Vec<Segment> = c
                .points
                .iter()
                .map(|p| Segment {
                    ends: [(p.position, p.on_mesh); 2],
                    sine: self.crossing_sine(p.faces),
                    rho: self.half_width(p.faces[p.near()]),
                })
                .collect();
            let join = |a: &Segment, b: &Segment| Segment {
                ends: [a.ends[0], b.ends[0]],
                ..*a
            };
            segments.extend(points.windows(2).map(|s| join(&s[0], &s[1])));
            if c.closed && points.len() > 2 {
                segments.push(join(&points[points.len() - 1], &points[0]));
            }
        }
        segments
    }

    /// One segment in the picture of `primary`'s camera, sampled once per pixel of its
    /// length: its projected length, the length seen, that length times the sine of the
    /// sheets' angle, and the halo's gap in pixels at its first end. `hits` is scratch.
    fn segment_seen(
        &self,
        primary: &Primary,
        segment: &Segment,
        hits: &mut Vec<Hit>,
    ) -> (f64, f64, f64, f64) {
        let cam = primary.camera();
        let (w, h) = (self.settings.width, self.settings.height);
        let Segment {
            ends: [(a, sa), (b, sb)],
            sine,
            rho,
        } = *segment;
        let (Some((pa, depth)), Some((pb, _))) = (cam.project(a, w, h), cam.project(b, w, h))
        else {
            return (0.0, 0.0, 0.0, 0.0);
        };
        let length = (pb[0] - pa[0]).hypot(pb[1] - pa[1]);
        let steps = (length.ceil() as usize).clamp(1, 4096);
        let piece = length / steps as f64;
        let mut seen = 0.0;
        for k in 0..steps {
            let f = (k as f64 + 0.5) / steps as f64;
            let (p, s) = (a + (b - a) * f, sa + (sb - sa) * f);
            let Some((xy, _)) = cam.project(p, w, h) else {
                continue;
            };
            let inside =
                xy[0] >= 0.0 && xy[1] >= 0.0 && xy[0] < f64::from(w) && xy[1] < f64::from(h);
            let clipped = self.settings.clip.is_some_and(|c| c.removes(p));
            if inside && !clipped {
                seen += piece * self.transmittance(primary, s, hits);
            }
        }
        (length, seen, seen * sine, rho / pixel_size(cam, depth, h))
    }

    /// The curves' ends at branch points, then the triple points, each seen or not through
    /// `primary`'s camera; gives how many branch points lead the list.
    fn marks_seen(&self, primary: &Primary) -> (usize, Vec<bool>) {
        let cam = primary.camera();
        let (w, h) = (self.settings.width, self.settings.height);
        let mut marks: Vec<DVec3> = Vec::new();
        for c in &self.input.curves.curves {
            for (end, p) in c.ends.iter().zip([c.points.first(), c.points.last()]) {
                if let (crate::intersect::End::BranchPoint, Some(p)) = (end, p) {
                    marks.push(p.on_mesh);
                }
            }
        }
        let branch_points = marks.len();
        marks.extend(self.input.curves.triple_points.iter().map(|t| t.position));
        let seen: Vec<bool> = marks
            .par_iter()
            .map_init(Vec::new, |hits, &p| {
                let inside = cam.project(p, w, h).is_some_and(|(xy, _)| {
                    xy[0] >= 0.0 && xy[1] >= 0.0 && xy[0] < f64::from(w) && xy[1] < f64::from(h)
                });
                inside
                    && !self.settings.clip.is_some_and(|c| c.removes(p))
                    && self.transmittance(primary, p, hits) > 0.5
            })
            .collect();
        (branch_points, seen)
    }

    /// The half-width of the halo of `face`'s surface at that face: the mean over its
    /// corners (0 where the surface has no halo).
    fn half_width(&self, face: crate::intersect::Face) -> f64 {
        let Some(Some(halo)) = self.input.halos.get(face.surface as usize) else {
            return 0.0;
        };
        let surf = &self.input.surfaces[face.surface as usize];
        let tri = surf.triangles[face.triangle as usize];
        tri.iter()
            .map(|&v| halo.half_width(v as usize))
            .sum::<f64>()
            / 3.0
    }

    /// The sine of the angle between the planes of the two triangles `faces` (0 where one
    /// is degenerate).
    fn crossing_sine(&self, faces: [crate::intersect::Face; 2]) -> f64 {
        let normal = |f: crate::intersect::Face| {
            let surf = &self.input.surfaces[f.surface as usize];
            let p = surf.triangles[f.triangle as usize].map(|v| surf.positions[v as usize]);
            (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero()
        };
        normal(faces[0]).cross(normal(faces[1])).length().min(1.0)
    }

    /// The share of light from `p` that reaches the eye through the surfaces in front of it
    /// that the halos leave visible.
    pub(super) fn transmittance(&self, primary: &Primary, p: DVec3, hits: &mut Vec<Hit>) -> f64 {
        let (origin, dir) = self.hits_before(primary, p, hits);
        let mut through = 1.0;
        for hit in hits.iter() {
            if self.hidden_hit(origin, dir, hit) {
                continue;
            }
            through *= 1.0 - self.opacity_at(hit);
            if through <= 0.0 {
                return 0.0;
            }
        }
        through
    }

    /// The opacity of the surface at `hit`, by its w (paper 001's opacity by w).
    pub(super) fn opacity_at(&self, hit: &Hit) -> f64 {
        let s = self.settings;
        match s.opacity_far {
            Some(far) => {
                let surf = &self.input.surfaces[hit.surface as usize];
                let tri = surf.triangles[hit.triangle as usize];
                let w: f64 = (0..3).map(|i| hit.bary[i] * surf.w[tri[i] as usize]).sum();
                let (w0, w1) = self.w_range;
                let span = if w1 > w0 { w1 - w0 } else { 1.0 };
                s.opacity + (far - s.opacity) * ((w - w0) / span).clamp(0.0, 1.0)
            }
            None => s.opacity,
        }
    }
}
