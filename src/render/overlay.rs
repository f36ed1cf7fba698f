//! The lines over a picture: the self-intersection curves, the silhouettes and the edges a
//! cutaway cuts ([`super::clip`]), drawn one pixel wide where they are visible and
//! broadened to an exact width ([`super::lines`]).
//!
//! The curves are drawn in a dark shade of the colour of the sheet that passes over them
//! ([`curve_ink`]: the w scale in [`OVER_BANDS`] bands), each band's ink in a mask of its own
//! broadened on its own, so that every line keeps its width; the inks are laid over the
//! picture in a fixed order (silhouettes and cut edges, then the bands from near to far).

use super::camera::Camera;
use super::lines::{Broadener, Coverage, Mask};
use super::trace::{Hit, Primary};
use super::{RenderError, Scene};
use crate::intersect::Curve;
use crate::limits::FieldError;
use glam::{DVec2, DVec3};
use rayon::prelude::*;

/// The colour of the silhouettes, and of the curves when they are drawn in one ink (linear
/// RGB).
pub const INK: DVec3 = DVec3::splat(0.02);

/// The w scale is cut into this many bands for the curves' inks ([`curve_ink`]).
pub const OVER_BANDS: usize = 12;

/// How dark a curve is drawn against the colour of the sheet passing over it: the factor
/// on that colour (linear RGB).
pub const OVER_SHADE: f64 = 0.35;

/// The band of the w scale `(w0, w1)` (the picture's colour scale) that `w` falls in.
fn band((w0, w1): (f64, f64), w: f64) -> usize {
    let span = if w1 > w0 { w1 - w0 } else { 1.0 };
    let s = ((w - w0) / span).clamp(0.0, 1.0);
    ((s * OVER_BANDS as f64) as usize).min(OVER_BANDS - 1)
}

/// The ink of a curve where the sheet passing over it (the one nearer in w) has depth `w`:
/// the colour `map` gives the middle of that w's band of the scale `w_range`, darkened by
/// [`OVER_SHADE`]. So a curve is drawn in a dark shade of the colour of the sheet that
/// passes over it, which the reader sees beside it, and the sheet broken at it (its halo's
/// gap) is the other.
pub fn curve_ink(map: super::Colormap, w_range: (f64, f64), w: f64) -> DVec3 {
    band_ink(map, band(w_range, w))
}

fn band_ink(map: super::Colormap, band: usize) -> DVec3 {
    super::shade::colormap(map, (band as f64 + 0.5) / OVER_BANDS as f64) * OVER_SHADE
}

/// The lines of one ink: its colour and how much of each pixel it covers.
pub(super) struct Lines {
    /// Linear RGB.
    pub ink: DVec3,
    /// Coverage in [0, 1] per pixel.
    pub coverage: Coverage,
}

/// A curve cut where the sheet that passes over changes: pieces of (the sheet nearer in w,
/// the piece's points). `points` are the curve's points, each with the sheet nearer in w
/// there ([`crate::CurvePoint::near`]), `None` where the two sheets' w are equal (at a
/// branch point where a curve ends, or where two surfaces meet in 4D): such a point takes
/// the sheet of the point before it (the first with one, where none is before it). A
/// segment whose two ends have different sheets over is cut at its middle, and a closed
/// curve's last segment returns to its first point (its last piece and its first are one
/// where they have the same sheet over, so a curve with one sheet over throughout is one
/// piece, drawn as in a single ink). A curve whose sheets' w are equal everywhere is one
/// piece with no sheet over.
pub(crate) fn over_pieces<T>(
    points: &[(T, Option<usize>)],
    closed: bool,
) -> Vec<(Option<usize>, Vec<T>)>
where
    T: Copy + std::ops::Add<Output = T> + std::ops::Mul<f64, Output = T>,
{
    let Some(&(first, _)) = points.first() else {
        return Vec::new();
    };
    let closing = closed.then_some(first);
    let Some(first_over) = points.iter().find_map(|p| p.1) else {
        let all = points.iter().map(|p| p.0).chain(closing).collect();
        return vec![(None, all)];
    };
    // Before the first point with a sheet over: a closed curve comes round from its last.
    let mut over = if closed {
        points.iter().rev().find_map(|p| p.1).unwrap_or(first_over)
    } else {
        first_over
    };
    let mut resolved: Vec<(T, usize)> = points
        .iter()
        .map(|&(p, near)| {
            over = near.unwrap_or(over);
            (p, over)
        })
        .collect();
    if closed {
        resolved.push(resolved[0]);
    }
    let mut pieces = Vec::new();
    let mut piece = (resolved[0].1, vec![resolved[0].0]);
    for pair in resolved.windows(2) {
        let ((p, _), (q, near)) = (pair[0], pair[1]);
        if near != piece.0 {
            let middle = (p + q) * 0.5;
            piece.1.push(middle);
            pieces.push(std::mem::replace(&mut piece, (near, vec![middle])));
        }
        piece.1.push(q);
    }
    pieces.push(piece);
    if closed && pieces.len() > 1 && pieces[0].0 == pieces[pieces.len() - 1].0 {
        let head = pieces.remove(0);
        if let Some(tail) = pieces.last_mut() {
            // The tail ends at the curve's first point, where the head starts.
            tail.1.extend_from_slice(&head.1[1..]);
        }
    }
    pieces
        .into_iter()
        .map(|(near, piece)| (Some(near), piece))
        .collect()
}

