//! A scene's motion pictures (`halo4d slice`): each surface cut by the hyperplanes
//! ⟨n, x⟩ = c, its critical levels found and checked by Morse theory ([`crate::motion`]),
//! one still between each pair of consecutive critical levels drawn as a link diagram, and
//! the files: `<name>-motion.png` and `.svg` (the stills in one strip), `<name>-motion.glb`
//! (their curves as tubes, side by side), `<name>-still-NN.ply` (each still's curves in the
//! hyperplane's frame) and `motion.json` (the critical points,
//! the components per interval, the stills and the verdict).

use crate::error::Error;
use crate::export::{Staged, StagedError};
use crate::limits::FieldError;
use crate::motion::{self, MotionPicture, Polyline, Shape, Slicing};
use crate::pipeline::Sampled;
use crate::progress::Job;
use crate::render::diagram;
use crate::render::text::compact;
use crate::sample::{ErrorBound, Mesh4, Sampling, Source};
use crate::scene::Scene;
use crate::surfaces::Surface;
use glam::DVec4;
use serde::Serialize;
use std::path::Path;

/// The stills' panels: pixels on a side, line width in pixels, panels per row.
const PANEL: u32 = 360;
const LINE: f64 = 2.5;
const COLUMNS: usize = 5;
/// The film's frames: pixels on a side, line width, frames per second.
const FILM_SIDE: u32 = 720;
const FILM_LINE: f64 = 3.0;
const FILM_FPS: u32 = 24;

/// Relative tolerances (of the surface's 4D diagonal) at which a catalogue or formula
/// surface is sampled again through its critical points, in turn after its own tolerance,
/// while its motion picture fails a check that a finer mesh can pass: a coarse mesh makes
/// pairs of critical vertices beside the surface's points that cross other critical levels.
const FINER: [f64; 3] = [2.5e-4, 6.25e-5, 1.5625e-5];

/// The samplings of a surface whose bounding diagonal is `diagonal`, as (absolute
/// tolerance, bound, triangle budget), that its motion picture tries in turn while it fails:
/// the scene's own `sampling` (when adaptive; a mesh through the critical points has its
/// slices change at the surface's critical levels), then the [`FINER`] tolerances below it.
fn rungs(sampling: &Sampling, diagonal: f64) -> Vec<(f64, ErrorBound, usize)> {
    let own = sampling.absolute_tolerance(diagonal).map(|t| {
        let budget = sampling.max_triangles(1).min(FINER_TRIANGLES);
        (t, sampling.bound(), budget)
    });
    let finer = FINER
        .iter()
        .map(|r| (r * diagonal, ErrorBound::Audited, FINER_TRIANGLES))
        .filter(|f| own.is_none_or(|o| f.0 < o.0));
    own.into_iter().chain(finer).collect()
}

/// The most triangles of a surface sampled again.
const FINER_TRIANGLES: usize = 4_000_000;

/// Why a motion picture could not be made.
#[derive(Debug, thiserror::Error)]
pub enum SliceError {
    /// A setting (a flag) is out of range.
    #[error("{0}")]
    Setting(FieldError),
    /// Sampling, drawing or writing failed.
    #[error(transparent)]
    Build(#[from] Error),
}

/// One surface's motion picture as `motion.json` records it.
#[derive(Clone, Debug, Serialize)]
pub struct SurfaceMotion {
    /// The surface's name.
    pub name: String,
    /// The unit direction n.
    pub direction: DVec4,
    /// The hyperplanes' frame: the stills' x, y and z axes in 4D.
    pub frame: [DVec4; 3],
    /// The Euler characteristic checked against (`None`: a mesh that is not a manifold,
    /// whose counts are not checked).
    pub euler: Option<i64>,
    /// Whether the surface is closed (else its boundary's critical points count too).
    pub closed: bool,
    /// (minima, saddles, maxima, degenerate) inside the surface.
    pub counts: [usize; 4],
    /// (births, deaths, joins, splits) on its boundary.
    pub boundary_counts: [usize; 4],
    /// The critical points, by level.
    pub critical_points: Vec<motion::CriticalPoint>,
    /// Critical vertices of the mesh that Newton's method found no critical point from.
    pub not_refined: usize,
    /// The critical points proven on the surface by interval arithmetic (`None` for a
    /// mesh read from a file).
    pub proven: Option<motion::ProvenCritical>,
    /// The slice's components in each interval between critical levels.
    pub components: Vec<usize>,
    /// The stills.
    pub stills: Vec<StillRecord>,
    /// Each check that failed.
    pub failures: Vec<String>,
    /// The film's frames, when one was asked for.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub film: Vec<FilmFrame>,
    /// The finer mesh the motion picture was made on, where the scene's failed a check
    /// (`None`: the scene's own mesh).
    pub resampled: Option<Resampled>,
}

/// A frame of the film as `motion.json` records it.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct FilmFrame {
    /// Its level c.
    pub level: f64,
    /// Its interval between critical levels.
    pub interval: usize,
    /// Its curves.
    pub curves: usize,
    /// Crossings of its link diagram.
    pub crossings: usize,
}

