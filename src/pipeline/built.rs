//! What a build computes before writing ([`Built`]): the stages from the view on, run on a
//! scene's samples.

use super::report::{CrowdingReport, MemoryReport, SamplingReport, Timings};
use super::sampled::{Sample, Sampled, refine_curves};
use super::{Stages, ms, work};
use crate::error::Error;
use crate::export::SurfaceData;
use crate::halo::{Halo, HaloParams, HaloReport};
use crate::intersect::{self, Curves};
use crate::limits::{MAX_COORDINATE, MIN_EXTENT};
use crate::parts::{HaloPart, Parts, SurfacePart};
use crate::progress::Task;
use crate::render::{self, CameraSettings, Picture, RenderError, RenderSettings};
use crate::sample::{Mesh4, MeshStats, Source};
use crate::scene::{Scene, SceneSurface};
use crate::stipple::Stipples;
use crate::verify::{self, Verification};
use crate::view::Projected;
use glam::DVec3;
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
    /// The memory the build was estimated to need, and the limit.
    pub memory: MemoryReport,
    /// How many boxes pile up at the surfaces' points, measured before the stages that
    /// query them.
    pub crowding: CrowdingReport,
    /// Which stages after the projection ran.
    pub stages: Stages,
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
pub(super) fn parts<'a>(
    surfaces: &'a [SurfaceProduct],
    halo: &HaloParams,
    curves: &'a Curves,
) -> Parts<'a> {
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

/// One surface sampled and projected: what the stages from the halos on take.
pub(super) struct InView<'a> {
    pub(super) entry: &'a SceneSurface,
    pub(super) sample: Sample,
    pub(super) projected: Projected,
}

/// The stages from the view on, from the scene's samples.
pub(super) fn in_view(
    scene: &Scene,
    samples: Sampled,
    stages: Stages,
    task: &Task,
) -> Result<Built, Error> {
    let job = task.job();
    let cancel = job.cancel();
    if scene.view.auto {
        return Err(Error::UnresolvedView {
            scene: scene.name.clone(),
        });
    }
    let mut timings = samples.timings;
    let mut projections = project(scene, samples.surfaces, &mut timings, task)?;
    // The certificate of the true surfaces' double curves, and the meshes held to it: their
    // curves, made here from the sheets alone.
    let mut held = None;
    if stages.curves && scene.curves.certify {
        task.doing("certifying the curves");
        let start = Instant::now();
        let surfaces: Vec<_> = projections
            .iter()
            .map(|p| p.entry.surface.parametric())
            .collect();
        let certificate =
            crate::intersect::certified::certify_until(&surfaces, &scene.view, cancel);
        job.check()?;
        timings.certify = ms(start);
        let (mut curves, rounds) =
            super::hold::hold(scene, &certificate, &mut projections, &mut timings, task)?;
        // The refined curves copy this report.
        curves.report.certified = Some(certificate);
        curves.report.sampled_finer = rounds;
        held = Some(curves);
    }
    task.doing("measuring the scene and how its triangles pile up");
    let start = Instant::now();
    let scale = Scale::of(scene, &projections, stages)?;
    // Measured for the stages that query the triangles; a build of the report alone (an
    // adaptive mesh of millions of triangles, say) skips it.
    let mut crowding = CrowdingReport::default();
    let probes = if stages.curves || stages.halos {
        work::probes(&projections)
    } else {
        Vec::new()
    };
    if !probes.is_empty() {
        crowding.triangles = work::surface_crowding(scene, &projections, &probes)?;
    }
    timings.guards += ms(start);
    let Scale {
        diagonal,
        pixel,
        rho,
        memory,
    } = scale;
    job.check()?;
    let mut products = Vec::with_capacity(projections.len());
    for view in projections {
        products.push(surface_product(
            scene,
            view,
            stages,
            rho,
            &mut timings,
            task,
        )?);
    }
    if stages.halos {
        task.doing("measuring how the halos pile up");
        let start = Instant::now();
        crowding.halos = work::halo_crowding(scene, &products, &probes, diagonal)?;
        timings.guards += ms(start);
    }
    let mut curves = Curves::default();
    if let Some(held) = held {
        curves = held;
    } else if stages.curves {
        task.doing("intersection curves");
        let start = Instant::now();
        // The curves are made from the sheets alone.
        let none = Curves::default();
        let sheets = parts(&products, &scene.halo, &none).sheets();
        curves = intersect::curves_until(&sheets, cancel);
        job.check()?;
        timings.curves = ms(start);
    }
    task.step();
    let refined = (stages.curves && scene.curves.refine).then(|| {
        task.doing("refining the curves");
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
        task.doing("verifying halos");
        let start = Instant::now();
        verification = verify::verify_until(&parts(&products, &scene.halo, &curves), cancel);
        job.check()?;
        timings.verify = ms(start);
    }
    Ok(Built {
        surfaces: products,
        diagonal,
        pixel_size: pixel,
        rho,
        memory,
        crowding,
        curves,
        refined,
        verification,
        timings,
        stages,
    })
}

/// One surface's product: its halo at half-width `rho` and its stipples, where the stages
/// ask for them, with their times added to `timings`; stopped once `task`'s job is
/// cancelled.
fn surface_product(
    scene: &Scene,
    view: InView,
    stages: Stages,
    rho: f64,
    timings: &mut Timings,
    task: &Task,
) -> Result<SurfaceProduct, Error> {
    let job = task.job();
    let InView {
        entry,
        sample,
        projected,
    } = view;
    let name = &sample.name;
    let (halo, halo_report) = if stages.halos {
        task.doing(&format!("halo of {name}"));
        let start = Instant::now();
        let built = crate::halo::build_halo_until(
            &projected,
            &sample.mesh.triangles,
            rho,
            &scene.halo,
            job.cancel(),
        );
        job.check()?;
        timings.halo += ms(start);
        built
    } else {
        Default::default()
    };
    task.step();
    let stipples = stages.stipples.then(|| {
        task.doing(&format!("stipples of {name}"));
        let start = Instant::now();
        let st = &scene.render.stipple;
        let set = sample.stipples(st.count, st.seed);
        timings.stipples += ms(start);
        set
    });
    let Sample {
        name,
        mesh,
        stats,
        report,
        ..
    } = sample;
    job.check()?;
    Ok(SurfaceProduct {
        name,
        surface: entry.surface.clone(),
        mesh,
        stats,
        sampling: report,
        projected,
        halo,
        halo_report,
        stipples,
    })
}

/// Each sample in the scene's view, its coordinates checked against the files' range.
fn project<'a>(
    scene: &'a Scene,
    samples: Vec<Sample>,
    timings: &mut Timings,
    task: &Task,
) -> Result<Vec<InView<'a>>, Error> {
    scene
        .surfaces
        .iter()
        .zip(samples)
        .map(|(entry, sample)| {
            let view = project_one(scene, entry, sample, timings, task);
            task.step();
            view
        })
        .collect()
}

