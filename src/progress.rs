//! What long work says while it runs, and how it is stopped. The library prints nothing: a
//! long operation (a build, a view search, a gallery, an animation, a motion picture) takes
//! a [`Job`], reports [`Event`]s to the job's [`Observer`] and checks its [`Cancel`] token
//! between its steps and inside its long loops. The programs decide what to show: the
//! `halo4d` command draws a progress bar, the Python package calls the function it is given
//! (a `tqdm` bar), the Blender add-on moves Blender's progress.
//!
//! ```
//! use halo4d::progress::{Cancel, Event, Job};
//! use std::sync::Mutex;
//!
//! let scene = halo4d::Scene::default_scene();
//! let said = Mutex::new(Vec::new());
//! let observer = |e: &Event| said.lock().unwrap().push(format!("{e:?}"));
//! let cancel = Cancel::new();
//! cancel.cancel(); // Ctrl-C before it began: it stops at its first check.
//! let err = halo4d::Sampled::sample(&scene, Job::new(&observer, &cancel)).unwrap_err();
//! assert!(err.to_string().contains("stopped"));
//! ```

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

/// What long work says while it runs.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum Event<'a> {
    /// A task of `steps` steps begins (a build's stages, a search's views, an animation's
    /// frames). Tasks nest: a gallery's builds begin and end inside the gallery's task.
    Begin {
        /// What the task is: `"build"`, `"view search"`, `"animation"`, `"gallery"`,
        /// `"motion pictures"`.
        task: &'a str,
        /// Its steps, at least 1.
        steps: u64,
    },
    /// What the innermost task is doing now (`"sampling spun_trefoil"`, `"halo of k"`).
    Doing(&'a str),
    /// The innermost task has done `done` of its steps.
    Done(u64),
    /// The innermost task ended, finished or not.
    End,
    /// Something the user should know about the result (a surface short of its tolerance).
    Warning(&'a str),
    /// A line of what was done (a frame's verdict, a surface sampled again).
    Note(&'a str),
}

/// Who hears a job's [`Event`]s. Any `Fn(&Event) + Sync` is one. Events come from the
/// thread that runs the job, and a task's steps from its worker threads too (a view
/// search's views are evaluated on the cores); the observer should return quickly.
pub trait Observer: Sync {
    /// Hears one event.
    fn event(&self, event: &Event<'_>);
}

impl<F: Fn(&Event<'_>) + Sync> Observer for F {
    fn event(&self, event: &Event<'_>) {
        self(event);
    }
}

/// The observer that hears nothing.
#[derive(Clone, Copy, Debug, Default)]
pub struct Silent;

impl Observer for Silent {
    fn event(&self, _: &Event<'_>) {}
}

/// A token that stops work: cloned into whoever may stop it (a signal handler, a timer, a
/// window's close button), checked by the work. Once cancelled it stays cancelled.
#[derive(Clone, Debug)]
pub struct Cancel(Option<Arc<AtomicBool>>);

/// The token no one can cancel.
static NEVER: Cancel = Cancel(None);

impl Default for Cancel {
    fn default() -> Cancel {
        Cancel::new()
    }
}

impl Cancel {
    /// The token that is never cancelled, for work no one stops.
    pub fn never() -> &'static Cancel {
        &NEVER
    }

    /// A fresh token, not cancelled.
    pub fn new() -> Cancel {
        Cancel(Some(Arc::default()))
    }

    /// Stops the work that checks this token (and every clone of it).
    pub fn cancel(&self) {
        if let Some(flag) = &self.0 {
            flag.store(true, Ordering::Relaxed);
        }
    }

    /// Whether the work should stop: one relaxed atomic load, cheap enough for a loop's
    /// every step.
    #[inline]
    pub fn is_cancelled(&self) -> bool {
        self.0.as_ref().is_some_and(|f| f.load(Ordering::Relaxed))
    }

    /// `Err(Cancelled)` once cancelled.
    pub fn check(&self) -> Result<(), Cancelled> {
        if self.is_cancelled() {
            Err(Cancelled)
        } else {
            Ok(())
        }
    }
}

/// Work stopped by its [`Cancel`] token before it finished; what it made is dropped and no
/// file of it is written.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("stopped before it finished (cancelled); nothing of it was written")]
pub struct Cancelled;

/// What a long operation reports to and is stopped by: an observer and a cancel token,
/// both the caller's.
#[derive(Clone, Copy)]
pub struct Job<'a> {
    observer: &'a dyn Observer,
    cancel: &'a Cancel,
}

impl std::fmt::Debug for Job<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Job")
            .field("cancel", self.cancel)
            .finish_non_exhaustive()
    }
}

