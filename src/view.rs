//! The 4D view: rotation, translation and projection to 3D.
//!
//! Takes: a [`Mesh4`] and a [`View`]. Gives: a [`Projected`] mesh: 3D positions, the w-depth
//! of every vertex, both tangents pushed through the Jacobian of the projection, and unit
//! vertex normals.
//!
//! Rotation: six plane rotations applied in the fixed order xy, xz, xw, yz, yw, zw (the
//! first applied first), angles in degrees, each turning its first axis towards its second.
//! Then the translation. Projection: orthographic drops w; perspective puts the 4D eye on the
//! w axis at w = -eye_distance, looking towards +w, and scales x, y, z by
//! eye_distance / (w + eye_distance), so that the hyperplane w = 0 keeps its size. In both,
//! the w-depth of a vertex is its w after rotation and translation: smaller is nearer the
//! eye. A point at or behind the eye is an error, never a NaN.

use crate::limits::{EYE_DISTANCE, FINITE, FieldError};
use crate::sample::Mesh4;
use crate::surfaces::{Eval4, Jet};
use glam::{DMat4, DVec3, DVec4};
use serde::{Deserialize, Serialize};

/// Rotation angles in degrees for each of the six planes of R^4.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Rotation4 {
    /// Angle in the xy plane.
    pub xy: f64,
    /// Angle in the xz plane.
    pub xz: f64,
    /// Angle in the xw plane.
    pub xw: f64,
    /// Angle in the yz plane.
    pub yz: f64,
    /// Angle in the yw plane.
    pub yw: f64,
    /// Angle in the zw plane.
    pub zw: f64,
}

impl Rotation4 {
    /// The angles with their plane names, in the order they are applied.
    pub fn planes(&self) -> [(&'static str, f64); 6] {
        [
            ("xy", self.xy),
            ("xz", self.xz),
            ("xw", self.xw),
            ("yz", self.yz),
            ("yw", self.yw),
            ("zw", self.zw),
        ]
    }

    /// The rotation matrix: R = R_zw R_yw R_yz R_xw R_xz R_xy (R_xy acts first).
    pub fn matrix(&self) -> DMat4 {
        self.planes()
            .iter()
            .fold(DMat4::IDENTITY, |m, (name, deg)| {
                plane_rotation(name, deg.to_radians()) * m
            })
    }
}

impl Rotation4 {
    /// The angles of a rotation matrix (in the order [`Rotation4::matrix`] composes them),
    /// each in (-180, 180]: `Rotation4::from_matrix(r.matrix())` is `r`'s rotation, whatever
    /// the angles `r` wrote it with. Exact where the decomposition is not unique (an angle of
    /// ±90 degrees in xw, say): the angles left free are 0.
    ///
    /// How: xy, xz and yz fix w, and yz commutes with xw, so R = W Q with W = R_zw R_yw R_xw
    /// and Q = R_yz R_xz R_xy a rotation of x, y, z. W alone moves e_w, to
    /// (-sin xw, -cos xw sin yw, -cos xw cos yw sin zw, cos xw cos yw cos zw): the w column of
    /// R gives xw, yw and zw; Q = W^T R gives xz and yz from its z column the same way, and
    /// what is left is R_xy.
    pub fn from_matrix(m: DMat4) -> Rotation4 {
        let w = m.w_axis;
        let xw = (-w.x).clamp(-1.0, 1.0).asin();
        let yw = (-w.y).atan2(w.z.hypot(w.w));
        let zw = (-w.z).atan2(w.w);
        let outer = plane_rotation("zw", zw) * plane_rotation("yw", yw) * plane_rotation("xw", xw);
        let q = outer.transpose() * m;
        let z = q.z_axis;
        let xz = (-z.x).clamp(-1.0, 1.0).asin();
        let yz = (-z.y).atan2(z.z);
        let p = (plane_rotation("yz", yz) * plane_rotation("xz", xz)).transpose() * q;
        let xy = p.x_axis.y.atan2(p.x_axis.x);
        let deg = |a: f64| wrap_degrees(a.to_degrees());
        Rotation4 {
            xy: deg(xy),
            xz: deg(xz),
            xw: deg(xw),
            yz: deg(yz),
            yw: deg(yw),
            zw: deg(zw),
        }
    }

