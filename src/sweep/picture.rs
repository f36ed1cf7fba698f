//! The picture's speed against error: the multi-slice mode against the exact one.

use super::{SweepError, plot, write_files};
use crate::limits::SLICES;
use crate::pipeline::{Sampled, Stages};
use crate::render::compare::{self, Comparison};
use crate::scene::Scene;
use std::path::{Path, PathBuf};

/// Builds `scene` (the stages its picture needs), renders it in the exact mode and with
/// each of `slices` (the exact render and each slice count, as `halo4d sweep --render` prints them), and writes `render_speed_vs_error.csv` and
/// `render_speed_vs_error.png` into `out_dir`. `progress` hears of each render. Gives the
/// rows and the paths written.
pub fn picture_sweep(
    scene: &Scene,
    slices: &[u32],
    out_dir: &Path,
    progress: &mut dyn FnMut(&Comparison),
) -> Result<(Vec<Comparison>, Vec<PathBuf>), SweepError> {
    for (i, &n) in slices.iter().enumerate() {
        SLICES.check(&format!("slices[{i}]"), n)?;
    }
    let built = Sampled::of(scene).into_built(scene, Stages::picture(scene))?;
    let rows = compare::compare(
        &built.parts(&scene.halo),
        &scene.render,
        &scene.camera,
        slices,
        progress,
    )?;
    let title = format!(
        "{}: multi-slice halos against the exact mode, {} x {}",
        scene.name, scene.render.width, scene.render.height
    );
    let png = plot::render_speed_vs_error_png(&rows, &title)?;
    let written = write_files(
        out_dir,
        [
            (
                "render_speed_vs_error.csv",
                compare::to_csv(&rows).into_bytes(),
            ),
            ("render_speed_vs_error.png", png),
        ],
    )?;
    Ok((rows, written))
}
