//! The pipeline's error type: bad input apart from internal failures, each saying how to
//! fix it.

use crate::limits::shorten;
use crate::scene::SceneError;
use crate::view::BehindEye;
use std::path::PathBuf;

/// Everything that can stop a build.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The scene file is unreadable or invalid.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// The view puts a surface at or behind the 4D eye.
    #[error("surface `{}` in the view of scene `{}`: {source}", shorten(.surface), shorten(.scene))]
    View {
        /// The scene.
        scene: String,
        /// The surface.
        surface: String,
        /// The offending vertex.
        source: BehindEye,
    },
    /// The scene leaves its view to the view search, which has not run.
    #[error(
        "scene `{}`: its view is \"auto\", which the view search finds before a build (halo4d::resolve_view; halo4d build, render, animate and gallery run it)",
        shorten(.scene)
    )]
    UnresolvedView {
        /// The scene.
        scene: String,
    },
    /// The scene's numbers are finite but put its geometry where the files' f32 or the exact
    /// predicates cannot follow (too large or too small), or so many triangles that the
    /// build would need more memory than the limit
    /// (`HALO4D_MAX_MEMORY` gigabytes, or three quarters of the machine's memory).
    #[error("scene `{}`: {message}", shorten(.scene))]
    Scale {
        /// The scene.
        scene: String,
        /// What is out of range, and what to change.
        message: String,
    },
    /// The picture could not be made (a camera inside the scene, a bad setting).
    #[error("scene `{}`: {source}", shorten(.scene))]
    Render {
        /// The scene.
        scene: String,
        /// The cause.
        source: crate::render::RenderError,
    },
    /// An output could not be written.
    #[error("cannot write {}: {source}; check that the output folder is writable (choose another with --out)", path.display())]
    Write {
        /// The file or folder.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The build would take far longer than a build of its size: its triangles are slivers
    /// whose boxes pile up, or its halos overlap themselves many times over (they keep
    /// their folds), so every query of the curves, the verification and the picture tests
    /// hundreds of them.
    #[error("scene `{}`: {message}", shorten(.scene))]
    Work {
        /// The scene.
        scene: String,
        /// What makes it slow, and what to change.
        message: String,
    },
    /// Another build is writing into the output folder.
    #[error(transparent)]
    Busy(crate::export::StagedError),
    /// The caller cancelled the build ([`crate::progress::Cancel`]): Ctrl-C, a timeout, a
    /// closed window. Nothing of it was written.
    #[error(transparent)]
    Cancelled(#[from] crate::progress::Cancelled),
    /// A stage produced something it must not (a bug, not bad input).
    #[error("internal error in stage {stage}: {message}")]
    Internal {
        /// The stage.
        stage: &'static str,
        /// What went wrong.
        message: String,
    },
}

impl Error {
    /// A picture's error as the build's: a cancelled picture is a cancelled build.
    pub(crate) fn render(scene: &str, source: crate::render::RenderError) -> Error {
        match source {
            crate::render::RenderError::Cancelled(c) => Error::Cancelled(c),
            source => Error::Render {
                scene: scene.to_string(),
                source,
            },
        }
    }
}
