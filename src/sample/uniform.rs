//! The uniform (u, v) grid sampler.

use super::{Classes, Mesh4};
use crate::surfaces::{Side, SideRule, Surface};

/// Samples every patch of `surface` on a grid of `nu` by `nv` cells (both even and at least
/// 4, as [`super::Sampling::check`] demands), welds the
/// nodes that the domain rules identify, and splits every cell into two triangles along
/// the diagonal (i, j)-(i+1, j+1), dropping the triangles that a pole collapses.
pub fn sample_uniform(surface: &Surface, nu: usize, nv: usize) -> Mesh4 {
    let patches = surface.patch_count();
    let per_patch = (nu + 1) * (nv + 1);
    let node = |patch: usize, i: usize, j: usize| patch * per_patch + j * (nu + 1) + i;
    // Nodes along a side, in the direction of its side coordinate, and their count - 1.
    let side_node = |patch: usize, side: Side, k: usize| match side {
        Side::U0 => node(patch, 0, k),
        Side::U1 => node(patch, nu, k),
        Side::V0 => node(patch, k, 0),
        Side::V1 => node(patch, k, nv),
    };
    let side_cells = |side: Side| {
        if matches!(side, Side::U0 | Side::U1) {
            nv
        } else {
            nu
        }
    };

    let mut classes = Classes((0..patches * per_patch).collect());
    let domains: Vec<_> = (0..patches).map(|p| surface.domain(p)).collect();
    for (patch, domain) in domains.iter().enumerate() {
        for side in Side::ALL {
            let n = side_cells(side);
            match domain.side(side) {
                SideRule::Open => {}
                SideRule::Pole => {
                    for k in 1..=n {
                        classes.union(side_node(patch, side, 0), side_node(patch, side, k));
                    }
                }
                SideRule::Glued(pieces) => {
                    for k in 0..=n {
                        // Piece ends and offsets are multiples of 1/2 and n is even, so a node
                        // maps exactly onto a node; a node on the end of two pieces joins both.
                        let sigma = k as f64 / n as f64;
                        for g in pieces.iter().filter(|g| g.from <= sigma && sigma <= g.to) {
                            let m = side_cells(g.side) as f64;
                            let target = g.map(sigma) * m;
                            let kt = target.round();
                            debug_assert!((target - kt).abs() < 1e-9 && kt >= 0.0 && kt <= m);
                            classes.union(
                                side_node(patch, side, k),
                                side_node(g.patch, g.side, kt as usize),
                            );
                        }
                    }
                }
            }
        }
    }

    // One vertex per class, evaluated at its representative (smallest) node.
    let mut vertex_of = vec![u32::MAX; patches * per_patch];
    let mut at = Vec::new();
    for id in 0..patches * per_patch {
        let rep = classes.find(id);
        if vertex_of[rep] == u32::MAX {
            let (patch, rest) = (rep / per_patch, rep % per_patch);
            let (i, j) = (rest % (nu + 1), rest / (nu + 1));
            let d = &domains[patch];
            let u = d.u[0] + (d.u[1] - d.u[0]) * i as f64 / nu as f64;
            let v = d.v[0] + (d.v[1] - d.v[0]) * j as f64 / nv as f64;
            vertex_of[rep] = at.len() as u32;
            at.push((patch, u, v));
        }
        vertex_of[id] = vertex_of[rep];
    }
    let mut mesh = Mesh4::default();
    mesh.push_vertices(surface, &at);

    for (patch, d) in domains.iter().enumerate() {
        let uv = |i: usize, j: usize| {
            [
                d.u[0] + (d.u[1] - d.u[0]) * i as f64 / nu as f64,
                d.v[0] + (d.v[1] - d.v[0]) * j as f64 / nv as f64,
            ]
        };
        for j in 0..nv {
            for i in 0..nu {
                let corners = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)];
                let [a, b, c, d] = corners.map(|(i, j)| vertex_of[node(patch, i, j)]);
                let [pa, pb, pc, pd] = corners.map(|(i, j)| uv(i, j));
                mesh.push_triangle([a, b, c], patch, [pa, pb, pc]);
                mesh.push_triangle([a, c, d], patch, [pa, pc, pd]);
            }
        }
    }
    mesh
}
