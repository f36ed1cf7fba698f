//! Double points between two boxes of parameters that do not touch: the arcs of
//! G(p, q) = f(p) - f(q) = 0 in a box X = A × B of (u1, v1, u2, v2), proven one by one.
//!
//! After Snyder (*Interval analysis for computer graphics*, SIGGRAPH 1992): where the 3×3
//! minor of G's Jacobian without the column of one coordinate t is regular over all of X
//! ([`regular`]), G(t, y) = 0 has at most one solution y for each t (G(t, y1) - G(t, y2) =
//! M (y1 - y2) with M in the minor's enclosure), so the solutions in X are arcs that are
//! graphs over disjoint intervals of t, each with both ends on X's boundary (no end inside:
//! every point is regular; no loop: a graph over t does not close). The ends are the
//! solutions of G = 0 on the eight faces of X, three equations in three unknowns each,
//! found and proven unique by Krawczyk's test on a subdivision of the face. Sorted by t,
//! the ends pair up, the first with the second, the third with the fourth: those are the
//! arcs. Where no minor is regular (the two sheets may be tangent, or the box is too large),
//! or a face point cannot be proven (it lies on the face's edge), the box is split.

use super::system::{I, Image, Krawczyk, M3, Projector, V3, krawczyk, regular, sub};

/// A point of the boxes' boundary where an arc ends.
#[derive(Clone, Copy, Debug)]
pub(super) struct End {
    /// Its enclosure in (u1, v1, u2, v2), tight (Krawczyk's operator iterated).
    pub x: [I; 4],
    /// The box of the face in which it is proven the only solution.
    pub unique: [I; 4],
    /// The coordinate held fixed on its face.
    pub face: usize,
}

/// What became of a box.
pub(super) enum Outcome {
    /// No double point in it.
    Empty,
    /// Exactly these arcs, by their ends.
    Arcs(Vec<[End; 2]>),
    /// Not decided at this size.
    Split(Why),
}

/// Why a box was not decided.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Why {
    /// No 3×3 minor of the Jacobian is regular over the box.
    Singular,
    /// A face's solutions could not all be proven (one on the face's edge, or too many).
    Face,
}

/// The two sheets of a box: f1 on `a`'s patch, f2 on `b`'s.
pub(super) struct Pair<'a> {
    pub a: &'a Projector<'a>,
    pub pa: usize,
    pub b: &'a Projector<'a>,
    pub pb: usize,
}

impl Pair<'_> {
    /// G over `x` and its Jacobian's columns (∂/∂u1, ∂/∂v1, ∂/∂u2, ∂/∂v2).
    fn eval(&self, x: &[I; 4]) -> (V3, [V3; 4]) {
        let fa = self.a.image(self.pa, x[0], x[1]);
        let fb = self.b.image(self.pb, x[2], x[3]);
        system(&fa, &fb)
    }

    /// The value of G at a point (as intervals).
    fn value(&self, x: &[f64; 4]) -> V3 {
        let fa = self.a.image(self.pa, I::point(x[0]), I::point(x[1]));
        let fb = self.b.image(self.pb, I::point(x[2]), I::point(x[3]));
        sub(fa.p, fb.p)
    }
}

/// G and its Jacobian's columns from the enclosures of both sheets over a box.
fn system(fa: &Image, fb: &Image) -> (V3, [V3; 4]) {
    let neg = |a: V3| a.map(|c| -c);
    (sub(fa.p, fb.p), [fa.du, fa.dv, neg(fb.du), neg(fb.dv)])
}

/// The minor of the columns `cols` without column `skip`, by rows.
fn minor(cols: &[V3; 4], skip: usize) -> M3 {
    let keep: Vec<usize> = (0..4).filter(|&k| k != skip).collect();
    std::array::from_fn(|r| std::array::from_fn(|s| cols[keep[s]][r]))
}

/// The three coordinates other than `skip`.
fn free(skip: usize) -> [usize; 3] {
    let mut out = [0; 3];
    for (n, k) in (0..4).filter(|&k| k != skip).enumerate() {
        out[n] = k;
    }
    out
}

/// Where a face or a box is split, a share of its extent: not the middle, so that points
/// at symmetric parameters (π, 0, the middle of a patch) do not fall on the cuts.
pub(super) const SPLIT: f64 = 0.5 + 0.0371;

/// Face boxes examined on one face at most before the box is split.
const FACE_BOXES: usize = 96;

/// Krawczyk steps that tighten a proven point.
const TIGHTEN: usize = 6;

