//! Cutaways (`render.clip`): half-spaces of the projected 3D scene removed from the picture,
//! so that double curves a closed surface encloses come into view.
//!
//! A clip is one plane (a half-space) or two (a wedge): it removes the points p where
//! `normal · p > offset` holds for every plane, in the coordinates of the projected scene
//! (the `.ply` files' frame). Paper 001's hither clipping cuts at a distance from the eye;
//! a clip cuts along any plane. The removed part is not drawn and hides nothing; the halos
//! still hide what they hide, so the gaps at the crossings stay. The cut edges, where the
//! surfaces meet the boundary of the removed region, are drawn as lines.

use crate::limits::{FINITE, FieldError};
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// One plane of a clip: the points p with `normal · p > offset` are on its removed side.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClipPlane {
    /// A nonzero vector across the plane, pointing into the removed side.
    pub normal: [f64; 3],
    /// The plane is `normal · p = offset`.
    pub offset: f64,
}

impl ClipPlane {
    /// `normal · p - offset`: positive on the removed side.
    fn side(&self, p: DVec3) -> f64 {
        DVec3::from(self.normal).dot(p) - self.offset
    }
}

/// `render.clip`: one plane, or a list of two (a wedge); removes the points beyond every
/// plane.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "serde_json::Value", into = "Planes")]
pub struct Clip {
    first: ClipPlane,
    second: Option<ClipPlane>,
}

/// A clip as a scene file writes it: a plane, or a list of planes.
#[derive(Clone, Debug, Serialize)]
#[serde(untagged)]
enum Planes {
    One(ClipPlane),
    Many(Vec<ClipPlane>),
}

/// Read through a JSON value, so that an error names what is wrong with the plane (an
/// unknown or missing field) rather than that no form matched.
impl TryFrom<serde_json::Value> for Clip {
    type Error = String;
    fn try_from(value: serde_json::Value) -> Result<Clip, String> {
        let plane = |v: serde_json::Value| {
            serde_json::from_value::<ClipPlane>(v)
                .map_err(|e| format!("{e}; a plane is {{\"normal\": [x, y, z], \"offset\": d}}"))
        };
        match value {
            serde_json::Value::Array(v) => {
                let n = v.len();
                let mut planes = v.into_iter().map(plane);
                match (planes.next(), planes.next(), n) {
                    (Some(first), second, 1 | 2) => Ok(Clip {
                        first: first?,
                        second: second.transpose()?,
                    }),
                    _ => Err(format!(
                        "a clip is one plane (a half-space) or a list of two (a wedge), got a list of {n}"
                    )),
                }
            }
            other => Ok(Clip {
                first: plane(other)?,
                second: None,
            }),
        }
    }
}

impl From<Clip> for Planes {
    fn from(c: Clip) -> Planes {
        match c.second {
            None => Planes::One(c.first),
            Some(second) => Planes::Many(vec![c.first, second]),
        }
    }
}

impl Clip {
    /// A half-space: the points with `normal · p > offset` are removed.
    pub fn half_space(normal: [f64; 3], offset: f64) -> Clip {
        Clip {
            first: ClipPlane { normal, offset },
            second: None,
        }
    }

    /// A wedge: the points beyond both planes are removed.
    pub fn wedge(a: ClipPlane, b: ClipPlane) -> Clip {
        Clip {
            first: a,
            second: Some(b),
        }
    }

    /// Its planes.
    pub fn planes(&self) -> impl Iterator<Item = &ClipPlane> {
        std::iter::once(&self.first).chain(self.second.as_ref())
    }

    /// Checks the numbers: names the first bad field (relative to `clip`).
    pub fn check(&self) -> Result<(), FieldError> {
        for (k, p) in self.planes().enumerate() {
            let field = if self.second.is_some() {
                format!("[{k}]")
            } else {
                String::new()
            };
            let n = DVec3::from(p.normal);
            if !(n.is_finite() && n.length() > 0.0 && n.length() < 1e300) {
                return Err(FieldError::new(
                    format!("{field}.normal").trim_start_matches('.'),
                    format!(
                        "must be three finite numbers, not all 0 (a direction across the plane, into the removed side), got {:?}",
                        p.normal
                    ),
                ));
            }
            FINITE.check(format!("{field}.offset").trim_start_matches('.'), p.offset)?;
        }
        Ok(())
    }

    /// Whether the clip removes `p`.
    pub fn removes(&self, p: DVec3) -> bool {
        self.planes().all(|plane| plane.side(p) > 0.0)
    }