/// A surface sampled again for its motion picture, through the critical points found on
/// the mesh before.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Resampled {
    /// The adaptive sampler's tolerance, relative to the surface's 4D diagonal.
    pub relative_tolerance: f64,
    /// Its triangles.
    pub triangles: usize,
    /// The critical points it was sampled through.
    pub through: usize,
}

/// A still as `motion.json` records it.
#[derive(Clone, Debug, Serialize)]
pub struct StillRecord {
    /// Its level c.
    pub level: f64,
    /// Its interval (0 below the lowest critical level).
    pub interval: usize,
    /// Whether it is its interval's own still (else an evenly spaced one).
    pub between: bool,
    /// Its curves.
    pub curves: usize,
    /// Its points (the PLY's vertices).
    pub points: usize,
    /// Its segments (the PLY's edges).
    pub segments: usize,
    /// Crossings of its link diagram.
    pub crossings: usize,
    /// The largest |h - c| of its points moved onto the surface.
    pub max_residual: f64,
    /// Points left on the mesh.
    pub not_converged: usize,
    /// Its PLY file.
    pub file: String,
}

/// A scene's motion pictures.
#[derive(Clone, Debug, Serialize)]
pub struct Motion {
    /// The scene's name.
    pub scene: String,
    /// The tilt applied, degrees.
    pub perturb: f64,
    /// Each surface's.
    pub surfaces: Vec<SurfaceMotion>,
    /// Whether every check passed.
    pub verified: bool,
    /// The files written.
    pub files: Vec<String>,
}

impl Motion {
    /// A few lines for the terminal: per surface its critical points, its stills and its
    /// verdict.
    pub fn summary(&self) -> String {
        let mut out = String::new();
        for s in &self.surfaces {
            let [min, saddle, max, degenerate] = s.counts;
            let euler = s.euler.map_or(
                "χ unknown, a mesh that is not a manifold: not counted".to_string(),
                |e| format!("χ = {e}"),
            );
            let boundary = match s.boundary_counts {
                [0, 0, 0, 0] if s.closed => String::new(),
                [b, d, j, k] => {
                    format!("; on the boundary {b} births, {d} deaths, {j} joins, {k} splits")
                }
            };
            if let Some(r) = s.resampled {
                out += &format!(
                    "{}: sampled again at {:e} of its diagonal ({} triangles) for the checks\n",
                    s.name, r.relative_tolerance, r.triangles
                );
            }
            out += &format!(
                "{}: {min} births, {saddle} saddles, {max} deaths{}{boundary} ({euler}); components per interval {:?}\n",
                s.name,
                if degenerate > 0 {
                    format!(", {degenerate} degenerate")
                } else {
                    String::new()
                },
                s.components
            );
            for still in &s.stills {
                out += &format!(
                    "  c = {:+.6}: {} curve(s), {} crossing(s)\n",
                    still.level, still.curves, still.crossings
                );
            }
            for f in &s.failures {
                out += &format!("  FAILED {f}\n");
            }
        }
        out
    }
}

