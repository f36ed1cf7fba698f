//! `halo4d animate`: every frame verified and identical to `halo4d render` of the scene in
//! that frame's view; the same frames however the run is sharded, with the shards running
//! side by side in one folder; a killed run leaves whole frames and a rerun makes only the
//! missing ones; status and assembly refuse a folder that is not complete.

use crate::common::{fixture, halo4d};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

const FRAMES: u32 = 24;

fn turn() -> PathBuf {
    fixture("animations/flat-torus-turn.json")
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn animate(args: &[&str], dir: &Path) -> Output {
    let mut all = vec!["animate"];
    all.extend_from_slice(args);
    halo4d(&all, dir)
}

fn record(dir: &Path, k: u32) -> serde_json::Value {
    let text = std::fs::read(dir.join(format!("frame-{k:05}.json")))
        .unwrap_or_else(|e| panic!("frame {k}'s record: {e}"));
    serde_json::from_slice(&text).expect("a record is JSON")
}

/// A record without its timings, which differ from run to run.
fn timeless(mut r: serde_json::Value) -> serde_json::Value {
    r.as_object_mut().unwrap().remove("timings_ms");
    if let Some(v) = r["verification"].as_object_mut() {
        v.remove("ms");
    }
    r
}

fn png(dir: &Path, k: u32) -> Vec<u8> {
    std::fs::read(dir.join(format!("frame-{k:05}.png")))
        .unwrap_or_else(|e| panic!("frame {k}'s picture: {e}"))
}

/// The hidden temporary files in a folder.
fn partial_files(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".partial"))
        .collect()
}

#[test]
fn a_turn_of_the_flat_torus_is_verified_and_every_frame_is_its_render() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("frames");
    let out = animate(
        &[turn().to_str().unwrap(), "--out", dir.to_str().unwrap()],
        tmp.path(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let scene: serde_json::Value = serde_json::from_slice(&std::fs::read(turn()).unwrap()).unwrap();
    for k in 0..FRAMES {
        let r = record(&dir, k);
        assert_eq!(r["verified"], true, "frame {k}: {r}");
        assert_eq!(r["verification"]["wrong"], 0, "frame {k}");
        assert_eq!(r["frame"], k);
        // A looped whole turn in yw from 30 degrees: 15 degrees a frame.
        let yw = r["view"]["rotation"]["yw"].as_f64().unwrap();
        assert!(
            (yw - (30.0 + 15.0 * f64::from(k))).abs() < 1e-9,
            "frame {k}: yw {yw}"
        );
        // The scene with this frame's view and camera, drawn by `halo4d render`.
        let mut frame = scene.clone();
        frame["view"] = r["view"].clone();
        frame["camera"] = r["camera"].clone();
        frame.as_object_mut().unwrap().remove("animation");
        let path = tmp.path().join("frame.json");
        std::fs::write(&path, frame.to_string()).unwrap();
        let picture = tmp.path().join(format!("render-{k}.png"));
        let out = halo4d(
            &[
                "render",
                path.to_str().unwrap(),
                "--quiet",
                "--out",
                picture.to_str().unwrap(),
            ],
            tmp.path(),
        );
        assert!(out.status.success(), "{}", stderr(&out));
        assert!(
            std::fs::read(&picture).unwrap() == png(&dir, k),
            "frame {k} differs from `halo4d render` of its view"
        );
    }
    // Frame 0 is the first keyframe: the scene's own view, exactly.
    assert_eq!(record(&dir, 0)["view"]["rotation"]["yw"], 30.0);
    // Every record in frame order, one a line.
    let lines = std::fs::read_to_string(dir.join("frames.jsonl")).unwrap();
    let frames: Vec<u64> = lines
        .lines()
        .map(|l| {
            serde_json::from_str::<serde_json::Value>(l).unwrap()["frame"]
                .as_u64()
                .unwrap()
        })
        .collect();
    assert_eq!(frames, (0..u64::from(FRAMES)).collect::<Vec<_>>());
    assert!(partial_files(&dir).is_empty());

    // Assembled: an animated PNG whose frames are the frames' pictures, pixel for pixel.
    let out = animate(&["--assemble", dir.to_str().unwrap()], tmp.path());
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("ffmpeg -framerate 12 -i"),
        "{}",
        stderr(&out)
    );
    let file = std::fs::File::open(dir.join("animation.png")).unwrap();
    let mut reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .expect("the animation reads as a PNG");
    let control = reader.info().animation_control.expect("an animated PNG");
    assert_eq!(control.num_frames, FRAMES);
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    for k in 0..FRAMES {
        let info = reader
            .next_frame(&mut buf)
            .expect("a frame of the animation");
        let frame = image::open(dir.join(format!("frame-{k:05}.png")))
            .unwrap()
            .to_rgb8();
        assert_eq!(
            &buf[..info.buffer_size()],
            frame.as_raw().as_slice(),
            "frame {k}"
        );
    }
}

