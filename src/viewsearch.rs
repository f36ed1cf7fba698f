//! The view search: the 4D view and camera orbit that show the most of a scene's double
//! curves (`halo4d view`).
//!
//! Takes: a scene. Gives: the six plane angles of the 4D rotation and the camera's azimuth
//! and elevation that maximize the curves' visible length in the picture, each piece
//! weighted by the sine of the angle at which its two sheets cross (a tangential contact
//! makes long curves that read as nothing), times the share of their length that is
//! visible ([`crate::render::visible`]: eye rays to the curves
//! against the surfaces as drawn), plus a tenth of the picture's side for every branch point
//! and triple point in view, scaled down in proportion where less than half of the curves'
//! length is visible; everything else of the scene kept. The surfaces are
//! sampled once on a coarse uniform grid ([`SEARCH_TRIANGLES`] triangles in all; a mesh file
//! as it is); each 4D view projects it and finds its exact curves ([`crate::intersect`]),
//! then tries several camera orbits on them, indexed once, which cost only the rays.
//!
//! The search is deterministic (a Halton sequence over the eight angles, the scene's own
//! view first, then a pattern search around the best with halving steps) and bounded:
//! [`SEARCH_VIEWS`] 4D views at most. Candidates are evaluated on the cores side by side and
//! compared in their order, so the result does not depend on the number of threads.

use crate::intersect::{self, Curves, Sheet};
use crate::limits::{SEARCH_TRIANGLES, SEARCH_VIEWS};
use crate::parts::{Parts, SurfacePart};
use crate::progress::{Cancelled, Job};
use crate::render::{self, CameraSettings, RenderSettings};
use crate::sample::{Mesh4, Sampling, Source};
use crate::scene::Scene;
use crate::view::{Rotation4, View};
use rayon::prelude::*;
use serde::Serialize;

/// The picture side, in pixels, at which candidates are measured: the share does not
/// depend on it, and the visible length scales with it.
const SEARCH_SIDE: u32 = 256;

/// Camera orbits tried for each 4D view: azimuths (degrees) ...
const AZIMUTHS: [f64; 8] = [0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0];
/// ... and elevations.
const ELEVATIONS: [f64; 3] = [-30.0, 15.0, 50.0];

/// What a branch point or a triple point in view adds to the objective, as a share of the
/// picture's side in pixels: they are where the structure of a double curve shows.
const MARK_SHARE: f64 = 0.1;

/// The visible share of the curves below which a view's objective is scaled down in
/// proportion: a picture should show at least half of its curves.
const SHARE_WANTED: f64 = 0.5;

/// 4D views drawn from the Halton sequence before the pattern search.
const GLOBAL_VIEWS: usize = 96;

/// What the search found.
#[derive(Clone, Debug, Serialize)]
pub struct Found {
    /// The 4D rotation.
    pub rotation: Rotation4,
    /// Camera azimuth, degrees.
    pub azimuth: f64,
    /// Camera elevation, degrees.
    pub elevation: f64,
    /// The visible share of the curves' projected length at the found view, on the search's
    /// coarse mesh.
    pub visible_curve_share: f64,
    /// The same at the scene's own view.
    pub start_share: f64,
    /// The objective (transversal visible pixels at 256 x 256 times the share) at the found
    /// view.
    pub score: f64,
    /// The objective at the scene's own view.
    pub start_score: f64,
    /// 4D views evaluated.
    pub views: usize,
    /// Triangles of the search's mesh.
    pub triangles: usize,
    /// Milliseconds the search took.
    pub ms: f64,
}

impl Found {
    /// The scene with the found view and camera orbit.
    pub fn apply(&self, scene: &Scene) -> Scene {
        let mut out = scene.clone();
        out.view.rotation = self.rotation;
        out.camera.azimuth = self.azimuth;
        out.camera.elevation = self.elevation;
        out.view.auto = false;
        out
    }

    /// One line: what the search did and what it found.
    pub fn summary(&self) -> String {
        format!(
            "view search: {} 4D views on {} triangles in {:.1} s; visible share of the curves {:.3} (the scene's own view: {:.3}), score {:.0} ({:.0}); rotation {}, camera azimuth {} and elevation {}",
            self.views,
            self.triangles,
            self.ms / 1e3,
            self.visible_curve_share,
            self.start_share,
            self.score,
            self.start_score,
            serde_json::to_string(&self.rotation).unwrap_or_default(),
            self.azimuth,
            self.elevation
        )
    }
}

/// Finds the view of a scene whose view is left to the search (`"view": "auto"`,
/// [`View::auto`]) with [`search`] (reporting to `job`) and puts it into the scene; `None`,
/// and the scene as it was, when the scene gives its view.
pub fn resolve(scene: &mut Scene, job: Job) -> Result<Option<Found>, SearchError> {
    if !scene.view.auto {
        return Ok(None);
    }
    let found = search(scene, job)?;
    *scene = found.apply(scene);
    Ok(Some(found))
}