    /// This rotation followed by a turn of `degrees` in the plane of the unit 3D direction
    /// `towards` (in the projected space) and w, turning that direction towards w: Hanson's
    /// 4D rolling ball, a drag along `towards` on the screen.
    pub fn rolled(&self, towards: DVec3, degrees: f64) -> Rotation4 {
        let d = towards.normalize_or_zero().extend(0.0);
        let (s, c) = degrees.to_radians().sin_cos();
        let outer = |a: DVec4, b: DVec4| DMat4::from_cols(a * b.x, a * b.y, a * b.z, a * b.w);
        // x -> x + (cos - 1)((x.d) d + (x.w) w) + sin ((x.d) w - (x.w) d).
        let turn = DMat4::IDENTITY
            + (outer(d, d) + outer(DVec4::W, DVec4::W)) * (c - 1.0)
            + (outer(DVec4::W, d) - outer(d, DVec4::W)) * s;
        Rotation4::from_matrix(turn * self.matrix())
    }

    /// The angle of the plane named `name` (`xy`, `xz`, `xw`, `yz`, `yw` or `zw`).
    pub fn angle_mut(&mut self, name: &str) -> Option<&mut f64> {
        Some(match name {
            "xy" => &mut self.xy,
            "xz" => &mut self.xz,
            "xw" => &mut self.xw,
            "yz" => &mut self.yz,
            "yw" => &mut self.yw,
            "zw" => &mut self.zw,
            _ => return None,
        })
    }
}

/// An angle in degrees as the same angle in (-180, 180].
pub fn wrap_degrees(degrees: f64) -> f64 {
    let d = degrees.rem_euclid(360.0);
    if d > 180.0 { d - 360.0 } else { d }
}

/// Rotation by `angle` in the plane of axes `name` (e.g. "xw"), turning the first axis towards
/// the second.
fn plane_rotation(name: &str, angle: f64) -> DMat4 {
    let axis = |c: u8| (c - b'w' + 3) as usize % 4; // x, y, z, w -> 0, 1, 2, 3
    let (a, b) = (axis(name.as_bytes()[0]), axis(name.as_bytes()[1]));
    let (s, c) = angle.sin_cos();
    let mut cols = [DVec4::X, DVec4::Y, DVec4::Z, DVec4::W];
    cols[a][a] = c;
    cols[a][b] = s;
    cols[b][a] = -s;
    cols[b][b] = c;
    DMat4::from_cols(cols[0], cols[1], cols[2], cols[3])
}

/// Projection from R^4 to R^3.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum Projection {
    /// Drop w.
    #[default]
    Orthographic,
    /// Divide by the distance to the eye on the w axis.
    Perspective {
        /// Distance of the eye from the hyperplane w = 0 (the eye is at w = -eye_distance).
        eye_distance: f64,
    },
}

impl Projection {
    /// The w of the eye (minus infinity for orthographic projection).
    pub fn eye_w(&self) -> f64 {
        match *self {
            Projection::Orthographic => f64::NEG_INFINITY,
            Projection::Perspective { eye_distance } => -eye_distance,
        }
    }

    /// Projects a rotated and translated point: its 3D position, and the Jacobian of the
    /// projection at it as a map of 4D tangents to 3D tangents. `None` when the point is at
    /// or behind the eye (or so close to it that the position overflows).
    pub fn apply(&self, p: DVec4) -> Option<(DVec3, impl Fn(DVec4) -> DVec3 + use<>)> {
        let xyz = p.truncate();
        let (f, g) = match *self {
            Projection::Orthographic => (1.0, 0.0),
            Projection::Perspective { eye_distance: e } => {
                let depth = p.w + e;
                if depth.is_nan() || depth <= 0.0 {
                    return None;
                }
                // d(f xyz) = f dxyz - (f / depth) xyz dw, with f = e / depth.
                (e / depth, e / (depth * depth))
            }
        };
        let pos = xyz * f;
        pos.is_finite()
            .then_some((pos, move |t: DVec4| t.truncate() * f - xyz * (g * t.w)))
    }
}

