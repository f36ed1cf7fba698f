//! Mixed meshes: hexahedra, wedges and pyramids certified through the tetrahedra they are
//! split into, beside the mesh's own tetrahedra.
//!
//! Takes: positions, tetrahedra (halo4d's orientation) and [`Solid`]s (VTK's corner order).
//! Gives: a [`Certificate`] of the tetrahedra and the split cells, with [`Cells`]: the
//! counts of each kind, the quadrilateral faces (planar or not, their warp, those that
//! cannot conform) and each cell's faults.
//!
//! The split, and what passing proves for each kind of cell:
//! - Each quadrilateral face is split into two triangles along one diagonal: the one along
//!   which two triangles of other cells (tetrahedra, pyramids' sides, wedges' ends) lie
//!   against it, where they do; else the diagonal through its smallest vertex index, which
//!   the cell on its other side, seeing the same four vertices, chooses alike.
//! - A pyramid becomes the two tetrahedra of its base's triangles and its apex; a
//!   hexahedron (12) and a wedge (8) the tetrahedra of their faces' triangles and the mean
//!   of their corners (a new vertex, constructed once; every decision about it is exact).
//! - These tetrahedra are certified with the mesh's own ([`certify`]). Passing proves: each
//!   cell is a polyhedron (its quadrilaterals bent along the chosen diagonals) that is
//!   star-shaped from a point inside it, so embedded and positively oriented; the cells
//!   meet face to face and fill the region their boundary encloses without overlapping.
//! - A quadrilateral between two cells that both have it as a face is split alike on both
//!   sides: they conform whatever its warp. A quadrilateral against two triangles of other
//!   cells conforms only where it is planar (its corners' `orient3d` exactly 0): bent, it is
//!   a surface the triangles do not follow in the cell's own (bilinear) form, and is
//!   reported as a [`Fault::NONCONFORMING`] quadrilateral.
//! - Non-planar quadrilaterals are counted, with the largest warp (the angle between the
//!   normals of the two triangles of a split, the larger of the two splits). The bilinear
//!   faces a finite element gives a bent quadrilateral are not certified beyond this.

use super::exact::orient;
use super::{Certificate, Fault, certify};
use crate::check::scaled;
use crate::convention::file_order;
use rayon::prelude::*;
use serde::Serialize;

/// A kind of solid cell other than a tetrahedron that a mixed mesh may have.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SolidKind {
    /// Eight corners: the quadrilateral 0 1 2 3, its normal (right-hand rule) towards the
    /// opposite one 4 5 6 7, corner i + 4 above corner i.
    Hexahedron,
    /// Six corners: the triangle 0 1 2, its normal away from the opposite one 3 4 5, corner
    /// i + 3 above corner i.
    Wedge,
    /// Five corners: the quadrilateral 0 1 2 3, its normal towards the apex 4.
    Pyramid,
}

impl SolidKind {
    /// How many corners.
    pub fn corners(self) -> usize {
        match self {
            SolidKind::Hexahedron => 8,
            SolidKind::Wedge => 6,
            SolidKind::Pyramid => 5,
        }
    }

    /// The name, singular.
    pub fn name(self) -> &'static str {
        match self {
            SolidKind::Hexahedron => "hexahedron",
            SolidKind::Wedge => "wedge",
            SolidKind::Pyramid => "pyramid",
        }
    }

    /// The name, plural.
    pub fn plural(self) -> &'static str {
        match self {
            SolidKind::Hexahedron => "hexahedra",
            SolidKind::Wedge => "wedges",
            SolidKind::Pyramid => "pyramids",
        }
    }

    /// VTK's number for the linear cell of this kind.
    pub fn vtk_type(self) -> u8 {
        match self {
            SolidKind::Hexahedron => 12,
            SolidKind::Wedge => 13,
            SolidKind::Pyramid => 14,
        }
    }
}