/// Why a search could not run.
#[derive(Debug, thiserror::Error)]
pub enum SearchError {
    /// A surface reaches behind the 4D eye in every view tried, or the scene has nothing to
    /// draw.
    #[error("the view search found no view in which the scene can be drawn: {0}")]
    NoView(String),
    /// The caller cancelled the search.
    #[error("the view search {0}")]
    Cancelled(#[from] Cancelled),
}

/// One candidate: the 8 angles.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Candidate {
    angles: [f64; 6],
    azimuth: f64,
    elevation: f64,
}

/// Searches the view of `scene` that shows the most of its curves: a task `"view search"`
/// of `job`, a step per 4D view, stopped once `job` is cancelled.
pub fn search(scene: &Scene, job: Job) -> Result<Found, SearchError> {
    let start = std::time::Instant::now();
    let meshes = coarse_meshes(scene);
    let triangles = meshes.iter().map(|m| m.triangles.len()).sum();
    let task = job.task("view search", SEARCH_VIEWS as u64);
    let cancel = job.cancel();
    let mut settings = scene.render;
    (settings.width, settings.height, settings.samples) = (SEARCH_SIDE, SEARCH_SIDE, 1);
    settings.halos = false;
    settings.stereo = false;
    let evaluate = |angles: [f64; 6], cameras: &[(f64, f64)]| -> Vec<(Candidate, f64, f64)> {
        if cancel.is_cancelled() {
            return Vec::new();
        }
        let result = evaluate_view(scene, &meshes, &settings, angles, cameras);
        task.step();
        result
    };
    let own = scene.view.rotation.planes().map(|(_, a)| a);
    let own_camera = (scene.camera.azimuth, scene.camera.elevation);
    let start_eval = evaluate(own, &[own_camera]);
    let (start_share, start_score) = start_eval.first().map_or((0.0, 0.0), |e| (e.1, e.2));
    let orbits: Vec<(f64, f64)> = std::iter::once(own_camera)
        .chain(
            ELEVATIONS
                .iter()
                .flat_map(|&e| AZIMUTHS.iter().map(move |&a| (a, e))),
        )
        .collect();
    // The global stage: the scene's own 4D view and Halton points, each with every orbit.
    let mut views: Vec<[f64; 6]> = vec![own];
    views.extend((1..GLOBAL_VIEWS).map(|k| std::array::from_fn(|d| 360.0 * halton(k, PRIMES[d]))));
    let mut best: Option<(Candidate, f64, f64)> = None;
    consider(
        &mut best,
        views
            .par_iter()
            .map(|&angles| evaluate(angles, &orbits))
            .collect(),
    );
    let mut evaluated = views.len() + 1;
    // The pattern search: each angle in turn moved by plus and minus the step, the best move
    // taken, the step halved when none improves.
    let mut step = 24.0;
    while step >= 3.0 && evaluated + 6 <= SEARCH_VIEWS {
        let Some((centre, _, score)) = best else {
            break;
        };
        let (mut moves, cameras) = pattern_moves(&centre, step);
        let remaining = SEARCH_VIEWS - evaluated;
        moves.truncate(remaining);
        evaluated += moves.len();
        consider(
            &mut best,
            moves
                .par_iter()
                .map(|&angles| evaluate(angles, &cameras))
                .collect(),
        );
        if best.as_ref().is_none_or(|b| b.2 <= score) {
            step *= 0.5;
        }
    }
    drop(task);
    job.check()?;
    let Some((found, share, score)) = best else {
        return Err(SearchError::NoView(
            "every view put a surface behind the 4D eye or left nothing to draw".into(),
        ));
    };
    Ok(Found {
        rotation: rotation_of(found.angles),
        azimuth: found.azimuth,
        elevation: found.elevation,
        visible_curve_share: share,
        start_share,
        score,
        start_score,
        views: evaluated,
        triangles,
        ms: start.elapsed().as_secs_f64() * 1e3,
    })
}

/// The pattern search's moves from `centre` by `step` degrees: each 4D angle in turn moved
/// by minus and plus the step, and the nine cameras around the centre's.
fn pattern_moves(centre: &Candidate, step: f64) -> (Vec<[f64; 6]>, Vec<(f64, f64)>) {
    let mut moves: Vec<[f64; 6]> = Vec::new();
    for d in 0..6 {
        for sign in [-1.0, 1.0] {
            let mut a = centre.angles;
            a[d] = crate::view::wrap_degrees(a[d] + sign * step);
            moves.push(a);
        }
    }
    let cameras: Vec<(f64, f64)> = [-1.0, 0.0, 1.0]
        .iter()
        .flat_map(|&da| {
            [-1.0, 0.0, 1.0].iter().map(move |&de| {
                (
                    crate::view::wrap_degrees(centre.azimuth + da * step),
                    (centre.elevation + de * step).clamp(-80.0, 80.0),
                )
            })
        })
        .collect();
    (moves, cameras)
}

