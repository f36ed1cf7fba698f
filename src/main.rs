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
    /// List the surface catalogue with each surface's parameters and defaults.
    List,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Build { scene, out, quiet } => {
            let scene = match scene {
                Some(path) => match Scene::load(&path) {
                    Ok(s) => s,
                    Err(e) => return fail(&e),
                },
                None => Scene::default_scene(),
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
                        "sample {:.1} ms, view {:.1} ms, export {:.1} ms, total {:.1} ms",
                        t.sample, t.view, t.export, t.total
                    );
                    for f in &report.files {
                        println!("{}", out.join(f).display());
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