/// A hexahedron, wedge or pyramid of a mixed mesh: its corners in VTK's order (the readers
/// convert Gmsh's prisms and VTK's voxels; a quadratic cell's corners, its other nodes
/// left out).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Solid {
    /// Which kind.
    pub kind: SolidKind,
    /// The corners, the first [`SolidKind::corners`] of them used (the rest 0).
    pub corners: [u32; 8],
    /// The cell's number in the file: its VTK cell id (counting every cell from 0), or its
    /// Gmsh element tag.
    pub id: u64,
}

impl Solid {
    /// The corners used.
    pub fn used(&self) -> &[u32] {
        &self.corners[..self.kind.corners()]
    }
}

/// A hexahedron's quadrilaterals, each turning counterclockwise seen from outside.
const HEX_QUADS: [[usize; 4]; 6] = [
    [0, 3, 2, 1],
    [4, 5, 6, 7],
    [0, 1, 5, 4],
    [1, 2, 6, 5],
    [2, 3, 7, 6],
    [3, 0, 4, 7],
];
/// A wedge's quadrilaterals and triangles, counterclockwise seen from outside.
const WEDGE_QUADS: [[usize; 4]; 3] = [[0, 3, 4, 1], [1, 4, 5, 2], [2, 5, 3, 0]];
const WEDGE_TRIANGLES: [[usize; 3]; 2] = [[0, 1, 2], [3, 5, 4]];
/// A pyramid's base and sides, counterclockwise seen from outside.
const PYRAMID_QUADS: [[usize; 4]; 1] = [[0, 3, 2, 1]];
const PYRAMID_TRIANGLES: [[usize; 3]; 4] = [[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]];

fn quads(kind: SolidKind) -> &'static [[usize; 4]] {
    match kind {
        SolidKind::Hexahedron => &HEX_QUADS,
        SolidKind::Wedge => &WEDGE_QUADS,
        SolidKind::Pyramid => &PYRAMID_QUADS,
    }
}

fn triangles(kind: SolidKind) -> &'static [[usize; 3]] {
    match kind {
        SolidKind::Hexahedron => &[],
        SolidKind::Wedge => &WEDGE_TRIANGLES,
        SolidKind::Pyramid => &PYRAMID_TRIANGLES,
    }
}

/// How many faulty cells [`Cells::faulty`] names.
const NAMED: usize = 10;

/// A mixed mesh's cells and quadrilaterals ([`Certificate::cells`]).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Cells {
    /// The mesh's own tetrahedra.
    pub tetrahedra: usize,
    /// Its hexahedra.
    pub hexahedra: usize,
    /// Its wedges (prisms).
    pub wedges: usize,
    /// Its pyramids.
    pub pyramids: usize,
    /// The tetrahedra certified: the mesh's own, then those of each other cell in turn.
    pub certified_tetrahedra: usize,
    /// The distinct quadrilateral faces.
    pub quads: usize,
    /// Those whose corners do not lie in one plane (exactly).
    pub nonplanar_quads: usize,
    /// The largest warp of a quadrilateral, in degrees (0 when all are planar).
    pub max_warp_deg: f64,
    /// Non-planar quadrilaterals against two triangles of other cells ([`Fault::NONCONFORMING`]).
    pub nonconforming_quads: usize,
    /// Quadrilaterals with a corner too small, against the mesh's largest coordinate, for
    /// their planarity to be decided exactly: counted neither planar nor not.
    pub undecided_quads: usize,
    /// Up to ten cells with a fault, in the order of the mesh (its tetrahedra first).
    pub faulty: Vec<FaultyCell>,
    /// How many cells have a fault (a cavity's face not counted).
    pub faulty_cells: usize,
    /// Each cell's [`Fault`] bits: the tetrahedra's, then each other cell's (those of all
    /// the tetrahedra it is split into).
    #[serde(skip)]
    pub faults: Vec<u32>,
    /// Where each other cell's tetrahedra begin among the certified ones, and after the
    /// last, where they end.
    #[serde(skip)]
    pub first_tet: Vec<usize>,
    /// The other cells' kinds and numbers in the file, in order.
    #[serde(skip)]
    pub solids: Vec<(SolidKind, u64)>,
}