impl Job<'static> {
    /// The job that says nothing and is never stopped.
    pub const SILENT: Job<'static> = Job {
        observer: &Silent,
        cancel: &NEVER,
    };
}

impl<'a> Job<'a> {
    /// A job that reports to `observer` and stops when `cancel` is cancelled.
    pub fn new(observer: &'a dyn Observer, cancel: &'a Cancel) -> Job<'a> {
        Job { observer, cancel }
    }

    /// The job's token.
    pub fn cancel(&self) -> &'a Cancel {
        self.cancel
    }

    /// `Err(Cancelled)` once the job is cancelled.
    pub fn check(&self) -> Result<(), Cancelled> {
        self.cancel.check()
    }

    /// Says `text` as a [`Event::Warning`].
    pub fn warn(&self, text: &str) {
        self.observer.event(&Event::Warning(text));
    }

    /// Says `text` as a [`Event::Note`].
    pub fn note(&self, text: &str) {
        self.observer.event(&Event::Note(text));
    }

    /// Begins a task of `steps` steps; it ends when the [`Task`] is dropped.
    pub fn task(&self, task: &str, steps: u64) -> Task<'a> {
        self.observer.event(&Event::Begin {
            task,
            steps: steps.max(1),
        });
        Task {
            job: *self,
            done: AtomicU64::new(0),
            steps: steps.max(1),
        }
    }
}

/// A task in progress: says what it is doing and how many steps it has done, and
/// [`Event::End`] when dropped (finished, failed or cancelled).
#[derive(Debug)]
pub struct Task<'a> {
    job: Job<'a>,
    done: AtomicU64,
    steps: u64,
}

impl<'a> Task<'a> {
    /// The job the task reports to.
    pub fn job(&self) -> Job<'a> {
        self.job
    }

    /// Says what the task is doing now.
    pub fn doing(&self, what: &str) {
        self.job.observer.event(&Event::Doing(what));
    }

    /// The steps done so far.
    pub fn done(&self) -> u64 {
        self.done.load(Ordering::Relaxed)
    }

    /// One more step done.
    pub fn step(&self) {
        let done = self.done.fetch_add(1, Ordering::Relaxed) + 1;
        self.job.observer.event(&Event::Done(done.min(self.steps)));
    }

    /// All steps but the last done: the task is at its last.
    pub fn at_last(&self) {
        self.done.store(self.steps - 1, Ordering::Relaxed);
        self.job.observer.event(&Event::Done(self.steps - 1));
    }
}

impl Drop for Task<'_> {
    fn drop(&mut self) {
        self.job.observer.event(&Event::End);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Mutex;

    #[test]
    fn a_task_says_its_steps_and_ends_when_dropped_and_a_token_stays_cancelled() {
        let said = Mutex::new(Vec::new());
        let observer = |e: &Event| said.lock().unwrap().push(format!("{e:?}"));
        let cancel = Cancel::new();
        let job = Job::new(&observer, &cancel);
        {
            let task = job.task("build", 3);
            task.doing("sampling");
            task.step();
            task.at_last();
            job.warn("w");
        }
        assert_eq!(
            *said.lock().unwrap(),
            [
                "Begin { task: \"build\", steps: 3 }",
                "Doing(\"sampling\")",
                "Done(1)",
                "Done(2)",
                "Warning(\"w\")",
                "End"
            ]
        );
        assert_eq!(job.check(), Ok(()));
        let clone = cancel.clone();
        clone.cancel();
        assert!(cancel.is_cancelled() && job.check() == Err(Cancelled));
        // The never-cancelled token cannot be cancelled.
        Cancel::never().cancel();
        assert!(!Cancel::never().is_cancelled());
        assert!(Job::SILENT.check().is_ok());
    }
}
