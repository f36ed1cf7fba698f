//! `orient3d` under Simulation of Simplicity (Edelsbrunner and Mücke 1990).
//!
//! Every vertex is moved by an infinitesimal whose size depends on its global index, so no
//! four vertices are ever coplanar: a determinant that is exactly zero is decided by the
//! first nonzero term of its expansion in the perturbation. The perturbation is the same in
//! every call, so all decisions describe one consistent, perturbed mesh in general position,
//! and the crossing curves built from them close. Input points are never moved; only their
//! zero-sign cases are resolved.
//!
//! Coordinate c of the point of rank r (its rank by global index among the four) moves by
//! ε^(2^(3r + c)). A monomial of the expansion picks distinct rows and columns of
//! `[p | 1]`; the smaller its exponent sum, the larger it is. Its coefficient is a signed
//! minor of `[p | 1]`: an `orient2d` of a coordinate projection, a coordinate difference or
//! a constant, all exact.

use glam::DVec3;
use robust::{Coord, Coord3D};
use std::sync::OnceLock;

/// `robust::orient3d` of four points: the determinant of the rows `[p_i, 1]`, positive
/// when `d` lies below the plane through `a`, `b`, `c` seen counterclockwise from above.
#[inline]
pub fn orient3d(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    let c3 = |p: DVec3| Coord3D {
        x: p.x,
        y: p.y,
        z: p.z,
    };
    robust::orient3d(c3(a), c3(b), c3(c), c3(d))
}

/// The sign of [`orient3d`] when floating point alone decides it (Shewchuk's first error
/// bound), else 0. Much cheaper than the exact predicate when the answer is uncertain.
#[inline]
pub fn orient3d_filtered(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> i8 {
    const BOUND: f64 = 7.771_561_172_376_103e-16;
    let (ad, bd, cd) = (a - d, b - d, c - d);
    let (bc, cb) = (bd.x * cd.y, cd.x * bd.y);
    let (ca, ac) = (cd.x * ad.y, ad.x * cd.y);
    let (ab, ba) = (ad.x * bd.y, bd.x * ad.y);
    let det = ad.z * (bc - cb) + bd.z * (ca - ac) + cd.z * (ab - ba);
    let permanent = (bc.abs() + cb.abs()) * ad.z.abs()
        + (ca.abs() + ac.abs()) * bd.z.abs()
        + (ab.abs() + ba.abs()) * cd.z.abs();
    let bound = BOUND * permanent;
    if det > bound {
        1
    } else if -det > bound {
        -1
    } else {
        0
    }
}

/// Sign (+1 or -1) of [`orient3d`] of four points with distinct global `ids`, zero resolved
/// by the perturbation. The value is that of the unperturbed determinant.
#[inline]
pub fn orient3d_sign(p: [DVec3; 4], ids: [u32; 4]) -> (f64, i8) {
    let value = orient3d(p[0], p[1], p[2], p[3]);
    if value > 0.0 {
        (value, 1)
    } else if value < 0.0 {
        (value, -1)
    } else {
        (value, perturbed(p, ids))
    }
}

/// A monomial of the expansion: up to three (row, column) pairs.
#[derive(Clone, Copy, Debug)]
struct Monomial {
    len: u8,
    pairs: [(u8, u8); 3],
}

/// The sign of the perturbed determinant when the unperturbed one is zero.
#[cold]
fn perturbed(p: [DVec3; 4], ids: [u32; 4]) -> i8 {
    debug_assert!(
        (0..4).all(|i| (i + 1..4).all(|j| ids[i] != ids[j])),
        "SoS needs four distinct vertices: {ids:?}"
    );
    let mut rank = [0usize; 4];
    for i in 0..4 {
        rank[i] = (0..4).filter(|&j| ids[j] < ids[i]).count();
    }
    let key = rank[0] * 64 + rank[1] * 16 + rank[2] * 4 + rank[3];
    for m in &orders()[key] {
        let sign = coefficient(&p, m);
        if sign != 0 {
            return sign;
        }
    }
    unreachable!("a monomial of three perturbations has coefficient +-1")
}

/// For each assignment of ranks to rows (indexed by the ranks in base 4), every monomial
/// in decreasing order of size: increasing sum of 2^(3 rank + column).
fn orders() -> &'static [Vec<Monomial>] {
    static ORDERS: OnceLock<Vec<Vec<Monomial>>> = OnceLock::new();
    ORDERS.get_or_init(|| {
        let all = monomials();
        (0..256)
            .map(|key| {
                let rank = [key / 64, key / 16 % 4, key / 4 % 4, key % 4];
                let mut ms = all.clone();
                ms.sort_by_key(|m| {
                    m.pairs[..m.len as usize]
                        .iter()
                        .map(|&(row, col)| 1u32 << (3 * rank[row as usize] + col as usize))
                        .sum::<u32>()
                });
                ms
            })
            .collect()
    })
}

/// Every nonempty set of (row, column) pairs with distinct rows and columns: 12 + 36 + 24.
fn monomials() -> Vec<Monomial> {
    let pairs: Vec<(u8, u8)> = (0..4).flat_map(|r| (0..3).map(move |c| (r, c))).collect();
    let mut out = Vec::with_capacity(72);
    for mask in 1u32..(1 << pairs.len()) {
        if mask.count_ones() > 3 {
            continue;
        }
        let chosen: Vec<(u8, u8)> = (0..pairs.len())
            .filter(|&k| mask & (1 << k) != 0)
            .map(|k| pairs[k])
            .collect();
        let rows = chosen.iter().fold(0u8, |m, &(r, _)| m | 1 << r);
        let cols = chosen.iter().fold(0u8, |m, &(_, c)| m | 1 << c);
        if rows.count_ones() as usize == chosen.len() && cols.count_ones() as usize == chosen.len()
        {
            let mut m = Monomial {
                len: chosen.len() as u8,
                pairs: [(0, 0); 3],
            };
            m.pairs[..chosen.len()].copy_from_slice(&chosen);
            out.push(m);
        }
    }
    out
}

