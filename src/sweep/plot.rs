//! PNG plots of the sweeps: audited error and curve error against triangles, log-log.

use super::{RESIDUAL_FLOOR, Row};
use crate::render::compare::Comparison;
use crate::render::text::FAMILY;
use plotters::prelude::*;

/// Why a plot could not be made.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// The rows hold nothing that can be drawn on the plot's axes.
    #[error("nothing to plot: {0}")]
    Empty(&'static str),
    /// Drawing or encoding failed (a bug, not bad input).
    #[error("internal error in the plot: {0}")]
    Draw(String),
}

/// Registers the labels' font ([`FAMILY`]).
fn register_font() -> Result<(), PlotError> {
    crate::render::text::register_font().map_err(PlotError::Draw)
}

const COLOURS: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
    RGBColor(140, 86, 75),
    RGBColor(127, 127, 127),
];

/// Encodes an RGB buffer as PNG.
fn encode_png(rgb: &[u8], width: u32, height: u32) -> Result<Vec<u8>, PlotError> {
    use image::ImageEncoder;
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(rgb, width, height, image::ExtendedColorType::Rgb8)
        .map_err(|e| PlotError::Draw(format!("PNG encoding failed: {e}")))?;
    Ok(out)
}

/// Audited max error (relative to the diagonal) against triangles, one line per surface and
/// method: solid with dots for the adaptive sampler, dashed with crosses for uniform grids.
/// Rows that did not meet their tolerance are drawn hollow.
pub(super) fn speed_vs_error_png(rows: &[Row], title: &str) -> Result<Vec<u8>, PlotError> {
    register_font()?;
    let (w, h) = (1200u32, 800u32);
    let mut rgb = vec![255u8; (w * h * 3) as usize];
    let finite: Vec<&Row> = rows
        .iter()
        .filter(|r| r.triangles > 0 && r.max_error.is_finite() && r.max_error > 0.0)
        .collect();
    if finite.is_empty() {
        return Err(PlotError::Empty(
            "no row has a finite, positive error and at least one triangle",
        ));
    }
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, 0.0f64, f64::MAX, 0.0f64);
    for r in &finite {
        x0 = x0.min(r.triangles as f64);
        x1 = x1.max(r.triangles as f64);
        y0 = y0.min(r.max_error.min(r.tolerance));
        y1 = y1.max(r.max_error.max(r.tolerance));
    }
    let draw = |rgb: &mut [u8]| -> Result<(), Box<dyn std::error::Error>> {
        let root = BitMapBackend::with_buffer(rgb, (w, h)).into_drawing_area();
        root.fill(&WHITE)?;
        let mut chart = log_log_chart(
            &root,
            title,
            x0 / 1.5..x1 * 1.5,
            y0 / 2.0..y1 * 2.0,
            "audited max error / 4D bounding diagonal",
        )?;
        let mut surfaces: Vec<&str> = Vec::new();
        for r in &finite {
            if !surfaces.contains(&r.surface.as_str()) {
                surfaces.push(&r.surface);
            }
        }
        for (i, surface) in surfaces.iter().enumerate() {
            let colour = COLOURS[i % COLOURS.len()];
            for method in ["adaptive", "uniform"] {
                let mut pts: Vec<(f64, f64, bool)> = finite
                    .iter()
                    .filter(|r| r.surface == *surface && r.method == method)
                    .map(|r| (r.triangles as f64, r.max_error, r.met))
                    .collect();
                pts.sort_by(|a, b| a.0.total_cmp(&b.0));
                if pts.is_empty() {
                    continue;
                }
                let line = pts.iter().map(|p| (p.0, p.1));
                let label = format!("{surface} ({method})");
                if method == "adaptive" {
                    chart
                        .draw_series(LineSeries::new(line, colour.stroke_width(2)))?
                        .label(label)
                        .legend(move |(x, y)| {
                            PathElement::new(vec![(x, y), (x + 24, y)], colour.stroke_width(2))
                        });
                    chart.draw_series(pts.iter().map(|p| {
                        Circle::new((p.0, p.1), 4, colour.stroke_width(2).filled_if(p.2))
                    }))?;
                } else {
                    chart
                        .draw_series(DashedLineSeries::new(line, 8, 5, colour.stroke_width(1)))?
                        .label(label)
                        .legend(move |(x, y)| {
                            PathElement::new(vec![(x, y), (x + 8, y)], colour.stroke_width(1))
                        });
                    chart.draw_series(
                        pts.iter()
                            .map(|p| Cross::new((p.0, p.1), 5, colour.stroke_width(2))),
                    )?;
                }
            }
        }
        chart
            .configure_series_labels()
            .label_font((FAMILY, 15))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::LowerLeft)
            .draw()?;
        root.present()?;
        Ok(())
    };
    draw(&mut rgb).map_err(|e| PlotError::Draw(e.to_string()))?;
    encode_png(&rgb, w, h)
}

