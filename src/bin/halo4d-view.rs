//! `halo4d-view`: the wgpu viewer of a scene's `.glb` (see `halo4d::viewer`).

use clap::{Parser, ValueEnum};
use halo4d::limits::FieldError;
use halo4d::viewer::{self, Asset, Gpu, HaloMode, SLICE_COUNTS, ViewSettings, ViewerError};
use halo4d::{CameraProjection, CameraSettings, Colormap};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser, Debug)]
#[command(
    name = "halo4d-view",
    version,
    about = "View a scene's .glb (written by `halo4d build`): surfaces, halos and curves on the GPU",
    after_help = viewer::window::HELP
)]
struct Args {
    /// The scene's .glb, e.g. exports/default/default.glb.
    file: PathBuf,
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
    #[arg(long, value_enum, default_value_t = Mode::Grid)]
    mode: Mode,
    /// Camera azimuth in degrees (default: the scene's camera, else 35).
    #[arg(long, allow_negative_numbers = true)]
    azimuth: Option<f64>,
    /// Camera elevation in degrees, -89 to 89 (default: the scene's, else 25).
    #[arg(long, allow_negative_numbers = true)]
    elevation: Option<f64>,
    /// Eye distance in half-diagonals of the scene (default: the scene's, else 3.2).
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
    #[arg(long, value_enum, default_value_t = Map::Diverging)]
    colormap: Map,
    /// Render a fixed orbit for each mode and slice count (64, 128, 256, 512) offscreen
    /// and print milliseconds per frame.
    #[arg(long)]
    bench: bool,
    /// Frames per orbit for --bench.
    #[arg(long, default_value_t = 36)]
    frames: u32,
    /// Render with the CPU renderer's exact mode too, and print for each mode and slice
    /// count the share of covered pixels where what is visible differs.
    #[arg(long)]
    compare: bool,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum Mode {
    Grid,
    View,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum Map {
    Diverging,
    Viridis,
    Gray,
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
    if args.headless && args.screenshot.is_none() && !args.bench && !args.compare {
        return Err(ViewerError::Setting(FieldError::new(
            "--headless",
            "needs --screenshot OUT.png (or --bench, or --compare)",
        )));
    }
    let (scene, asset) = Asset::read(&args.file)?;
    if !asset.surfaces_without_halo.is_empty() {
        eprintln!(
            "note: no halo for {}: those surfaces are never hidden (build with halo.enabled)",
            asset.surfaces_without_halo.join(", ")
        );
    }
    let recorded = asset.camera.unwrap_or_default();
    let settings = ViewSettings {
        width: args.size.0,
        height: args.size.1,
        camera: CameraSettings {
            azimuth: args.azimuth.unwrap_or(recorded.azimuth),
            elevation: args.elevation.unwrap_or(recorded.elevation),
            distance: args.distance.unwrap_or(recorded.distance),
            fov: args.fov.unwrap_or(recorded.fov),
            projection: if args.orthographic {
                CameraProjection::Orthographic
            } else {
                recorded.projection
            },
        },
        slices: args.slices,
        samples: args
            .samples
            .unwrap_or(if args.screenshot.is_some() { 4 } else { 1 }),
        mode: match args.mode {
            Mode::Grid => HaloMode::Grid,
            Mode::View => HaloMode::View,
        },
        halos: !args.no_halos,
        curves: !args.no_curves,
        silhouettes: !args.no_silhouettes,
        transparent: args.transparent,
        colour_by_w: !args.grey,
        colormap: match args.colormap {
            Map::Diverging => Colormap::Diverging,
            Map::Viridis => Colormap::Viridis,
            Map::Gray => Colormap::Gray,
        },
    };
    settings.check()?;
    if args.bench {
        return bench(&asset, &settings, args.frames);
    }
    if args.compare {
        return compare(&scene, &asset, &settings);
    }
    if let Some(out) = &args.screenshot {
        let gpu = Gpu::headless()?;
        let frame = viewer::screenshot(&gpu, &asset, &settings)?;
        halo4d::internals::write_atomic(out, &frame.picture.png()).map_err(|e| {
            ViewerError::Write {
                path: out.display().to_string(),
                message: e.to_string(),
            }
        })?;
        println!(
            "{}: {}x{}, {} {} slices, {:.1} ms{} on {}",
            out.display(),
            settings.width,
            settings.height,
            settings.mode.name(),
            settings.slices,
            frame.times.frame_ms,
            frame
                .times
                .grid_ms
                .map_or_else(String::new, |g| format!(" + grid {g:.1} ms")),
            gpu.describe()
        );
        return Ok(());
    }
    println!("{}", viewer::window::HELP);
    viewer::window::run(asset, settings)
}

fn bench(asset: &Asset, settings: &ViewSettings, frames: u32) -> Result<(), ViewerError> {
    if frames == 0 {
        return Err(ViewerError::Setting(FieldError::new(
            "--frames",
            "must be at least 1",
        )));
    }
    let gpu = Gpu::headless()?;
    println!(
        "{}: {} triangles, {} tetrahedra, {}x{}, {} frames per orbit, on {}",
        asset.name,
        asset.triangle_count(),
        asset.tet_count(),
        settings.width,
        settings.height,
        frames,
        gpu.describe()
    );
    println!(
        "| mode | slices | grid build (ms) | ms per frame (mean) | median | frames per second |"
    );
    println!("| --- | --- | --- | --- | --- | --- |");
    viewer::bench(&gpu, asset, settings, &SLICE_COUNTS, frames, &mut |r| {
        println!(
            "| {} | {} | {} | {:.2} | {:.2} | {:.1} |",
            r.mode.name(),
            r.slices,
            r.grid_ms.map_or_else(|| "-".into(), |g| format!("{g:.1}")),
            r.mean_ms,
            r.median_ms,
            1e3 / r.mean_ms
        );
    })?;
    Ok(())
}

fn compare(
    scene: &halo4d::ImportedScene,
    asset: &Asset,
    settings: &ViewSettings,
) -> Result<(), ViewerError> {
    let gpu = Gpu::headless()?;
    println!(
        "{}: {}x{}, against the CPU renderer's exact mode (one sample per pixel), on {}",
        asset.name,
        settings.width,
        settings.height,
        gpu.describe()
    );
    println!("| mode | slices | verdict differs | ms (GPU frame) |");
    println!("| --- | --- | --- | --- |");
    let (cpu_ms, _) = viewer::compare(&gpu, scene, asset, settings, &SLICE_COUNTS, &mut |r| {
        println!(
            "| {} | {} | {:.3}% | {:.1} |",
            r.mode.name(),
            r.slices,
            r.verdict_differs * 100.0,
            r.ms
        );
    })?;
    println!("exact CPU render: {cpu_ms:.0} ms");
    Ok(())
}
