//! Link diagrams: closed and open curves in 3D drawn as a topologist draws a link, each
//! projected to the page along the camera's view direction with every crossing's
//! under-strand broken; a strip of such panels, each with its labels, as a PNG and as an
//! SVG of the same lines (a motion picture's stills).
//!
//! A crossing is where two segments' projections cross properly, decided by the exact
//! `orient2d` on their page coordinates; the strand farther from the eye there is the
//! under-strand, cut by a gap of [`GAP`] line widths on each side. Lines are drawn at an
//! exact width by the renderer's line broadening (`render::lines`), one mask per colour;
//! each curve of a panel has its own colour.

use super::CameraSettings;
use super::camera::basis;
use super::lines::{Broadener, Mask};
use super::svg::rgb as svg_colour;
use super::text;
use super::{Picture, RenderError};
use crate::motion::Polyline;
use glam::{DVec2, DVec3};
use std::fmt::Write;

/// The gap cut into an under-strand on each side of a crossing, in line widths.
pub const GAP: f64 = 2.5;

/// Component colours (linear RGB), in turn: the curves of a still, in the pictures and
/// the stills' `.glb`.
pub const PALETTE: [[f64; 3]; 6] = [
    [0.018, 0.162, 0.440],
    [0.730, 0.080, 0.030],
    [0.020, 0.360, 0.080],
    [0.520, 0.150, 0.560],
    [0.800, 0.330, 0.000],
    [0.030, 0.350, 0.420],
];

/// The page's colour (linear RGB).
const PAPER: DVec3 = DVec3::ONE;
/// The panels' frames': a light blue, which no curve's colour and no shade of the labels'
/// grey comes near.
const FRAME: DVec3 = DVec3::new(0.35, 0.55, 0.95);
/// The labels'.
const INK: DVec3 = DVec3::splat(0.02);

/// A panel's curves on the page: each point in pixels of the panel with its depth (larger
/// farther), each curve with whether it closes, and the diagram's crossings.
#[derive(Clone, Debug, Default)]
pub struct Page {
    /// The curves.
    pub curves: Vec<(Vec<(DVec2, f64)>, bool)>,
    /// Its crossings, each an under-strand's place.
    pub under: Vec<Under>,
}

/// A crossing on the page: the under-strand's curve and its arc length there (pixels).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Under {
    /// The curve passing under.
    pub curve: usize,
    /// Where along it, in pixels of arc length from its first point.
    pub at: f64,
}

/// The crossings of `curves` (page points with their depth, larger farther), as the
/// under-strand's place. Segments that share a point of one curve do not cross; two
/// segments cross where each one's ends lie strictly on opposite sides of the other's line
/// (exact `orient2d`). Segments are swept along x, so only those whose x-ranges meet are
/// tested.
pub fn crossings(curves: &[(Vec<(DVec2, f64)>, bool)]) -> Vec<Under> {
    struct Segment {
        curve: usize,
        index: usize,
        a: (DVec2, f64),
        b: (DVec2, f64),
        start: f64,
        segments: usize,
    }
    let mut segments = Vec::new();
    for (curve, (points, closed)) in curves.iter().enumerate() {
        let count = if *closed {
            points.len()
        } else {
            points.len().saturating_sub(1)
        };
        let mut start = 0.0;
        for index in 0..count {
            let (a, b) = (points[index], points[(index + 1) % points.len()]);
            segments.push(Segment {
                curve,
                index,
                a,
                b,
                start,
                segments: count,
            });
            start += a.0.distance(b.0);
        }
    }
    segments.sort_by(|s, t| s.a.0.x.min(s.b.0.x).total_cmp(&t.a.0.x.min(t.b.0.x)));
    let orient = |p: DVec2, q: DVec2, r: DVec2| {
        let c = |v: DVec2| robust::Coord { x: v.x, y: v.y };
        robust::orient2d(c(p), c(q), c(r))
    };
    let mut out = Vec::new();
    for (i, s) in segments.iter().enumerate() {
        let right = s.a.0.x.max(s.b.0.x);
        let (low, high) = (s.a.0.y.min(s.b.0.y), s.a.0.y.max(s.b.0.y));
        for t in &segments[i + 1..] {
            if t.a.0.x.min(t.b.0.x) > right {
                break;
            }
            if t.a.0.y.max(t.b.0.y) < low || t.a.0.y.min(t.b.0.y) > high {
                continue;
            }
            let neighbours = s.curve == t.curve && {
                let d = s.index.abs_diff(t.index);
                d <= 1 || d == s.segments - 1
            };
            if neighbours {
                continue;
            }
            let (sa, sb) = (orient(t.a.0, t.b.0, s.a.0), orient(t.a.0, t.b.0, s.b.0));
            let (ta, tb) = (orient(s.a.0, s.b.0, t.a.0), orient(s.a.0, s.b.0, t.b.0));
            if !(sa * sb < 0.0 && ta * tb < 0.0) {
                continue;
            }
            // Where along each: the share of the way its ends' sides say.
            let (u, v) = (sa / (sa - sb), ta / (ta - tb));
            let depth = |seg: &Segment, k: f64| seg.a.1 + (seg.b.1 - seg.a.1) * k;
            let (under, k) = if depth(s, u) > depth(t, v) {
                (s, u)
            } else {
                (t, v)
            };
            out.push(Under {
                curve: under.curve,
                at: under.start + k * under.a.0.distance(under.b.0),
            });
        }
    }
    out
}

