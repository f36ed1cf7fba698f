//! Where a scene surface's 4D mesh comes from: a parametric surface (the catalogue's or a
//! formula), sampled; or a mesh read from a file, taken as it is.
//!
//! A mesh from a file has no parametrization, so its tangents for the halo's normals come
//! from the mesh: at each vertex, the plane that best fits the planes of the triangles
//! around it, weighted by their areas (the two leading eigenvectors of the sum of the
//! triangles' orthogonal projectors, a 4 x 4 symmetric matrix), turned to agree with the
//! triangles' winding. Its vertices all get patch 0 and parameters (0, 0).

use super::{Mesh4, MeshStats, Sampled, Sampling};
use crate::limits::FieldError;
use crate::surfaces::{Surface, Topology};
use glam::DVec4;
use serde::{Deserialize, Serialize};
use std::path::Path;
use std::sync::Arc;

/// A triangle mesh in R^4 as a file holds it ([`crate::import::read_mesh4`] reads one).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshData4 {
    /// The vertices' points of R^4.
    pub positions: Vec<DVec4>,
    /// Triangles as indices into `positions`, in the order and orientation of the file's
    /// faces.
    pub triangles: Vec<[u32; 3]>,
}

/// A surface of a scene: parametric, or a 4D mesh from a file.
#[derive(Clone, Debug, PartialEq)]
pub enum Source {
    /// A catalogue or formula surface, sampled as the scene's `sampling` says.
    Parametric(Surface),
    /// A 4D mesh read from a file (`{"type": "mesh", "path": "..."}`), not sampled.
    Mesh(MeshSurface),
}

/// A 4D triangle mesh read from a file: Geomview `4OFF` or `nOFF` of dimension 4 (ASCII or
/// binary), OBJ with four coordinates per vertex, or PLY with `x y z w` vertex properties.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshSurface {
    /// The file as the scene names it, relative to the scene file's folder.
    pub path: String,
    /// The mesh with its tangents, once [`MeshSurface::set`] has it (the scene reads the file).
    #[serde(skip)]
    pub mesh: Arc<Mesh4>,
}

impl MeshSurface {
    /// Takes the mesh read from its file `file`: welds its coincident vertices and makes
    /// its tangents.
    pub fn set(&mut self, data: MeshData4, file: &Path) -> Result<(), FieldError> {
        let data = weld(data).map_err(|m| {
            FieldError::new(
                "path",
                format!(
                    "{}: {m}",
                    crate::limits::shorten(&file.display().to_string())
                ),
            )
        })?;
        self.mesh = Arc::new(mesh_from_data(data));
        Ok(())
    }

    /// What the mesh's combinatorics say of the surface (`mesh_topology` of its
    /// statistics).
    pub fn topology(&self) -> Topology {
        mesh_topology(&self.mesh.validate())
    }
}

/// What a mesh's statistics say of its surface: closed when no edge is on one triangle
/// only, orientable when the triangles' windings agree across every edge (as written),
/// and V - E + F.
pub fn mesh_topology(stats: &MeshStats) -> Topology {
    let closed = stats.boundary_edges == 0;
    Topology {
        closed,
        orientable: stats.orientation_conflicts == 0,
        euler_characteristic: closed.then_some(stats.euler_characteristic),
    }
}

impl Serialize for Source {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Source::Parametric(surface) => surface.serialize(s),
            Source::Mesh(m) => {
                use serde::ser::SerializeMap;
                let mut map = s.serialize_map(Some(2))?;
                map.serialize_entry("type", "mesh")?;
                map.serialize_entry("path", &m.path)?;
                map.end()
            }
        }
    }
}

/// `{"type": "mesh", ...}` is a mesh file, any other type a parametric surface.
impl<'de> Deserialize<'de> for Source {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        let mut map = serde_json::Map::deserialize(d)?;
        if map.get("type").and_then(|t| t.as_str()) != Some("mesh") {
            return Surface::deserialize(serde_json::Value::Object(map))
                .map(Source::Parametric)
                .map_err(D::Error::custom);
        }
        map.remove("type");
        serde_path_to_error::deserialize(serde_json::Value::Object(map))
            .map(Source::Mesh)
            .map_err(|e| match e.path().to_string().as_str() {
                "." => D::Error::custom(e.inner()),
                path => D::Error::custom(FieldError::new(path, e.inner().to_string())),
            })
    }
}

