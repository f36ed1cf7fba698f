//! Scene files: JSON describing surfaces, view, sampling, halo parameters and outputs.
//!
//! Takes: a file path or JSON text. Gives: a validated [`Scene`]. Guarantees: unknown keys
//! are rejected (a typo is an error, not a silent default); every number is finite and in
//! range; every error names the file and the field (`surfaces[0].surface.n`) and says what
//! is allowed. No input makes the parser panic.

use crate::animation::Animation;
use crate::halo::HaloParams;
use crate::intersect::CurveSettings;
use crate::limits::shorten;
use crate::limits::{FieldError, NAME_LENGTH, SURFACES, TRIANGLES, TUBE_RADIUS};
use crate::motion::Slicing;
use crate::render::{CameraSettings, RenderSettings};
use crate::sample::{Sampling, Source};
use crate::view::View;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The scene built when none is given: a spun trefoil in the 4D view the view search found.
pub const DEFAULT_SCENE: &str = include_str!("../fixtures/scenes/default.json");

/// A scene: what to build and what to write.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Name of the scene; names the output folder and files (letters, digits, `-`, `_`, `.`).
    pub name: String,
    /// Free text.
    #[serde(default)]
    pub description: String,
    /// The surfaces.
    pub surfaces: Vec<SceneSurface>,
    /// The 4D view, or `"auto"`: the view search's ([`View::auto`]).
    #[serde(default, deserialize_with = "crate::view::view_or_auto")]
    pub view: View,
    /// Default sampling for surfaces that set none.
    #[serde(default)]
    pub sampling: Sampling,
    /// Halo parameters.
    #[serde(default)]
    pub halo: HaloParams,
    /// Which intersection curves the files and the picture show.
    #[serde(default)]
    pub curves: CurveSettings,
    /// The 3D camera of the picture.
    #[serde(default)]
    pub camera: CameraSettings,
    /// How the picture is drawn.
    #[serde(default)]
    pub render: RenderSettings,
    /// Which files to write.
    #[serde(default)]
    pub outputs: Outputs,
    /// A path through 4D views for `halo4d animate`: frames, keyframes of the view and the
    /// camera.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub animation: Option<Animation>,
    /// What `halo4d slice` cuts the surfaces along: the direction, evenly spaced stills
    /// and a tilt.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub slicing: Option<Slicing>,
}

/// One surface of a scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneSurface {
    /// Name of the surface's mesh in the outputs; defaults to its type, which must then be
    /// unique in the scene.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// The surface and its parameters: a parametric surface (the catalogue's or a formula)
    /// or a 4D mesh from a file.
    pub surface: Source,
    /// Sampling for this surface, overriding the scene's (not for a mesh file).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sampling: Option<Sampling>,
}

/// Which files `halo4d build` writes.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Outputs {
    /// `<name>.glb`: glTF 2.0 binary.
    pub glb: bool,
    /// `<name>.ply`: the surfaces for MeshLab, w as vertex quality.
    pub ply: bool,
    /// `<name>.obj`: the surfaces as Wavefront OBJ.
    pub obj: bool,
    /// `<name>.4off` (one surface) or `<name>-<surface>.4off` (several): each surface's 4D
    /// mesh before the view, as Geomview `4OFF` text that reads back bit for bit (a scene's
    /// `mesh` surface, or another 4D viewer).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub off4: bool,
    /// `<name>-halo.vtk` (one surface) or `<name>-<surface>-halo.vtk` (several): each halo's
    /// tetrahedra as legacy VTK, for ParaView and meshio.
    pub vtk: bool,
    /// `report.json`: counts, bounds, timings and the parsed scene.
    pub report: bool,
    /// `<name>.png`: the picture of the `render` settings through the `camera`.
    pub png: bool,
    /// `<name>.svg`: the picture's lines as line art (silhouettes, cut edges, double curves
    /// in their inks, broken edges of the sheets passing under), the same lines the PNG
    /// draws, scalable for papers and slides.
    pub svg: bool,
    /// `<name>.html`: a page that shows the `.glb` in a web browser through the picture's
    /// camera (turned with the mouse), the halos hidden, for sharing a figure; it holds
    /// three.js and the `.glb`, so it opens from a file, offline. Needs `glb`.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub html: bool,
    /// Whether the halos are checked against the intersection curves. Always when a halo
    /// file is written (`glb`, `vtk`; the default then), and on request without one (the
    /// verdict in `report.json` and the exit status).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub verify: Option<bool>,
    /// The stipples of the stipple style (`render.stipple`): a `stipples` point cloud in
    /// `<name>.glb` (when `glb`) and `<name>-stipples.ply`, every stipple the set ranks, at
    /// its place in the view, with its w and the radius of `render.stipple.size` at the
    /// camera's distance.
    #[serde(default)]
    pub stipples: bool,
    /// Radius of the intersection curves' tubes in `<name>.glb`, a share of the projected
    /// scene's diagonal (as `halo.rho`).
    pub curve_radius: f64,
    /// The proven bound of every triangle's distance from its surface in `report.json`
    /// (`sampling.proven_max_error`): on by default; `false` saves its time (2 to 11 µs a
    /// triangle on two cores) where the audit is enough. A surface sampled with `"bound":
    /// "proven"` is proven either way.
    #[serde(skip_serializing_if = "is_true")]
    pub prove: bool,
}