/// The runs left of a curve (page points, closed or not) once the stretches within `gap`
/// of arc length of each place in `cuts` are taken out: polylines, a closed curve without
/// a cut one loop back to its first point.
pub fn runs(points: &[DVec2], closed: bool, cuts: &[f64], gap: f64) -> Vec<Vec<DVec2>> {
    if points.len() < 2 {
        return Vec::new();
    }
    let mut path: Vec<DVec2> = points.to_vec();
    if closed {
        path.push(points[0]);
    }
    let mut along = vec![0.0];
    for w in path.windows(2) {
        along.push(along[along.len() - 1] + w[0].distance(w[1]));
    }
    let length = along[along.len() - 1];
    if cuts.is_empty() {
        return vec![path];
    }
    // The kept stretches, as arc-length intervals; on a closed curve they may pass its
    // first point, and are taken from the path gone round twice.
    let mut removed: Vec<(f64, f64)> = cuts.iter().map(|&c| (c - gap, c + gap)).collect();
    removed.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut merged: Vec<(f64, f64)> = Vec::new();
    for r in removed {
        match merged.last_mut() {
            Some(last) if r.0 <= last.1 => last.1 = last.1.max(r.1),
            _ => merged.push(r),
        }
    }
    let mut kept = Vec::new();
    if closed {
        if merged[merged.len() - 1].1 - merged[0].0 >= length {
            return Vec::new();
        }
        for (k, r) in merged.iter().enumerate() {
            let next = merged.get(k + 1).map_or(merged[0].0 + length, |n| n.0);
            kept.push((r.1, next));
        }
    } else {
        let mut from = 0.0;
        for r in &merged {
            kept.push((from, r.0));
            from = r.1;
        }
        kept.push((from, length));
    }
    let at = |s: f64| -> DVec2 {
        let s = if closed { s.rem_euclid(length) } else { s };
        let k = along.partition_point(|&a| a <= s).clamp(1, path.len() - 1);
        let (a, b) = (along[k - 1], along[k]);
        let t = if b > a { (s - a) / (b - a) } else { 0.0 };
        path[k - 1].lerp(path[k], t.clamp(0.0, 1.0))
    };
    let mut out = Vec::new();
    for (from, to) in kept {
        if to - from <= 0.0 {
            continue;
        }
        let mut run = vec![at(from)];
        // The path's points strictly inside, gone round once more past its length.
        let laps = if closed { 2 } else { 1 };
        for lap in 0..laps {
            for (k, &a) in along.iter().enumerate() {
                let s = a + lap as f64 * length;
                if s > from && s < to && !(closed && k == along.len() - 1) {
                    run.push(path[k]);
                }
            }
        }
        run.push(at(to));
        out.push(run);
    }
    out
}

