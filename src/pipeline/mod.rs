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
pub use write::{glb_bytes, report_of, write, write_with};

use crate::error::Error;
use crate::export;
use crate::progress::Job;
use crate::render::{self, Picture, RenderError, Style};
use crate::scene::Scene;
use built::in_view;
use sampled::sample_with;
use serde::Serialize;
use std::path::Path;
use std::time::Instant;

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
/// picture and the milliseconds the rendering took. Reports to `job` and stops when it is
/// cancelled.
pub fn render_to(scene: &Scene, out: &Path, job: Job) -> Result<(Picture, f64), Error> {
    let render_error = |source| Error::render(&scene.name, source);
    // The settings first: a bad one stops the command before the build.
    (scene.render.check()).map_err(|e| render_error(RenderError::Setting(e.within("render"))))?;
    let (built, picture, took) =
        run_stages(scene, Stages::picture(scene), job, "the picture", |built| {
            let start = Instant::now();
            let picture = render::render_until(
                &built.parts(&scene.halo),
                &scene.render,
                &scene.camera,
                job.cancel(),
            )
            .map_err(render_error)?;
            Ok((built, picture, ms(start)))
        })?;
    if scene.render.style == Style::Stipple {
        let parts = built.parts(&scene.halo);
        let drawn =
            render::stipples_drawn(&parts, &scene.render, &scene.camera).map_err(render_error)?;
        let saturated = drawn.iter().filter(|d| d.saturated).count();
        if saturated * 100 > drawn.len() {
            job.warn(&format!(
                "{saturated} of {} stipples are where the tone asks for more than render.stipple.count = {} ranks; those places are drawn lighter: raise the count (about 0.6 per pixel of the picture: {})",
                drawn.len(),
                scene.render.stipple.count,
                (0.6 * f64::from(scene.render.width) * f64::from(scene.render.height)).ceil()
            ));
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

/// The stages `stages` of a build of `scene`, then `finish` (the files, the picture) with
/// the task at its last step and `last` as what it is doing: a task `"build"` of `job`.
fn run_stages<T>(
    scene: &Scene,
    stages: Stages,
    job: Job,
    last: &str,
    finish: impl FnOnce(Built) -> Result<T, Error>,
) -> Result<T, Error> {
    let task = job.task("build", (scene.surfaces.len() * 3 + 3) as u64);
    let samples = sample_with(scene, &task)?;
    let built = in_view(scene, samples, stages, &task)?;
    task.at_last();
    task.doing(last);
    finish(built)
}

/// Builds a scene into `out_dir`: runs the stages and writes the outputs the scene asks for,
/// reporting to `job` and stopping, with nothing written, when it is cancelled.
pub fn build(scene: &Scene, out_dir: &Path, job: Job) -> Result<Report, Error> {
    build_since(scene, out_dir, job, Instant::now())
}

/// [`build`], for a program that started its work (reading the scene, finding its view)
/// at `started`: the report's `setup` is the time until the build, and its `total` the wall
/// time from `started` to `report.json` written. The build's memory is freed before the
/// report is written, and its time is the report's `free`.
pub fn build_since(
    scene: &Scene,
    out_dir: &Path,
    job: Job,
    started: Instant,
) -> Result<Report, Error> {
    let setup = ms(started);
    let last = if scene.outputs.png || scene.outputs.svg {
        "the picture and the files"
    } else {
        "the files"
    };
    run_stages(scene, Stages::of(scene), job, last, |mut built| {
        built.timings.setup = setup;
        let (staged, mut report) = write::stage(scene, &built, out_dir, job)?;
        let start = Instant::now();
        drop(built);
        report.timings_ms.free = ms(start);
        write::finish(scene, staged, report, |_| ms(started))
    })
}
