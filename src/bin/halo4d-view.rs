//! `halo4d-view`: the wgpu viewer and 4D explorer of scenes and `.glb` files (see
//! `halo4d::viewer`).

use clap::Parser;
use halo4d::limits::{BENCH_FRAMES, FINITE, FieldError};
use halo4d::render::{CameraProjection, CameraSettings, Colormap, RenderSettings, Style};
use halo4d::view::View;
use halo4d::viewer::{self, Gpu, HaloMode, SLICE_COUNTS, Source, ViewSettings, ViewerError};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser, Debug)]
#[command(
    name = "halo4d-view",
    version,
    about = "Explore a scene in 4D (SCENE.json, or the default scene), or view a scene's .glb (written by `halo4d build`): surfaces, halos and curves on the GPU",
    after_help = viewer::window::HELP
)]
struct Args {
    /// A scene file (turned in 4D, its halos rebuilt on the GPU for every view), or a
    /// scene's .glb as `halo4d build` writes it (turned in 3D); the default scene if none.
    file: Option<PathBuf>,
    /// Turn the scene's 4D view: PLANE=DEGREES added to the scene's angle of that plane
    /// (xy, xz, xw, yz, yw or zw; applied in that order, as in the scene file). Repeatable.
    #[arg(long, value_name = "PLANE=DEGREES", value_parser = parse_rotate, allow_hyphen_values = true)]
    rotate: Vec<(String, f64)>,
    /// Write the scene with the current 4D view and camera to OUT.json, which `halo4d build`
    /// turns into the verified asset of that view.
    #[arg(long, value_name = "OUT.json")]
    save_scene: Option<PathBuf>,
    /// Render offscreen (no window, no display) and write --screenshot.
    #[arg(long)]
    headless: bool,
    /// The PNG a headless run writes.
    #[arg(long, value_name = "OUT.png")]
    screenshot: Option<PathBuf>,
    /// Image (or first window) size, WIDTHxHEIGHT.
    #[arg(long, value_name = "WxH", default_value = "1024x1024", value_parser = parse_size)]
    size: (u32, u32),
    /// Slices of the halo depth (64, 128, 256 or 512 in the window; 2 to 1024 here).
    #[arg(long, default_value_t = 256)]
    slices: u32,
    /// Samples per pixel (1, 4, 9 or 16; default 4 for --screenshot, as `halo4d render`,
    /// else 1).
    #[arg(long)]
    samples: Option<u32>,
    /// How the halo depth is sliced: once into a 3D grid, or per frame along the view.
    #[arg(long, value_enum, default_value_t = HaloMode::Grid)]
    mode: HaloMode,
    /// Camera azimuth in degrees (default: the scene's camera, else 35).
    #[arg(long, allow_negative_numbers = true)]
    azimuth: Option<f64>,
    /// Camera elevation in degrees, -89 to 89 (default: the scene's, else 25).
    #[arg(long, allow_negative_numbers = true)]
    elevation: Option<f64>,
    /// Eye distance in half-diagonals of the scene (default: the scene's, else fitted so
    /// that the surfaces fill the picture).
    #[arg(long)]
    distance: Option<f64>,
    /// Vertical field of view in degrees (default: the scene's, else 38).
    #[arg(long)]
    fov: Option<f64>,
    /// Orthographic instead of perspective.
    #[arg(long)]
    orthographic: bool,
    /// Halos hide nothing.
    #[arg(long)]
    no_halos: bool,
    /// Leave the curves out.
    #[arg(long)]
    no_curves: bool,
    /// Leave the silhouettes out.
    #[arg(long)]
    no_silhouettes: bool,
    /// Half-transparent surfaces.
    #[arg(long)]
    transparent: bool,
    /// One grey instead of colour by w.
    #[arg(long)]
    grey: bool,
    /// The colour scale of w.
    #[arg(long, value_enum, default_value_t = Colormap::Diverging)]
    colormap: Colormap,
    /// Shaded surfaces, or stipples (paper 003) on the first surface the halos leave
    /// visible, with the scene's render.stipple (default: the scene's render.style).
    #[arg(long, value_enum)]
    style: Option<Style>,
    /// Render a fixed orbit (and for a scene a 4D turn) for each mode and slice count (64,
    /// 128, 256, 512) offscreen, then in stipples in --mode at --slices, and print
    /// milliseconds per frame (with --style, that style's rows only).
    #[arg(long)]
    bench: bool,
    /// Frames per orbit for --bench.
    #[arg(long, default_value_t = 36)]
    frames: u32,
    /// Show the slice by the hyperplane of the scene's `slicing` (the one `halo4d slice`
    /// cuts along) at LEVEL, a height along its direction, over the surfaces (a scene only;
    /// in the window, `L` shows it at the middle and `,` `.` move it).
    #[arg(long, value_name = "LEVEL", allow_negative_numbers = true)]
    hyperplane: Option<f64>,
    /// Render with the CPU renderer's exact mode too, and print for each mode and slice
    /// count the share of covered pixels where what is visible differs.
    #[arg(long)]
    compare: bool,
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("`{s}` is not WIDTHxHEIGHT, e.g. 1920x1080"))?;
    let n = |v: &str| {
        v.trim()
            .parse::<u32>()
            .map_err(|_| format!("`{v}` in `{s}` is not a whole number of pixels"))
    };
    Ok((n(w)?, n(h)?))
}

