//! Text in pictures and plots: the embedded DejaVu Sans Mono, registered once with plotters
//! for the plots' labels, and the numbers of the colour bar laid out and rasterized by
//! ab_glyph (plotters' own font backend) into a render's image, blended in sRGB as a text
//! renderer does.

use ab_glyph::{Font, FontRef, GlyphId, PxScale, ScaleFont, point};
use glam::DVec3;
use plotters::style::FontStyle;

/// The font family every label is drawn in, once [`register_font`] has run.
pub const FAMILY: &str = "halo4d-mono";

/// The font, embedded so that labels look the same on every machine (DejaVu Sans Mono;
/// licence in `assets/fonts/DejaVu-LICENSE.txt`).
const FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSansMono.ttf");

/// The smallest label drawn, in pixels (the font's size): below it digits do not read.
pub const MIN_TEXT: f64 = 8.0;

/// A label's size as a share of the picture's smaller side: 16 px at 512, 64 px at 2048.
const TEXT_PER_SIDE: f64 = 1.0 / 32.0;

/// Registers [`FAMILY`] with plotters (once; later calls return the first outcome). An
/// error is a bug: the embedded font is not a font.
pub fn register_font() -> Result<(), String> {
    static DONE: std::sync::OnceLock<Result<(), String>> = std::sync::OnceLock::new();
    DONE.get_or_init(|| {
        plotters::style::register_font(FAMILY, FontStyle::Normal, FONT)
            .map_err(|_| "the embedded font is not a valid font".to_string())
    })
    .clone()
}

/// The pixels `text` covers at `size` pixels (ab_glyph's scale: the font's height, ascent
/// to descent), laid out on a baseline at y = 0 from x = 0 with the font's advances,
/// bearings and kerning: (x, y, coverage in (0, 1]).
fn rasterize(text: &str, size: f64) -> Result<Vec<(i32, i32, f32)>, String> {
    let font =
        FontRef::try_from_slice(FONT).map_err(|_| "the embedded font is not a valid font")?;
    let scaled = font.as_scaled(PxScale::from(size as f32));
    let mut caret = 0.0f32;
    let mut previous: Option<GlyphId> = None;
    let mut out = Vec::new();
    for c in text.chars() {
        let id = scaled.glyph_id(c);
        if let Some(p) = previous {
            caret += scaled.kern(p, id);
        }
        let glyph = id.with_scale_and_position(scaled.scale(), point(caret, 0.0));
        caret += scaled.h_advance(id);
        previous = Some(id);
        if let Some(outlined) = font.outline_glyph(glyph) {
            let at = outlined.px_bounds().min;
            outlined.draw(|x, y, c| {
                if c > 0.0 {
                    out.push((at.x as i32 + x as i32, at.y as i32 + y as i32, c.min(1.0)));
                }
            });
        }
    }
    Ok(out)
}

/// `x` with three significant digits, compactly: fixed point from 0.001 to 99999 (with as
/// many more decimals as `step`, the difference between neighbouring labels, needs to show
/// at three digits), else `1.23e-5`; trailing zeros dropped. `0` for a value below a
/// billionth of `step`.
pub fn compact(x: f64, step: f64) -> String {
    if !x.is_finite() {
        return format!("{x}");
    }
    if x == 0.0 || x.abs() < step.abs() * 1e-9 {
        return "0".into();
    }
    // The exponent after rounding to three digits (9.996 is 1.00e1).
    let exponent = |v: f64| -> i32 {
        format!("{:.2e}", v.abs())
            .split_once('e')
            .and_then(|(_, e)| e.parse().ok())
            .unwrap_or(0)
    };
    let e = exponent(x);
    let trim = |s: String| -> String {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    };
    if !(-3..5).contains(&e) {
        let (mantissa, exp) = format!("{x:.2e}")
            .split_once('e')
            .map(|(m, e)| (m.to_string(), e.to_string()))
            .unwrap_or_default();
        return format!("{}e{exp}", trim(mantissa));
    }
    let step_digits = if step.is_finite() && step != 0.0 {
        2 - exponent(step)
    } else {
        0
    };
    let decimals = (2 - e).max(step_digits).clamp(0, 12) as usize;
    let s = trim(format!("{x:.decimals$}"));
    if s == "-0" { "0".into() } else { s }
}

