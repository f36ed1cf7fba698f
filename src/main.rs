//! The `halo4d` command line.

use clap::{Parser, Subcommand};
use halo4d::check::{CheckStats, check};
use halo4d::import::{ImportError, ImportedHalo, read_scene_glb};
use halo4d::{Scene, Surface};
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
        /// Scene file (JSON). Without it, the built-in default scene (a spun trefoil in an
        /// oblique 4D view) is built.
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
        mode: Option<ModeArg>,
        /// Slices for --mode slices.
        #[arg(long)]
        slices: Option<u32>,
        /// A cross-eyed stereo pair side by side.
        #[arg(long)]
        stereo: bool,
        /// No progress bar.
        #[arg(long, short)]
        quiet: bool,
    },
    /// List the surface catalogue with each surface's parameters and defaults.
    List,
    /// Check the halos of a .glb or .vtk file with the independent checker, or a build's
    /// output folder: its halos and their verification against the intersection curves.
    ///
    /// With a FILE, prints the checker's statistics, one column per halo. Exit status 0 when
    /// every halo conforms and has no inverted or flat tetrahedron, 1 when one does not, 2
    /// when the file cannot be read as halos.
    ///
    /// With a folder (what `halo4d build --out DIR` wrote), reads its one .glb, runs the
    /// checker on each halo, recomputes the intersection curves of the file's surfaces and
    /// verifies the halos against them (along every curve the far sheet hidden by the near
    /// sheet's halo and the near sheet visible; nowhere a halo cutting a gap away from its
    /// sheet), and prints both. Exit status 0 when every halo conforms with no inverted or
    /// flat tetrahedron and the verification finds no wrong curve sample and no spurious
    /// hidden sample, 1 when something failed (a `FAILED` line says what), 2 when the folder
    /// or its .glb cannot be read.
    Check {
        /// A .glb (every mesh with `halo` extras) or legacy .vtk (with `surface_vertices`
        /// field data) file, or a folder with one scene .glb, as `halo4d build` writes them.
        #[arg(value_name = "FILE|DIR")]
        file: PathBuf,
    },
}

/// `--mode` of `halo4d render`.
#[derive(Clone, Copy, clap::ValueEnum)]
enum ModeArg {
    /// Each hit asks the tetrahedra whether it is hidden.
    Exact,
    /// Halo depth images on planes perpendicular to the view.
    Slices,
}

/// `halo4d sweep --render`.
fn render_sweep(scene: &Scene, slices: &[u32], out: &Path, quiet: bool) -> ExitCode {
    if let Some(bad) = slices.iter().find(|n| !(1..=4096).contains(*n)) {
        eprintln!("error: --slices: every count must be 1 to 4096, got {bad}");
        return ExitCode::FAILURE;
    }
    let built = match halo4d::run_for_picture(scene, quiet) {
        Ok(b) => b,
        Err(e) => return fail(&e),
    };
    let parts = built.render_parts(&scene.halo);
    let input = parts.input();
    let mut progress = |r: &halo4d::render::compare::Comparison| {
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
    let rows = match halo4d::render::compare::compare(
        &input,
        &scene.render,
        &scene.camera,
        slices,
        &mut progress,
    ) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::FAILURE;
        }
    };
    if let Err(e) = std::fs::create_dir_all(out) {
        eprintln!("error: cannot create {}: {e}", out.display());
        return ExitCode::FAILURE;
    }
    let title = format!(
        "{}: multi-slice halos against the exact mode, {} x {}",
        scene.name, scene.render.width, scene.render.height
    );
    let plot = match halo4d::export::render_speed_vs_error_png(&rows, &title) {
        Ok(p) => p,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::FAILURE;
        }
    };
    for (name, bytes) in [
        (
            "render_speed_vs_error.csv",
            halo4d::render::compare::to_csv(&rows).into_bytes(),
        ),
        ("render_speed_vs_error.png", plot),
    ] {
        let path = out.join(name);
        if let Err(e) = halo4d::export::write_atomic(&path, &bytes) {
            eprintln!("error: cannot write {}: {e}", path.display());
            return ExitCode::FAILURE;
        }
        println!("{}", path.display());
    }
    ExitCode::SUCCESS
}

fn load(scene: Option<PathBuf>) -> Result<Scene, halo4d::SceneError> {
    match scene {
        Some(path) => Scene::load(&path),
        None => Ok(Scene::default_scene()),
    }
}

