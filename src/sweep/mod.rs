//! Speed against error: what each tolerance costs with the adaptive sampler and with the
//! best uniform grid, audited the same way.
//!
//! For every surface and relative tolerance (share of the 4D bounding diagonal): the
//! adaptive sampler at that tolerance, and the coarsest uniform grid whose audited maximum
//! error meets it. The grid is found by a search over its size (multiplicative steps
//! extrapolated from the error's order, then bisection to 3%), for three shapes: the
//! patch's metric aspect ratio, and that ratio halved and doubled; the shape that needs the
//! fewest triangles wins. Rows give triangles, sampling milliseconds (the final mesh only,
//! not the search) and the audited errors relative to the diagonal.
//!
//! Every row's mesh (adaptive and uniform alike) also gets its intersection curves in the
//! scene's view ([`Settings::view`]): the surface alone, as a one-sheet scene, projected,
//! its self-intersections found by the exact curve stage ([`crate::intersect::curves`]) and moved onto
//! the analytic surface by Newton's method, as a build refines them. The refinement's
//! largest shift is the mesh curve's error, measured for free; its largest residual is the
//! refined curve's. Both are relative to the projected mesh's 3D bounding diagonal. A
//! surface whose projection does not cross itself has no curve: zero points, errors 0.

mod picture;
mod plot;

pub use picture::picture_sweep;
pub use plot::PlotError;

use crate::error::Error;
use crate::intersect::{self, Analytic, Sheet};
use crate::limits::{self, Bound, FieldError, GRID_CELLS, RELATIVE_TOLERANCE};
use crate::render::RenderError;
use crate::sample::{self, Mesh4, audit, bounding_diagonal, sample_adaptive, sample_uniform};
use crate::scene::Scene;
use crate::surfaces::Surface;
use crate::view::{BehindEye, View};
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Relative tolerances of the default sweep, 1e-2 down to 1e-5.
pub const TOLERANCES: [f64; 7] = [1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5, 1e-5];

/// The floor of the log axis of `curves_vs_error.png`: a refined residual below it (about
/// 1e-16 to 1e-13 where Newton reached rounding, exactly 0 at times) is drawn at it.
pub const RESIDUAL_FLOOR: f64 = 1e-17;

/// One line of the sweep.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Row {
    /// Surface name.
    pub surface: String,
    /// `adaptive` or `uniform`.
    pub method: &'static str,
    /// Relative tolerance asked for.
    pub tolerance: f64,
    /// Triangles of the mesh.
    pub triangles: usize,
    /// Milliseconds to sample it (wall, release build).
    pub ms: f64,
    /// Audited max error, relative to the diagonal.
    pub max_error: f64,
    /// Audited RMS error, relative to the diagonal.
    pub rms_error: f64,
    /// Whether the mesh meets the tolerance (false: the triangle budget ran out first).
    pub met: bool,
    /// The grid, for uniform rows (cells along u and v per patch).
    pub grid: Option<[usize; 2]>,
    /// Milliseconds of the exact curve stage on this mesh (its self-intersections, the
    /// surface alone as a one-sheet scene, in [`Settings::view`]).
    pub curve_ms: f64,
    /// Milliseconds refining those curves onto the analytic surface.
    pub refine_ms: f64,
    /// The mesh curve's error: the largest distance from a mesh curve point to its refined
    /// point (the refinement's `max_shift`; curve ends moved onto a cross-cap not
    /// included), relative to the projected mesh's 3D bounding diagonal; 0 with no curve.
    pub curve_error: f64,
    /// The refined curve's largest |P1 - P2| (the refinement's `max_residual`), relative to
    /// the same diagonal; 0 with no curve.
    pub refined_residual: f64,
    /// Points of the mesh's curves; 0: no curve (the projection does not cross itself).
    pub curve_points: usize,
    /// Curve points the refinement kept where the mesh put them (Newton did not converge
    /// there: the refinement's `not_converged`); they count in neither error.
    pub not_converged: usize,
    /// The mesh's curves: closed, open.
    pub curves: [usize; 2],
    /// The true surface's double curves in the same view, certified
    /// ([`crate::intersect::certified`]): closed, open; `None` where the certificate is not
    /// complete. The same on every row of a surface: it does not depend on the mesh.
    pub certified: Option<[usize; 2]>,
    /// Milliseconds the certificate took (once per surface, the same on its rows).
    pub certify_ms: f64,
}

