//! A scene's surfaces sampled once ([`Sampled`]), and the curves a build shows of 4D meshes
//! ([`shown_curves`]).

use super::report::{SamplingReport, Timings, surface_warnings};
use super::{Built, Stages, built::in_view, ms};
use crate::error::Error;
use crate::intersect::{self, Curves, Sheet};
use crate::progress::{Job, Task};
use crate::sample::{self, Audit, ErrorBound, Finer, Mesh4, MeshStats, Sampling, Source};
use crate::scene::Scene;
use crate::stipple::Stipples;
use glam::DVec3;
use std::sync::{Arc, OnceLock};
use std::time::Instant;

/// A scene's surfaces sampled (or read from their files) and audited: what a build makes
/// before the view, which does not depend on the view. Sample once ([`Sampled::of`]), then
/// build any number of views ([`Sampled::build`]): what an animation does for its frames,
/// and what the explorer turns ([`shown_curves`] gives it the curves a build shows).
#[derive(Clone, Debug)]
pub struct Sampled {
    pub(super) surfaces: Vec<Sample>,
    /// The sampling and audit times (the other stages 0).
    pub(super) timings: Timings,
}

#[derive(Clone, Debug)]
pub(super) struct Sample {
    pub(super) name: String,
    pub(super) mesh: Mesh4,
    pub(super) stats: MeshStats,
    pub(super) report: SamplingReport,
    /// The mesh's stipples for the count and seed first asked, ranked once and shared by
    /// every clone of the samples: they depend on the 4D mesh alone, not on the view, so
    /// the frames of an animation and the views built from one sampling rank them once.
    pub(super) stipples: Arc<OnceLock<(StippleKey, Stipples)>>,
}

/// The stipples' count and seed.
type StippleKey = (usize, u64);

impl Sample {
    /// The mesh's `count` stipples from `seed` ([`Stipples::generate`]): the shared set when
    /// it was ranked for them, else ranked now (and shared when it is the first asked).
    pub(super) fn stipples(&self, count: usize, seed: u64) -> Stipples {
        let rank = || Stipples::generate(&self.mesh.positions, &self.mesh.triangles, count, seed);
        let (key, set) = self.stipples.get_or_init(|| ((count, seed), rank()));
        if *key == (count, seed) {
            set.clone()
        } else {
            rank()
        }
    }
}

impl Sampled {
    /// Samples (or reads) and audits every surface of the scene, saying nothing (the
    /// warnings are in each surface's report) and never stopped.
    pub fn of(scene: &Scene) -> Sampled {
        match Sampled::sample(scene, Job::SILENT) {
            Ok(sampled) => sampled,
            Err(e) => unreachable!("a silent job is never cancelled: {e}"),
        }
    }

    /// [`Sampled::of`] as a task `"sampling"` of `job`, a step per surface, with the
    /// warnings a build gives; `Err(Error::Cancelled)` once `job` is cancelled.
    pub fn sample(scene: &Scene, job: Job) -> Result<Sampled, Error> {
        let task = job.task("sampling", scene.surfaces.len() as u64);
        sample_with(scene, &task)
    }

    /// The build of `scene` from these samples (of a scene with the same surfaces and
    /// sampling) in its view: the stages `stages` asks for ([`Stages::of`] for what its
    /// outputs need); the sampling times are these samples'.
    pub fn build(&self, scene: &Scene, stages: Stages) -> Result<Built, Error> {
        self.clone().into_built(scene, stages)
    }

    /// [`Sampled::build`], the samples moved into the build.
    pub fn into_built(self, scene: &Scene, stages: Stages) -> Result<Built, Error> {
        self.into_built_with(scene, stages, Job::SILENT)
    }

