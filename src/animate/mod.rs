//! `halo4d animate`: the frames of a scene's animation, each the verified build of the scene
//! in that frame's view, in a folder that any number of processes fill side by side.
//!
//! Takes: a scene with an `animation`, the frames to make (a range, a shard `I/N` of a batch
//! engine's array) and a folder. Gives: per frame `frame-00042.png` (and `.glb` on request)
//! and its record `frame-00042.json` (time, view, camera, counts, verification, timings);
//! `frames.jsonl`, the records one per line in frame order, once every frame is there; the
//! folder's status and the assembled animation ([`assemble`]).
//!
//! Guarantees:
//! - frame k is what `halo4d render` draws of the scene with frame k's view and camera (the
//!   scene's [`Scene::frame`]), whichever process makes it and however the frames are
//!   sharded: the mesh is sampled once per process, the same way in each;
//! - a file is whole or absent: each is written under a temporary name and renamed, the
//!   record last, so a frame is done exactly when its record is there; a killed process
//!   leaves whole frames and, at most, temporary files of the frames it was making, which
//!   the next process to make those frames removes;
//! - a rerun makes only the frames without a record;
//! - processes never write the same file with different bytes: frame files belong to one
//!   frame, and the folder's shared files (`animation.json`, `frames.jsonl`) are the same
//!   from every process, each renamed from a temporary file of its own. Nothing is
//!   appended, so the folder may be on a network file system that all the machines share.
//!
//! No scheduler of its own: `--shard I/N` takes the frames whose index modulo N is I, so a
//! Slurm array (`$SLURM_ARRAY_TASK_ID`), a Kubernetes Indexed Job (`$JOB_COMPLETION_INDEX`)
//! or GNU parallel maps its task index onto it (the README's recipes).

mod assemble;

pub use crate::animation::{Animation, CameraKey, Keyframe, RotationKey, ViewKey};
pub use assemble::{Assembled, Status, assemble, status};

use crate::error::Error;
use crate::export;
use crate::limits::{Bound, FieldError, SHARDS};
use crate::pipeline::{self, Sampled, Stages, Timings};
use crate::progress::{Cancel, Cancelled, Job, Silent, Task};
use crate::render::{self, CameraSettings};
use crate::scene::Scene;
use crate::view::View;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::str::FromStr;
use std::time::Instant;

/// The folder's description of its animation: the scene it is made from.
pub const MANIFEST: &str = "animation.json";

/// The records of every frame, one JSON object per line in frame order.
pub const RECORDS: &str = "frames.jsonl";

/// The file name of frame `k`'s `ext` file (`frame-00042.png`).
pub fn frame_file(k: u32, ext: &str) -> String {
    format!("frame-{k:05}.{ext}")
}

/// Which of the frames a process makes: those whose index modulo `count` is `index`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    /// This process's index, below `count`.
    pub index: u32,
    /// How many processes share the frames.
    pub count: u32,
}

impl Shard {
    /// All frames in one process.
    pub const ALL: Shard = Shard { index: 0, count: 1 };

    /// Whether frame `k` is this shard's.
    pub fn has(&self, k: u32) -> bool {
        k % self.count == self.index
    }
}

impl FromStr for Shard {
    type Err = String;

    /// `I/N`, with N at least 1 and I below N.
    fn from_str(s: &str) -> Result<Shard, String> {
        let usage = || {
            format!(
                "`{}` is not a shard: write I/N, the index I (0 to N - 1) of this process among N, as in 2/4",
                crate::limits::shorten(s)
            )
        };
        let (i, n) = s.split_once('/').ok_or_else(usage)?;
        let (index, count): (u32, u32) = (
            i.trim().parse().map_err(|_| usage())?,
            n.trim().parse().map_err(|_| usage())?,
        );
        let shown = crate::limits::shorten(s);
        SHARDS
            .check("N", count)
            .and_then(|()| {
                Bound::closed(0, count - 1, "").check_with(
                    "I",
                    index,
                    "the index counts from 0, below the number of shards N",
                )
            })
            .map_err(|e| format!("`{shown}`: {e}"))?;
        Ok(Shard { index, count })
    }
}