/// The intersection curves' errors against triangles, log-log, relative to each mesh's
/// projected diagonal: one colour per surface; the mesh curve's error as in
/// [`speed_vs_error_png`] (solid with dots for the adaptive sampler, hollow where the mesh
/// missed its tolerance; dashed with crosses for uniform grids), the refined curve's
/// residual with triangles (filled for adaptive, hollow for uniform). Residuals
/// below [`RESIDUAL_FLOOR`] are drawn on it (a grey dashed line); rows without a curve are
/// left out, and when no row has one the axes say so.
pub(super) fn curves_vs_error_png(rows: &[Row], title: &str) -> Result<Vec<u8>, PlotError> {
    register_font()?;
    let (w, h) = (1200u32, 800u32);
    let mut rgb = vec![255u8; (w * h * 3) as usize];
    let meshes: Vec<&Row> = rows.iter().filter(|r| r.triangles > 0).collect();
    if meshes.is_empty() {
        return Err(PlotError::Empty("no row has at least one triangle"));
    }
    let curved: Vec<&Row> = meshes
        .iter()
        .copied()
        .filter(|r| r.curve_points > 0 && r.curve_error.is_finite())
        .collect();
    let (mut x0, mut x1) = (f64::MAX, 0.0f64);
    for r in &meshes {
        x0 = x0.min(r.triangles as f64);
        x1 = x1.max(r.triangles as f64);
    }
    // Down to the floor, up to the largest error (the axes' decades when there is none).
    let y1 = if curved.is_empty() {
        1.0
    } else {
        curved
            .iter()
            .map(|r| shown_curve_error(r).max(shown_residual(r)))
            .fold(RESIDUAL_FLOOR * 10.0, f64::max)
    };
    let draw = |rgb: &mut [u8]| -> Result<(), Box<dyn std::error::Error>> {
        let root = BitMapBackend::with_buffer(rgb, (w, h)).into_drawing_area();
        root.fill(&WHITE)?;
        let mut chart = log_log_chart(
            &root,
            title,
            x0 / 1.5..x1 * 1.5,
            RESIDUAL_FLOOR / 10.0..y1 * 10.0,
            "curve error / projected 3D bounding diagonal",
        )?;
        if curved.is_empty() {
            chart.draw_series(std::iter::once(Text::new(
                "no curve: no surface's projection crosses itself in this view",
                (x0, 1e-3),
                (FAMILY, 20),
            )))?;
        }
        let grey = RGBColor(127, 127, 127);
        chart
            .draw_series(DashedLineSeries::new(
                [(x0 / 1.5, RESIDUAL_FLOOR), (x1 * 1.5, RESIDUAL_FLOOR)],
                6,
                6,
                grey.stroke_width(1),
            ))?
            .label(format!(
                "floor {RESIDUAL_FLOOR:.0e}: smaller residuals drawn on it"
            ))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 8, y)], grey.stroke_width(1)));
        let mut surfaces: Vec<&str> = Vec::new();
        for r in &meshes {
            if !surfaces.contains(&r.surface.as_str()) {
                surfaces.push(&r.surface);
            }
        }
        for (i, surface) in surfaces.iter().enumerate() {
            let colour = COLOURS[i % COLOURS.len()];
            for method in ["adaptive", "uniform"] {
                let mut mine: Vec<&Row> = curved
                    .iter()
                    .copied()
                    .filter(|r| r.surface == *surface && r.method == method)
                    .collect();
                if mine.is_empty() {
                    continue;
                }
                mine.sort_by_key(|r| r.triangles);
                draw_curve_rows(&mut chart, &mine, surface, method, colour)?;
            }
        }
        chart
            .configure_series_labels()
            .label_font((FAMILY, 15))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::MiddleRight)
            .draw()?;
        root.present()?;
        Ok(())
    };
    draw(&mut rgb).map_err(|e| PlotError::Draw(e.to_string()))?;
    encode_png(&rgb, w, h)
}

/// A row's refined residual as plotted: on [`RESIDUAL_FLOOR`] when below it or not finite.
fn shown_residual(r: &Row) -> f64 {
    if r.refined_residual.is_finite() {
        r.refined_residual.max(RESIDUAL_FLOOR)
    } else {
        RESIDUAL_FLOOR
    }
}

/// A row's mesh curve error as plotted: on [`RESIDUAL_FLOOR`] when below it.
fn shown_curve_error(r: &Row) -> f64 {
    r.curve_error.max(RESIDUAL_FLOOR)
}