/// Where a polyline is drawn: the silhouettes', cut edges' and single ink's mask (0), the
/// broken edges' ([`BROKEN`]), or that of the curves whose sheet over lies in w band k - 2
/// (k from 2 to [`OVER_BANDS`] + 1), laid over the picture in that order.
pub(crate) type InkClass = usize;

/// A visible stretch of a line in the picture: the mask it is drawn into, its ink, and its
/// points in pixels (y down) with the line's width there.
pub(crate) struct Run {
    /// The mask ([`InkClass`]).
    pub class: InkClass,
    /// Linear RGB.
    pub ink: DVec3,
    /// Points in pixels, with the width at each.
    pub points: Vec<(DVec2, f64)>,
}

/// The mask of the broken edges of the sheets passing under.
const BROKEN: InkClass = 1;

/// The mask of the curves whose sheet over lies in w band `band`.
fn band_class(band: usize) -> InkClass {
    2 + band
}

/// The width of the broken edges, as a share of the lines' width: thinner than the curves,
/// which they meet.
pub const BROKEN_WIDTH: f64 = 0.5;

impl Scene<'_> {
    /// The scene's lines in the image of `cam`, one entry per ink that has any, in the
    /// order they are laid over the picture; `gap` marks the pixels whose first surface a
    /// halo hides (empty where unknown), whose outline are the broken edges.
    pub(super) fn lines(&self, cam: &Camera, gap: &[bool]) -> Result<Vec<Lines>, RenderError> {
        self.rasterize(&self.runs(&self.primary(cam), gap)?)
    }

    /// The runs drawn one pixel wide into a mask per ink and broadened, one entry per ink
    /// that has any, in the order they are laid over the picture.
    pub(super) fn rasterize(&self, runs: &[Run]) -> Result<Vec<Lines>, RenderError> {
        let s = self.settings;
        let (w, h) = (s.width as usize, s.height as usize);
        // Each class's runs, in order; the classes drawn and broadened side by side on the
        // cores, each thread with its own FFT plans.
        let mut classes: Vec<Vec<&Run>> = vec![Vec::new(); band_class(OVER_BANDS)];
        for run in runs {
            classes[run.class].push(run);
        }
        let lines: Vec<Option<Lines>> = classes
            .into_par_iter()
            .enumerate()
            .map_init(Broadener::new, |broadener, (class, runs)| {
                let Some(first) = runs.first() else {
                    return Ok(None);
                };
                let mut mask = Mask::new(w, h).map_err(line_error)?;
                for run in &runs {
                    mask.draw_polyline(&run.points).map_err(line_error)?;
                }
                if mask.is_empty() {
                    return Ok(None);
                }
                let coverage = match (s.line_width_far, class) {
                    (_, BROKEN) => broadener.broaden(&mask, s.line_width * BROKEN_WIDTH),
                    (Some(_), _) => broadener.broaden_varying(&mask),
                    (None, _) => broadener.broaden(&mask, s.line_width),
                }
                .map_err(line_error)?;
                Ok(Some(Lines {
                    ink: first.ink,
                    coverage,
                }))
            })
            .collect::<Result<_, RenderError>>()?;
        Ok(lines.into_iter().flatten().collect())
    }

    /// The visible runs of the scene's lines in the image of `primary`'s camera (its tiles
    /// trace the rays towards them): the curves, silhouettes and cut edges where a ray from
    /// the eye reaches them, and the outline of `gap`.
    pub(super) fn runs(&self, primary: &Primary, gap: &[bool]) -> Result<Vec<Run>, RenderError> {
        let cam = primary.camera();
        let s = self.settings;
        let (w, h) = (s.width, s.height);
        let mut out = Vec::new();
        if s.broken_edges && gap.len() == w as usize * h as usize {
            let width = s.line_width * BROKEN_WIDTH;
            for line in super::contour::outline(gap, w as usize, h as usize) {
                out.push(Run {
                    class: BROKEN,
                    ink: s.broken_edge_colour.map_or(INK, DVec3::from),
                    points: line.into_iter().map(|p| (p, width)).collect(),
                });
            }
        }
        // Each line's runs on the cores, joined in the lines' order.
        let runs: Vec<Vec<Run>> = self
            .polylines(cam)
            .par_iter()
            .map_init(Vec::new, |hits, (class, line)| {
                self.line_runs(primary, *class, line, hits)
            })
            .collect();
        out.extend(runs.into_iter().flatten());
        Ok(out)
    }

    /// The visible runs of one line of ink class `class`, stepped a pixel at a time in the
    /// image of `primary`'s camera; `hits` is scratch.
    fn line_runs(
        &self,
        primary: &Primary,
        class: InkClass,
        line: &[LinePoint],
        hits: &mut Vec<Hit>,
    ) -> Vec<Run> {
        let cam = primary.camera();
        let s = self.settings;
        let (w, h) = (s.width, s.height);
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
        let see_through = s.opacity < 1.0 || s.opacity_far.is_some_and(|o| o < 1.0);
        let ink = match class {
            0 => INK,
            k => band_ink(s.colormap, k - 2),
        };
        let mut out = Vec::new();
        let mut run: Vec<(DVec2, f64)> = Vec::new();
        let mut flush = |run: &mut Vec<(DVec2, f64)>| {
            if run.len() >= 2 {
                out.push(Run {
                    class,
                    ink,
                    points: std::mem::take(run),
                });
            }
            run.clear();
        };
        for pair in line.windows(2) {
            let (a, b) = (pair[0], pair[1]);
            let (Some((pa, _)), Some((pb, _))) = (cam.project(a.at, w, h), cam.project(b.at, w, h))
            else {
                flush(&mut run);
                continue;
            };
            let steps = ((pb[0] - pa[0]).hypot(pb[1] - pa[1]).ceil() as usize).clamp(1, 4096);
            for k in 0..=steps {
                if k == 0 && !run.is_empty() {
                    continue;
                }
                let f = k as f64 / steps as f64;
                let (p, seen) = (a.at + (b.at - a.at) * f, a.seen + (b.seen - a.seen) * f);
                let Some((xy, _)) = cam.project(p, w, h) else {
                    flush(&mut run);
                    continue;
                };
                let inside = xy[0] >= 0.0
                    && xy[1] >= 0.0
                    && xy[0] < f64::from(w)
                    && xy[1] < f64::from(h)
                    && !s.clip.is_some_and(|c| c.removes(p));
                let visible = inside && (see_through || !self.occluded(primary, seen, hits));
                if visible {
                    run.push((DVec2::new(xy[0], xy[1]), width_at(p)));
                } else {
                    flush(&mut run);
                }
            }
        }
        flush(&mut run);
        out
    }

    /// The scene's lines in space, each with its ink class: the curves (banded by depth when
    /// the settings colour them), the silhouettes seen from `cam` and the edges the clip cuts.
    fn polylines(&self, cam: &Camera) -> Vec<(InkClass, Vec<LinePoint>)> {
        let s = self.settings;
        let mut polylines: Vec<(InkClass, Vec<LinePoint>)> = Vec::new();
        if s.curves {
            for c in &self.input.curves.curves {
                polylines.extend(curve_polylines(c, s.curve_colours, self.w_range));
            }
        }
        if s.silhouettes {
            polylines.extend(
                self.silhouette_edges(cam)
                    .into_iter()
                    .map(|[a, b]| (0, vec![LinePoint::plain(a), LinePoint::plain(b)])),
            );
        }
        if let Some(clip) = &s.clip {
            let mut cuts = Vec::new();
            for surf in &self.input.surfaces {
                for t in surf.triangles {
                    clip.cut_edges(t.map(|v| surf.positions[v as usize]), &mut cuts);
                }
            }
            polylines.extend(
                cuts.into_iter()
                    .map(|[a, b]| (0, vec![LinePoint::plain(a), LinePoint::plain(b)])),
            );
        }
        polylines
    }

    /// Whether a surface the halos leave visible lies between the eye and `p` (surfaces
    /// through `p` itself, as both sheets at a curve point, do not count).
    pub(super) fn occluded(&self, primary: &Primary, p: DVec3, hits: &mut Vec<Hit>) -> bool {
        let (origin, dir) = self.hits_before(primary, p, hits);
        hits.iter().any(|hit| !self.hidden_hit(origin, dir, hit))
    }

    /// Traces the eye ray through `p` (of `primary`'s camera, through its tiles where `p` is
    /// in the picture) and keeps in `hits` the surfaces it meets before `p` (those through
    /// `p` itself do not count); gives the ray (origin, unit direction).
    pub(super) fn hits_before(
        &self,
        primary: &Primary,
        p: DVec3,
        hits: &mut Vec<Hit>,
    ) -> (DVec3, DVec3) {
        let (origin, dir) = primary.hits_towards(p, self.t_min(), hits);
        self.cut(origin, dir, hits);
        let t_p = primary.camera().ray_distance(p);
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

/// A point of a line: where it is drawn, and where its visibility is decided (the mesh's
/// point of a refined curve point, [`crate::CurvePoint::on_mesh`]; the point itself
/// otherwise).
#[derive(Clone, Copy, Debug, PartialEq)]
struct LinePoint {
    at: DVec3,
    seen: DVec3,
}

impl LinePoint {
    fn plain(at: DVec3) -> Self {
        LinePoint { at, seen: at }
    }
}

impl std::ops::Add for LinePoint {
    type Output = LinePoint;
    fn add(self, o: LinePoint) -> LinePoint {
        LinePoint {
            at: self.at + o.at,
            seen: self.seen + o.seen,
        }
    }
}

impl std::ops::Mul<f64> for LinePoint {
    type Output = LinePoint;
    fn mul(self, k: f64) -> LinePoint {
        LinePoint {
            at: self.at * k,
            seen: self.seen * k,
        }
    }
}

/// A curve's polylines with the mask each is drawn into: the whole curve in the single ink,
/// or its pieces in the ink of the w band of the sheet over them (the scale `w_range`).
fn curve_polylines(
    c: &Curve,
    colours: bool,
    w_range: (f64, f64),
) -> Vec<(InkClass, Vec<LinePoint>)> {
    let point = |p: &crate::intersect::CurvePoint| LinePoint {
        at: p.position,
        seen: p.on_mesh,
    };
    if colours {
        let points: Vec<(LinePoint, Option<usize>)> = c
            .points
            .iter()
            .map(|p| (point(p), Some(band(w_range, p.w[0].min(p.w[1])))))
            .collect();
        over_pieces(&points, c.closed)
            .into_iter()
            .map(|(band, piece)| (band.map_or(0, band_class), piece))
            .collect()
    } else {
        let mut p: Vec<LinePoint> = c.points.iter().map(point).collect();
        if c.closed && !p.is_empty() {
            p.push(p[0]);
        }
        vec![(0, p)]
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

#[cfg(test)]
mod tests {
    use super::*;

    fn at(x: f64) -> DVec3 {
        DVec3::new(x, 0.0, 0.0)
    }

    #[test]
    fn a_curve_is_cut_at_the_middle_of_the_segment_where_the_sheet_over_changes() {
        let points = [
            (at(0.0), Some(0)),
            (at(1.0), Some(0)),
            (at(2.0), Some(1)),
            (at(4.0), Some(1)),
        ];
        assert_eq!(
            over_pieces(&points, false),
            vec![
                (Some(0), vec![at(0.0), at(1.0), at(1.5)]),
                (Some(1), vec![at(1.5), at(2.0), at(4.0)]),
            ]
        );
        // Closed: the last segment returns to the first point, cut at its middle too, and
        // the first and last pieces, both with sheet 0 over, are one through the start.
        assert_eq!(
            over_pieces(&points, true),
            vec![
                (Some(1), vec![at(1.5), at(2.0), at(4.0), at(2.0)]),
                (Some(0), vec![at(2.0), at(0.0), at(1.0), at(1.5)]),
            ]
        );
    }

    #[test]
    fn points_without_a_sheet_over_take_their_neighbours() {
        // A curve between two branch points, where the sheets' w are equal: one piece.
        let points = [
            (at(0.0), None),
            (at(1.0), Some(1)),
            (at(2.0), Some(1)),
            (at(3.0), None),
        ];
        assert_eq!(
            over_pieces(&points, false),
            vec![(Some(1), vec![at(0.0), at(1.0), at(2.0), at(3.0)])]
        );
        // Through a point where the sheets meet in 4D, the sheet over may change after it.
        let points = [(at(0.0), Some(0)), (at(1.0), None), (at(2.0), Some(1))];
        assert_eq!(
            over_pieces(&points, false),
            vec![
                (Some(0), vec![at(0.0), at(1.0), at(1.5)]),
                (Some(1), vec![at(1.5), at(2.0)]),
            ]
        );
        // No sheet over anywhere.
        let points = [(at(0.0), None), (at(1.0), None)];
        assert_eq!(
            over_pieces(&points, true),
            vec![(None, vec![at(0.0), at(1.0), at(0.0)])]
        );
        assert!(over_pieces::<DVec3>(&[], true).is_empty());
        // One sheet over throughout a closed curve: the curve and its closing segment.
        let points = [(at(0.0), Some(1)), (at(1.0), Some(1)), (at(2.0), None)];
        assert_eq!(
            over_pieces(&points, true),
            vec![(Some(1), vec![at(0.0), at(1.0), at(2.0), at(0.0)])]
        );
    }
}