/// A range of frame indices, `start` included, `end` not.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameRange {
    /// The first frame.
    pub start: u32,
    /// The frame after the last.
    pub end: u32,
}

impl FromStr for FrameRange {
    type Err = String;

    /// `A..B` (A to B - 1), `A..=B` (A to B) or `A` (that frame alone).
    fn from_str(s: &str) -> Result<FrameRange, String> {
        let usage = || {
            format!(
                "`{}` is not a range of frames: write A..B (frames A to B - 1), A..=B (A to B) or A",
                crate::limits::shorten(s)
            )
        };
        let number = |t: &str| t.trim().parse::<u32>().map_err(|_| usage());
        let (start, end) = if let Some((a, b)) = s.split_once("..=") {
            (number(a)?, number(b)?.checked_add(1).ok_or_else(usage)?)
        } else if let Some((a, b)) = s.split_once("..") {
            (number(a)?, number(b)?)
        } else {
            let a = number(s)?;
            (a, a.checked_add(1).ok_or_else(usage)?)
        };
        if start >= end {
            return Err(format!(
                "`{s}` holds no frame: the end must be after the start"
            ));
        }
        Ok(FrameRange { start, end })
    }
}

/// What to animate and where.
#[derive(Clone, Copy, Debug)]
pub struct Request<'a> {
    /// The scene, with its `animation`.
    pub scene: &'a Scene,
    /// The folder of the frames.
    pub out: &'a Path,
    /// Only these frames (all when `None`).
    pub frames: Option<FrameRange>,
    /// Only this shard's frames.
    pub shard: Shard,
    /// Write each frame's `.glb` too.
    pub glb: bool,
}

/// Why frames could not be made or read (a frame whose build fails is not one: its record
/// says why, and the run goes on).
#[derive(Debug, thiserror::Error)]
pub enum AnimateError {
    /// The scene has no animation.
    #[error(
        "scene `{}` has no `animation`; add one, for example \"animation\": {{\"frames\": 24, \"keyframes\": [{{\"time\": 0}}, {{\"time\": 1, \"view\": {{\"rotation\": {{\"yw\": 360}}}}}}]}}",
        crate::limits::shorten(.0)
    )]
    NoAnimation(String),
    /// A flag is out of range.
    #[error("{0}")]
    Flag(FieldError),
    /// The folder holds something else, or is not an animation's folder.
    #[error("{}: {message}", dir.display())]
    Folder {
        /// The folder.
        dir: PathBuf,
        /// What is wrong and what to do.
        message: String,
    },
    /// `--assemble` on a folder whose frames are not all there and verified.
    #[error("not every frame is done and verified:\n{0}")]
    Incomplete(String),
    /// A file could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The caller cancelled the run: the frames done before are kept, the one under way
    /// is not written.
    #[error("the animation {0}")]
    Cancelled(#[from] Cancelled),
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> AnimateError + '_ {
    move |source| AnimateError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// `animation.json`: the scene a folder's frames are made from.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// The halo4d version that began the folder.
    pub halo4d: String,
    /// The scene, its animation and picture size included.
    pub scene: serde_json::Value,
}

impl Manifest {
    /// The animation's frame count, frames per second and picture size, read from the
    /// recorded scene.
    pub fn numbers(&self) -> Option<(u32, u32, u32, u32)> {
        let s = &self.scene;
        let u = |v: &serde_json::Value| v.as_u64().and_then(|n| u32::try_from(n).ok());
        Some((
            u(&s["animation"]["frames"])?,
            u(&s["animation"]["fps"])?,
            u(&s["render"]["width"])?,
            u(&s["render"]["height"])?,
        ))
    }
}

