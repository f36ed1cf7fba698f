//! The 3D orbit camera: where the eye stands ([`Placement`]: the scene's `camera.distance`,
//! or fitted so that the surfaces fill the picture), eye rays through pixels, and points
//! projected back to pixels.

use super::{CameraProjection, CameraSettings, RenderError};
use glam::DVec3;

/// The share of the picture's width and height a fitted camera leaves free on each side.
pub const FIT_MARGIN: f64 = 0.05;

/// The eye's distance from the point it looks at of a fitted orthographic camera, in
/// half-diagonals of the scene's bounding box (the default distance of old, well outside
/// the box; an orthographic picture does not depend on it).
pub const FITTED_ORTHOGRAPHIC_DISTANCE: f64 = 3.2;

/// The half height of an orthographic picture at a given `camera.distance`, in
/// half-diagonals: the bounding sphere and 5% more.
const ORTHOGRAPHIC_HALF_HEIGHT: f64 = 1.05;

/// The nearest a fitted perspective eye comes to the box's centre, in half-diagonals: just
/// outside the bounding sphere, so that every point of the scene lies in front of it.
const NEAREST_FITTED_EYE: f64 = 1.01;

/// A camera placed around a scene's bounding sphere.
#[derive(Clone, Copy, Debug)]
pub struct Camera {
    /// Eye position.
    pub eye: DVec3,
    /// Unit view direction.
    pub forward: DVec3,
    /// Unit right vector.
    pub right: DVec3,
    /// Unit up vector.
    pub up: DVec3,
    /// Perspective or orthographic.
    pub projection: CameraProjection,
    /// Half the image height: tan(fov / 2) in perspective, a length in orthographic.
    pub half_height: f64,
    /// Width over height.
    pub aspect: f64,
}

impl Camera {
    /// The camera of `settings` placed by `placement` (made for the same settings and
    /// picture size), for an image of `width` x `height`, turned by `azimuth_offset` degrees
    /// (for the second eye of a stereo pair).
    pub fn new(
        settings: &CameraSettings,
        placement: &Placement,
        width: u32,
        height: u32,
        azimuth_offset: f64,
    ) -> Result<Camera, RenderError> {
        let (lo, hi) = placement.bounds;
        let radius = bounding_radius(placement.bounds);
        let eye =
            placement.target + towards_eye(settings, azimuth_offset) * placement.distance * radius;
        let inside = (0..3).all(|k| eye[k] > lo[k] && eye[k] < hi[k]);
        if inside && settings.projection == CameraProjection::Orthographic {
            return Err(RenderError::CameraInside {
                distance: placement.distance,
            });
        }
        let (forward, right, up) = basis(settings, azimuth_offset);
        let half_height = match settings.projection {
            CameraProjection::Perspective => (settings.fov.to_radians() * 0.5).tan(),
            CameraProjection::Orthographic => radius * placement.half_height,
        };
        Ok(Camera {
            eye,
            forward,
            right,
            up,
            projection: settings.projection,
            half_height,
            aspect: width as f64 / height as f64,
        })
    }

    /// The ray (origin, unit direction) through image point (sx, sy) in [-1, 1]^2, sy up.
    pub fn ray(&self, sx: f64, sy: f64) -> (DVec3, DVec3) {
        let (x, y) = (sx * self.half_height * self.aspect, sy * self.half_height);
        match self.projection {
            CameraProjection::Perspective => (
                self.eye,
                (self.forward + self.right * x + self.up * y).normalize(),
            ),
            CameraProjection::Orthographic => {
                (self.eye + self.right * x + self.up * y, self.forward)
            }
        }
    }

    /// Where `p` lands in an image of `width` x `height` (pixel units, y down), and its
    /// depth along the view direction; `None` behind the eye.
    pub fn project(&self, p: DVec3, width: u32, height: u32) -> Option<([f64; 2], f64)> {
        let v = p - self.eye;
        let depth = v.dot(self.forward);
        let (x, y) = match self.projection {
            CameraProjection::Perspective => {
                if depth <= 0.0 {
                    return None;
                }
                (v.dot(self.right) / depth, v.dot(self.up) / depth)
            }
            CameraProjection::Orthographic => (v.dot(self.right), v.dot(self.up)),
        };
        let (sx, sy) = (x / (self.half_height * self.aspect), y / self.half_height);
        Some((
            [
                (sx + 1.0) * 0.5 * width as f64,
                (1.0 - sy) * 0.5 * height as f64,
            ],
            depth,
        ))
    }

