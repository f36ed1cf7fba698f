//! Halos (paper 000, eq. 1-3): a projected surface thickened into a shell of tetrahedra.
//!
//! Takes: a projected surface (3D points, w-depths, unit normals from the view) and its
//! triangles. Gives: a [`Halo`]: the two offset surfaces v ± rho n̂ (t = 0 on the negative
//! side, 1 on the positive), each offset vertex keeping t and d_orig (its w-depth), and the
//! tetrahedra of the prisms between them ([`crate::tets`]). Inside the halo the depth grows
//! as d_new = d_orig + max(0, |2t - 1| - delta_t) delta_d, evaluated after interpolating t
//! and d_orig, so the halo carries those two and not d_new.
//!
//! The normal n̂ is the view's: the normalized cross product of the projected tangents
//! (eq. 1); where they are (nearly) parallel, at cross-caps of the projection and at the
//! poles of spun spheres, and where a triangle around the vertex faces away from it, it is
//! the normalized sum of the area-weighted normals of the triangles around the vertex,
//! which depends on the mesh and not on the parametrization ([`offset_directions`]). It is
//! never NaN.
//!
//! Where rho exceeds what the local geometry allows, the offsets fold and prisms invert.
//! With `fold: shrink` (the default) rho is halved at the corners of every inverted prism
//! for as long as that leaves fewer of them (at most 30 times); the report counts the
//! vertices shrunk. Prisms that no rho mends (around cross-caps, and across the seam of a
//! non-orientable surface) stay inverted and are counted. With `fold: report` the inverted
//! tetrahedra are only counted.

use crate::check::{CheckStats, TetMesh, check};
use crate::tets::{Split, SplitStats, Tetrahedra, tetrahedralize};
use crate::view::Projected;
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// The parameters of the volumetric halos of a scene.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct HaloParams {
    /// Half-width of the halo, relative to the diagonal of the projected scene's bounding box.
    pub rho: f64,
    /// Depth increment delta_d at the halo's outer surfaces (eq. 3), in w units.
    pub delta_d: f64,
    /// Dead zone delta_t in [0, 1) of |2t - 1| before the depth starts to grow (eq. 3).
    pub delta_t: f64,
    /// How prisms are split into tetrahedra.
    pub split: Split,
    /// What to do where the offsets fold.
    pub fold: Fold,
}

/// What to do where rho is too large for the local geometry and prisms invert.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Fold {
    /// Shrink rho locally until every prism is valid, and count the vertices shrunk.
    #[default]
    Shrink,
    /// Keep rho and count the inverted tetrahedra.
    Report,
}

impl Default for HaloParams {
    fn default() -> Self {
        HaloParams {
            rho: 0.01,
            delta_d: 0.5,
            delta_t: 0.1,
            split: Split::default(),
            fold: Fold::default(),
        }
    }
}

impl HaloParams {
    /// Checks the numbers: `Err((field, message))` names the first bad one.
    pub fn check(&self) -> Result<(), (&'static str, String)> {
        if !(self.rho.is_finite() && self.rho > 0.0 && self.rho < 0.5) {
            return Err((
                "rho",
                format!(
                    "must be greater than 0 and less than 0.5 (a share of the scene's diagonal), got {}",
                    self.rho
                ),
            ));
        }
        if !(self.delta_d.is_finite() && self.delta_d >= 0.0) {
            return Err((
                "delta_d",
                format!(
                    "must be a finite number of at least 0, got {}",
                    self.delta_d
                ),
            ));
        }
        if !(self.delta_t.is_finite() && (0.0..1.0).contains(&self.delta_t)) {
            return Err((
                "delta_t",
                format!("must be in [0, 1), got {}", self.delta_t),
            ));
        }
        Ok(())
    }
}

/// A surface's halo: vertices (negative offsets, positive offsets, then inserted vertices)
/// with t and d_orig, and tetrahedra.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Halo {
    /// Surface vertices n.
    pub surface_vertices: usize,
    /// Vertex positions.
    pub positions: Vec<DVec3>,
    /// t of each vertex: 0 on the negative offset, 1 on the positive, 0.5 inside.
    pub t: Vec<f64>,
    /// w-depth of the surface point each vertex came from.
    pub d_orig: Vec<f64>,
    /// Tetrahedra, positively oriented (`robust::orient3d`).
    pub tets: Vec<[u32; 4]>,
    /// The half-width used at each surface vertex (rho, or less where it was shrunk).
    pub rho: Vec<f64>,
    /// The surface triangle whose prism each inserted vertex (from 2n on) is in.
    pub inserted_in: Vec<u32>,
}

impl Halo {
    /// The halo in the checker's terms.
    pub fn tet_mesh(&self) -> TetMesh {
        TetMesh {
            positions: self.positions.iter().map(|p| p.to_array()).collect(),
            surface_vertices: self.surface_vertices,
            tets: self.tets.clone(),
        }
    }
}

/// What `report.json` says of a halo.
#[derive(Clone, Debug, Serialize)]
pub struct HaloReport {
    /// The split used.
    pub split: &'static str,
    /// Prisms (surface triangles).
    pub prisms: usize,
    /// Tetrahedra.
    pub tets: usize,
    /// Half-width asked for, absolute.
    pub rho: f64,
    /// The builder's counts.
    #[serde(flatten)]
    pub split_stats: SplitStats,
    /// Inverted or flat tetrahedra, as the checker counts them.
    pub inverted: usize,
    /// Surface vertices whose rho was shrunk.
    pub shrunk_vertices: usize,
    /// Smallest dihedral angle, degrees (checker).
    pub min_dihedral_deg: f64,
    /// The checker's full statistics.
    pub check: CheckStats,
    /// Milliseconds: thickening, splitting, fixing and checking.
    pub ms: f64,
}