/// A cell with a fault, as [`Cells::faulty`] names it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FaultyCell {
    /// `tetrahedron`, `hexahedron`, `wedge` or `pyramid`.
    pub kind: &'static str,
    /// Its number: a tetrahedron's index among the tetrahedra, another cell's number in
    /// the file (VTK's cell id, Gmsh's element tag).
    pub id: u64,
    /// Its faults' names ([`Fault::ALL`]).
    pub faults: Vec<&'static str>,
}

impl Cells {
    /// The cell a certified tetrahedron belongs to: its kind and number ([`FaultyCell`]).
    pub fn cell_of(&self, tet: usize) -> (&'static str, u64) {
        if tet < self.tetrahedra {
            return ("tetrahedron", tet as u64);
        }
        let j = self.first_tet.partition_point(|&f| f <= tet) - 1;
        let (kind, id) = self.solids[j];
        (kind.name(), id)
    }
}

/// A quadrilateral face of a cell: its sorted corners, the cell, which face of it.
type QuadUse = ([u32; 4], u32, u8);

/// How a quadrilateral is split, and whether it conforms.
#[derive(Clone, Copy)]
struct Split {
    /// The diagonal it is split along: its two corners, the smaller first.
    diagonal: [u32; 2],
    /// Bent (exactly) and against two triangles of other cells.
    nonconforming: bool,
}

