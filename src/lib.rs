//! halo4d turns surfaces that live in four dimensions into verified 3D geometry.
//!
//! A [`Scene`] says what to build; [`build`] runs the stages its outputs need and writes the
//! files ([`Sampled::of`] then [`Sampled::build`], and [`write()`], do the two halves; a
//! sample serves any number of views; [`render_to`] makes its picture). The
//! stages, in the order of the pipeline: a [`Surface`] of the catalogue (4D, exact
//! derivatives) is sampled to a tolerance ([`sample`], a welded, audited [`Mesh4`]), turned
//! and projected by a [`View`] ([`Projected`]), thickened into a [`Halo`] of tetrahedra
//! ([`build_halo`], checked by the independent [`check`]); the intersection [`curves`] of
//! all surfaces are the ground truth the halos are verified against ([`verify`]), and
//! [`refine()`] moves them onto the analytic surfaces for the files and the picture;
//! [`Parts`] hands what a scene produced to the verification and the renderer ([`render`]).
//! The files are read back with [`read_halos`] and [`read_scene_glb`], and checked again
//! with [`check_file`] and [`check_dir`]. [`limits`] holds every limit a user can meet;
//! [`sweep`] measures speed against error. The README's ARCHITECTURE section draws the
//! module graph.
//!
//! From a scene to a verified build and its files:
//!
//! ```
//! // A flat torus turned 30 degrees in yw: its projection crosses itself along two arcs.
//! let scene = halo4d::Scene::parse(
//!     r#"{
//!         "name": "torus",
//!         "surfaces": [{ "surface": { "type": "flat_torus" } }],
//!         "sampling": { "method": "uniform", "u": 32, "v": 32 },
//!         "view": { "rotation": { "yw": 30 } },
//!         "render": { "width": 160, "height": 160 },
//!         "outputs": { "glb": true, "ply": false, "vtk": false, "png": true }
//!     }"#,
//!     "torus.json",
//! )?;
//! // Sample once; build it in its view (the halos verified against the exact curves).
//! let sampled = halo4d::Sampled::of(&scene);
//! let built = sampled.build(&scene, halo4d::Stages::of(&scene))?;
//! assert!(built.failures().is_empty(), "{:?}", built.failures());
//! assert_eq!(built.shown_curves().curves.len(), 2);
//! // The files: the .glb, the picture and report.json.
//! let out = std::env::temp_dir().join(format!("halo4d-doc-{}", std::process::id()));
//! let report = halo4d::write(&scene, &built, &out)?;
//! assert!(report.verified);
//! assert!(out.join("torus.glb").is_file() && out.join("torus.png").is_file());
//! // The independent checker on the file: every halo conforms.
//! let checked = halo4d::check_file(&out.join("torus.glb"))?;
//! assert!(checked.failures().is_empty());
//! # std::fs::remove_dir_all(&out)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![warn(missing_docs)]

mod animate;
mod animation;
mod check;
mod convention;
mod error;
mod export;
pub mod gallery;
mod halo;
mod import;
mod inspect;
mod intersect;
pub mod limits;
mod memory;
mod parts;
mod pipeline;
mod render;
mod sample;
mod scene;
mod stipple;
mod surfaces;
pub mod sweep;
mod tets;
mod verify;
mod view;
#[cfg(feature = "viewer")]
pub mod viewer;
mod viewsearch;

// The scene, the build and what it gives.
pub use error::Error;
pub use pipeline::{
    Bounds, Built, MemoryReport, PictureReport, Report, Sampled, SamplingReport, Stages,
    SurfaceProduct, SurfaceReport, Timings, build, glb_bytes, render_to, shown_curves, write,
};
pub use scene::{DEFAULT_SCENE, Outputs, Scene, SceneError, SceneSurface};
pub use viewsearch::{Found, SearchError, resolve as resolve_view, search as search_view};

// Animations: a path through 4D views, and its frames.
pub use animate::{
    AnimateError, Assembled, FrameRange, FrameRecord, Request, Shard, Status, Summary, animate,
    assemble, status,
};
pub use animation::{Animation, CameraKey, Keyframe, RotationKey, ViewKey};

// The stages, in the order of the pipeline.
pub use check::{CheckStats, TetMesh, check};
pub use halo::{Fold, Halo, HaloParams, HaloReport, build_halo};
pub use intersect::{
    Analytic, Curve, CurvePoint, CurveSettings, Curves, CurvesReport, End, Face, Refinement, Sheet,
    TriplePoint, curves, refine,
};
pub use parts::{HaloIndex, HaloPart, Parts, SurfacePart};
pub use render::clip::{Clip, ClipPlane};
pub use render::compare::Comparison;
pub use render::{
    CameraProjection, CameraSettings, Colormap, Lighting, Picture, RenderError, RenderMode,
    RenderSettings, RibbonAxis, Ribbons, StippleSettings, Style, render,
};
pub use sample::{
    Audit, Mesh4, MeshData4, MeshStats, MeshSurface, Sampling, Source, audit, mesh_from_data,
    mesh_tangents, sample, sample_adaptive, sample_uniform,
};
pub use stipple::{Stipples, poisson_radius};
pub use surfaces::{
    Bound, Domain, Eval4, Fermat, FlatTorus, Formula, FormulaEdge, FormulaSeam, FormulaSides,
    FormulaSource, Glue, Jet, KleinBottle, Patches, ProductPolynomial, ProjectivePlane, Side,
    SideRule, SpunTrefoil, Surface, Topology, TwistSpunTrefoil,
};
pub use verify::{Ambiguous, Verification, verify};
pub use view::{BehindEye, Mapped, Projected, Projection, Rotation4, View, ViewMap};

// The files: written, read back and checked.
pub use export::{
    StagedError, SurfaceData, to_4off, to_curves_ply, to_obj, to_ply, write_atomic, write_vtk,
};
pub use import::{
    FileParams, ImportError, ImportedCurves, ImportedHalo, ImportedScene, ImportedSurface,
    MeshFileError, MeshFileLocation, MeshFormat, parse_mesh4, read as read_halos, read_glb,
    read_mesh4, read_scene_glb, read_vtk,
};
pub use inspect::{Checked, InspectError, check_dir, check_file, verify_scene};

/// What the tests and benches reach into beneath the API: stage internals with their own
/// contracts, kept public so that they can be tested on their own, not for use.
pub mod internals {
    pub use crate::convention::file_order;
    pub use crate::export::{LOCK, glb_container, to_glb, write_atomic};
    pub use crate::intersect::{BroadPhase, Node, curves_with};
    pub use crate::render::camera::{Camera, Placement};
    pub use crate::render::compare::verdict_differs;
    pub use crate::render::overlay::{INK, OVER_BANDS, OVER_SHADE, curve_ink};
    pub use crate::render::stipple::{Drawn, density, luminance, tone};
    pub use crate::render::visible::{CurveVisibility, PictureCamera, curve_visibility};
    pub use crate::render::{Prober, Seen, line_coverage, render_with_depth, stipples_drawn};
    pub use crate::sample::{bounding_diagonal, uniform_error};

    /// One-pixel lines broadened to an exact width.
    pub mod lines {
        pub use crate::render::lines::*;
    }

    /// Prisms split into tetrahedra.
    pub mod tets {
        pub use crate::tets::*;
    }
}