/// Runs the shards of `count` side by side into one folder.
fn sharded(count: u32, dir: &Path, cwd: &Path) {
    let children: Vec<_> = (0..count)
        .map(|i| {
            Command::new(env!("CARGO_BIN_EXE_halo4d"))
                .args([
                    "animate",
                    turn().to_str().unwrap(),
                    "--quiet",
                    "--out",
                    dir.to_str().unwrap(),
                    "--shard",
                    &format!("{i}/{count}"),
                ])
                .current_dir(cwd)
                .stdout(Stdio::null())
                .stderr(Stdio::piped())
                .spawn()
                .expect("halo4d runs")
        })
        .collect();
    for child in children {
        let out = child.wait_with_output().unwrap();
        assert!(out.status.success(), "{}", stderr(&out));
    }
}

#[test]
fn shards_side_by_side_make_the_same_frames_as_one_process() {
    let tmp = tempfile::tempdir().unwrap();
    let one = tmp.path().join("one");
    let out = animate(
        &[
            turn().to_str().unwrap(),
            "--quiet",
            "--out",
            one.to_str().unwrap(),
        ],
        tmp.path(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    for count in [3, 4] {
        let dir = tmp.path().join(format!("shards-{count}"));
        sharded(count, &dir, tmp.path());
        for k in 0..FRAMES {
            assert!(
                png(&dir, k) == png(&one, k),
                "{count} shards: frame {k} differs"
            );
            assert_eq!(timeless(record(&dir, k)), timeless(record(&one, k)));
        }
        // The last shard to finish gathered every record.
        assert_eq!(
            std::fs::read_to_string(dir.join("frames.jsonl"))
                .unwrap()
                .lines()
                .count(),
            FRAMES as usize
        );
        assert!(partial_files(&dir).is_empty(), "{count} shards");
    }
    // A shard that is already done makes nothing.
    let dir = tmp.path().join("shards-4");
    let out = animate(
        &[
            turn().to_str().unwrap(),
            "--out",
            dir.to_str().unwrap(),
            "--shard",
            "1/4",
        ],
        tmp.path(),
    );
    assert!(out.status.success());
    assert!(
        stderr(&out).contains("6 frames in this run: 0 made, 6 done before"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn a_killed_run_leaves_whole_frames_and_a_rerun_makes_only_the_missing() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("frames");
    // Large pictures, so that a frame takes long enough to be killed in the middle.
    let mut child = Command::new(env!("CARGO_BIN_EXE_halo4d"))
        .args([
            "animate",
            turn().to_str().unwrap(),
            "--quiet",
            "--width",
            "768",
            "--height",
            "768",
            "--out",
            dir.to_str().unwrap(),
        ])
        .current_dir(tmp.path())
        .spawn()
        .expect("halo4d runs");
    let done = |dir: &Path| {
        (0..FRAMES)
            .filter(|k| dir.join(format!("frame-{k:05}.json")).exists())
            .count()
    };
    let start = std::time::Instant::now();
    while done(&dir) < 3 {
        assert!(
            start.elapsed().as_secs() < 120,
            "no frame after two minutes"
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    // What the kill left: every picture and record there is whole.
    let before = done(&dir);
    assert!(
        before < FRAMES as usize,
        "the run ended before it was killed"
    );
    let mut records = Vec::new();
    for k in 0..FRAMES {
        if dir.join(format!("frame-{k:05}.json")).exists() {
            records.push((
                k,
                std::fs::read(dir.join(format!("frame-{k:05}.json"))).unwrap(),
            ));
            assert_eq!(record(&dir, k)["verified"], true);
        }
        if dir.join(format!("frame-{k:05}.png")).exists() {
            let picture = image::open(dir.join(format!("frame-{k:05}.png")))
                .unwrap_or_else(|e| panic!("frame {k}'s picture is not whole: {e}"));
            assert_eq!(picture.width(), 768);
        }
    }
    // As a kill in the middle of writing leaves them: a torn temporary file of a missing
    // frame, and a picture without its record.
    let missing = (0..FRAMES)
        .find(|k| !dir.join(format!("frame-{k:05}.json")).exists())
        .unwrap();
    std::fs::write(
        dir.join(format!(".frame-{missing:05}.png.partial")),
        b"\x89PNG torn",
    )
    .unwrap();
    let status = animate(&["--status", dir.to_str().unwrap()], tmp.path());
    assert_eq!(status.status.code(), Some(1));
    let text = String::from_utf8_lossy(&status.stdout);
    assert!(
        text.contains(&format!("done and verified: {before}")),
        "{text}"
    );
    assert!(
        text.contains(&format!("missing: {}", FRAMES as usize - before)),
        "{text}"
    );
    let out = animate(&["--assemble", dir.to_str().unwrap()], tmp.path());
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("not every frame is done"),
        "{}",
        stderr(&out)
    );
    assert!(!dir.join("animation.png").exists());

    let out = animate(
        &[
            turn().to_str().unwrap(),
            "--width",
            "768",
            "--height",
            "768",
            "--out",
            dir.to_str().unwrap(),
        ],
        tmp.path(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let expected = format!(
        "{FRAMES} frames in this run: {} made, {before} done before",
        FRAMES as usize - before
    );
    assert!(stderr(&out).contains(&expected), "{}", stderr(&out));
    // The frames done before the kill were left as they were.
    for (k, bytes) in records {
        assert_eq!(
            std::fs::read(dir.join(format!("frame-{k:05}.json"))).unwrap(),
            bytes
        );
    }
    assert!(partial_files(&dir).is_empty(), "{:?}", partial_files(&dir));
    let status = animate(&["--status", dir.to_str().unwrap()], tmp.path());
    assert!(status.status.success());
}

#[test]
fn a_frame_that_cannot_be_built_is_recorded_and_blocks_the_assembly() {
    let tmp = tempfile::tempdir().unwrap();
    // The 4D eye comes nearer until it is inside the torus (|w| reaches 1): the last frame
    // puts vertices behind the eye.
    let scene = r#"{
        "name": "eye-inside",
        "surfaces": [{"surface": {"type": "flat_torus"}}],
        "sampling": {"method": "uniform", "u": 24, "v": 24},
        "view": {"rotation": {"yw": 30}, "projection": {"type": "perspective", "eye_distance": 5}},
        "render": {"width": 64, "height": 64},
        "animation": {"frames": 3, "keyframes": [
            {"time": 0},
            {"time": 1, "view": {"projection": {"type": "perspective", "eye_distance": 0.5}}}
        ]}
    }"#;
    std::fs::write(tmp.path().join("eye.json"), scene).unwrap();
    let out = animate(&["eye.json", "--out", "frames"], tmp.path());
    assert_eq!(out.status.code(), Some(3), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("UNVERIFIED frame 2"),
        "{}",
        stderr(&out)
    );
    let dir = tmp.path().join("frames");
    assert_eq!(record(&dir, 0)["verified"], true);
    assert_eq!(record(&dir, 1)["verified"], true);
    let failed = record(&dir, 2);
    assert_eq!(failed["verified"], false);
    assert!(
        failed["failures"][0].as_str().unwrap().contains("eye"),
        "{failed}"
    );
    assert!(!dir.join("frame-00002.png").exists());
    let status = animate(&["--status", "frames"], tmp.path());
    assert_eq!(status.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&status.stdout).contains("failed: 1\n  frame 2:"));
    let out = animate(&["--assemble", "frames"], tmp.path());
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("frame 2:"), "{}", stderr(&out));
    // A rerun does not make the failed frame again (its build would fail the same way),
    // and still says it failed.
    let out = animate(&["eye.json", "--out", "frames"], tmp.path());
    assert_eq!(out.status.code(), Some(3));
    assert!(
        stderr(&out).contains("0 made, 3 done before"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn bad_requests_get_clear_errors() {
    let tmp = tempfile::tempdir().unwrap();
    let turn = turn();
    let turn = turn.to_str().unwrap();
    let default = fixture("scenes/flat-torus.json");
    let cases: &[(&[&str], &[&str])] = &[
        (
            &[default.to_str().unwrap()],
            &["has no `animation`", "keyframes"],
        ),
        (
            &[turn, "--shard", "4/4"],
            &["--shard", "below the number of shards"],
        ),
        (&[turn, "--shard", "x"], &["--shard", "I/N"]),
        (
            &[turn, "--frames", "20..30"],
            &["--frames", "past the animation's 24 frames"],
        ),
        (&[turn, "--frames", "5..5"], &["--frames", "no frame"]),
        (&[turn, "--width", "0"], &["--width"]),
        (&["--status", "nowhere"], &["nowhere", "animation.json"]),
        (&["--assemble", "nowhere"], &["nowhere", "animation.json"]),
        (&[], &["SCENE"]),
    ];
    for (args, words) in cases {
        let out = animate(args, tmp.path());
        assert!(!out.status.success(), "{args:?} succeeded");
        let err = stderr(&out);
        for w in *words {
            assert!(err.contains(w), "{args:?}: the error lacks `{w}`: {err}");
        }
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
    // A folder of one scene's frames refuses another scene's.
    let out = animate(
        &[turn, "--frames", "0", "--quiet", "--out", "f"],
        tmp.path(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let out = animate(&[turn, "--width", "100", "--out", "f"], tmp.path());
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("another scene"), "{}", stderr(&out));
    assert!(stderr(&out).contains("`render`"), "{}", stderr(&out));
}

/// The animation fixtures load, and follow their keys: the default scene's turn in xw is
/// at its halfway point halfway through, with the camera swung out to its key.
#[test]
fn the_animation_fixtures_follow_their_keys() {
    let files = crate::common::scenes_in("animations");
    assert!(!files.is_empty());
    for file in &files {
        let scene = halo4d::Scene::load(file).unwrap_or_else(|e| panic!("{e}"));
        assert!(scene.animation.is_some(), "{}", file.display());
    }
    let scene = halo4d::Scene::load(&fixture("animations/spun-trefoil-xw.json")).unwrap();
    let first = scene.frame(0).unwrap();
    assert_eq!((first.view, first.camera), (scene.view, scene.camera));
    let half = scene.frame(180).unwrap();
    assert!((half.view.rotation.xw - 200.0).abs() < 1e-9);
    assert_eq!(half.view.rotation.yw, 35.0);
    assert_eq!(half.camera.azimuth, 80.0);
    assert!(scene.frame(360).is_none());
}