/// Certifies tetrahedra (halo4d's orientation) and other solid cells on `positions` (see
/// the module documentation); without other cells, [`certify`] itself.
pub fn certify_cells(positions: &[[f64; 3]], tets: &[[u32; 4]], solids: &[Solid]) -> Certificate {
    if solids.is_empty() {
        return certify(positions, tets);
    }
    // Every quadrilateral face of every cell, sorted so that a face's uses are together.
    let mut uses: Vec<QuadUse> = solids
        .par_iter()
        .enumerate()
        .flat_map_iter(|(j, s)| {
            quads(s.kind).iter().enumerate().map(move |(f, q)| {
                let mut key = q.map(|i| s.corners[i]);
                key.sort_unstable();
                (key, j as u32, f as u8)
            })
        })
        .collect();
    uses.par_sort_unstable();
    let corners = |j: u32, f: u8| {
        let s = &solids[j as usize];
        quads(s.kind)[f as usize].map(|i| s.corners[i])
    };
    let present = triangles_against(tets, solids, &uses, corners);
    let has = |k: [u32; 3]| present.binary_search(&k).is_ok();

    // Each distinct quadrilateral's split: along the diagonal of the triangles against it,
    // else through its smallest corner.
    let groups: Vec<&[QuadUse]> = uses.chunk_by(|a, b| a.0 == b.0).collect();
    let mut judged: Vec<(Split, Option<bool>, f64)> = groups
        .par_iter()
        .map(|g| {
            let (_, j, f) = g[0];
            let q = corners(j, f);
            let h = halves(q);
            let (ac, bd) = (has(h[0]) && has(h[1]), has(h[2]) && has(h[3]));
            let least = *q.iter().min().expect("four corners");
            let along_ac = if ac || bd {
                ac
            } else {
                least == q[0] || least == q[2]
            };
            let (u, v) = if along_ac { (q[0], q[2]) } else { (q[1], q[3]) };
            let split = Split {
                diagonal: [u.min(v), u.max(v)],
                nonconforming: ac || bd,
            };
            (split, None, 0.0)
        })
        .collect();
    // Each cell's faces' diagonals, by the cell and face.
    let mut first_quad = Vec::with_capacity(solids.len() + 1);
    let mut n = 0;
    for s in solids {
        first_quad.push(n);
        n += quads(s.kind).len();
    }
    first_quad.push(n);
    let mut diagonals = vec![[0u32; 2]; n];
    for (g, (split, _, _)) in groups.iter().zip(&judged) {
        for &(_, j, f) in *g {
            diagonals[first_quad[j as usize] + f as usize] = split.diagonal;
        }
    }
    let (all_positions, all_tets, first_tet) =
        split_into_tetrahedra(positions, tets, solids, |j, f| diagonals[first_quad[j] + f]);

    // Each quadrilateral's planarity, exactly, on the coordinates the certificate decides
    // on; its warp where bent; against triangles and bent, it cannot conform.
    let scaled = scaled(&all_positions, &all_tets);
    groups
        .par_iter()
        .zip(&mut judged)
        .for_each(|(g, (split, planar, w))| {
            let (_, j, f) = g[0];
            let q = corners(j, f);
            let at = |i: u32| scaled.positions[i as usize];
            *planar = (!q.iter().any(|&i| scaled.tiny[i as usize]))
                .then(|| orient(at(q[0]), at(q[1]), at(q[2]), at(q[3])) == 0);
            if *planar == Some(false) {
                *w = warp(q.map(|i| positions[i as usize]));
            }
            split.nonconforming &= *planar != Some(true);
        });
    drop(scaled);
    let mut nonconforming = vec![false; solids.len()];
    for (g, (split, _, _)) in groups.iter().zip(&judged) {
        if split.nonconforming {
            g.iter()
                .for_each(|&(_, j, _)| nonconforming[j as usize] = true);
        }
    }
    let mut certificate = certify(&all_positions, &all_tets);

    // Each cell's faults: its tetrahedra's, and a quadrilateral that cannot conform.
    let nt = tets.len();
    let mut faults = certificate.faults[..nt].to_vec();
    for (j, w) in first_tet.windows(2).enumerate() {
        let mut bits = certificate.faults[w[0]..w[1]].iter().fold(0, |a, &b| a | b);
        if nonconforming[j] {
            bits |= Fault::NONCONFORMING;
            certificate.faults[w[0]..w[1]]
                .iter_mut()
                .for_each(|b| *b |= Fault::NONCONFORMING);
        }
        faults.push(bits);
    }
    let count = |kind| solids.iter().filter(|s| s.kind == kind).count();
    let solid_ids: Vec<(SolidKind, u64)> = solids.iter().map(|s| (s.kind, s.id)).collect();
    let faulty_bits = |b: u32| b & !Fault::CAVITY != 0;
    let faulty = faulty_cells(&faults, nt, &solid_ids);
    certificate.cells = Some(Cells {
        tetrahedra: nt,
        hexahedra: count(SolidKind::Hexahedron),
        wedges: count(SolidKind::Wedge),
        pyramids: count(SolidKind::Pyramid),
        certified_tetrahedra: all_tets.len(),
        quads: groups.len(),
        nonplanar_quads: judged.iter().filter(|j| j.1 == Some(false)).count(),
        max_warp_deg: judged.iter().map(|j| j.2).fold(0.0, f64::max),
        nonconforming_quads: judged.iter().filter(|j| j.0.nonconforming).count(),
        undecided_quads: judged.iter().filter(|j| j.1.is_none()).count(),
        faulty,
        faulty_cells: faults.iter().filter(|&&b| faulty_bits(b)).count(),
        faults,
        first_tet,
        solids: solid_ids,
    });
    certificate
}

/// The triangles of other cells (the tetrahedra's faces, the pyramids' sides, the wedges'
/// ends) that lie against a quadrilateral of `uses` along one of its diagonals, sorted.
fn triangles_against(
    tets: &[[u32; 4]],
    solids: &[Solid],
    uses: &[QuadUse],
    corners: impl Fn(u32, u8) -> [u32; 4] + Sync,
) -> Vec<[u32; 3]> {
    let mut wanted: Vec<[u32; 3]> = uses
        .par_iter()
        .flat_map_iter(|&(_, j, f)| halves(corners(j, f)))
        .collect();
    wanted.par_sort_unstable();
    wanted.dedup();
    let fixed = tets
        .par_iter()
        .flat_map_iter(|t| {
            [
                [t[0], t[1], t[2]],
                [t[0], t[1], t[3]],
                [t[0], t[2], t[3]],
                [t[1], t[2], t[3]],
            ]
        })
        .chain(
            solids
                .par_iter()
                .flat_map_iter(|s| triangles(s.kind).iter().map(|t| t.map(|i| s.corners[i]))),
        )
        .map(sorted3)
        .filter(|k| wanted.binary_search(k).is_ok());
    let mut present: Vec<[u32; 3]> = fixed.collect();
    present.par_sort_unstable();
    present.dedup();
    present
}

