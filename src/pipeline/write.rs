//! A build's files: written under temporary names side by side, moved into place together,
//! with `report.json`.

use super::report::{PictureReport, Report, Timings, surface_report, surface_warnings};
use super::{Built, ms};
use crate::error::Error;
use crate::export::{self, SurfaceData};
use crate::progress::{Cancel, Cancelled, Job};
use crate::render;
use crate::scene::Scene;
use rayon::prelude::*;
use std::io::Write;
use std::path::Path;
use std::time::Instant;

/// Writes the outputs the scene asks for from its build ([`crate::Sampled::build`]) into
/// `out_dir`, and returns the report (also written as `report.json` when asked for). The
/// export time is added to the build's timings, and the total is the sum of the stages.
pub fn write(scene: &Scene, built: &Built, out_dir: &Path) -> Result<Report, Error> {
    write_with(scene, built, out_dir, Job::SILENT)
}

/// [`write()`], stopped once `job` is cancelled (its picture between rows, its files
/// before each is begun), with nothing written.
pub fn write_with(scene: &Scene, built: &Built, out_dir: &Path, job: Job) -> Result<Report, Error> {
    let (staged, report) = stage(scene, built, out_dir, job)?;
    finish(scene, staged, report, Timings::sum)
}

/// The report of a build that was not written (what [`write()`] reports, with no files and
/// no picture), as the Python package gives it.
pub fn report_of(scene: &Scene, built: &Built) -> Report {
    let mut report = assemble_report(scene, built, built.timings, None, built.failures(), vec![]);
    report.timings_ms.total = report.timings_ms.sum();
    report.memory.peak_gb = crate::memory::peak_resident().map(|b| b / crate::memory::GB);
    report
}

/// Writes every output but `report.json` under a temporary name (a failure leaves the
/// folder as it was, and so does `job` cancelled: each file is begun only while it is not),
/// and assembles the report, its total not yet set.
pub(super) fn stage(
    scene: &Scene,
    built: &Built,
    out_dir: &Path,
    job: Job,
) -> Result<(export::Staged, Report), Error> {
    let mut timings = built.timings;
    let export_start = Instant::now();
    let staged = export::Staged::new(out_dir).map_err(staged_error)?;
    let data: Vec<SurfaceData> = built.surfaces.iter().map(|p| p.data(&scene.halo)).collect();
    let failures = built.failures();
    let stipples = file_stipples(scene, built)?;
    let mut files = write_meshes(scene, built, &staged, &data, &stipples, &failures, job)?;
    let mut picture_report = None;
    if scene.outputs.png || scene.outputs.svg {
        let (picture, written) = write_picture(scene, built, &staged, &mut timings.render, job)?;
        files.extend(written);
        picture_report = Some(picture);
    }
    // The picture's files (its PNG encoded, its SVG) are the export's.
    timings.export = ms(export_start) - timings.render;
    if scene.outputs.report {
        files.push("report.json".into());
    }
    let report = assemble_report(scene, built, timings, picture_report, failures, files);
    job.check()?;
    Ok((staged, report))
}

/// Moves the staged files into place (its time added to the export's: replacing a former
/// build's files of hundreds of megabytes takes a noticeable part of a second), then sets
/// the report's peak memory and `total` (from its timings) and writes `report.json` last,
/// when asked for. The former `report.json` is removed first, so the folder never holds a
/// report beside files it does not describe.
pub(super) fn finish(
    scene: &Scene,
    staged: export::Staged,
    mut report: Report,
    total: impl FnOnce(&Timings) -> f64,
) -> Result<Report, Error> {
    let start = Instant::now();
    let last = scene.outputs.report.then_some("report.json");
    staged.move_into_place(last).map_err(staged_error)?;
    report.timings_ms.export += ms(start);
    report.memory.peak_gb = crate::memory::peak_resident().map(|b| b / crate::memory::GB);
    report.timings_ms.total = total(&report.timings_ms);
    if let Some(file) = last {
        let text = serde_json::to_vec_pretty(&report).map_err(|e| Error::Internal {
            stage: "export",
            message: e.to_string(),
        })?;
        staged.write(file.into(), &text).map_err(staged_error)?;
    }
    staged.commit().map_err(staged_error)?;
    Ok(report)
}

