//! The `halo4d` command line.

use clap::{Parser, Subcommand};
use halo4d::limits::{self, FieldError};
use halo4d::{Comparison, FrameRange, Shard};
use halo4d::{RenderMode, Style};
use halo4d::{Scene, sweep};
use std::path::{Path, PathBuf};
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
        /// Scene file (JSON). Without it, the built-in default scene (a spun trefoil in the
        /// 4D view the view search found) is built.
        scene: Option<PathBuf>,
        /// Output folder [default: exports/<scene name>/].
        #[arg(long)]
        out: Option<PathBuf>,
        /// No progress bar.
        #[arg(long, short)]
        quiet: bool,
        /// Exit 0 even when the build's own verification fails (the files are written, and
        /// marked `verified: false`, either way).
        #[arg(long)]
        allow_unverified: bool,
    },
    /// Speed against error: for each surface of a scene, the adaptive sampler and the
    /// coarsest uniform grid at relative tolerances 1e-2 to 1e-5, audited alike, each mesh
    /// with its self-intersection curves in the scene's view (time, the mesh curve's error,
    /// the refined curve's residual). Writes speed_vs_error.csv, speed_vs_error.png and
    /// curves_vs_error.png.
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
        #[arg(long, default_value_t = limits::SWEEP_TRIANGLES)]
        max_triangles: usize,
        /// Instead: the picture's speed against error. Builds the scene, renders it in the
        /// exact mode and with each of --slices, and writes render_speed_vs_error.csv and
        /// render_speed_vs_error.png (time, share of pixels whose hidden/visible verdict
        /// differs from the exact mode's, mean and 99th-percentile pixel difference).
        #[arg(long)]
        render: bool,
        /// Slice counts for --render, comma-separated.
        #[arg(long, value_delimiter = ',', default_values_t = [32u32, 64, 128, 256, 512])]
        slices: Vec<u32>,
        /// No progress messages.
        #[arg(long, short)]
        quiet: bool,
    },
    /// Render a scene's picture (its `camera` and `render` settings, with the flags below
    /// overriding them) to a PNG.
    Render {
        /// Scene file (JSON) [default: the built-in default scene].
        scene: Option<PathBuf>,
        /// The PNG to write [default: exports/<scene name>/<scene name>.png].
        #[arg(long)]
        out: Option<PathBuf>,
        /// Image width in pixels.
        #[arg(long)]
        width: Option<u32>,
        /// Image height in pixels.
        #[arg(long)]
        height: Option<u32>,
        /// How halos hide sheets: exact (per hit, the reference) or slices (paper 000).
        #[arg(long, value_enum)]
        mode: Option<RenderMode>,
        /// Slices for --mode slices.
        #[arg(long)]
        slices: Option<u32>,
        /// How surfaces are drawn: shaded (Phong over the w colours) or stipple (paper 003).
        #[arg(long, value_enum)]
        style: Option<Style>,
        /// A cross-eyed stereo pair side by side.
        #[arg(long)]
        stereo: bool,
        /// No progress bar.
        #[arg(long, short)]
        quiet: bool,
    },
    /// Animate a scene: the frames of its `animation`, each the build of the scene in that
    /// frame's 4D view and camera, its halos verified against its curves, its picture
    /// (frame-00042.png) and record (frame-00042.json: view, counts, verification,
    /// timings). The surfaces are sampled once. A rerun makes only the frames without a
    /// record; any number of processes may fill one folder side by side (`--shard`).
    ///
    /// Exit status 0 when every frame of the run is verified, 3 when one is not (its
    /// record says why), 1 on an error. With --status: 0 when every frame of the folder is
    /// done and verified, 1 when not, 2 when the folder is not an animation's. With
    /// --assemble: 0 when the animation was written, 1 when frames are missing or not
    /// verified (listed) or the folder is unreadable.
    Animate {
        /// Scene file (JSON) with an `animation`.
        #[arg(required_unless_present_any = ["assemble", "status"])]
        scene: Option<PathBuf>,
        /// Folder of the frames [default: exports/<scene name>/frames/].
        #[arg(long)]
        out: Option<PathBuf>,
        /// Only these frames: A..B (A to B - 1), A..=B, or A.
        #[arg(long, value_name = "A..B")]
        frames: Option<FrameRange>,
        /// Only the frames whose index modulo N is I: task I of N of a batch engine's array
        /// (`--shard $SLURM_ARRAY_TASK_ID/N`, `--shard $JOB_COMPLETION_INDEX/N`).
        #[arg(long, value_name = "I/N")]
        shard: Option<Shard>,
        /// Picture width in pixels [default: the scene's render.width].
        #[arg(long)]
        width: Option<u32>,
        /// Picture height in pixels [default: the scene's render.height].
        #[arg(long)]
        height: Option<u32>,
        /// Write each frame's .glb too (frame-00042.glb).
        #[arg(long)]
        glb: bool,
        /// No progress output.
        #[arg(long, short)]
        quiet: bool,
        /// Instead: check that every frame of the folder DIR is done and verified (else
        /// list those that are not), write frames.jsonl and the animated PNG animation.png,
        /// and print the ffmpeg command line for an MP4.
        #[arg(long, value_name = "DIR", conflicts_with_all = ["scene", "status", "frames", "shard", "glb", "out"])]
        assemble: Option<PathBuf>,
        /// Instead: print where the frames of the folder DIR stand (done, failed, missing).
        #[arg(long, value_name = "DIR", conflicts_with_all = ["scene", "frames", "shard", "glb", "out"])]
        status: Option<PathBuf>,
    },
    /// List the surface catalogue with each surface's parameters and defaults.
    List,
    /// Build every scene of a folder (paper 000's figures by default) into a gallery: each
    /// figure's picture and report in a folder of its own, an index page (index.html) with
    /// each picture's description, the share of its double curves in view and its
    /// verdict, and a contact sheet of all the pictures (gallery.png).
    ///
    /// Exit status 0 when every figure is verified, 3 when one is not, 1 on an error.
    Gallery {
        /// The folder of scene files.
        #[arg(default_value = "fixtures/figures")]
        figures: PathBuf,
        /// The gallery's folder.
        #[arg(long, default_value = "exports/gallery")]
        out: PathBuf,
        /// No progress output.
        #[arg(long, short)]
        quiet: bool,
    },
    /// Check the halos of a .glb or .vtk file with the independent checker, or a build's
    /// output folder: its halos and their verification against the intersection curves.
    ///
    /// With a FILE, prints the checker's statistics, one column per halo. Exit status 0 when
    /// every halo passes the checker (conforms, no inverted, flat or undecidable
    /// tetrahedron, a volume defect of at most 1e-9), 1 when one does not, 2 when the file
    /// cannot be read as halos.
    ///
    /// With a folder (what `halo4d build --out DIR` wrote), reads its one .glb, runs the
    /// checker on each halo, recomputes the intersection curves of the file's surfaces and
    /// verifies the halos against them (along every curve the far sheet hidden by the near
    /// sheet's halo and the near sheet visible; nowhere a halo cutting a gap away from its
    /// sheet), and prints both. Exit status 0 when every halo passes the checker, every
    /// curve is resolved and the verification finds no wrong curve sample and no spurious
    /// hidden sample (a build's own verdict), 1 when something failed (a `FAILED` line says
    /// what), 2 when the folder or its .glb cannot be read.
    /// Search the 4D view and camera orbit that show the most of a scene's double curves
    /// (their visible length in the picture times the share visible, by rays from the
    /// eye), on a coarse grid of the surfaces; prints what it found and writes the scene
    /// with that view (`view.rotation`, `camera.azimuth` and `camera.elevation`; the rest
    /// of the file as it was) to --out.
    View {
        /// Scene file (JSON) [default: the built-in default scene].
        scene: Option<PathBuf>,
        /// The scene file to write with the view found; without it, nothing is written.
        #[arg(long)]
        out: Option<PathBuf>,
        /// No progress bar.
        #[arg(long, short)]
        quiet: bool,
    },
    Check {
        /// A .glb (every mesh with `halo` extras) or legacy .vtk (with `surface_vertices`
        /// field data) file, or a folder with one scene .glb, as `halo4d build` writes them.
        #[arg(value_name = "FILE|DIR")]
        file: PathBuf,
    },
}

