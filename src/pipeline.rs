//! The build: runs the stages a scene needs and writes its outputs.
//!
//! scene -> surfaces -> sample -> view -> export. Each stage hands a plain value to the
//! next and is timed; [`Report`] collects counts, bounds, mesh statistics and timings.

use crate::error::Error;
use crate::export::{self, SurfaceData};
use crate::halo::{Halo, HaloParams, HaloReport, build_halo};
use crate::intersect::{self, Curves, CurvesReport, Sheet};
use crate::limits::{MAX_COORDINATE, MIN_EXTENT};
use crate::parts::{HaloPart, Parts, SurfacePart};
use crate::render::{self, CameraSettings, Picture, RenderError, RenderSettings, Style};
use crate::sample::{self, Audit, Mesh4, MeshStats, Sampling, Source, audit};
use crate::scene::Scene;
use crate::stipple::Stipples;
use crate::surfaces::Topology;
use crate::verify::{self, Verification};
use crate::view::Projected;
use glam::DVec3;
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use serde::Serialize;
use std::path::Path;
use std::time::Instant;

/// One surface after sampling and projection.
#[derive(Clone, Debug)]
pub struct SurfaceProduct {
    /// Name in the outputs.
    pub name: String,
    /// The surface.
    pub surface: Source,
    /// Its 4D mesh.
    pub mesh: Mesh4,
    /// The mesh's statistics.
    pub stats: MeshStats,
    /// How it was sampled and how far it is from the surface.
    pub sampling: SamplingReport,
    /// Its 3D projection.
    pub projected: Projected,
    /// Its halo and what the checker said of it.
    pub halo: Halo,
    /// The halo's report.
    pub halo_report: HaloReport,
    /// Its stipples, made from the 4D mesh when the stipple style or a stipple file asks.
    pub stipples: Option<Stipples>,
}

/// Everything a build computes before writing.
#[derive(Clone, Debug)]
pub struct Built {
    /// Per surface.
    pub surfaces: Vec<SurfaceProduct>,
    /// The intersection curves of all surfaces together, exact for the meshes: what the
    /// halos are verified against.
    pub curves: Curves,
    /// The same curves moved onto the analytic surfaces (`curves.refine`), when made.
    pub refined: Option<Curves>,
    /// The halos checked against the curves.
    pub verification: Verification,
    /// Milliseconds per stage so far.
    pub timings: Timings,
    /// The diagonal of the projected scene's bounding box, of which `halo.rho` and
    /// `outputs.curve_radius` are shares, at least [`MIN_EXTENT`].
    pub diagonal: f64,
    /// The side of a pixel of the scene's picture at the depth its camera looks at, in
    /// scene units, of which `halo.gap_px` is a multiple.
    pub pixel_size: f64,
    /// The halos' half-width asked for, in scene units (less where a halo was shrunk).
    pub rho: f64,
    /// The memory the stages from the halos on were estimated to need, and the limit.
    pub memory: MemoryReport,
    /// Which stages after the projection ran.
    pub stages: Stages,
}

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

/// `report.json`'s `memory`: what the stages from the halos on were estimated to need (1100
/// bytes per triangle) against the limit (`HALO4D_MAX_MEMORY` gigabytes, or three quarters
/// of the machine's memory), in GB. The picture is estimated on its own when it is made.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct MemoryReport {
    /// Estimated peak of the stages from the halos on.
    pub estimate_gb: f64,
    /// The limit a build refuses to go beyond.
    pub limit_gb: f64,
    /// The process's peak resident memory when the files were made (null where the system
    /// does not say).
    pub peak_gb: Option<f64>,
}

impl Built {
    /// The build's verdict: what keeps it from being verified, empty when it is. Of the
    /// stages that ran: every surface has a halo that passes the checker
    /// ([`crate::check::CheckStats::passes`]), every curve is resolved, and the halos'
    /// verification found no wrong curve sample and no spurious hidden surface sample.
    pub fn failures(&self) -> Vec<String> {
        let mut out = Vec::new();
        for p in self.surfaces.iter().filter(|_| self.stages.halos) {
            if p.halo.tets.is_empty() {
                out.push(format!("{}: no halo (no tetrahedron)", p.name));
            } else {
                out.extend(p.halo_report.check.verdict(&format!("{}-halo", p.name)));
            }
        }
        out.extend(self.curves.report.failures());
        out.extend(self.verification.failures());
        out
    }

    /// The curves the files and the picture show: the refined ones when made, else the
    /// mesh's.
    pub fn shown_curves(&self) -> &Curves {
        self.refined.as_ref().unwrap_or(&self.curves)
    }

