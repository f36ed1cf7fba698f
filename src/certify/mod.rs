//! A certified check of any tetrahedral mesh (TetGen's, Gmsh's, fTetWild's): is it a valid
//! tetrahedralization of the region its boundary encloses?
//!
//! Takes: vertex positions and tetrahedra in halo4d's orientation (the readers convert
//! every file's, `convention`). Gives: [`Certificate`]: the counts of
//! [`crate::check::check_tetrahedra`] (orientation, repeats, faces in more than two,
//! folded faces, the volume), the [`Boundary`] (components, cavities, non-manifold and
//! misoriented edges, non-manifold vertices, hanging vertices, self-intersections, the
//! winding number just inside each component), the cells' [`Quality`] (reported, not
//! judged) and each tetrahedron's faults ([`Fault`], for `halo4d check --mark`).
//! Guarantees: every decision is a sign of `robust::orient3d` or `orient2d`, unperturbed,
//! on the coordinates scaled as a whole by a power of two (exact at 1e150 as at 1e-150);
//! a mesh whose tetrahedra are all negative is read in the other convention and says so.
//!
//! Why passing proves the mesh valid: let every tetrahedron be positive, and every
//! interior face lie between exactly two tetrahedra on opposite sides of it (no face in
//! more than two, none folded). Then the number of tetrahedra covering a point changes only
//! across boundary faces, by one, as the boundary's winding number does, and both are 0
//! far away: every point is covered as many times as the boundary winds around it. A
//! boundary that does not meet itself, with winding number 1 just inside each of its
//! components, winds 0 or 1 times around every point (each region of space it leaves is
//! just inside or just outside one of them). So no point is covered twice: no two
//! tetrahedra overlap, and they fill exactly the region the boundary encloses. With no
//! hanging vertex, they meet face to face: a simplicial complex.
//!
//! The one construction is the point the winding number is taken at: the centroid of a
//! boundary face's tetrahedron, checked to lie strictly inside it, with no boundary face
//! between it and the face's centroid. The winding number there is exact.

mod boundary;
mod cells;
mod exact;
mod grid;
mod quality;

pub use boundary::Boundary;
pub use cells::{Cells, FaultyCell, Solid, SolidKind, certify_cells};
pub use grid::kuhn_cube;
pub use quality::{BINS, Bin, Cell, Quality, WORST};

use crate::check::{CheckStats, FaceFault, examine_tetrahedra};
use crate::convention::file_order;
use rayon::prelude::*;
use serde::Serialize;
use std::collections::HashMap;

/// The faults a tetrahedron can have, as bits of [`Certificate::faults`] (the `fault` cell
/// field `halo4d check --mark` writes).
pub struct Fault;

impl Fault {
    /// Negatively oriented (in the convention the mesh is read in).
    pub const INVERTED: u32 = 1;
    /// Flat: zero volume, exactly.
    pub const FLAT: u32 = 1 << 1;
    /// A coordinate too small, against the mesh's largest, for the exact predicates.
    pub const UNDECIDABLE: u32 = 1 << 2;
    /// A vertex repeated.
    pub const DEGENERATE: u32 = 1 << 3;
    /// Listed more than once.
    pub const DUPLICATE: u32 = 1 << 4;
    /// A face in more than two tetrahedra.
    pub const OVERSHARED: u32 = 1 << 5;
    /// A face whose other tetrahedron lies on the same side of it.
    pub const FOLDED: u32 = 1 << 6;
    /// A boundary face with a vertex of another face on it.
    pub const HANGING: u32 = 1 << 7;
    /// A boundary face at a non-manifold or misoriented edge or vertex.
    pub const NONMANIFOLD: u32 = 1 << 8;
    /// A boundary face that meets another beyond what they share.
    pub const SELF_INTERSECTION: u32 = 1 << 9;
    /// A boundary face of a component whose winding number just inside is not 1.
    pub const WINDING: u32 = 1 << 10;
    /// A boundary face of a cavity (not a fault: reported).
    pub const CAVITY: u32 = 1 << 11;
    /// A cell with a bent quadrilateral against two triangles of other cells (mixed meshes).
    pub const NONCONFORMING: u32 = 1 << 12;

    /// Every bit with its name, as `--mark`'s legend and the README give them.
    pub const NAMES: [(u32, &'static str); 13] = [
        (Self::INVERTED, "inverted"),
        (Self::FLAT, "flat"),
        (Self::UNDECIDABLE, "undecidable"),
        (Self::DEGENERATE, "degenerate"),
        (Self::DUPLICATE, "duplicate"),
        (Self::OVERSHARED, "overshared face"),
        (Self::FOLDED, "folded face"),
        (Self::HANGING, "hanging vertex"),
        (Self::NONMANIFOLD, "non-manifold boundary"),
        (Self::SELF_INTERSECTION, "self-intersecting boundary"),
        (Self::WINDING, "wrong winding"),
        (Self::CAVITY, "cavity (not a fault)"),
        (Self::NONCONFORMING, "non-conforming quadrilateral"),
    ];
}

/// The convention a mesh's tetrahedra were read in.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Convention {
    /// The file's own: positive tetrahedra.
    #[default]
    Positive,
    /// Every tetrahedron was negative in the file's convention: read in the other.
    Reversed,
}

