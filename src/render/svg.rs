//! The picture as line art (`outputs.svg`): the lines the PNG draws (silhouettes, cut
//! edges, double curves in their inks, the broken edges of the sheets passing under), as
//! scalable SVG paths for papers and slides.
//!
//! The paths are the very runs the PNG's lines are drawn from (the parts of each line a
//! ray from the eye reaches), in the picture's pixel coordinates (y down, as SVG's), each
//! stroked at its width with round caps and joins, over the background's colour. Inks are
//! written in sRGB, as the PNG's pixels are.

use super::overlay::Run;
use glam::DVec3;
use std::fmt::Write;

/// An SVG document of `width` x `height` pixels with `runs` stroked over `background`
/// (linear RGB).
pub(crate) fn document(width: u32, height: u32, background: DVec3, runs: &[Run]) -> String {
    let mut out = header(width, height, background);
    // In the order the PNG lays its inks over each other.
    let mut ordered: Vec<&Run> = runs.iter().collect();
    ordered.sort_by_key(|r| r.class);
    for run in ordered {
        if run.points.len() < 2 {
            continue;
        }
        let width = run.points.iter().map(|p| p.1).sum::<f64>() / run.points.len() as f64;
        let _ = write!(
            out,
            r#"<path fill="none" stroke="{}" stroke-width="{width:.3}" stroke-linecap="round" stroke-linejoin="round" d=""#,
            rgb(run.ink)
        );
        for (k, (p, _)) in run.points.iter().enumerate() {
            let _ = write!(
                out,
                "{}{:.2} {:.2}",
                if k == 0 { "M" } else { " L" },
                p.x,
                p.y
            );
        }
        out.push_str("\"/>\n");
    }
    out.push_str("</svg>\n");
    out
}

/// `rgb(r,g,b)` of a linear colour, in sRGB bytes.
/// The start of an SVG document of `width` x `height` pixels filled with `background`
/// (linear RGB); the caller closes it with `</svg>`.
pub(super) fn header(width: u32, height: u32, background: DVec3) -> String {
    format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" viewBox="0 0 {width} {height}">
<rect width="{width}" height="{height}" fill="{}"/>
"#,
        rgb(background)
    )
}

/// A linear colour as SVG's sRGB `rgb(r,g,b)`.
pub(super) fn rgb(c: DVec3) -> String {
    let [r, g, b] = [c.x, c.y, c.z].map(super::to_srgb8);
    format!("rgb({r},{g},{b})")
}