    /// Where triangle `p` meets the boundary of the removed region: at most one segment per
    /// plane, the part of the triangle's cut by that plane that lies beyond the other plane.
    /// A corner counts as removed exactly where [`Clip::removes`] says so for the plane, so
    /// the cuts of two triangles sharing an edge meet.
    pub fn cut_edges(&self, p: [DVec3; 3], out: &mut Vec<[DVec3; 2]>) {
        let planes: Vec<&ClipPlane> = self.planes().collect();
        for (k, plane) in planes.iter().enumerate() {
            let s = p.map(|q| plane.side(q));
            let mut ends = Vec::with_capacity(2);
            for i in 0..3 {
                let j = (i + 1) % 3;
                if (s[i] > 0.0) != (s[j] > 0.0) {
                    let f = s[i] / (s[i] - s[j]);
                    ends.push(p[i] + (p[j] - p[i]) * f);
                }
            }
            let [a, b] = ends[..] else { continue };
            // The part beyond the other plane of a wedge.
            let (mut lo, mut hi) = (0.0f64, 1.0f64);
            if let Some(other) = planes.get(1 - k).filter(|_| planes.len() == 2) {
                let (sa, sb) = (other.side(a), other.side(b));
                match (sa > 0.0, sb > 0.0) {
                    (true, true) => {}
                    (false, false) => continue,
                    (true, false) => hi = sa / (sa - sb),
                    (false, true) => lo = sa / (sa - sb),
                }
            }
            out.push([a + (b - a) * lo, a + (b - a) * hi]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The wedge x > 0, y > 0.
    fn quadrant() -> Clip {
        let plane = |normal| ClipPlane {
            normal,
            offset: 0.0,
        };
        Clip::wedge(plane([1.0, 0.0, 0.0]), plane([0.0, 1.0, 0.0]))
    }

    #[test]
    fn a_wedge_removes_what_is_beyond_both_planes() {
        let wedge = quadrant();
        assert!(wedge.removes(DVec3::new(1.0, 1.0, 5.0)));
        assert!(!wedge.removes(DVec3::new(1.0, -1.0, 0.0)));
        assert!(!wedge.removes(DVec3::new(-1.0, 1.0, 0.0)));
        // On a plane is kept.
        assert!(!wedge.removes(DVec3::new(0.0, 1.0, 0.0)));
    }

    #[test]
    fn cut_edges_run_along_the_boundary_of_the_removed_region() {
        // The triangle in z = 0 spanning [-1, 1]^2 roughly, cut by the wedge x > 0, y > 0:
        // the cuts are the segments of x = 0 with y > 0 and of y = 0 with x > 0.
        let wedge = quadrant();
        let t = [
            DVec3::new(-1.0, -1.0, 0.0),
            DVec3::new(3.0, -1.0, 0.0),
            DVec3::new(-1.0, 3.0, 0.0),
        ];
        let mut out = Vec::new();
        wedge.cut_edges(t, &mut out);
        assert_eq!(out.len(), 2);
        for [a, b] in out {
            let on_x = a.x.abs() < 1e-12 && b.x.abs() < 1e-12;
            let on_y = a.y.abs() < 1e-12 && b.y.abs() < 1e-12;
            assert!(on_x || on_y, "{a} {b}");
            let along = if on_x { (a.y, b.y) } else { (a.x, b.x) };
            assert!(
                along.0.min(along.1).abs() < 1e-12 && (along.0.max(along.1) - 2.0).abs() < 1e-12
            );
        }
        // A half-space: the whole cut.
        let mut out = Vec::new();
        Clip::half_space([1.0, 0.0, 0.0], 0.0).cut_edges(t, &mut out);
        assert_eq!(out.len(), 1);
        let [a, b] = out[0];
        assert!(
            ((a - b).length() - 3.0).abs() < 1e-12,
            "x = 0 across the triangle: y from -1 to 2"
        );
    }

    #[test]
    fn a_clip_reads_as_a_plane_or_a_list_of_at_most_two() {
        let one: Clip = serde_json::from_str(r#"{"normal": [0, 0, 1], "offset": 0.5}"#).unwrap();
        assert_eq!(one, Clip::half_space([0.0, 0.0, 1.0], 0.5));
        let list: Clip = serde_json::from_str(r#"[{"normal": [0, 0, 1], "offset": 0.5}]"#).unwrap();
        assert_eq!(list, one);
        let typo = r#"{"normale": [0, 0, 1], "offset": 0.5}"#;
        let e = serde_json::from_str::<Clip>(typo).unwrap_err().to_string();
        assert!(e.contains("unknown field `normale`"), "{e}");
        let three = r#"[{"normal": [0, 0, 1], "offset": 0}, {"normal": [0, 1, 0], "offset": 0}, {"normal": [1, 0, 0], "offset": 0}]"#;
        let e = serde_json::from_str::<Clip>(three).unwrap_err().to_string();
        assert!(e.contains("a list of two (a wedge)"), "{e}");
        assert!(Clip::half_space([0.0; 3], 1.0).check().is_err());
        let text = serde_json::to_string(&one).unwrap();
        assert_eq!(serde_json::from_str::<Clip>(&text).unwrap(), one);
    }
}