/// A quadrilateral's triangles split along its diagonal from its first corner, then from its
/// second, each sorted.
fn halves([a, b, c, d]: [u32; 4]) -> [[u32; 3]; 4] {
    [[a, b, c], [a, c, d], [a, b, d], [b, c, d]].map(sorted3)
}

/// The mesh's positions and tetrahedra with each cell's after them (its quadrilateral `f`
/// split along `diagonal(j, f)` for cell j; a hexahedron's and a wedge's apex, the mean of
/// their corners, a new vertex), and where each cell's tetrahedra begin (and the last end).
fn split_into_tetrahedra(
    positions: &[[f64; 3]],
    tets: &[[u32; 4]],
    solids: &[Solid],
    diagonal: impl Fn(usize, usize) -> [u32; 2],
) -> (Vec<[f64; 3]>, Vec<[u32; 4]>, Vec<usize>) {
    // The tetrahedra: the mesh's, then each cell's.
    let mut all_positions = positions.to_vec();
    let mut all_tets = tets.to_vec();
    let mut first_tet = Vec::with_capacity(solids.len() + 1);
    for (j, s) in solids.iter().enumerate() {
        first_tet.push(all_tets.len());
        let c = |i: usize| s.corners[i];
        let apex = match s.kind {
            SolidKind::Pyramid => c(4),
            SolidKind::Hexahedron | SolidKind::Wedge => {
                // Each corner divided first: no sum overflows.
                let k = s.kind.corners() as f64;
                let mean = s.used().iter().fold([0.0; 3], |m, &i| {
                    let p = positions[i as usize];
                    [0, 1, 2].map(|a| m[a] + p[a] / k)
                });
                all_positions.push(mean);
                (all_positions.len() - 1) as u32
            }
        };
        // Each outward triangle (a, b, c) with the apex inside: (a, c, b, apex) is positive
        // in the files' convention.
        let mut cone = |[a, b, c]: [u32; 3]| all_tets.push(file_order([a, c, b, apex]));
        for (f, q) in quads(s.kind).iter().enumerate() {
            let [a, b, cc, d] = q.map(c);
            if diagonal(j, f) == [a.min(cc), a.max(cc)] {
                cone([a, b, cc]);
                cone([a, cc, d]);
            } else {
                cone([a, b, d]);
                cone([b, cc, d]);
            }
        }
        if s.kind == SolidKind::Wedge {
            for t in &WEDGE_TRIANGLES {
                cone(t.map(c));
            }
        }
    }
    first_tet.push(all_tets.len());
    (all_positions, all_tets, first_tet)
}

/// Up to [`NAMED`] cells with a fault, in the order of `faults` (the `nt` tetrahedra, then
/// the cells of `solids`), with their faults' names.
fn faulty_cells(faults: &[u32], nt: usize, solids: &[(SolidKind, u64)]) -> Vec<FaultyCell> {
    faults
        .iter()
        .enumerate()
        .filter(|(_, b)| **b & !Fault::CAVITY != 0)
        .take(NAMED)
        .map(|(k, &b)| {
            let (kind, id) = if k < nt {
                ("tetrahedron", k as u64)
            } else {
                let (kind, id) = solids[k - nt];
                (kind.name(), id)
            };
            FaultyCell {
                kind,
                id,
                faults: Fault::ALL
                    .iter()
                    .filter(|f| b & f.bit != 0 && f.bit != Fault::CAVITY)
                    .map(|f| f.name)
                    .collect(),
            }
        })
        .collect()
}

fn sorted3(mut k: [u32; 3]) -> [u32; 3] {
    k.sort_unstable();
    k
}