/// Settings of a sweep.
#[derive(Clone, Debug)]
pub struct Settings {
    /// Relative tolerances.
    pub tolerances: Vec<f64>,
    /// The most triangles any one mesh may have.
    pub max_triangles: usize,
    /// The view in which each mesh's curves are found: the scene's.
    pub view: View,
}

impl Default for Settings {
    /// [`TOLERANCES`], [`limits::SWEEP_TRIANGLES`] and the default scene's view.
    fn default() -> Self {
        Settings {
            tolerances: TOLERANCES.to_vec(),
            max_triangles: limits::SWEEP_TRIANGLES,
            view: Scene::default_scene().view,
        }
    }
}

impl Settings {
    /// Checks the settings for sweeping `surfaces` (name, surface), naming the first bad
    /// field (`tolerances`, `max_triangles`): every tolerance within
    /// [`limits::RELATIVE_TOLERANCE`], the budget within [`limits::TRIANGLES`] and at least
    /// the coarsest grid of every surface ([`coarsest_grid_triangles`]).
    pub fn check(&self, surfaces: &[(String, Surface)]) -> Result<(), FieldError> {
        for (i, &t) in self.tolerances.iter().enumerate() {
            RELATIVE_TOLERANCE.check(&format!("tolerances[{i}]"), t)?;
        }
        let max = self.max_triangles;
        limits::TRIANGLES.check("max_triangles", max)?;
        for (name, surface) in surfaces {
            let least = Bound {
                lo: coarsest_grid_triangles(surface),
                ..limits::TRIANGLES
            };
            least.check_with(
                "max_triangles",
                max,
                &format!(
                    "the coarsest grid of `{name}` ({} patches) has {} triangles",
                    surface.patch_count(),
                    least.lo
                ),
            )?;
        }
        Ok(())
    }
}