/// One surface's sample projected into the scene's view.
pub(super) fn project_one<'a>(
    scene: &Scene,
    entry: &'a SceneSurface,
    sample: Sample,
    timings: &mut Timings,
    task: &Task,
) -> Result<InView<'a>, Error> {
    let name = &sample.name;
    task.job().check()?;
    task.doing(&format!("projecting {name}"));
    let start = Instant::now();
    let projected = scene
        .view
        .project(&sample.mesh)
        .map_err(|source| Error::View {
            scene: scene.name.clone(),
            surface: name.clone(),
            source,
        })?;
    timings.view += ms(start);
    if let Some(largest) = projected.out_of_range() {
        return Err(Error::Scale {
            scene: scene.name.clone(),
            message: format!(
                "surface `{name}` reaches a coordinate of {largest:.3e} in the view, beyond {MAX_COORDINATE:e}, where the files' f32 and the exact predicates stay exact; make it smaller (its size parameters, or view.translation)"
            ),
        });
    }
    Ok(InView {
        entry,
        sample,
        projected,
    })
}

/// The scene's size in the view and what follows from it: the diagonal the halos' rho is a
/// share of, a pixel's size, rho, and the memory the build needs.
struct Scale {
    diagonal: f64,
    pixel: f64,
    rho: f64,
    memory: MemoryReport,
}

impl Scale {
    /// The scale of `projections`, refused when too small to keep its digits or too large
    /// for the memory limit.
    fn of(scene: &Scene, projections: &[InView], stages: Stages) -> Result<Scale, Error> {
        // Halos: rho is a share of the whole projected scene's diagonal.
        let (lo, hi) = projections
            .iter()
            .filter_map(|p| p.projected.bounds())
            .fold(
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
            projections.iter().map(|p| {
                (
                    p.projected.positions.as_slice(),
                    p.sample.mesh.triangles.as_slice(),
                )
            }),
            &scene.render,
            &scene.camera,
        )
        .map_err(|source| Error::Render {
            scene: scene.name.clone(),
            source,
        })?;
        let rho = scene.halo.half_width(diagonal, pixel);
        let triangles: usize = projections
            .iter()
            .map(|p| p.sample.mesh.triangles.len())
            .sum();
        let adaptive = projections
            .iter()
            .any(|p| p.sample.report.method == "adaptive");
        let picture = if scene.outputs.png || scene.outputs.svg {
            render::picture_bytes(&scene.render)
        } else {
            0.0
        };
        // The picture is refused on its own, by the renderer, which knows its mode's needs.
        let needed = crate::memory::build_bytes(triangles, adaptive, stages.curves, stages.halos);
        let (limit, source_of_limit) = crate::memory::limit().map_err(|message| Error::Scale {
            scene: scene.name.clone(),
            message,
        })?;
        if needed > limit {
            return Err(Error::Scale {
                scene: scene.name.clone(),
                message: format!(
                    "the build of {triangles} triangles would need about {:.2} GB, more than the limit of {:.2} GB ({source_of_limit}); sample fewer triangles (sampling.tolerance, sampling.max_triangles or a coarser grid)",
                    needed / crate::memory::GB,
                    limit / crate::memory::GB
                ),
            });
        }
        Ok(Scale {
            diagonal,
            pixel,
            rho,
            memory: MemoryReport {
                estimate_gb: (needed + picture) / crate::memory::GB,
                limit_gb: limit / crate::memory::GB,
                peak_gb: None,
            },
        })
    }
}
