//! Animations: a path through 4D views and cameras, from keyframes (`animation` in a scene).
//!
//! Takes: a scene's `view` and `camera` and its `animation` (a frame count and keyframes,
//! each a time in [0, 1] with the view and camera fields it sets). Gives: the view and
//! camera of every frame ([`Animation::frame`]).
//!
//! Keys per number: every number of the view and the camera (the six plane angles, the
//! translation, the 4D eye distance, the camera's azimuth, elevation, distance and field of
//! view) follows its own path through the keyframes that set it, starting from the scene's
//! value at time 0 unless a keyframe at time 0 sets it; a number no keyframe sets keeps the
//! scene's value. So a keyframe that sets only the camera does not pin the view there, and
//! `[{"time": 1, "view": {"rotation": {"yw": 390}}}]` alone turns the scene's view from its
//! own yw to 390 degrees.
//!
//! Interpolation: each path is a monotone cubic spline (Fritsch and Carlson's piecewise
//! cubic Hermite interpolation, as scipy's `PchipInterpolator`). Why per plane angle, and
//! not a rotation interpolation (a geodesic in SO(4)):
//! - the scene speaks angles per plane, and a turn in one plane stays in that plane: a
//!   keyframe path in yw alone never moves another angle;
//! - an angle may go past 180 degrees: keyframes 0 and 360 are a whole turn, 720 two,
//!   where a geodesic takes the shortest way between two rotations (none for a whole turn);
//! - the monotone spline never overshoots: between two keys every value lies between
//!   theirs, so a path whose keyframes are valid (an elevation within ±89 degrees, a
//!   positive distance) is valid at every frame, and a value two keys share stays put;
//! - it is smooth (continuous first derivative), and with two keys it is a turn at
//!   constant speed.
//!
//! Frame k of N is at time k / (N - 1), so that the first and last frames are at times 0
//! and 1; with `loop` it is at k / N, so that a turn whose end is the start's view plus a
//! whole turn plays round without a repeated frame. After the last key of a number the path
//! keeps its value.

use crate::limits::{ANIMATION_FRAMES, Bound, FPS, FieldError, KEYFRAME_TIME, KEYFRAMES};
use crate::render::{CameraProjection, CameraSettings};
use crate::view::{Projection, View};
use serde::{Deserialize, Serialize};

/// A path through 4D views and cameras (`animation` in a scene file).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Animation {
    /// How many frames.
    pub frames: u32,
    /// Frames per second of the assembled animation.
    #[serde(default = "default_fps")]
    pub fps: u32,
    /// Whether the animation plays round: frame k at time k / frames, so that the last
    /// frame is followed by the first.
    #[serde(default, rename = "loop")]
    pub looped: bool,
    /// The keyframes, in order of time.
    pub keyframes: Vec<Keyframe>,
}

fn default_fps() -> u32 {
    24
}

/// One keyframe: a time and the view and camera fields it sets (each a key of its own
/// number's path).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Keyframe {
    /// When, in [0, 1] (0 the first frame, 1 the last).
    pub time: f64,
    /// The view's fields it sets (in the scene's `view` syntax).
    #[serde(default)]
    pub view: ViewKey,
    /// The camera's fields it sets (in the scene's `camera` syntax).
    #[serde(default)]
    pub camera: CameraKey,
}

/// The fields of a [`View`] a keyframe sets.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ViewKey {
    /// Plane angles in degrees.
    #[serde(skip_serializing_if = "RotationKey::is_empty")]
    pub rotation: RotationKey,
    /// Translation (x, y, z, w).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub translation: Option<[f64; 4]>,
    /// Projection: its type must be the scene's (a path cannot turn an orthographic
    /// projection into a perspective one); a perspective eye distance is interpolated.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub projection: Option<Projection>,
}

/// The plane angles a keyframe sets, in degrees.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RotationKey {
    /// Angle in the xy plane.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub xy: Option<f64>,
    /// Angle in the xz plane.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub xz: Option<f64>,
    /// Angle in the xw plane.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub xw: Option<f64>,
    /// Angle in the yz plane.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub yz: Option<f64>,
    /// Angle in the yw plane.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub yw: Option<f64>,
    /// Angle in the zw plane.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub zw: Option<f64>,
}

impl RotationKey {
    fn is_empty(&self) -> bool {
        *self == RotationKey::default()
    }
}