    /// What the build produced, as the renderer and the viewer read it, with the curves
    /// the files show; `halo` are the scene's halo parameters.
    pub fn parts<'a>(&'a self, halo: &HaloParams) -> Parts<'a> {
        parts(&self.surfaces, halo, self.shown_curves())
    }

    /// [`Built::parts`] with the mesh's curves, which the halos are verified against.
    pub fn verified_parts<'a>(&'a self, halo: &HaloParams) -> Parts<'a> {
        parts(&self.surfaces, halo, &self.curves)
    }

    /// The picture of the given settings (the scene's `render` and `camera`, usually).
    pub fn render(
        &self,
        halo: &HaloParams,
        settings: &RenderSettings,
        camera: &CameraSettings,
    ) -> Result<Picture, RenderError> {
        render::render(&self.parts(halo), settings, camera)
    }
}

/// The one place a build's products become the hand-off.
fn parts<'a>(surfaces: &'a [SurfaceProduct], halo: &HaloParams, curves: &'a Curves) -> Parts<'a> {
    Parts {
        surfaces: surfaces
            .iter()
            .map(|p| SurfacePart {
                positions: &p.projected.positions,
                w: &p.projected.w,
                normals: &p.projected.normals,
                // A mesh file's vertices have no parameters.
                uv: p.surface.parametric().map(|_| p.mesh.uv.as_slice()),
                triangles: &p.mesh.triangles,
                stipples: p.stipples.as_ref(),
            })
            .collect(),
        halos: surfaces
            .iter()
            .map(|p| {
                (!p.halo.tets.is_empty()).then_some(HaloPart {
                    positions: &p.halo.positions,
                    t: &p.halo.t,
                    d_orig: &p.halo.d_orig,
                    tets: &p.halo.tets,
                    surface_vertices: p.halo.surface_vertices,
                    delta_d: halo.delta_d,
                    delta_t: halo.delta_t,
                })
            })
            .collect(),
        curves,
    }
}

/// How a surface was sampled, and the audit of the mesh (`report.json`'s `sampling`).
#[derive(Clone, Debug, Serialize)]
pub struct SamplingReport {
    /// `adaptive`, `uniform`, or `file` for a mesh read from a file (not sampled, not
    /// audited: the mesh is the surface, its errors are 0).
    pub method: &'static str,
    /// The absolute tolerance the adaptive sampler aimed at.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tolerance: Option<f64>,
    /// The same, relative to `diagonal`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub relative_tolerance: Option<f64>,
    /// The adaptive sampler's triangle budget.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_triangles: Option<usize>,
    /// Diagonal of the surface's 4D bounding box, the length relative values refer to.
    pub diagonal: f64,
    /// Triangles.
    pub triangles: usize,
    /// Vertices.
    pub vertices: usize,
    /// Audited largest distance, triangle to surface, in R^4.
    pub max_error: f64,
    /// Audited root mean square distance.
    pub rms_error: f64,
    /// `max_error / diagonal`.
    pub max_error_relative: f64,
    /// `rms_error / diagonal`.
    pub rms_error_relative: f64,
    /// Whether the sampler met its tolerance everywhere (false when its triangle budget
    /// stopped it).
    pub complete: bool,
    /// When the budget stopped adaptive sampling: the audited max error of a uniform grid
    /// of about as many triangles ([`sample::uniform_error`]), to compare `max_error` with.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub uniform_max_error: Option<f64>,
    /// Milliseconds spent sampling.
    pub ms: f64,
    /// Milliseconds spent auditing (with the uniform grid of `uniform_max_error`).
    pub audit_ms: f64,
}

impl SamplingReport {
    fn new(
        method: &'static str,
        sampling: &Sampling,
        sampled: &sample::Sampled,
        audit: &Audit,
        uniform_max_error: Option<f64>,
        ms: f64,
        audit_ms: f64,
    ) -> Self {
        let (max_rel, rms_rel) = audit.relative(sampled.diagonal);
        SamplingReport {
            method,
            max_triangles: match *sampling {
                Sampling::Adaptive { max_triangles, .. } if method == "adaptive" => {
                    Some(max_triangles)
                }
                _ => None,
            },
            tolerance: sampled.tolerance,
            relative_tolerance: sampled.tolerance.map(|t| t / sampled.diagonal),
            diagonal: sampled.diagonal,
            triangles: sampled.mesh.triangles.len(),
            vertices: sampled.mesh.vertex_count(),
            max_error: audit.max_error,
            rms_error: audit.rms_error,
            max_error_relative: max_rel,
            rms_error_relative: rms_rel,
            complete: sampled.complete,
            uniform_max_error,
            ms,
            audit_ms,
        }
    }