impl Source {
    /// What `halo4d list` prints: the catalogue, the formula type and the mesh type, each
    /// with its parameters or an example.
    pub fn listing() -> String {
        format!(
            "{}{:<20} a 4D triangle mesh from a file, not sampled: Geomview 4OFF or nOFF with dimension 4 (ASCII or BINARY), OBJ with `v x y z w`, PLY with vertex properties x y z w; the path relative to the scene file (this scene's, for a scene saved in halo4d's folder)\n{:<20} a scene: {{\"name\":\"my-mesh\",\"surfaces\":[{{\"surface\":{{\"type\":\"mesh\",\"path\":\"fixtures/meshes/clifford-torus.4off\"}}}}]}}\n",
            Surface::catalogue_listing(),
            "mesh",
            ""
        )
    }

    /// The `type` name used in scene files.
    pub fn type_name(&self) -> &'static str {
        match self {
            Source::Parametric(s) => s.type_name(),
            Source::Mesh(_) => "mesh",
        }
    }

    /// The parametric surface, if this is one.
    pub fn parametric(&self) -> Option<&Surface> {
        match self {
            Source::Parametric(s) => Some(s),
            Source::Mesh(_) => None,
        }
    }

    /// Number of parameter patches (1 for a mesh file).
    pub fn patch_count(&self) -> usize {
        self.parametric().map_or(1, Surface::patch_count)
    }

    /// Closedness, orientability and Euler characteristic: the surface's own, or what a
    /// mesh file's combinatorics say.
    pub fn topology(&self) -> Topology {
        match self {
            Source::Parametric(s) => s.topology(),
            Source::Mesh(m) => m.topology(),
        }
    }

    /// Checks the parameters (a mesh file must have been read): names the first bad field.
    pub fn check(&self) -> Result<(), FieldError> {
        match self {
            Source::Parametric(s) => s.check(),
            Source::Mesh(m) if m.mesh.triangles.is_empty() => Err(FieldError::new(
                "path",
                format!(
                    "`{}` has not been read: scenes read their mesh files when loaded (`Scene::load`, or `Scene::parse` with the scene file's path)",
                    crate::limits::shorten(&m.path)
                ),
            )),
            Source::Mesh(_) => Ok(()),
        }
    }

    /// The 4D mesh: a parametric surface sampled as `sampling` says, a mesh file as read.
    pub fn sample(&self, sampling: &Sampling) -> Sampled {
        match self {
            Source::Parametric(s) => super::sample(s, sampling),
            Source::Mesh(m) => Sampled {
                mesh: Mesh4::clone(&m.mesh),
                tolerance: None,
                diagonal: m
                    .mesh
                    .bounds()
                    .map(|(lo, hi)| (hi - lo).length())
                    .filter(|d| *d > 0.0)
                    .unwrap_or(1.0),
                complete: true,
            },
        }
    }
}

/// The mesh with vertices at the same point made one (files written face by face repeat
/// them; two vertices with the same four coordinates are one point of the surface, so this
/// is not welding by distance). A triangle with two corners at one point is an error.
fn weld(data: MeshData4) -> Result<MeshData4, String> {
    use std::collections::HashMap;
    // -0.0 and 0.0 are the same point.
    let key = |p: DVec4| p.to_array().map(|x| (x + 0.0).to_bits());
    let mut first: HashMap<[u64; 4], u32> = HashMap::with_capacity(data.positions.len());
    let mut positions = Vec::with_capacity(data.positions.len());
    let mut index = Vec::with_capacity(data.positions.len());
    for p in &data.positions {
        let next = positions.len() as u32;
        let i = *first.entry(key(*p)).or_insert(next);
        if i == next {
            positions.push(*p);
        }
        index.push(i);
    }
    let mut triangles = Vec::with_capacity(data.triangles.len());
    let mut used = vec![false; positions.len()];
    for (f, t) in data.triangles.iter().enumerate() {
        let w = t.map(|v| index[v as usize]);
        if w[0] == w[1] || w[1] == w[2] || w[0] == w[2] {
            let p = positions[w[0].min(w[1]).min(w[2]) as usize];
            return Err(format!(
                "triangle {f} (0-based, after splitting polygons) has two corners at the same point {p}: remove it or move its corners apart"
            ));
        }
        for v in w {
            used[v as usize] = true;
        }
        triangles.push(w);
    }
    // Vertices no triangle uses are dropped: they are no part of the surface.
    let mut renumber = vec![u32::MAX; positions.len()];
    let mut kept = Vec::with_capacity(positions.len());
    for (i, p) in positions.into_iter().enumerate() {
        if used[i] {
            renumber[i] = kept.len() as u32;
            kept.push(p);
        }
    }
    for t in &mut triangles {
        *t = t.map(|v| renumber[v as usize]);
    }
    Ok(MeshData4 {
        positions: kept,
        triangles,
    })
}

