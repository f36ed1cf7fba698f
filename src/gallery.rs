//! A gallery: every scene of a folder (paper 000's figures, `fixtures/figures/`) built into
//! a folder of its own, verified, with an index page (`index.html`) that shows each picture
//! with its description, the share of its double curves in view and its verdict, and a
//! contact sheet of all the pictures (`gallery.png`).

use crate::export::write_atomic;
use crate::pipeline::{self, Report};
use crate::progress::Job;
use crate::scene::{Scene, SceneError};
use std::path::{Path, PathBuf};

/// The height of a picture on the contact sheet, in pixels.
pub const SHEET_ROW: u32 = 256;
/// The width of the contact sheet, in pixels: pictures are laid out in rows up to it.
pub const SHEET_WIDTH: u32 = 1024;

/// Why a gallery could not be made.
#[derive(Debug, thiserror::Error)]
pub enum GalleryError {
    /// The folder of scenes cannot be read.
    #[error("{}: cannot read the folder of figures: {source}; give the folder of scene files (fixtures/figures in the repository)", path.display())]
    Folder {
        /// The folder.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The folder holds no scene.
    #[error("{}: no scene file (*.json) in the folder of figures", path.display())]
    Empty {
        /// The folder.
        path: PathBuf,
    },
    /// Two scenes of the folder have one name, so one would overwrite the other's files.
    #[error(
        "{first} and {second} both name their scene `{name}`; give each figure a name of its own"
    )]
    SameName {
        /// The name.
        name: String,
        /// The first file.
        first: String,
        /// The second file.
        second: String,
    },
    /// A scene file is not a valid scene.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// A figure could not be built.
    #[error("figure {}: {source}", file.display())]
    Build {
        /// The scene file.
        file: PathBuf,
        /// Why.
        source: crate::error::Error,
    },
    /// The view search of a figure whose view is `"auto"` found no view.
    #[error("figure {}: {source}", file.display())]
    Search {
        /// The scene file.
        file: PathBuf,
        /// Why.
        source: crate::viewsearch::SearchError,
    },
    /// The index page or the contact sheet could not be made or written.
    #[error("{}: {message}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// Why.
        message: String,
    },
}

/// One figure of a gallery.
#[derive(Clone, Debug)]
pub struct Figure {
    /// The scene file.
    pub file: PathBuf,
    /// The build's report (with the scene it built, in the view it was built in).
    pub report: Report,
}

impl Figure {
    /// The scene's name: its folder in the gallery.
    pub fn name(&self) -> &str {
        &self.report.scene.name
    }

    /// The picture, relative to the gallery's folder.
    pub fn picture(&self) -> String {
        format!("{0}/{0}.png", self.name())
    }
}

/// What [`make`] made.
#[derive(Clone, Debug)]
pub struct Gallery {
    /// The figures, in the order of their file names.
    pub figures: Vec<Figure>,
    /// The index page.
    pub index: PathBuf,
    /// The contact sheet.
    pub sheet: PathBuf,
}

impl Gallery {
    /// Whether every figure's build verified its halos.
    pub fn verified(&self) -> bool {
        self.figures.iter().all(|f| f.report.verified)
    }
}

/// The scene files (`*.json`) of `folder`, in the order of their names.
pub fn scenes(folder: &Path) -> Result<Vec<PathBuf>, GalleryError> {
    let folder_error = |source| GalleryError::Folder {
        path: folder.to_path_buf(),
        source,
    };
    let mut files = Vec::new();
    for entry in std::fs::read_dir(folder).map_err(folder_error)? {
        let path = entry.map_err(folder_error)?.path();
        if path.extension().is_some_and(|e| e == "json") && path.is_file() {
            files.push(path);
        }
    }
    if files.is_empty() {
        return Err(GalleryError::Empty {
            path: folder.to_path_buf(),
        });
    }
    files.sort();
    Ok(files)
}

