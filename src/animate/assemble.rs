//! A folder's status (`halo4d animate --status`), and its frames assembled into one
//! animated PNG (`--assemble`).
//!
//! The animation is an APNG, written by the `png` crate (which `image` uses to write every
//! picture): lossless, so the frames' thin curves and colour bar stay as drawn (a GIF's 256
//! colours would band the w colours), and shown by every current browser. The frames are
//! read and written one at a time, so a long animation never is in memory whole. For an
//! MP4, the command line for ffmpeg is given.

use super::{AnimateError, MANIFEST, frame_file, gather, io, read_manifest, read_record};
use crate::export;
use std::path::{Path, PathBuf};

/// The animation's file in the folder.
pub const ANIMATION: &str = "animation.png";

/// Where the frames of a folder stand.
#[derive(Clone, Debug, PartialEq)]
pub struct Status {
    /// The folder.
    pub dir: PathBuf,
    /// The scene's name.
    pub scene: String,
    /// Frames of the animation.
    pub frames: u32,
    /// Frames per second.
    pub fps: u32,
    /// The pictures' size.
    pub size: (u32, u32),
    /// Frames done and verified.
    pub done: Vec<u32>,
    /// Frames done but not verified, with why.
    pub failed: Vec<(u32, String)>,
    /// Frames without a record.
    pub missing: Vec<u32>,
    /// Milliseconds each frame with a record took.
    pub frame_ms: Vec<f64>,
}

impl Status {
    /// Whether every frame is done and verified.
    pub fn complete(&self) -> bool {
        self.failed.is_empty() && self.missing.is_empty()
    }

    /// What `halo4d animate --status` prints.
    pub fn text(&self) -> String {
        let mut out = format!(
            "{}: {} frames of scene `{}` ({} x {}, {} fps)\n",
            self.dir.display(),
            self.frames,
            crate::limits::shorten(&self.scene),
            self.size.0,
            self.size.1,
            self.fps
        );
        out += &format!("done and verified: {}\n", self.done.len());
        out += &format!("failed: {}", self.failed.len());
        for (k, why) in self.failed.iter().take(10) {
            out += &format!("\n  frame {k}: {}", crate::limits::shorten(why));
        }
        if self.failed.len() > 10 {
            out += &format!("\n  and {} more", self.failed.len() - 10);
        }
        out += &format!("\nmissing: {}", self.missing.len());
        if !self.missing.is_empty() {
            out += &format!(" ({})", ranges(&self.missing));
        }
        out += "\n";
        if !self.frame_ms.is_empty() {
            let mean = self.frame_ms.iter().sum::<f64>() / self.frame_ms.len() as f64;
            out += &format!(
                "a frame took {:.2} s on average; the missing frames need about {} of one process\n",
                mean / 1e3,
                super::duration(mean / 1e3 * self.missing.len() as f64)
            );
        }
        out
    }
}

/// Frame indices as ranges: `0-3, 7, 9-12`, at most 20 of them.
fn ranges(frames: &[u32]) -> String {
    let mut runs: Vec<(u32, u32)> = Vec::new();
    for &k in frames {
        match runs.last_mut() {
            Some((_, end)) if *end + 1 == k => *end = k,
            _ => runs.push((k, k)),
        }
    }
    let mut parts: Vec<String> = runs
        .iter()
        .take(20)
        .map(|&(a, b)| {
            if a == b {
                a.to_string()
            } else {
                format!("{a}-{b}")
            }
        })
        .collect();
    if runs.len() > 20 {
        parts.push(format!("and {} more runs", runs.len() - 20));
    }
    parts.join(", ")
}

