//! One-pixel lines broadened to an exact width (`render::lines`): widths measured across
//! straight lines and a circle, zero padding at the borders, widths that vary, the line walk,
//! determinism and bad input.

use crate::common::Rng;
use glam::DVec2;
use halo4d::internals::lines::{
    Broadener, Coverage, LinesError, MAX_COORDINATE, MAX_SIDE, Mask, broaden, sigma_for_width,
};

/// Where the coverage along a cross-section crosses 1/2, by linear interpolation between
/// pixel centres, in pixel coordinates along the cross-section.
fn half_crossings(n: usize, coverage: impl Fn(usize) -> f32) -> Vec<f64> {
    let mut out = Vec::new();
    for j in 0..n - 1 {
        let (a, b) = (f64::from(coverage(j)), f64::from(coverage(j + 1)));
        if (a < 0.5) != (b < 0.5) {
            out.push(j as f64 + 0.5 + (0.5 - a) / (b - a));
        }
    }
    out
}

/// A band measured across one cross-section: its width and how far its centre lies from
/// the line, both perpendicular to the line.
struct Section {
    width: f64,
    centre_offset: f64,
}

/// Measures the band around the line through `point` along `dir` (unit) on every column
/// (rows where the line is steeper than 45°) whose band lies at least `margin` pixels from
/// the image's border.
fn sections(coverage: &Coverage, point: DVec2, dir: DVec2, margin: f64) -> Vec<Section> {
    let (w, h) = (coverage.width(), coverage.height());
    let x_major = dir.x.abs() >= dir.y.abs();
    let (major_size, minor_size) = if x_major { (w, h) } else { (h, w) };
    let (p_major, p_minor, d_major, d_minor) = if x_major {
        (point.x, point.y, dir.x, dir.y)
    } else {
        (point.y, point.x, dir.y, dir.x)
    };
    let mut out = Vec::new();
    for i in 0..major_size {
        let centre = i as f64 + 0.5;
        let line = p_minor + (centre - p_major) * d_minor / d_major;
        let inside = |v: f64, size: usize| v >= margin && v <= size as f64 - margin;
        if !inside(centre, major_size) || !inside(line, minor_size) {
            continue;
        }
        let at = |j: usize| {
            let (x, y) = if x_major { (i, j) } else { (j, i) };
            coverage.get(x, y).expect("inside the image")
        };
        let crossings = half_crossings(minor_size, at);
        assert_eq!(
            crossings.len(),
            2,
            "one band across section {i} of the line along {dir}"
        );
        out.push(Section {
            width: (crossings[1] - crossings[0]) * d_major.abs(),
            centre_offset: (0.5 * (crossings[0] + crossings[1]) - line) * d_major.abs(),
        });
    }
    out
}

/// One straight line through the point, across the whole image.
fn line_mask(n: usize, point: DVec2, dir: DVec2, width: f64) -> Mask {
    let mut mask = Mask::new(n, n).expect("a valid size");
    let drawn = mask
        .draw_segment(
            point - 4.0 * n as f64 * dir,
            point + 4.0 * n as f64 * dir,
            width,
        )
        .expect("a valid segment");
    assert!(drawn >= n, "the line crosses the image");
    mask
}

/// Margin from the border beyond which a band is not cut by it: its half-width, and the
/// blur's reach (the mask holds no line beyond the border).
fn margin(width: f64) -> f64 {
    0.5 * width + 4.0 * sigma_for_width(width) + 2.0
}

// The staircase of a one-pixel line widens the band by up to about 0.375 / sigma px where
// it steps (two offset half-lines blur to a wider profile), and drawing moves a line by up
// to half a pixel to the pixel centres; both stay under half a pixel.
const WIDTH_TOLERANCE: f64 = 0.5;