/// Sign of the coefficient of one monomial: the parity of the permutation that sends the
/// chosen rows to their columns and the other rows, in order, to the other columns (the
/// ones column last), times the sign of the complementary minor.
fn coefficient(p: &[DVec3; 4], m: &Monomial) -> i8 {
    let chosen = &m.pairs[..m.len as usize];
    let mut perm = [usize::MAX; 4];
    let mut col_used = [false; 4];
    for &(r, c) in chosen {
        perm[r as usize] = c as usize;
        col_used[c as usize] = true;
    }
    let (mut rows, mut cols) = ([0usize; 4], [0usize; 4]);
    let (mut nr, mut nc) = (0, 0);
    for k in 0..4 {
        if perm[k] == usize::MAX {
            rows[nr] = k;
            nr += 1;
        }
        if !col_used[k] {
            cols[nc] = k;
            nc += 1;
        }
    }
    for k in 0..nr {
        perm[rows[k]] = cols[k];
    }
    let inversions = (0..4)
        .flat_map(|i| (i + 1..4).map(move |j| (i, j)))
        .filter(|&(i, j)| perm[i] > perm[j])
        .count();
    let parity = if inversions % 2 == 0 { 1 } else { -1 };
    let minor = match nr {
        3 => {
            let (a, b) = (cols[0], cols[1]);
            let q = |r: usize| Coord {
                x: p[r][a],
                y: p[r][b],
            };
            robust::orient2d(q(rows[0]), q(rows[1]), q(rows[2]))
        }
        2 => p[rows[0]][cols[0]] - p[rows[1]][cols[0]],
        _ => 1.0,
    };
    parity * sign(minor)
}

fn sign(x: f64) -> i8 {
    if x > 0.0 {
        1
    } else if x < 0.0 {
        -1
    } else {
        0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dv(x: f64, y: f64, z: f64) -> DVec3 {
        DVec3::new(x, y, z)
    }

    #[test]
    fn nondegenerate_sign_is_robusts() {
        let p = [
            dv(0.0, 0.0, 0.0),
            dv(1.0, 0.0, 0.0),
            dv(0.0, 1.0, 0.0),
            dv(0.0, 0.0, -1.0),
        ];
        assert_eq!(orient3d_sign(p, [0, 1, 2, 3]).1, 1);
        assert_eq!(orient3d_sign(p, [9, 4, 7, 1]).1, 1);
    }

    /// The first term decides: moving the lowest-index point a little along the first
    /// coordinate whose coefficient is nonzero gives the same sign as the perturbation.
    #[test]
    fn leading_term_matches_a_real_perturbation() {
        let planar = [
            dv(0.0, 0.0, 0.0),
            dv(1.0, 0.0, 0.0),
            dv(0.0, 1.0, 0.0),
            dv(0.3, 0.6, 0.0),
        ];
        for ids in [[0, 1, 2, 3], [3, 2, 1, 0], [5, 0, 9, 2], [1, 7, 3, 4]] {
            let (_, s) = orient3d_sign(planar, ids);
            let lowest = (0..4).min_by_key(|&i| ids[i]).unwrap();
            // For points in z = 0, the lowest point's x and y terms vanish (the minors have
            // a zero z column); its z coefficient is the orient2d of the other three.
            let mut moved = planar;
            moved[lowest].z += 1e-9;
            let real = orient3d(moved[0], moved[1], moved[2], moved[3]);
            assert_eq!(s, sign(real), "ids {ids:?}");
        }
    }

    #[test]
    fn the_filter_agrees_with_robust_when_it_decides() {
        let mut unit = crate::intersect::lcg(3);
        let mut next = || unit() - 0.5;
        let mut decided = 0;
        for k in 0..20000 {
            let mut p = [(); 4].map(|_| dv(next(), next(), next()));
            if k % 2 == 0 {
                // Nearly coplanar: the filter must give up rather than guess.
                p[3] = p[0] + (p[1] - p[0]) * next() + (p[2] - p[0]) * next();
            }
            let f = orient3d_filtered(p[0], p[1], p[2], p[3]);
            if f != 0 {
                decided += 1;
                assert_eq!(f, sign(orient3d(p[0], p[1], p[2], p[3])));
            }
        }
        assert!(decided > 10000, "the filter decided only {decided}");
    }

    #[test]
    fn swapping_two_points_flips_the_sign() {
        let coincident = [
            dv(0.0, 0.0, 0.0),
            dv(0.0, 0.0, 0.0),
            dv(1.0, 1.0, 0.0),
            dv(2.0, 2.0, 0.0),
        ];
        let ids = [4, 2, 8, 6];
        let (_, s) = orient3d_sign(coincident, ids);
        for (i, j) in [(0, 1), (1, 2), (0, 3), (2, 3)] {
            let mut p = coincident;
            let mut k = ids;
            p.swap(i, j);
            k.swap(i, j);
            assert_eq!(orient3d_sign(p, k).1, -s);
        }
    }
}
