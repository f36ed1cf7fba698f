//! The library reports and the programs print; work stops when its token is cancelled,
//! wherever it is, with nothing written.

use crate::common::{fixture, halo4d};
use halo4d::progress::{Cancel, Event, Job};
use halo4d::{Error, Scene};
use std::sync::Mutex;

/// Every event of a job, as `Debug` text.
#[derive(Default)]
struct Heard(Mutex<Vec<String>>);

impl Heard {
    fn all(&self) -> Vec<String> {
        self.0.lock().unwrap().clone()
    }
}

impl halo4d::progress::Observer for Heard {
    fn event(&self, event: &Event<'_>) {
        self.0.lock().unwrap().push(format!("{event:?}"));
    }
}

fn torus() -> Scene {
    let mut scene = Scene::load(&fixture("scenes/flat-torus.json")).unwrap();
    scene.outputs.png = true;
    scene.outputs.vtk = true;
    scene.render.width = 96;
    scene.render.height = 96;
    scene
}

#[test]
fn a_build_reports_its_stages_in_order_then_ends() {
    let scene = torus();
    let dir = tempfile::tempdir().unwrap();
    let heard = Heard::default();
    let report = halo4d::build(&scene, dir.path(), Job::new(&heard, Cancel::never())).unwrap();
    assert!(report.verified);
    let events = heard.all();
    // One surface: sampled, projected and given its halo (3 steps), the curves, and the files.
    assert_eq!(events[0], "Begin { task: \"build\", steps: 6 }");
    assert_eq!(events.last().unwrap(), "End");
    let doing: Vec<&str> = events
        .iter()
        .filter_map(|e| e.strip_prefix("Doing(\""))
        .collect();
    let order = [
        "sampling flat_torus",
        "projecting flat_torus",
        "measuring the scene",
        "halo of flat_torus",
        "intersection curves",
        "verifying halos",
        "the picture and the files",
    ];
    let mut at = 0;
    for stage in order {
        let found = doing[at..].iter().position(|d| d.starts_with(stage));
        let found = found.unwrap_or_else(|| panic!("no `{stage}` after {:?}", &doing[..at]));
        at += found + 1;
    }
    let done: Vec<u64> = events
        .iter()
        .filter_map(|e| e.strip_prefix("Done(")?.strip_suffix(')')?.parse().ok())
        .collect();
    assert_eq!(done, [1, 2, 3, 4, 5]);
}

#[test]
fn a_build_cancelled_at_any_stage_stops_and_writes_nothing() {
    // Cancelled as each stage begins: the build ends with `Error::Cancelled`, and the folder
    // holds none of its files, not even partial ones; a build left alone writes them all.
    let scene = torus();
    let stages = [
        "sampling",
        "projecting",
        "measuring the scene",
        "halo of",
        "intersection curves",
        "verifying halos",
        "the picture and the files",
    ];
    for stage in stages {
        let dir = tempfile::tempdir().unwrap();
        let cancel = Cancel::new();
        let stop = |e: &Event<'_>| {
            if matches!(e, Event::Doing(d) if d.starts_with(stage)) {
                cancel.cancel();
            }
        };
        let err = halo4d::build(&scene, dir.path(), Job::new(&stop, &cancel)).unwrap_err();
        assert!(matches!(err, Error::Cancelled(_)), "{stage}: {err}");
        assert!(
            err.to_string().contains("nothing of it was written"),
            "{err}"
        );
        let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert!(left.is_empty(), "{stage}: {left:?}");
    }
    let dir = tempfile::tempdir().unwrap();
    let report = halo4d::build(&scene, dir.path(), Job::SILENT).unwrap();
    assert!(report.files.len() >= 4, "{:?}", report.files);
    for f in &report.files {
        assert!(dir.path().join(f).is_file(), "{f}");
    }
}

#[test]
fn the_other_long_operations_stop_when_cancelled() {
    let cancelled = Cancel::new();
    cancelled.cancel();
    let job = Job::new(&halo4d::progress::Silent, &cancelled);
    let scene = torus();
    // Sampling, a view of samples, the view search, a picture, a motion picture.
    assert!(matches!(
        halo4d::Sampled::sample(&scene, job),
        Err(Error::Cancelled(_))
    ));
    let sampled = halo4d::Sampled::of(&scene);
    let stages = halo4d::Stages::of(&scene);
    assert!(matches!(
        sampled.clone().into_built_with(&scene, stages, job),
        Err(Error::Cancelled(_))
    ));
    assert!(matches!(
        halo4d::search_view(&scene, job),
        Err(halo4d::SearchError::Cancelled(_))
    ));
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("p.png");
    assert!(matches!(
        halo4d::render_to(&scene, &png, job),
        Err(Error::Cancelled(_))
    ));
    let built = sampled.build(&scene, stages).unwrap();
    let parts = built.parts(&scene.halo);
    assert!(matches!(
        halo4d::render::render_until(&parts, &scene.render, &scene.camera, &cancelled),
        Err(halo4d::render::RenderError::Cancelled(_))
    ));
    let slicing = halo4d::motion::Slicing {
        levels: 4,
        ..Default::default()
    };
    assert!(matches!(
        halo4d::slicing::slice_scene(&scene, slicing, dir.path(), job),
        Err(halo4d::slicing::SliceError::Build(Error::Cancelled(_)))
    ));
    assert!(!png.exists() && std::fs::read_dir(dir.path()).unwrap().next().is_none());
}

#[test]
fn build_timeout_stops_the_build_with_exit_124_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let scene = fixture("scenes/default.json");
    let out = halo4d(
        &[
            "build",
            scene.to_str().unwrap(),
            "--out",
            "out",
            "--timeout",
            "0.05",
        ],
        dir.path(),
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(124), "{stderr}");
    assert!(
        stderr.contains("not finished within --timeout 0.05 s; nothing of it was written"),
        "{stderr}"
    );
    let out_dir = dir.path().join("out");
    assert!(
        !out_dir.exists() || std::fs::read_dir(&out_dir).unwrap().next().is_none(),
        "{:?}",
        std::fs::read_dir(&out_dir).map(|d| d.count())
    );
    // A bad timeout names the flag.
    for bad in ["0", "-1", "soon", "inf"] {
        let out = halo4d(&["build", &format!("--timeout={bad}")], dir.path());
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{bad}: {stderr}");
        assert!(
            stderr.contains("--timeout") && stderr.contains("seconds above 0"),
            "{bad}: {stderr}"
        );
    }
}
