//! The broken edges of the sheets passing under: where, in the picture, a halo starts to
//! hide the sheet the eye would otherwise see first (the edges of the gaps, as a broken
//! surface diagram draws them).
//!
//! Takes a mask over the pixels (true where the first surface along the pixel's centre ray
//! is hidden by a halo); gives its outline as polylines in pixel coordinates, traced through
//! the pixel centres by marching squares (the outline passes through the middle of every
//! pair of neighbouring centres that disagree), chained end to end and smoothed once, so that
//! the staircase of the pixels does not show.

use glam::DVec2;
use rayon::prelude::*;
use std::collections::HashMap;

/// A crossing of the outline with the segment between two neighbouring pixel centres:
/// (x, y, 0) between (x, y) and (x + 1, y), (x, y, 1) between (x, y) and (x, y + 1).
type Crossing = (u32, u32, u8);

/// The outline of `mask` (`width` x `height`, row-major) as polylines through pixel
/// centres' midpoints, each at least two points long; closed outlines repeat their first
/// point at the end.
pub(crate) fn outline(mask: &[bool], width: usize, height: usize) -> Vec<Vec<DVec2>> {
    let at = |x: usize, y: usize| mask[y * width + x];
    // Row by row of squares on the cores, joined in order.
    let segments: Vec<[Crossing; 2]> = (0..height.saturating_sub(1))
        .into_par_iter()
        .flat_map_iter(|y| {
            let mut row = Vec::new();
            for x in 0..width.saturating_sub(1) {
                // The square of centres (x, y), (x + 1, y), (x + 1, y + 1), (x, y + 1).
                let c = [at(x, y), at(x + 1, y), at(x + 1, y + 1), at(x, y + 1)];
                if c == [c[0]; 4] {
                    continue; // most squares: the outline does not pass
                }
                let (xs, ys) = (x as u32, y as u32);
                let top = (xs, ys, 0u8);
                let right = (xs + 1, ys, 1u8);
                let bottom = (xs, ys + 1, 0u8);
                let left = (xs, ys, 1u8);
                let edges = [top, right, bottom, left];
                let mut crossed = (0..4).filter(|&k| c[k] != c[(k + 1) % 4]).map(|k| edges[k]);
                if c[0] == c[2] && c[1] == c[3] {
                    // A saddle: the two diagonal corners that are set stay apart.
                    if c[0] {
                        row.extend([[top, right], [bottom, left]]);
                    } else {
                        row.extend([[top, left], [right, bottom]]);
                    }
                } else if let (Some(a), Some(b)) = (crossed.next(), crossed.next()) {
                    row.push([a, b]);
                }
            }
            row
        })
        .collect();
    chain(&segments)
        .into_iter()
        .map(|line| {
            let points: Vec<DVec2> = line.iter().map(|&c| point(c)).collect();
            smooth(points)
        })
        .collect()
}

/// Where a crossing lies: the midpoint of its two pixel centres.
fn point((x, y, axis): Crossing) -> DVec2 {
    let centre = DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
    centre
        + if axis == 0 {
            DVec2::new(0.5, 0.0)
        } else {
            DVec2::new(0.0, 0.5)
        }
}

/// The segments joined end to end into polylines (each crossing is an end of at most two
/// segments), in a deterministic order.
fn chain(segments: &[[Crossing; 2]]) -> Vec<Vec<Crossing>> {
    let mut by_end: HashMap<Crossing, Vec<usize>> = HashMap::new();
    for (i, s) in segments.iter().enumerate() {
        for &c in s {
            by_end.entry(c).or_default().push(i);
        }
    }
    let mut used = vec![false; segments.len()];
    let mut lines = Vec::new();
    // Open chains first, from an end only one segment reaches; then the closed loops.
    let mut starts: Vec<usize> = (0..segments.len())
        .filter(|&i| segments[i].iter().any(|c| by_end[c].len() == 1))
        .collect();
    starts.extend(0..segments.len());
    for start in starts {
        if used[start] {
            continue;
        }
        used[start] = true;
        let [a, b] = segments[start];
        let (first, mut last) = if by_end[&a].len() == 1 {
            (a, b)
        } else {
            (b, a)
        };
        let mut line = vec![first, last];
        loop {
            let next = by_end[&last].iter().copied().find(|&j| !used[j]);
            let Some(j) = next else { break };
            used[j] = true;
            let [p, q] = segments[j];
            last = if p == last { q } else { p };
            line.push(last);
        }
        lines.push(line);
    }
    lines
}

/// One pass of averaging each inner point with its neighbours (a closed line's first and
/// last points too), which rounds the pixel staircase into the line it stands for.
fn smooth(points: Vec<DVec2>) -> Vec<DVec2> {
    let n = points.len();
    let closed = n > 3 && points[0] == points[n - 1];
    if n < 3 {
        return points;
    }
    let mut out = points.clone();
    for i in 1..n - 1 {
        out[i] = points[i] * 0.5 + (points[i - 1] + points[i + 1]) * 0.25;
    }
    if closed {
        let p = points[0] * 0.5 + (points[n - 2] + points[1]) * 0.25;
        out[0] = p;
        out[n - 1] = p;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_outline_of_a_disc_is_one_closed_line_around_it() {
        let (w, h) = (40, 30);
        let centre = DVec2::new(20.0, 15.0);
        let mask: Vec<bool> = (0..w * h)
            .map(|i| {
                let p = DVec2::new((i % w) as f64 + 0.5, (i / w) as f64 + 0.5);
                (p - centre).length() < 9.0
            })
            .collect();
        let lines = outline(&mask, w, h);
        assert_eq!(lines.len(), 1);
        let line = &lines[0];
        assert_eq!(line.first(), line.last(), "closed");
        for p in line {
            let r = (*p - centre).length();
            assert!((r - 9.0).abs() < 0.8, "{p} at {r}");
        }
        let length: f64 = line.windows(2).map(|s| (s[1] - s[0]).length()).sum();
        let circle = 2.0 * std::f64::consts::PI * 9.0;
        assert!(
            (length / circle - 1.0).abs() < 0.12,
            "{length} against {circle}"
        );
    }

    #[test]
    fn a_half_plane_gives_one_open_line_and_an_empty_mask_none() {
        let (w, h) = (10, 6);
        let mask: Vec<bool> = (0..w * h).map(|i| i % w < 4).collect();
        let lines = outline(&mask, w, h);
        assert_eq!(lines.len(), 1);
        assert!(lines[0].iter().all(|p| (p.x - 4.0).abs() < 1e-12));
        assert_eq!(lines[0].len(), h);
        assert!(outline(&vec![false; w * h], w, h).is_empty());
        assert!(outline(&vec![true; w * h], w, h).is_empty());
    }

    #[test]
    fn a_saddle_keeps_the_set_corners_apart() {
        let mask = [true, false, false, true];
        let lines = outline(&mask, 2, 2);
        assert_eq!(lines.len(), 2);
    }
}