/// The motion picture of `mesh` (sampled from `surface`, where it has one, as `sampling`
/// says) along `n` with its hyperplanes' `frame`, its surface's `shape` and `extra` evenly
/// spaced stills ([`motion::motion_picture`]); while it fails a check that a mesh through the
/// critical points can pass, made again on the surface sampled through those it found, at
/// the scene's own tolerance (when adaptive), then 2.5e-4, 6.25e-5 and 1.5625e-5 of its
/// diagonal below it, in turn. Gives the last picture, and the mesh it was made of where
/// that is not `mesh`; `say` hears each time why the surface is sampled again.
pub fn motion_through(
    mesh: &Mesh4,
    surface: Option<&Surface>,
    sampling: &Sampling,
    (n, frame, shape, extra): (DVec4, [DVec4; 3], Shape, usize),
    say: &mut dyn FnMut(String),
) -> Result<(MotionPicture, Option<(Resampled, Mesh4)>), FieldError> {
    let cut = |mesh: &Mesh4, proven| {
        motion::motion_picture_proven(mesh, surface, proven, n, frame, shape, extra)
    };
    let mut picture = cut(mesh, None)?;
    let mut last = None;
    let Some(s) = surface else {
        return Ok((picture, last));
    };
    let diagonal = crate::sample::bounding_diagonal(s);
    for (tolerance, bound, budget) in rungs(sampling, diagonal) {
        // A degenerate direction stays degenerate on any mesh.
        if picture.failures.is_empty() || picture.critical.counts()[3] > 0 {
            break;
        }
        let (points, through) = motion::through_points(s, &picture, diagonal);
        let relative = tolerance / diagonal;
        say(format!(
            "{}; sampling again at {relative:.3e} of its diagonal through its {points} \
             critical points",
            picture.failures[0],
        ));
        let again = crate::sample::sample_adaptive_through(s, tolerance, bound, budget, &through);
        picture = cut(&again.mesh, picture.proven.take())?;
        let resampled = Resampled {
            relative_tolerance: relative,
            triangles: again.mesh.triangles.len(),
            through: points,
        };
        last = Some((resampled, again.mesh));
    }
    Ok((picture, last))
}

/// The analytic surface of a scene's surface `source` where `mesh` has its parameters (a
/// scene's own sampling; a mesh read from a file has none), and the topology its motion
/// picture is checked against: the surface's, else the mesh's (its Euler characteristic
/// where it is a manifold).
pub fn surface_shape<'a>(source: &'a Source, mesh: &Mesh4) -> (Option<&'a Surface>, Shape) {
    match source {
        Source::Parametric(s) if mesh.triangle_uv.len() == mesh.triangles.len() => {
            (Some(s), s.topology().into())
        }
        _ => {
            let stats = mesh.validate();
            let shape = Shape {
                euler: stats.is_manifold().then_some(stats.euler_characteristic),
                closed: stats.boundary_edges == 0,
                orientable: stats.orientation_conflicts == 0,
            };
            (None, shape)
        }
    }
}

/// Makes the motion pictures of every surface of `scene` along `slicing` (the scene's
/// `slicing`, or other settings) into `out` (files written under temporary names and moved
/// into place together): a task `"motion pictures"` of `job`, a step per surface, with a
/// note when a surface is sampled again and why, stopped between surfaces once `job` is
/// cancelled (nothing written).
pub fn slice_scene(
    scene: &Scene,
    slicing: Slicing,
    out: &Path,
    job: Job,
) -> Result<Motion, SliceError> {
    slicing
        .check()
        .map_err(|e| SliceError::Setting(e.within("slicing")))?;
    let (n, frame) = slicing.direction_and_frame(scene.view.rotation.matrix());
    let sampled = Sampled::sample(scene, job)?;
    let task = job.task("motion pictures", scene.surfaces.len() as u64);
    let staged = Staged::new(out).map_err(staged_error)?;
    let mut surfaces = Vec::new();
    let mut files = Vec::new();
    for (index, ((name, mesh), entry)) in sampled.meshes().zip(&scene.surfaces).enumerate() {
        let (surface, shape) = surface_shape(&entry.surface, mesh);
        let sampling = scene.surface_sampling(index);
        task.doing(&format!("motion picture of {name}"));
        let mut say = |m: String| job.note(&format!("{name}: {m}"));
        let (picture, finest) = motion_through(
            mesh,
            surface,
            sampling,
            (n, frame, shape, slicing.levels),
            &mut say,
        )
        .map_err(SliceError::Setting)?;
        let (mut record, written) = write_surface(scene, name, &picture, shape, &staged)?;
        files.extend(written);
        record.resampled = finest.as_ref().map(|f| f.0);
        if slicing.film > 0 {
            let mesh = finest.as_ref().map_or(mesh, |f| &f.1);
            let (frames, failures, file) =
                write_film(scene, name, &picture, mesh, surface, slicing.film, &staged)?;
            record.film = frames;
            record.failures.extend(failures);
            files.push(file);
        }
        surfaces.push(record);
        job.check().map_err(Error::from)?;
        task.step();
    }
    drop(task);
    files.push("motion.json".into());
    let motion = Motion {
        scene: scene.name.clone(),
        perturb: slicing.perturb,
        verified: surfaces.iter().all(|s| s.failures.is_empty()),
        surfaces,
        files,
    };
    let json = serde_json::to_vec_pretty(&motion).map_err(|e| Error::Internal {
        stage: "motion",
        message: e.to_string(),
    })?;
    staged
        .write("motion.json".into(), &json)
        .map_err(staged_error)?;
    staged.commit().map_err(staged_error)?;
    Ok(motion)
}