#[test]
fn straight_lines_broaden_to_the_requested_width_at_every_angle() {
    let n = 160;
    let mut broadener = Broadener::new();
    for degrees in [0.0, 17.0, 45.0, 90.0, 33.3, 71.0, 135.0] {
        let dir = DVec2::from_angle(f64::to_radians(degrees));
        for width in [1.5, 3.0, 5.0, 8.0] {
            // Offsets that put the line on pixel centres, between them and on their edges.
            for offset in [0.0, 0.25, 0.5, 0.71] {
                let point = DVec2::new(80.0 + offset, 80.0 + 0.37 * offset);
                let mask = line_mask(n, point, dir, width);
                let coverage = broadener.broaden(&mask, width).expect("a valid width");
                let measured = sections(&coverage, point, dir, margin(width));
                assert!(measured.len() > 40, "{degrees}°: enough sections");
                for s in &measured {
                    assert!(
                        (s.width - width).abs() <= WIDTH_TOLERANCE,
                        "{degrees}°, offset {offset}: band {} px wide, wanted {width}",
                        s.width
                    );
                    assert!(
                        s.centre_offset.abs() <= 0.5 + 1e-6,
                        "{degrees}°, offset {offset}, width {width}: band centred {} px \
                         from the line",
                        s.centre_offset
                    );
                }
                let mean = measured.iter().map(|s| s.width).sum::<f64>() / measured.len() as f64;
                assert!(
                    (mean - width).abs() <= 0.2,
                    "{degrees}°, offset {offset}: mean width {mean}, wanted {width}"
                );
            }
        }
    }
}

#[test]
fn a_line_along_an_axis_is_covered_exactly_its_width() {
    // On a line through pixel centres along an axis, the coverage of a column adds up to
    // the width: the ramp is one pixel wide and centred on the band's edge.
    let mut broadener = Broadener::new();
    for width in [0.4, 1.0, 1.5, 2.0, 3.0, 5.0, 8.0, 13.0] {
        let mask = line_mask(96, DVec2::new(48.5, 40.5), DVec2::X, width);
        let coverage = broadener.broaden(&mask, width).expect("a valid width");
        for x in 30..66 {
            let sum: f64 = (0..96)
                .map(|y| f64::from(coverage.get(x, y).expect("inside")))
                .sum();
            assert!(
                (sum - width).abs() < 1e-3,
                "column {x}: coverage {sum}, wanted {width}"
            );
        }
    }
}

/// Bilinear interpolation of the coverage between pixel centres.
fn sample(coverage: &Coverage, p: DVec2) -> f64 {
    let q = p - 0.5;
    let (x, y) = (q.x.floor(), q.y.floor());
    let (fx, fy) = (q.x - x, q.y - y);
    let at = |dx: f64, dy: f64| {
        f64::from(
            coverage
                .get((x + dx) as usize, (y + dy) as usize)
                .unwrap_or(0.0),
        )
    };
    (1.0 - fy) * ((1.0 - fx) * at(0.0, 0.0) + fx * at(1.0, 0.0))
        + fy * ((1.0 - fx) * at(0.0, 1.0) + fx * at(1.0, 1.0))
}

#[test]
fn a_circles_outline_has_the_requested_width() {
    let (n, radius, centre) = (160, 50.0, DVec2::new(80.3, 79.6));
    let mut broadener = Broadener::new();
    for width in [3.0, 6.0] {
        let mut mask = Mask::new(n, n).expect("a valid size");
        let sides = 200;
        let corner = |k: usize| {
            centre + radius * DVec2::from_angle(k as f64 * std::f64::consts::TAU / sides as f64)
        };
        let mut ring: Vec<(DVec2, f64)> = (0..sides).map(|k| (corner(k), width)).collect();
        ring.push(ring[0]);
        mask.draw_polyline(&ring).expect("a valid polyline");
        let coverage = broadener.broaden(&mask, width).expect("a valid width");
        for ray in 0..720 {
            let dir = DVec2::from_angle(f64::from(ray) * std::f64::consts::TAU / 720.0);
            let profile: Vec<f64> = (0..=400)
                .map(|k| {
                    sample(
                        &coverage,
                        centre + (radius - 10.0 + 0.05 * f64::from(k)) * dir,
                    )
                })
                .collect();
            let crossings = half_crossings(profile.len(), |k| profile[k] as f32);
            assert_eq!(crossings.len(), 2, "ray {ray}: one band");
            let measured = (crossings[1] - crossings[0]) * 0.05;
            // Interpolating between pixel centres adds up to a tenth of a pixel.
            assert!(
                (measured - width).abs() <= WIDTH_TOLERANCE + 0.1,
                "ray {ray}: outline {measured} px wide, wanted {width}"
            );
        }
        let area: f64 = coverage.values().iter().map(|&c| f64::from(c)).sum();
        // The staircase's steps widen the band a little on average.
        let mean = area / (std::f64::consts::TAU * radius);
        assert!(
            (mean - width).abs() < 0.15,
            "covered area {area}: mean width {mean}, wanted {width}"
        );
    }
}