/// A label rasterized and placed: its pixels relative to its placement, and its extent.
struct Label {
    pixels: Vec<(i32, i32, f32)>,
    /// Smallest and largest x and y of its pixels.
    lo: (i32, i32),
    hi: (i32, i32),
}

impl Label {
    fn new(text: &str, size: f64) -> Result<Option<Label>, String> {
        let pixels = rasterize(text, size)?;
        let Some(&(x, y, _)) = pixels.first() else {
            return Ok(None);
        };
        let (mut lo, mut hi) = ((x, y), (x, y));
        for &(x, y, _) in &pixels {
            lo = (lo.0.min(x), lo.1.min(y));
            hi = (hi.0.max(x), hi.1.max(y));
        }
        Ok(Some(Label { pixels, lo, hi }))
    }
}

/// Draws `text` at `size` pixels in `ink` into the `width` x `height` image `rgb` (linear
/// RGB, row-major), centred on `(x, y)` both ways (its pixels' box), clipped to the image.
pub(super) fn draw_centred(
    rgb: &mut [DVec3],
    (width, _height): (usize, usize),
    text: &str,
    size: f64,
    (x, y): (f64, f64),
    ink: DVec3,
) -> Result<(), String> {
    let Some(label) = Label::new(text, size)? else {
        return Ok(());
    };
    let dx = x.round() as i32 - (label.lo.0 + label.hi.0) / 2;
    let dy = y.round() as i32 - (label.lo.1 + label.hi.1) / 2;
    for &(px, py, c) in &label.pixels {
        blend(rgb, width, (px + dx, py + dy), ink, c);
    }
    Ok(())
}

/// Labels the colour bar whose top row is `bar_top` and which spans columns `x0..x1` of the
/// `width` x `height` image `rgb` (linear RGB, row-major) with the w of its left end, its
/// middle and its right end, `w`: text in `ink` with a thin outline in `outline`, on one
/// baseline above the bar, the first label starting at the bar's left end, the last ending
/// at its right end, the middle one centred. The text's size is a 32nd of the picture's
/// smaller side. Nothing is drawn, and `false` returned, when the labels would be under
/// [`MIN_TEXT`] pixels, overlap one another or leave the picture.
#[allow(clippy::too_many_arguments)]
pub(super) fn label_bar(
    rgb: &mut [DVec3],
    (width, height): (usize, usize),
    bar_top: usize,
    (x0, x1): (usize, usize),
    w: [f64; 3],
    ink: DVec3,
    outline: DVec3,
) -> Result<bool, String> {
    let size = (width.min(height) as f64 * TEXT_PER_SIDE).floor();
    if size < MIN_TEXT {
        return Ok(false);
    }
    let step = (w[1] - w[0]).abs();
    let mut labels = Vec::new();
    for &v in &w {
        match Label::new(&format!("w {}", compact(v, step)), size)? {
            Some(label) => labels.push(label),
            None => return Ok(false),
        }
    }
    // The outline's reach, and the gaps kept to the bar and between the labels.
    let reach = ((size / 12.0).round() as i32).max(1);
    let gap = (size * 0.25).round() as i32 + reach;
    let spacing = (size * 0.5).round() as i32;
    let bottom = labels.iter().map(|l| l.hi.1).max().unwrap_or(0);
    let dy = bar_top as i32 - gap - bottom;
    let (x0, x1) = (x0 as i32, x1 as i32 - 1);
    let centre = (x0 + x1) / 2;
    let dx = [
        x0 - labels[0].lo.0,
        centre - (labels[1].lo.0 + labels[1].hi.0) / 2,
        x1 - labels[2].hi.0,
    ];
    let left = |k: usize| labels[k].lo.0 + dx[k];
    let right = |k: usize| labels[k].hi.0 + dx[k];
    let top = labels.iter().map(|l| l.lo.1).min().unwrap_or(0) + dy;
    let fits = top - reach >= 0
        && left(0) - reach >= 0
        && right(2) + reach < width as i32
        && right(0) + spacing < left(1)
        && right(1) + spacing < left(2);
    if !fits {
        return Ok(false);
    }
    // The outline first, for every label, then the text over it.
    for (label, &dx) in labels.iter().zip(&dx) {
        for &(x, y, c) in &label.pixels {
            for oy in -reach..=reach {
                for ox in -reach..=reach {
                    blend(rgb, width, (x + dx + ox, y + dy + oy), outline, c);
                }
            }
        }
    }
    for (label, &dx) in labels.iter().zip(&dx) {
        for &(x, y, c) in &label.pixels {
            blend(rgb, width, (x + dx, y + dy), ink, c);
        }
    }
    Ok(true)
}