    /// The eye ray (origin, unit direction) through point `p`, whose distance along it is
    /// [`Camera::ray_distance`].
    pub fn ray_to(&self, p: DVec3) -> (DVec3, DVec3) {
        let t = self.ray_distance(p);
        match self.projection {
            CameraProjection::Perspective => (self.eye, (p - self.eye) / t),
            CameraProjection::Orthographic => (p - self.forward * t, self.forward),
        }
    }

    /// The distance along a ray from this camera to `p` (what ray hits report as t).
    pub fn ray_distance(&self, p: DVec3) -> f64 {
        match self.projection {
            CameraProjection::Perspective => (p - self.eye).length(),
            CameraProjection::Orthographic => (p - self.eye).dot(self.forward),
        }
    }
}

/// Where the eye of a picture stands and how much the picture spans, shared by the eyes of
/// a stereo pair: the scene's `camera.distance`, or, where it gives none, fitted to the
/// surfaces' vertices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    /// The box the camera frames; lengths are in units of half its diagonal.
    pub bounds: (DVec3, DVec3),
    /// The point the eye looks at: the box's centre, or for a fitted camera the point that
    /// centres the surfaces in the picture.
    pub target: DVec3,
    /// The eye's distance from `target`, in half-diagonals.
    pub distance: f64,
    /// Orthographic: half the picture's height, in half-diagonals (perspective pictures
    /// span tan(fov / 2) instead).
    pub half_height: f64,
    /// Whether the placement was fitted to the vertices.
    pub fitted: bool,
}

impl Placement {
    /// The placement of `settings` around the box `bounds` of the surfaces' vertices
    /// `points`, for pictures of `width` x `height` seen from the azimuth offsets `eyes`
    /// (one per eye; `[0.0]` for a single picture).
    ///
    /// With `settings.distance` the eye looks at the box's centre from that many
    /// half-diagonals away, as it always has. Without, the camera is fitted: it looks along
    /// the settings' direction, moved across it so that the surfaces are centred in the
    /// picture, and the eye stands as near as it can (perspective), or the picture is as
    /// small as it can be (orthographic), with every point inside the picture and
    /// `FIT_MARGIN` of the picture free on each side, for every eye.
    ///
    /// A point at offsets a, b, c along right, up and forward from where the eye looks, the
    /// eye D away, lies in the picture when |a| <= kx (D + c) and |b| <= ky (D + c), with kx =
    /// tan(fov / 2) aspect (1 - 2 margin) and ky = tan(fov / 2) (1 - 2 margin) (orthographic:
    /// |a| <= kx H, |b| <= ky H with H the half height and no tangent). Across the view the
    /// eye can move by s: the points fit for some s exactly when D >= (P + Q) / 2 with P the
    /// largest a / kx - c and Q the largest -a / kx - c, and s = kx (P - Q) / 2 then centres
    /// them; the same for b. That centre is taken for the middle eye (no azimuth offset);
    /// D is then the largest |a| / kx - c and |b| / ky - c over the points seen from each
    /// eye, and no less than what keeps the eye outside the box's bounding sphere.
    pub fn new(
        settings: &CameraSettings,
        bounds: (DVec3, DVec3),
        points: impl Iterator<Item = DVec3> + Clone,
        width: u32,
        height: u32,
        eyes: &[f64],
    ) -> Placement {
        let centre = (bounds.0 + bounds.1) * 0.5;
        if let Some(distance) = settings.distance {
            return Placement {
                bounds,
                target: centre,
                distance,
                half_height: ORTHOGRAPHIC_HALF_HEIGHT,
                fitted: false,
            };
        }
        let radius = bounding_radius(bounds);
        let room = 1.0 - 2.0 * FIT_MARGIN;
        let aspect = f64::from(width) / f64::from(height);
        let perspective = settings.projection == CameraProjection::Perspective;
        let tangent = if perspective {
            (settings.fov.to_radians() * 0.5).tan()
        } else {
            1.0
        };
        let k = [tangent * aspect * room, tangent * room];
        // The depth term: c in perspective, none in orthographic.
        let along = |v: DVec3, forward: DVec3| if perspective { v.dot(forward) } else { 0.0 };
        // Where to look: the surfaces centred for the middle eye.
        let (forward, right, up) = basis(settings, 0.0);
        let mut reach = [[f64::NEG_INFINITY; 2]; 2];
        for p in points.clone() {
            let v = p - centre;
            let c = along(v, forward);
            for (axis, a) in [v.dot(right), v.dot(up)].into_iter().enumerate() {
                reach[axis][0] = reach[axis][0].max(a / k[axis] - c);
                reach[axis][1] = reach[axis][1].max(-a / k[axis] - c);
            }
        }
        let shift = |axis: usize| {
            let [p, q] = reach[axis];
            let s = k[axis] * (p - q) * 0.5;
            if s.is_finite() { s } else { 0.0 }
        };
        let target = centre + right * shift(0) + up * shift(1);
        // How far (perspective) or how wide (orthographic), for every eye.
        let mut needed = 0.0f64;
        for &offset in eyes {
            let (forward, right, up) = basis(settings, offset);
            for p in points.clone() {
                let v = p - target;
                let c = along(v, forward);
                needed = needed
                    .max(v.dot(right).abs() / k[0] - c)
                    .max(v.dot(up).abs() / k[1] - c);
            }
        }
        if perspective {
            let nearest = NEAREST_FITTED_EYE * radius + (target - centre).length();
            Placement {
                bounds,
                target,
                distance: needed.max(nearest) / radius,
                half_height: ORTHOGRAPHIC_HALF_HEIGHT,
                fitted: true,
            }
        } else {
            // All points on one line of sight: a picture a thousandth of the box.
            Placement {
                bounds,
                target,
                distance: FITTED_ORTHOGRAPHIC_DISTANCE,
                half_height: (needed / radius).max(1e-3),
                fitted: true,
            }
        }
    }
}