/// Whether a flag is on (its default, not written).
fn is_true(flag: &bool) -> bool {
    *flag
}

/// The default [`Outputs::curve_radius`]: through the camera at distance 3.2 (the default
/// before the camera was fitted, which shows the default scene about 1.4 times larger),
/// tubes about 7 pixels across in a 1024-pixel picture, so that a curve in the crease
/// between two sheets, which bury most of its tube, still shows (measured in Blender by
/// `.ci/real-programs.py --render`: a radius of 0.003 leaves half of the default scene's
/// visible curve points light at 640 pixels, 0.004 one in twelve).
pub const CURVE_RADIUS: f64 = 0.004;

impl Outputs {
    /// Checks the numbers: names the first bad field.
    pub fn check(&self) -> Result<(), FieldError> {
        if self.verify == Some(false) && (self.glb || self.vtk) {
            return Err(FieldError::new(
                "verify",
                "halo files (glb, vtk) are always verified; remove `verify: false`, or set `glb` and `vtk` to false",
            ));
        }
        if self.html && !self.glb {
            return Err(FieldError::new(
                "html",
                "the page shows the scene's .glb, which it holds: set `glb` to true as well, or `html` to false",
            ));
        }
        TUBE_RADIUS.check("curve_radius", self.curve_radius)?;
        Ok(())
    }
}

impl Default for Outputs {
    fn default() -> Self {
        Outputs {
            glb: true,
            ply: true,
            obj: false,
            off4: false,
            vtk: true,
            report: true,
            png: true,
            svg: false,
            html: false,
            curve_radius: CURVE_RADIUS,
            verify: None,
            stipples: false,
            prove: true,
        }
    }
}

/// Why a scene could not be read.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read.
    #[error("{file}: cannot read the scene file: {source}")]
    Io {
        /// The file.
        file: String,
        /// The cause.
        source: std::io::Error,
    },
    /// The text is not a scene: bad JSON, a wrong type, an unknown key or surface type.
    #[error("{file}:{line}:{column}: {}: {}", shorten(.field), shorten(.message))]
    Syntax {
        /// The file.
        file: String,
        /// Path of the field, like `surfaces[0].surface.n`.
        field: String,
        /// What is wrong.
        message: String,
        /// Line of the error.
        line: usize,
        /// Column of the error.
        column: usize,
    },
    /// A value is out of range or inconsistent.
    #[error("{file}: {}: {}", shorten(.field), shorten(.message))]
    Invalid {
        /// The file.
        file: String,
        /// Path of the field.
        field: String,
        /// What is wrong and what is allowed.
        message: String,
    },
}

