//! The shape of each tetrahedron: its smallest and largest dihedral angles and its radius
//! ratio, with the mesh's extremes, histograms and worst elements. Reported, never judged:
//! a sliver is a valid tetrahedron.

use super::exact::P;
use rayon::prelude::*;
use serde::Serialize;

/// How many of the worst tetrahedra [`Quality::worst`] lists.
pub const WORST: usize = 10;

/// Bins of each histogram.
pub const BINS: usize = 10;

/// The largest smallest dihedral angle a tetrahedron can have (the regular one's),
/// arccos(1/3), in degrees: where the histogram of smallest angles ends.
const REGULAR_DIHEDRAL_DEG: f64 = 70.528_779_365_509_31;

/// The cells' shape.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Quality {
    /// The smallest dihedral angle of any tetrahedron, in degrees.
    pub min_dihedral_deg: f64,
    /// The largest dihedral angle of any tetrahedron, in degrees.
    pub max_dihedral_deg: f64,
    /// The smallest radius ratio: 3 r / R (inradius over circumradius), 1 for the regular
    /// tetrahedron, 0 for a flat one.
    pub min_radius_ratio: f64,
    /// The mean radius ratio.
    pub mean_radius_ratio: f64,
    /// How many tetrahedra have their smallest dihedral angle in each tenth of 0 to
    /// arccos(1/3) (the regular tetrahedron's, about 70.53 degrees).
    pub min_dihedral_histogram: Vec<Bin>,
    /// How many tetrahedra have their radius ratio in each tenth of 0 to 1.
    pub radius_ratio_histogram: Vec<Bin>,
    /// The tetrahedra of the smallest radius ratio, worst first (ties by index), at most
    /// [`WORST`].
    pub worst: Vec<Cell>,
}

/// A histogram's bin: [from, to), the last one closed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Bin {
    /// Its lower end.
    pub from: f64,
    /// Its upper end.
    pub to: f64,
    /// Tetrahedra in it.
    pub count: usize,
}

/// One tetrahedron's shape.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Cell {
    /// Its index in the file, from 0.
    pub tet: usize,
    /// Its smallest dihedral angle, in degrees.
    pub min_dihedral_deg: f64,
    /// Its largest dihedral angle, in degrees.
    pub max_dihedral_deg: f64,
    /// Its radius ratio.
    pub radius_ratio: f64,
}

fn sub(a: P, b: P) -> P {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: P, b: P) -> P {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: P, b: P) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn norm(a: P) -> f64 {
    dot(a, a).sqrt()
}

/// A tetrahedron's smallest and largest dihedral angles (degrees) and radius ratio; all 0
/// for a flat or degenerate one. Computed in floating point on coordinates scaled to about 1
/// (the checker's): what it reports, not what it decides.
pub fn shape(p: [P; 4]) -> [f64; 3] {
    // The face opposite vertex i, its area vector turned away from vertex i.
    let mut normals = [[0.0; 3]; 4];
    let mut area = 0.0;
    for (i, n) in normals.iter_mut().enumerate() {
        let [a, b, c] = [(i + 1) % 4, (i + 2) % 4, (i + 3) % 4].map(|k| p[k]);
        let m = cross(sub(b, a), sub(c, a));
        let sign = if dot(m, sub(p[i], a)) > 0.0 {
            -1.0
        } else {
            1.0
        };
        *n = m.map(|x| sign * x);
        area += norm(m) / 2.0;
    }
    let (a, b, c) = (sub(p[1], p[0]), sub(p[2], p[0]), sub(p[3], p[0]));
    let six_volume = dot(a, cross(b, c)).abs();
    if !(six_volume > 0.0 && six_volume.is_finite()) {
        return [0.0; 3];
    }
    // The dihedral angle at the edge between faces i and j: pi less the angle of their
    // outward normals.
    let (mut smallest, mut largest) = (180.0f64, 0.0f64);
    for i in 0..4 {
        for j in i + 1..4 {
            let cos = -dot(normals[i], normals[j]) / (norm(normals[i]) * norm(normals[j]));
            let angle = cos.clamp(-1.0, 1.0).acos().to_degrees();
            smallest = smallest.min(angle);
            largest = largest.max(angle);
        }
    }
    // r = 3V / area; R = |a² (b × c) + b² (c × a) + c² (a × b)| / (12 V).
    let inradius = 0.5 * six_volume / area;
    let circum = [cross(b, c), cross(c, a), cross(a, b)]
        .iter()
        .zip([dot(a, a), dot(b, b), dot(c, c)])
        .fold([0.0; 3], |s, (v, w)| {
            [s[0] + w * v[0], s[1] + w * v[1], s[2] + w * v[2]]
        });
    let circumradius = norm(circum) / (2.0 * six_volume);
    let ratio = (3.0 * inradius / circumradius).clamp(0.0, 1.0);
    [
        smallest,
        largest,
        if ratio.is_finite() { ratio } else { 0.0 },
    ]
}

