//! The build: runs the stages a scene needs and writes its outputs.
//!
//! scene -> surfaces -> sample -> view -> halos, curves, verification -> files. Sample once
//! ([`Sampled::of`], `sampled`), build any view from the samples ([`Sampled::build`], `built`:
//! each stage hands a plain value to the next and is timed), write what the scene asks for
//! ([`write`], `write`); [`Report`] (`report`) collects counts, bounds, mesh statistics and
//! timings.

mod built;
mod hold;
pub mod report;
mod sampled;
mod work;
mod write;

pub use built::{Built, SurfaceProduct};
pub use report::{Report, Timings};
pub use sampled::{Sampled, shown_curves};
pub(crate) use write::staged_error;
pub use write::{glb_bytes, report_of, write};

use crate::error::Error;
use crate::export;
use crate::render::{self, Picture, RenderError, Style};
use crate::scene::Scene;
use built::in_view;
use indicatif::{ProgressBar, ProgressStyle};
use sampled::sample_with;
use serde::Serialize;
use std::io::IsTerminal;
use std::path::Path;
use std::time::{Duration, Instant};

/// Which stages after the projection a build runs: those whose products an output the
/// scene asks for uses (`report.json`'s `stages`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Stages {
    /// Halos: for `glb`, `vtk`, a `png` whose `render.halos` is on, and the verification.
    pub halos: bool,
    /// Intersection curves: for `glb`, `ply` (`-curves.ply`), a `png` whose
    /// `render.curves` is on, and the verification.
    pub curves: bool,
    /// The halos checked against the curves: whenever a halo file is written, and where
    /// `outputs.verify` asks for it.
    pub verify: bool,
    /// Stipples on the 4D meshes: for a picture in `render.style` `stipple` and for
    /// `outputs.stipples`.
    pub stipples: bool,
}

impl Stages {
    /// The stages `scene`'s outputs need.
    pub fn of(scene: &Scene) -> Stages {
        Stages::with_picture(scene, scene.outputs.png || scene.outputs.svg)
    }

    /// The stages `scene`'s picture needs besides those of its files, whatever the scene
    /// says of `png`: what `halo4d render` and `halo4d sweep --render` draw from.
    pub fn picture(scene: &Scene) -> Stages {
        Stages::with_picture(scene, true)
    }

    /// Every stage of a verified build with its picture, whatever files the scene writes:
    /// an animation's frame.
    pub fn verified_picture(scene: &Scene) -> Stages {
        Stages {
            halos: true,
            curves: true,
            verify: true,
            ..Stages::with_picture(scene, true)
        }
    }

    /// The stages `scene`'s outputs need, with a picture's when `picture` whatever the scene
    /// says of `png`.
    fn with_picture(scene: &Scene, picture: bool) -> Stages {
        let o = &scene.outputs;
        let verify = o.verify.unwrap_or(o.glb || o.vtk);
        Stages {
            halos: verify || o.glb || o.vtk || (picture && scene.render.halos),
            curves: verify || o.glb || o.ply || (picture && scene.render.curves),
            verify,
            stipples: o.stipples || (picture && scene.render.style == Style::Stipple),
        }
    }
}

/// Renders the scene's picture (the stages it needs, then its `render` and `camera`) and
/// writes it to `out` as PNG, whole or not at all, making its folder when missing. Gives the
/// picture and the milliseconds the rendering took.
pub fn render_to(scene: &Scene, out: &Path, quiet: bool) -> Result<(Picture, f64), Error> {
    let render_error = |source| Error::Render {
        scene: scene.name.clone(),
        source,
    };
    // The settings first: a bad one stops the command before the build.
    (scene.render.check()).map_err(|e| render_error(RenderError::Setting(e.within("render"))))?;
    let (built, picture, took) = run_stages(
        scene,
        Stages::picture(scene),
        quiet,
        "the picture",
        |built| {
            let start = Instant::now();
            let picture = built
                .render(&scene.halo, &scene.render, &scene.camera)
                .map_err(render_error)?;
            Ok((built, picture, ms(start)))
        },
    )?;
    if scene.render.style == Style::Stipple {
        let parts = built.parts(&scene.halo);
        let drawn =
            render::stipples_drawn(&parts, &scene.render, &scene.camera).map_err(render_error)?;
        let saturated = drawn.iter().filter(|d| d.saturated).count();
        if saturated * 100 > drawn.len() {
            eprintln!(
                "warning: {saturated} of {} stipples are where the tone asks for more than render.stipple.count = {} ranks; those places are drawn lighter: raise the count (about 0.6 per pixel of the picture: {})",
                drawn.len(),
                scene.render.stipple.count,
                (0.6 * f64::from(scene.render.width) * f64::from(scene.render.height)).ceil()
            );
        }
    }
    let write_error = |path: &Path| {
        let path = path.to_path_buf();
        move |source| Error::Write { path, source }
    };
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(write_error(dir))?;
    }
    export::write_atomic(out, &picture.png()).map_err(write_error(out))?;
    Ok((picture, took))
}