/// Why a sweep stopped.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    /// A setting is out of range.
    #[error(transparent)]
    Setting(#[from] FieldError),
    /// A mesh reaches the 4D eye of the view its curves are found in.
    #[error("surface `{surface}`: {source}")]
    View {
        /// The surface.
        surface: String,
        /// The offending vertex.
        source: BehindEye,
    },
    /// The build the picture sweep draws failed.
    #[error(transparent)]
    Build(#[from] Error),
    /// A picture could not be made.
    #[error(transparent)]
    Render(#[from] RenderError),
    /// The plot could not be made.
    #[error(transparent)]
    Plot(#[from] PlotError),
    /// A file could not be written.
    #[error("cannot write {}: {source}; check that the output folder is writable (choose another with --out)", path.display())]
    Write {
        /// The file or folder.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
}

fn ms(since: Instant) -> f64 {
    since.elapsed().as_secs_f64() * 1e3
}

/// Sweeps one surface: an adaptive and a uniform row per tolerance, each with its mesh's
/// curves. `progress` is told what is being done.
pub fn sweep_surface(
    name: &str,
    surface: &Surface,
    settings: &Settings,
    progress: &mut dyn FnMut(&str),
) -> Result<Vec<Row>, SweepError> {
    let diagonal = bounding_diagonal(surface);
    progress(&format!("{name}: certifying its double curves"));
    let certificate = intersect::certified::certify(&[Some(surface)], &settings.view);
    let truth = Truth {
        certified: certificate
            .complete
            .then_some([certificate.closed, certificate.open]),
        certify_ms: certificate.ms,
    };
    let mut rows = Vec::new();
    let mut grids = GridSearch::new(surface, diagonal, settings.max_triangles);
    let curves = |mesh: &Mesh4| {
        mesh_curves(surface, mesh, &settings.view).map_err(|source| SweepError::View {
            surface: name.to_string(),
            source,
        })
    };
    for &tolerance in &settings.tolerances {
        progress(&format!("{name}: adaptive at {tolerance:.0e}"));
        let start = Instant::now();
        let out = sample_adaptive(surface, tolerance * diagonal, settings.max_triangles);
        let took = ms(start);
        let a = audit(surface, &out.mesh);
        let (max, rms) = a.relative(diagonal);
        progress(&format!(
            "{name}: curves of the adaptive mesh at {tolerance:.0e}"
        ));
        let c = curves(&out.mesh)?;
        rows.push(Row {
            surface: name.to_string(),
            method: "adaptive",
            tolerance,
            triangles: out.mesh.triangles.len(),
            ms: took,
            max_error: max,
            rms_error: rms,
            met: out.complete && max <= tolerance,
            grid: None,
            curve_ms: c.curve_ms,
            refine_ms: c.refine_ms,
            curve_error: c.curve_error,
            refined_residual: c.refined_residual,
            curve_points: c.curve_points,
            not_converged: c.not_converged,
            curves: c.curves,
            certified: truth.certified,
            certify_ms: truth.certify_ms,
        });
        drop(out);
        progress(&format!("{name}: uniform grids at {tolerance:.0e}"));
        let (m, met) = grids.coarsest(tolerance);
        let start = Instant::now();
        let mesh = sample_uniform(surface, m.cells[0], m.cells[1]);
        let took = ms(start);
        progress(&format!(
            "{name}: curves of the uniform grid at {tolerance:.0e}"
        ));
        let c = curves(&mesh)?;
        rows.push(Row {
            surface: name.to_string(),
            method: "uniform",
            tolerance,
            triangles: m.triangles,
            ms: took,
            max_error: m.max,
            rms_error: m.rms,
            met,
            grid: Some(m.cells),
            curve_ms: c.curve_ms,
            refine_ms: c.refine_ms,
            curve_error: c.curve_error,
            refined_residual: c.refined_residual,
            curve_points: c.curve_points,
            not_converged: c.not_converged,
            curves: c.curves,
            certified: truth.certified,
            certify_ms: truth.certify_ms,
        });
    }
    Ok(rows)
}

/// A surface's certified curves, for its rows ([`Row::certified`], [`Row::certify_ms`]).
struct Truth {
    certified: Option<[usize; 2]>,
    certify_ms: f64,
}

/// What a mesh's curves cost and how far they are from the surface's: [`Row`]'s curve
/// columns.
struct MeshCurves {
    curves: [usize; 2],
    curve_ms: f64,
    refine_ms: f64,
    curve_error: f64,
    refined_residual: f64,
    curve_points: usize,
    not_converged: usize,
}

/// The self-intersection curves of `mesh` (of `surface`) projected by `view`, as a
/// one-sheet scene, and their refinement onto the surface; errors relative to the
/// projected mesh's 3D bounding diagonal, as the build's refinement measures them.
fn mesh_curves(surface: &Surface, mesh: &Mesh4, view: &View) -> Result<MeshCurves, BehindEye> {
    let projected = view.project(mesh)?;
    let diagonal = projected
        .bounds()
        .map_or(0.0, |(lo, hi)| (hi - lo).length());
    let sheets = [Sheet {
        positions: &projected.positions,
        w: &projected.w,
        triangles: &mesh.triangles,
    }];
    let curves = intersect::curves(&sheets);
    let refined = intersect::refine(
        &curves,
        &sheets,
        &[Analytic {
            surface: Some(surface),
            mesh,
        }],
        view,
        diagonal,
    );
    let r = refined.report.refinement.unwrap_or_default();
    let relative = |x: f64| if diagonal > 0.0 { x / diagonal } else { 0.0 };
    Ok(MeshCurves {
        curves: [curves.report.closed, curves.report.open],
        curve_ms: curves.report.ms,
        refine_ms: r.refine_ms,
        curve_error: relative(r.max_shift),
        refined_residual: relative(r.max_residual),
        curve_points: curves.report.points,
        not_converged: r.not_converged,
    })
}

/// The triangles of the coarsest uniform grid the sweep tries on `surface` (the fewest
/// cells along u and v that it allows, on every patch): a budget below it leaves no grid.
pub fn coarsest_grid_triangles(surface: &Surface) -> usize {
    let [u, v] = coarsest_cells(surface);
    2 * u * v * surface.patch_count()
}

/// The fewest cells along u and v of any grid the sweep tries on `surface`.
fn coarsest_cells(surface: &Surface) -> [usize; 2] {
    surface.min_cells().map(|n| (n + n % 2).max(2))
}

/// A uniform grid and its audited relative errors.
#[derive(Clone, Copy)]
struct Measured {
    cells: [usize; 2],
    triangles: usize,
    max: f64,
    rms: f64,
}

/// Finds the coarsest uniform grids that meet tolerances, remembering every grid audited.
struct GridSearch<'a> {
    surface: &'a Surface,
    diagonal: f64,
    max_triangles: usize,
    aspect: f64,
    seen: Vec<Measured>,
    /// Per shape (aspect factor bits): the finest grid within the budget, when it missed a
    /// tolerance; tighter tolerances cannot do better.
    exhausted: Vec<(u64, Measured)>,
}

impl<'a> GridSearch<'a> {
    fn new(surface: &'a Surface, diagonal: f64, max_triangles: usize) -> Self {
        GridSearch {
            surface,
            diagonal,
            max_triangles,
            aspect: sample::metric_aspect(surface),
            seen: Vec::new(),
            exhausted: Vec::new(),
        }
    }

    /// The grid of size `k` (about k^2 cells per patch) and shape `aspect`.
    fn cells(&self, k: f64, aspect: f64) -> [usize; 2] {
        let [min_u, min_v] = self.surface.min_cells();
        let even = |x: f64, min: usize| {
            let n = (x.round().clamp(GRID_CELLS.lo as f64, GRID_CELLS.hi as f64) as usize).max(min);
            (n + n % 2).min(GRID_CELLS.hi)
        };
        [
            even(k * aspect.sqrt(), min_u),
            even(k / aspect.sqrt(), min_v),
        ]
    }

    fn triangles(&self, cells: [usize; 2]) -> usize {
        2 * cells[0] * cells[1] * self.surface.patch_count()
    }

    fn measure(&mut self, cells: [usize; 2]) -> Measured {
        if let Some(m) = self.seen.iter().find(|m| m.cells == cells) {
            return *m;
        }
        let mesh = sample_uniform(self.surface, cells[0], cells[1]);
        let (max, rms) = audit(self.surface, &mesh).relative(self.diagonal);
        let m = Measured {
            cells,
            triangles: mesh.triangles.len(),
            max,
            rms,
        };
        self.seen.push(m);
        m
    }

    /// The coarsest grid of one shape that meets `tolerance`, or the finest allowed.
    fn search(&mut self, tolerance: f64, aspect: f64) -> (Measured, bool) {
        if let Some((_, m)) = self.exhausted.iter().find(|e| e.0 == aspect.to_bits()) {
            return (*m, false);
        }
        let mut fail: Option<(f64, Measured)> = None;
        let mut pass: Option<(f64, Measured)> = None;
        let mut k = 8.0;
        for _ in 0..24 {
            let cells = self.cells(k, aspect);
            if self.triangles(cells) > self.max_triangles || cells.contains(&GRID_CELLS.hi) {
                // Beyond the budget: step back towards the last failing size, or down
                // towards the coarsest grid while nothing was measured, or stop.
                match (fail, pass) {
                    (Some((kf, _)), _) if k / kf > 1.03 => {
                        k = (k * kf).sqrt();
                        continue;
                    }
                    (None, None) if k > 2.0 => {
                        k = (k / 2.0).max(2.0);
                        continue;
                    }
                    _ => break,
                }
            }
            let m = self.measure(cells);
            if m.max <= tolerance {
                pass = Some((k, m));
            } else {
                fail = Some((k, m));
            }
            k = match (fail, pass) {
                (Some((kf, _)), Some((kp, _))) => {
                    if kp / kf < 1.03 {
                        break;
                    }
                    (kf * kp).sqrt()
                }
                // Errors fall like k^-2 where the surface is smooth; overshoot a little.
                (Some((kf, mf)), None) => kf * ((mf.max / tolerance).sqrt() * 1.1).clamp(1.2, 8.0),
                (None, Some((kp, mp))) => kp / ((tolerance / mp.max).sqrt() * 1.1).clamp(1.2, 8.0),
                (None, None) => unreachable!("a size was measured"),
            };
        }
        match (pass, fail) {
            (Some((_, m)), _) => (m, true),
            (None, Some((_, m))) => {
                self.exhausted.push((aspect.to_bits(), m));
                (m, false)
            }
            // Nothing measured within the budget: the coarsest grid, which the budget holds
            // (`coarsest_grid_triangles`); it may still meet the tolerance.
            (None, None) => {
                let m = self.measure(coarsest_cells(self.surface));
                (m, m.max <= tolerance)
            }
        }
    }

    /// The coarsest grid (over three shapes) that meets `tolerance`, and whether it does
    /// (else the finest within the budget).
    fn coarsest(&mut self, tolerance: f64) -> (Measured, bool) {
        let mut best: Option<(Measured, bool)> = None;
        for f in [1.0, 0.5, 2.0] {
            let found = self.search(tolerance, self.aspect * f);
            best = Some(match best {
                None => found,
                Some(b) => match (b.1, found.1) {
                    (true, true) if found.0.triangles < b.0.triangles => found,
                    (false, true) => found,
                    (false, false) if found.0.max < b.0.max => found,
                    _ => b,
                },
            });
        }
        best.expect("three shapes were searched")
    }
}

/// The columns of [`to_csv`], in order.
pub const CSV_HEADER: &str = "surface,method,tolerance,triangles,ms,max_error,rms_error,met,grid,\
curve_ms,refine_ms,curve_error,refined_residual,curve_points,not_converged,closed,open,\
certified_closed,certified_open,certify_ms";

/// The rows as CSV, the columns of [`CSV_HEADER`]: a [`Row`]'s fields in order, `grid` as
/// `UxV` (empty for adaptive rows), `curves` as `closed,open` and `certified` as
/// `certified_closed,certified_open` (empty where the certificate is not complete).
pub fn to_csv(rows: &[Row]) -> String {
    let mut out = format!("{CSV_HEADER}\n");
    for r in rows {
        let grid = r.grid.map_or(String::new(), |[u, v]| format!("{u}x{v}"));
        let certified = r
            .certified
            .map_or(",".to_string(), |[c, o]| format!("{c},{o}"));
        out.push_str(&format!(
            "{},{},{:e},{},{:.3},{:.6e},{:.6e},{},{},{:.3},{:.3},{:.6e},{:.6e},{},{},{},{},{},{:.3}\n",
            r.surface,
            r.method,
            r.tolerance,
            r.triangles,
            r.ms,
            r.max_error,
            r.rms_error,
            r.met,
            grid,
            r.curve_ms,
            r.refine_ms,
            r.curve_error,
            r.refined_residual,
            r.curve_points,
            r.not_converged,
            r.curves[0],
            r.curves[1],
            certified,
            r.certify_ms
        ));
    }
    out
}

/// Uniform triangles over adaptive triangles at one tolerance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Ratio {
    /// Both met the tolerance.
    Exact(f64),
    /// Only the adaptive sampler met it: the best uniform grid within the budget did not,
    /// so the ratio is at least this.
    AtLeast(f64),
    /// The adaptive sampler did not meet it.
    Unknown,
}

impl std::fmt::Display for Ratio {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Ratio::Exact(r) => write!(f, "{r:.2}"),
            Ratio::AtLeast(r) => write!(f, ">{r:.2}"),
            Ratio::Unknown => write!(f, "-"),
        }
    }
}