/// The panels of curves in 3D (each curve with whether it closes) on pages of `side`
/// pixels, projected along the view direction of `camera` (its azimuth and elevation;
/// orthographic), all at one scale and centred alike so that a place in 3D is the same
/// place in every panel (the scale fits every panel's points and the points `also`, such
/// as a surface whose slices a film shows), with their crossings.
pub fn pages(
    panels: &[Vec<Polyline>],
    camera: &CameraSettings,
    side: u32,
    also: &[DVec3],
) -> Vec<Page> {
    let (forward, right, up) = basis(camera, 0.0);
    let page = |p: DVec3| (DVec2::new(p.dot(right), -p.dot(up)), p.dot(forward));
    let (mut lo, mut hi) = (DVec2::INFINITY, DVec2::NEG_INFINITY);
    let points = panels.iter().flatten().flat_map(|c| &c.0).chain(also);
    for &p in points {
        let q = page(p).0;
        (lo, hi) = (lo.min(q), hi.max(q));
    }
    let extent = (hi - lo).max_element();
    let margin = 0.08 * f64::from(side);
    // Centred on the box, also when it is a point (a slice shrunk to one, at a birth).
    let centre = if lo.is_finite() && hi.is_finite() {
        (lo + hi) * 0.5
    } else {
        DVec2::ZERO
    };
    let scale = if extent > 0.0 && extent.is_finite() {
        (f64::from(side) - 2.0 * margin) / extent
    } else {
        1.0
    };
    let to_px = |q: DVec2| (q - centre) * scale + DVec2::splat(0.5 * f64::from(side));
    panels
        .iter()
        .map(|curves| {
            let curves: Vec<(Vec<(DVec2, f64)>, bool)> = curves
                .iter()
                .map(|(points, closed)| {
                    let q = points
                        .iter()
                        .map(|&p| {
                            let (q, depth) = page(p);
                            (to_px(q), depth)
                        })
                        .collect();
                    (q, *closed)
                })
                .collect();
            let under = crossings(&curves);
            Page { curves, under }
        })
        .collect()
}

