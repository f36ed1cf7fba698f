//! A valid tetrahedral mesh of any size: the cube [0, n]^3 cut into unit cubes, each into
//! six tetrahedra around its diagonal from (0, 0, 0) to (1, 1, 1) (Kuhn's subdivision,
//! conforming because every cube's faces are split along the same diagonals). Integer
//! coordinates, so that a point planted on an edge or face is exactly on it. What the
//! checker's benches and tests plant faults in.

/// The vertices ((n + 1)^3, x fastest) and the 6 n^3 tetrahedra, positive in halo4d's
/// orientation, of the cube [0, n]^3.
pub fn kuhn_cube(n: u32) -> (Vec<[f64; 3]>, Vec<[u32; 4]>) {
    let m = n + 1;
    let id = |x: u32, y: u32, z: u32| x + m * (y + m * z);
    let positions = (0..m * m * m)
        .map(|i| [(i % m) as f64, (i / m % m) as f64, (i / (m * m)) as f64])
        .collect();
    // Each path from corner 0 to corner 7 along the axes in one order; its parity sets the
    // orientation.
    const ORDERS: [([usize; 3], bool); 6] = [
        ([0, 1, 2], false),
        ([0, 2, 1], true),
        ([1, 0, 2], true),
        ([1, 2, 0], false),
        ([2, 0, 1], false),
        ([2, 1, 0], true),
    ];
    let mut tets = Vec::with_capacity(6 * (n as usize).pow(3));
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                for (order, odd) in ORDERS {
                    let mut at = [x, y, z];
                    let mut tet = [id(x, y, z), 0, 0, 0];
                    for (k, &axis) in order.iter().enumerate() {
                        at[axis] += 1;
                        tet[k + 1] = id(at[0], at[1], at[2]);
                    }
                    // The path along x, y, z turns (1,0,0), (1,1,0), (1,1,1) clockwise
                    // seen from the corner: negative in halo4d's orientation.
                    if !odd {
                        tet.swap(2, 3);
                    }
                    tets.push(tet);
                }
            }
        }
    }
    (positions, tets)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_tetrahedron_of_the_cube_is_positive_and_the_cube_is_certified() {
        let (p, t) = kuhn_cube(3);
        assert_eq!((p.len(), t.len()), (64, 162));
        let c = super::super::certify(&p, &t);
        assert_eq!(c.stats.inverted + c.stats.flat, 0);
        assert!(c.failures().is_empty(), "{:?}", c.failures());
        assert_eq!(c.boundary.faces, 6 * 9 * 2);
        assert!(
            (c.stats.volume - 27.0).abs() < 1e-12 * 27.0,
            "{}",
            c.stats.volume
        );
    }
}