/// The ratio of uniform to adaptive triangles for the adaptive row `a`.
pub fn ratio(rows: &[Row], a: &Row) -> Ratio {
    let u = rows
        .iter()
        .find(|r| r.method == "uniform" && r.surface == a.surface && r.tolerance == a.tolerance);
    match u {
        Some(u) if a.met => {
            let r = u.triangles as f64 / a.triangles.max(1) as f64;
            if u.met {
                Ratio::Exact(r)
            } else {
                Ratio::AtLeast(r)
            }
        }
        _ => Ratio::Unknown,
    }
}

/// A table for the terminal: per surface and tolerance, both methods and their ratio, then
/// the adaptive mesh's curves: points, the mesh curve's error and the refined curve's
/// residual (relative to the projected diagonal; `no curve` where the projection does not
/// cross itself), and whether its curves are the certified ones (`=`, else its closed/open
/// counts; `?` where the certificate is not complete); after each surface, its certificate
/// and what it cost against the curve stage.
pub fn table(rows: &[Row]) -> String {
    let mut out = format!(
        "{:<22} {:>9} {:>10} {:>10} {:>10} {:>10} {:>10} {:>10} {:>7} {:>8} {:>9} {:>9} {:>6}\n",
        "surface",
        "tolerance",
        "adaptive",
        "ms",
        "max err",
        "uniform",
        "ms",
        "max err",
        "ratio",
        "crv pts",
        "crv err",
        "refined",
        "truth"
    );
    for a in rows.iter().filter(|r| r.method == "adaptive") {
        let u = rows.iter().find(|r| {
            r.method == "uniform" && r.surface == a.surface && r.tolerance == a.tolerance
        });
        let mark = |met: bool| if met { ' ' } else { '!' };
        let (ut, ums, uerr, umet) = u.map_or((0, 0.0, f64::NAN, false), |u| {
            (u.triangles, u.ms, u.max_error, u.met)
        });
        let (err, residual) = if a.curve_points == 0 {
            ("no curve".to_string(), "-".to_string())
        } else {
            (
                format!("{:.2e}", a.curve_error),
                format!("{:.1e}", a.refined_residual),
            )
        };
        let truth = match a.certified {
            None => "?".to_string(),
            Some(c) if c == a.curves => "=".to_string(),
            Some(_) => format!("{}/{}", a.curves[0], a.curves[1]),
        };
        out.push_str(&format!(
            "{:<22} {:>9.0e} {:>10} {:>10.1} {:>9.2e}{} {:>10} {:>10.1} {:>9.2e}{} {:>7} {:>8} {:>9} {:>9} {:>6}\n",
            a.surface,
            a.tolerance,
            a.triangles,
            a.ms,
            a.max_error,
            mark(a.met),
            ut,
            ums,
            uerr,
            mark(umet),
            ratio(rows, a).to_string(),
            a.curve_points,
            err,
            residual,
            truth,
        ));
        let last = rows
            .iter()
            .rfind(|r| r.method == "adaptive" && r.surface == a.surface);
        if last == Some(a) {
            let curve_ms = a.curve_ms + a.refine_ms;
            let certified = a.certified.map_or("not complete".to_string(), |[c, o]| {
                format!("{c} closed and {o} open curves")
            });
            out.push_str(&format!(
                "{:<22} certified: {certified}, in {:.0} ms ({:.1}x the curves and their \
                 refinement on the adaptive mesh at {:.0e})\n",
                a.surface,
                a.certify_ms,
                a.certify_ms / curve_ms.max(1e-3),
                a.tolerance
            ));
        }
    }
    out.push_str("(! = tolerance not met within the triangle budget; crv = the adaptive mesh's curves: points, error and refined residual relative to the projected diagonal; truth = its curves those certified on the true surface (=), else its closed/open counts, ? = not certified)\n");
    out
}