/// A [`Mesh4`] of a file's mesh: its points and triangles, tangents from the mesh, every
/// vertex on patch 0 at parameters (0, 0).
pub fn mesh_from_data(data: MeshData4) -> Mesh4 {
    let (tangent_u, tangent_v) = mesh_tangents(&data.positions, &data.triangles);
    let n = data.positions.len();
    let t = data.triangles.len();
    Mesh4 {
        positions: data.positions,
        tangent_u,
        tangent_v,
        uv: vec![[0.0; 2]; n],
        patch: vec![0; n],
        triangle_patch: vec![0; t],
        triangle_uv: vec![[[0.0; 2]; 3]; t],
        triangles: data.triangles,
    }
}

/// Unit tangents at each vertex spanning the area-weighted best plane of its triangles,
/// ordered so that they agree with the winding of most of its triangles' area (u ∧ v
/// against each triangle's (b - a) ∧ (c - a)). A vertex on no triangle, or whose triangles
/// all have zero area, gets the first two axes.
pub fn mesh_tangents(positions: &[DVec4], triangles: &[[u32; 3]]) -> (Vec<DVec4>, Vec<DVec4>) {
    let n = positions.len();
    let mut projectors = vec![[[0.0f64; 4]; 4]; n];
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let Some((e1, e2)) = orthonormal_pair(b - a, c - a) else {
            continue;
        };
        let area = triangle_area(b - a, c - a);
        for &i in t {
            let m = &mut projectors[i as usize];
            for r in 0..4 {
                for s in 0..4 {
                    m[r][s] += area * (e1[r] * e1[s] + e2[r] * e2[s]);
                }
            }
        }
    }
    let mut tangent_u = Vec::with_capacity(n);
    let mut tangent_v = Vec::with_capacity(n);
    for m in &projectors {
        let (tu, tv) = leading_plane(*m).unwrap_or((DVec4::X, DVec4::Y));
        tangent_u.push(tu);
        tangent_v.push(tv);
    }
    // The winding: the sign of u ∧ v against each triangle's bivector, area-weighted (the
    // inner product of the two bivectors is that weight).
    let mut agree = vec![0.0f64; n];
    for t in triangles {
        for k in 0..3 {
            let i = t[k] as usize;
            let (p, q, r) = (
                positions[i],
                positions[t[(k + 1) % 3] as usize],
                positions[t[(k + 2) % 3] as usize],
            );
            let (e1, e2) = (q - p, r - p);
            let (tu, tv) = (tangent_u[i], tangent_v[i]);
            agree[i] += e1.dot(tu) * e2.dot(tv) - e1.dot(tv) * e2.dot(tu);
        }
    }
    for (tv, a) in tangent_v.iter_mut().zip(agree) {
        if a < 0.0 {
            *tv = -*tv;
        }
    }
    (tangent_u, tangent_v)
}

fn triangle_area(a: DVec4, b: DVec4) -> f64 {
    0.5 * (a.length_squared() * b.length_squared() - a.dot(b).powi(2))
        .max(0.0)
        .sqrt()
}

/// An orthonormal basis of the plane of a and b, by Gram-Schmidt; `None` when they are
/// (nearly) parallel.
fn orthonormal_pair(a: DVec4, b: DVec4) -> Option<(DVec4, DVec4)> {
    let e1 = a.try_normalize()?;
    let rest = b - e1 * e1.dot(b);
    if rest.length() <= 1e-12 * b.length() {
        return None;
    }
    Some((e1, rest.normalize()))
}

