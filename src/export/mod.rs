//! Export: the products of a build as files.
//!
//! Takes: the sampled and projected surfaces, their halos and the intersection curves.
//! Gives: `.glb` (glTF 2.0 binary, for Blender: surfaces, halos, and the intersection curves
//! as tubes with their exact polylines as data), `.ply` (binary PLY with w as vertex
//! `quality`, for MeshLab), `-curves.ply` (the intersection curves as PLY edges, with the
//! depth gap dw as vertex `quality`, for MeshLab), `.obj` (Wavefront, positions and normals
//! only), `.vtk` (legacy VTK unstructured grids of the halos' tetrahedra, for ParaView and
//! meshio), `.html` (a page that shows the `.glb` in a web browser, three.js and the file
//! inlined), `report.json`, and any tetrahedra with cell fields as `.vtu`
//! ([`write_tetrahedra_vtu`], what `halo4d check --mark` writes). Guarantees: each file in its format's conventions
//! (`convention`); every file is written to a temporary name and renamed into place,
//! so a failure never leaves a half-written file, and a build's files move into place
//! together ([`Staged`]). A build's files are not synced to the disk (the operating system
//! writes them in its own time): a failed or killed build leaves none half-written, a
//! power cut in the seconds after one may (syncing cost 0.5 to 1 s of a 1M-triangle
//! build's 490 MB), and the build can be run again. The files of long runs that resume
//! from what they find ([`write_atomic`]: an animation's frames, a gallery's pictures)
//! are synced before they are renamed, so that a file found is whole. [`crate::import`]
//! reads the halos and surfaces back.

mod gltf;
mod html;
mod obj;
mod off4;
mod ply;
mod tubes;
mod vtk;
mod vtu;

pub use gltf::{
    Figure, HALO_SCENE, glb_chunks, glb_container, stills_glb, to_glb, w_colour,
    write_glb_container,
};
pub use html::write_html;
pub use obj::to_obj;
pub use off4::to_4off;
pub use ply::{segments, to_curves_ply, to_ply, to_still_ply, to_stipples_ply};
pub use vtk::write_vtk;
pub use vtu::{CellValues, write_tetrahedra_vtu};

mod staged;
pub use staged::{LOCK, Staged, StagedError};

use crate::halo::{Halo, HaloParams};
use crate::sample::Mesh4;
use crate::view::Projected;
use std::io::Write;
use std::path::Path;

/// What the writers need of one surface.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceData<'a> {
    /// Mesh name.
    pub name: &'a str,
    /// Catalogue type of the surface.
    pub surface_type: &'a str,
    /// Number of parameter patches.
    pub patches: usize,
    /// The 4D mesh (triangles, parameters, patches).
    pub mesh: &'a Mesh4,
    /// Its projection (3D positions, w-depth, normals).
    pub projected: &'a Projected,
    /// Its halo, in the layout of [`crate::check`].
    pub halo: &'a Halo,
    /// The scene's halo parameters (`rho` among them is relative).
    pub halo_params: &'a HaloParams,
    /// The halo's half-width, absolute (before any local shrinking).
    pub rho: f64,
}

/// Writes `bytes` to `path` through a temporary file in the same folder and a rename.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let tmp = write_partial_as(path, "partial", Durable::Synced, |w| w.write_all(bytes))?;
    std::fs::rename(&tmp, path).inspect_err(|_| {
        let _ = std::fs::remove_file(&tmp);
    })
}

/// [`write_atomic`] for a file that several processes may write at once (the shards of one
/// animation, each writing the same bytes), streamed from `fill`: the temporary name
/// carries the process id (`.<file name>.<pid>.partial`), so that each process renames a
/// whole file of its own.
pub fn write_atomic_shared(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let suffix = format!("{}.partial", std::process::id());
    let tmp = write_partial_as(path, &suffix, Durable::Synced, fill)?;
    std::fs::rename(&tmp, path).inspect_err(|_| {
        let _ = std::fs::remove_file(&tmp);
    })
}

/// Whether a file is synced to the disk before it is renamed into place.
#[derive(Clone, Copy, PartialEq)]
enum Durable {
    /// Synced: a file found after a power cut is whole (what a resumed run relies on).
    Synced,
    /// Left to the operating system (a build's files, all made again by the next build).
    Unsynced,
}

/// Writes what `fill` writes, buffered, to the temporary name of `path`
/// (`.<file name>.partial` in its folder), unsynced, and returns that name; on failure
/// removes what it wrote.
fn write_partial(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> std::io::Result<std::path::PathBuf> {
    write_partial_as(path, "partial", Durable::Unsynced, fill)
}

/// [`write_partial`] to `.<file name>.<suffix>`, synced or not.
fn write_partial_as(
    path: &Path,
    suffix: &str,
    durable: Durable,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> std::io::Result<std::path::PathBuf> {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = path.with_file_name(format!(".{name}.{suffix}"));
    std::fs::File::create(&tmp)
        .and_then(|f| {
            let mut w = std::io::BufWriter::with_capacity(1 << 20, f);
            fill(&mut w)?;
            let f = w.into_inner().map_err(|e| e.into_error())?;
            if durable == Durable::Synced {
                f.sync_all()
            } else {
                Ok(())
            }
        })
        .inspect_err(|_| {
            let _ = std::fs::remove_file(&tmp);
        })?;
    Ok(tmp)
}

/// Writes an animated PNG of `frames` pictures of `width` x `height` (8-bit RGB, each
/// given by `frame(k)` as it is written, so that no more than one is held), shown at `fps`
/// frames per second, looping.
pub fn write_apng(
    w: &mut dyn Write,
    (width, height): (u32, u32),
    fps: u32,
    frames: u32,
    mut frame: impl FnMut(u32) -> std::io::Result<Vec<u8>>,
) -> std::io::Result<()> {
    let mut encoder = png::Encoder::new(w, width, height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder
        .set_animated(frames, 0)
        .map_err(std::io::Error::other)?;
    encoder
        .set_frame_delay(1, u16::try_from(fps).unwrap_or(u16::MAX))
        .map_err(std::io::Error::other)?;
    let mut writer = encoder.write_header().map_err(std::io::Error::other)?;
    for k in 0..frames {
        writer
            .write_image_data(&frame(k)?)
            .map_err(std::io::Error::other)?;
    }
    writer.finish().map_err(std::io::Error::other)
}