#[test]
fn lines_along_the_border_do_not_wrap_around() {
    // 64 is already a fast FFT length: without the padding, the blur would be circular on
    // exactly the image and these bands would reappear on the opposite sides (the unit test
    // `unpadded_blur_wraps_around` shows it).
    let (n, width) = (64, 8.0);
    let mut mask = Mask::new(n, n).expect("a valid size");
    let far = n as f64;
    mask.draw_segment(DVec2::new(0.0, 0.5), DVec2::new(far, 0.5), width)
        .expect("top edge");
    mask.draw_segment(DVec2::new(0.5, 0.0), DVec2::new(0.5, far), width)
        .expect("left edge");
    let coverage = broaden(&mask, width).expect("a valid width");
    for y in 0..n {
        for x in 0..n {
            // Where the two lines meet, their blurs add up and round the inner corner.
            let c = coverage.get(x, y).expect("inside");
            if x.min(y) < 3 {
                assert_eq!(c, 1.0, "({x}, {y}) is in the band");
            } else if x.min(y) >= 5 && x.max(y) >= 10 {
                assert_eq!(c, 0.0, "({x}, {y}) is beyond the band");
            }
        }
    }
}

#[test]
fn an_empty_mask_stays_empty() {
    let mut mask = Mask::new(70, 50).expect("a valid size");
    // Segments wholly outside the image draw nothing.
    for (a, b) in [
        (DVec2::new(-5.0, -5.0), DVec2::new(-1.0, 30.0)),
        (DVec2::new(71.0, 0.0), DVec2::new(90.0, 49.0)),
        (DVec2::new(-10.0, 60.0), DVec2::new(80.0, 51.0)),
    ] {
        assert_eq!(mask.draw_segment(a, b, 3.0), Ok(0));
    }
    assert!(mask.is_empty());
    assert_eq!(mask.max_width(), 0.0);
    let mut broadener = Broadener::new();
    for coverage in [
        broadener.broaden(&mask, 5.0).expect("a valid width"),
        broadener
            .broaden_varying(&mask)
            .expect("nothing to broaden"),
    ] {
        assert_eq!((coverage.width(), coverage.height()), (70, 50));
        assert!(coverage.values().iter().all(|&c| c == 0.0));
    }
}

fn random_mask(rng: &mut Rng, n: usize, segments: usize) -> Mask {
    let mut mask = Mask::new(n, n + 17).expect("a valid size");
    let mut point = || DVec2::new(rng.unit() * 1.2 - 0.1, rng.unit() * 1.2 - 0.1) * n as f64;
    for _ in 0..segments {
        let (a, b) = (point(), point());
        mask.draw_polyline(&[(a, 2.0), (b, 7.0)])
            .expect("a valid segment");
    }
    mask
}

#[test]
fn broadening_is_deterministic() {
    let mask = random_mask(&mut Rng(7), 300, 60);
    let bits = |c: &Coverage| c.values().iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    let mut broadener = Broadener::new();
    let first = broadener.broaden(&mask, 4.0).expect("a valid width");
    let varying = broadener.broaden_varying(&mask).expect("valid widths");
    assert!(first.values().iter().any(|&c| c > 0.0));
    assert_eq!(
        bits(&first),
        bits(&broadener.broaden(&mask, 4.0).expect("again"))
    );
    assert_eq!(
        bits(&first),
        bits(&broaden(&mask, 4.0).expect("a fresh broadener"))
    );
    assert_eq!(
        bits(&varying),
        bits(&Broadener::new().broaden_varying(&mask).expect("again"))
    );
}