    /// [`Sampled::into_built`] as a task `"view"` of `job` (its stages as steps), stopped
    /// once `job` is cancelled.
    pub fn into_built_with(self, scene: &Scene, stages: Stages, job: Job) -> Result<Built, Error> {
        let task = job.task("view", (self.surfaces.len() * 2 + 1) as u64);
        in_view(scene, self, stages, &task)
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

    /// Milliseconds spent sampling, auditing and proving.
    pub fn ms(&self) -> f64 {
        self.timings.sample + self.timings.audit + self.timings.prove
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
pub(super) fn refine_curves<'a>(
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

/// Every surface of the scene sampled, a step of `task` each.
pub(super) fn sample_with(scene: &Scene, task: &Task) -> Result<Sampled, Error> {
    let mut timings = Timings::default();
    let mut surfaces = Vec::with_capacity(scene.surfaces.len());
    for i in 0..scene.surfaces.len() {
        surfaces.push(sample_surface(scene, i, &[], &mut timings, task)?);
        task.step();
    }
    Ok(Sampled { surfaces, timings })
}

/// Samples surface `i` of the scene (an adaptive sampling holding the rectangles `finer` to
/// their own tolerance), audits it, proves its bound where asked and validates its mesh,
/// with the times added to `timings`; its warnings said to `task`'s job, which stops it
/// once cancelled.
pub(super) fn sample_surface(
    scene: &Scene,
    i: usize,
    finer: &[Finer],
    timings: &mut Timings,
    task: &Task,
) -> Result<Sample, Error> {
    let entry = &scene.surfaces[i];
    let name = scene.surface_name(i);
    task.doing(&format!("sampling {name}"));
    let job = task.job();
    let cancel = job.cancel();
    let sampling = scene.surface_sampling(i);
    let start = Instant::now();
    let sampled = match &entry.surface {
        Source::Parametric(surface) => sample::sample_finer(surface, sampling, finer, cancel),
        source => source.sample(sampling),
    };
    job.check()?;
    let sample_ms = ms(start);
    timings.sample += sample_ms;
    let start = Instant::now();
    // Stopped by its budget: the uniform grid of as many triangles to compare with,
    // audited too (and timed with the audit). A mesh file is the surface: nothing to
    // audit.
    let (audited, uniform, method) = match &entry.surface {
        Source::Parametric(surface) => (
            sample::audit_until(surface, &sampled.mesh, cancel),
            (!sampled.complete && !cancel.is_cancelled())
                .then(|| sample::uniform_error(surface, sampled.mesh.triangles.len())),
            sampling.method(),
        ),
        Source::Mesh(_) => (Audit::default(), None, "file"),
    };
    job.check()?;
    let audit_ms = ms(start);
    timings.audit += audit_ms;
    let start = Instant::now();
    let aimed = matches!(
        sampling,
        Sampling::Adaptive {
            bound: ErrorBound::Proven,
            ..
        }
    );
    let proof = entry
        .surface
        .parametric()
        .filter(|_| scene.outputs.prove || aimed)
        .map(|surface| sample::prove_until(surface, &sampled.mesh, cancel));
    job.check()?;
    let proven_ms = ms(start);
    timings.prove += proven_ms;
    let report = SamplingReport::new(
        method,
        sampling,
        &sampled,
        &audited,
        proof.as_ref(),
        uniform,
        [sample_ms, audit_ms, proven_ms],
    );
    if let Some(w) = report.warning(&name) {
        job.warn(&w);
    }
    let start = Instant::now();
    let mesh = sampled.mesh;
    let stats = mesh.validate();
    timings.audit += ms(start);
    for w in surface_warnings(&name, &entry.surface, &stats) {
        job.warn(&w);
    }
    Ok(Sample {
        name,
        mesh,
        stats,
        report,
        stipples: Arc::default(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn views_built_from_one_sampling_rank_their_stipples_once() {
        // An animation's frames are views built from one sampling: a stipple picture's
        // ranking (seconds at 600,000 stipples) is made for the first and shared by the rest.
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/fixtures/scenes/klein-bottle-stipples.json"
        );
        let mut scene = Scene::load(std::path::Path::new(path)).unwrap();
        scene.render.stipple.count = 3000;
        let samples = Sampled::of(&scene);
        let stipples = |built: &Built| built.surfaces[0].stipples.clone().unwrap();
        let first = stipples(&samples.build(&scene, Stages::of(&scene)).unwrap());
        let mesh = &samples.surfaces[0].mesh;
        // The first build ranked them into the samples' shared set.
        let (key, shared) = samples.surfaces[0]
            .stipples
            .get()
            .expect("the set is shared");
        assert_eq!(*key, (3000, scene.render.stipple.seed));
        assert_eq!(shared.bary, first.bary);
        // Another view takes the shared set: the same points, ranked by the mesh alone.
        let mut turned = scene.clone();
        turned.view.rotation.xw += 30.0;
        let second = stipples(&samples.build(&turned, Stages::of(&turned)).unwrap());
        assert_eq!(
            (&second.triangle, &second.bary),
            (&first.triangle, &first.bary)
        );
        // Another count is ranked anew, the shared set kept.
        let mut more = scene.clone();
        more.render.stipple.count = 4000;
        let other = stipples(&samples.build(&more, Stages::of(&more)).unwrap());
        let fresh = Stipples::generate(
            &mesh.positions,
            &mesh.triangles,
            4000,
            more.render.stipple.seed,
        );
        assert_eq!(
            (&other.triangle, &other.bary),
            (&fresh.triangle, &fresh.bary)
        );
        assert_eq!(samples.surfaces[0].stipples.get().unwrap().0, *key);
    }
}