/// The fields of a [`CameraSettings`] a keyframe sets.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CameraKey {
    /// Degrees about the z axis, from +x.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub azimuth: Option<f64>,
    /// Degrees above the xy plane.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub elevation: Option<f64>,
    /// Distance in half-diagonals: only where the scene's camera gives one too (a camera
    /// without is fitted to each frame's surfaces).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub distance: Option<f64>,
    /// Vertical field of view in degrees.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fov: Option<f64>,
    /// Perspective or orthographic: must be the scene's.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub projection: Option<CameraProjection>,
}

impl Keyframe {
    /// The numbers this keyframe sets, in the order of [`channels`].
    fn channels(&self) -> [Option<f64>; CHANNELS] {
        let r = self.view.rotation;
        let t = self.view.translation;
        let eye = match self.view.projection {
            Some(Projection::Perspective { eye_distance }) => Some(eye_distance),
            _ => None,
        };
        let c = self.camera;
        [
            r.xy,
            r.xz,
            r.xw,
            r.yz,
            r.yw,
            r.zw,
            t.map(|t| t[0]),
            t.map(|t| t[1]),
            t.map(|t| t[2]),
            t.map(|t| t[3]),
            eye,
            c.azimuth,
            c.elevation,
            c.distance,
            c.fov,
        ]
    }
}

/// How many numbers of a view and a camera are interpolated.
const CHANNELS: usize = 15;

/// The numbers a path interpolates, in a fixed order: six angles, translation, the eye
/// distance (0 for an orthographic view), azimuth, elevation, distance (0 for a fitted
/// camera) and field of view.
fn channels(view: &View, camera: &CameraSettings) -> [f64; CHANNELS] {
    let r = view.rotation;
    let t = view.translation;
    let eye = match view.projection {
        Projection::Orthographic => 0.0,
        Projection::Perspective { eye_distance } => eye_distance,
    };
    [
        r.xy,
        r.xz,
        r.xw,
        r.yz,
        r.yw,
        r.zw,
        t[0],
        t[1],
        t[2],
        t[3],
        eye,
        camera.azimuth,
        camera.elevation,
        camera.distance.unwrap_or(0.0),
        camera.fov,
    ]
}

/// The view and camera of `c` (from [`channels`]), with the projection types and the
/// fitting of `view` and `camera`.
fn from_channels(
    c: [f64; CHANNELS],
    view: &View,
    camera: &CameraSettings,
) -> (View, CameraSettings) {
    let mut out = *view;
    let r = &mut out.rotation;
    [r.xy, r.xz, r.xw, r.yz, r.yw, r.zw] = [c[0], c[1], c[2], c[3], c[4], c[5]];
    out.translation = [c[6], c[7], c[8], c[9]];
    if let Projection::Perspective { eye_distance } = &mut out.projection {
        *eye_distance = c[10];
    }
    let camera = CameraSettings {
        azimuth: c[11],
        elevation: c[12],
        distance: camera.distance.map(|_| c[13]),
        fov: c[14],
        projection: camera.projection,
    };
    (out, camera)
}

impl Animation {
    /// The time of frame `k` in [0, 1].
    pub fn time(&self, k: u32) -> f64 {
        let steps = if self.looped {
            self.frames
        } else {
            self.frames.saturating_sub(1)
        };
        if steps == 0 {
            0.0
        } else {
            f64::from(k) / f64::from(steps)
        }
    }

    /// The view and camera of frame `k` (of a checked animation), from the scene's `view`
    /// and `camera`. A frame at a keyframe's time has the values that keyframe sets exactly.
    pub fn frame(&self, k: u32, view: &View, camera: &CameraSettings) -> (View, CameraSettings) {
        self.path(view, camera).at(self.time(k))
    }

    /// The interpolating path through the keyframes (of a checked animation), from the
    /// scene's `view` and `camera`: each number through the keyframes that set it, from the
    /// scene's value at time 0 unless a keyframe at time 0 sets it.
    pub fn path(&self, view: &View, camera: &CameraSettings) -> Path {
        let base = channels(view, camera);
        let keys: Vec<(f64, [Option<f64>; CHANNELS])> = self
            .keyframes
            .iter()
            .map(|k| (k.time, k.channels()))
            .collect();
        let splines = std::array::from_fn(|i| {
            let (mut t, mut y): (Vec<f64>, Vec<f64>) = keys
                .iter()
                .filter_map(|(time, c)| c[i].map(|v| (*time, v)))
                .unzip();
            if t.first().is_none_or(|&first| first > 0.0) {
                t.insert(0, 0.0);
                y.insert(0, base[i]);
            }
            Pchip::new(&t, &y)
        });
        Path {
            splines,
            view: *view,
            camera: *camera,
        }
    }