impl Scene {
    /// Reads and validates a scene file, and the mesh files it names (relative to its
    /// folder).
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|source| SceneError::Io {
            file: file.clone(),
            source,
        })?;
        Scene::parse(&text, &file)
    }

    /// The embedded default scene.
    pub fn default_scene() -> Scene {
        Scene::parse(DEFAULT_SCENE, "<default scene>").expect("the embedded default scene is valid")
    }

    /// Parses and validates scene text; `file` names it in errors, and its folder is where
    /// the paths of mesh files start.
    pub fn parse(text: &str, file: &str) -> Result<Scene, SceneError> {
        let mut scene: Scene = from_json(text, file, None)?;
        let folder = Path::new(file).parent().unwrap_or(Path::new(""));
        let invalid = |FieldError { field, message }| SceneError::Invalid {
            file: file.to_string(),
            field,
            message,
        };
        for (i, s) in scene.surfaces.iter_mut().enumerate() {
            if let Source::Mesh(m) = &mut s.surface {
                let file = folder.join(&m.path);
                crate::import::read_mesh4(&file)
                    .map_err(|e| FieldError::new("path", e.to_string()))
                    .and_then(|data| m.set(data, &file))
                    .map_err(|e| invalid(e.within(&format!("surfaces[{i}].surface"))))?;
            }
        }
        scene.validate().map_err(invalid)?;
        Ok(scene)
    }

    /// This scene in the view that `text` gives (a scene file's `view` as JSON, or
    /// `"auto"`), checked as [`Scene::parse`] checks a scene, its errors' fields under
    /// `view`; `file` names the text in them. The surfaces are kept as they are: a mesh
    /// file is not read again.
    pub fn with_view(&self, text: &str, file: &str) -> Result<Scene, SceneError> {
        #[derive(Deserialize)]
        struct Only(#[serde(deserialize_with = "crate::view::view_or_auto")] View);
        let Only(view) = from_json(text, file, Some("view"))?;
        let scene = Scene {
            view,
            ..self.clone()
        };
        scene
            .validate()
            .map_err(|FieldError { field, message }| SceneError::Invalid {
                file: file.to_string(),
                field,
                message,
            })?;
        Ok(scene)
    }

    /// The scene of frame `k` of its animation: its view and camera those of the frame, no
    /// animation. `None` without an animation or beyond its frames.
    pub fn frame(&self, k: u32) -> Option<Scene> {
        let a = self.animation.as_ref().filter(|a| k < a.frames)?;
        let (view, camera) = a.frame(k, &self.view, &self.camera);
        Some(Scene {
            view,
            camera,
            animation: None,
            ..self.clone()
        })
    }

    /// The name of surface `i` in the outputs.
    pub fn surface_name(&self, i: usize) -> String {
        self.surfaces[i]
            .name
            .clone()
            .unwrap_or_else(|| self.surfaces[i].surface.type_name().to_string())
    }

    /// The sampling of surface `i`.
    pub fn surface_sampling(&self, i: usize) -> &Sampling {
        self.surfaces[i].sampling.as_ref().unwrap_or(&self.sampling)
    }

    /// Checks every value; names the first bad field.
    pub fn validate(&self) -> Result<(), FieldError> {
        check_name(&self.name).map_err(|m| FieldError::new("name", m))?;
        SURFACES.check("surfaces", self.surfaces.len())?;
        self.sampling.check().map_err(|e| e.within("sampling"))?;
        let mut names = Vec::new();
        let mut triangles = 0usize;
        for (i, s) in self.surfaces.iter().enumerate() {
            s.surface
                .check()
                .map_err(|e| e.within(&format!("surfaces[{i}].surface")))?;
            if let (Source::Mesh(_), Some(_)) = (&s.surface, &s.sampling) {
                return Err(FieldError::new(
                    format!("surfaces[{i}].sampling"),
                    "a mesh file is taken as it is, not sampled; remove `sampling`",
                ));
            }
            if let Some(sampling) = &s.sampling {
                sampling
                    .check()
                    .map_err(|e| e.within(&format!("surfaces[{i}].sampling")))?;
            }
            let name = self.surface_name(i);
            check_name(&name).map_err(|m| FieldError::new(format!("surfaces[{i}].name"), m))?;
            if names.contains(&name) {
                return Err(FieldError::new(
                    format!("surfaces[{i}].name"),
                    format!(
                        "`{name}` is used by an earlier surface; give each surface a unique `name`"
                    ),
                ));
            }
            names.push(name);
            let sampling = self.surface_sampling(i);
            let field = if s.sampling.is_some() {
                format!("surfaces[{i}].sampling")
            } else {
                "sampling".into()
            };
            let surface = match &s.surface {
                Source::Parametric(surface) => surface,
                Source::Mesh(m) => {
                    triangles = triangles.saturating_add(m.mesh.triangles.len());
                    continue;
                }
            };
            if let Sampling::Adaptive {
                absolute_tolerance: Some(tolerance),
                ..
            } = *sampling
            {
                // Relative to the surface's size, as `tolerance` is bounded: far below, the
                // mesh's error is rounding and the sampler fills its budget for nothing.
                let diagonal = crate::sample::bounding_diagonal(surface);
                let lowest = crate::limits::RELATIVE_TOLERANCE.lo * diagonal;
                if tolerance < lowest {
                    return Err(FieldError::new(
                        format!("{field}.absolute_tolerance"),
                        format!(
                            "{tolerance:e} is {:.1e} of the surface's 4D diagonal ({diagonal:.3}), below the {:e} of it where the mesh's error is rounding; ask for at least {lowest:.1e}, or give `tolerance` relative to the diagonal",
                            tolerance / diagonal,
                            crate::limits::RELATIVE_TOLERANCE.lo
                        ),
                    ));
                }
            }
            if let Sampling::Uniform { u, v } = *sampling {
                let [min_u, min_v] = surface.min_cells();
                if u < min_u || v < min_v {
                    return Err(FieldError::new(
                        field,
                        format!(
                            "{} needs at least {min_u} x {min_v} cells, got {u} x {v}",
                            surface.type_name()
                        ),
                    ));
                }
            }
            // Adaptive budgets are bounded one by one in `Sampling::check`.
            if let Sampling::Uniform { .. } = sampling {
                triangles = triangles.saturating_add(sampling.max_triangles(surface.patch_count()));
            }
        }
        if triangles > TRIANGLES.hi {
            return Err(FieldError::new(
                "sampling",
                format!(
                    "the scene's grids and mesh files make {triangles} triangles, more than the limit of {}; lower u and v",
                    TRIANGLES.hi
                ),
            ));
        }
        self.view.check().map_err(|e| e.within("view"))?;
        self.halo.check().map_err(|e| e.within("halo"))?;
        self.camera.check().map_err(|e| e.within("camera"))?;
        self.render.check().map_err(|e| e.within("render"))?;
        self.outputs.check().map_err(|e| e.within("outputs"))?;
        if let Some(a) = &self.animation {
            a.check(&self.view, &self.camera)
                .map_err(|e| e.within("animation"))?;
        }
        if let Some(slicing) = &self.slicing {
            slicing.check().map_err(|e| e.within("slicing"))?;
        }
        Ok(())
    }
}

