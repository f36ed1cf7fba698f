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
/// field `halo4d check --mark` writes). Each is declared once, below: its bit, its
/// documentation, its name and what it marks, from which [`Fault::ALL`], the `--mark`
/// legend ([`Fault::legend`]) and the README's table ([`Fault::table`]) are made.
pub struct Fault;

/// One fault bit: its value, its name and what a cell marked with it is (empty where the
/// name says it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FaultBit {
    /// The bit.
    pub bit: u32,
    /// Its name, as `--mark`'s legend and `halo4d check` give it.
    pub name: &'static str,
    /// What a cell marked with it is, where the name does not say it all.
    pub note: &'static str,
}

/// Declares the fault bits: each its constant (with its documentation), name and note.
macro_rules! faults {
    ($($(#[doc = $doc:literal])* $constant:ident = $bit:literal, $name:literal, $note:literal;)*) => {
        impl Fault {
            $($(#[doc = $doc])* pub const $constant: u32 = $bit;)*

            /// Every fault bit, in the order of the bits.
            pub const ALL: [FaultBit; [$($bit),*].len()] =
                [$(FaultBit { bit: $bit, name: $name, note: $note }),*];
        }
    };
}

faults! {
    /// Negatively oriented (in the convention the mesh is read in).
    INVERTED = 1, "inverted", "";
    /// Flat: zero volume, exactly.
    FLAT = 2, "flat", "";
    /// A coordinate too small, against the mesh's largest, for the exact predicates.
    UNDECIDABLE = 4, "undecidable", "a coordinate 1e80 times smaller than the largest";
    /// A vertex repeated.
    DEGENERATE = 8, "degenerate", "a vertex repeated";
    /// Listed more than once.
    DUPLICATE = 16, "duplicate", "";
    /// A face in more than two tetrahedra.
    OVERSHARED = 32, "overshared face", "in more than two tetrahedra";
    /// A face whose other tetrahedron lies on the same side of it.
    FOLDED = 64, "folded face", "";
    /// A boundary face with a vertex of another face on it.
    HANGING = 128, "hanging vertex", "the face it hangs on";
    /// A boundary face at a non-manifold or misoriented edge or vertex.
    NONMANIFOLD = 256, "non-manifold boundary", "or misoriented";
    /// A boundary face that meets another beyond what they share.
    SELF_INTERSECTION = 512, "self-intersecting boundary", "";
    /// A boundary face of a component whose winding number just inside is not 1.
    WINDING = 1024, "wrong winding", "every face of the component";
    /// A boundary face of a cavity (not a fault: reported).
    CAVITY = 2048, "cavity (not a fault)", "";
    /// A cell with a bent quadrilateral against two triangles of other cells (mixed meshes).
    NONCONFORMING = 4096, "non-conforming quadrilateral", "a mixed mesh's cell";
}

impl Fault {
    /// The bits as `--mark`'s help lists them: `1 inverted, 2 flat, ...`.
    pub fn legend() -> String {
        let bits: Vec<String> = Fault::ALL
            .iter()
            .map(|f| format!("{} {}", f.bit, f.name))
            .collect();
        bits.join(", ")
    }

    /// The bits as the README's table (Markdown), one row a bit.
    pub fn table() -> String {
        let mut out = String::from("| bit | fault |\n| --- | --- |\n");
        for f in Fault::ALL {
            let note = if f.note.is_empty() {
                String::new()
            } else {
                format!(" ({})", f.note)
            };
            out += &format!("| {} | {}{note} |\n", f.bit, f.name);
        }
        out
    }
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
        let mut out = self.stats.failures();
        let quads = self.cells.as_ref().map_or(0, |c| c.nonconforming_quads);
        for (name, count, what) in self.boundary.fault_counts().into_iter().chain([(
            "nonconforming_quads",
            quads,
            "bent quadrilaterals against two triangles of other cells",
        )]) {
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