/// The radius of a box's bounding sphere, the unit of a camera's lengths.
pub fn bounding_radius((lo, hi): (DVec3, DVec3)) -> f64 {
    ((hi - lo).length() * 0.5).max(f64::MIN_POSITIVE)
}

/// The unit vector from the centre towards the eye of `settings` turned by
/// `azimuth_offset` degrees.
fn towards_eye(settings: &CameraSettings, azimuth_offset: f64) -> DVec3 {
    let (az, el) = (
        (settings.azimuth + azimuth_offset).to_radians(),
        settings.elevation.to_radians(),
    );
    // z is up; azimuth turns about z from +x, elevation rises from the xy plane.
    DVec3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin())
}

/// The view direction, right and up of `settings` turned by `azimuth_offset` degrees.
pub(crate) fn basis(settings: &CameraSettings, azimuth_offset: f64) -> (DVec3, DVec3, DVec3) {
    let forward = -towards_eye(settings, azimuth_offset);
    let right = forward.cross(DVec3::Z).try_normalize().unwrap_or(DVec3::Y);
    let up = right.cross(forward);
    (forward, right, up)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A seeded cloud of points in a lopsided box.
    fn cloud() -> Vec<DVec3> {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut unit = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        (0..500)
            .map(|_| DVec3::new(3.0 * unit() - 1.0, unit() * 0.5, 2.0 * unit() + 4.0))
            .collect()
    }

    fn bounds(points: &[DVec3]) -> (DVec3, DVec3) {
        points
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| {
                (lo.min(p), hi.max(p))
            })
    }

    /// The smallest and largest pixel coordinates of the points, per axis.
    fn extent(cam: &Camera, points: &[DVec3], w: u32, h: u32) -> ([f64; 2], [f64; 2]) {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for &p in points {
            let (xy, depth) = cam.project(p, w, h).expect("in front of the eye");
            assert!(depth > 0.0);
            for k in 0..2 {
                (lo[k], hi[k]) = (lo[k].min(xy[k]), hi[k].max(xy[k]));
            }
        }
        (lo, hi)
    }

    #[test]
    fn a_fitted_camera_frames_every_point_within_the_margin_and_touches_it() {
        let points = cloud();
        let b = bounds(&points);
        for projection in [
            CameraProjection::Perspective,
            CameraProjection::Orthographic,
        ] {
            for (azimuth, elevation, (w, h)) in
                [(35.0, 25.0, (400, 300)), (-120.0, -60.0, (200, 500))]
            {
                let settings = CameraSettings {
                    azimuth,
                    elevation,
                    projection,
                    ..CameraSettings::default()
                };
                for eyes in [&[0.0][..], &[2.5, -2.5]] {
                    let placement =
                        Placement::new(&settings, b, points.iter().copied(), w, h, eyes);
                    assert!(placement.fitted && placement.distance >= NEAREST_FITTED_EYE);
                    // As near as it can be: for one eye, both sides of one axis on the
                    // margin; for a pair, one side of one eye's.
                    let mut touches = false;
                    for &eye in eyes {
                        let cam = Camera::new(&settings, &placement, w, h, eye).unwrap();
                        // The same distance for both eyes of a pair.
                        let d = (cam.eye - placement.target).length() / bounding_radius(b);
                        assert!((d - placement.distance).abs() < 1e-12);
                        let (lo, hi) = extent(&cam, &points, w, h);
                        let size = [f64::from(w), f64::from(h)];
                        for k in 0..2 {
                            let margin = FIT_MARGIN * size[k];
                            assert!(
                                lo[k] >= margin - 1e-6 && hi[k] <= size[k] - margin + 1e-6,
                                "{projection:?} {azimuth} {eyes:?}: axis {k} {lo:?} {hi:?}"
                            );
                            let low = (lo[k] - margin).abs() < 1e-6;
                            let high = (hi[k] - size[k] + margin).abs() < 1e-6;
                            touches |= if eyes.len() == 1 {
                                low && high
                            } else {
                                low || high
                            };
                        }
                    }
                    assert!(
                        touches,
                        "{projection:?} {azimuth} {eyes:?}: as near as it can"
                    );
                }
            }
        }
    }

    #[test]
    fn a_given_distance_places_the_camera_as_it_always_has() {
        let points = cloud();
        let (lo, hi) = bounds(&points);
        for projection in [
            CameraProjection::Perspective,
            CameraProjection::Orthographic,
        ] {
            let settings = CameraSettings {
                distance: Some(3.2),
                projection,
                ..CameraSettings::default()
            };
            let placement = Placement::new(
                &settings,
                (lo, hi),
                points.iter().copied(),
                640,
                480,
                &[0.0],
            );
            assert!(!placement.fitted);
            let cam = Camera::new(&settings, &placement, 640, 480, 0.0).unwrap();
            let centre = (lo + hi) * 0.5;
            let radius = (hi - lo).length() * 0.5;
            let (az, el) = (35f64.to_radians(), 25f64.to_radians());
            let towards_eye = DVec3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin());
            assert_eq!(cam.eye, centre + towards_eye * 3.2 * radius);
            assert_eq!(
                cam.half_height,
                match projection {
                    CameraProjection::Perspective => (38f64.to_radians() * 0.5).tan(),
                    CameraProjection::Orthographic => radius * 1.05,
                }
            );
        }
    }

    #[test]
    fn points_seen_end_on_still_make_a_picture() {
        // Two points on the line of sight: nothing to span, but a finite camera.
        let settings = CameraSettings {
            azimuth: 0.0,
            elevation: 0.0,
            projection: CameraProjection::Orthographic,
            ..CameraSettings::default()
        };
        let points = [DVec3::new(-1.0, 0.0, 0.0), DVec3::new(1.0, 0.0, 0.0)];
        let b = bounds(&points);
        let placement = Placement::new(&settings, b, points.iter().copied(), 10, 10, &[0.0]);
        let cam = Camera::new(&settings, &placement, 10, 10, 0.0).unwrap();
        assert!(cam.half_height > 0.0 && cam.eye.is_finite());
        let settings = CameraSettings {
            projection: CameraProjection::Perspective,
            ..settings
        };
        let placement = Placement::new(&settings, b, points.iter().copied(), 10, 10, &[0.0]);
        assert!(placement.distance >= NEAREST_FITTED_EYE);
    }
}