/// Builds every scene of `figures` (its picture always, whatever its `outputs` say) into
/// `out/<name>/`, then writes `out/index.html` and `out/gallery.png`: a task `"gallery"` of
/// `job`, a step per figure, with a note of each figure before it is built
/// (`figure 2 of 5: file`), stopped once `job` is cancelled. The scenes are all read and
/// checked before the first is built.
pub fn make(figures: &Path, out: &Path, job: Job) -> Result<Gallery, GalleryError> {
    let files = scenes(figures)?;
    let mut scenes: Vec<(PathBuf, Scene)> = Vec::new();
    for file in files {
        let scene = Scene::load(&file)?;
        if let Some((first, _)) = scenes.iter().find(|(_, s)| s.name == scene.name) {
            return Err(GalleryError::SameName {
                name: scene.name,
                first: first.display().to_string(),
                second: file.display().to_string(),
            });
        }
        scenes.push((file, scene));
    }
    let (count, mut built) = (scenes.len(), Vec::new());
    let task = job.task("gallery", count as u64);
    for (k, (file, mut scene)) in scenes.into_iter().enumerate() {
        job.note(&format!("figure {} of {count}: {}", k + 1, file.display()));
        crate::viewsearch::resolve(&mut scene, job).map_err(|source| GalleryError::Search {
            file: file.clone(),
            source,
        })?;
        scene.outputs.png = true;
        let report = pipeline::build(&scene, &out.join(&scene.name), job).map_err(|source| {
            GalleryError::Build {
                file: file.clone(),
                source,
            }
        })?;
        built.push(Figure { file, report });
        task.step();
    }
    drop(task);
    let write = |name: &str, bytes: &[u8]| {
        let path = out.join(name);
        write_atomic(&path, bytes).map_err(|e| GalleryError::Write {
            path: path.clone(),
            message: e.to_string(),
        })?;
        Ok::<_, GalleryError>(path)
    };
    let sheet = contact_sheet(out, &built)?;
    let sheet = write("gallery.png", &sheet)?;
    let index = write("index.html", index_page(&built).as_bytes())?;
    Ok(Gallery {
        figures: built,
        index,
        sheet,
    })
}

/// The pictures of `figures` (read back from `out`) scaled to [`SHEET_ROW`] pixels high
/// and laid out left to right in rows of up to [`SHEET_WIDTH`] pixels on white: a PNG.
fn contact_sheet(out: &Path, figures: &[Figure]) -> Result<Vec<u8>, GalleryError> {
    use image::imageops::{FilterType, overlay, resize};
    let mut cells = Vec::new();
    for f in figures {
        let path = out.join(f.picture());
        let picture = image::open(&path)
            .map_err(|e| GalleryError::Write {
                path: path.clone(),
                message: format!("cannot read the figure's picture back: {e}"),
            })?
            .to_rgb8();
        let scale = f64::from(SHEET_ROW) / f64::from(picture.height());
        let width = ((f64::from(picture.width()) * scale).round() as u32).clamp(1, SHEET_WIDTH);
        cells.push(resize(&picture, width, SHEET_ROW, FilterType::Lanczos3));
    }
    // Rows: each cell starts a new one where it would overrun the sheet.
    let mut places = Vec::new();
    let (mut x, mut y) = (0u32, 0u32);
    for cell in &cells {
        if x > 0 && x + cell.width() > SHEET_WIDTH {
            (x, y) = (0, y + SHEET_ROW);
        }
        places.push((x, y));
        x += cell.width();
    }
    let mut sheet = image::RgbImage::from_pixel(SHEET_WIDTH, y + SHEET_ROW, image::Rgb([255; 3]));
    for (cell, &(x, y)) in cells.iter().zip(&places) {
        overlay(&mut sheet, cell, i64::from(x), i64::from(y));
    }
    let mut png = Vec::new();
    sheet
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .map_err(|e| GalleryError::Write {
            path: out.join("gallery.png"),
            message: e.to_string(),
        })?;
    Ok(png)
}

/// Text for HTML: `&`, `<`, `>` and `"` escaped.
fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The index page: each figure's picture, name, description, the share of its double
/// curves in view and its verdict.
fn index_page(figures: &[Figure]) -> String {
    let mut html = String::from(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>halo4d gallery</title>\n<style>\nbody { font-family: sans-serif; max-width: 70em; margin: 2em auto; padding: 0 1em; }\nfigure { margin: 0 0 3em 0; }\nimg { max-width: 100%; border: 1px solid #ddd; }\n.failed { color: #b00; }\n</style>\n</head>\n<body>\n<h1>halo4d gallery</h1>\n<p>Each picture is the build of its scene file; every build verifies its halos against the exact double curves.</p>\n",
    );
    for f in figures {
        let r = &f.report;
        let share = r.picture.as_ref().map_or_else(
            || "no picture report".to_string(),
            |p| {
                format!(
                    "{:.0}% of the double curves' projected length in view, gaps {} px",
                    100.0 * p.curves.visible_curve_share,
                    p.gap_px.round()
                )
            },
        );
        let verdict = if r.verified {
            "verified".to_string()
        } else {
            format!(
                "<span class=\"failed\">NOT verified: {}</span>",
                escape(&r.failures.join("; "))
            )
        };
        html.push_str(&format!(
            "<figure id=\"{name}\">\n<img src=\"{src}\" alt=\"{name}\">\n<figcaption><b>{name}</b>: {description}<br><small>{share}; {verdict}; built in {ms:.1} s from <code>{file}</code></small></figcaption>\n</figure>\n",
            name = escape(f.name()),
            src = escape(&f.picture()),
            description = escape(&f.report.scene.description),
            ms = r.timings_ms.total / 1e3,
            file = escape(&f.file.display().to_string()),
        ));
    }
    html.push_str("</body>\n</html>\n");
    html
}