/// Sweeps the surfaces and writes `speed_vs_error.csv`, `speed_vs_error.png` and
/// `curves_vs_error.png` into `out_dir`. Returns the rows and the paths written.
pub fn run(
    surfaces: &[(String, Surface)],
    settings: &Settings,
    out_dir: &Path,
    progress: &mut dyn FnMut(&str),
) -> Result<(Vec<Row>, Vec<PathBuf>), SweepError> {
    settings.check(surfaces)?;
    let mut rows = Vec::new();
    for (name, surface) in surfaces {
        rows.extend(sweep_surface(name, surface, settings, progress)?);
    }
    let png = plot::speed_vs_error_png(
        &rows,
        "halo4d: audited error against triangles, adaptive and uniform",
    )?;
    let curves_png = plot::curves_vs_error_png(
        &rows,
        "halo4d: intersection curve error against triangles, adaptive and uniform",
    )?;
    let written = write_files(
        out_dir,
        [
            ("speed_vs_error.csv", to_csv(&rows).into_bytes()),
            ("speed_vs_error.png", png),
            ("curves_vs_error.png", curves_png),
        ],
    )?;
    Ok((rows, written))
}

/// Writes each (file, bytes) into `out_dir` (made when missing), each file whole or not at
/// all; gives the paths.
fn write_files<const N: usize>(
    out_dir: &Path,
    files: [(&str, Vec<u8>); N],
) -> Result<Vec<PathBuf>, SweepError> {
    std::fs::create_dir_all(out_dir).map_err(|source| SweepError::Write {
        path: out_dir.to_path_buf(),
        source,
    })?;
    let mut written = Vec::new();
    for (file, bytes) in files {
        let path = out_dir.join(file);
        crate::export::write_atomic(&path, &bytes).map_err(|source| SweepError::Write {
            path: path.clone(),
            source,
        })?;
        written.push(path);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surfaces::FlatTorus;
    use crate::view::Projection;

    fn flat_torus_rows(view: View) -> Vec<Row> {
        let settings = Settings {
            tolerances: vec![1e-2],
            view,
            ..Settings::default()
        };
        let surface = Surface::FlatTorus(FlatTorus::default());
        sweep_surface("torus", &surface, &settings, &mut |_| {}).unwrap()
    }

    #[test]
    fn sweep_of_an_embedded_projection_has_no_curve_and_errors_zero() {
        // In perspective from w = -3 the flat torus is embedded in R^3: nothing crosses.
        let view = View {
            projection: Projection::Perspective { eye_distance: 3.0 },
            ..View::default()
        };
        let rows = flat_torus_rows(view);
        assert_eq!(rows.len(), 2);
        for r in &rows {
            assert_eq!(
                (
                    r.curve_points,
                    r.not_converged,
                    r.curve_error,
                    r.refined_residual
                ),
                (0, 0, 0.0, 0.0),
                "{r:?}"
            );
        }
        assert!(table(&rows).contains("no curve"), "{}", table(&rows));
        // The certificate is the true surface's: the same on both rows. Around the torus's
        // seams it is not complete here, and the table says so.
        assert_eq!(rows[0].certified, rows[1].certified);
        assert_eq!(rows[0].certify_ms, rows[1].certify_ms);
        assert!(rows.iter().all(|r| r.curves == [0, 0]));
        let table = table(&rows);
        let line = table.lines().find(|l| l.contains("certified:")).unwrap();
        match rows[0].certified {
            Some(c) => assert!(line.contains(&format!("{} closed", c[0])), "{table}"),
            None => assert!(
                line.contains("not complete") && table.contains(" ?"),
                "{table}"
            ),
        }
    }

    #[test]
    fn sweep_rows_carry_the_curves_of_their_mesh_in_the_view() {
        // The flat-torus fixture's view: two arcs ending at four cross-caps.
        let view = View {
            rotation: crate::view::Rotation4 {
                yw: 30.0,
                ..Default::default()
            },
            ..View::default()
        };
        let rows = flat_torus_rows(view);
        for r in &rows {
            assert!(r.curve_points > 0, "{r:?}");
            assert!(r.curve_error > r.refined_residual, "{r:?}");
            assert!(r.refined_residual < 1e-12, "{r:?}");
            assert!(r.curve_ms >= 0.0 && r.refine_ms >= 0.0, "{r:?}");
        }
        // Every CSV line has the header's columns.
        let csv = to_csv(&rows);
        let columns = CSV_HEADER.split(',').count();
        assert!(csv.starts_with(CSV_HEADER));
        assert!(
            csv.lines().all(|l| l.split(',').count() == columns),
            "{csv}"
        );
    }

    #[test]
    fn sweep_of_a_view_behind_the_eye_names_the_surface() {
        let view = View {
            projection: Projection::Perspective { eye_distance: 0.5 },
            ..View::default()
        };
        let settings = Settings {
            tolerances: vec![1e-2],
            view,
            ..Settings::default()
        };
        let surface = Surface::FlatTorus(FlatTorus::default());
        let err = sweep_surface("torus", &surface, &settings, &mut |_| {}).unwrap_err();
        assert!(
            matches!(err, SweepError::View { ref surface, .. } if surface == "torus"),
            "{err}"
        );
        assert!(
            err.to_string().starts_with("surface `torus`: vertex"),
            "{err}"
        );
    }
}