/// Draws the rows of one surface and one method (`mine`, by triangles) on the curves plot:
/// the mesh curve's error and the refined residual, each a line with its markers and its
/// legend entry, in the surface's `colour`.
fn draw_curve_rows<'a, 'b: 'a>(
    chart: &mut LogLogChart<'a, 'b>,
    mine: &[&Row],
    surface: &str,
    method: &str,
    colour: RGBColor,
) -> Result<(), Box<dyn std::error::Error>> {
    let adaptive = method == "adaptive";
    for (quantity, value) in [
        ("curve error", shown_curve_error as fn(&Row) -> f64),
        ("refined residual", shown_residual),
    ] {
        let pts: Vec<(f64, f64, bool)> = mine
            .iter()
            .map(|r| (r.triangles as f64, value(r), r.met))
            .collect();
        let line = pts.iter().map(|p| (p.0, p.1));
        let label = format!("{surface} {quantity} ({method})");
        let series = if adaptive {
            chart.draw_series(LineSeries::new(line, colour.stroke_width(2)))?
        } else {
            chart.draw_series(DashedLineSeries::new(line, 8, 5, colour.stroke_width(1)))?
        };
        // The legend's line as in `speed_vs_error_png`, with the marker on it.
        let (length, width) = if adaptive { (24, 2) } else { (8, 1) };
        let style = colour.stroke_width(2);
        let entry = move |(x, y): (i32, i32)| {
            EmptyElement::at((x, y))
                + PathElement::new(vec![(0, 0), (length, 0)], colour.stroke_width(width))
        };
        let mid = (length / 2, 0);
        let series = series.label(label);
        match (quantity, adaptive) {
            ("curve error", true) => {
                series.legend(move |at| entry(at) + Circle::new(mid, 4, style.filled()));
                chart.draw_series(
                    pts.iter()
                        .map(|p| Circle::new((p.0, p.1), 4, style.filled_if(p.2))),
                )?;
            }
            ("curve error", false) => {
                series.legend(move |at| entry(at) + Cross::new(mid, 5, style));
                chart.draw_series(pts.iter().map(|p| Cross::new((p.0, p.1), 5, style)))?;
            }
            (_, filled) => {
                series.legend(move |at| {
                    entry(at) + TriangleMarker::new(mid, 5, style.filled_if(filled))
                });
                chart.draw_series(
                    pts.iter()
                        .map(|p| TriangleMarker::new((p.0, p.1), 5, style.filled_if(filled))),
                )?;
            }
        }
    }
    Ok(())
}

/// The multi-slice mode against the exact one: render time (left) and the share of covered
/// pixels whose hidden/visible verdict differs with the 99th-percentile pixel difference
/// (right), against slices on a log scale; the exact mode's time as a dashed line.
pub(super) fn render_speed_vs_error_png(
    rows: &[Comparison],
    title: &str,
) -> Result<Vec<u8>, PlotError> {
    register_font()?;
    let (w, h) = (1400u32, 650u32);
    let mut rgb = vec![255u8; (w * h * 3) as usize];
    let exact_ms = rows.iter().find(|r| r.slices == 0).map(|r| r.ms);
    let sliced: Vec<_> = rows.iter().filter(|r| r.slices > 0).collect();
    if sliced.is_empty() {
        return Err(PlotError::Empty(
            "no slice count to compare with the exact mode",
        ));
    }
    let x0 = sliced
        .iter()
        .map(|r| f64::from(r.slices))
        .fold(f64::MAX, f64::min);
    let x1 = sliced
        .iter()
        .map(|r| f64::from(r.slices))
        .fold(0.0, f64::max);
    let draw = |rgb: &mut [u8]| -> Result<(), Box<dyn std::error::Error>> {
        let root = BitMapBackend::with_buffer(rgb, (w, h)).into_drawing_area();
        root.fill(&WHITE)?;
        let root = root.titled(title, (FAMILY, 24))?;
        let (left, right) = root.split_horizontally(w / 2);
        draw_render_time(&left, &sliced, exact_ms, (x0, x1))?;
        draw_render_difference(&right, &sliced, (x0, x1))?;
        root.present()?;
        Ok(())
    };
    draw(&mut rgb).map_err(|e| PlotError::Draw(e.to_string()))?;
    encode_png(&rgb, w, h)
}

