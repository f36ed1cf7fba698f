//! Chaining segments into curves by their shared nodes: two segments that end at the same
//! node (an edge crossing a triangle) are consecutive, so no distance tolerance is involved
//! and closed curves close.

use super::exact::{Node, Segment, Soup};
use super::{Curve, CurvePoint, End, Face};

/// The curves through `segments`, and the number of crossing nodes where more than two
/// segments meet (branches, which end every curve through them, unresolved: an edge of a
/// closed manifold mesh crosses a triangle in at most two segments). Several segments
/// ending at one mesh vertex are curves ending at a singular point of the projection (where
/// the triangles around the vertex intersect each other, as at a cross-cap, or where
/// several double curves meet, as where patches of a Fermat surface meet in a view that
/// folds them together): each ends there as at a branch point.
pub fn chain(soup: &Soup, segments: &[Segment], face: impl Fn(u32) -> Face) -> (Vec<Curve>, usize) {
    // Each segment end, sorted by node: equal nodes are adjacent.
    let mut ends: Vec<(Node, u32)> = segments
        .iter()
        .enumerate()
        .flat_map(|(i, s)| [(s.ends[0], i as u32), (s.ends[1], i as u32)])
        .collect();
    ends.sort_unstable();
    let mut groups: Vec<(usize, usize)> = Vec::new();
    let mut start = 0;
    for i in 1..=ends.len() {
        if i == ends.len() || ends[i].0 != ends[start].0 {
            groups.push((start, i));
            start = i;
        }
    }
    // For each segment end, the group of its node.
    let mut group_of = vec![[u32::MAX; 2]; segments.len()];
    for (g, &(a, b)) in groups.iter().enumerate() {
        for &(node, s) in &ends[a..b] {
            let side = usize::from(segments[s as usize].ends[0] != node);
            group_of[s as usize][side] = g as u32;
        }
    }
    let degree = |g: u32| groups[g as usize].1 - groups[g as usize].0;
    let branches = groups
        .iter()
        .filter(|&&(a, b)| b - a > 2 && matches!(ends[a].0, Node::Crossing { .. }))
        .count();
    let mut used = vec![false; segments.len()];
    let mut curves = Vec::new();
    let walk = |first: u32, from_side: usize, used: &mut [bool]| -> Curve {
        let mut points = Vec::new();
        let mut seg = first;
        let mut side = from_side;
        // Sheet labels: the triangle on each of the curve's two sheets.
        let mut sheets = segments[seg as usize].tris;
        let start_group = group_of[seg as usize][side];
        loop {
            used[seg as usize] = true;
            let s = &segments[seg as usize];
            points.push(point(soup, s.ends[side], sheets, &face));
            let next_group = group_of[seg as usize][1 - side];
            let node = s.ends[1 - side];
            let (a, b) = groups[next_group as usize];
            let next = (degree(next_group) == 2)
                .then(|| ends[a..b].iter().map(|e| e.1).find(|&o| o != seg))
                .flatten();
            match next {
                Some(n) if n == first && next_group == start_group => {
                    return Curve {
                        points,
                        closed: true,
                        ends: [End::Closed; 2],
                    };
                }
                Some(n) if !used[n as usize] => {
                    let ns = &segments[n as usize];
                    sheets = relabel(sheets, node, ns.tris);
                    side = usize::from(ns.ends[0] != node);
                    seg = n;
                }
                _ => {
                    points.push(point(soup, node, sheets, &face));
                    return Curve {
                        points,
                        closed: false,
                        ends: [
                            end_kind(s_end(segments, first, from_side), degree(start_group)),
                            end_kind(node, degree(next_group)),
                        ],
                    };
                }
            }
        }
    };
    // Open curves first, from every end that is not a pass-through.
    for s in 0..segments.len() {
        for (side, &g) in group_of[s].iter().enumerate() {
            if !used[s] && degree(g) != 2 {
                curves.push(walk(s as u32, side, &mut used));
            }
        }
    }
    for s in 0..segments.len() {
        if !used[s] {
            curves.push(walk(s as u32, 0, &mut used));
        }
    }
    (curves, branches)
}

fn s_end(segments: &[Segment], s: u32, side: usize) -> Node {
    segments[s as usize].ends[side]
}

fn end_kind(node: Node, degree: usize) -> End {
    match (node, degree) {
        (Node::Vertex(_), _) => End::BranchPoint,
        (_, d) if d > 2 => End::Branch,
        (Node::Crossing { .. }, _) => End::Boundary,
    }
}

/// Keeps the label of the triangle that continues through `node` (its face; at a vertex,
/// whichever triangle is shared) and gives the other label to the next segment's other
/// triangle.
fn relabel(sheets: [u32; 2], node: Node, next: [u32; 2]) -> [u32; 2] {
    let keep = match node {
        Node::Crossing { face, .. } => Some(face),
        Node::Vertex(_) => next.iter().copied().find(|t| sheets.contains(t)),
    };
    match keep {
        Some(k) if sheets[0] == k => [k, if next[0] == k { next[1] } else { next[0] }],
        Some(k) if sheets[1] == k => [if next[0] == k { next[1] } else { next[0] }, k],
        _ => next,
    }
}

fn point(soup: &Soup, node: Node, sheets: [u32; 2], face: &impl Fn(u32) -> Face) -> CurvePoint {
    let placed = soup.place(node);
    let [w_edge, w_face] = placed.w;
    let w = match node {
        Node::Crossing { face, .. } if sheets[0] == face => [w_face, w_edge],
        _ => [w_edge, w_face],
    };
    CurvePoint {
        position: placed.position,
        on_mesh: placed.position,
        w,
        faces: sheets.map(face),
        node,
        coplanar: placed.coplanar,
        perturbed: placed.on_plane,
    }
}
