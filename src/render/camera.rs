//! The 3D orbit camera: eye rays through pixels, and points projected back to pixels.

use super::{CameraProjection, CameraSettings, RenderError};
use glam::DVec3;

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
    /// The camera of `settings` around the box `[lo, hi]`, for an image of `width` x
    /// `height`, turned by `azimuth_offset` degrees (for the second eye of a stereo pair).
    pub fn new(
        settings: &CameraSettings,
        (lo, hi): (DVec3, DVec3),
        width: u32,
        height: u32,
        azimuth_offset: f64,
    ) -> Result<Camera, RenderError> {
        let centre = (lo + hi) * 0.5;
        let radius = ((hi - lo).length() * 0.5).max(f64::MIN_POSITIVE);
        let (az, el) = (
            (settings.azimuth + azimuth_offset).to_radians(),
            settings.elevation.to_radians(),
        );
        // z is up; azimuth turns about z from +x, elevation rises from the xy plane.
        let towards_eye = DVec3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin());
        let eye = centre + towards_eye * settings.distance * radius;
        let inside = (0..3).all(|k| eye[k] > lo[k] && eye[k] < hi[k]);
        if inside && settings.projection == CameraProjection::Orthographic {
            return Err(RenderError::CameraInside {
                distance: settings.distance,
            });
        }
        let forward = -towards_eye;
        let right = forward.cross(DVec3::Z).try_normalize().unwrap_or(DVec3::Y);
        let up = right.cross(forward);
        let half_height = match settings.projection {
            CameraProjection::Perspective => (settings.fov.to_radians() * 0.5).tan(),
            CameraProjection::Orthographic => radius * 1.05,
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