/// The exit status of a build whose own verification failed.
const UNVERIFIED: u8 = 3;

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Build {
            scene,
            out,
            quiet,
            allow_unverified,
        } => {
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
                    match &report.curves {
                        Some(c) => eprintln!(
                            "curves: {} ({} closed, {} open), {} points, {} triple points, {} unresolved",
                            c.count, c.closed, c.open, c.points, c.triple_points, c.unresolved
                        ),
                        None => eprintln!("curves: not computed (no output uses them)"),
                    }
                    match &report.halo_verification {
                        Some(v) => eprintln!(
                            "halo verification: {} curve samples: {} correct, {} wrong, {} ambiguous, {} third sheet; {} surface samples, {} far tetrahedra, {} spurious",
                            v.curve_samples,
                            v.correct,
                            v.wrong,
                            v.ambiguous,
                            v.third_sheet,
                            v.surface_samples,
                            v.far_tetrahedra,
                            v.spurious_hidden_samples
                        ),
                        None => eprintln!(
                            "halo verification: not run (no halo file written; `outputs.verify: true` asks for it)"
                        ),
                    }
                    let t = report.timings_ms;
                    eprintln!(
                        "sample {:.1} ms, audit {:.1} ms, view {:.1} ms, halo {:.1} ms, curves {:.1} ms, verify {:.1} ms, export {:.1} ms, render {:.1} ms, total {:.1} ms",
                        t.sample,
                        t.audit,
                        t.view,
                        t.halo,
                        t.curves,
                        t.verify,
                        t.export,
                        t.render,
                        t.total
                    );
                    eprintln!(
                        "memory: about {:.2} GB estimated from the halos on, limit {:.2} GB{}",
                        report.memory.estimate_gb,
                        report.memory.limit_gb,
                        report
                            .memory
                            .peak_gb
                            .map(|gb| format!(", peak {gb:.2} GB"))
                            .unwrap_or_default()
                    );
                    for f in &report.files {
                        println!("{}", out.join(f).display());
                    }
                    if report.verified {
                        return ExitCode::SUCCESS;
                    }
                    for f in &report.failures {
                        eprintln!("UNVERIFIED {f}");
                    }
                    eprintln!(
                        "the build is not verified: its files are written and marked `verified: false` (report.json, the .glb's asset extras){}",
                        if allow_unverified {
                            ""
                        } else {
                            "; exit status 3 (--allow-unverified exits 0)"
                        }
                    );
                    if allow_unverified {
                        ExitCode::SUCCESS
                    } else {
                        ExitCode::from(UNVERIFIED)
                    }
                }
                Err(e) => fail(&e),
            }
        }
        Command::Render {
            scene,
            out,
            width,
            height,
            mode,
            slices,
            stereo,
            quiet,
        } => {
            let mut scene = match load(scene) {
                Ok(s) => s,
                Err(e) => return fail(&e),
            };
            let r = &mut scene.render;
            r.width = width.unwrap_or(r.width);
            r.height = height.unwrap_or(r.height);
            r.slices = slices.unwrap_or(r.slices);
            r.stereo |= stereo;
            if let Some(m) = mode {
                r.mode = match m {
                    ModeArg::Exact => halo4d::render::RenderMode::Exact,
                    ModeArg::Slices => halo4d::render::RenderMode::Slices,
                };
            }
            if let Err((field, message)) = scene.render.check() {
                eprintln!("error: render.{field}: {message}");
                return ExitCode::FAILURE;
            }
            let out = out.unwrap_or_else(|| {
                Path::new("exports")
                    .join(&scene.name)
                    .join(format!("{}.png", scene.name))
            });
            let built = match halo4d::run_for_picture(&scene, quiet) {
                Ok(b) => b,
                Err(e) => return fail(&e),
            };
            let start = std::time::Instant::now();
            let picture = match built.render(&scene.halo, &scene.render, &scene.camera) {
                Ok(p) => p,
                Err(e) => {
                    eprintln!("error: {e}");
                    return ExitCode::FAILURE;
                }
            };
            let ms = start.elapsed().as_secs_f64() * 1e3;
            if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty())
                && let Err(e) = std::fs::create_dir_all(dir)
            {
                eprintln!("error: cannot create {}: {e}", dir.display());
                return ExitCode::FAILURE;
            }
            if let Err(e) = halo4d::export::write_atomic(&out, &picture.png()) {
                eprintln!("error: cannot write {}: {e}", out.display());
                return ExitCode::FAILURE;
            }
            eprintln!(
                "{} x {} {:?} render in {ms:.0} ms",
                picture.width, picture.height, scene.render.mode
            );
            println!("{}", out.display());
            ExitCode::SUCCESS
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
            let scene = match load(scene) {
                Ok(s) => s,
                Err(e) => return fail(&e),
            };
            if render {
                return render_sweep(&scene, &slices, &out, quiet);
            }
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
            for (name, surface) in &surfaces {
                let least = halo4d::sweep::coarsest_grid_triangles(surface);
                if max_triangles < least {
                    eprintln!(
                        "error: --max-triangles {max_triangles} is less than the {least} triangles of the coarsest grid of `{name}` ({} patches); give at least {least}",
                        surface.patch_count()
                    );
                    return ExitCode::FAILURE;
                }
            }
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
        Command::Check { file } if file.is_dir() => check_dir(&file),
        Command::Check { file } => check_file(&file),
    }
}