/// One frame's record (`frame-00042.json`, a line of `frames.jsonl`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FrameRecord {
    /// The frame's index.
    pub frame: u32,
    /// Its time in [0, 1].
    pub time: f64,
    /// Its 4D view.
    pub view: View,
    /// Its camera.
    pub camera: CameraSettings,
    /// Whether its build is verified.
    pub verified: bool,
    /// What keeps it from being verified: the build's verdict, or the error that stopped
    /// it.
    pub failures: Vec<String>,
    /// Surface triangles.
    pub triangles: usize,
    /// Halo tetrahedra.
    pub halo_tetrahedra: usize,
    /// Intersection curves (those the picture shows).
    pub curves: usize,
    /// Their points.
    pub curve_points: usize,
    /// The halos' verification against the curves (`report.json`'s `halo_verification`).
    pub verification: Option<serde_json::Value>,
    /// Milliseconds per stage: `export` is writing the frame's files, `total` the whole
    /// frame; `sample` and `audit` are 0, the surfaces being sampled once per process.
    pub timings_ms: Timings,
    /// Its files in the folder, the record's own last.
    pub files: Vec<String>,
}

/// What a run did.
#[derive(Clone, Debug, Default)]
pub struct Summary {
    /// The frames this run was given (its range and shard).
    pub selected: usize,
    /// Of those, already done by an earlier run.
    pub skipped: usize,
    /// Made by this run.
    pub made: usize,
    /// The given frames that are not verified, with why (made now or before).
    pub failed: Vec<(u32, String)>,
    /// Milliseconds sampling the surfaces.
    pub sample_ms: f64,
    /// Milliseconds of the whole run.
    pub ms: f64,
}

/// Makes the frames of `request` that are not yet done: the scene sampled once, then per
/// frame the build in its view, verified, its picture and record. See the module's
/// guarantees.
pub fn animate(request: &Request, job: Job) -> Result<Summary, AnimateError> {
    let start = Instant::now();
    let scene = request.scene;
    let animation = scene
        .animation
        .as_ref()
        .ok_or_else(|| AnimateError::NoAnimation(scene.name.clone()))?;
    let all = FrameRange {
        start: 0,
        end: animation.frames,
    };
    let range = request.frames.unwrap_or(all);
    if range.end > all.end {
        return Err(AnimateError::Flag(FieldError::new(
            "--frames",
            format!(
                "{}..{} goes past the animation's {} frames (0..{})",
                range.start, range.end, all.end, all.end
            ),
        )));
    }
    let dir = request.out;
    std::fs::create_dir_all(dir).map_err(io(dir))?;
    claim(dir, scene)?;
    let selected: Vec<u32> = (range.start..range.end)
        .filter(|&k| request.shard.has(k))
        .collect();
    // What a killed process left of these frames.
    for &k in &selected {
        for ext in ["png", "glb", "json"] {
            let _ = std::fs::remove_file(dir.join(format!(".{}.partial", frame_file(k, ext))));
        }
    }
    let mut summary = Summary {
        selected: selected.len(),
        ..Summary::default()
    };
    let mut todo = Vec::new();
    for &k in &selected {
        match read_record(dir, k) {
            Some(r) => {
                summary.skipped += 1;
                if !r.verified {
                    summary.failed.push((k, r.failures.join("; ")));
                }
            }
            None => todo.push(k),
        }
    }
    let progress = Progress::new(job, todo.len(), summary.skipped);
    if !todo.is_empty() {
        progress.note(&format!(
            "{} frames to make of {} in this run ({} already done); sampling the surfaces",
            todo.len(),
            selected.len(),
            summary.skipped
        ));
        let sampled = Instant::now();
        let samples = Sampled::sample(scene, job).map_err(|e| match e {
            Error::Cancelled(c) => AnimateError::Cancelled(c),
            e => AnimateError::Folder {
                dir: dir.to_path_buf(),
                message: e.to_string(),
            },
        })?;
        summary.sample_ms = ms(sampled);
        progress.note(&format!(
            "sampled {} triangles in {:.1} s",
            samples.triangles(),
            summary.sample_ms / 1e3
        ));
        for &k in &todo {
            let record = make_frame(scene, k, &samples, dir, request.glb, job.cancel())?;
            summary.made += 1;
            if !record.verified {
                summary.failed.push((k, record.failures.join("; ")));
            }
            progress.frame(&record);
        }
    }
    drop(progress);
    summary.failed.sort_by_key(|f| f.0);
    gather(dir, animation.frames)?;
    summary.ms = ms(start);
    Ok(summary)
}

