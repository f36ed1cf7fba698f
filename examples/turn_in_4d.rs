//! The library from code: a scene sampled once and built in several 4D views, the surface
//! turned step by step in the xw plane, each view's double curves found and its halos
//! verified against them.
//!
//! ```sh
//! cargo run --release --example turn_in_4d                     # the default scene, 6 views
//! cargo run --release --example turn_in_4d -- fixtures/scenes/klein-bottle.json 12
//! ```

use halo4d::{Sampled, Scene, Stages};
use std::path::Path;
use std::process::ExitCode;

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let mut scene = match args.next() {
        Some(path) => Scene::load(Path::new(&path))?,
        None => Scene::default_scene(),
    };
    let steps: u32 = match args.next() {
        Some(n) => n
            .parse()
            .map_err(|e| format!("STEPS: {e}: give a whole number of views, 1 or more"))?,
        None => 6,
    };
    if steps == 0 {
        return Err("STEPS: give a whole number of views, 1 or more".into());
    }
    // A scene whose view is "auto" starts from the view the search finds.
    halo4d::resolve_view(&mut scene, halo4d::progress::Job::SILENT)?;

    // The 4D meshes do not depend on the view: sampled and audited once.
    let sampled = Sampled::of(&scene);
    println!(
        "{}: {} triangles, sampled and audited in {:.0} ms",
        scene.name,
        sampled.triangles(),
        sampled.ms()
    );
    println!(
        "{:>8} {:>7} {:>7} {:>14} {:>9}",
        "xw (°)", "curves", "points", "triple points", "verified"
    );
    // Halos, curves and their verification; no picture, no files.
    let stages = Stages {
        halos: true,
        curves: true,
        verify: true,
        stipples: false,
    };
    for k in 0..steps {
        let mut turned = scene.clone();
        turned.view.rotation.xw =
            (scene.view.rotation.xw + 360.0 * f64::from(k) / f64::from(steps)).rem_euclid(360.0);
        let built = sampled.build(&turned, stages)?;
        let curves = built.shown_curves();
        let points: usize = curves.curves.iter().map(|c| c.points.len()).sum();
        let failures = built.failures();
        println!(
            "{:>8.1} {:>7} {:>7} {:>14} {:>9}",
            turned.view.rotation.xw,
            curves.curves.len(),
            points,
            curves.triple_points.len(),
            if failures.is_empty() { "yes" } else { "NO" }
        );
        for f in failures {
            println!("         {f}");
        }
    }
    Ok(())
}