/// One surface's strip, stills and record, its files staged.
fn write_surface(
    scene: &Scene,
    name: &str,
    picture: &MotionPicture,
    shape: Shape,
    staged: &Staged,
) -> Result<(SurfaceMotion, Vec<String>), SliceError> {
    let critical = &picture.critical;
    let step = critical
        .points
        .windows(2)
        .map(|w| w[1].level - w[0].level)
        .fold(f64::INFINITY, f64::min);
    let step = if step.is_finite() { step } else { 1.0 };
    let curves: Vec<_> = picture
        .stills
        .iter()
        .map(|still| still.in_frame(&picture.frame))
        .collect();
    let pages = diagram::pages(&curves, &scene.camera, PANEL, &[]);
    let labels: Vec<(String, String)> = picture
        .stills
        .iter()
        .zip(&pages)
        .map(|(still, page)| {
            let after = still
                .interval
                .checked_sub(1)
                .map(|k| format!(" · after a {}", picture.sequence[k].event.name()))
                .unwrap_or_default();
            (
                format!("c = {}{after}", compact(still.slice.level, step)),
                caption(still.slice.curves.len(), page.under.len()),
            )
        })
        .collect();
    let (strip, svg) =
        diagram::draw_strip(&pages, &labels, COLUMNS, PANEL, LINE).map_err(|e| Error::Render {
            scene: scene.name.clone(),
            source: e,
        })?;
    let mut files = Vec::new();
    let mut write = |file: String, bytes: &[u8]| -> Result<String, SliceError> {
        let file = staged.write(file, bytes).map_err(staged_error)?;
        files.push(file.clone());
        Ok(file)
    };
    write(format!("{name}-motion.png"), &strip.png())?;
    write(
        format!("{name}-motion.glb"),
        &stills_glb(scene, name, picture, &curves)?,
    )?;
    write(format!("{name}-motion.svg"), svg.as_bytes())?;
    let mut stills = Vec::new();
    for (k, ((still, page), curves)) in picture.stills.iter().zip(&pages).zip(&curves).enumerate() {
        let file = write(
            format!("{name}-still-{k:02}.ply"),
            &crate::export::to_still_ply(curves, still.slice.level, name),
        )?;
        stills.push(StillRecord {
            level: still.slice.level,
            interval: still.interval,
            between: still.between,
            curves: still.slice.curves.len(),
            points: curves.iter().map(|c| c.0.len()).sum(),
            segments: curves.iter().map(crate::export::segments).sum(),
            crossings: page.under.len(),
            max_residual: still.slice.max_residual,
            not_converged: still.slice.not_converged,
            file,
        });
    }
    let record = SurfaceMotion {
        name: name.to_string(),
        direction: critical.direction,
        frame: picture.frame,
        euler: shape.euler,
        closed: shape.closed,
        counts: critical.counts(),
        boundary_counts: critical.boundary_counts(),
        critical_points: critical.points.clone(),
        not_refined: critical.not_converged.len(),
        proven: picture.proven.clone(),
        components: picture.components.clone(),
        stills,
        failures: picture.failures.clone(),
        film: Vec::new(),
        resampled: None,
    };
    Ok((record, files))
}

/// A still's caption: its curves and crossings.
fn caption(curves: usize, crossings: usize) -> String {
    let s = |k: usize| if k == 1 { "" } else { "s" };
    format!(
        "{curves} curve{}, {crossings} crossing{}",
        s(curves),
        s(crossings)
    )
}