/// Makes the folder this scene's, or checks that it is: its `animation.json` records the
/// scene, and a folder of another scene's frames is refused.
fn claim(dir: &Path, scene: &Scene) -> Result<(), AnimateError> {
    let path = dir.join(MANIFEST);
    let json = serde_json::to_value(scene).map_err(|e| AnimateError::Folder {
        dir: dir.to_path_buf(),
        message: format!("cannot record the scene: {e}"),
    })?;
    match read_manifest(dir) {
        Ok(m) if m.scene == json => Ok(()),
        Ok(m) => {
            let differs = json
                .as_object()
                .into_iter()
                .flatten()
                .find(|(key, value)| m.scene.get(key.as_str()) != Some(value))
                .map(|(key, _)| key.clone())
                .or_else(|| {
                    m.scene
                        .as_object()
                        .into_iter()
                        .flatten()
                        .map(|(key, _)| key.clone())
                        .find(|key| json.get(key.as_str()).is_none())
                })
                .unwrap_or_default();
            Err(AnimateError::Folder {
                dir: dir.to_path_buf(),
                message: format!(
                    "holds the frames of another scene (its {MANIFEST} differs from this scene in `{differs}`); give another --out, or delete the folder to start again"
                ),
            })
        }
        Err(AnimateError::Io { source, .. }) if source.kind() == std::io::ErrorKind::NotFound => {
            let manifest = Manifest {
                halo4d: env!("CARGO_PKG_VERSION").to_string(),
                scene: json,
            };
            let text = serde_json::to_vec_pretty(&manifest).map_err(|e| AnimateError::Folder {
                dir: dir.to_path_buf(),
                message: format!("cannot record the scene: {e}"),
            })?;
            export::write_atomic_shared(&path, |w| w.write_all(&text)).map_err(io(&path))
        }
        Err(e) => Err(e),
    }
}

/// Reads a folder's `animation.json`.
pub fn read_manifest(dir: &Path) -> Result<Manifest, AnimateError> {
    let path = dir.join(MANIFEST);
    let text = std::fs::read(&path).map_err(io(&path))?;
    serde_json::from_slice(&text).map_err(|e| AnimateError::Folder {
        dir: dir.to_path_buf(),
        message: format!("{MANIFEST} is not an animation's description: {e}"),
    })
}

/// Frame `k`'s record, when it is done: its record reads, and its picture is there.
pub fn read_record(dir: &Path, k: u32) -> Option<FrameRecord> {
    read_done(dir, k).map(|(record, _)| record)
}

/// [`read_record`] with the record's bytes as written.
fn read_done(dir: &Path, k: u32) -> Option<(FrameRecord, Vec<u8>)> {
    let text = std::fs::read(dir.join(frame_file(k, "json"))).ok()?;
    let record: FrameRecord = serde_json::from_slice(&text).ok()?;
    let whole = record.frame == k && record.files.iter().all(|f| dir.join(f).is_file());
    whole.then_some((record, text))
}

