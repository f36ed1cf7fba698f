//! File conventions: where the formats halo4d writes differ from its own frame and
//! orientation, and the conversions, which the exporters and importers call at the file
//! boundary and nothing else does.
//!
//! - **Frame.** halo4d's 3D frame is right-handed with z up (the camera's elevation turns
//!   towards +z). glTF's is right-handed with +y up and the front towards +z, so a point or
//!   normal (x, y, z) is (x, z, −y) in a `.glb` ([`to_gltf`], [`from_gltf`]); Blender's
//!   importer turns that back into (x, y, z), z up. It is a rotation: windings and
//!   orientations are kept. PLY, legacy VTK and OBJ state no up axis; they hold halo4d's
//!   coordinates as they are.
//! - **Tetrahedra.** Inside halo4d a tetrahedron (a, b, c, d) is positive when
//!   `robust::orient3d(a, b, c, d) > 0`, i.e. det[b − a, c − a, d − a] < 0. The files (`.vtk`
//!   and the `.glb`'s tetrahedra) take VTK's convention, which meshio and Gmsh share: a, b, c
//!   seen from d run counter-clockwise, det[b − a, c − a, d − a] > 0 ([`file_order`]).
//! - **4D.** The `.glb` holds each surface's 4D mesh before the view as twelve float SCALAR
//!   custom attributes ([`MESH_4D`]): R^4 has no up axis and no program but halo4d reads
//!   them, so they are (x, y, z, w) in the scene's own coordinates. SCALARs, because
//!   Blender's importer (4.5) fails on a primitive whose custom attributes mix SCALAR and
//!   VEC4.

use glam::DVec3;

/// The names (without the leading `_`) of the `.glb`'s custom attributes of a surface's 4D
/// mesh: the position, ∂p/∂u and ∂p/∂v, each as its x, y, z and w.
pub const MESH_4D: [[&str; 4]; 3] = [
    ["X4", "Y4", "Z4", "W4"],
    ["XU4", "YU4", "ZU4", "WU4"],
    ["XV4", "YV4", "ZV4", "WV4"],
];

/// A point or direction of halo4d's frame in glTF's (y up).
pub fn to_gltf(p: DVec3) -> DVec3 {
    DVec3::new(p.x, p.z, -p.y)
}

/// A point or direction of glTF's frame in halo4d's (z up); the inverse of [`to_gltf`].
pub fn from_gltf(p: DVec3) -> DVec3 {
    DVec3::new(p.x, -p.z, p.y)
}

/// A tetrahedron between halo4d's orientation and the files': the last two vertices swapped,
/// which converts both ways.
pub fn file_order(tet: [u32; 4]) -> [u32; 4] {
    [tet[0], tet[1], tet[3], tet[2]]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn c(p: DVec3) -> robust::Coord3D<f64> {
        robust::Coord3D {
            x: p.x,
            y: p.y,
            z: p.z,
        }
    }

    #[test]
    fn a_positive_tetrahedron_is_vtk_positive_in_file_order_in_either_frame() {
        let p = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
        let [a, b, c_, d] = p;
        // (0, x, y, z) has det[b - a, c - a, d - a] = 1: VTK-positive, orient3d-negative.
        assert!(robust::orient3d(c(a), c(b), c(c_), c(d)) < 0.0);
        let t = file_order([0, 1, 2, 3]).map(|i| p[i as usize]);
        assert!(robust::orient3d(c(t[0]), c(t[1]), c(t[2]), c(t[3])) > 0.0);
        assert_eq!(file_order(file_order([4, 5, 6, 7])), [4, 5, 6, 7]);
        // The change of frame is a rotation: it keeps every orientation.
        let g = p.map(to_gltf);
        assert_eq!(
            robust::orient3d(c(g[0]), c(g[1]), c(g[2]), c(g[3])),
            robust::orient3d(c(a), c(b), c(c_), c(d))
        );
        let q = DVec3::new(0.25, -1.5, 3.0);
        assert_eq!(from_gltf(to_gltf(q)), q);
        assert_eq!(to_gltf(DVec3::Z), DVec3::Y);
    }
}