    /// The warning a build prints when the sampler stopped short of its tolerance.
    pub fn warning(&self, surface: &str) -> Option<String> {
        if self.complete {
            return None;
        }
        Some(format!(
            "surface `{surface}`: the triangle budget (max_triangles = {}) stopped refinement at {} triangles before every triangle met the tolerance {:.3e}; the audited max error is {:.3e} ({:.3e} of the diagonal; a uniform grid of as many triangles: {:.3e}). Raise max_triangles or the tolerance.",
            self.max_triangles.unwrap_or(0),
            self.triangles,
            self.tolerance.unwrap_or(f64::NAN),
            self.max_error,
            self.max_error_relative,
            self.uniform_max_error.unwrap_or(f64::NAN),
        ))
    }
}

/// The warning a build prints for a mesh file that is not a manifold (the sampler's meshes
/// always are): what the halos and curves meet there is what the file gives.
fn mesh_file_warning(surface: &str, source: &Source, stats: &MeshStats) -> Option<String> {
    if !matches!(source, Source::Mesh(_)) || stats.is_manifold() {
        return None;
    }
    Some(format!(
        "surface `{surface}`: the mesh file is not a manifold: {} edges in more than two triangles, {} triangles of zero area; halos and curves follow the triangles as they are, and verification may call samples there ambiguous",
        stats.non_manifold_edges, stats.degenerate_triangles
    ))
}

impl SurfaceProduct {
    /// The view the writers take; `halo_params` are the scene's.
    pub fn data<'a>(&'a self, halo_params: &'a HaloParams) -> SurfaceData<'a> {
        SurfaceData {
            name: &self.name,
            surface_type: self.surface.type_name(),
            patches: self.surface.patch_count(),
            mesh: &self.mesh,
            projected: &self.projected,
            halo: &self.halo,
            halo_params,
            rho: self.halo_report.rho,
        }
    }
}

/// Milliseconds spent in each stage.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, serde::Deserialize)]
pub struct Timings {
    /// Sampling, all surfaces.
    pub sample: f64,
    /// Auditing the samples, all surfaces.
    pub audit: f64,
    /// View (rotation, projection, normals), all surfaces.
    pub view: f64,
    /// Halos: thickening, tetrahedra, checking, all surfaces.
    pub halo: f64,
    /// Intersection curves, all surfaces together.
    pub curves: f64,
    /// Moving the curves onto the analytic surfaces.
    pub refine: f64,
    /// Verifying the halos against the curves.
    pub verify: f64,
    /// Ranking the stipples, all surfaces.
    pub stipples: f64,
    /// Rendering the picture.
    pub render: f64,
    /// Writing the outputs.
    pub export: f64,
    /// Sum of the stages.
    pub total: f64,
}

/// Bounding box.
#[derive(Clone, Debug, Serialize)]
pub struct Bounds {
    /// Lower corner.
    pub min: Vec<f64>,
    /// Upper corner.
    pub max: Vec<f64>,
}

/// What the report says of one surface.
#[derive(Clone, Debug, Serialize)]
pub struct SurfaceReport {
    /// Mesh name.
    pub name: String,
    /// Catalogue type.
    #[serde(rename = "type")]
    pub type_name: String,
    /// Parameter patches.
    pub patches: usize,
    /// Sampling and its audit.
    pub sampling: SamplingReport,
    /// Vertices.
    pub vertices: usize,
    /// Triangles.
    pub triangles: usize,
    /// Expected topology.
    pub topology: Topology,
    /// Measured combinatorics.
    pub mesh: MeshStats,
    /// Bounding box in R^4 before the view.
    pub bounds_4d: Option<Bounds>,
    /// Bounding box of the projection.
    pub bounds_3d: Option<Bounds>,
    /// Range of w-depth after the view.
    pub w_range: Option<[f64; 2]>,
    /// The halo (null when no output needs one).
    pub halo: Option<HaloReport>,
    /// Stipples ranked on the 4D mesh (absent when none were made).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stipples: Option<usize>,
}

/// `report.json`'s `picture`: how to reproduce the picture's projection, the halos' width in
/// it, and the share of the curves it shows ([`render::visible`]).
#[derive(Clone, Debug, Serialize)]
pub struct PictureReport {
    /// The camera, in the projected scene's coordinates.
    #[serde(flatten)]
    pub camera: render::visible::PictureCamera,
    /// The cutaway (`render.clip`), when set: the points where `normal · p > offset` holds
    /// for every plane are removed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub clip: Option<render::clip::Clip>,
    /// The halos' half-width asked for, in scene units.
    pub rho: f64,
    /// The same in pixels at the depth the camera looks at.
    pub gap_px: f64,
    /// The curves' projected length and the share of it in view.
    #[serde(flatten)]
    pub curves: render::visible::CurveVisibility,
}

