//! halo4d turns surfaces that live in four dimensions into verified 3D geometry.
//!
//! A [`Scene`] says what to build. [`Sampled::of`] samples and audits its surfaces once;
//! [`Sampled::build`] builds them in the scene's view (any number of views from one
//! sampling) into a [`Built`], whose verdict is [`Built::failures`]; [`write()`] makes the
//! files the scene asks for and gives the [`report::Report`]. [`build`] does all three and
//! [`render_to`] makes the scene's picture. The library prints nothing: a long operation
//! reports to the [`progress::Job`] it is given and stops, with nothing written, when the
//! job's token is cancelled. The files are checked again by [`check_file`] and [`check_dir`].
//!
//! The stages, each a module, in the order of the pipeline: a surface of the catalogue or
//! a formula ([`surfaces`]: 4D, exact derivatives) is sampled to a tolerance ([`sample`]: a
//! welded, audited 4D mesh), turned and projected ([`view`]), thickened into halos of
//! tetrahedra ([`halo`], checked by the independent [`check`]); the exact intersection
//! curves of all surfaces ([`intersect`]) are the ground truth the halos are verified
//! against ([`verify`]), and are moved onto the analytic surfaces for the files and the
//! picture; [`Parts`] hands what a build or a file produced to the verification and the
//! renderer ([`render`], [`stipple`]). [`export`] writes the files and [`import`] reads
//! them back; [`animate`] makes the frames of a path through 4D views, [`gallery`] a folder
//! of figures and [`sweep`] speed against error. [`limits`] holds every limit a user can
//! meet. `docs/ARCHITECTURE.md` draws the module graph.
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

pub mod animate;
mod animation;
pub mod certify;
pub mod check;
mod convention;
mod error;
pub mod export;
pub mod gallery;
pub mod halo;
pub mod import;
mod inspect;
pub mod intersect;
pub mod limits;
mod memory;
pub mod motion;
mod parts;
mod pipeline;
pub mod progress;
pub mod render;
pub mod sample;
mod scene;
pub mod slicing;
pub mod stipple;
pub mod surfaces;
pub mod sweep;
mod tets;
pub mod verify;
pub mod view;
#[cfg(feature = "viewer")]
pub mod viewer;
mod viewsearch;

// The scene, the build and what it gives; the stages and the files are in the modules
// above, in the order of the pipeline.
pub use error::Error;
pub use pipeline::report;
pub use pipeline::{
    Built, Sampled, Stages, SurfaceProduct, build, build_since, glb_bytes, render_to, report_of,
    shown_curves, write, write_with,
};
pub use scene::{DEFAULT_SCENE, Outputs, Scene, SceneError, SceneSurface};
pub use viewsearch::{Found, SearchError, resolve as resolve_view, search as search_view};

// What a build or a scene's file produced, as the verification and the renderer read it.
pub use parts::{HaloIndex, HaloPart, Parts, SurfacePart};

// The files: each written whole or not at all, and checked again.
pub use export::write_atomic;
pub use inspect::{
    Checked, InspectError, Piece, Unchecked, check_dir, check_file, check_mesh, verify_scene,
};

/// What the tests and benches reach into beneath the API: stage internals with their own
/// contracts, kept public so that they can be tested on their own, not for use.
#[doc(hidden)]
pub mod internals {
    pub use crate::convention::file_order;
    pub use crate::render::camera::{Camera, Placement};
    pub use crate::render::compare::verdict_differs;
    pub use crate::render::overlay::{INK, OVER_BANDS, OVER_SHADE, curve_ink};
    pub use crate::render::shade::colormap;
    pub use crate::render::stipple::{Drawn, tone};
    pub use crate::render::trace::{Hit, Primary, TraceSurface, Tracer};
    pub use crate::render::visible::curve_visibility;

    /// One-pixel lines broadened to an exact width.
    pub mod lines {
        pub use crate::render::lines::*;
    }

    /// Prisms split into tetrahedra.
    pub mod tets {
        pub use crate::tets::*;
    }
}
