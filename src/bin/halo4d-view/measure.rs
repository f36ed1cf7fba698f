//! `halo4d-view --bench` and `--compare`: the GPU's frame times, and what it draws against
//! the CPU renderer's exact mode.

use halo4d::limits::{BENCH_FRAMES, FieldError};
use halo4d::render::Style;
use halo4d::view::View;
use halo4d::viewer::{self, Gpu, SLICE_COUNTS, Source, ViewSettings, ViewerError};

pub fn bench(
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

pub fn compare(
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