/// `report.json`.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    /// Version of halo4d that wrote it.
    pub halo4d: &'static str,
    /// Scene name.
    pub scene_name: String,
    /// Per surface.
    pub surfaces: Vec<SurfaceReport>,
    /// Which stages after the projection ran (those the outputs need).
    pub stages: Stages,
    /// The intersection curves of all surfaces together (null when not computed).
    pub curves: Option<CurvesReport>,
    /// The halos checked against the curves (null when not verified).
    pub halo_verification: Option<Verification>,
    /// Milliseconds per stage.
    pub timings_ms: Timings,
    /// Memory estimated before the halos, against the limit.
    pub memory: MemoryReport,
    /// Warnings, also printed on stderr.
    pub warnings: Vec<String>,
    /// The picture: its camera, halo width and how much of the curves it shows (absent when
    /// no picture was drawn).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub picture: Option<PictureReport>,
    /// Whether the build is verified: [`Built::failures`] found nothing in the stages that
    /// ran.
    pub verified: bool,
    /// What [`Built::failures`] found.
    pub failures: Vec<String>,
    /// Files written, relative to the output folder.
    pub files: Vec<String>,
    /// The scene as parsed, with every default filled in.
    pub scene: Scene,
}

impl Report {
    /// What `halo4d build` prints on stderr: per surface its mesh, the curves, the halo
    /// verification, the timings and the memory, one line each.
    pub fn summary(&self) -> String {
        let mut out = String::new();
        for s in &self.surfaces {
            out += &format!(
                "{:<24} {:>9} vertices {:>9} triangles  Euler characteristic {}\n",
                s.name, s.vertices, s.triangles, s.mesh.euler_characteristic
            );
        }
        match &self.curves {
            Some(c) => out += &format!("{}\n", c.summary()),
            None => out += "curves: not computed (no output uses them)\n",
        }
        match &self.halo_verification {
            Some(v) => {
                out += &format!(
                    "halo verification: {} curve samples: {} correct, {} wrong, {} ambiguous, {} third sheet; {} surface samples, {} far tetrahedra, {} spurious\n",
                    v.curve_samples,
                    v.correct,
                    v.wrong,
                    v.ambiguous,
                    v.third_sheet,
                    v.surface_samples,
                    v.far_tetrahedra,
                    v.spurious_hidden_samples
                )
            }
            None => {
                out += "halo verification: not run (no halo file written; `outputs.verify: true` asks for it)\n"
            }
        }
        let t = self.timings_ms;
        out += &format!(
            "sample {:.1} ms, audit {:.1} ms, view {:.1} ms, halo {:.1} ms, curves {:.1} ms, refine {:.1} ms, verify {:.1} ms, export {:.1} ms, render {:.1} ms, total {:.1} ms\n",
            t.sample,
            t.audit,
            t.view,
            t.halo,
            t.curves,
            t.refine,
            t.verify,
            t.export,
            t.render,
            t.total
        );
        out += &format!(
            "memory: about {:.2} GB estimated from the halos on, limit {:.2} GB{}\n",
            self.memory.estimate_gb,
            self.memory.limit_gb,
            self.memory
                .peak_gb
                .map(|gb| format!(", peak {gb:.2} GB"))
                .unwrap_or_default()
        );
        out
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
    let built = run_for_picture(scene, quiet)?;
    let start = Instant::now();
    let picture = built
        .render(&scene.halo, &scene.render, &scene.camera)
        .map_err(render_error)?;
    let took = ms(start);
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
    bar
}

/// Samples, projects and thickens every surface of the scene, finds the intersection
/// curves and verifies the halos against them: the stages its outputs need ([`Stages::of`]).
pub fn run(scene: &Scene, quiet: bool) -> Result<Built, Error> {
    run_stages(scene, Stages::of(scene), quiet)
}

/// [`run`] with the stages a picture of the scene needs too, whatever files the scene
/// writes: what `halo4d render` and `halo4d sweep --render` draw from.
pub fn run_for_picture(scene: &Scene, quiet: bool) -> Result<Built, Error> {
    run_stages(scene, Stages::with_picture(scene, true), quiet)
}

fn run_stages(scene: &Scene, stages: Stages, quiet: bool) -> Result<Built, Error> {
    let bar = progress(scene.surfaces.len() * 3 + 2, quiet);
    let samples = sample_with(scene, &bar);
    let built = in_view(scene, samples, stages, &bar);
    bar.finish_and_clear();
    built
}

/// A scene's surfaces sampled (or read from their files) and audited: what a build makes
/// before the view, which does not depend on the view. Sample once ([`Sampled::of`]), then
/// build any number of views ([`Sampled::build`]): what an animation does for its frames,
/// and what the explorer turns ([`shown_curves`] gives it the curves a build shows).
#[derive(Clone, Debug)]
pub struct Sampled {
    surfaces: Vec<Sample>,
    /// The sampling and audit times (the other stages 0).
    timings: Timings,
}

#[derive(Clone, Debug)]
struct Sample {
    name: String,
    mesh: Mesh4,
    stats: MeshStats,
    report: SamplingReport,
}

impl Sampled {
    /// Samples (or reads) and audits every surface of the scene, printing the warnings a
    /// build prints.
    pub fn of(scene: &Scene) -> Sampled {
        sample_with(scene, &ProgressBar::hidden())
    }

