//! The independent checker of halo tetrahedra. It shares no code with the builder
//! ([`crate::tets`]): it reads only vertex positions, the vertex layout and the tetrahedra,
//! and decides with exact predicates.
//!
//! Layout (the same in memory, in `.glb` and in `.vtk`): for a surface of n vertices, vertex
//! i < n is the negative offset (t = 0) of surface vertex i, vertex n + i its positive offset
//! (t = 1), and vertices from 2n on are inserted inside prisms.
//!
//! What it checks, each as its own count:
//! - every tetrahedron positively oriented under exact `robust::orient3d` (`inverted`, `flat`),
//!   with four distinct vertices (`degenerate`) and no repeat (`duplicate_tets`);
//! - every face in one or two tetrahedra (`overshared_faces`);
//! - no quad between two prisms split differently from its two sides (`quad_mismatches`);
//! - the boundary is exactly the two offset surfaces plus the side walls over the surface's
//!   open edges (`missing_offset_faces`, `unexpected_boundary_faces`);
//! - the tetrahedra's volumes add up to the volume the boundary encloses (`volume_defect`).

use serde::Serialize;
use std::collections::HashMap;

/// A tetrahedral mesh in the halo layout.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TetMesh {
    /// Vertex positions.
    pub positions: Vec<[f64; 3]>,
    /// Surface vertices n: the first 2n vertices are the two offsets.
    pub surface_vertices: usize,
    /// Four vertex indices each.
    pub tets: Vec<[u32; 4]>,
}

/// What the checker found.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct CheckStats {
    /// Vertices.
    pub vertices: usize,
    /// Tetrahedra.
    pub tets: usize,
    /// Tetrahedra with negative orientation.
    pub inverted: usize,
    /// Tetrahedra with zero volume (exactly).
    pub flat: usize,
    /// Tetrahedra repeating a vertex or naming one that does not exist.
    pub degenerate: usize,
    /// Tetrahedra listed more than once.
    pub duplicate_tets: usize,
    /// Faces in more than two tetrahedra.
    pub overshared_faces: usize,
    /// Quads between two prisms whose sides are split differently.
    pub quad_mismatches: usize,
    /// Offset-surface triangles whose partner on the other offset is not on the boundary.
    pub missing_offset_faces: usize,
    /// Boundary faces that are neither offset triangles nor side walls over an open edge.
    pub unexpected_boundary_faces: usize,
    /// Faces in exactly one tetrahedron.
    pub boundary_faces: usize,
    /// Faces in exactly two tetrahedra.
    pub interior_faces: usize,
    /// Sum of the tetrahedra's absolute volumes.
    pub volume: f64,
    /// Volume enclosed by the boundary faces.
    pub boundary_volume: f64,
    /// |volume - boundary_volume| / boundary_volume.
    pub volume_defect: f64,
    /// Smallest tetrahedron volume (signed).
    pub min_volume: f64,
    /// Largest tetrahedron volume.
    pub max_volume: f64,
    /// Smallest dihedral angle of any tetrahedron, in degrees.
    pub min_dihedral_deg: f64,
}

impl CheckStats {
    /// Whether the mesh conforms: no mismatched, missing, extra, repeated or overshared face.
    pub fn conforms(&self) -> bool {
        self.degenerate == 0
            && self.duplicate_tets == 0
            && self.overshared_faces == 0
            && self.quad_mismatches == 0
            && self.missing_offset_faces == 0
            && self.unexpected_boundary_faces == 0
    }

    /// Whether the mesh conforms, every tetrahedron is positive, and the tetrahedra fill
    /// exactly the volume the boundary encloses (no overlap).
    pub fn valid(&self) -> bool {
        self.conforms() && self.inverted == 0 && self.flat == 0 && self.volume_defect <= 1e-9
    }
}

