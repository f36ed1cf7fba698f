//! Legacy VTK (`.vtk`, version 3.0, binary) of a halo's tetrahedra, for ParaView and meshio.
//!
//! One `UNSTRUCTURED_GRID` per halo: every halo vertex in the layout of [`crate::check`]
//! (negative offsets, positive offsets, the surface, inserted vertices) as `double` POINTS,
//! every tetrahedron as a cell of 4 ids and type 10 (`VTK_TETRA`) in VTK's orientation
//! ([`file_order`]), the dataset's field data `surface_vertices`, `surface_triangles` (the
//! surface's triangles, three surface vertex indices each) and `layers` ([`LAYERS`]) (int),
//! `rho` (absolute), `delta_d` and `delta_t` (double), and the point
//! scalars `t` and `d_orig` (double). Binary legacy VTK is big-endian; each binary block ends
//! with a newline, as VTK's own writer does and meshio requires.
//!
//! The field data comes after `CELL_TYPES` rather than right after `DATASET`: VTK's reader
//! takes it anywhere at the dataset level, but meshio files it as field data only there.

use super::SurfaceData;
use crate::check::LAYERS;
use crate::convention::file_order;
use std::io::{self, Write};

/// Writes the `.vtk` of one surface's halo to `out` as it goes (no copy of the file in
/// memory; give it a buffered writer). The title line is
/// `<surface>-halo: halo4d <version>, scene <scene_name>`.
pub fn write_vtk(out: &mut dyn Write, surface: &SurfaceData, scene_name: &str) -> io::Result<()> {
    let halo = surface.halo;
    let points = halo.positions.len();
    let tets = halo.tets.len();
    write!(
        out,
        "# vtk DataFile Version 3.0\n{}-halo: halo4d {}, scene {scene_name}\nBINARY\n\
         DATASET UNSTRUCTURED_GRID\nPOINTS {points} double\n",
        surface.name,
        env!("CARGO_PKG_VERSION"),
    )?;
    for p in &halo.positions {
        for x in p.to_array() {
            out.write_all(&x.to_be_bytes())?;
        }
    }
    // Ids are 32-bit ints in legacy VTK; a scene's triangle limit keeps them far below 2^31.
    write!(out, "\nCELLS {tets} {}\n", 5 * tets)?;
    for &tet in &halo.tets {
        let mut cell = [0u8; 20];
        cell[..4].copy_from_slice(&4i32.to_be_bytes());
        for (k, i) in file_order(tet).into_iter().enumerate() {
            cell[4 + 4 * k..8 + 4 * k].copy_from_slice(&(i as i32).to_be_bytes());
        }
        out.write_all(&cell)?;
    }
    write!(out, "\nCELL_TYPES {tets}\n")?;
    for _ in 0..tets {
        out.write_all(&10i32.to_be_bytes())?;
    }
    write!(out, "\nFIELD FieldData 6\nsurface_vertices 1 1 int\n")?;
    out.write_all(&(halo.surface_vertices as i32).to_be_bytes())?;
    // The surface's triangles, so that a checker sees a prism missing whole.
    let triangles = &surface.mesh.triangles;
    write!(out, "\nsurface_triangles 3 {} int\n", triangles.len())?;
    for &v in triangles.iter().flatten() {
        out.write_all(&(v as i32).to_be_bytes())?;
    }
    write!(out, "\nlayers 1 1 int\n")?;
    out.write_all(&(LAYERS as i32).to_be_bytes())?;
    let params = surface.halo_params;
    for (name, value) in [
        ("rho", surface.rho),
        ("delta_d", params.delta_d),
        ("delta_t", params.delta_t),
    ] {
        write!(out, "\n{name} 1 1 double\n")?;
        out.write_all(&value.to_be_bytes())?;
    }
    write!(out, "\nPOINT_DATA {points}\n")?;
    for (name, values) in [("t", &halo.t), ("d_orig", &halo.d_orig)] {
        write!(out, "SCALARS {name} double 1\nLOOKUP_TABLE default\n")?;
        for x in values.iter() {
            out.write_all(&x.to_be_bytes())?;
        }
        out.write_all(b"\n")?;
    }
    Ok(())
}