    /// Checks the animation of a scene with this `view` and `camera`: the counts, the
    /// keyframes' times and values, and every frame's view and camera. Names the first bad
    /// field (`keyframes[2].camera.elevation`).
    pub fn check(&self, view: &View, camera: &CameraSettings) -> Result<(), FieldError> {
        ANIMATION_FRAMES.check("frames", self.frames)?;
        FPS.check("fps", self.fps)?;
        KEYFRAMES.check("keyframes", self.keyframes.len())?;
        for (i, key) in self.keyframes.iter().enumerate() {
            let field = |name: &str| format!("keyframes[{i}].{name}");
            KEYFRAME_TIME.check(&field("time"), key.time)?;
            if i > 0 {
                let before = self.keyframes[i - 1].time;
                Bound {
                    lo: before,
                    lo_included: false,
                    ..KEYFRAME_TIME
                }
                .check_with(
                    &field("time"),
                    key.time,
                    &format!(
                        "later than keyframes[{}]'s time; list the keyframes in order of time",
                        i - 1
                    ),
                )?;
            }
            if let Some(p) = key.view.projection
                && std::mem::discriminant(&p) != std::mem::discriminant(&view.projection)
            {
                return Err(FieldError::new(
                    field("view.projection"),
                    "its type must be the scene's view.projection type: a path interpolates the eye distance, not the kind of projection",
                ));
            }
            if key
                .camera
                .projection
                .is_some_and(|p| p != camera.projection)
            {
                return Err(FieldError::new(
                    field("camera.projection"),
                    "must be the scene's camera.projection: a path cannot switch between perspective and orthographic",
                ));
            }
            if camera.distance.is_none() && key.camera.distance.is_some() {
                return Err(FieldError::new(
                    field("camera.distance"),
                    "the scene's camera is fitted to each frame (no camera.distance): set camera.distance in the scene too, or in no keyframe",
                ));
            }
        }
        // Every keyframe's view and camera, and every frame's.
        let path = self.path(view, camera);
        for (i, key) in self.keyframes.iter().enumerate() {
            let (v, c) = path.at(key.time);
            v.check()
                .map_err(|e| e.within(&format!("keyframes[{i}].view")))?;
            c.check()
                .map_err(|e| e.within(&format!("keyframes[{i}].camera")))?;
        }
        for k in 0..self.frames {
            let (v, c) = path.at(self.time(k));
            let field = format!("frame {k}");
            v.check()
                .map_err(|e| e.within(&format!("{field}'s view")))?;
            c.check()
                .map_err(|e| e.within(&format!("{field}'s camera")))?;
        }
        Ok(())
    }
}

/// The interpolating path of an animation: every number of the view and camera as a spline
/// of time.
#[derive(Clone, Debug)]
pub struct Path {
    splines: [Pchip; CHANNELS],
    /// The scene's view and camera, for the projection types and the fitting.
    view: View,
    camera: CameraSettings,
}

impl Path {
    /// The view and camera at time `t`.
    pub fn at(&self, t: f64) -> (View, CameraSettings) {
        from_channels(
            std::array::from_fn(|i| self.splines[i].at(t)),
            &self.view,
            &self.camera,
        )
    }
}

/// A monotone piecewise cubic Hermite interpolant (Fritsch and Carlson 1980, with scipy's
/// end slopes). Written here because it is thirty lines, and the crates that have it bring
/// a linear-algebra or finance library with them.
#[derive(Clone, Debug)]
struct Pchip {
    t: Vec<f64>,
    y: Vec<f64>,
    /// The slope at each knot.
    d: Vec<f64>,
}

impl Pchip {
    /// Through the points (t[i], y[i]); `t` strictly increasing, at least one point.
    fn new(t: &[f64], y: &[f64]) -> Pchip {
        let n = t.len();
        let h: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
        let delta: Vec<f64> = (0..n.saturating_sub(1))
            .map(|i| (y[i + 1] - y[i]) / h[i])
            .collect();
        let mut d = vec![0.0; n];
        match n {
            0 | 1 => {}
            2 => d.fill(delta[0]),
            _ => {
                for i in 1..n - 1 {
                    let (a, b) = (delta[i - 1], delta[i]);
                    if a * b > 0.0 {
                        // The weighted harmonic mean of the neighbouring secants.
                        let w1 = 2.0 * h[i] + h[i - 1];
                        let w2 = h[i] + 2.0 * h[i - 1];
                        d[i] = (w1 + w2) / (w1 / a + w2 / b);
                    }
                }
                d[0] = end_slope(h[0], h[1], delta[0], delta[1]);
                d[n - 1] = end_slope(h[n - 2], h[n - 3], delta[n - 2], delta[n - 3]);
            }
        }
        Pchip {
            t: t.to_vec(),
            y: y.to_vec(),
            d,
        }
    }

