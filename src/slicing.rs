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
use crate::render::diagram;
use crate::render::text::compact;
use crate::sample::Source;
use crate::scene::Scene;
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
/// surface is sampled again, in turn, while its motion picture fails a check that a finer
/// mesh can pass: a coarse mesh has pairs of critical vertices where the surface has none,
/// and critical vertices in another order than the surface's critical levels.
const FINER: [f64; 3] = [2.5e-4, 6.25e-5, 1.5625e-5];

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
    /// The Euler characteristic checked against (`None`: the surface has a boundary and
    /// nothing is checked).
    pub euler: Option<i64>,
    /// (minima, saddles, maxima, degenerate).
    pub counts: [usize; 4],
    /// The critical points, by level.
    pub critical_points: Vec<motion::CriticalPoint>,
    /// Critical vertices of the mesh that Newton's method found no critical point from.
    pub not_refined: usize,
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

/// A surface sampled again, finer, for its motion picture.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Resampled {
    /// The adaptive sampler's tolerance, relative to the surface's 4D diagonal.
    pub relative_tolerance: f64,
    /// Its triangles.
    pub triangles: usize,
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
            let euler = s
                .euler
                .map_or("a surface with boundary: not checked".to_string(), |e| {
                    format!("χ = {e}")
                });
            if let Some(r) = s.resampled {
                out += &format!(
                    "{}: sampled again at {:e} of its diagonal ({} triangles) for the checks\n",
                    s.name, r.relative_tolerance, r.triangles
                );
            }
            out += &format!(
                "{}: {min} births, {saddle} saddles, {max} deaths{} ({euler}); components per interval {:?}\n",
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

/// Makes the motion pictures of every surface of `scene` along `slicing` (the scene's
/// `slicing`, or other settings) into `out` (files written under temporary names and moved
/// into place together); unless `quiet`, says on stderr when a surface is sampled again
/// and why.
pub fn slice_scene(
    scene: &Scene,
    slicing: Slicing,
    out: &Path,
    quiet: bool,
) -> Result<Motion, SliceError> {
    slicing
        .check()
        .map_err(|e| SliceError::Setting(e.within("slicing")))?;
    let (n, frame) = slicing.direction_and_frame(scene.view.rotation.matrix());
    let sampled = Sampled::of(scene);
    let staged = Staged::new(out).map_err(staged_error)?;
    let mut surfaces = Vec::new();
    let mut files = Vec::new();
    for ((name, mesh), entry) in sampled.meshes().zip(&scene.surfaces) {
        let (surface, shape) = match &entry.surface {
            Source::Parametric(s) => {
                let t = s.topology();
                let euler = if t.closed {
                    t.euler_characteristic
                } else {
                    None
                };
                (
                    Some(s),
                    Shape {
                        euler,
                        orientable: t.orientable,
                    },
                )
            }
            Source::Mesh(_) => {
                let stats = mesh.validate();
                let closed = stats.boundary_edges == 0 && stats.is_manifold();
                (
                    None,
                    Shape {
                        euler: closed.then_some(stats.euler_characteristic),
                        orientable: stats.orientation_conflicts == 0,
                    },
                )
            }
        };
        let cut = |mesh: &crate::sample::Mesh4| {
            motion::motion_picture(mesh, surface, n, frame, shape, slicing.levels)
                .map_err(SliceError::Setting)
        };
        let mut picture = cut(mesh)?;
        // The finer mesh made, with its relative tolerance, once the scene's fails.
        let mut finest: Option<(f64, crate::sample::Mesh4)> = None;
        if let Some(s) = surface {
            let diagonal = crate::sample::bounding_diagonal(s);
            for relative in FINER {
                // A degenerate direction stays degenerate on any mesh.
                if picture.failures.is_empty() || picture.critical.counts()[3] > 0 {
                    break;
                }
                if !quiet {
                    eprintln!(
                        "{name}: {}; sampling again at {relative:e} of its diagonal",
                        picture.failures[0]
                    );
                }
                let finer = crate::sample::sample_adaptive(s, relative * diagonal, FINER_TRIANGLES);
                let current = finest.as_ref().map_or(mesh, |f| &f.1);
                // A scene sampled finer already keeps its mesh.
                if finer.mesh.triangles.len() <= current.triangles.len() {
                    continue;
                }
                picture = cut(&finer.mesh)?;
                finest = Some((relative, finer.mesh));
            }
        }
        let (mut record, written) = write_surface(scene, name, &picture, shape, &staged)?;
        files.extend(written);
        record.resampled = finest.as_ref().map(|(relative_tolerance, m)| Resampled {
            relative_tolerance: *relative_tolerance,
            triangles: m.triangles.len(),
        });
        if slicing.film > 0 {
            let mesh = finest.as_ref().map_or(mesh, |f| &f.1);
            let (frames, failures, file) =
                write_film(scene, name, &picture, mesh, surface, slicing.film, &staged)?;
            record.film = frames;
            record.failures.extend(failures);
            files.push(file);
        }
        surfaces.push(record);
    }
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
        counts: critical.counts(),
        critical_points: critical.points.clone(),
        not_refined: critical.not_converged.len(),
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