/// Lays `colour` over pixel (x, y) with coverage `c`, blended in sRGB (pixels outside are
/// left alone).
fn blend(rgb: &mut [DVec3], width: usize, (x, y): (i32, i32), colour: DVec3, c: f32) {
    if x < 0 || y < 0 || x as usize >= width {
        return;
    }
    if let Some(p) = rgb.get_mut(y as usize * width + x as usize) {
        let mixed = encode(*p).lerp(encode(colour), f64::from(c));
        *p = mixed.map(decode);
    }
}

/// Linear RGB in [0, 1] to sRGB's encoding, per channel.
fn encode(c: DVec3) -> DVec3 {
    c.clamp(DVec3::ZERO, DVec3::ONE).map(|c| {
        if c <= 0.003_130_8 {
            12.92 * c
        } else {
            1.055 * c.powf(1.0 / 2.4) - 0.055
        }
    })
}

/// sRGB's encoding back to linear.
fn decode(s: f64) -> f64 {
    if s <= 0.040_45 {
        s / 12.92
    } else {
        ((s + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_three_digits_compactly() {
        let cases = [
            (-1.2345, 1.0, "-1.23"),
            (0.5, 1.0, "0.5"),
            (1.0, 1.0, "1"),
            (9.996, 1.0, "10"),
            (123.456, 100.0, "123"),
            (12345.6, 1e4, "12346"),
            (123456.0, 1e5, "1.23e5"),
            (0.000123, 1e-4, "1.23e-4"),
            (-0.00123, 1e-3, "-0.00123"),
            (1e-17, 1.0, "0"),
            // Neighbouring labels 0.001 apart keep the digits that tell them apart.
            (10.001, 0.001, "10.001"),
            (10.002, 0.001, "10.002"),
        ];
        for (x, step, want) in cases {
            assert_eq!(compact(x, step), want, "{x} (step {step})");
        }
    }

    #[test]
    fn labels_are_drawn_above_the_bar_when_they_fit_and_not_at_all_when_not() {
        for (side, drawn) in [(512usize, true), (2048, true), (200, false)] {
            let bar_top = side - side / 20;
            let mut rgb = vec![DVec3::ONE; side * side];
            let done = label_bar(
                &mut rgb,
                (side, side),
                bar_top,
                (side / 40, side - side / 40),
                [-1.23, 0.135, 1.5],
                DVec3::ZERO,
                DVec3::ONE,
            )
            .unwrap();
            assert_eq!(done, drawn, "{side} px");
            let dark: Vec<usize> = (0..rgb.len()).filter(|&i| rgb[i].x < 0.5).collect();
            if !drawn {
                assert!(dark.is_empty(), "{side} px: nothing drawn");
                continue;
            }
            // Text, all of it above the bar, within a few label heights of it.
            let size = side / 32;
            assert!(
                dark.len() > 10 * size,
                "{side} px: {} dark pixels",
                dark.len()
            );
            for &i in &dark {
                let y = i / side;
                assert!(y < bar_top && y + 3 * size > bar_top, "{side} px: row {y}");
            }
            // The first label starts at the bar's left end, the last ends at its right
            // end, and the middle one covers the bar's middle.
            let columns: Vec<usize> = dark.iter().map(|&i| i % side).collect();
            let (x0, x1) = (side / 40, side - side / 40);
            let (lo, hi) = (columns.iter().min().unwrap(), columns.iter().max().unwrap());
            assert!(
                lo.abs_diff(x0) <= 2 && hi.abs_diff(x1 - 1) <= 2,
                "{side} px"
            );
            assert!(
                columns.iter().any(|&x| x.abs_diff(side / 2) < size),
                "{side} px"
            );
        }
    }
}