/// The direction each vertex is offset along: the view's normal (eq. 1), unless some
/// triangle around the vertex faces away from it (near a cross-cap of the projection the
/// projected triangles turn over), in which case the normalized sum of the area-weighted
/// normals of the triangles around it, so that the prisms there keep their orientation.
pub fn offset_directions(p: &Projected, triangles: &[[u32; 3]]) -> Vec<DVec3> {
    let mut sum = vec![DVec3::ZERO; p.positions.len()];
    let mut against = vec![false; p.positions.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| p.positions[i as usize]);
        let face = (b - a).cross(c - a);
        for &i in t {
            sum[i as usize] += face;
            against[i as usize] |= p.normals[i as usize].dot(face) <= 0.0;
        }
    }
    (0..p.positions.len())
        .map(|i| {
            if against[i] {
                sum[i].try_normalize().unwrap_or(p.normals[i])
            } else {
                p.normals[i]
            }
        })
        .collect()
}

/// Offsets every vertex by ∓`rho[i]` along `dir[i]`: negative side first, then positive.
fn offsets(p: &Projected, dir: &[DVec3], rho: &[f64]) -> Vec<DVec3> {
    let below = (0..p.positions.len()).map(|i| p.positions[i] - dir[i] * rho[i]);
    let above = (0..p.positions.len()).map(|i| p.positions[i] + dir[i] * rho[i]);
    below.chain(above).collect()
}

/// The surface vertices of prisms with an inverted or flat tetrahedron.
fn folded_vertices(positions: &[DVec3], tets: &Tetrahedra) -> Vec<u32> {
    let c = |i: u32| {
        let p = if (i as usize) < positions.len() {
            positions[i as usize]
        } else {
            tets.inserted[i as usize - positions.len()]
        };
        robust::Coord3D {
            x: p.x,
            y: p.y,
            z: p.z,
        }
    };
    let n = positions.len() / 2;
    let mut out = Vec::new();
    for tet in &tets.tets {
        if robust::orient3d(c(tet[0]), c(tet[1]), c(tet[2]), c(tet[3])) <= 0.0 {
            out.extend(
                tet.iter()
                    .filter(|&&i| (i as usize) < 2 * n)
                    .map(|&i| i % n as u32),
            );
        }
    }
    out.sort_unstable();
    out.dedup();
    out
}

/// Thickens a projected surface by `rho` (absolute) and splits it into tetrahedra, then
/// checks the result with the independent checker.
pub fn build_halo(
    projected: &Projected,
    triangles: &[[u32; 3]],
    rho: f64,
    params: &HaloParams,
) -> (Halo, HaloReport) {
    let start = Instant::now();
    let n = projected.positions.len();
    let mut rho_at = vec![rho; n];
    let mut shrunk = vec![false; n];
    let dir = offset_directions(projected, triangles);
    let mut positions = offsets(projected, &dir, &rho_at);
    let mut tets = tetrahedralize(triangles, &positions, n, params.split);
    if params.fold == Fold::Shrink {
        // Halve rho around inverted prisms while that removes inverted tetrahedra; where it
        // does not (the triangles around a cross-cap face every way), keep the last rho that
        // helped and let the checker count what is left.
        let mut folded = folded_vertices(&positions, &tets);
        for _ in 0..30 {
            if folded.is_empty() {
                break;
            }
            let mut trial = rho_at.clone();
            for &v in &folded {
                trial[v as usize] *= 0.5;
            }
            let p = offsets(projected, &dir, &trial);
            let t = tetrahedralize(triangles, &p, n, params.split);
            let f = folded_vertices(&p, &t);
            if f.len() >= folded.len() {
                break;
            }
            for &v in &folded {
                shrunk[v as usize] = true;
            }
            (rho_at, positions, tets, folded) = (trial, p, t, f);
        }
    }
    let mut t = vec![0.0; n];
    t.extend(std::iter::repeat_n(1.0, n));
    let mut d_orig = projected.w.clone();
    d_orig.extend_from_slice(&projected.w);
    for &tri in &tets.inserted_in {
        let corners = triangles[tri as usize];
        t.push(0.5);
        d_orig.push(
            corners
                .iter()
                .map(|&i| projected.w[i as usize])
                .sum::<f64>()
                / 3.0,
        );
    }
    positions.extend_from_slice(&tets.inserted);
    let halo = Halo {
        surface_vertices: n,
        positions,
        t,
        d_orig,
        tets: tets.tets,
        rho: rho_at,
        inserted_in: tets.inserted_in,
    };
    let checked = check(&halo.tet_mesh());
    let report = HaloReport {
        split: params.split.name(),
        prisms: triangles.len(),
        tets: halo.tets.len(),
        rho,
        split_stats: tets.stats,
        inverted: checked.inverted + checked.flat,
        shrunk_vertices: shrunk.iter().filter(|s| **s).count(),
        min_dihedral_deg: checked.min_dihedral_deg,
        check: checked,
        ms: start.elapsed().as_secs_f64() * 1e3,
    };
    (halo, report)
}