/// The scene file (the default scene without one), its view found by the view search when
/// it is `"auto"`.
fn load(scene: Option<PathBuf>, quiet: bool) -> Result<Scene, Box<dyn std::error::Error>> {
    let mut scene = match scene {
        Some(path) => Scene::load(&path)?,
        None => Scene::default_scene(),
    };
    if let Some(found) = halo4d::resolve_view(&mut scene, quiet)?
        && !quiet
    {
        eprintln!("{}", found.summary());
    }
    Ok(scene)
}

/// The exit status of a build whose own verification failed.
const UNVERIFIED: u8 = 3;

fn main() -> ExitCode {
    match run(Cli::parse().command) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(command: Command) -> Result<ExitCode, Box<dyn std::error::Error>> {
    match command {
        Command::Build {
            scene,
            out,
            quiet,
            allow_unverified,
        } => {
            let scene = load(scene, quiet)?;
            let out = out.unwrap_or_else(|| PathBuf::from("exports").join(&scene.name));
            let report = halo4d::build(&scene, &out, quiet)?;
            eprint!("{}", report.summary());
            for f in &report.files {
                println!("{}", out.join(f).display());
            }
            if report.verified {
                return Ok(ExitCode::SUCCESS);
            }
            for f in &report.failures {
                eprintln!("UNVERIFIED {f}");
            }
            // Say where the verdict is marked only in files that were written.
            let marks: Vec<&str> = [
                (scene.outputs.report, "report.json"),
                (scene.outputs.glb, "the .glb's asset extras"),
            ]
            .into_iter()
            .filter_map(|(written, what)| written.then_some(what))
            .collect();
            eprintln!(
                "the build is not verified: {}{}",
                if marks.is_empty() {
                    "the files asked for are written; none records the verdict (outputs.report and outputs.glb are off)".to_string()
                } else {
                    format!(
                        "its files are written and marked `verified: false` ({})",
                        marks.join(", ")
                    )
                },
                if allow_unverified {
                    ""
                } else {
                    "; exit status 3 (--allow-unverified exits 0)"
                }
            );
            Ok(if allow_unverified {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(UNVERIFIED)
            })
        }
        Command::View { scene, out, quiet } => {
            // Read once: parsed here, and written back with the view found.
            let (text, parsed) = match &scene {
                Some(path) => {
                    let text = std::fs::read_to_string(path)
                        .map_err(|e| format!("{}: cannot read the scene: {e}", path.display()))?;
                    let parsed = Scene::parse(&text, &path.display().to_string())?;
                    (text, parsed)
                }
                None => (halo4d::DEFAULT_SCENE.to_string(), Scene::default_scene()),
            };
            let found = halo4d::search_view(&parsed, quiet)?;
            eprintln!("{}", found.summary());
            let mut json: serde_json::Value = serde_json::from_str(&text)?;
            let rotation = serde_json::to_value(found.rotation)?;
            let object = json
                .as_object_mut()
                .ok_or("the scene is not a JSON object")?;
            let view = object
                .entry("view")
                .or_insert_with(|| serde_json::json!({}));
            view["rotation"] = rotation;
            let camera = object
                .entry("camera")
                .or_insert_with(|| serde_json::json!({}));
            camera["azimuth"] = serde_json::json!(found.azimuth);
            camera["elevation"] = serde_json::json!(found.elevation);
            let text = serde_json::to_string_pretty(&json)? + "\n";
            match out {
                Some(out) => {
                    halo4d::internals::write_atomic(&out, text.as_bytes())
                        .map_err(|e| format!("{}: cannot write the scene: {e}", out.display()))?;
                    println!("{}", out.display());
                }
                None => print!("{text}"),
            }
            Ok(ExitCode::SUCCESS)
        }
        Command::Render {
            scene,
            out,
            width,
            height,
            mode,
            slices,
            style,
            stereo,
            quiet,
        } => {
            let mut scene = load(scene, quiet)?;
            let r = &mut scene.render;
            r.width = width.unwrap_or(r.width);
            r.height = height.unwrap_or(r.height);
            r.slices = slices.unwrap_or(r.slices);
            r.stereo |= stereo;
            r.mode = mode.unwrap_or(r.mode);
            r.style = style.unwrap_or(r.style);
            let out = out.unwrap_or_else(|| {
                Path::new("exports")
                    .join(&scene.name)
                    .join(format!("{}.png", scene.name))
            });
            let (picture, ms) = halo4d::render_to(&scene, &out, quiet)?;
            eprintln!(
                "{} x {} {:?} render in {ms:.0} ms",
                picture.width, picture.height, scene.render.mode
            );
            println!("{}", out.display());
            Ok(ExitCode::SUCCESS)
        }
        Command::Sweep {
            scene,
            out,
            tolerances,
            max_triangles,
            render,
            slices,
            quiet,
        } => {
            let scene = load(scene, quiet)?;
            let files = if render {
                let mut progress = |r: &Comparison| {
                    if !quiet {
                        eprintln!(
                            "{:>5} {:>9.0} ms  verdict differs on {:.3}% of covered pixels, p99 difference {:.3}",
                            if r.slices == 0 {
                                "exact".to_string()
                            } else {
                                r.slices.to_string()
                            },
                            r.ms,
                            100.0 * r.verdict_differs,
                            r.p99_diff
                        );
                    }
                };
                sweep::picture_sweep(&scene, &slices, &out, quiet, &mut progress)
                    .map_err(flag_names)?
                    .1
            } else {
                let surfaces = (0..scene.surfaces.len())
                    .map(|i| match &scene.surfaces[i].surface {
                        halo4d::Source::Parametric(s) => Ok((scene.surface_name(i), s.clone())),
                        halo4d::Source::Mesh(m) => Err(format!(
                            "surface `{}` is a mesh file ({}): the sweep samples parametric surfaces at several tolerances; sweep the pictures (`--slices`) instead",
                            scene.surface_name(i),
                            halo4d::limits::shorten(&m.path)
                        )),
                    })
                    .collect::<Result<Vec<_>, _>>()?;
                let settings = sweep::Settings {
                    tolerances,
                    max_triangles,
                    view: scene.view,
                };
                let mut progress = |msg: &str| {
                    if !quiet {
                        eprintln!("{msg}");
                    }
                };
                let (rows, files) =
                    sweep::run(&surfaces, &settings, &out, &mut progress).map_err(flag_names)?;
                print!("{}", sweep::table(&rows));
                files
            };
            for f in files {
                println!("{}", f.display());
            }
            Ok(ExitCode::SUCCESS)
        }
        Command::Animate {
            scene,
            out,
            frames,
            shard,
            width,
            height,
            glb,
            quiet,
            assemble,
            status,
        } => {
            if let Some(dir) = status {
                return Ok(match halo4d::status(&dir) {
                    Ok(s) => {
                        print!("{}", s.text());
                        if s.complete() {
                            ExitCode::SUCCESS
                        } else {
                            ExitCode::FAILURE
                        }
                    }
                    Err(e) => {
                        eprintln!("error: {e}");
                        ExitCode::from(2)
                    }
                });
            }
            if let Some(dir) = assemble {
                let a = halo4d::assemble(&dir)?;
                eprintln!(
                    "{} frames assembled into an animated PNG of {:.1} MB",
                    a.frames,
                    a.bytes as f64 / 1e6
                );
                eprintln!(
                    "an MP4 with ffmpeg{}:\n  {}",
                    if a.ffmpeg_found {
                        ""
                    } else {
                        " (not found on this machine; install it, e.g. apt-get install ffmpeg)"
                    },
                    a.ffmpeg
                );
                println!("{}", a.path.display());
                return Ok(ExitCode::SUCCESS);
            }
            let mut scene = load(scene, quiet)?;
            let r = &mut scene.render;
            r.width = width.unwrap_or(r.width);
            r.height = height.unwrap_or(r.height);
            scene
                .render
                .check()
                .map_err(|e| flag_field(e.field.as_str(), e.message))?;
            let out = out.unwrap_or_else(|| Path::new("exports").join(&scene.name).join("frames"));
            let summary = halo4d::animate(&halo4d::Request {
                scene: &scene,
                out: &out,
                frames,
                shard: shard.unwrap_or(Shard::ALL),
                glb,
                quiet,
            })?;
            if !quiet {
                eprintln!(
                    "{} frames in this run: {} made, {} done before; {} not verified; {:.1} s",
                    summary.selected,
                    summary.made,
                    summary.skipped,
                    summary.failed.len(),
                    summary.ms / 1e3
                );
            }
            for (k, why) in &summary.failed {
                eprintln!("UNVERIFIED frame {k}: {why}");
            }
            println!("{}", out.display());
            Ok(if summary.failed.is_empty() {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(UNVERIFIED)
            })
        }
        Command::Gallery {
            figures,
            out,
            quiet,
        } => {
            let gallery = halo4d::gallery::make(&figures, &out, quiet, |k, n, file| {
                if !quiet {
                    eprintln!("figure {} of {n}: {}", k + 1, file.display());
                }
            })?;
            for f in &gallery.figures {
                let share = f
                    .report
                    .picture
                    .as_ref()
                    .map_or(f64::NAN, |p| p.curves.visible_curve_share);
                eprintln!(
                    "{:<36} {} visible curve share {share:.3}, {:.1} s",
                    f.name(),
                    if f.report.verified {
                        "verified    "
                    } else {
                        "NOT verified"
                    },
                    f.report.timings_ms.total / 1e3
                );
                for failure in &f.report.failures {
                    eprintln!("UNVERIFIED {}: {failure}", f.name());
                }
            }
            println!("{}", gallery.index.display());
            println!("{}", gallery.sheet.display());
            Ok(if gallery.verified() {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(UNVERIFIED)
            })
        }
        Command::List => {
            print!("{}", halo4d::Source::listing());
            Ok(ExitCode::SUCCESS)
        }
        Command::Check { file } => {
            let checked = if file.is_dir() {
                halo4d::check_dir(&file)
            } else {
                halo4d::check_file(&file)
            };
            match checked {
                Ok(c) => {
                    print!("{}", c.text());
                    Ok(if c.failures().is_empty() {
                        ExitCode::SUCCESS
                    } else {
                        ExitCode::FAILURE
                    })
                }
                Err(e) => {
                    eprintln!("error: {e}");
                    Ok(ExitCode::from(2))
                }
            }
        }
    }
}

/// A render setting's error named by its flag (`width` is `--width`).
fn flag_field(field: &str, message: String) -> FieldError {
    FieldError::new(format!("--{}", field.replace('_', "-")), message)
}

/// A sweep's setting error named by its flag (`max_triangles` is `--max-triangles`).
fn flag_names(e: sweep::SweepError) -> sweep::SweepError {
    match e {
        sweep::SweepError::Setting(f) => sweep::SweepError::Setting(FieldError {
            field: format!("--{}", f.field.replace('_', "-")),
            ..f
        }),
        other => other,
    }
}