/// Each tetrahedron's [`shape`] (as f32: smallest and largest dihedral angle, radius ratio)
/// and the mesh's [`Quality`]; tetrahedra repeating a vertex have shape 0.
pub fn quality(positions: &[P], tets: &[[u32; 4]]) -> (Quality, Vec<[f32; 3]>) {
    let shapes: Vec<[f64; 3]> = tets
        .par_iter()
        .map(|t| {
            let distinct = (0..4).all(|i| (i + 1..4).all(|j| t[i] != t[j]));
            if distinct {
                shape(t.map(|i| positions[i as usize]))
            } else {
                [0.0; 3]
            }
        })
        .collect();
    let n = shapes.len();
    let mut q = Quality {
        min_dihedral_deg: shapes.iter().map(|s| s[0]).fold(f64::INFINITY, f64::min),
        max_dihedral_deg: shapes.iter().map(|s| s[1]).fold(0.0, f64::max),
        min_radius_ratio: shapes.iter().map(|s| s[2]).fold(f64::INFINITY, f64::min),
        mean_radius_ratio: shapes.iter().map(|s| s[2]).sum::<f64>() / n.max(1) as f64,
        min_dihedral_histogram: histogram(shapes.iter().map(|s| s[0]), REGULAR_DIHEDRAL_DEG),
        radius_ratio_histogram: histogram(shapes.iter().map(|s| s[2]), 1.0),
        worst: Vec::new(),
    };
    if n == 0 {
        (q.min_dihedral_deg, q.min_radius_ratio) = (0.0, 0.0);
    }
    let mut order: Vec<usize> = (0..n).collect();
    let by_ratio = |&i: &usize, &j: &usize| shapes[i][2].total_cmp(&shapes[j][2]).then(i.cmp(&j));
    if n > WORST {
        order.select_nth_unstable_by(WORST, by_ratio);
        order.truncate(WORST);
    }
    order.sort_unstable_by(by_ratio);
    q.worst = order
        .iter()
        .map(|&i| Cell {
            tet: i,
            min_dihedral_deg: shapes[i][0],
            max_dihedral_deg: shapes[i][1],
            radius_ratio: shapes[i][2],
        })
        .collect();
    let per_cell = shapes
        .into_par_iter()
        .map(|s| s.map(|x| x as f32))
        .collect();
    (q, per_cell)
}

/// [`BINS`] bins from 0 to `top`, the last closed.
fn histogram(values: impl Iterator<Item = f64>, top: f64) -> Vec<Bin> {
    let width = top / BINS as f64;
    let mut bins: Vec<Bin> = (0..BINS)
        .map(|i| Bin {
            from: i as f64 * width,
            to: if i + 1 == BINS {
                top
            } else {
                (i + 1) as f64 * width
            },
            count: 0,
        })
        .collect();
    for v in values {
        let i = ((v / width).floor().max(0.0) as usize).min(BINS - 1);
        bins[i].count += 1;
    }
    bins
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_regular_tetrahedron_has_ratio_1_and_equal_angles() {
        let p = [
            [1.0, 1.0, 1.0],
            [1.0, -1.0, -1.0],
            [-1.0, 1.0, -1.0],
            [-1.0, -1.0, 1.0],
        ];
        let [lo, hi, ratio] = shape(p);
        assert!((lo - REGULAR_DIHEDRAL_DEG).abs() < 1e-9, "{lo}");
        assert!((hi - REGULAR_DIHEDRAL_DEG).abs() < 1e-9, "{hi}");
        assert!((ratio - 1.0).abs() < 1e-12, "{ratio}");
    }

    #[test]
    fn the_corner_tetrahedron_and_a_sliver() {
        let corner = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ];
        let [lo, hi, ratio] = shape(corner);
        // Right angles at the three edges from the corner; arccos(1/sqrt 3) at the others.
        assert!((hi - 90.0).abs() < 1e-9 && (lo - 54.735_610_317_245_35).abs() < 1e-9);
        // r = 1 / (3 + sqrt 3), R = sqrt 3 / 2.
        let expected = 3.0 * (1.0 / (3.0 + 3f64.sqrt())) / (3f64.sqrt() / 2.0);
        assert!((ratio - expected).abs() < 1e-12, "{ratio} {expected}");
        let sliver = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.3, 0.3, 1e-9],
        ];
        let [lo, _, ratio] = shape(sliver);
        assert!(lo < 1e-6 && ratio < 1e-8, "{lo} {ratio}");
        assert_eq!(
            shape([corner[0], corner[1], corner[2], [0.5, 0.5, 0.0]]),
            [0.0; 3]
        );
    }
}