/// Writes the mesh files the scene asks for (`.glb`, `.html`, `.ply`, stipples, `.obj`,
/// `.4off`, `.vtk`), staged, from the surfaces' `data`, the `stipples` and the build's verdict
/// (`failures`); gives their names in the report's order.
fn write_meshes(
    scene: &Scene,
    built: &Built,
    staged: &export::Staged,
    data: &[SurfaceData],
    stipples: &[render::stipple::Drawn],
    failures: &[String],
    job: Job,
) -> Result<Vec<String>, Error> {
    let write = |file: String, bytes: &[u8]| -> Result<String, Error> {
        staged.write(file, bytes).map_err(staged_error)
    };
    let name = &scene.name;
    // The files are made on the cores side by side, each written as it is made (a halo's
    // `.vtk` streamed, the `.glb`'s chunks written as they are, with no copy of the whole
    // file in memory); the report lists them in this order.
    type Writer<'a> = Box<dyn FnOnce() -> Result<Vec<String>, Error> + Send + 'a>;
    // A file streamed (the `.glb`, the halos' `.vtk`: hundreds of megabytes at millions of
    // triangles) stops at its next write once the job is cancelled.
    let cancel = job.cancel();
    let mut jobs: Vec<Writer> = Vec::new();
    if scene.outputs.glb {
        jobs.push(Box::new(|| {
            let (text, bin) = glb_chunks(scene, built, data, stipples, failures)?;
            let file = staged
                .stream(format!("{name}.glb"), |w| {
                    export::write_glb_container(&mut Stoppable { out: w, cancel }, &text, &bin)
                })
                .map_err(staged_error)?;
            Ok(vec![file])
        }));
    }
    if scene.outputs.html {
        // The page holds the same bytes as the `.glb`, made again on a core of its own.
        jobs.push(Box::new(|| {
            let (text, bin) = glb_chunks(scene, built, data, stipples, failures)?;
            let glb = export::glb_container(text, bin);
            let file = staged
                .stream(format!("{name}.html"), |w| {
                    export::write_html(
                        &mut Stoppable { out: w, cancel },
                        name,
                        &glb,
                        scene.render.background,
                    )
                })
                .map_err(staged_error)?;
            Ok(vec![file])
        }));
    }
    if scene.outputs.ply {
        jobs.push(Box::new(|| {
            Ok(vec![
                write(format!("{name}.ply"), &export::to_ply(data, name))?,
                write(
                    format!("{name}-curves.ply"),
                    &export::to_curves_ply(built.shown_curves(), name),
                )?,
            ])
        }));
    }
    if scene.outputs.stipples {
        jobs.push(Box::new(|| {
            Ok(vec![write(
                format!("{name}-stipples.ply"),
                &export::to_stipples_ply(stipples, name),
            )?])
        }));
    }
    if scene.outputs.obj {
        jobs.push(Box::new(|| {
            Ok(vec![write(
                format!("{name}.obj"),
                export::to_obj(data, name).as_bytes(),
            )?])
        }));
    }
    if scene.outputs.off4 {
        for p in &built.surfaces {
            let file = per_surface(name, &p.name, data.len(), ".4off");
            jobs.push(Box::new(move || {
                let text = export::to_4off(&p.mesh.positions, &p.mesh.triangles, &p.name);
                Ok(vec![write(file, text.as_bytes())?])
            }));
        }
    }
    if scene.outputs.vtk {
        for d in data {
            let file = per_surface(name, d.name, data.len(), "-halo.vtk");
            jobs.push(Box::new(move || {
                let file = staged
                    .stream(file, |w| {
                        export::write_vtk(&mut Stoppable { out: w, cancel }, d, name)
                    })
                    .map_err(staged_error)?;
                Ok(vec![file])
            }));
        }
    }
    let written: Result<Vec<Vec<String>>, Error> = jobs
        .into_par_iter()
        .map(|writer| {
            job.check()?;
            writer()
        })
        .collect();
    // A file stopped by the token fails as cancelled, not as a write that failed.
    job.check()?;
    Ok(written?.into_iter().flatten().collect())
}

/// A writer that fails once `cancel` is cancelled, so that a file being streamed stops at
/// its next write (its partial file is removed with the build's others).
struct Stoppable<'a, 'w> {
    out: &'a mut (dyn Write + 'w),
    cancel: &'a Cancel,
}

impl Write for Stoppable<'_, '_> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        if self.cancel.is_cancelled() {
            return Err(std::io::Error::other(Cancelled));
        }
        self.out.write(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.out.flush()
    }
}

/// Renders the picture and writes it as `.png` and/or `.svg`, staged, with the render time
/// in `render_ms`: the picture's report and the files written.
fn write_picture(
    scene: &Scene,
    built: &Built,
    staged: &export::Staged,
    render_ms: &mut f64,
    job: Job,
) -> Result<(PictureReport, Vec<String>), Error> {
    let write = |file: String, bytes: &[u8]| -> Result<String, Error> {
        staged.write(file, bytes).map_err(staged_error)
    };
    let name = &scene.name;
    let mut files = Vec::new();
    let start = Instant::now();
    let rendered = render::render_for_build(
        &built.parts(&scene.halo),
        &scene.render,
        &scene.camera,
        scene.outputs.svg,
        job.cancel(),
    )
    .map_err(|source| Error::render(&scene.name, source))?;
    *render_ms = ms(start);
    if scene.outputs.png {
        files.push(write(format!("{name}.png"), &rendered.picture.png())?);
    }
    if let Some(svg) = &rendered.svg {
        files.push(write(format!("{name}.svg"), svg.as_bytes())?);
    }
    let picture = PictureReport {
        camera: rendered.camera,
        clip: scene.render.clip,
        rho: built.rho,
        gap_px: built.rho / built.pixel_size,
        curves: rendered.curves,
    };
    Ok((picture, files))
}