/// Makes frame `k`: its build from the samples in its view, its files, its record last.
fn make_frame(
    scene: &Scene,
    k: u32,
    samples: &Sampled,
    dir: &Path,
    glb: bool,
    cancel: &Cancel,
) -> Result<FrameRecord, AnimateError> {
    let start = Instant::now();
    let animation = scene.animation.as_ref().expect("an animated scene");
    let frame = scene.frame(k).expect("a frame of the animation");
    let mut record = FrameRecord {
        frame: k,
        time: animation.time(k),
        view: frame.view,
        camera: frame.camera,
        verified: false,
        failures: Vec::new(),
        triangles: samples.triangles(),
        halo_tetrahedra: 0,
        curves: 0,
        curve_points: 0,
        verification: None,
        timings_ms: Timings::default(),
        files: Vec::new(),
    };
    // The run's own task says how the frames go; a frame's build says nothing.
    let silent = Job::new(&Silent, cancel);
    let made = (samples.clone())
        .into_built_with(&frame, Stages::verified_picture(&frame), silent)
        .and_then(|built| {
            let rendered = Instant::now();
            let parts = built.parts(&frame.halo);
            let picture = render::render_until(&parts, &frame.render, &frame.camera, cancel)
                .map_err(|source| Error::render(&frame.name, source))?;
            Ok((built, picture, ms(rendered)))
        });
    let (built, picture, render_ms) = match made {
        Ok(made) => made,
        Err(Error::Cancelled(c)) => return Err(c.into()),
        Err(e) => {
            // The frame cannot be built in its view (an eye inside the surfaces, a scale
            // beyond the files' precision): its record says so, and the run goes on.
            record.failures.push(e.to_string());
            record.timings_ms.total = ms(start);
            return write_record(dir, record);
        }
    };
    let files_start = Instant::now();
    let png = frame_file(k, "png");
    write_frame_file(dir, &png, &picture.png())?;
    record.files.push(png);
    if glb {
        let name = frame_file(k, "glb");
        let bytes = pipeline::glb_bytes(&frame, &built).map_err(|e| AnimateError::Folder {
            dir: dir.to_path_buf(),
            message: format!("frame {k}: {e}"),
        })?;
        write_frame_file(dir, &name, &bytes)?;
        record.files.push(name);
    }
    record.timings_ms = Timings {
        sample: 0.0,
        audit: 0.0,
        render: render_ms,
        export: ms(files_start),
        total: ms(start),
        ..built.timings
    };
    record.failures = built.failures();
    record.verified = record.failures.is_empty();
    record.halo_tetrahedra = built.surfaces.iter().map(|s| s.halo.tets.len()).sum();
    let curves = built.shown_curves();
    record.curves = curves.curves.len();
    record.curve_points = curves.curves.iter().map(|c| c.points.len()).sum();
    record.verification = serde_json::to_value(&built.verification).ok();
    write_record(dir, record)
}

fn ms(since: Instant) -> f64 {
    since.elapsed().as_secs_f64() * 1e3
}

fn write_frame_file(dir: &Path, name: &str, bytes: &[u8]) -> Result<(), AnimateError> {
    let path = dir.join(name);
    export::write_atomic(&path, bytes).map_err(io(&path))
}

/// Writes a frame's record, which makes the frame done.
fn write_record(dir: &Path, mut record: FrameRecord) -> Result<FrameRecord, AnimateError> {
    let name = frame_file(record.frame, "json");
    record.files.push(name.clone());
    let mut line = serde_json::to_vec(&record).map_err(|e| AnimateError::Folder {
        dir: dir.to_path_buf(),
        message: format!("frame {}: cannot write its record: {e}", record.frame),
    })?;
    line.push(b'\n');
    write_frame_file(dir, &name, &line)?;
    Ok(record)
}

/// Writes `frames.jsonl` when every frame of the folder's `frames` has its record; says
/// whether it did.
fn gather(dir: &Path, frames: u32) -> Result<bool, AnimateError> {
    let mut lines = Vec::new();
    for k in 0..frames {
        let Some((_, text)) = read_done(dir, k) else {
            return Ok(false);
        };
        lines.extend(text);
    }
    let path = dir.join(RECORDS);
    export::write_atomic_shared(&path, |w| w.write_all(&lines)).map_err(io(&path))?;
    Ok(true)
}