#[test]
fn bad_input_is_an_error_naming_the_problem() {
    for (w, h) in [(0, 10), (10, 0), (MAX_SIDE + 1, 1)] {
        assert_eq!(
            Mask::new(w, h),
            Err(LinesError::BadSize {
                width: w,
                height: h
            })
        );
    }
    let mut mask = Mask::new(40, 30).expect("a valid size");
    let (a, b) = (DVec2::new(1.0, 1.0), DVec2::new(20.0, 9.0));
    mask.draw_segment(a, b, 3.0).expect("a valid segment");
    let before = mask.clone();
    let mut broadener = Broadener::new();
    for width in [0.0, -2.0, f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let err = broadener.broaden(&mask, width).expect_err("a bad width");
        assert!(matches!(err, LinesError::BadWidth { .. }), "{err}");
        assert!(err.to_string().contains("greater than 0"), "{err}");
        let err = mask.draw_segment(a, b, width).expect_err("a bad width");
        assert!(matches!(err, LinesError::BadWidth { .. }), "{err}");
        let err = mask
            .draw_polyline(&[(a, 3.0), (b, width)])
            .expect_err("a bad width");
        assert!(matches!(err, LinesError::BadWidth { .. }), "{err}");
    }
    for width in [40.5, 1e9] {
        let err = broadener.broaden(&mask, width).expect_err("too wide");
        assert_eq!(
            err,
            LinesError::WidthTooLarge {
                width,
                image_width: 40,
                image_height: 30,
                limit: 40.0
            }
        );
        assert!(err.to_string().contains("at most 40 px"), "{err}");
        let err = mask.draw_segment(a, b, width).expect_err("too wide");
        assert!(matches!(err, LinesError::WidthTooLarge { .. }), "{err}");
    }
    for p in [
        DVec2::new(f64::NAN, 1.0),
        DVec2::new(1.0, f64::INFINITY),
        DVec2::new(-2.0 * MAX_COORDINATE, 0.0),
    ] {
        let err = mask.draw_segment(a, p, 3.0).expect_err("a bad point");
        assert!(matches!(err, LinesError::BadPoint { .. }), "{err}");
        assert!(err.to_string().contains("finite"), "{err}");
        let err = mask.draw_segment(p, b, 3.0).expect_err("a bad point");
        assert!(matches!(err, LinesError::BadPoint { .. }), "{err}");
    }
    assert_eq!(mask, before, "failed draws change nothing");
    // The widest width accepted, and far endpoints that clip into the image, are fine.
    broadener
        .broaden(&mask, 40.0)
        .expect("as wide as the image");
    let far = 0.5 * MAX_COORDINATE;
    assert_eq!(
        mask.draw_segment(DVec2::new(-far, 15.5), DVec2::new(far, 15.5), 2.0),
        Ok(40)
    );
}

/// Measures the band across columns of a horizontal line at row `y`.
fn column_width(coverage: &Coverage, x: usize, rows: std::ops::Range<usize>) -> f64 {
    let start = rows.start;
    let crossings = half_crossings(rows.len(), |j| coverage.get(x, start + j).expect("inside"));
    assert_eq!(crossings.len(), 2, "one band across column {x}");
    crossings[1] - crossings[0]
}

#[test]
fn bands_narrow_where_the_drawn_width_shrinks() {
    let (n, y) = (160, 60.5);
    let mut mask = Mask::new(n, n).expect("a valid size");
    // One line narrowing from 8 px to 2 px, and far below it two lines of constant widths.
    let (left, right) = (-20.0, n as f64 + 20.0);
    mask.draw_polyline(&[(DVec2::new(left, y), 8.0), (DVec2::new(right, y), 2.0)])
        .expect("a valid segment");
    mask.draw_segment(DVec2::new(left, 100.5), DVec2::new(right, 100.5), 8.0)
        .expect("a valid segment");
    mask.draw_segment(DVec2::new(left, 130.5), DVec2::new(right, 130.5), 2.0)
        .expect("a valid segment");
    assert_eq!(mask.max_width(), 8.0);
    let coverage = Broadener::new()
        .broaden_varying(&mask)
        .expect("valid widths");
    let mut last = f64::INFINITY;
    for x in (20..140).step_by(10) {
        let wanted = 8.0 + (x as f64 + 0.5 - left) / (right - left) * (2.0 - 8.0);
        let measured = column_width(&coverage, x, 30..90);
        assert!(
            (measured - wanted).abs() <= WIDTH_TOLERANCE,
            "column {x}: {measured} px, wanted {wanted}"
        );
        assert!(measured < last, "column {x}: narrower than to its left");
        last = measured;
        let wide = column_width(&coverage, x, 85..115);
        let thin = column_width(&coverage, x, 120..145);
        assert!((wide - 8.0).abs() <= WIDTH_TOLERANCE, "column {x}: {wide}");
        assert!((thin - 2.0).abs() <= WIDTH_TOLERANCE, "column {x}: {thin}");
    }
}