/// The eigenvectors of the two largest eigenvalues of a symmetric 4 x 4 matrix, by cyclic
/// Jacobi rotations (a few sweeps reach rounding at this size: no linear algebra crate
/// needed for one matrix kind); `None` for the zero matrix or a plane that is not defined
/// (a second eigenvalue of zero: all the triangles' planes are one line).
fn leading_plane(mut a: [[f64; 4]; 4]) -> Option<(DVec4, DVec4)> {
    let scale: f64 = a.iter().flatten().map(|x| x.abs()).sum();
    if !(scale.is_finite() && scale > 0.0) {
        return None;
    }
    let mut v = [[0.0f64; 4]; 4];
    for (i, row) in v.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    for _ in 0..32 {
        let off: f64 = (0..4)
            .flat_map(|p| (0..4).filter(move |&q| q != p).map(move |q| (p, q)))
            .map(|(p, q)| a[p][q] * a[p][q])
            .sum();
        if off <= (1e-30 * scale).powi(2) {
            break;
        }
        for p in 0..3 {
            for q in p + 1..4 {
                if a[p][q] == 0.0 {
                    continue;
                }
                // The rotation that zeroes a[p][q] (Golub and Van Loan, algorithm 8.4.1).
                let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                // A J (columns p and q of A), V J, then J^T (A J) (rows p and q).
                for row in a.iter_mut().chain(v.iter_mut()) {
                    let (x, y) = (row[p], row[q]);
                    row[p] = c * x - s * y;
                    row[q] = s * x + c * y;
                }
                let (rp, rq) = (a[p], a[q]);
                a[p] = std::array::from_fn(|k| c * rp[k] - s * rq[k]);
                a[q] = std::array::from_fn(|k| s * rp[k] + c * rq[k]);
            }
        }
    }
    let mut order = [0, 1, 2, 3];
    order.sort_by(|&i, &j| a[j][j].total_cmp(&a[i][i]));
    if a[order[1]][order[1]] <= 1e-12 * a[order[0]][order[0]] {
        return None;
    }
    let column = |j: usize| DVec4::new(v[0][j], v[1][j], v[2][j], v[3][j]).normalize();
    Some((column(order[0]), column(order[1])))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn welding_joins_equal_points_only_and_refuses_collapsed_triangles() {
        let p = |x: f64| DVec4::new(x, 0.5 * x * x, 1.0, -x);
        // Two triangles written face by face: six vertices, four points (0.0 and -0.0 one).
        let data = MeshData4 {
            positions: vec![p(0.0), p(1.0), p(2.0), p(-0.0), p(2.0), p(3.0), p(9.0)],
            triangles: vec![[0, 1, 2], [3, 4, 5]],
        };
        let welded = weld(data).unwrap();
        assert_eq!(welded.positions, vec![p(0.0), p(1.0), p(2.0), p(3.0)]);
        assert_eq!(welded.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        let collapsed = MeshData4 {
            positions: vec![p(0.0), p(1.0), p(1.0)],
            triangles: vec![[0, 1, 2]],
        };
        let err = weld(collapsed).unwrap_err();
        assert!(err.starts_with("triangle 0 "), "{err}");
    }

    #[test]
    fn jacobi_finds_the_plane_of_a_projector() {
        // The projector onto span{(1, 1, 0, 0), (0, 0, 1, -1)} / sqrt 2, times 3.
        let (e1, e2) = (
            DVec4::new(1.0, 1.0, 0.0, 0.0).normalize(),
            DVec4::new(0.0, 0.0, 1.0, -1.0).normalize(),
        );
        let mut m = [[0.0; 4]; 4];
        for r in 0..4 {
            for s in 0..4 {
                m[r][s] = 3.0 * (e1[r] * e1[s] + e2[r] * e2[s]);
            }
        }
        let (a, b) = leading_plane(m).expect("a plane");
        for x in [a, b] {
            // x lies in the plane: its projection onto it is itself.
            let inside = e1 * e1.dot(x) + e2 * e2.dot(x);
            assert!((inside - x).length() < 1e-14, "{x}");
        }
        assert!(a.dot(b).abs() < 1e-14);
        assert!(leading_plane([[0.0; 4]; 4]).is_none());
    }

    #[test]
    fn tangents_of_a_flat_mesh_span_its_plane_and_follow_its_winding() {
        // A square in the plane w = x, z = 2, as two triangles counter-clockwise in (x, y).
        let p = |x: f64, y: f64| DVec4::new(x, y, 2.0, x);
        let positions = vec![p(0.0, 0.0), p(1.0, 0.0), p(1.0, 1.0), p(0.0, 1.0)];
        let triangles = vec![[0, 1, 2], [0, 2, 3]];
        let (tu, tv) = mesh_tangents(&positions, &triangles);
        let (ex, ey) = (DVec4::new(1.0, 0.0, 0.0, 1.0).normalize(), DVec4::Y);
        for i in 0..4 {
            for t in [tu[i], tv[i]] {
                let inside = ex * ex.dot(t) + ey * ey.dot(t);
                assert!((inside - t).length() < 1e-12);
            }
            // u ∧ v has the orientation of x ∧ y.
            let orient = tu[i].dot(ex) * tv[i].dot(ey) - tu[i].dot(ey) * tv[i].dot(ex);
            assert!(orient > 0.99, "vertex {i}: {orient}");
        }
        // Reversed winding, reversed tangent orientation.
        let reversed: Vec<[u32; 3]> = triangles.iter().map(|t| [t[0], t[2], t[1]]).collect();
        let (tu, tv) = mesh_tangents(&positions, &reversed);
        let orient = tu[0].dot(ex) * tv[0].dot(ey) - tu[0].dot(ey) * tv[0].dot(ex);
        assert!(orient < -0.99);
    }
}