/// The rotation of the six plane angles, in [`Rotation4::planes`]'s order.
fn rotation_of(angles: [f64; 6]) -> Rotation4 {
    let names = Rotation4::default().planes().map(|(n, _)| n);
    let mut rotation = Rotation4::default();
    for (name, angle) in names.iter().zip(angles) {
        *rotation.angle_mut(name).expect("a plane's name") = angle;
    }
    rotation
}

/// Keeps in `best` the candidate of highest score of `results` (the first of equal ones).
fn consider(best: &mut Option<(Candidate, f64, f64)>, results: Vec<Vec<(Candidate, f64, f64)>>) {
    for r in results.into_iter().flatten() {
        if best.as_ref().is_none_or(|b| r.2 > b.2) {
            *best = Some(r);
        }
    }
}

/// The first six primes: the Halton sequence's bases, one per plane angle.
const PRIMES: [usize; 6] = [2, 3, 5, 7, 11, 13];

/// The `k`th point of the van der Corput sequence in `base`, in [0, 1).
fn halton(mut k: usize, base: usize) -> f64 {
    let (mut f, mut r) = (1.0, 0.0);
    while k > 0 {
        f /= base as f64;
        r += f * (k % base) as f64;
        k /= base;
    }
    r
}

/// Every surface of the scene on a uniform grid of about [`SEARCH_TRIANGLES`] triangles in
/// all (an even number of cells per side of each patch); a mesh file as it is.
fn coarse_meshes(scene: &Scene) -> Vec<Mesh4> {
    let patches: usize = scene
        .surfaces
        .iter()
        .filter(|s| matches!(s.surface, Source::Parametric(_)))
        .map(|s| s.surface.patch_count())
        .sum();
    let per_patch = SEARCH_TRIANGLES / (2 * patches.max(1));
    let cells = (((per_patch as f64).sqrt() / 2.0).floor() as usize * 2).max(4);
    scene
        .surfaces
        .iter()
        .map(|s| {
            s.surface
                .sample(&Sampling::Uniform { u: cells, v: cells })
                .mesh
        })
        .collect()
}

/// The candidates of one 4D view, one per camera orbit, each with its visible share and
/// score; none where the view cannot be drawn.
fn evaluate_view(
    scene: &Scene,
    meshes: &[Mesh4],
    settings: &RenderSettings,
    angles: [f64; 6],
    cameras: &[(f64, f64)],
) -> Vec<(Candidate, f64, f64)> {
    let mut view: View = scene.view;
    let names = Rotation4::default().planes().map(|(n, _)| n);
    for (name, angle) in names.iter().zip(angles) {
        *view.rotation.angle_mut(name).expect("a plane's name") = angle;
    }
    let Ok(projected) = meshes
        .iter()
        .map(|m| view.project(m))
        .collect::<Result<Vec<_>, _>>()
    else {
        return Vec::new();
    };
    let sheets: Vec<Sheet> = projected
        .iter()
        .zip(meshes)
        .map(|(p, m)| Sheet {
            positions: &p.positions,
            w: &p.w,
            triangles: &m.triangles,
        })
        .collect();
    let curves: Curves = intersect::curves(&sheets);
    let parts = Parts {
        surfaces: projected
            .iter()
            .zip(meshes)
            .map(|(p, m)| SurfacePart {
                positions: &p.positions,
                w: &p.w,
                normals: &p.normals,
                uv: None,
                triangles: &m.triangles,
                stipples: None,
            })
            .collect(),
        halos: vec![None; meshes.len()],
        curves: &curves,
    };
    let settings_of = |&(azimuth, elevation): &(f64, f64)| CameraSettings {
        azimuth,
        elevation,
        ..scene.camera
    };
    let orbits: Vec<CameraSettings> = cameras.iter().map(settings_of).collect();
    let Ok(seen) = render::visible::curve_visibility_each(&parts, settings, &orbits) else {
        return Vec::new();
    };
    cameras
        .iter()
        .zip(seen)
        .filter_map(|(&(azimuth, elevation), seen)| {
            let seen = seen?;
            let marks = seen.branch_points_visible + seen.triple_points_visible;
            let score = (seen.transversal_visible_px * seen.visible_curve_share
                + MARK_SHARE * f64::from(SEARCH_SIDE) * marks as f64)
                * (seen.visible_curve_share / SHARE_WANTED).min(1.0);
            Some((
                Candidate {
                    angles,
                    azimuth,
                    elevation,
                },
                seen.visible_curve_share,
                score,
            ))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn halton_points_are_the_radical_inverses() {
        assert_eq!(halton(1, 2), 0.5);
        assert_eq!(halton(3, 2), 0.75);
        assert!((halton(5, 3) - (2.0 / 3.0 + 1.0 / 9.0)).abs() < 1e-15);
        assert_eq!(halton(0, 7), 0.0);
    }
}