#[test]
fn constant_drawn_widths_broaden_like_one_width() {
    let mut rng = Rng(11);
    let mut mask = Mask::new(120, 90).expect("a valid size");
    for _ in 0..12 {
        let mut p = || DVec2::new(rng.unit() * 120.0, rng.unit() * 90.0);
        let (a, b) = (p(), p());
        mask.draw_segment(a, b, 5.0).expect("a valid segment");
    }
    let mut broadener = Broadener::new();
    let uniform = broadener.broaden(&mask, 5.0).expect("a valid width");
    let varying = broadener.broaden_varying(&mask).expect("valid widths");
    let worst = uniform
        .values()
        .iter()
        .zip(varying.values())
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f32::max);
    assert!(worst < 1e-3, "coverages differ by {worst}");
}

#[test]
fn lines_are_one_pixel_wide_and_connected_at_every_slope() {
    let mut rng = Rng(3);
    for k in 0..400 {
        let (w, h) = (50, 40);
        let mut mask = Mask::new(w, h).expect("a valid size");
        let a = DVec2::new(5.0 + 40.0 * rng.unit(), 5.0 + 30.0 * rng.unit());
        let dir = DVec2::from_angle(rng.unit() * std::f64::consts::TAU);
        let b = a + (0.5 + 30.0 * rng.unit()) * dir;
        let drawn = mask.draw_segment(a, b, 2.0).expect("a valid segment");
        let ink = |x: usize, y: usize| mask.ink()[y * w + x];
        let x_major = dir.x.abs() >= dir.y.abs();
        let (major, minor) = if x_major { (w, h) } else { (h, w) };
        let at = |i: usize, j: usize| if x_major { ink(i, j) } else { ink(j, i) };
        // Exactly one pixel per column (row), in consecutive columns, each at most one row
        // from the last: one pixel wide and 8-connected.
        let mut last: Option<(usize, usize)> = None;
        let mut count = 0;
        for i in 0..major {
            let set: Vec<usize> = (0..minor).filter(|&j| at(i, j) > 0.0).collect();
            assert!(
                set.len() <= 1,
                "segment {k}: {} pixels in line {i}",
                set.len()
            );
            if let Some(&j) = set.first() {
                if let Some((li, lj)) = last {
                    assert_eq!(li + 1, i, "segment {k}: a gap before line {i}");
                    assert!(lj.abs_diff(j) <= 1, "segment {k}: a jump at line {i}");
                }
                last = Some((i, j));
                count += 1;
            }
        }
        assert_eq!(count, drawn, "segment {k}");
        // The walk starts and ends in the endpoints' columns (rows), within a pixel of them;
        // the ink is the length each pixel stands for.
        for p in [a, b] {
            if p.x >= w as f64 || p.y >= h as f64 || p.min_element() < 0.0 {
                continue;
            }
            let (i, j) = if x_major { (p.x, p.y) } else { (p.y, p.x) };
            let (i, j) = (i as usize, j as usize);
            assert!(
                (j.saturating_sub(1)..=j + 1).any(|j| j < minor && at(i, j) > 0.0),
                "segment {k}: nothing drawn by the endpoint {p}"
            );
        }
        let expected = 1.0 / dir.x.abs().max(dir.y.abs());
        assert!(
            mask.ink()
                .iter()
                .all(|&v| v == 0.0 || (f64::from(v) - expected).abs() < 1e-6),
            "segment {k}: ink"
        );
    }
}

#[test]
fn polylines_are_connected() {
    let mut rng = Rng(5);
    let (w, h) = (60, 45);
    for k in 0..100 {
        let mut mask = Mask::new(w, h).expect("a valid size");
        let mut point = || DVec2::new(2.0 + 56.0 * rng.unit(), 2.0 + 41.0 * rng.unit());
        let mut a = point();
        for _ in 0..6 {
            let b = point();
            mask.draw_segment(a, b, 2.0).expect("a valid segment");
            a = b;
        }
        // Flood fill from one inked pixel through 8-neighbours reaches all of them.
        let inked = |x: i64, y: i64| {
            x >= 0
                && y >= 0
                && x < w as i64
                && y < h as i64
                && mask.ink()[y as usize * w + x as usize] > 0.0
        };
        let start = mask
            .ink()
            .iter()
            .position(|&v| v > 0.0)
            .expect("something drawn");
        let mut seen = vec![false; w * h];
        let mut stack = vec![((start % w) as i64, (start / w) as i64)];
        seen[start] = true;
        let mut reached = 0;
        while let Some((x, y)) = stack.pop() {
            reached += 1;
            for (dx, dy) in [
                (-1, -1),
                (0, -1),
                (1, -1),
                (-1, 0),
                (1, 0),
                (-1, 1),
                (0, 1),
                (1, 1),
            ] {
                let (nx, ny) = (x + dx, y + dy);
                if inked(nx, ny) && !seen[ny as usize * w + nx as usize] {
                    seen[ny as usize * w + nx as usize] = true;
                    stack.push((nx, ny));
                }
            }
        }
        let total = mask.ink().iter().filter(|&&v| v > 0.0).count();
        assert_eq!(
            reached,
            total,
            "polyline {k}: {} pixels cut off",
            total - reached
        );
    }
}