/// The left panel of [`render_speed_vs_error_png`]: render time against slices (`x`, the
/// smallest and largest count), the exact mode's time as a dashed line.
fn draw_render_time(
    area: &DrawingArea<BitMapBackend, plotters::coord::Shift>,
    sliced: &[&Comparison],
    exact_ms: Option<f64>,
    (x0, x1): (f64, f64),
) -> Result<(), Box<dyn std::error::Error>> {
    let t1 = sliced
        .iter()
        .map(|r| r.ms)
        .chain(exact_ms)
        .fold(0.0, f64::max);
    let mut time = ChartBuilder::on(area)
        .margin(20)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d((x0 / 1.3..x1 * 1.3).log_scale(), 0.0..t1 * 1.15)?;
    time.configure_mesh()
        .x_desc("slices")
        .y_desc("render time (ms)")
        .label_style((FAMILY, 15))
        .axis_desc_style((FAMILY, 17))
        .x_label_formatter(&|x| format!("{x:.0}"))
        .draw()?;
    let pts: Vec<(f64, f64)> = sliced.iter().map(|r| (f64::from(r.slices), r.ms)).collect();
    time.draw_series(LineSeries::new(pts.clone(), COLOURS[0].stroke_width(2)))?
        .label("slices")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], COLOURS[0].stroke_width(2)));
    time.draw_series(pts.iter().map(|&p| Circle::new(p, 4, COLOURS[0].filled())))?;
    if let Some(e) = exact_ms {
        time.draw_series(DashedLineSeries::new(
            vec![(x0 / 1.3, e), (x1 * 1.3, e)],
            8,
            5,
            COLOURS[1].stroke_width(2),
        ))?
        .label("exact")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 8, y)], COLOURS[1].stroke_width(2)));
    }
    time.configure_series_labels()
        .label_font((FAMILY, 15))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperLeft)
        .draw()?;
    Ok(())
}

/// The right panel of [`render_speed_vs_error_png`]: against slices (`x`, the smallest and
/// largest count), the share of pixels whose verdict differs from the exact mode's and the
/// 99th-percentile pixel difference, in percent.
fn draw_render_difference(
    area: &DrawingArea<BitMapBackend, plotters::coord::Shift>,
    sliced: &[&Comparison],
    (x0, x1): (f64, f64),
) -> Result<(), Box<dyn std::error::Error>> {
    let e1 = sliced
        .iter()
        .map(|r| (100.0 * r.verdict_differs).max(100.0 * r.p99_diff))
        .fold(0.0, f64::max)
        .max(1.0);
    let mut error = ChartBuilder::on(area)
        .margin(20)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d((x0 / 1.3..x1 * 1.3).log_scale(), 0.0..e1 * 1.15)?;
    error
        .configure_mesh()
        .x_desc("slices")
        .y_desc("difference to the exact mode (%)")
        .label_style((FAMILY, 15))
        .axis_desc_style((FAMILY, 17))
        .x_label_formatter(&|x| format!("{x:.0}"))
        .draw()?;
    for (k, (label, f)) in [
        (
            "pixels whose verdict differs",
            (|r: &Comparison| r.verdict_differs) as fn(&Comparison) -> f64,
        ),
        ("99th percentile pixel difference", |r| r.p99_diff),
    ]
    .into_iter()
    .enumerate()
    {
        let colour = COLOURS[(k + 2) % COLOURS.len()];
        let pts: Vec<(f64, f64)> = sliced
            .iter()
            .map(|r| (f64::from(r.slices), 100.0 * f(r)))
            .collect();
        error
            .draw_series(LineSeries::new(pts.clone(), colour.stroke_width(2)))?
            .label(label)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 24, y)], colour.stroke_width(2))
            });
        error.draw_series(pts.iter().map(|&p| Circle::new(p, 4, colour.filled())))?;
    }
    error
        .configure_series_labels()
        .label_font((FAMILY, 15))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperRight)
        .draw()?;
    Ok(())
}

/// A style filled or not.
trait FilledIf {
    fn filled_if(self, filled: bool) -> ShapeStyle;
}

impl FilledIf for ShapeStyle {
    fn filled_if(self, filled: bool) -> ShapeStyle {
        if filled { self.filled() } else { self }
    }
}

/// A chart with log axes both ways.
type LogLogChart<'a, 'b> =
    ChartContext<'a, BitMapBackend<'b>, Cartesian2d<LogCoord<f64>, LogCoord<f64>>>;

/// A titled chart with triangles along a log x axis and an error (`y_desc`) along a log y
/// axis, its mesh drawn: the frame the sweep's two error plots share.
fn log_log_chart<'a, 'b>(
    root: &'a DrawingArea<BitMapBackend<'b>, plotters::coord::Shift>,
    title: &str,
    x: std::ops::Range<f64>,
    y: std::ops::Range<f64>,
    y_desc: &str,
) -> Result<LogLogChart<'a, 'b>, Box<dyn std::error::Error>> {
    let mut chart = ChartBuilder::on(root)
        .caption(title, (FAMILY, 26))
        .margin(20)
        .x_label_area_size(60)
        .y_label_area_size(90)
        .build_cartesian_2d(x.log_scale(), y.log_scale())?;
    chart
        .configure_mesh()
        .x_desc("triangles")
        .y_desc(y_desc)
        .label_style((FAMILY, 16))
        .axis_desc_style((FAMILY, 18))
        .x_label_formatter(&|x| format!("{x:.0e}"))
        .y_label_formatter(&|y| format!("{y:.0e}"))
        .draw()?;
    Ok(chart)
}