/// `halo4d check FILE`.
fn check_file(file: &Path) -> ExitCode {
    let halos = match halo4d::import::read(file) {
        Ok(h) => h,
        Err(e) => {
            eprintln!("error: {}: {e}", file.display());
            return ExitCode::from(2);
        }
    };
    let halos: Vec<&ImportedHalo> = halos.iter().collect();
    if !check_halos(&halos) {
        return ExitCode::FAILURE;
    }
    println!(
        "ok: {}, no inverted or flat tetrahedron",
        conform(halos.len())
    );
    ExitCode::SUCCESS
}

/// `halo4d check DIR`.
fn check_dir(dir: &Path) -> ExitCode {
    let file = match scene_glb(dir) {
        Ok(f) => f,
        Err(message) => {
            eprintln!("error: {}: {message}", dir.display());
            return ExitCode::from(2);
        }
    };
    let scene = match std::fs::read(&file)
        .map_err(ImportError::from)
        .and_then(|bytes| read_scene_glb(&bytes))
    {
        Ok(s) => s,
        Err(e) => {
            eprintln!("error: {}: {e}", file.display());
            return ExitCode::from(2);
        }
    };
    match &scene.name {
        Some(name) => println!("scene {name}: {}", file.display()),
        None => println!("{}", file.display()),
    }
    let halos: Vec<&ImportedHalo> = scene
        .surfaces
        .iter()
        .filter_map(|s| s.halo.as_ref())
        .collect();
    let mut ok = check_halos(&halos);
    let (curves, v) = scene.verify();
    let c = &curves.report;
    println!();
    println!(
        "curves: {} ({} closed, {} open), {} points, {} triple points, {} unresolved",
        c.count, c.closed, c.open, c.points, c.triple_points, c.unresolved
    );
    let rows = [
        ("curve_samples", v.curve_samples),
        ("correct", v.correct),
        ("wrong", v.wrong),
        ("ambiguous", v.ambiguous),
        ("  branch_point", v.ambiguous_reasons.branch_point),
        ("  boundary", v.ambiguous_reasons.boundary),
        ("  vanished_halo", v.ambiguous_reasons.vanished_halo),
        ("  resolution", v.ambiguous_reasons.resolution),
        ("third_sheet", v.third_sheet),
        ("surface_samples", v.surface_samples),
        ("far_tetrahedra", v.far_tetrahedra),
        ("spurious_hidden_samples", v.spurious_hidden_samples),
    ];
    let width = rows.iter().map(|(k, _)| k.len()).max().unwrap_or(0);
    println!("{:<width$}  {:>9}", "halo verification", "samples");
    for (k, n) in rows {
        println!("{k:<width$}  {n:>9}");
    }
    let at = |points: &[[f64; 3]]| {
        points
            .first()
            .map(|p| format!(" (the first at ({:.6}, {:.6}, {:.6}))", p[0], p[1], p[2]))
            .unwrap_or_default()
    };
    if v.wrong > 0 {
        ok = false;
        println!(
            "FAILED halo verification: {} of {} curve samples wrong{}",
            v.wrong,
            v.curve_samples,
            at(&v.wrong_at)
        );
    }
    if v.spurious_hidden_samples > 0 {
        ok = false;
        println!(
            "FAILED halo verification: {} of {} surface samples hidden where no sheet is within rho{}",
            v.spurious_hidden_samples,
            v.surface_samples,
            at(&v.spurious_at)
        );
    }
    if !ok {
        return ExitCode::FAILURE;
    }
    println!(
        "ok: {}, no inverted or flat tetrahedron; {} curve samples correct, {} ambiguous, {} third sheet, none wrong; no spurious hidden sample",
        conform(halos.len()),
        v.correct,
        v.ambiguous,
        v.third_sheet
    );
    ExitCode::SUCCESS
}