/// Draws `pages` (made by [`pages`] at `side`) in a grid of `columns`, each with its
/// (title, caption) of `labels`, lines `line` pixels wide, each curve of a page in its
/// own colour and every under-strand broken at its crossings: the picture and the SVG.
pub fn draw_strip(
    pages: &[Page],
    labels: &[(String, String)],
    columns: usize,
    side: u32,
    line: f64,
) -> Result<(Picture, String), RenderError> {
    let columns = columns.clamp(1, pages.len().max(1));
    let (width, height) = strip_size(pages.len(), side, columns);
    let band = label_band(side);
    let text_size = text_size(side);
    let (cell_w, cell_h) = (side, side + 2 * band);
    let lines = |e: super::lines::LinesError| RenderError::Internal(e.to_string());
    let mut rgb = vec![PAPER; width as usize * height as usize];
    let mut svg = super::svg::header(width, height, PAPER);
    let mut broadener = Broadener::new();
    let empty = (String::new(), String::new());
    for (k, page) in pages.iter().enumerate() {
        let (title, caption) = labels.get(k).unwrap_or(&empty);
        let (x0, y0) = (
            (k % columns) as u32 * cell_w,
            (k / columns) as u32 * cell_h + band,
        );
        // The panel's frame.
        let _ = writeln!(
            svg,
            r#"<rect x="{x0}.5" y="{y0}.5" width="{}" height="{}" fill="none" stroke="{}"/>"#,
            side - 1,
            side - 1,
            svg_colour(FRAME)
        );
        frame(&mut rgb, width as usize, (x0, y0), side);
        for (c, (points, closed)) in page.curves.iter().enumerate() {
            let colour = DVec3::from(PALETTE[c % PALETTE.len()]);
            let cuts: Vec<f64> = page
                .under
                .iter()
                .filter(|u| u.curve == c)
                .map(|u| u.at)
                .collect();
            let flat: Vec<DVec2> = points.iter().map(|p| p.0).collect();
            let pieces = runs(&flat, *closed, &cuts, GAP * line);
            let mut mask = Mask::new(side as usize, side as usize).map_err(lines)?;
            for run in &pieces {
                let with: Vec<(DVec2, f64)> = run.iter().map(|&p| (p, line)).collect();
                mask.draw_polyline(&with).map_err(lines)?;
                let _ = write!(
                    svg,
                    r#"<path fill="none" stroke="{}" stroke-width="{line:.2}" stroke-linecap="round" stroke-linejoin="round" d=""#,
                    svg_colour(colour)
                );
                for (i, p) in run.iter().enumerate() {
                    let _ = write!(
                        svg,
                        "{}{:.2},{:.2}",
                        if i == 0 { "M" } else { " L" },
                        p.x + f64::from(x0),
                        p.y + f64::from(y0)
                    );
                }
                svg.push_str("\"/>\n");
            }
            let coverage = broadener.broaden(&mask, line).map_err(lines)?;
            for y in 0..side as usize {
                for x in 0..side as usize {
                    let c = f64::from(coverage.get(x, y).unwrap_or(0.0));
                    if c > 0.0 {
                        let at = (y0 as usize + y) * width as usize + x0 as usize + x;
                        rgb[at] = rgb[at].lerp(colour, c);
                    }
                }
            }
        }
        for (label, y) in [
            (title, y0 as f64 - 0.5 * f64::from(band)),
            (caption, f64::from(y0 + side) + 0.5 * f64::from(band)),
        ] {
            let x = f64::from(x0) + 0.5 * f64::from(side);
            text::draw_centred(
                &mut rgb,
                (width as usize, height as usize),
                label,
                text_size,
                (x, y),
                INK,
            )
            .map_err(RenderError::Internal)?;
            let _ = writeln!(
                svg,
                r#"<text x="{x:.1}" y="{:.1}" font-family="DejaVu Sans Mono, monospace" font-size="{text_size}" text-anchor="middle" dominant-baseline="central" fill="{}">{}</text>"#,
                y,
                svg_colour(INK),
                escape(label)
            );
        }
    }
    svg.push_str("</svg>\n");
    let rgb8 = rgb
        .iter()
        .flat_map(|c| c.to_array().map(super::to_srgb8))
        .collect();
    Ok((
        Picture {
            width,
            height,
            rgb: rgb8,
        },
        svg,
    ))
}

/// The labels' size in pixels for panels of `side`.
fn text_size(side: u32) -> f64 {
    (f64::from(side) / 22.0).round().max(text::MIN_TEXT)
}

/// The height of the band above and below a panel of `side` that holds its labels.
fn label_band(side: u32) -> u32 {
    (text_size(side) * 1.8).round() as u32
}

/// The size of [`draw_strip`]'s picture of `panels` panels of `side` in rows of `columns`.
pub fn strip_size(panels: usize, side: u32, columns: usize) -> (u32, u32) {
    let columns = columns.clamp(1, panels.max(1));
    let rows = panels.div_ceil(columns).max(1);
    (
        side * columns as u32,
        (side + 2 * label_band(side)) * rows as u32,
    )
}

/// A one-pixel frame round the panel of `side` at (x0, y0).
fn frame(rgb: &mut [DVec3], width: usize, (x0, y0): (u32, u32), side: u32) {
    let (x0, y0, side) = (x0 as usize, y0 as usize, side as usize);
    for i in 0..side {
        for (x, y) in [
            (x0 + i, y0),
            (x0 + i, y0 + side - 1),
            (x0, y0 + i),
            (x0 + side - 1, y0 + i),
        ] {
            rgb[y * width + x] = FRAME;
        }
    }
}

