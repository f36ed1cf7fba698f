//! `halo4d-view`: the wgpu viewer and 4D explorer of scenes and `.glb` files (see
//! `halo4d::viewer`): its flags (`cli`), and the GPU's measures (`measure`).

mod cli;
mod measure;
#[path = "../halo4d/terminal.rs"]
mod terminal;

use clap::Parser;
use cli::Args;
use halo4d::limits::FieldError;
use halo4d::render::{CameraProjection, CameraSettings, RenderSettings, Style};
use halo4d::viewer::{self, Gpu, Source, ViewSettings, ViewerError};
use std::process::ExitCode;

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
    // The view search of a scene whose view is "auto" shows its bar.
    let terminal = terminal::Terminal::new(false);
    let job = halo4d::progress::Job::new(&terminal, halo4d::progress::Cancel::never());
    let (source, notes) = Source::open(args.file.as_deref(), job)?;
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
        return measure::bench(&source, view.as_ref(), &settings, args.frames, args.style);
    }
    if args.compare {
        return measure::compare(&source, view.as_ref(), &settings);
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