fn ms(since: Instant) -> f64 {
    since.elapsed().as_secs_f64() * 1e3
}

/// A progress bar on stderr (hidden when stderr is not a terminal or `quiet`).
fn progress(len: usize, quiet: bool) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(len as u64);
    bar.set_style(
        ProgressStyle::with_template("{spinner} [{elapsed_precise}] {bar:30} {pos}/{len} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    // Redrawn on its own: a stage of many seconds (sampling a fine tolerance, the halos of
    // a million triangles) shows its time passing, never a frozen line.
    bar.enable_steady_tick(Duration::from_millis(250));
    if !std::io::stderr().is_terminal() {
        heartbeat(bar.clone());
    }
    bar
}

/// Where stderr is not a terminal (a log, a pipe), indicatif draws nothing: a line every
/// [`HEARTBEAT`] with the stage and the time, until the bar finishes, so that a long build
/// never sits silent in a log.
fn heartbeat(bar: ProgressBar) {
    std::thread::spawn(move || {
        let start = Instant::now();
        let mut next = HEARTBEAT;
        while !bar.is_finished() {
            std::thread::sleep(Duration::from_millis(100));
            if start.elapsed() >= next {
                eprintln!(
                    "halo4d: {:.0} s, stage {}/{}: {}",
                    start.elapsed().as_secs_f64(),
                    bar.position(),
                    bar.length().unwrap_or(0),
                    bar.message()
                );
                next += HEARTBEAT;
            }
        }
    });
}

/// How often a build whose stderr is not a terminal says what it is doing.
const HEARTBEAT: Duration = Duration::from_secs(10);

/// The stages `stages` of a build of `scene`, then `finish` (the files, the picture) with
/// the bar at its last step and `last` as its message; with a progress bar unless `quiet`.
fn run_stages<T>(
    scene: &Scene,
    stages: Stages,
    quiet: bool,
    last: &str,
    finish: impl FnOnce(Built) -> Result<T, Error>,
) -> Result<T, Error> {
    let bar = progress(scene.surfaces.len() * 3 + 3, quiet);
    let samples = sample_with(scene, &bar);
    let done = in_view(scene, samples, stages, &bar).and_then(|built| {
        bar.set_position(bar.length().unwrap_or(1) - 1);
        bar.set_message(last.to_string());
        finish(built)
    });
    bar.finish_and_clear();
    done
}

/// Builds a scene into `out_dir`: runs the stages and writes the outputs the scene asks for.
pub fn build(scene: &Scene, out_dir: &Path, quiet: bool) -> Result<Report, Error> {
    build_since(scene, out_dir, quiet, Instant::now())
}

/// [`build`], for a program that started its work (reading the scene, finding its view)
/// at `started`: the report's `setup` is the time until the build, and its `total` the wall
/// time from `started` to `report.json` written. The build's memory is freed before the
/// report is written, and its time is the report's `free`.
pub fn build_since(
    scene: &Scene,
    out_dir: &Path,
    quiet: bool,
    started: Instant,
) -> Result<Report, Error> {
    let setup = ms(started);
    let last = if scene.outputs.png || scene.outputs.svg {
        "the picture and the files"
    } else {
        "the files"
    };
    run_stages(scene, Stages::of(scene), quiet, last, |mut built| {
        built.timings.setup = setup;
        let (staged, mut report) = write::stage(scene, &built, out_dir)?;
        let start = Instant::now();
        drop(built);
        report.timings_ms.free = ms(start);
        write::finish(scene, staged, report, |_| ms(started))
    })
}