#[test]
fn closed_polylines_are_one_pixel_wide_rings() {
    // A convex ring drawn one pixel wide is a simple 8-curve: every pixel of it has exactly
    // two 8-neighbours in it, also at the joints and where it closes.
    let mut rng = Rng(17);
    let (w, h) = (140, 140);
    for k in 0..200 {
        let radius = 6.0 + 60.0 * rng.unit();
        let centre = DVec2::new(69.0 + 2.0 * rng.unit(), 69.0 + 2.0 * rng.unit());
        let sides = 12 + (radius * (0.5 + 3.0 * rng.unit())) as usize;
        let turn = rng.unit();
        let mut ring: Vec<(DVec2, f64)> = (0..sides)
            .map(|i| {
                let angle = (i as f64 + turn) * std::f64::consts::TAU / sides as f64;
                (centre + radius * DVec2::from_angle(angle), 2.0)
            })
            .collect();
        ring.push(ring[0]);
        let mut mask = Mask::new(w, h).expect("a valid size");
        mask.draw_polyline(&ring).expect("a valid polyline");
        let inked = |x: i64, y: i64| mask.ink()[y as usize * w + x as usize] > 0.0;
        for y in 1..h as i64 - 1 {
            for x in 1..w as i64 - 1 {
                if !inked(x, y) {
                    continue;
                }
                let neighbours = (-1..=1)
                    .flat_map(|dy| (-1..=1).map(move |dx| (dx, dy)))
                    .filter(|&(dx, dy)| (dx, dy) != (0, 0) && inked(x + dx, y + dy))
                    .count();
                assert_eq!(
                    neighbours, 2,
                    "ring {k} (radius {radius:.2}, {sides} sides): pixel ({x}, {y})"
                );
            }
        }
    }
}

#[test]
fn tiny_images_and_single_points_broaden() {
    let mut broadener = Broadener::new();
    for (w, h) in [(1, 1), (1, 7), (7, 1), (2, 3)] {
        let mut mask = Mask::new(w, h).expect("a valid size");
        let centre = DVec2::new(w as f64, h as f64) * 0.5;
        assert_eq!(mask.draw_polyline(&[(centre, 1.0)]), Ok(1), "{w} x {h}");
        let (x, y) = (w / 2, h / 2);
        assert_eq!(mask.ink()[y * w + x], 1.0);
        for coverage in [
            broadener.broaden(&mask, 1.0).expect("a valid width"),
            broadener.broaden_varying(&mask).expect("a valid width"),
        ] {
            assert!(coverage.values().iter().all(|&c| (0.0..=1.0).contains(&c)));
        }
    }
    // A point is a line of no length, whose ends recede (see the module docs): a band 1 px
    // wide all but loses it, one 4 px wide keeps a dot about 3 px across.
    let mut mask = Mask::new(9, 9).expect("a valid size");
    mask.draw_polyline(&[(DVec2::new(4.5, 4.5), 4.0)])
        .expect("a valid point");
    let dot = broadener.broaden_varying(&mask).expect("a valid width");
    assert_eq!(dot.get(4, 4), Some(1.0));
    let area: f32 = dot.values().iter().sum();
    assert!((4.0..10.0).contains(&area), "dot of {area} px²");
    let mut mask = Mask::new(5, 5).expect("a valid size");
    assert_eq!(mask.draw_polyline(&[]), Ok(0));
    assert_eq!(
        mask.draw_polyline(&[(DVec2::new(-1.0, 2.0), 1.0)]),
        Ok(0),
        "a point outside draws nothing"
    );
    assert!(mask.is_empty());
}
