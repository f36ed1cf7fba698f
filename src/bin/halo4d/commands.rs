//! What each command of `halo4d` does: one function per command, each giving the exit
//! status.

use crate::cli::{
    AnimateArgs, BuildArgs, CheckArgs, GalleryArgs, RenderArgs, SliceArgs, SweepArgs, ViewArgs,
};
use crate::terminal::Terminal;
use clap::ValueEnum;
use halo4d::limits::{FieldError, shorten};
use halo4d::progress::{Cancel, Job};
use halo4d::{Scene, animate::Shard, render::Comparison, sweep};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// What a command gives: its exit status, or an error printed as `error: ...` (exit 1).
pub type Outcome = Result<ExitCode, Box<dyn std::error::Error>>;

/// The exit status of a build whose own verification failed.
const UNVERIFIED: u8 = 3;

/// The exit status of work stopped by `--timeout`, as `timeout(1)` gives.
const TIMED_OUT: u8 = 124;

/// The scene file (the default scene without one), its view found by the view search when
/// it is `"auto"`, which says what it found unless `quiet`.
fn load(
    scene: Option<PathBuf>,
    quiet: bool,
    job: Job,
) -> Result<Scene, Box<dyn std::error::Error>> {
    let mut scene = match scene {
        Some(path) => Scene::load(&path)?,
        None => Scene::default_scene(),
    };
    if let Some(found) = halo4d::resolve_view(&mut scene, job)?
        && !quiet
    {
        eprintln!("{}", found.summary());
    }
    Ok(scene)
}

/// Exit 124, saying so, where `--timeout` stopped the work of `watch`.
fn timed_out(watch: &Watch) -> Option<ExitCode> {
    let seconds = watch.timed_out()?;
    eprintln!("error: not finished within --timeout {seconds} s; nothing of it was written");
    Some(ExitCode::from(TIMED_OUT))
}

/// `halo4d build`.
pub fn build(args: BuildArgs) -> Outcome {
    // Reading the scene and finding its view are part of the build's time (`setup`).
    let started = std::time::Instant::now();
    let BuildArgs {
        scene,
        out,
        quiet,
        timeout,
        allow_unverified,
    } = args;
    let watch = Watch::new(quiet, timeout);
    let loaded = load(scene, quiet, watch.job());
    if let (Err(_), Some(code)) = (&loaded, timed_out(&watch)) {
        return Ok(code);
    }
    let scene = loaded?;
    let out = out.unwrap_or_else(|| PathBuf::from("exports").join(&scene.name));
    let built = halo4d::build_since(&scene, &out, watch.job(), started);
    if let (Err(_), Some(code)) = (&built, timed_out(&watch)) {
        return Ok(code);
    }
    let report = built?;
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

/// `halo4d view`.
pub fn view(args: ViewArgs) -> Outcome {
    let ViewArgs { scene, out, quiet } = args;
    let watch = Watch::new(quiet, None);
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
    let found = halo4d::search_view(&parsed, watch.job())?;
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
            halo4d::write_atomic(&out, text.as_bytes())
                .map_err(|e| format!("{}: cannot write the scene: {e}", out.display()))?;
            println!("{}", out.display());
        }
        None => print!("{text}"),
    }
    Ok(ExitCode::SUCCESS)
}

/// `halo4d render`.
pub fn render(args: RenderArgs) -> Outcome {
    let RenderArgs {
        scene,
        out,
        width,
        height,
        mode,
        slices,
        style,
        stereo,
        quiet,
    } = args;
    // The flag first: a bad path stops the command before the build.
    if let Some(out) = &out {
        png_path(out)?;
    }
    let watch = Watch::new(quiet, None);
    let mut scene = load(scene, quiet, watch.job())?;
    let r = &mut scene.render;
    r.width = width.unwrap_or(r.width);
    r.height = height.unwrap_or(r.height);
    r.slices = slices.unwrap_or(r.slices);
    r.stereo |= stereo;
    r.mode = mode.unwrap_or(r.mode);
    r.style = style.unwrap_or(r.style);
    // Beside the build's picture, not over it: its report.json describes that one.
    let out = out.unwrap_or_else(|| {
        Path::new("exports")
            .join(&scene.name)
            .join(format!("{}-render.png", scene.name))
    });
    let (picture, ms) = halo4d::render_to(&scene, &out, watch.job())?;
    eprintln!(
        "{} x {} {} picture, {} halos, in {ms:.0} ms",
        picture.width,
        picture.height,
        value_name(scene.render.style),
        value_name(scene.render.mode)
    );
    println!("{}", out.display());
    Ok(ExitCode::SUCCESS)
}