    /// The build of `scene` from these samples (of a scene with the same surfaces and
    /// sampling) in its view: the stages `stages` asks for ([`Stages::of`] for what its
    /// outputs need); the sampling times are these samples'.
    pub fn build(&self, scene: &Scene, stages: Stages) -> Result<Built, Error> {
        self.clone().into_built(scene, stages)
    }

    /// [`Sampled::build`], the samples moved into the build.
    pub fn into_built(self, scene: &Scene, stages: Stages) -> Result<Built, Error> {
        in_view(scene, self, stages, &ProgressBar::hidden())
    }

    /// Each surface's name and 4D mesh, in the scene's order.
    pub fn meshes(&self) -> impl Iterator<Item = (&str, &Mesh4)> {
        self.surfaces.iter().map(|s| (s.name.as_str(), &s.mesh))
    }

    /// Each surface's name and 4D mesh, moved out.
    pub fn into_meshes(self) -> Vec<(String, Mesh4)> {
        self.surfaces
            .into_iter()
            .map(|s| (s.name, s.mesh))
            .collect()
    }

    /// Triangles of all surfaces.
    pub fn triangles(&self) -> usize {
        self.surfaces.iter().map(|s| s.mesh.triangles.len()).sum()
    }

    /// Milliseconds spent sampling and auditing.
    pub fn ms(&self) -> f64 {
        self.timings.sample + self.timings.audit
    }
}

/// The curves a build of `scene` shows from its surfaces' 4D meshes (one per surface, in
/// the scene's order): each mesh projected as the build projects it, the exact curves of
/// the sheets, and those refined onto the analytic surfaces when `scene.curves.refine`.
pub fn shown_curves(scene: &Scene, meshes: &[&Mesh4]) -> Result<Curves, Error> {
    if scene.view.auto {
        return Err(Error::UnresolvedView {
            scene: scene.name.clone(),
        });
    }
    let projected = meshes
        .iter()
        .enumerate()
        .map(|(i, mesh)| {
            scene.view.project(mesh).map_err(|source| Error::View {
                scene: scene.name.clone(),
                surface: scene.surface_name(i),
                source,
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let sheets: Vec<Sheet> = projected
        .iter()
        .zip(meshes)
        .map(|(p, mesh)| Sheet {
            positions: &p.positions,
            w: &p.w,
            triangles: &mesh.triangles,
        })
        .collect();
    let curves = intersect::curves(&sheets);
    if !scene.curves.refine {
        return Ok(curves);
    }
    let (lo, hi) = projected.iter().filter_map(|p| p.bounds()).fold(
        (DVec3::INFINITY, DVec3::NEG_INFINITY),
        |(lo, hi), (a, b)| (lo.min(a), hi.max(b)),
    );
    let sources = scene.surfaces.iter().map(|s| &s.surface);
    Ok(refine_curves(
        scene,
        &curves,
        &sheets,
        sources.zip(meshes.iter().copied()),
        (hi - lo).length(),
    ))
}

/// `curves` (found on `sheets`) moved onto the analytic surfaces of `surfaces` (each
/// surface's source and 4D mesh, in the sheets' order) in the scene's view.
fn refine_curves<'a>(
    scene: &Scene,
    curves: &Curves,
    sheets: &[Sheet],
    surfaces: impl Iterator<Item = (&'a Source, &'a Mesh4)>,
    diagonal: f64,
) -> Curves {
    // A mesh without its triangles' parameters (a 4D mesh read back from a .glb, which
    // keeps the vertices' only) keeps its curve points, as a mesh file's do.
    let analytic: Vec<intersect::Analytic> = surfaces
        .map(|(source, mesh)| intersect::Analytic {
            surface: source.parametric().filter(|_| {
                mesh.triangle_uv.len() == mesh.triangles.len()
                    && mesh.triangle_patch.len() == mesh.triangles.len()
            }),
            mesh,
        })
        .collect();
    intersect::refine(curves, sheets, &analytic, &scene.view, diagonal)
}

fn sample_with(scene: &Scene, bar: &ProgressBar) -> Sampled {
    let mut timings = Timings::default();
    let mut surfaces = Vec::with_capacity(scene.surfaces.len());
    for (i, entry) in scene.surfaces.iter().enumerate() {
        let name = scene.surface_name(i);
        bar.set_message(format!("sampling {name}"));
        let sampling = scene.surface_sampling(i);
        let start = Instant::now();
        let sampled = entry.surface.sample(sampling);
        let sample_ms = ms(start);
        timings.sample += sample_ms;
        let start = Instant::now();
        // Stopped by its budget: the uniform grid of as many triangles to compare with,
        // audited too (and timed with the audit). A mesh file is the surface: nothing to
        // audit.
        let (audited, uniform, method) = match &entry.surface {
            Source::Parametric(surface) => (
                audit(surface, &sampled.mesh),
                (!sampled.complete)
                    .then(|| sample::uniform_error(surface, sampled.mesh.triangles.len())),
                sampling.method(),
            ),
            Source::Mesh(_) => (Audit::default(), None, "file"),
        };
        let audit_ms = ms(start);
        timings.audit += audit_ms;
        let report = SamplingReport::new(
            method, sampling, &sampled, &audited, uniform, sample_ms, audit_ms,
        );
        if let Some(w) = report.warning(&name) {
            bar.suspend(|| eprintln!("warning: {w}"));
        }
        let mesh = sampled.mesh;
        let stats = mesh.validate();
        if let Some(w) = mesh_file_warning(&name, &entry.surface, &stats) {
            bar.suspend(|| eprintln!("warning: {w}"));
        }
        bar.inc(1);
        surfaces.push(Sample {
            name,
            mesh,
            stats,
            report,
        });
    }
    Sampled { surfaces, timings }
}

/// The stages from the view on, from the scene's samples.
fn in_view(
    scene: &Scene,
    samples: Sampled,
    stages: Stages,
    bar: &ProgressBar,
) -> Result<Built, Error> {
    if scene.view.auto {
        return Err(Error::UnresolvedView {
            scene: scene.name.clone(),
        });
    }
    let mut timings = samples.timings;
    let mut products = Vec::with_capacity(scene.surfaces.len());
    let mut projections = Vec::with_capacity(scene.surfaces.len());
    for (entry, sample) in scene.surfaces.iter().zip(samples.surfaces) {
        let Sample {
            name,
            mesh,
            stats,
            report,
        } = sample;
        bar.set_message(format!("projecting {name}"));
        let start = Instant::now();
        let projected = scene.view.project(&mesh).map_err(|source| Error::View {
            scene: scene.name.clone(),
            surface: name.clone(),
            source,
        })?;
        timings.view += ms(start);
        bar.inc(1);
        if let Some(largest) = projected.out_of_range() {
            return Err(Error::Scale {
                scene: scene.name.clone(),
                message: format!(
                    "surface `{name}` reaches a coordinate of {largest:.3e} in the view, beyond {MAX_COORDINATE:e}, where the files' f32 and the exact predicates stay exact; make it smaller (its size parameters, or view.translation)"
                ),
            });
        }
        projections.push((name, entry, mesh, stats, report, projected));
    }

    // Halos: rho is a share of the whole projected scene's diagonal.
    let (lo, hi) = projections.iter().filter_map(|p| p.5.bounds()).fold(
        (DVec3::INFINITY, DVec3::NEG_INFINITY),
        |(lo, hi), (a, b)| (lo.min(a), hi.max(b)),
    );
    let diagonal = (hi - lo).length();
    if diagonal.is_nan() || diagonal < MIN_EXTENT {
        return Err(Error::Scale {
            scene: scene.name.clone(),
            message: format!(
                "the projected surfaces are {diagonal:.3e} across, less than {MIN_EXTENT:e}, below which the files' f32 and the exact predicates lose their digits; make them larger (their size parameters)"
            ),
        });
    }
    let pixel = render::picture_pixel_size(
        projections
            .iter()
            .map(|p| (p.5.positions.as_slice(), p.2.triangles.as_slice())),
        &scene.render,
        &scene.camera,
    )
    .map_err(|source| Error::Render {
        scene: scene.name.clone(),
        source,
    })?;
    let rho = scene.halo.half_width(diagonal, pixel);
    let triangles: usize = projections.iter().map(|p| p.2.triangles.len()).sum();
    let needed = if stages.halos || stages.curves {
        triangles as f64 * crate::memory::BUILD_BYTES_PER_TRIANGLE
    } else {
        0.0
    };
    let (limit, source_of_limit) = crate::memory::limit().map_err(|message| Error::Scale {
        scene: scene.name.clone(),
        message,
    })?;
    if needed > limit {
        return Err(Error::Scale {
            scene: scene.name.clone(),
            message: format!(
                "the halos, curves and verification of {triangles} triangles would need about {:.2} GB ({} bytes per triangle), more than the limit of {:.2} GB ({source_of_limit}); sample fewer triangles (sampling.tolerance, sampling.max_triangles or a coarser grid)",
                needed / crate::memory::GB,
                crate::memory::BUILD_BYTES_PER_TRIANGLE,
                limit / crate::memory::GB
            ),
        });
    }
    for (name, entry, mesh, stats, report, projected) in projections {
        let (halo, halo_report) = if stages.halos {
            bar.set_message(format!("halo of {name}"));
            let start = Instant::now();
            let built = build_halo(&projected, &mesh.triangles, rho, &scene.halo);
            timings.halo += ms(start);
            built
        } else {
            Default::default()
        };
        bar.inc(1);
        let stipples = stages.stipples.then(|| {
            bar.set_message(format!("stipples of {name}"));
            let start = Instant::now();
            let st = &scene.render.stipple;
            let set = Stipples::generate(&mesh.positions, &mesh.triangles, st.count, st.seed);
            timings.stipples += ms(start);
            set
        });
        products.push(SurfaceProduct {
            name,
            surface: entry.surface.clone(),
            mesh,
            stats,
            sampling: report,
            projected,
            halo,
            halo_report,
            stipples,
        });
    }
    let mut curves = Curves::default();
    if stages.curves {
        bar.set_message("intersection curves");
        let start = Instant::now();
        // The curves are made from the sheets alone.
        let none = Curves::default();
        curves = intersect::curves(&parts(&products, &scene.halo, &none).sheets());
        timings.curves = ms(start);
    }
    bar.inc(1);
    let refined = (stages.curves && scene.curves.refine).then(|| {
        bar.set_message("refining the curves");
        let start = Instant::now();
        let none = Curves::default();
        let sheets = parts(&products, &scene.halo, &none).sheets();
        let surfaces = products.iter().map(|p| (&p.surface, &p.mesh));
        let refined = refine_curves(scene, &curves, &sheets, surfaces, diagonal);
        timings.refine = ms(start);
        refined
    });
    let mut verification = Verification::default();
    if stages.verify {
        bar.set_message("verifying halos");
        let start = Instant::now();
        verification = verify::verify(&parts(&products, &scene.halo, &curves));
        timings.verify = ms(start);
    }
    Ok(Built {
        surfaces: products,
        diagonal,
        pixel_size: pixel,
        rho,
        memory: MemoryReport {
            estimate_gb: needed / crate::memory::GB,
            limit_gb: limit / crate::memory::GB,
            peak_gb: None,
        },
        curves,
        refined,
        verification,
        timings,
        stages,
    })
}

/// Builds a scene into `out_dir`: runs the stages and writes the outputs the scene asks for.
pub fn build(scene: &Scene, out_dir: &Path, quiet: bool) -> Result<Report, Error> {
    write(scene, &run(scene, quiet)?, out_dir)
}

/// Writes the outputs the scene asks for from the products of [`run`] into `out_dir`, and
/// returns the report (also written as `report.json` when asked for). The export time is
/// added to the timings of [`run`], and the total is the sum of the stages.
pub fn write(scene: &Scene, built: &Built, out_dir: &Path) -> Result<Report, Error> {
    let products = &built.surfaces;
    let mut timings = built.timings;
    let export_start = Instant::now();
    // Every file under a temporary name until all were made: a failure leaves the folder
    // as it was.
    let staged = export::Staged::new(out_dir).map_err(staged_error)?;
    let data: Vec<SurfaceData> = products.iter().map(|p| p.data(&scene.halo)).collect();
    let write = |file: String, bytes: &[u8]| -> Result<String, Error> {
        staged.write(file, bytes).map_err(staged_error)
    };
    let name = &scene.name;
    let failures = built.failures();
    let stipples = file_stipples(scene, built)?;
    // The files are made on the cores side by side, each written as it is made (a halo's
    // `.vtk` streamed, the `.glb`'s chunks written as they are, with no copy of the whole
    // file in memory); the report lists them in this order.
    type Job<'a> = Box<dyn FnOnce() -> Result<Vec<String>, Error> + Send + 'a>;
    let mut jobs: Vec<Job> = Vec::new();
    if scene.outputs.glb {
        jobs.push(Box::new(|| {
            let (text, bin) = glb_chunks(scene, built, &data, &stipples, &failures)?;
            let file = staged
                .stream(format!("{name}.glb"), |w| {
                    export::write_glb_container(w, &text, &bin)
                })
                .map_err(staged_error)?;
            Ok(vec![file])
        }));
    }
    if scene.outputs.ply {
        jobs.push(Box::new(|| {
            Ok(vec![
                write(format!("{name}.ply"), &export::to_ply(&data, name))?,
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
                &export::to_stipples_ply(&stipples, name),
            )?])
        }));
    }
    if scene.outputs.obj {
        jobs.push(Box::new(|| {
            Ok(vec![write(
                format!("{name}.obj"),
                export::to_obj(&data, name).as_bytes(),
            )?])
        }));
    }
    if scene.outputs.vtk {
        for d in &data {
            let file = if data.len() == 1 {
                format!("{name}-halo.vtk")
            } else {
                format!("{name}-{}-halo.vtk", d.name)
            };
            let staged = &staged;
            jobs.push(Box::new(move || {
                let file = staged
                    .stream(file, |w| export::write_vtk(w, d, name))
                    .map_err(staged_error)?;
                Ok(vec![file])
            }));
        }
    }
    let written: Result<Vec<Vec<String>>, Error> = jobs.into_par_iter().map(|job| job()).collect();
    let mut files: Vec<String> = written?.into_iter().flatten().collect();
    timings.export = ms(export_start);
    let mut picture_report = None;
    if scene.outputs.png || scene.outputs.svg {
        let start = Instant::now();
        let rendered = render::render_for_build(
            &built.parts(&scene.halo),
            &scene.render,
            &scene.camera,
            scene.outputs.svg,
        )
        .map_err(|source| Error::Render {
            scene: scene.name.clone(),
            source,
        })?;
        timings.render = ms(start);
        if scene.outputs.png {
            files.push(write(format!("{name}.png"), &rendered.picture.png())?);
        }
        if let Some(svg) = &rendered.svg {
            files.push(write(format!("{name}.svg"), svg.as_bytes())?);
        }
        picture_report = Some(PictureReport {
            camera: rendered.camera,
            clip: scene.render.clip,
            rho: built.rho,
            gap_px: built.rho / built.pixel_size,
            curves: rendered.curves,
        });
    }
    if scene.outputs.report {
        files.push("report.json".into());
    }
    timings.total = timings.sample
        + timings.audit
        + timings.view
        + timings.halo
        + timings.curves
        + timings.refine
        + timings.verify
        + timings.stipples
        + timings.render
        + timings.export;
    let report = Report {
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
        memory: MemoryReport {
            peak_gb: crate::memory::peak_resident().map(|b| b / crate::memory::GB),
            ..built.memory
        },
        warnings: products
            .iter()
            .flat_map(|p| {
                let file = mesh_file_warning(&p.name, &p.surface, &p.stats);
                p.sampling.warning(&p.name).into_iter().chain(file)
            })
            .collect(),
        picture: picture_report,
        verified: failures.is_empty(),
        failures,
        files,
        scene: scene.clone(),
    };
    if scene.outputs.report {
        let text = serde_json::to_vec_pretty(&report).map_err(|e| Error::Internal {
            stage: "export",
            message: e.to_string(),
        })?;
        write("report.json".into(), &text)?;
    }
    staged.commit().map_err(staged_error)?;
    Ok(report)
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
        &asset,
    )
    .map_err(internal)
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
fn staged_error(e: export::StagedError) -> Error {
    match e {
        export::StagedError::Io { path, source } => Error::Write { path, source },
        busy => Error::Busy(busy),
    }
}

fn surface_report(p: &SurfaceProduct, halo: bool) -> SurfaceReport {
    SurfaceReport {
        name: p.name.clone(),
        type_name: p.surface.type_name().to_string(),
        patches: p.surface.patch_count(),
        sampling: p.sampling.clone(),
        vertices: p.mesh.vertex_count(),
        triangles: p.mesh.triangles.len(),
        // A mesh file's from the statistics already measured, not by validating it again.
        topology: match &p.surface {
            Source::Parametric(s) => s.topology(),
            Source::Mesh(_) => sample::mesh_topology(&p.stats),
        },
        mesh: p.stats,
        bounds_4d: p.mesh.bounds().map(|(lo, hi)| Bounds {
            min: lo.to_array().to_vec(),
            max: hi.to_array().to_vec(),
        }),
        bounds_3d: p.projected.bounds().map(|(lo, hi)| Bounds {
            min: lo.to_array().to_vec(),
            max: hi.to_array().to_vec(),
        }),
        w_range: p.projected.w_range(),
        halo: halo.then(|| p.halo_report.clone()),
        stipples: p.stipples.as_ref().map(Stipples::len),
    }
}
