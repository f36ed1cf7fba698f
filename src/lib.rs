//! halo4d turns surfaces that live in four dimensions into verified 3D geometry.
//!
//! The pipeline, one module per stage (see the README's architecture section):
//! [`scene`] (what to build) -> [`surfaces`] (4D parametric surfaces with exact derivatives)
//! -> [`sample`](mod@sample) (meshes to a tolerance, welded by domain rules, audited) ->
//! [`view`] (4D rotation and projection) -> [`halo`] (offsets, tetrahedra from [`tets`],
//! checked by [`check`]) -> [`export`] (glTF, PLY, OBJ, VTK, report). [`pipeline`] runs them
//! in order; [`sweep`] measures what each tolerance costs; [`import`] reads halos and scenes
//! back for checking.
#![warn(missing_docs)]

pub mod check;
pub mod convention;
pub mod error;
pub mod export;
pub mod halo;
pub mod import;
pub mod inspect;
pub mod intersect;
pub mod limits;
pub mod memory;
pub mod parts;
pub mod pipeline;
pub mod render;
pub mod sample;
pub mod scene;
pub mod surfaces;
pub mod sweep;
pub mod tets;
pub mod verify;
pub mod view;
#[cfg(feature = "viewer")]
pub mod viewer;

pub use error::Error;
pub use pipeline::{Built, Report, build, render_to, run, run_for_picture, write};
pub use sample::{Mesh4, MeshStats, Sampling, sample, sample_adaptive, sample_uniform};
pub use scene::{Scene, SceneError};
pub use surfaces::{Domain, Eval4, Surface, Topology};
pub use view::{Projected, Projection, Rotation4, View};