/// `--out` of `halo4d render`: a `.png` file's path, not a folder.
fn png_path(out: &Path) -> Result<(), FieldError> {
    let shown = shorten(&out.display().to_string());
    if out.is_dir() {
        return Err(FieldError::new(
            "--out",
            format!("`{shown}` is a folder; name the picture's file, e.g. {shown}/picture.png"),
        ));
    }
    let png = out
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if !png {
        return Err(FieldError::new(
            "--out",
            format!("`{shown}`: the picture is written as PNG; name a file ending in .png"),
        ));
    }
    Ok(())
}

/// `halo4d sweep`.
pub fn sweep(args: SweepArgs) -> Outcome {
    let SweepArgs {
        scene,
        out,
        tolerances,
        max_triangles,
        render,
        slices,
        quiet,
    } = args;
    let scene = load(scene, quiet, Watch::new(quiet, None).job())?;
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
        sweep::picture_sweep(&scene, &slices, &out, &mut progress)
            .map_err(flag_names)?
            .1
    } else {
        let surfaces = (0..scene.surfaces.len())
            .map(|i| match &scene.surfaces[i].surface {
                halo4d::sample::Source::Parametric(s) => Ok((scene.surface_name(i), s.clone())),
                halo4d::sample::Source::Mesh(m) => Err(format!(
                    "surface `{}` is a mesh file ({}): the sweep samples parametric surfaces at several tolerances; sweep the pictures (`--slices`) instead",
                    scene.surface_name(i),
                    shorten(&m.path)
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

/// `halo4d animate`, with `--status` and `--assemble`.
pub fn animate(args: AnimateArgs) -> Outcome {
    if let Some(dir) = &args.status {
        return Ok(match halo4d::animate::status(dir) {
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
    if let Some(dir) = &args.assemble {
        let a = halo4d::animate::assemble(dir)?;
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
    let quiet = args.quiet;
    let watch = Watch::new(quiet, None);
    let mut scene = load(args.scene, quiet, watch.job())?;
    let r = &mut scene.render;
    r.width = args.width.unwrap_or(r.width);
    r.height = args.height.unwrap_or(r.height);
    scene
        .render
        .check()
        .map_err(|e| flag_field(e.field.as_str(), e.message))?;
    let out = (args.out).unwrap_or_else(|| Path::new("exports").join(&scene.name).join("frames"));
    let summary = halo4d::animate::animate(
        &halo4d::animate::Request {
            scene: &scene,
            out: &out,
            frames: args.frames,
            shard: args.shard.unwrap_or(Shard::ALL),
            glb: args.glb,
        },
        watch.job(),
    )?;
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

/// `halo4d gallery`.
pub fn gallery(args: GalleryArgs) -> Outcome {
    let GalleryArgs {
        figures,
        out,
        quiet,
    } = args;
    let watch = Watch::new(quiet, None);
    let gallery = halo4d::gallery::make(&figures, &out, watch.job())?;
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

/// `halo4d list`.
pub fn list() -> Outcome {
    print!("{}", halo4d::sample::Source::listing());
    Ok(ExitCode::SUCCESS)
}

/// `halo4d check`.
pub fn check(args: CheckArgs) -> Outcome {
    let file = args.file;
    if let Some(mark) = &args.mark {
        let vtu = mark
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("vtu"));
        if !vtu || mark.is_dir() {
            eprintln!(
                "error: --mark {}: give a .vtu file to write the marked mesh to",
                mark.display()
            );
            return Ok(ExitCode::from(2));
        }
    }
    let checked = if file.is_dir() {
        halo4d::check_dir(&file)
    } else {
        halo4d::check_file(&file)
    };
    let c = match checked {
        Ok(c) => c,
        Err(e) => {
            eprintln!("error: {e}");
            return Ok(ExitCode::from(2));
        }
    };
    if let Some(mark) = &args.mark
        && let Err(e) = c.write_marks(mark)
    {
        eprintln!("error: {e}");
        return Ok(ExitCode::from(2));
    }
    if args.json {
        println!("{}", c.json());
    } else {
        print!("{}", c.text());
        if let Some(mark) = &args.mark {
            let marked: Vec<String> = c
                .marked()
                .iter()
                .map(|(name, n)| format!("{n} {name}"))
                .collect();
            println!(
                "wrote {} (cell field `fault`: {})",
                mark.display(),
                if marked.is_empty() {
                    "no cell marked".to_string()
                } else {
                    marked.join(", ")
                }
            );
        }
    }
    Ok(if c.failures().is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}

/// The name a flag gives a value (`stipple`, `exact`).
fn value_name(value: impl ValueEnum) -> String {
    value
        .to_possible_value()
        .map_or_else(String::new, |v| v.get_name().to_string())
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

/// `halo4d slice`.
pub fn slice(args: SliceArgs) -> Outcome {
    let SliceArgs {
        scene,
        direction,
        levels,
        perturb,
        film,
        out,
        quiet,
    } = args;
    // The flags first, named as flags: a bad one stops the command before the sampling.
    let flags = halo4d::motion::Slicing {
        direction,
        levels: levels.unwrap_or(0),
        perturb: perturb.unwrap_or(0.0),
        film: film.unwrap_or(0),
    };
    flags.check().map_err(|e| FieldError {
        field: format!("--{}", e.field),
        ..e
    })?;
    let watch = Watch::new(quiet, None);
    let scene = load(scene, quiet, watch.job())?;
    let out = out.unwrap_or_else(|| PathBuf::from("exports").join(&scene.name).join("motion"));
    let from_scene = scene.slicing.unwrap_or_default();
    let slicing = halo4d::motion::Slicing {
        direction: direction.or(from_scene.direction),
        levels: levels.unwrap_or(from_scene.levels),
        perturb: perturb.unwrap_or(from_scene.perturb),
        film: film.unwrap_or(from_scene.film),
    };
    let motion = halo4d::slicing::slice_scene(&scene, slicing, &out, watch.job())?;
    eprint!("{}", motion.summary());
    for f in &motion.files {
        println!("{}", out.join(f).display());
    }
    if motion.verified {
        return Ok(ExitCode::SUCCESS);
    }
    eprintln!(
        "the motion picture fails its checks: its files are written, motion.json lists the failures; exit status 3"
    );
    Ok(ExitCode::from(UNVERIFIED))
}

/// A command's observer and its cancel token, cancelled after `timeout` seconds when given.
struct Watch {
    terminal: Terminal,
    cancel: Cancel,
    timeout: Option<f64>,
}

impl Watch {
    /// The terminal (quiet or not) and a token that a timer cancels after `timeout`
    /// seconds.
    fn new(quiet: bool, timeout: Option<f64>) -> Watch {
        let cancel = Cancel::new();
        if let Some(seconds) = timeout {
            let timer = cancel.clone();
            std::thread::spawn(move || {
                std::thread::sleep(std::time::Duration::from_secs_f64(seconds));
                timer.cancel();
            });
        }
        Watch {
            terminal: Terminal::new(quiet),
            cancel,
            timeout,
        }
    }

    /// The timeout, once it has passed (and cancelled the work).
    fn timed_out(&self) -> Option<f64> {
        self.timeout.filter(|_| self.cancel.is_cancelled())
    }

    /// The job the library's work reports to.
    fn job(&self) -> Job<'_> {
        Job::new(&self.terminal, &self.cancel)
    }
}