/// The film of `picture` (made of `mesh` and its `surface`): `frames` slices at levels
/// spread evenly from the mesh's lowest point to its highest, each drawn as a link diagram
/// at one scale (the whole surface's), written as `<name>-film.png`, an animated PNG; each
/// frame checked against its interval's number of components. Gives the frames' records,
/// the failures and the file.
fn write_film(
    scene: &Scene,
    name: &str,
    picture: &MotionPicture,
    mesh: &crate::sample::Mesh4,
    surface: Option<&crate::surfaces::Surface>,
    frames: u32,
    staged: &Staged,
) -> Result<(Vec<FilmFrame>, Vec<String>, String), SliceError> {
    use rayon::prelude::*;
    let n = picture.critical.direction;
    let (lowest, highest) = motion::heights(mesh, n);
    let stills: Vec<(motion::Still, Option<String>)> = (0..frames)
        .into_par_iter()
        .map(|k| {
            let level = lowest + (highest - lowest) * (f64::from(k) + 0.5) / f64::from(frames);
            picture.still_at(mesh, surface, level)
        })
        .collect();
    let curves: Vec<Vec<Polyline>> = stills
        .iter()
        .map(|(still, _)| still.in_frame(&picture.frame))
        .collect();
    let f = &picture.frame;
    let outline: Vec<glam::DVec3> = mesh
        .positions
        .iter()
        .map(|p| glam::DVec3::new(p.dot(f[0]), p.dot(f[1]), p.dot(f[2])))
        .collect();
    let pages = diagram::pages(&curves, &scene.camera, FILM_SIDE, &outline);
    let step = (highest - lowest) / f64::from(frames);
    let mut failures = Vec::new();
    let mut records = Vec::new();
    for (k, ((still, failure), page)) in stills.iter().zip(&pages).enumerate() {
        failures.extend(failure.iter().map(|f| format!("film frame {k}: {f}")));
        records.push(FilmFrame {
            level: still.slice.level,
            interval: still.interval,
            curves: still.slice.curves.len(),
            crossings: page.under.len(),
        });
    }
    let draw = |k: usize| -> std::io::Result<Vec<u8>> {
        let r = &records[k];
        let label = (
            format!("c = {}", compact(r.level, step)),
            caption(r.curves, r.crossings),
        );
        diagram::draw_strip(&pages[k..=k], &[label], 1, FILM_SIDE, FILM_LINE)
            .map(|(picture, _)| picture.rgb)
            .map_err(std::io::Error::other)
    };
    let size = diagram::strip_size(1, FILM_SIDE, 1);
    let mut bytes = Vec::new();
    crate::export::write_apng(&mut bytes, size, FILM_FPS, frames, |k| draw(k as usize)).map_err(
        |e| {
            SliceError::Build(Error::Internal {
                stage: "motion",
                message: e.to_string(),
            })
        },
    )?;
    let file = staged
        .write(format!("{name}-film.png"), &bytes)
        .map_err(staged_error)?;
    Ok((records, failures, file))
}

/// The stills as tubes in a `.glb`, side by side in rows of [`COLUMNS`] as in the strip,
/// each still's tubes `outputs.curve_radius` of the stills' diagonal thick.
fn stills_glb(
    scene: &Scene,
    name: &str,
    picture: &MotionPicture,
    curves: &[Vec<Polyline>],
) -> Result<Vec<u8>, SliceError> {
    let (lo, hi) = curves.iter().flatten().flat_map(|c| &c.0).fold(
        (glam::DVec3::INFINITY, glam::DVec3::NEG_INFINITY),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    let (centre, size) = if lo.x <= hi.x {
        (
            crate::convention::to_gltf((lo + hi) * 0.5),
            (hi - lo).max_element(),
        )
    } else {
        (glam::DVec3::ZERO, 1.0)
    };
    let diagonal = if lo.x <= hi.x {
        (hi - lo).length()
    } else {
        1.0
    };
    let spacing = 1.25 * size.max(f64::MIN_POSITIVE);
    let offset = |k: usize| {
        glam::DVec3::new(
            (k % COLUMNS) as f64 * spacing,
            -((k / COLUMNS) as f64) * spacing,
            0.0,
        ) - centre
    };
    let stills: Vec<(f64, Vec<Polyline>)> = picture
        .stills
        .iter()
        .zip(curves)
        .map(|(s, c)| (s.slice.level, c.clone()))
        .collect();
    let asset = serde_json::json!({
        "surface": name,
        "direction": picture.critical.direction.to_array(),
        "frame": picture.frame.map(|e| e.to_array()),
    });
    crate::export::stills_glb(
        &stills,
        scene.outputs.curve_radius * diagonal,
        offset,
        &asset,
    )
    .map_err(|message| {
        SliceError::Build(Error::Internal {
            stage: "motion",
            message,
        })
    })
}

/// A staging failure as the build's error.
fn staged_error(e: StagedError) -> SliceError {
    SliceError::Build(crate::pipeline::staged_error(e))
}