fn check_name(name: &str) -> Result<(), String> {
    let ok = NAME_LENGTH.contains(name.len())
        && !name.starts_with('.')
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_.".contains(c));
    if ok {
        Ok(())
    } else {
        Err(format!(
            "`{name}` is not a usable name: use {} letters, digits, `-`, `_` or `.`, not starting with `.`",
            NAME_LENGTH.range_words()
        ))
    }
}

/// serde_json appends " at line L column C"; we report the position ourselves.
/// A `T` read from JSON `text` (named `file` in errors), every error a
/// [`SceneError::Syntax`] naming its field's path, under `within` where given (a surface's
/// own field joins the path, `surfaces[0].surface.x`, as its checks name it).
fn from_json<T: serde::de::DeserializeOwned>(
    text: &str,
    file: &str,
    within: Option<&str>,
) -> Result<T, SceneError> {
    let syntax = |path: &str, inner: serde_json::Error| {
        let FieldError { field, message } =
            FieldError::from_serde(path, &strip_position(&inner.to_string()));
        SceneError::Syntax {
            file: file.to_string(),
            field,
            message,
            line: inner.line(),
            column: inner.column(),
        }
    };
    let mut de = serde_json::Deserializer::from_str(text);
    let value = serde_path_to_error::deserialize(&mut de).map_err(|e| {
        let path = match (e.path().to_string(), within) {
            // `?`: where the text stopped being JSON, before any key.
            (p, None) if p == "." || p == "?" => "(top level)".to_string(),
            (p, None) => p,
            (p, Some(w)) if p == "." || p == "?" => w.to_string(),
            (p, Some(w)) => format!("{w}.{p}"),
        };
        syntax(&path, e.into_inner())
    })?;
    de.end()
        .map_err(|e| syntax(within.unwrap_or("(after the scene)"), e))?;
    Ok(value)
}

fn strip_position(message: &str) -> String {
    match message.rfind(" at line ") {
        Some(i) => message[..i].to_string(),
        None => message.to_string(),
    }
}