/// What [`certify`] found.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Certificate {
    /// The counts of [`crate::check::check_tetrahedra`], in the convention read in.
    #[serde(skip)]
    pub stats: CheckStats,
    /// The convention the tetrahedra were read in.
    pub convention: Convention,
    /// The boundary.
    pub boundary: Boundary,
    /// The cells' shape.
    pub quality: Quality,
    /// Each tetrahedron's [`Fault`] bits.
    #[serde(skip)]
    pub faults: Vec<u32>,
    /// Each tetrahedron's smallest and largest dihedral angle (degrees) and radius ratio.
    #[serde(skip)]
    pub shapes: Vec<[f32; 3]>,
    /// For a mixed mesh (hexahedra, wedges, pyramids): its cells and quadrilaterals
    /// ([`certify_cells`]); the tetrahedra above are then those certified.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cells: Option<Cells>,
}

impl Certificate {
    /// Each cell's [`Fault`] bits: each tetrahedron's, and for a mixed mesh then each other
    /// cell's ([`Cells::faults`]).
    pub fn cell_faults(&self) -> &[u32] {
        self.cells.as_ref().map_or(&self.faults, |c| &c.faults)
    }

    /// What keeps the mesh from passing: [`CheckStats::failures`] (a mesh without
    /// tetrahedra among them), then each non-zero count of the boundary's faults as `<count> <name>`;
    /// empty when it passes.
    pub fn failures(&self) -> Vec<String> {
        let b = &self.boundary;
        let mut out = self.stats.failures();
        for (name, count, what) in [
            (
                "nonmanifold_edges",
                b.nonmanifold_edges,
                "edges in more than two boundary faces",
            ),
            (
                "misoriented_edges",
                b.misoriented_edges,
                "boundary edges whose faces face opposite ways",
            ),
            (
                "nonmanifold_vertices",
                b.nonmanifold_vertices,
                "boundary vertices where pieces touch",
            ),
            (
                "hanging_vertices",
                b.hanging_vertices,
                "vertices on a face or edge not their own",
            ),
            (
                "self_intersections",
                b.self_intersections,
                "pairs of boundary faces that meet",
            ),
            (
                "wrong_winding",
                b.wrong_winding,
                "boundary components around which the mesh does not wind once",
            ),
            (
                "undecided_windings",
                b.undecided_windings,
                "components whose winding number could not be decided",
            ),
            (
                "nonconforming_quads",
                self.cells.as_ref().map_or(0, |c| c.nonconforming_quads),
                "bent quadrilaterals against two triangles of other cells",
            ),
        ] {
            if count > 0 {
                out.push(format!("{count} {name} ({what})"));
            }
        }
        out
    }
}

/// Certifies tetrahedra (halo4d's orientation) on `positions` (see the module
/// documentation).
pub fn certify(positions: &[[f64; 3]], tets: &[[u32; 4]]) -> Certificate {
    let mut examined = examine_tetrahedra(positions, tets);
    let mut convention = Convention::Positive;
    let reversed: Vec<[u32; 4]>;
    let mut tets = tets;
    if examined.stats.inverted > 0 && !examined.orientation.contains(&1) {
        reversed = tets.par_iter().map(|&t| file_order(t)).collect();
        tets = &reversed;
        examined = examine_tetrahedra(positions, tets);
        convention = Convention::Reversed;
    }
    let (boundary, face_marks) = boundary::judge(
        &examined.boundary,
        &examined.scaled,
        examined.centre,
        &examined.tiny,
    );
    let (quality, shapes) = quality::quality(&examined.scaled, tets);

    // Each tetrahedron's own faults, then those of its faces.
    let mut faults: Vec<u32> = tets
        .par_iter()
        .zip(&examined.orientation)
        .map(|(t, &o)| {
            let distinct = (0..4).all(|i| (i + 1..4).all(|j| t[i] != t[j]));
            if !distinct {
                Fault::DEGENERATE
            } else if t.iter().any(|&i| examined.tiny[i as usize]) {
                Fault::UNDECIDABLE
            } else if o < 0 {
                Fault::INVERTED
            } else if o == 0 {
                Fault::FLAT
            } else {
                0
            }
        })
        .collect();
    let mut by_face: HashMap<[u32; 3], u32> = HashMap::new();
    for fault in &examined.face_faults {
        let (k, bit) = match *fault {
            FaceFault::Overshared(k) => (k, Fault::OVERSHARED),
            FaceFault::Folded(k) => (k, Fault::FOLDED),
        };
        *by_face.entry(k).or_default() |= bit;
    }
    for (&(k, _), &bits) in examined.boundary.iter().zip(&face_marks) {
        if bits != 0 {
            *by_face.entry(k).or_default() |= bits;
        }
    }
    if !by_face.is_empty() {
        faults.par_iter_mut().zip(tets).for_each(|(bits, t)| {
            for skip in 0..4 {
                let mut k = [0u32; 3];
                let mut n = 0;
                for (i, &v) in t.iter().enumerate() {
                    if i != skip {
                        k[n] = v;
                        n += 1;
                    }
                }
                k.sort_unstable();
                if let Some(b) = by_face.get(&k) {
                    *bits |= b;
                }
            }
        });
    }
    if examined.stats.duplicate_tets > 0 {
        let mut seen: HashMap<[u32; 4], usize> = HashMap::new();
        let key = |t: &[u32; 4]| {
            let mut s = *t;
            s.sort_unstable();
            s
        };
        for t in tets {
            *seen.entry(key(t)).or_default() += 1;
        }
        for (bits, t) in faults.iter_mut().zip(tets) {
            if seen[&key(t)] > 1 {
                *bits |= Fault::DUPLICATE;
            }
        }
    }
    Certificate {
        stats: examined.stats,
        convention,
        boundary,
        quality,
        faults,
        shapes,
        cells: None,
    }
}
