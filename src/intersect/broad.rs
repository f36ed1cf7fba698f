//! Broad phase: pairs of triangles whose bounding boxes touch, from an obvhs BVH traversed
//! against itself.
//!
//! obvhs stores f32 boxes; each f64 box is rounded outward so that no touching pair is lost.

use glam::{DVec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::ploc::{PlocBuilder, PlocSearchDistance, SortPrecision};

/// The f32 box that contains every point of the f64 box `[lo, hi]`.
pub fn outward(lo: DVec3, hi: DVec3) -> Aabb {
    let down = |x: f64| {
        let f = x as f32;
        if f as f64 > x { f.next_down() } else { f }
    };
    let up = |x: f64| {
        let f = x as f32;
        if (f as f64) < x { f.next_up() } else { f }
    };
    Aabb::new(
        Vec3A::new(down(lo.x), down(lo.y), down(lo.z)),
        Vec3A::new(up(hi.x), up(hi.y), up(hi.z)),
    )
}

/// A BVH over boxes with up to `leaf` primitives per leaf.
pub fn build(boxes: &[Aabb], leaf: u32) -> Bvh2 {
    let mut bvh = PlocBuilder::with_capacity(boxes.len()).build(
        PlocSearchDistance::Minimum,
        boxes,
        (0..boxes.len() as u32).collect(),
        SortPrecision::U64,
        0,
    );
    obvhs::bvh2::leaf_collapser::collapse(&mut bvh, leaf, 1.0);
    bvh
}

/// Calls `pair(i, j)` with i < j for every two primitives whose boxes touch, by a
/// simultaneous descent of the tree against itself (each node pair visited once).
pub fn self_pairs(bvh: &Bvh2, boxes: &[Aabb], mut pair: impl FnMut(u32, u32)) {
    if bvh.nodes.is_empty() {
        return;
    }
    let leaf_prims = |n: u32| {
        let node = &bvh.nodes[n as usize];
        let first = node.first_index as usize;
        &bvh.primitive_indices[first..first + node.prim_count as usize]
    };
    let mut emit = |a: u32, b: u32| {
        if a != b && boxes[a as usize].intersect_aabb(&boxes[b as usize]) {
            pair(a.min(b), a.max(b));
        }
    };
    let mut stack: Vec<(u32, u32)> = vec![(0, 0)];
    while let Some((i, j)) = stack.pop() {
        let (ni, nj) = (&bvh.nodes[i as usize], &bvh.nodes[j as usize]);
        if i == j {
            if ni.is_leaf() {
                let prims = leaf_prims(i);
                for (k, &a) in prims.iter().enumerate() {
                    for &b in &prims[k + 1..] {
                        emit(a, b);
                    }
                }
            } else {
                let (l, r) = (ni.first_index, ni.first_index + 1);
                stack.push((l, l));
                stack.push((r, r));
                stack.push((l, r));
            }
            continue;
        }
        if !ni.aabb().intersect_aabb(nj.aabb()) {
            continue;
        }
        match (ni.is_leaf(), nj.is_leaf()) {
            (true, true) => {
                for &a in leaf_prims(i) {
                    for &b in leaf_prims(j) {
                        emit(a, b);
                    }
                }
            }
            (false, true) => {
                stack.push((ni.first_index, j));
                stack.push((ni.first_index + 1, j));
            }
            (true, false) => {
                stack.push((i, nj.first_index));
                stack.push((i, nj.first_index + 1));
            }
            (false, false) => {
                // Descend the larger box: the pair of children that touch is then smaller.
                if ni.aabb().half_area() >= nj.aabb().half_area() {
                    stack.push((ni.first_index, j));
                    stack.push((ni.first_index + 1, j));
                } else {
                    stack.push((i, nj.first_index));
                    stack.push((i, nj.first_index + 1));
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outward_boxes_contain_their_f64_box() {
        let lo = DVec3::new(0.1, -1.0 / 3.0, 1e-30);
        let hi = DVec3::new(0.7, 2.0 / 3.0, 1.0 + 1e-12);
        let b = outward(lo, hi);
        for k in 0..3 {
            assert!((b.min[k] as f64) <= lo[k] && (b.max[k] as f64) >= hi[k]);
        }
    }

    #[test]
    fn self_pairs_equal_all_pairs() {
        let mut next = crate::intersect::lcg(7);
        let boxes: Vec<Aabb> = (0..400)
            .map(|_| {
                let c = DVec3::new(next(), next(), next());
                let h = DVec3::new(next(), next(), next()) * 0.05;
                outward(c - h, c + h)
            })
            .collect();
        for leaf in [1, 4, 8] {
            let bvh = build(&boxes, leaf);
            let mut fast = Vec::new();
            self_pairs(&bvh, &boxes, |a, b| fast.push((a, b)));
            fast.sort_unstable();
            let mut slow = Vec::new();
            for a in 0..boxes.len() as u32 {
                for b in a + 1..boxes.len() as u32 {
                    if boxes[a as usize].intersect_aabb(&boxes[b as usize]) {
                        slow.push((a, b));
                    }
                }
            }
            assert_eq!(fast, slow, "leaf size {leaf}");
        }
    }
}
