//! What the programs show of the library's progress ([`halo4d::progress`]) on stderr: a bar
//! for the task under way (the innermost: a gallery's bar gives way to its figure's build
//! and comes back after it), the warnings and notes above it; where stderr is not a
//! terminal (a log, a pipe) indicatif draws nothing, and a line every [`HEARTBEAT`] says
//! what a long task is doing instead. Quiet: the warnings alone. Shared by `halo4d` and
//! `halo4d-view`.

use halo4d::progress::{Event, Observer};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// How often a task whose stderr is not a terminal says what it is doing.
const HEARTBEAT: Duration = Duration::from_secs(10);

/// The observer of the programs' terminal.
pub struct Terminal {
    quiet: bool,
    /// The tasks under way, outermost first; only the last has its bar drawn.
    tasks: Mutex<Vec<Level>>,
}

/// A task under way: what its bar shows, kept to draw it again once a task inside it ends.
struct Level {
    task: String,
    steps: u64,
    done: u64,
    doing: String,
    bar: ProgressBar,
}

impl Terminal {
    /// A terminal observer; `quiet` shows only the warnings.
    pub fn new(quiet: bool) -> Terminal {
        Terminal {
            quiet,
            tasks: Mutex::new(Vec::new()),
        }
    }

    /// Prints `line` on stderr above the bar under way.
    fn say(tasks: &[Level], line: &str) {
        match tasks.last() {
            Some(level) => level.bar.suspend(|| eprintln!("{line}")),
            None => eprintln!("{line}"),
        }
    }
}

impl Observer for Terminal {
    fn event(&self, event: &Event<'_>) {
        let mut tasks = self.tasks.lock().unwrap_or_else(|e| e.into_inner());
        match *event {
            Event::Warning(text) => Terminal::say(&tasks, &format!("warning: {text}")),
            _ if self.quiet => {}
            Event::Note(text) => Terminal::say(&tasks, text),
            Event::Begin { task, steps } => {
                if let Some(outer) = tasks.last() {
                    outer.bar.finish_and_clear();
                }
                let mut level = Level {
                    task: task.to_string(),
                    steps,
                    done: 0,
                    doing: task.to_string(),
                    bar: ProgressBar::hidden(),
                };
                level.bar = draw(&level);
                tasks.push(level);
            }
            Event::Doing(what) => {
                if let Some(level) = tasks.last_mut() {
                    what.clone_into(&mut level.doing);
                    level.bar.set_message(what.to_string());
                }
            }
            Event::Done(done) => {
                if let Some(level) = tasks.last_mut() {
                    level.done = done;
                    level.bar.set_position(done);
                }
            }
            Event::End => {
                if let Some(level) = tasks.pop() {
                    level.bar.finish_and_clear();
                }
                if let Some(outer) = tasks.last_mut() {
                    outer.bar = draw(outer);
                }
            }
            _ => {}
        }
    }
}

/// The bar of a task as the command line has always drawn it: the view search's views and
/// an animation's frames in their own words, any other task's steps with a spinner that
/// keeps turning through a long stage.
fn draw(level: &Level) -> ProgressBar {
    let bar = ProgressBar::new(level.steps);
    let (template, steady) = match level.task.as_str() {
        "view search" => ("{msg} [{bar:30}] {pos}/{len} 4D views ({elapsed})", false),
        "animation" => (
            "{spinner} [{elapsed_precise}] {bar:30} {pos}/{len} frames  {msg}",
            false,
        ),
        _ => (
            "{spinner} [{elapsed_precise}] {bar:30} {pos}/{len} {msg}",
            true,
        ),
    };
    let style =
        ProgressStyle::with_template(template).unwrap_or_else(|_| ProgressStyle::default_bar());
    bar.set_style(if level.task == "view search" {
        style.progress_chars("=> ")
    } else {
        style
    });
    bar.set_position(level.done);
    bar.set_message(level.doing.clone());
    if steady {
        // Redrawn on its own: a stage of many seconds (sampling a fine tolerance, the
        // halos of a million triangles) shows its time passing, never a frozen line.
        bar.enable_steady_tick(Duration::from_millis(250));
        if !std::io::stderr().is_terminal() {
            heartbeat(bar.clone());
        }
    }
    bar
}

/// A line every [`HEARTBEAT`] with the stage and the time, until the bar finishes, so that
/// a long build never sits silent in a log.
fn heartbeat(bar: ProgressBar) {
    std::thread::spawn(move || {
        let start = Instant::now();
        let mut next = HEARTBEAT;
        while !bar.is_finished() {
            std::thread::sleep(Duration::from_millis(100));
            if start.elapsed() >= next {
                eprintln!(
                    "halo4d: {:.0} s, stage {}/{}: {}",
                    start.elapsed().as_secs_f64(),
                    bar.position(),
                    bar.length().unwrap_or(0),
                    bar.message()
                );
                next += HEARTBEAT;
            }
        }
    });
}