fn parse_rotate(s: &str) -> Result<(String, f64), String> {
    let (plane, degrees) = s
        .split_once('=')
        .ok_or_else(|| format!("`{s}` is not PLANE=DEGREES, e.g. xw=20"))?;
    let plane = plane.trim().to_ascii_lowercase();
    if halo4d::view::Rotation4::default()
        .angle_mut(&plane)
        .is_none()
    {
        return Err(format!(
            "`{plane}` is not a plane of R^4: use xy, xz, xw, yz, yw or zw"
        ));
    }
    let degrees: f64 = degrees
        .trim()
        .parse()
        .map_err(|_| format!("`{degrees}` in `{s}` is not a number of degrees"))?;
    FINITE
        .check("DEGREES", degrees)
        .map_err(|e| format!("`{s}`: {e}"))?;
    Ok((plane, degrees))
}

fn main() -> ExitCode {
    let args = Args::parse();
    match run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(args: &Args) -> Result<(), ViewerError> {
    if args.headless
        && args.screenshot.is_none()
        && args.save_scene.is_none()
        && !args.bench
        && !args.compare
    {
        return Err(ViewerError::Setting(FieldError::new(
            "--headless",
            "needs --screenshot OUT.png (or --save-scene OUT.json, --bench or --compare)",
        )));
    }
    if args.hyperplane.is_some() && (args.bench || args.compare) {
        return Err(ViewerError::Setting(FieldError::new(
            "--hyperplane",
            "is drawn in a screenshot or the window, not in --bench or --compare",
        )));
    }
    let (source, notes) = Source::open(args.file.as_deref())?;
    for note in notes {
        eprintln!("note: {note}");
    }
    let view = match &source {
        Source::Model(model) => {
            let mut view = model.scene.view;
            for (plane, degrees) in &args.rotate {
                *view
                    .rotation
                    .angle_mut(plane)
                    .expect("checked by the parser") += degrees;
            }
            Some(view)
        }
        Source::Asset(asset) => {
            if !args.rotate.is_empty() || args.save_scene.is_some() {
                return Err(ViewerError::Setting(FieldError::new(
                    if args.rotate.is_empty() {
                        "--save-scene"
                    } else {
                        "--rotate"
                    },
                    format!(
                        "{} turns only in 3D (see the note above); open its scene file to turn it in 4D or save a view",
                        asset.1.name
                    ),
                )));
            }
            None
        }
    };
    let recorded = source.camera();
    let render = source.render_settings();
    let settings = ViewSettings {
        // The scene's picture, with the flags over it.
        render: RenderSettings {
            width: args.size.0,
            height: args.size.1,
            slices: args.slices,
            samples: args
                .samples
                .unwrap_or(if args.screenshot.is_some() { 4 } else { 1 }),
            halos: !args.no_halos,
            curves: !args.no_curves,
            silhouettes: !args.no_silhouettes,
            colormap: args.colormap,
            style: args.style.unwrap_or(render.style),
            ..render
        },
        camera: CameraSettings {
            azimuth: args.azimuth.unwrap_or(recorded.azimuth),
            elevation: args.elevation.unwrap_or(recorded.elevation),
            distance: args.distance.or(recorded.distance),
            fov: args.fov.unwrap_or(recorded.fov),
            projection: if args.orthographic {
                CameraProjection::Orthographic
            } else {
                recorded.projection
            },
        },
        mode: args.mode,
        transparent: args.transparent,
        colour_by_w: !args.grey,
    };
    settings.check()?;
    if let (Some(out), Source::Model(model), Some(view)) = (&args.save_scene, &source, &view) {
        let written = viewer::save_scene(&model.scene, view, &settings.camera, out)?;
        println!(
            "{}: scene `{}` in this view; build it with `halo4d build {}`",
            out.display(),
            written.name,
            out.display()
        );
    }
    if args.bench {
        return bench(&source, view.as_ref(), &settings, args.frames, args.style);
    }
    if args.compare {
        return compare(&source, view.as_ref(), &settings);
    }
    if let Some(out) = &args.screenshot {
        let gpu = Gpu::headless()?;
        let frame =
            viewer::screenshot_of(&gpu, &source, view.as_ref(), &settings, args.hyperplane)?;
        halo4d::write_atomic(out, &frame.picture.png()).map_err(|e| ViewerError::Write {
            path: out.display().to_string(),
            message: e.to_string(),
        })?;
        println!(
            "{}: {}x{}, {}, {} {} slices, {:.1} ms{} on {}",
            out.display(),
            settings.render.width,
            settings.render.height,
            match settings.render.style {
                Style::Shaded => "shaded",
                Style::Stipple => "stipples",
            },
            settings.mode.name(),
            settings.render.slices,
            frame.times.frame_ms,
            frame
                .times
                .grid_ms
                .map_or_else(String::new, |g| format!(" + grid {g:.1} ms")),
            gpu.describe()
        );
        return Ok(());
    }
    if args.headless {
        return Ok(());
    }
    println!("{}", viewer::window::HELP);
    viewer::window::run(source, view, settings, args.hyperplane)
}

fn bench(
    source: &Source,
    view: Option<&View>,
    settings: &ViewSettings,
    frames: u32,
    style: Option<Style>,
) -> Result<(), ViewerError> {
    BENCH_FRAMES
        .check("--frames", frames)
        .map_err(ViewerError::Setting)?;
    let gpu = Gpu::headless()?;
    let (triangles, tets) = match source {
        Source::Model(m) => (m.triangle_count(), 6 * m.triangle_count()),
        Source::Asset(a) => (a.1.triangle_count(), a.1.tet_count()),
    };
    println!(
        "{}: {triangles} triangles, {tets} tetrahedra, {}x{}, {frames} frames per motion, on {}",
        source.name(),
        settings.render.width,
        settings.render.height,
        gpu.describe()
    );
    println!(
        "| motion | mode | slices | halo rebuild (ms) | grid build (ms) | ms per frame (mean) | median | frames per second |"
    );
    println!("| --- | --- | --- | --- | --- | --- | --- | --- |");
    let ms = |v: Option<f64>| v.map_or_else(|| "-".into(), |g| format!("{g:.1}"));
    // The stipple rows, where the source has a 4D mesh to fix stipples to; `--style` asks
    // for one style's rows only.
    let clock = std::time::Instant::now();
    let st = settings.render.stipple;
    let made = match style {
        Some(Style::Shaded) => Err(ViewerError::Setting(FieldError::new(
            "--style",
            "shaded rows only",
        ))),
        _ => source.stipples(st.count, st.seed),
    };
    let stipples = match made {
        Ok(set) => {
            eprintln!(
                "stipples: {} ({} per surface, seed {}) made on the CPU in {:.0} ms",
                set.len(),
                st.count,
                st.seed,
                clock.elapsed().as_secs_f64() * 1e3
            );
            Some(set)
        }
        Err(e) => {
            eprintln!("note: no stipple rows: {e}");
            None
        }
    };
    viewer::bench(
        &gpu,
        source,
        view,
        settings,
        if style == Some(Style::Stipple) {
            &[]
        } else {
            &SLICE_COUNTS
        },
        frames,
        stipples.as_ref(),
        &mut |r| {
            println!(
                "| {}{} | {} | {} | {} | {} | {:.2} | {:.2} | {:.1} |",
                r.motion.name(),
                match r.style {
                    Style::Shaded => "",
                    Style::Stipple => ", stipples",
                },
                r.mode.name(),
                r.slices,
                ms(r.turn_ms),
                ms(r.grid_ms),
                r.mean_ms,
                r.median_ms,
                1e3 / r.mean_ms
            );
        },
    )?;
    Ok(())
}

fn compare(
    source: &Source,
    view: Option<&View>,
    settings: &ViewSettings,
) -> Result<(), ViewerError> {
    let gpu = Gpu::headless()?;
    println!(
        "{}: {}x{}, against the CPU renderer's exact mode (one sample per pixel), on {}",
        source.name(),
        settings.render.width,
        settings.render.height,
        gpu.describe()
    );
    println!("| mode | slices | verdict differs | ms (GPU frame) |");
    println!("| --- | --- | --- | --- |");
    let mut row = |r: &viewer::CompareRow| {
        println!(
            "| {} | {} | {:.3}% | {:.1} |",
            r.mode.name(),
            r.slices,
            r.verdict_differs * 100.0,
            r.ms
        );
    };
    match (source, view) {
        (Source::Model(model), Some(view)) => {
            let found =
                viewer::compare_turned(&gpu, model, view, settings, &SLICE_COUNTS, &mut row)?;
            println!(
                "build and exact CPU render of the scene in this view: {:.0} ms; the build shrank rho at {} of {} vertices (the GPU's halos keep it)",
                found.cpu_ms, found.shrunk, found.vertices
            );
        }
        (Source::Asset(a), _) => {
            let (cpu_ms, _) = viewer::compare(&gpu, &a.0, &a.1, settings, &SLICE_COUNTS, &mut row)?;
            println!("exact CPU render: {cpu_ms:.0} ms");
        }
        (Source::Model(_), None) => unreachable!("a model always has a view"),
    }
    Ok(())
}