/// The one `.glb` in `dir`, or why there is none.
fn scene_glb(dir: &Path) -> Result<PathBuf, String> {
    let entries = std::fs::read_dir(dir).map_err(|e| format!("cannot read the folder: {e}"))?;
    let mut glbs = Vec::new();
    for entry in entries {
        let path = entry
            .map_err(|e| format!("cannot read the folder: {e}"))?
            .path();
        if path.is_file()
            && path
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("glb"))
        {
            glbs.push(path);
        }
    }
    glbs.sort();
    match glbs.len() {
        1 => Ok(glbs.remove(0)),
        0 => Err(
            "no .glb in the folder: give a folder that `halo4d build` wrote with outputs.glb on"
                .into(),
        ),
        n => Err(format!(
            "{n} .glb files in the folder ({}); expected one, the scene's <name>.glb: check a file instead",
            glbs.iter()
                .filter_map(|p| p.file_name())
                .map(|n| n.to_string_lossy())
                .collect::<Vec<_>>()
                .join(", ")
        )),
    }
}

/// "1 halo conforms" or "n halos conform".
fn conform(n: usize) -> String {
    if n == 1 {
        "1 halo conforms".into()
    } else {
        format!("{n} halos conform")
    }
}

/// Runs the checker on each halo and prints its table and a `FAILED` line per halo that does
/// not conform or has an inverted or flat tetrahedron; returns whether none failed.
fn check_halos(halos: &[&ImportedHalo]) -> bool {
    if halos.is_empty() {
        println!("no halo in the file");
        return true;
    }
    let stats: Vec<CheckStats> = halos.iter().map(|h| check(&h.mesh)).collect();
    let names: Vec<&str> = halos.iter().map(|h| h.name.as_str()).collect();
    print!("{}", table(&names, &stats));
    let mut failed = false;
    for (name, s) in names.iter().zip(&stats) {
        if !s.passes() {
            failed = true;
            println!("FAILED {name}: {}", s.failures().join(", "));
        }
    }
    !failed
}

/// The checker's statistics as a table: a row per statistic, in the struct's order, and a
/// column per halo.
fn table(names: &[&str], stats: &[CheckStats]) -> String {
    let columns: Vec<Vec<(String, String)>> = stats.iter().map(stat_rows).collect();
    let labels: Vec<&str> = columns
        .first()
        .map(|c| c.iter().map(|(k, _)| k.as_str()).collect())
        .unwrap_or_default();
    let label_width = labels.iter().map(|l| l.len()).max().unwrap_or(0).max(4);
    let widths: Vec<usize> = names
        .iter()
        .zip(&columns)
        .map(|(n, c)| {
            c.iter()
                .map(|(_, v)| v.len())
                .max()
                .unwrap_or(0)
                .max(n.len())
        })
        .collect();
    let mut out = format!("{:<label_width$}", "halo");
    for (n, w) in names.iter().zip(&widths) {
        out += &format!("  {n:>w$}");
    }
    out.push('\n');
    for (row, label) in labels.iter().enumerate() {
        out += &format!("{label:<label_width$}");
        for (c, w) in columns.iter().zip(&widths) {
            out += &format!("  {:>w$}", c[row].1);
        }
        out.push('\n');
    }
    out
}

/// The fields of `stats` in declaration order, formatted. (Through serde, so that a
/// statistic added to the checker shows up here too.)
fn stat_rows(stats: &CheckStats) -> Vec<(String, String)> {
    struct Rows(Vec<(String, serde_json::Value)>);
    impl<'de> serde::Deserialize<'de> for Rows {
        fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
            struct Visit;
            impl<'de> serde::de::Visitor<'de> for Visit {
                type Value = Rows;
                fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                    f.write_str("a map")
                }
                fn visit_map<A: serde::de::MapAccess<'de>>(
                    self,
                    mut map: A,
                ) -> Result<Rows, A::Error> {
                    let mut rows = Vec::new();
                    while let Some(entry) = map.next_entry()? {
                        rows.push(entry);
                    }
                    Ok(Rows(rows))
                }
            }
            d.deserialize_map(Visit)
        }
    }
    let rows = serde_json::to_string(stats)
        .and_then(|text| serde_json::from_str::<Rows>(&text))
        .map(|r| r.0)
        .unwrap_or_default();
    rows.into_iter()
        .map(|(k, v)| {
            let text = match v {
                serde_json::Value::Number(n) if n.is_u64() || n.is_i64() => n.to_string(),
                serde_json::Value::Number(n) => {
                    let x = n.as_f64().unwrap_or(f64::NAN);
                    if x == 0.0 || (1e-2..1e6).contains(&x.abs()) {
                        format!("{x:.4}")
                    } else {
                        format!("{x:.3e}")
                    }
                }
                // serde_json writes a non-finite number as null.
                serde_json::Value::Null => "not finite".into(),
                other => other.to_string(),
            };
            (k, text)
        })
        .collect()
}

fn fail(e: &dyn std::error::Error) -> ExitCode {
    eprintln!("error: {e}");
    ExitCode::FAILURE
}