    /// The value at `t`: the end values beyond the ends, a knot's value exactly at it.
    fn at(&self, t: f64) -> f64 {
        let n = self.t.len();
        // The first knot later than t: t lies in [knot i - 1, knot i).
        let i = self.t.partition_point(|&k| k <= t);
        if i == 0 {
            return self.y[0];
        }
        if i == n || self.t[i - 1] == t {
            return self.y[i - 1];
        }
        let (k, h) = (i - 1, self.t[i] - self.t[i - 1]);
        let s = (t - self.t[k]) / h;
        let (s2, s3) = (s * s, s * s * s);
        // Hermite form written from y[k], so that a constant stays exactly constant.
        let h01 = 3.0 * s2 - 2.0 * s3;
        let h10 = s3 - 2.0 * s2 + s;
        let h11 = s3 - s2;
        self.y[k] + h01 * (self.y[i] - self.y[k]) + h * (h10 * self.d[k] + h11 * self.d[i])
    }
}

/// The slope at an end knot from the two nearest intervals (widths `h0` at the end, `h1`
/// next; secants `d0`, `d1`), limited so that the end interval stays monotone.
fn end_slope(h0: f64, h1: f64, d0: f64, d1: f64) -> f64 {
    let d = ((2.0 * h0 + h1) * d0 - h0 * d1) / (h0 + h1);
    if d.signum() != d0.signum() || d0 == 0.0 {
        0.0
    } else if d0.signum() != d1.signum() && d.abs() > 3.0 * d0.abs() {
        3.0 * d0
    } else {
        d
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn animation(json: &str) -> Animation {
        serde_json::from_str(json).expect("a valid animation")
    }

    #[test]
    fn two_keyframes_turn_at_constant_speed_and_hit_both_ends() {
        let view = View::default();
        let camera = CameraSettings::default();
        let a = animation(
            r#"{"frames": 5, "keyframes": [{"time": 0, "view": {"rotation": {"yw": 30}}},
                {"time": 1, "view": {"rotation": {"yw": 390}}}]}"#,
        );
        a.check(&view, &camera).unwrap();
        let yw: Vec<f64> = (0..5)
            .map(|k| a.frame(k, &view, &camera).0.rotation.yw)
            .collect();
        assert_eq!(yw[0], 30.0);
        assert_eq!(yw[4], 390.0);
        for (k, y) in yw.iter().enumerate() {
            assert!((y - (30.0 + 90.0 * k as f64)).abs() < 1e-12, "{yw:?}");
        }
        // Every other number keeps the scene's exactly.
        let (v, c) = a.frame(2, &view, &camera);
        assert_eq!(
            (v.rotation.xy, v.rotation.zw, v.translation),
            (0.0, 0.0, [0.0; 4])
        );
        assert_eq!(c, camera);
    }

    /// A keyframe that sets only the camera leaves the view's path alone.
    #[test]
    fn each_number_follows_the_keyframes_that_set_it() {
        let view = View {
            rotation: crate::view::Rotation4 {
                xw: 20.0,
                ..Default::default()
            },
            ..View::default()
        };
        let camera = CameraSettings::default();
        let a = animation(
            r#"{"frames": 5, "keyframes": [{"time": 0},
                {"time": 0.5, "camera": {"azimuth": 80}},
                {"time": 1, "view": {"rotation": {"xw": 380}}, "camera": {"azimuth": 35}}]}"#,
        );
        a.check(&view, &camera).unwrap();
        let (v, c) = a.frame(2, &view, &camera);
        assert!((v.rotation.xw - 200.0).abs() < 1e-9, "{}", v.rotation.xw);
        assert_eq!(c.azimuth, 80.0);
        // Set only at time 1: from the scene's value at time 0.
        let a = animation(r#"{"frames": 3, "keyframes": [{"time": 1, "camera": {"fov": 60}}]}"#);
        let fov: Vec<f64> = (0..3).map(|k| a.frame(k, &view, &camera).1.fov).collect();
        assert_eq!(fov, [38.0, 49.0, 60.0]);
    }

    #[test]
    fn a_loop_leaves_out_the_repeated_last_frame() {
        let a = animation(
            r#"{"frames": 4, "loop": true, "keyframes": [{"time": 0},
                {"time": 1, "view": {"rotation": {"xw": 360}}}]}"#,
        );
        let view = View::default();
        let camera = CameraSettings::default();
        let xw: Vec<f64> = (0..4)
            .map(|k| a.frame(k, &view, &camera).0.rotation.xw)
            .collect();
        assert_eq!(xw, [0.0, 90.0, 180.0, 270.0]);
    }

    /// Against the monotone interpolant's defining properties on a lopsided set of
    /// keyframes: through every knot, between neighbouring knots' values (no overshoot),
    /// monotone where the knots are, and a continuous slope at the inner knots.
    #[test]
    fn the_spline_passes_through_the_knots_without_overshoot() {
        let t = [0.0, 0.1, 0.15, 0.6, 0.7, 1.0];
        let y = [0.0, 10.0, 10.0, 80.0, -20.0, -19.0];
        let p = Pchip::new(&t, &y);
        for (ti, yi) in t.iter().zip(&y) {
            assert_eq!(p.at(*ti), *yi);
        }
        let steps = 10_000;
        let mut last = p.at(0.0);
        for s in 1..=steps {
            let x = f64::from(s) / f64::from(steps);
            let v = p.at(x);
            // The interval (t[k - 1], t[k]] that the step from the last x ends in.
            let k = t.partition_point(|&k| k < x).clamp(1, t.len() - 1);
            let (lo, hi) = (y[k - 1].min(y[k]), y[k - 1].max(y[k]));
            assert!(
                v >= lo - 1e-9 && v <= hi + 1e-9,
                "{v} at {x} beyond [{lo}, {hi}]"
            );
            if y[k] >= y[k - 1] {
                assert!(v >= last - 1e-9, "falls at {x}");
            } else {
                assert!(v <= last + 1e-9, "rises at {x}");
            }
            last = v;
        }
        // The flat stretch between the two 10s stays exactly flat.
        assert_eq!(p.at(0.125), 10.0);
        for &knot in &t[1..t.len() - 1] {
            let e = 1e-7;
            let left = (p.at(knot) - p.at(knot - e)) / e;
            let right = (p.at(knot + e) - p.at(knot)) / e;
            assert!(
                (left - right).abs() < 1e-2 * (1.0 + left.abs().max(right.abs())),
                "{left} {right}"
            );
        }
        // A constant is exactly constant; a line is a line.
        let c = Pchip::new(&[0.0, 0.3, 1.0], &[35.0, 35.0, 35.0]);
        assert!((0..=100).all(|s| c.at(f64::from(s) / 100.0) == 35.0));
        let l = Pchip::new(&[0.0, 0.25, 1.0], &[0.0, 90.0, 360.0]);
        assert!((0..=100).all(|s| (l.at(f64::from(s) / 100.0) - 3.6 * f64::from(s)).abs() < 1e-9));
    }

    #[test]
    fn bad_animations_name_their_field() {
        let view = View::default();
        let camera = CameraSettings::default();
        let cases = [
            (r#"{"frames": 0, "keyframes": [{"time": 0}]}"#, "frames"),
            (
                r#"{"frames": 100000, "keyframes": [{"time": 0}]}"#,
                "frames",
            ),
            (
                r#"{"frames": 2, "fps": 0, "keyframes": [{"time": 0}]}"#,
                "fps",
            ),
            (r#"{"frames": 2, "keyframes": []}"#, "keyframes"),
            (
                r#"{"frames": 2, "keyframes": [{"time": 1.5}]}"#,
                "keyframes[0].time",
            ),
            (
                r#"{"frames": 2, "keyframes": [{"time": 0.5}, {"time": 0.5}]}"#,
                "keyframes[1].time",
            ),
            (
                r#"{"frames": 2, "keyframes": [{"time": 0}, {"time": 1, "camera": {"elevation": 95}}]}"#,
                "keyframes[1].camera.elevation",
            ),
            (
                r#"{"frames": 2, "keyframes": [{"time": 0}, {"time": 1, "camera": {"distance": 3}}]}"#,
                "keyframes[1].camera.distance",
            ),
            (
                r#"{"frames": 2, "keyframes": [{"time": 1, "view": {"projection": {"type": "perspective", "eye_distance": 4}}}]}"#,
                "keyframes[0].view.projection",
            ),
            (
                r#"{"frames": 2, "keyframes": [{"time": 1, "camera": {"projection": "orthographic"}}]}"#,
                "keyframes[0].camera.projection",
            ),
        ];
        for (json, field) in cases {
            let e = animation(json).check(&view, &camera).unwrap_err();
            assert_eq!(e.field, field, "{json}: {e}");
        }
    }
}