/// Reads where the frames of the folder `dir` stand.
pub fn status(dir: &Path) -> Result<Status, AnimateError> {
    let manifest = read_manifest(dir)?;
    let (frames, fps, width, height) = manifest.numbers().ok_or_else(|| AnimateError::Folder {
        dir: dir.to_path_buf(),
        message: format!("{MANIFEST} does not record an animated scene"),
    })?;
    let mut status = Status {
        dir: dir.to_path_buf(),
        scene: manifest.scene["name"].as_str().unwrap_or("").to_string(),
        frames,
        fps,
        size: (width, height),
        done: Vec::new(),
        failed: Vec::new(),
        missing: Vec::new(),
        frame_ms: Vec::new(),
    };
    for k in 0..frames {
        match read_record(dir, k) {
            Some(r) => {
                status.frame_ms.push(r.timings_ms.total);
                if r.verified {
                    status.done.push(k);
                } else {
                    status.failed.push((k, r.failures.join("; ")));
                }
            }
            None => status.missing.push(k),
        }
    }
    Ok(status)
}

/// What [`assemble`] wrote.
#[derive(Clone, Debug, PartialEq)]
pub struct Assembled {
    /// The animated PNG.
    pub path: PathBuf,
    /// Its frames.
    pub frames: u32,
    /// Its size in bytes.
    pub bytes: u64,
    /// The command line that makes an MP4 of the frames with ffmpeg.
    pub ffmpeg: String,
    /// Whether `ffmpeg` is on the PATH.
    pub ffmpeg_found: bool,
}

/// Checks that every frame of the folder is there and verified (an
/// [`AnimateError::Incomplete`] with the folder's status otherwise), removes what killed
/// processes left, writes `frames.jsonl` and the animated PNG `animation.png`, and gives the
/// ffmpeg command line for an MP4.
pub fn assemble(dir: &Path) -> Result<Assembled, AnimateError> {
    let status = status(dir)?;
    if !status.complete() {
        return Err(AnimateError::Incomplete(status.text()));
    }
    // No process writes into the folder now: temporary files are leftovers.
    if let Ok(entries) = std::fs::read_dir(dir) {
        for entry in entries.flatten() {
            let name = entry.file_name().to_string_lossy().into_owned();
            if name.starts_with('.') && name.ends_with(".partial") {
                let _ = std::fs::remove_file(entry.path());
            }
        }
    }
    gather(dir, status.frames)?;
    let path = dir.join(ANIMATION);
    let (width, height) = status.size;
    export::write_atomic_shared(&path, |w| {
        export::write_apng(w, (width, height), status.fps, status.frames, |k| {
            let file = frame_file(k, "png");
            let frame = image::open(dir.join(&file))
                .map_err(|e| std::io::Error::other(format!("{file}: {e}")))?
                .to_rgb8();
            if frame.dimensions() != (width, height) {
                return Err(std::io::Error::other(format!(
                    "{file} is {} x {}, not the animation's {width} x {height}",
                    frame.width(),
                    frame.height()
                )));
            }
            Ok(frame.into_raw())
        })
    })
    .map_err(io(&path))?;
    let bytes = std::fs::metadata(&path).map_err(io(&path))?.len();
    let quote = |p: &Path| {
        let s = p.display().to_string();
        if s.chars()
            .all(|c| c.is_ascii_alphanumeric() || "/._-".contains(c))
        {
            s
        } else {
            format!("'{}'", s.replace('\'', r"'\''"))
        }
    };
    let ffmpeg = format!(
        "ffmpeg -framerate {} -i {} -c:v libx264 -pix_fmt yuv420p -vf 'pad=ceil(iw/2)*2:ceil(ih/2)*2' {}",
        status.fps,
        quote(&dir.join("frame-%05d.png")),
        quote(&dir.join("animation.mp4"))
    );
    let ffmpeg_found = std::env::var_os("PATH")
        .is_some_and(|paths| std::env::split_paths(&paths).any(|p| p.join("ffmpeg").is_file()));
    Ok(Assembled {
        path,
        frames: status.frames,
        bytes,
        ffmpeg,
        ffmpeg_found,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_lists_read_as_ranges() {
        assert_eq!(ranges(&[0, 1, 2, 3, 7, 9, 10]), "0-3, 7, 9-10");
        let many: Vec<u32> = (0..100).map(|k| 2 * k).collect();
        assert!(ranges(&many).ends_with("and 80 more runs"));
    }
}
