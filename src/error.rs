//! The pipeline's error type: bad input apart from internal failures, each saying how to
//! fix it.

use crate::scene::SceneError;
use crate::view::BehindEye;
use std::path::PathBuf;

/// The most bytes of one run of text without whitespace an error message echoes.
const ECHO_RUN: usize = 60;

/// The most bytes of user text one error message echoes.
const ECHO_TOTAL: usize = 300;

/// User text (a name, a key, a line of a file) as an error message echoes it: a run of
/// more than 60 bytes without whitespace, and text of more than 300 bytes, keep their ends
/// (whole characters) and say how much was left out, so that a long name or binary data
/// read as text cannot bury the message.
pub fn shorten(text: &str) -> String {
    fn cut(s: &str, keep: usize) -> String {
        if s.len() <= keep {
            return s.to_string();
        }
        let mut head = keep / 2;
        while !s.is_char_boundary(head) {
            head -= 1;
        }
        let mut tail = s.len() - keep / 2;
        while !s.is_char_boundary(tail) {
            tail += 1;
        }
        format!(
            "{}...({} bytes left out)...{}",
            &s[..head],
            tail - head,
            &s[tail..]
        )
    }
    let mut out = String::with_capacity(text.len().min(2 * ECHO_TOTAL));
    let mut run = String::new();
    for c in text.chars().chain(std::iter::once(' ')) {
        if c.is_whitespace() {
            out.push_str(&cut(&run, ECHO_RUN));
            run.clear();
            out.push(c);
        } else {
            run.push(c);
        }
    }
    out.pop();
    cut(&out, ECHO_TOTAL)
}

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
    /// The scene's numbers are finite but put its geometry where the files' f32 or the exact
    /// predicates cannot follow (too large or too small), or so many triangles that the
    /// stages from the halos on would need more memory than the limit
    /// ([`crate::memory::limit`]).
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
    /// Another build is writing into the output folder.
    #[error(transparent)]
    Busy(crate::export::StagedError),
    /// A stage produced something it must not (a bug, not bad input).
    #[error("internal error in stage {stage}: {message}")]
    Internal {
        /// The stage.
        stage: &'static str,
        /// What went wrong.
        message: String,
    },
}

#[cfg(test)]
mod tests {
    use super::shorten;

    #[test]
    fn long_runs_and_long_texts_keep_their_ends() {
        assert_eq!(shorten("a short message"), "a short message");
        let long = format!("name `{}` is bad", "x".repeat(1000));
        let s = shorten(&long);
        assert!(s.starts_with("name `xxx") && s.ends_with("` is bad"), "{s}");
        assert!(s.contains("(942 bytes left out)"), "{s}");
        let emoji = "\u{1F600} ".repeat(400);
        let s = shorten(&emoji);
        assert!(s.len() < 400 && s.is_char_boundary(s.len()), "{s}");
        let words = "word ".repeat(500);
        let s = shorten(words.trim_end());
        assert!(
            s.len() < 500 && s.starts_with("word word") && s.ends_with("word"),
            "{s}"
        );
        assert_eq!(
            shorten("tabs\tand\nnewlines  stay"),
            "tabs\tand\nnewlines  stay"
        );
    }
}