/// A run's progress, a task `"animation"` of the run's job, a step per frame made: a note
/// per frame (its verdict, the rate and the time left), the time left as what it is doing.
struct Progress<'a> {
    task: Task<'a>,
    start: Instant,
    total: usize,
}

impl<'a> Progress<'a> {
    fn new(job: Job<'a>, total: usize, skipped: usize) -> Progress<'a> {
        let task = job.task("animation", total as u64);
        task.doing(&format!("({skipped} done before)"));
        Progress {
            task,
            start: Instant::now(),
            total,
        }
    }

    fn note(&self, text: &str) {
        self.task.job().note(text);
    }

    /// A frame is done.
    fn frame(&self, record: &FrameRecord) {
        let done = self.task.done() as usize + 1;
        let minutes = self.start.elapsed().as_secs_f64() / 60.0;
        let rate = done as f64 / minutes.max(1e-9);
        let left = (self.total - done) as f64 / rate;
        let eta = format!(
            "{rate:.1} frames/min, {} left, about {} more (ends {} UTC)",
            self.total - done,
            duration(left * 60.0),
            clock_in(left * 60.0)
        );
        let verdict = if record.verified {
            "verified".to_string()
        } else {
            format!("NOT verified: {}", record.failures.join("; "))
        };
        self.note(&format!(
            "frame {} ({done} of {}) in {:.1} s: {verdict}; {eta}",
            record.frame,
            self.total,
            record.timings_ms.total / 1e3
        ));
        self.task.doing(&eta);
        self.task.step();
    }
}

/// Seconds as `1 h 02 min`, `3 min 05 s` or `12 s`.
fn duration(seconds: f64) -> String {
    let s = seconds.max(0.0).round() as u64;
    match s {
        0..60 => format!("{s} s"),
        60..3600 => format!("{} min {:02} s", s / 60, s % 60),
        _ => format!("{} h {:02} min", s / 3600, s / 60 % 60),
    }
}

/// The UTC time of day `seconds` from now, `HH:MM`.
fn clock_in(seconds: f64) -> String {
    let now = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0.0, |d| d.as_secs_f64());
    let t = (now + seconds.max(0.0)) as u64;
    format!("{:02}:{:02}", t / 3600 % 24, t / 60 % 60)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_and_ranges_parse_and_refuse_what_they_must() {
        assert_eq!("2/4".parse(), Ok(Shard { index: 2, count: 4 }));
        assert_eq!("0/1".parse(), Ok(Shard::ALL));
        for bad in ["4/4", "1/0", "2", "a/4", "-1/4", "2/4/1", ""] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
        assert_eq!("3..7".parse(), Ok(FrameRange { start: 3, end: 7 }));
        assert_eq!("3..=7".parse(), Ok(FrameRange { start: 3, end: 8 }));
        assert_eq!("5".parse(), Ok(FrameRange { start: 5, end: 6 }));
        for bad in [
            "7..3",
            "3..3",
            "a..4",
            "..4",
            "4294967295",
            "1..=4294967295",
        ] {
            assert!(bad.parse::<FrameRange>().is_err(), "{bad}");
        }
        // The shards of N cover every frame exactly once.
        for n in 1..6 {
            for k in 0..50 {
                let owners = (0..n).filter(|&i| Shard { index: i, count: n }.has(k));
                assert_eq!(owners.count(), 1);
            }
        }
    }

    #[test]
    fn durations_read_as_people_write_them() {
        assert_eq!(duration(12.4), "12 s");
        assert_eq!(duration(185.0), "3 min 05 s");
        assert_eq!(duration(3720.0), "1 h 02 min");
    }
}