/// A 4D view: rotation, then translation, then projection.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct View {
    /// Whether the rotation (and the camera's azimuth and elevation) are left to the view
    /// search, which starts from `rotation` (`"view": "auto"` in a scene file is short for
    /// `{"auto": true}`). A build finds them before anything uses the view
    /// (`halo4d::resolve_view`) and records the view found.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub auto: bool,
    /// Rotation angles in degrees.
    pub rotation: Rotation4,
    /// Translation (x, y, z, w) applied after the rotation.
    pub translation: [f64; 4],
    /// Projection to 3D.
    pub projection: Projection,
}

/// Reads a [`View`], or the string `"auto"` for `{"auto": true}` (serde's
/// `deserialize_with` for a scene's `view`).
pub fn view_or_auto<'de, D: serde::Deserializer<'de>>(d: D) -> Result<View, D::Error> {
    struct Visitor;
    impl<'de> serde::de::Visitor<'de> for Visitor {
        type Value = View;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("a view (an object with rotation, translation, projection) or \"auto\"")
        }
        fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<View, E> {
            match v {
                "auto" => Ok(View {
                    auto: true,
                    ..View::default()
                }),
                other => Err(E::invalid_value(serde::de::Unexpected::Str(other), &self)),
            }
        }
        fn visit_map<A: serde::de::MapAccess<'de>>(self, map: A) -> Result<View, A::Error> {
            View::deserialize(serde::de::value::MapAccessDeserializer::new(map))
        }
    }
    d.deserialize_any(Visitor)
}

/// A point at or behind the 4D eye.
#[derive(Debug, thiserror::Error, PartialEq)]
#[error(
    "vertex {vertex} is at w = {w} after rotation and translation, at or behind the 4D eye at w = {eye}; \
     increase view.projection.eye_distance or change view.translation"
)]
pub struct BehindEye {
    /// Index of the offending vertex.
    pub vertex: usize,
    /// Its w after rotation and translation.
    pub w: f64,
    /// The eye's w.
    pub eye: f64,
}

/// A mesh projected to 3D.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Projected {
    /// 3D positions.
    pub positions: Vec<DVec3>,
    /// w-depth of each vertex (w after rotation and translation; smaller is nearer).
    pub w: Vec<f64>,
    /// ∂/∂u of the projected position.
    pub tangent_u: Vec<DVec3>,
    /// ∂/∂v of the projected position.
    pub tangent_v: Vec<DVec3>,
    /// Unit normals (see [`View::project`]).
    pub normals: Vec<DVec3>,
}

impl Projected {
    /// The smallest and largest w-depth, or `None` for an empty mesh.
    pub fn w_range(&self) -> Option<[f64; 2]> {
        let first = *self.w.first()?;
        Some(
            self.w
                .iter()
                .fold([first, first], |[lo, hi], w| [lo.min(*w), hi.max(*w)]),
        )
    }

    /// The largest |x|, |y|, |z| or |w| when it exceeds [`MAX_COORDINATE`](crate::limits::MAX_COORDINATE) (or is not finite).
    pub fn out_of_range(&self) -> Option<f64> {
        let largest = self
            .positions
            .iter()
            .flat_map(|p| p.to_array())
            .chain(self.w.iter().copied())
            .fold(0.0f64, |m, x| {
                if x.is_finite() {
                    m.max(x.abs())
                } else {
                    f64::INFINITY
                }
            });
        (largest > crate::limits::MAX_COORDINATE).then_some(largest)
    }

    /// Axis-aligned bounding box of the 3D positions, or `None` for an empty mesh.
    pub fn bounds(&self) -> Option<(DVec3, DVec3)> {
        let first = *self.positions.first()?;
        Some(
            self.positions
                .iter()
                .fold((first, first), |(lo, hi), p| (lo.min(*p), hi.max(*p))),
        )
    }
}

impl View {
    /// Checks the numbers: names the first bad field.
    pub fn check(&self) -> Result<(), FieldError> {
        for (name, deg) in self.rotation.planes() {
            FINITE.check(&format!("rotation.{name}"), deg)?;
        }
        for (i, &t) in self.translation.iter().enumerate() {
            FINITE.check(&format!("translation[{i}]"), t)?;
        }
        if let Projection::Perspective { eye_distance } = self.projection {
            EYE_DISTANCE.check("projection.eye_distance", eye_distance)?;
        }
        Ok(())
    }

