//! The build at scale: the oblique flat torus (`fixtures/scenes/flat-torus.json`) on uniform
//! grids of about 100k, 1M, 4M and 10M triangles, with every output but the picture (glb,
//! vtk, ply, report). For each size: the wall time of each stage and the total (from
//! `report.json`) beside the wall time measured from outside, the estimated memory beside
//! the peak the report read and the one `/usr/bin/time` measured (where it is installed),
//! and the bytes written, as a Markdown table.
//!
//! `cargo bench --bench scale` runs 100k and 1M; `HALO4D_SCALE=100k,1M,4M,10M cargo bench
//! --bench scale` chooses the sizes (a size beyond the machine's memory limit is refused by
//! the build, and the table says so). The builds run the release `halo4d` binary, one at a
//! time, each in a fresh process so that its peak memory is its own.

use std::path::Path;
use std::process::Command;

/// Grid side for about `triangles` triangles (2 side² of them), even as sampling requires.
fn side(triangles: f64) -> u32 {
    ((triangles / 2.0).sqrt() / 2.0).round() as u32 * 2
}

fn parse_size(text: &str) -> Option<f64> {
    let text = text.trim().to_ascii_lowercase();
    let (number, unit) = match text.chars().last()? {
        'k' => (&text[..text.len() - 1], 1e3),
        'm' => (&text[..text.len() - 1], 1e6),
        _ => (&text[..], 1.0),
    };
    number.parse::<f64>().ok().map(|n| n * unit)
}

fn folder_bytes(dir: &Path) -> u64 {
    std::fs::read_dir(dir)
        .map(|entries| {
            entries
                .filter_map(|e| e.ok()?.metadata().ok())
                .map(|m| m.len())
                .sum()
        })
        .unwrap_or(0)
}

fn main() {
    let sizes: Vec<f64> = std::env::var("HALO4D_SCALE")
        .unwrap_or_else(|_| "100k,1M".into())
        .split(',')
        .map(|s| parse_size(s).unwrap_or_else(|| panic!("HALO4D_SCALE: bad size {s:?}")))
        .collect();
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/scenes/flat-torus.json");
    let mut scene: serde_json::Value =
        serde_json::from_slice(&std::fs::read(fixture).expect("the flat torus fixture"))
            .expect("the fixture is JSON");
    scene["outputs"] = serde_json::json!({
        "glb": true, "vtk": true, "ply": true, "report": true, "png": false
    });
    let dir = tempfile::tempdir().expect("a temporary folder");
    println!(
        "| triangles | sample | audit | prove | view | guards | halo | curves | verify | export | free | total (s) | wall (s) | estimate (GB) | peak (GB) | peak, time (GB) | written (MB) |"
    );
    println!(
        "| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
    );
    let time = Path::new("/usr/bin/time");
    for size in sizes {
        let u = side(size);
        scene["sampling"] = serde_json::json!({"method": "uniform", "u": u, "v": u});
        let file = dir.path().join(format!("scale-{u}.json"));
        std::fs::write(&file, serde_json::to_vec(&scene).unwrap()).unwrap();
        let out = dir.path().join(format!("out-{u}"));
        let halo4d = env!("CARGO_BIN_EXE_halo4d");
        let mut command = if time.exists() {
            let mut c = Command::new(time);
            c.args(["-f", "halo4d-peak-kb %M", halo4d]);
            c
        } else {
            Command::new(halo4d)
        };
        let start = std::time::Instant::now();
        let run = command
            .args(["build", "--quiet", "--out"])
            .arg(&out)
            .arg(&file)
            .output()
            .expect("halo4d runs");
        let wall = start.elapsed().as_secs_f64();
        let peak_outside = String::from_utf8_lossy(&run.stderr)
            .lines()
            .find_map(|l| l.strip_prefix("halo4d-peak-kb "))
            .and_then(|kb| kb.trim().parse::<f64>().ok())
            .map_or("-".to_string(), |kib| format!("{:.2}", kib * 1024.0 / 1e9));
        let triangles = 2 * u as u64 * u as u64;
        if !run.status.success() {
            let err = String::from_utf8_lossy(&run.stderr);
            println!(
                "| {triangles} | refused or failed: {} |",
                err.trim().replace('\n', " ")
            );
            continue;
        }
        let report: serde_json::Value =
            serde_json::from_slice(&std::fs::read(out.join("report.json")).unwrap()).unwrap();
        let t = &report["timings_ms"];
        let s = |k: &str| t[k].as_f64().unwrap_or(f64::NAN) / 1e3;
        let memory = &report["memory"];
        let gb = |k: &str| memory[k].as_f64().unwrap_or(f64::NAN);
        println!(
            "| {triangles} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {wall:.2} | {:.2} | {:.2} | {peak_outside} | {:.0} |",
            s("sample"),
            s("audit"),
            s("prove"),
            s("view"),
            s("guards"),
            s("halo"),
            s("curves"),
            s("verify"),
            s("export"),
            s("free"),
            s("total"),
            gb("estimate_gb"),
            gb("peak_gb"),
            folder_bytes(&out) as f64 / 1e6
        );
        let h = &report["surfaces"][0]["halo"]["stage_ms"];
        println!(
            "|  | halo: directions {:.2}, plan {:.2}, shrink {:.2}, split {:.2}, check {:.2} |",
            h["directions"].as_f64().unwrap_or(f64::NAN) / 1e3,
            h["plan"].as_f64().unwrap_or(f64::NAN) / 1e3,
            h["shrink"].as_f64().unwrap_or(f64::NAN) / 1e3,
            h["split"].as_f64().unwrap_or(f64::NAN) / 1e3,
            h["check"].as_f64().unwrap_or(f64::NAN) / 1e3,
        );
        std::fs::remove_dir_all(&out).ok();
    }
}
