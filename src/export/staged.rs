//! All-or-nothing output: a build's files are written under temporary names and moved into
//! place together, only once every one of them was made, by one build at a time per folder.
//!
//! A build that fails (or is killed) before [`Staged::commit`] leaves the folder's previous
//! files as they were: its temporary files (`.<file>.partial`) are removed on failure, and a
//! killed build's are overwritten by the next. A lock file `.halo4d-build.lock` holding the
//! build's process id keeps a second build out of the folder while one is writing; a lock
//! whose process is gone (a killed build) is taken over.

use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// The lock file's name in the output folder.
pub const LOCK: &str = ".halo4d-build.lock";

/// Why the files could not be staged or moved into place.
#[derive(Debug, thiserror::Error)]
pub enum StagedError {
    /// Another build holds the folder's lock.
    #[error(
        "another halo4d build (process {pid}) is writing into {}; wait for it to finish, or delete {} if no build is running",
        dir.display(),
        lock.display()
    )]
    Busy {
        /// The output folder.
        dir: PathBuf,
        /// The lock file.
        lock: PathBuf,
        /// The process that holds it.
        pid: String,
    },
    /// A file or the folder could not be written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> StagedError + '_ {
    move |source| StagedError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// The files of one build in one folder, staged until [`Staged::commit`].
#[derive(Debug)]
pub struct Staged {
    dir: PathBuf,
    lock: PathBuf,
    /// (temporary, final) paths of the files written so far (files may be written from
    /// several threads at once).
    files: std::sync::Mutex<Vec<(PathBuf, PathBuf)>>,
}

impl Staged {
    /// Creates `dir` if needed and takes its lock.
    pub fn new(dir: &Path) -> Result<Staged, StagedError> {
        std::fs::create_dir_all(dir).map_err(io(dir))?;
        let lock = dir.join(LOCK);
        let pid = std::process::id().to_string();
        // The lock appears with its process id in it, or not at all: written under another
        // name, then linked to the lock's (which fails if the lock exists), so that a build
        // killed at any moment never leaves a lock without its id.
        let mine = dir.join(format!("{LOCK}.{pid}"));
        std::fs::write(&mine, &pid).map_err(io(&mine))?;
        let taken = link_lock(&mine, &lock, dir);
        let _ = std::fs::remove_file(&mine);
        taken.map(|()| Staged {
            dir: dir.to_path_buf(),
            lock,
            files: Default::default(),
        })
    }

    /// Writes `bytes` as `file` in the folder under a temporary name; returns `file`.
    pub fn write(&self, file: String, bytes: &[u8]) -> Result<String, StagedError> {
        self.stream(file, |w| w.write_all(bytes))
    }

    /// Writes `file` in the folder under a temporary name through `fill`, buffered, with
    /// no copy of the whole file in memory; returns `file`.
    pub fn stream(
        &self,
        file: String,
        fill: impl FnOnce(&mut dyn std::io::Write) -> std::io::Result<()>,
    ) -> Result<String, StagedError> {
        let path = self.dir.join(&file);
        let tmp = super::write_partial(&path, fill).map_err(io(&path))?;
        self.files
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .push((tmp, path));
        Ok(file)
    }

    /// Moves the files written so far into place, keeping the lock for more; `stale`, a
    /// file the build writes last, is removed from the folder first (so that the folder
    /// never holds a former build's `report.json` beside the new files).
    ///
    /// The former files are removed (side by side) before the new ones are renamed: a
    /// rename over a file makes ext4 allocate and start writing the new file's blocks there
    /// and then, which took three times as long as removing the former file first (0.7 s
    /// against 0.25 s for 238 MB).
    pub fn move_into_place(&self, stale: Option<&str>) -> Result<(), StagedError> {
        let mut files = self.files.lock().unwrap_or_else(|e| e.into_inner());
        let former: Vec<PathBuf> = stale
            .map(|file| self.dir.join(file))
            .into_iter()
            .chain(files.iter().map(|(_, path)| path.clone()))
            .collect();
        former
            .par_iter()
            .try_for_each(|path| match std::fs::remove_file(path) {
                Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(io(path)(e)),
                _ => Ok(()),
            })?;
        // Those moved leave the list; the others stay, for `Drop` to remove.
        let mut moved = 0;
        let renamed = files.iter().try_for_each(|(tmp, path)| {
            std::fs::rename(tmp, path).map_err(io(path))?;
            moved += 1;
            Ok(())
        });
        files.drain(..moved);
        renamed
    }

    /// Moves every file written into place, then releases the lock.
    pub fn commit(self) -> Result<(), StagedError> {
        self.move_into_place(None)
    }
}

impl Drop for Staged {
    /// Removes what was not committed, and the lock.
    fn drop(&mut self) {
        for (tmp, _) in self
            .files
            .get_mut()
            .unwrap_or_else(|e| e.into_inner())
            .iter()
        {
            let _ = std::fs::remove_file(tmp);
        }
        let _ = std::fs::remove_file(&self.lock);
    }
}

/// Links `mine` (a file holding this process's id) to `lock`, taking over a lock whose
/// process is gone.
fn link_lock(mine: &Path, lock: &Path, dir: &Path) -> Result<(), StagedError> {
    for attempt in 0..2 {
        match std::fs::hard_link(mine, lock) {
            Ok(()) => return Ok(()),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                let holder = std::fs::read_to_string(lock).unwrap_or_default();
                let holder = holder.trim().to_string();
                if attempt == 0 && !alive(&holder) {
                    // A killed build's lock: take it over.
                    let _ = std::fs::remove_file(lock);
                    continue;
                }
                return Err(StagedError::Busy {
                    dir: dir.to_path_buf(),
                    lock: lock.to_path_buf(),
                    pid: if holder.is_empty() {
                        "?".into()
                    } else {
                        holder
                    },
                });
            }
            Err(e) => return Err(io(lock)(e)),
        }
    }
    unreachable!("the second attempt takes the lock or returns")
}

/// Whether the process `pid` (as a lock file holds it) runs. Where that cannot be told (no
/// `/proc`) it counts as running, and the message says to delete the lock. A lock without a
/// process id is no build's: ours appear with theirs.
fn alive(pid: &str) -> bool {
    match pid.parse::<u32>() {
        Ok(p) if Path::new("/proc/self").exists() => Path::new(&format!("/proc/{p}")).exists(),
        Ok(_) => true,
        Err(_) => false,
    }
}