    /// Rotates and translates a point of R^4.
    pub fn transform(&self, p: DVec4) -> DVec4 {
        self.rotation.matrix() * p + DVec4::from_array(self.translation)
    }

    /// Projects a mesh. Tangents go through the Jacobian of the projection. Normals are the
    /// normalized cross product of the projected tangents (eq. 1 of paper 000); where that
    /// vanishes (poles, cross-caps of the projection, parametrization singularities) they
    /// are the normalized sum of the incident triangles' area-weighted normals, and where
    /// that vanishes too (a surface projected edge-on), +z.
    ///
    /// Positions and w are rounded to f32, the precision the files store, so that every
    /// later stage (halos, curves, the verification) works on the geometry as written and
    /// `halo4d check` on the files finds what the build found. Tangents and normals are
    /// those of the exact point.
    pub fn project(&self, mesh: &Mesh4) -> Result<Projected, BehindEye> {
        let rot = self.rotation.matrix();
        let shift = DVec4::from_array(self.translation);
        let n = mesh.vertex_count();
        let mut out = Projected {
            positions: Vec::with_capacity(n),
            w: Vec::with_capacity(n),
            tangent_u: Vec::with_capacity(n),
            tangent_v: Vec::with_capacity(n),
            normals: Vec::with_capacity(n),
        };
        for i in 0..n {
            let p = rot * mesh.positions[i] + shift;
            let (pos, jac) = self.projection.apply(p).ok_or(BehindEye {
                vertex: i,
                w: p.w,
                eye: self.projection.eye_w(),
            })?;
            out.positions.push(pos.as_vec3().as_dvec3());
            out.w.push(p.w as f32 as f64);
            out.tangent_u.push(jac(rot * mesh.tangent_u[i]));
            out.tangent_v.push(jac(rot * mesh.tangent_v[i]));
        }
        out.normals = vertex_normals(&out, &mesh.triangles);
        Ok(out)
    }
}

/// A [`View`] ready to map many surface points: its rotation matrix computed once.
#[derive(Clone, Copy, Debug)]
pub struct ViewMap {
    rotation: DMat4,
    shift: DVec4,
    projection: Projection,
}

/// A surface point mapped by a [`ViewMap`]: its 3D position, the images of its tangents, its
/// w-depth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mapped {
    /// 3D position.
    pub position: DVec3,
    /// ∂/∂u and ∂/∂v of the 3D position.
    pub tangents: [DVec3; 2],
    /// w after rotation and translation.
    pub w: f64,
}

impl ViewMap {
    /// The 3D position, projected tangents and w-depth of a surface point with its
    /// derivatives, in f64 (no rounding to the files' f32); `None` at or behind the eye.
    pub fn map(&self, e: &Eval4) -> Option<Mapped> {
        let p = self.rotation * e.p + self.shift;
        let (position, jac) = self.projection.apply(p)?;
        Some(Mapped {
            position,
            tangents: [jac(self.rotation * e.du), jac(self.rotation * e.dv)],
            w: p.w,
        })
    }

    /// The projected x, y, z and the w-depth of a surface point as jets in (u, v): exact
    /// first and second derivatives of the projected surface, through the quotient of a
    /// perspective projection. `None` at or behind the eye.
    pub fn jets(&self, e: &Eval4) -> Option<[Jet; 4]> {
        let coordinate = |i: usize| Jet {
            v: e.p[i],
            du: e.du[i],
            dv: e.dv[i],
            duu: e.duu[i],
            duv: e.duv[i],
            dvv: e.dvv[i],
        };
        let s = [0, 1, 2, 3].map(coordinate);
        let row = |j: usize| {
            (0..4).fold(Jet::constant(self.shift[j]), |acc, i| {
                acc + s[i] * self.rotation.col(i)[j]
            })
        };
        let [x, y, z, w] = [0, 1, 2, 3].map(row);
        match self.projection {
            Projection::Orthographic => Some([x, y, z, w]),
            Projection::Perspective { eye_distance } => {
                let depth = w + eye_distance;
                if depth.v.is_nan() || depth.v <= 0.0 {
                    return None;
                }
                let f = depth.recip() * eye_distance;
                Some([x * f, y * f, z * f, w])
            }
        }
    }
}

