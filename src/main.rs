//! The `halo4d` command line.

use clap::{Parser, Subcommand};
use halo4d::{Scene, Surface};
use std::path::PathBuf;
use std::process::ExitCode;

/// Surfaces in 4D turned into verified 3D geometry: glTF for Blender, PLY for MeshLab.
#[derive(Parser)]
#[command(name = "halo4d", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Build a scene: sample, view and export its surfaces.
    Build {
        /// Scene file (JSON). Without it, the built-in default scene (a spun trefoil in an
        /// oblique 4D view) is built.
        scene: Option<PathBuf>,
        /// Output folder [default: exports/<scene name>/].
        #[arg(long)]
        out: Option<PathBuf>,
        /// No progress bar.
        #[arg(long, short)]
        quiet: bool,
    },
    /// Speed against error: for each surface of a scene, the adaptive sampler and the
    /// coarsest uniform grid at relative tolerances 1e-2 to 1e-5, audited alike. Writes
    /// speed_vs_error.csv and speed_vs_error.png.
    Sweep {
        /// Scene file (JSON) [default: the built-in default scene].
        scene: Option<PathBuf>,
        /// Output folder.
        #[arg(long, default_value = "exports/reports")]
        out: PathBuf,
        /// Relative tolerances, comma-separated.
        #[arg(long, value_delimiter = ',', default_values_t = halo4d::sweep::TOLERANCES)]
        tolerances: Vec<f64>,
        /// The most triangles of any one mesh.
        #[arg(long, default_value_t = 8_000_000)]
        max_triangles: usize,
        /// No progress messages.
        #[arg(long, short)]
        quiet: bool,
    },
    /// List the surface catalogue with each surface's parameters and defaults.
    List,
}

fn load(scene: Option<PathBuf>) -> Result<Scene, halo4d::SceneError> {
    match scene {
        Some(path) => Scene::load(&path),
        None => Ok(Scene::default_scene()),
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Build { scene, out, quiet } => {
            let scene = match load(scene) {
                Ok(s) => s,
                Err(e) => return fail(&e),
            };
            let out = out.unwrap_or_else(|| PathBuf::from("exports").join(&scene.name));
            match halo4d::build(&scene, &out, quiet) {
                Ok(report) => {
                    for s in &report.surfaces {
                        eprintln!(
                            "{:<24} {:>9} vertices {:>9} triangles  Euler characteristic {}",
                            s.name, s.vertices, s.triangles, s.mesh.euler_characteristic
                        );
                    }
                    let t = report.timings_ms;
                    eprintln!(
                        "sample {:.1} ms, audit {:.1} ms, view {:.1} ms, export {:.1} ms, total {:.1} ms",
                        t.sample, t.audit, t.view, t.export, t.total
                    );
                    for f in &report.files {
                        println!("{}", out.join(f).display());
                    }
                    ExitCode::SUCCESS
                }
                Err(e) => fail(&e),
            }
        }
        Command::Sweep {
            scene,
            out,
            tolerances,
            max_triangles,
            quiet,
        } => {
            let scene = match load(scene) {
                Ok(s) => s,
                Err(e) => return fail(&e),
            };
            if let Some(bad) = tolerances.iter().find(|t| !(1e-9..=0.5).contains(*t)) {
                eprintln!(
                    "error: --tolerances: every tolerance must be from 1e-9 to 0.5 (a share of the bounding diagonal), got {bad}"
                );
                return ExitCode::FAILURE;
            }
            if !(64..=halo4d::scene::MAX_TRIANGLES).contains(&max_triangles) {
                eprintln!(
                    "error: --max-triangles must be from 64 to {}, got {max_triangles}",
                    halo4d::scene::MAX_TRIANGLES
                );
                return ExitCode::FAILURE;
            }
            let surfaces: Vec<_> = (0..scene.surfaces.len())
                .map(|i| (scene.surface_name(i), scene.surfaces[i].surface.clone()))
                .collect();
            let settings = halo4d::sweep::Settings {
                tolerances,
                max_triangles,
            };
            let mut progress = |msg: &str| {
                if !quiet {
                    eprintln!("{msg}");
                }
            };
            match halo4d::sweep::run(&surfaces, &settings, &out, &mut progress) {
                Ok((rows, files)) => {
                    print!("{}", halo4d::sweep::table(&rows));
                    for f in files {
                        println!("{}", f.display());
                    }
                    ExitCode::SUCCESS
                }
                Err(e) => fail(&e),
            }
        }
        Command::List => {
            for s in Surface::catalogue() {
                let mut params = serde_json::to_value(&s).unwrap_or_default();
                if let Some(map) = params.as_object_mut() {
                    map.remove("type");
                }
                println!("{:<20} {}", s.type_name(), s.description());
                println!(
                    "{:<20} patches: {}, defaults: {}",
                    "",
                    s.patch_count(),
                    params
                );
            }
            ExitCode::SUCCESS
        }
    }
}

fn fail(e: &dyn std::error::Error) -> ExitCode {
    eprintln!("error: {e}");
    ExitCode::FAILURE
}
