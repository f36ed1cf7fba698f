//! Speed against error of the multi-slice mode: for several slice counts, the render time
//! and how far the picture is from the exact mode's.

use super::{CameraSettings, RenderError, RenderMode, RenderSettings, render_with_depth};
use crate::parts::Parts;
use serde::Serialize;
use std::time::Instant;

/// One render compared with the exact one.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Comparison {
    /// Slices (0 for the exact mode itself).
    pub slices: u32,
    /// Milliseconds for the render.
    pub ms: f64,
    /// Mean absolute difference per pixel and channel, in [0, 1].
    pub mean_diff: f64,
    /// The 99th percentile of the per-pixel difference (largest channel), in [0, 1].
    pub p99_diff: f64,
    /// Share of covered pixels (a surface in either picture) where the first visible
    /// surface differs: the hidden/visible verdict of the two modes disagrees there.
    pub verdict_differs: f64,
}

/// The exact render first, then the slice mode with each of `slices`, all with `settings`
/// otherwise; `progress` hears of each.
pub fn compare(
    input: &Parts,
    settings: &RenderSettings,
    camera: &CameraSettings,
    slices: &[u32],
    progress: &mut dyn FnMut(&Comparison),
) -> Result<Vec<Comparison>, RenderError> {
    let settings = RenderSettings {
        stereo: false,
        ..*settings
    };
    let exact_settings = RenderSettings {
        mode: RenderMode::Exact,
        ..settings
    };
    let start = Instant::now();
    let (exact, exact_depth) = render_with_depth(input, &exact_settings, camera)?;
    let exact_row = Comparison {
        slices: 0,
        ms: start.elapsed().as_secs_f64() * 1e3,
        mean_diff: 0.0,
        p99_diff: 0.0,
        verdict_differs: 0.0,
    };
    progress(&exact_row);
    let mut rows = vec![exact_row];
    for &n in slices {
        let s = RenderSettings {
            mode: RenderMode::Slices,
            slices: n,
            ..settings
        };
        let start = Instant::now();
        let (picture, depth) = render_with_depth(input, &s, camera)?;
        let ms = start.elapsed().as_secs_f64() * 1e3;
        let mut diffs: Vec<f64> = exact
            .rgb
            .chunks(3)
            .zip(picture.rgb.chunks(3))
            .map(|(a, b)| {
                (0..3)
                    .map(|k| (f64::from(a[k]) - f64::from(b[k])).abs() / 255.0)
                    .fold(0.0, f64::max)
            })
            .collect();
        let mean_diff = exact
            .rgb
            .iter()
            .zip(&picture.rgb)
            .map(|(&a, &b)| (f64::from(a) - f64::from(b)).abs() / 255.0)
            .sum::<f64>()
            / exact.rgb.len().max(1) as f64;
        diffs.sort_by(f64::total_cmp);
        let p99_diff = diffs
            .get(((diffs.len() as f64 * 0.99) as usize).min(diffs.len().saturating_sub(1)))
            .copied()
            .unwrap_or(0.0);
        let row = Comparison {
            slices: n,
            ms,
            mean_diff,
            p99_diff,
            verdict_differs: verdict_differs(&exact_depth, &depth, 1e-9),
        };
        progress(&row);
        rows.push(row);
    }
    Ok(rows)
}

/// The share of covered pixels (finite in either) where the first visible surface differs:
/// where the distances to it (infinite where none) differ by more than `tolerance` of the
/// larger (or of 1).
pub fn verdict_differs(exact: &[f64], other: &[f64], tolerance: f64) -> f64 {
    let (mut covered, mut differs) = (0usize, 0usize);
    for (&a, &b) in exact.iter().zip(other) {
        if a.is_finite() || b.is_finite() {
            covered += 1;
            if !(a.is_finite() && b.is_finite() && (a - b).abs() <= tolerance * a.abs().max(1.0)) {
                differs += 1;
            }
        }
    }
    differs as f64 / covered.max(1) as f64
}

/// The rows as CSV, with a header.
pub fn to_csv(rows: &[Comparison]) -> String {
    let mut out = String::from("mode,slices,ms,mean_diff,p99_diff,verdict_differs\n");
    for r in rows {
        let mode = if r.slices == 0 { "exact" } else { "slices" };
        out.push_str(&format!(
            "{mode},{},{:.3},{:.6},{:.6},{:.6}\n",
            r.slices, r.ms, r.mean_diff, r.p99_diff, r.verdict_differs
        ));
    }
    out
}