impl View {
    /// The view ready to map many points ([`ViewMap`]).
    pub fn map(&self) -> ViewMap {
        ViewMap {
            rotation: self.rotation.matrix(),
            shift: DVec4::from_array(self.translation),
            projection: self.projection,
        }
    }
}

/// Per vertex, the sum of the normals of the triangles around it, each as long as twice the
/// triangle's area: normalized, the area-weighted vertex normal of a mesh without tangents.
pub fn area_normal_sums(positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<DVec3> {
    let mut sums = vec![DVec3::ZERO; positions.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let n = (b - a).cross(c - a);
        for &i in t {
            sums[i as usize] += n;
        }
    }
    sums
}

fn vertex_normals(p: &Projected, triangles: &[[u32; 3]]) -> Vec<DVec3> {
    let face_sum = area_normal_sums(&p.positions, triangles);
    (0..p.positions.len())
        .map(|i| {
            let (tu, tv) = (p.tangent_u[i], p.tangent_v[i]);
            let n = tu.cross(tv);
            // Relative test: the tangents are not (nearly) parallel.
            if n.is_finite() && n.length() > 1e-9 * tu.length() * tv.length() {
                n.normalize()
            } else {
                face_sum[i].try_normalize().unwrap_or(DVec3::Z)
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plane_rotation_turns_first_axis_towards_second() {
        let r = plane_rotation("xw", std::f64::consts::FRAC_PI_2);
        assert!((r * DVec4::X - DVec4::W).length() < 1e-15);
        let r = plane_rotation("yz", std::f64::consts::FRAC_PI_2);
        assert!((r * DVec4::Y - DVec4::Z).length() < 1e-15);
    }

    #[test]
    fn angles_are_recovered_from_the_matrix_everywhere_even_at_gimbal_lock() {
        let mut cases = vec![
            Rotation4::default(),
            Rotation4 {
                xw: 90.0,
                yw: 30.0,
                zw: -40.0,
                ..Default::default()
            },
            Rotation4 {
                xz: -90.0,
                xy: 20.0,
                yz: 70.0,
                ..Default::default()
            },
        ];
        // Seeded angles over the whole circle (a linear congruential generator).
        let mut seed = 12345u64;
        let mut angle = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 720.0 - 360.0
        };
        for _ in 0..200 {
            cases.push(Rotation4 {
                xy: angle(),
                xz: angle(),
                xw: angle(),
                yz: angle(),
                yw: angle(),
                zw: angle(),
            });
        }
        for r in cases {
            let m = r.matrix();
            let back = Rotation4::from_matrix(m);
            assert!(
                (back.matrix() - m)
                    .to_cols_array()
                    .iter()
                    .all(|e| e.abs() < 1e-12),
                "{r:?} came back as {back:?}"
            );
            assert!(
                back.planes()
                    .iter()
                    .all(|(_, a)| (-180.0..=180.0).contains(a))
            );
        }
    }

    #[test]
    fn the_rolling_ball_turns_the_drag_direction_towards_w() {
        let start = Rotation4 {
            xy: 10.0,
            yw: 25.0,
            ..Default::default()
        };
        let towards = DVec3::new(0.6, -0.8, 0.0);
        let rolled = start.rolled(towards, 90.0);
        // A point that was at `towards` in the projected space is now on +w.
        let p = start.matrix().inverse() * towards.extend(0.0);
        assert!((rolled.matrix() * p - DVec4::W).length() < 1e-12);
        // Turning by 0 changes nothing; w itself goes to -towards.
        assert!(
            (start.rolled(towards, 0.0).matrix() - start.matrix()).abs_diff_eq(DMat4::ZERO, 1e-12)
        );
        let q = start.matrix().inverse() * DVec4::W;
        assert!((rolled.matrix() * q + towards.extend(0.0)).length() < 1e-12);
    }

    #[test]
    fn rotations_compose_in_documented_order() {
        // xy by 90° first (x -> y), then yw by 90° (y -> w): x ends on w.
        let rot = Rotation4 {
            xy: 90.0,
            yw: 90.0,
            ..Default::default()
        };
        assert!((rot.matrix() * DVec4::X - DVec4::W).length() < 1e-15);
    }
}