/// The build's report: the scene, each surface, the stages that ran, the curves and the
/// verification, the `timings`, the memory (its peak not yet measured), the warnings, the
/// `picture`, the verdict (`failures`) and the `files` written.
fn assemble_report(
    scene: &Scene,
    built: &Built,
    timings: Timings,
    picture: Option<PictureReport>,
    failures: Vec<String>,
    files: Vec<String>,
) -> Report {
    let products = &built.surfaces;
    Report {
        halo4d: env!("CARGO_PKG_VERSION"),
        scene_name: scene.name.clone(),
        surfaces: products
            .iter()
            .map(|p| surface_report(p, built.stages.halos))
            .collect(),
        stages: built.stages,
        curves: built
            .stages
            .curves
            .then(|| built.shown_curves().report.clone()),
        halo_verification: built.stages.verify.then(|| built.verification.clone()),
        timings_ms: timings,
        memory: built.memory,
        crowding: built.crowding.clone(),
        warnings: products
            .iter()
            .flat_map(|p| {
                let surface = surface_warnings(&p.name, &p.surface, &p.stats);
                p.sampling.warning(&p.name).into_iter().chain(surface)
            })
            .collect(),
        picture,
        verified: failures.is_empty(),
        failures,
        files,
        scene: scene.clone(),
    }
}

/// The file of one of a scene's `surfaces` surfaces: `<scene><ending>` when it has one,
/// `<scene>-<surface><ending>` when several.
fn per_surface(scene: &str, surface: &str, surfaces: usize, ending: &str) -> String {
    if surfaces == 1 {
        format!("{scene}{ending}")
    } else {
        format!("{scene}-{surface}{ending}")
    }
}

/// The stipples of the picture, for the files that carry them (`outputs.stipples`; none
/// otherwise).
fn file_stipples(scene: &Scene, built: &Built) -> Result<Vec<render::stipple::Drawn>, Error> {
    if !scene.outputs.stipples {
        return Ok(Vec::new());
    }
    render::stipples_drawn(&built.parts(&scene.halo), &scene.render, &scene.camera).map_err(
        |source| Error::Render {
            scene: scene.name.clone(),
            source,
        },
    )
}

/// The JSON and binary chunks of the scene's `.glb`: the surfaces, halos, shown curves and
/// `stipples`, with the scene and the build's verdict (`failures`) in the asset's extras.
fn glb_chunks(
    scene: &Scene,
    built: &Built,
    data: &[SurfaceData],
    stipples: &[render::stipple::Drawn],
    failures: &[String],
) -> Result<(Vec<u8>, Vec<u8>), Error> {
    let internal = |message: String| Error::Internal {
        stage: "export",
        message,
    };
    let scene_json = serde_json::to_value(scene).map_err(|e| internal(e.to_string()))?;
    let asset = serde_json::json!({
        "scene": scene_json,
        "verified": failures.is_empty(),
        "failures": failures,
    });
    export::glb_chunks(
        data,
        built.shown_curves(),
        scene.outputs.curve_radius * built.diagonal,
        stipples,
        &figure(scene, built),
        &asset,
    )
    .map_err(internal)
}

/// What the `.glb` carries of the scene's picture: its colour map and its camera (none when
/// the picture has none: no triangle to frame, or an orthographic eye inside the box, which
/// the picture itself reports as an error when there is one).
fn figure(scene: &Scene, built: &Built) -> export::Figure {
    let parts = built.parts(&scene.halo);
    let surfaces = parts.surfaces.iter().map(|s| (s.positions, s.triangles));
    export::Figure {
        camera: render::picture_camera(surfaces, &scene.render, &scene.camera).ok(),
        colormap: scene.render.colormap,
    }
}

/// The bytes of the `.glb` a build of `scene` writes (with its stipples when
/// `outputs.stipples`), for a file written on its own.
pub fn glb_bytes(scene: &Scene, built: &Built) -> Result<Vec<u8>, Error> {
    let stipples = file_stipples(scene, built)?;
    let data: Vec<SurfaceData> = built.surfaces.iter().map(|p| p.data(&scene.halo)).collect();
    let (text, bin) = glb_chunks(scene, built, &data, &stipples, &built.failures())?;
    let mut out = Vec::new();
    export::write_glb_container(&mut out, &text, &bin).map_err(|e| Error::Internal {
        stage: "export",
        message: e.to_string(),
    })?;
    Ok(out)
}

/// A [`export::StagedError`] as the pipeline's error.
pub(crate) fn staged_error(e: export::StagedError) -> Error {
    match e {
        export::StagedError::Io { path, source } => Error::Write { path, source },
        busy => Error::Busy(busy),
    }
}