/// Text made safe for XML.
fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_farther_strand_is_the_one_broken() {
        // Two straight strands crossing at the page's (1, 1): the first at depth 5, the
        // second at depth 1 (nearer), so the first passes under, at its middle.
        let near = vec![(DVec2::new(0.0, 2.0), 1.0), (DVec2::new(2.0, 0.0), 1.0)];
        let far = vec![(DVec2::new(0.0, 0.0), 5.0), (DVec2::new(2.0, 2.0), 5.0)];
        let under = crossings(&[(far.clone(), false), (near.clone(), false)]);
        assert_eq!(under.len(), 1);
        assert_eq!(under[0].curve, 0);
        assert!((under[0].at - 2f64.sqrt()).abs() < 1e-12);
        // Swapped depths: the other strand.
        let under = crossings(&[(near, false), (far, false)]);
        assert_eq!(under[0].curve, 1);
    }

    #[test]
    fn strands_that_only_touch_or_follow_each_other_do_not_cross() {
        // A closed square: its sides meet at corners only. A strand ending on another
        // (a T) is not a proper crossing.
        let square: Vec<(DVec2, f64)> = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
            .map(|(x, y)| (DVec2::new(x, y), 0.0))
            .to_vec();
        assert!(crossings(&[(square.clone(), true)]).is_empty());
        let t = vec![(DVec2::new(0.5, 0.0), 1.0), (DVec2::new(0.5, -1.0), 1.0)];
        assert!(crossings(&[(square, true), (t, false)]).is_empty());
        // A figure eight crosses itself once.
        let eight: Vec<(DVec2, f64)> = [
            (0.0, 0.0, 0.0),
            (2.0, 2.0, 0.0),
            (2.0, 0.0, 1.0),
            (0.0, 2.0, 1.0),
        ]
        .map(|(x, y, d)| (DVec2::new(x, y), d))
        .to_vec();
        let under = crossings(&[(eight, true)]);
        assert_eq!(under.len(), 1);
        // The later diagonal (depth 1) is farther: cut at its middle, 2 + 2√2 + √2 along.
        assert!((under[0].at - (2.0 + 3.0 * 2f64.sqrt())).abs() < 1e-12);
    }

    #[test]
    fn a_slice_shrunk_to_a_far_point_is_drawn_at_the_panels_centre() {
        let p = DVec3::new(1e29, -3e28, 5e28);
        let pages = pages(
            &[vec![(vec![p; 3], true)]],
            &CameraSettings::default(),
            64,
            &[],
        );
        let q = pages[0].curves[0].0[0].0;
        assert!(q.distance(DVec2::splat(32.0)) < 1e-9, "{q}");
        let (picture, svg) = draw_strip(&pages, &[], 1, 64, 2.0).unwrap();
        assert_eq!((picture.width, picture.height), strip_size(1, 64, 1));
        assert!(svg.ends_with("</svg>\n"));
    }

    #[test]
    fn a_cut_leaves_the_rest_of_the_curve_in_runs() {
        let line = [DVec2::ZERO, DVec2::new(10.0, 0.0)];
        let r = runs(&line, false, &[5.0], 1.0);
        assert_eq!(
            r,
            vec![
                vec![DVec2::ZERO, DVec2::new(4.0, 0.0)],
                vec![DVec2::new(6.0, 0.0), DVec2::new(10.0, 0.0)]
            ]
        );
        // A closed square of side 1 cut at its first point: one run from 0.5 round to 3.5.
        let square = [DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y];
        let r = runs(&square, true, &[0.0], 0.5);
        assert_eq!(r.len(), 1);
        assert_eq!(r[0].first(), Some(&DVec2::new(0.5, 0.0)));
        assert_eq!(r[0].last(), Some(&DVec2::new(0.0, 0.5)));
        assert_eq!(r[0].len(), 5);
        // Uncut, a closed curve comes back to its first point; cut all round, nothing.
        assert_eq!(runs(&square, true, &[], 0.5)[0].len(), 5);
        assert!(runs(&square, true, &[0.0, 2.0], 1.0).is_empty());
    }
}
