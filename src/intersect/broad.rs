//! Broad phase: pairs of triangles whose bounding boxes touch, from an obvhs BVH traversed
//! against itself.
//!
//! obvhs stores f32 boxes; each f64 box is rounded outward so that no touching pair is lost.

use glam::{DVec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::ploc::{PlocBuilder, PlocSearchDistance, SortPrecision};
use rayon::prelude::*;

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

/// Node pairs the parallel descent hands out as tasks, at least: enough for the
/// work-stealing pool to balance uneven subtrees on many cores, few enough that each is worth
/// a task. A constant, so that the tasks, and the order of the pairs, do not depend on the
/// number of threads.
const TASKS: usize = 1024;

/// Every two primitives whose boxes touch, (i, j) with i < j, found by a simultaneous
/// descent of the tree against itself (each node pair visited once) on the cores: `pair`
/// adds a pair to the value `init` makes for each task, and the values come back in the
/// order of the pairs they hold. Concatenated, they are the pairs in the order of a
/// depth-first descent on one core, whatever the number of threads.
pub fn self_pairs_par<T: Send>(
    bvh: &Bvh2,
    boxes: &[Aabb],
    init: impl Fn() -> T + Sync,
    pair: impl Fn(&mut T, u32, u32) + Sync,
) -> Vec<T> {
    split_descent(bvh, boxes, TASKS, init, pair)
}

/// What a depth-first descent finds from a node pair is what that pair itself gives (the
/// primitive pairs of two leaves) followed by what the descents from the node pairs it
/// pushes find, the last pushed first. So the root is expanded in place, level by level,
/// into a list in that order of found pairs and node pairs still to descend, until it
/// holds `tasks` of the latter (or none); their descents then run on the cores.
fn split_descent<T: Send>(
    bvh: &Bvh2,
    boxes: &[Aabb],
    tasks: usize,
    init: impl Fn() -> T + Sync,
    pair: impl Fn(&mut T, u32, u32) + Sync,
) -> Vec<T> {
    enum Item<T> {
        Found(T),
        Descend((u32, u32)),
    }
    if bvh.nodes.is_empty() {
        return Vec::new();
    }
    let mut items = vec![Item::Descend((0, 0))];
    let pending = |items: &[Item<T>]| {
        items
            .iter()
            .filter(|i| matches!(i, Item::Descend(_)))
            .count()
    };
    while (1..tasks).contains(&pending(&items)) {
        let mut next = Vec::with_capacity(3 * items.len());
        for item in items {
            let Item::Descend(node_pair) = item else {
                next.push(item);
                continue;
            };
            let mut found = init();
            let mut pushed = Vec::new();
            step(
                bvh,
                boxes,
                node_pair,
                &mut |a, b| pair(&mut found, a, b),
                &mut pushed,
            );
            next.push(Item::Found(found));
            next.extend(pushed.into_iter().rev().map(Item::Descend));
        }
        items = next;
    }
    items
        .into_par_iter()
        .map(|item| match item {
            Item::Found(found) => found,
            Item::Descend(node_pair) => {
                let mut found = init();
                descend(bvh, boxes, node_pair, &mut |a, b| pair(&mut found, a, b));
                found
            }
        })
        .collect()
}

/// The depth-first descent from a node pair.
fn descend(bvh: &Bvh2, boxes: &[Aabb], from: (u32, u32), pair: &mut dyn FnMut(u32, u32)) {
    let mut stack = vec![from];
    while let Some(node_pair) = stack.pop() {
        step(bvh, boxes, node_pair, pair, &mut stack);
    }
}

/// One step of the descent: the primitive pairs whose boxes touch where both nodes are the
/// same leaf or two leaves, or else the node pairs to descend to, pushed on `stack`.
fn step(
    bvh: &Bvh2,
    boxes: &[Aabb],
    (i, j): (u32, u32),
    pair: &mut dyn FnMut(u32, u32),
    stack: &mut Vec<(u32, u32)>,
) {
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
        return;
    }
    if !ni.aabb().intersect_aabb(nj.aabb()) {
        return;
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
            descend(&bvh, &boxes, (0, 0), &mut |a, b| fast.push((a, b)));
            fast.sort_unstable();
            let mut slow = Vec::new();
            for a in 0..boxes.len() as u32 {
                for b in a + 1..boxes.len() as u32 {
                    if boxes[a as usize].intersect_aabb(&boxes[b as usize]) {
                        slow.push((a, b));
                    }
                }
            }
            // On the cores, however the descent is split: the same pairs in the same order.
            let mut ordered = Vec::new();
            descend(&bvh, &boxes, (0, 0), &mut |a, b| ordered.push((a, b)));
            for tasks in [1, 2, 7, 64, TASKS] {
                let split = split_descent(&bvh, &boxes, tasks, Vec::new, |v, a, b| v.push((a, b)));
                assert!(split.len() >= tasks.min(64), "{tasks}: {}", split.len());
                assert_eq!(split.concat(), ordered, "leaf size {leaf}, {tasks} tasks");
            }
            assert_eq!(fast, slow, "leaf size {leaf}");
        }
    }
}