/// The arcs of double points in `x` (see the module documentation), from the enclosures
/// `fa` and `fb` of both sheets over it; `work` counts the enclosures computed.
pub(super) fn arcs(pair: &Pair, x: [I; 4], fa: &Image, fb: &Image, work: &mut usize) -> Outcome {
    let (g, cols) = system(fa, fb);
    if super::system::nonzero(&g) {
        return Outcome::Empty;
    }
    // The coordinate the arcs are graphs over: the best conditioned regular minor.
    let Some(t) = (0..4)
        .filter_map(|k| regular(&minor(&cols, k)).map(|r| (k, r.2)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(k, _)| k)
    else {
        return Outcome::Split(Why::Singular);
    };
    let mut ends = Vec::new();
    for face in 0..4 {
        for c in [x[face].lo(), x[face].hi()] {
            let mut on = x;
            on[face] = I::point(c);
            match solve_face(pair, on, face, work) {
                Some(points) => ends.extend(points),
                None => return Outcome::Split(Why::Face),
            }
        }
    }
    ends.sort_by(|a, b| a.x[t].mid().total_cmp(&b.x[t].mid()));
    // Two ends at one t would be one point (at most one solution per t): a point on an
    // edge of the box, seen from two faces. Undecided at this size.
    if ends.len() % 2 == 1 || ends.windows(2).any(|w| w[0].x[t].meets(w[1].x[t])) {
        return Outcome::Split(Why::Face);
    }
    Outcome::Arcs(ends.chunks(2).map(|c| [c[0], c[1]]).collect())
}

/// Every solution of G = 0 on the face `on` (coordinate `face` fixed), each proven the only
/// one in its part of the face; `None` when some part could not be decided.
fn solve_face(pair: &Pair, on: [I; 4], face: usize, work: &mut usize) -> Option<Vec<End>> {
    let coords = free(face);
    let mut out = Vec::new();
    let mut stack = vec![on];
    let mut boxes = 0;
    while let Some(z) = stack.pop() {
        boxes += 1;
        if boxes > FACE_BOXES {
            return None;
        }
        let (g, cols) = pair.eval(&z);
        *work += 1;
        if super::system::nonzero(&g) {
            continue;
        }
        let zf = coords.map(|k| z[k]);
        let verdict = regular(&minor(&cols, face)).map(|pre| {
            let c = zf.map(I::mid);
            let mut at = z.map(I::mid);
            for (n, &k) in coords.iter().enumerate() {
                at[k] = c[n];
            }
            at[face] = z[face].lo();
            *work += 1;
            krawczyk(zf, c, pair.value(&at), &pre)
        });
        match verdict {
            Some(Krawczyk::None) => {}
            Some(Krawczyk::One(k)) => out.push(tighten(pair, z, k, face, work)),
            _ => {
                // Split the widest of the free coordinates.
                let (n, _) = zf
                    .iter()
                    .enumerate()
                    .map(|(n, i)| (n, i.width()))
                    .fold((0, -1.0), |m, (n, w)| if w > m.1 { (n, w) } else { m });
                let k = coords[n];
                let cut = z[k].lo() + (z[k].hi() - z[k].lo()) * SPLIT;
                if !(z[k].lo() < cut && cut < z[k].hi()) {
                    return None;
                }
                let (mut lo, mut hi) = (z, z);
                lo[k] = I::new(z[k].lo(), cut);
                hi[k] = I::new(cut, z[k].hi());
                stack.push(hi);
                stack.push(lo);
            }
        }
    }
    Some(out)
}

/// A proven face point: Krawczyk's operator iterated from `k` (inside `z`) to a tight box.
fn tighten(pair: &Pair, z: [I; 4], k: [I; 3], face: usize, work: &mut usize) -> End {
    let coords = free(face);
    let mut tight = z;
    for (n, &c) in coords.iter().enumerate() {
        tight[c] = k[n];
    }
    for _ in 0..TIGHTEN {
        let (_, cols) = pair.eval(&tight);
        *work += 1;
        let Some(pre) = regular(&minor(&cols, face)) else {
            break;
        };
        let zf = coords.map(|c| tight[c]);
        let c = zf.map(I::mid);
        let mut at = tight.map(I::mid);
        for (n, &k) in coords.iter().enumerate() {
            at[k] = c[n];
        }
        at[face] = z[face].lo();
        *work += 1;
        let next = match krawczyk(zf, c, pair.value(&at), &pre) {
            Krawczyk::One(k) | Krawczyk::Unknown(k) => k,
            Krawczyk::None => break,
        };
        let narrower = (0..3).any(|n| next[n].width() < 0.5 * zf[n].width());
        for (n, &c) in coords.iter().enumerate() {
            tight[c] = next[n].intersect(zf[n]).unwrap_or(zf[n]);
        }
        if !narrower {
            break;
        }
    }
    End {
        x: tight,
        unique: z,
        face,
    }
}