/// A bent quadrilateral's warp, in degrees: the angle between the normals of the two
/// triangles of a split along a diagonal, the larger of the two splits (taken from its
/// first corner, so that it does not cancel wherever it stands).
fn warp(q: [[f64; 3]; 4]) -> f64 {
    let v = |i: usize| glam::DVec3::from(q[i]) - glam::DVec3::from(q[0]);
    let (a, b, c, d) = (glam::DVec3::ZERO, v(1), v(2), v(3));
    let angle = |n: glam::DVec3, m: glam::DVec3| {
        let (n, m) = (n.normalize_or_zero(), m.normalize_or_zero());
        if n == glam::DVec3::ZERO || m == glam::DVec3::ZERO {
            0.0
        } else {
            n.dot(m).clamp(-1.0, 1.0).acos().to_degrees()
        }
    };
    let ac = angle((b - a).cross(c - a), (c - a).cross(d - a));
    let bd = angle((b - a).cross(d - a), (c - b).cross(d - b));
    ac.max(bd)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit cube's corners in VTK's hexahedron order, moved by `at`.
    fn cube(at: [f64; 3]) -> Vec<[f64; 3]> {
        [
            [0., 0., 0.],
            [1., 0., 0.],
            [1., 1., 0.],
            [0., 1., 0.],
            [0., 0., 1.],
            [1., 0., 1.],
            [1., 1., 1.],
            [0., 1., 1.],
        ]
        .map(|p| [p[0] + at[0], p[1] + at[1], p[2] + at[2]])
        .to_vec()
    }

    fn hex(corners: [u32; 8], id: u64) -> Solid {
        Solid {
            kind: SolidKind::Hexahedron,
            corners,
            id,
        }
    }

    #[test]
    fn a_cube_is_twelve_positive_tetrahedra_of_volume_one() {
        let c = certify_cells(&cube([0.0; 3]), &[], &[hex([0, 1, 2, 3, 4, 5, 6, 7], 0)]);
        assert!(c.failures().is_empty(), "{:?}", c.failures());
        let cells = c.cells.expect("mixed");
        assert_eq!(cells.certified_tetrahedra, 12);
        assert_eq!((cells.quads, cells.nonplanar_quads), (6, 0));
        assert!((c.stats.volume - 1.0).abs() < 1e-12);
    }

    #[test]
    fn a_mirrored_hexahedron_is_read_in_the_other_convention_and_a_lone_one_is_inverted() {
        let mirrored = hex([0, 3, 2, 1, 4, 7, 6, 5], 0);
        let c = certify_cells(&cube([0.0; 3]), &[], &[mirrored]);
        assert_eq!(c.convention, super::super::Convention::Reversed);
        // Beside a positive cube, the mirrored one is inverted.
        let mut p = cube([0.0; 3]);
        p.extend(cube([2.0, 0.0, 0.0]));
        let c = certify_cells(
            &p,
            &[],
            &[
                hex([0, 1, 2, 3, 4, 5, 6, 7], 7),
                hex([8, 11, 10, 9, 12, 15, 14, 13], 9),
            ],
        );
        let cells = c.cells.expect("mixed");
        assert_eq!(cells.faulty_cells, 1);
        assert_eq!(
            (cells.faulty[0].kind, cells.faulty[0].id),
            ("hexahedron", 9)
        );
        assert!(cells.faulty[0].faults.contains(&"inverted"));
    }

    /// Two cubes side by side sharing the face x = 1, bent by moving its corner (1, 1, 1) by
    /// `lift` in x; the second cube a hexahedron (`None`) or six tetrahedra splitting the
    /// shared face along one diagonal or the other.
    fn two_cubes(lift: f64, second_as_tets: Option<bool>) -> Certificate {
        let mut p = cube([0.0; 3]);
        p.extend(cube([1.0, 0.0, 0.0])[1..3].iter().copied()); // 8: (2,0,0), 9: (2,1,0)
        p.extend(cube([1.0, 0.0, 0.0])[5..7].iter().copied()); // 10: (2,0,1), 11: (2,1,1)
        p[6][0] += lift; // corner (1, 1, 1) of the shared face 1 2 6 5
        let first = hex([0, 1, 2, 3, 4, 5, 6, 7], 0);
        let second = [1, 8, 9, 2, 5, 10, 11, 6];
        match second_as_tets {
            None => certify_cells(&p, &[], &[first, hex(second, 1)]),
            Some(along_first) => {
                // Kuhn's six tetrahedra of the second cube split its face 1 2 6 5 along
                // 1-6 (`along_first`) or, mirrored, along 2-5.
                let tets = kuhn(second, along_first);
                certify_cells(&p, &tets, &[first])
            }
        }
    }

    /// Six tetrahedra filling a hexahedron (VTK order), all around its diagonal 0-6 or
    /// 3-5.
    fn kuhn(h: [u32; 8], around_06: bool) -> Vec<[u32; 4]> {
        let paths: [[usize; 4]; 6] = if around_06 {
            [
                [0, 1, 2, 6],
                [0, 2, 3, 6],
                [0, 3, 7, 6],
                [0, 7, 4, 6],
                [0, 4, 5, 6],
                [0, 5, 1, 6],
            ]
        } else {
            [
                [3, 0, 1, 5],
                [3, 1, 2, 5],
                [3, 2, 6, 5],
                [3, 6, 7, 5],
                [3, 7, 4, 5],
                [3, 4, 0, 5],
            ]
        };
        // Each a, b, c, d (b and c neighbours around the diagonal a-d) positive in the files'
        // convention, then in halo4d's.
        paths.iter().map(|t| file_order(t.map(|i| h[i]))).collect()
    }

    #[test]
    fn two_hexahedra_conform_across_a_bent_face() {
        let c = two_cubes(0.25, None);
        assert!(c.failures().is_empty(), "{:?}", c.failures());
        let cells = c.cells.expect("mixed");
        assert_eq!((cells.quads, cells.nonplanar_quads), (11, 1));
        assert!(cells.max_warp_deg > 5.0);
    }

    #[test]
    fn a_planar_face_conforms_with_triangles_along_either_diagonal() {
        for along in [true, false] {
            let c = two_cubes(0.0, Some(along));
            assert!(c.failures().is_empty(), "{along}: {:?}", c.failures());
            assert!((c.stats.volume - 2.0).abs() < 1e-12);
        }
    }

    #[test]
    fn a_bent_face_against_triangles_is_named() {
        let c = two_cubes(0.25, Some(true));
        let cells = c.cells.clone().expect("mixed");
        assert_eq!(cells.nonconforming_quads, 1);
        assert!(
            c.failures()
                .iter()
                .any(|f| f.contains("nonconforming_quads"))
        );
        assert!(
            cells
                .faulty
                .iter()
                .any(|f| f.kind == "hexahedron" && f.id == 0)
        );
    }

    #[test]
    fn a_wedge_and_a_pyramid_fill_their_volumes_at_any_position() {
        for at in [[0.0; 3], [1e6, -3e6, 7e5]] {
            let p = cube(at);
            // The cube as two wedges (VTK order: the triangle turning away from the
            // opposite one) split along its diagonal face 0 2 6 4.
            let wedge = |c: [u32; 6]| {
                let mut corners = [0u32; 8];
                corners[..6].copy_from_slice(&c);
                Solid {
                    kind: SolidKind::Wedge,
                    corners,
                    id: 0,
                }
            };
            let c = certify_cells(
                &p,
                &[],
                &[wedge([0, 2, 1, 4, 6, 5]), wedge([0, 3, 2, 4, 7, 6])],
            );
            assert!(c.failures().is_empty(), "{at:?}: {:?}", c.failures());
            assert!((c.stats.volume - 1.0).abs() < 1e-9, "{}", c.stats.volume);
            // A pyramid on the cube's bottom face, its apex the cube's centre.
            let mut p = cube(at);
            p.push([at[0] + 0.5, at[1] + 0.5, at[2] + 0.5]);
            let pyramid = Solid {
                kind: SolidKind::Pyramid,
                corners: [0, 1, 2, 3, 8, 0, 0, 0],
                id: 3,
            };
            let c = certify_cells(&p, &[], &[pyramid]);
            assert!(c.failures().is_empty(), "{:?}", c.failures());
            assert!((c.stats.volume - 1.0 / 6.0).abs() < 1e-9);
            assert_eq!(c.cells.expect("mixed").certified_tetrahedra, 2);
        }
    }
}