fn c3(p: [f64; 3]) -> robust::Coord3D<f64> {
    robust::Coord3D {
        x: p[0],
        y: p[1],
        z: p[2],
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Volume of a tetrahedron, positive when `orient3d` is.
fn volume(p: [[f64; 3]; 4]) -> f64 {
    -dot(cross(sub(p[1], p[0]), sub(p[2], p[0])), sub(p[3], p[0])) / 6.0
}

/// Smallest dihedral angle in degrees (0 for a flat tetrahedron).
fn min_dihedral_deg(p: [[f64; 3]; 4]) -> f64 {
    let mut normals = [[0.0; 3]; 4];
    for (i, n) in normals.iter_mut().enumerate() {
        let f: Vec<[f64; 3]> = (0..4).filter(|&k| k != i).map(|k| p[k]).collect();
        let m = cross(sub(f[1], f[0]), sub(f[2], f[0]));
        let len = dot(m, m).sqrt();
        if len == 0.0 || !len.is_finite() {
            return 0.0;
        }
        let m = m.map(|x| x / len);
        // Outward: away from the vertex opposite the face.
        *n = if dot(m, sub(p[i], f[0])) > 0.0 {
            m.map(|x| -x)
        } else {
            m
        };
    }
    let mut min = 180.0f64;
    for i in 0..4 {
        for j in i + 1..4 {
            let c = dot(normals[i], normals[j]).clamp(-1.0, 1.0);
            min = min.min(180.0 - c.acos().to_degrees());
        }
    }
    min
}

/// A face as its sorted vertex triple.
fn key(mut f: [u32; 3]) -> [u32; 3] {
    f.sort_unstable();
    f
}

/// Checks a tetrahedral halo (see the module documentation).
pub fn check(mesh: &TetMesh) -> CheckStats {
    let n = mesh.surface_vertices as u32;
    let nv = mesh.positions.len();
    let mut s = CheckStats {
        vertices: nv,
        tets: mesh.tets.len(),
        min_volume: f64::INFINITY,
        max_volume: f64::NEG_INFINITY,
        min_dihedral_deg: 180.0,
        ..CheckStats::default()
    };
    // Faces with their uses: (count, one outward orientation).
    let mut faces: HashMap<[u32; 3], (u32, [u32; 3])> = HashMap::new();
    let mut seen = std::collections::HashSet::new();
    for tet in &mesh.tets {
        let mut sorted = *tet;
        sorted.sort_unstable();
        let distinct = sorted.windows(2).all(|w| w[0] != w[1]);
        if !distinct || tet.iter().any(|&i| i as usize >= nv) {
            s.degenerate += 1;
            continue;
        }
        if !seen.insert(sorted) {
            s.duplicate_tets += 1;
        }
        let p = tet.map(|i| mesh.positions[i as usize]);
        let o = robust::orient3d(c3(p[0]), c3(p[1]), c3(p[2]), c3(p[3]));
        if o < 0.0 {
            s.inverted += 1;
        } else if o == 0.0 {
            s.flat += 1;
        }
        let v = volume(p);
        s.volume += v.abs();
        s.min_volume = s.min_volume.min(v);
        s.max_volume = s.max_volume.max(v);
        s.min_dihedral_deg = s.min_dihedral_deg.min(min_dihedral_deg(p));
        // Outward faces of a positive tetrahedron (a, b, c, d): the face opposite each
        // vertex, ordered so that the opposite vertex lies below it.
        let [a, b, c, d] = *tet;
        for f in [[b, c, d], [a, d, c], [a, b, d], [a, c, b]] {
            let f = if o < 0.0 { [f[0], f[2], f[1]] } else { f };
            let e = faces.entry(key(f)).or_insert((0, f));
            e.0 += 1;
        }
    }
    if mesh.tets.is_empty() {
        s.min_volume = 0.0;
        s.max_volume = 0.0;
        s.min_dihedral_deg = 0.0;
    }

    let is_boundary = |f: &[u32; 3]| faces.get(&key(*f)).is_some_and(|e| e.0 == 1);
    let layer = |i: u32| {
        if i < n {
            Some(0)
        } else if i < 2 * n {
            Some(1)
        } else {
            None
        }
    };
    // The surface's triangles: bottom faces of prisms, i.e. faces with every vertex on the
    // negative offset. Their edges tell the open boundary of the surface.
    let bottoms: Vec<[u32; 3]> = faces
        .keys()
        .filter(|f| f.iter().all(|&i| layer(i) == Some(0)))
        .copied()
        .collect();
    let mut edge_uses: HashMap<[u32; 2], u32> = HashMap::new();
    for f in &bottoms {
        for (x, y) in [(f[0], f[1]), (f[1], f[2]), (f[0], f[2])] {
            *edge_uses.entry([x.min(y), x.max(y)]).or_default() += 1;
        }
    }
    for f in &bottoms {
        let top = f.map(|i| i + n);
        if !is_boundary(f) || !is_boundary(&top) {
            s.missing_offset_faces += 1;
        }
    }
    // Quads over surface edges: their two triangles, for each diagonal.
    let quad_faces = |[x, y]: [u32; 2]| {
        [
            [[x, y, y + n], [x, y + n, x + n]],
            [[x, y, x + n], [y, y + n, x + n]],
        ]
    };
    let mut side_walls = std::collections::HashSet::new();
    for (&edge, &uses) in &edge_uses {
        let [d1, d2] = quad_faces(edge);
        let count = |f: &[u32; 3]| faces.get(&key(*f)).map_or(0, |e| e.0);
        if uses == 1 {
            // An open edge: its quad is a side wall, on the boundary, split one way.
            let one = d1.iter().all(|f| count(f) == 1) && d2.iter().all(|f| count(f) == 0);
            let other = d2.iter().all(|f| count(f) == 1) && d1.iter().all(|f| count(f) == 0);
            if !(one || other) {
                s.quad_mismatches += 1;
            }
            for f in d1.iter().chain(&d2) {
                side_walls.insert(key(*f));
            }
        } else {
            // Between prisms: one diagonal, each of its triangles shared by two tetrahedra.
            let one = d1.iter().all(|f| count(f) == 2) && d2.iter().all(|f| count(f) == 0);
            let other = d2.iter().all(|f| count(f) == 2) && d1.iter().all(|f| count(f) == 0);
            if !(one || other) {
                s.quad_mismatches += 1;
            }
        }
    }
    let mut boundary_volume = 0.0;
    for (k, (count, f)) in &faces {
        match count {
            1 => {
                s.boundary_faces += 1;
                let offset = k.iter().all(|&i| layer(i) == Some(0))
                    || k.iter().all(|&i| layer(i) == Some(1));
                if !offset && !side_walls.contains(k) {
                    s.unexpected_boundary_faces += 1;
                }
                let [a, b, c] = f.map(|i| mesh.positions[i as usize]);
                // Outward faces whose vertices turn clockwise seen from outside (the
                // orientation convention above): the divergence theorem with a sign.
                boundary_volume -= dot(a, cross(b, c)) / 6.0;
            }
            2 => s.interior_faces += 1,
            _ => s.overshared_faces += 1,
        }
    }
    s.boundary_volume = boundary_volume;
    s.volume_defect = if boundary_volume.abs() > 0.0 {
        (s.volume - boundary_volume).abs() / boundary_volume.abs()
    } else if s.volume == 0.0 {
        0.0
    } else {
        f64::INFINITY
    };
    s
}
