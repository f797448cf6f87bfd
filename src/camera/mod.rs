//! The camera: where it stands and looks, its lens, its projection
//! (`projection`) and the ray through each pixel (a pinhole's or another
//! projection's, or a thin lens's from a point on the aperture), for one
//! eye or two.

mod projection;

pub use projection::{Projection, Stereo, StereoLayout};

use crate::exact::{Coordinates, Digits};
use crate::march::Ray;
use crate::math::{normalize_or, DVec3, Real};
use serde::{Deserialize, Serialize};

/// A camera: a pinhole, or a thin lens when its aperture is open.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(from = "CameraForm", into = "CameraForm")]
pub struct Camera {
    pub position: DVec3,
    pub target: DVec3,
    /// The digits of `position` and of `target` where the timeline wrote
    /// them as strings, for deep frames (`crate::exact`).
    pub position_digits: Option<Digits>,
    pub target_digits: Option<Digits>,
    /// The position relative to the target, exactly, where `camera.distance`
    /// placed the camera: `position` is `target` plus this, rounded, which
    /// keeps nothing of it once it is below f64's resolution of `target`.
    pub offset: Option<DVec3>,
    /// Approximate up direction; the true up is made perpendicular to the view.
    pub up: DVec3,
    /// Rotation about the viewing direction, counter-clockwise as seen by the camera.
    pub roll_degrees: Real,
    /// Vertical field of view.
    pub fov_degrees: Real,
    /// Radius of the thin lens; 0 (the default) is a pinhole with no depth of field.
    pub aperture_radius: Real,
    /// Distance along the view direction that is in focus [default: the target's].
    pub focus_distance: Option<Real>,
    /// How image positions map to directions (`fov_degrees` is the
    /// perspective's alone).
    pub projection: Projection,
    /// Two eyes side by side or one above the other, or one eye.
    pub stereo: Option<Stereo>,
}

impl Default for Camera {
    fn default() -> Self {
        Camera {
            position: DVec3::new(0.0, 0.6, 2.6),
            target: DVec3::ZERO,
            up: DVec3::Y,
            roll_degrees: 0.0,
            fov_degrees: 45.0,
            aperture_radius: 0.0,
            focus_distance: None,
            projection: Projection::Perspective,
            stereo: None,
            position_digits: None,
            target_digits: None,
            offset: None,
        }
    }
}

/// The camera as a timeline writes it: position and target may be numbers
/// or strings of digits.
#[derive(Serialize, Deserialize)]
#[serde(rename = "Camera", deny_unknown_fields, default)]
struct CameraForm {
    position: Coordinates,
    target: Coordinates,
    up: DVec3,
    roll_degrees: Real,
    fov_degrees: Real,
    aperture_radius: Real,
    focus_distance: Option<Real>,
    /// Left out of a scene's hash when they are the defaults, so frames of
    /// every timeline without them keep their hashes.
    #[serde(skip_serializing_if = "Projection::is_perspective")]
    projection: Projection,
    #[serde(skip_serializing_if = "Option::is_none")]
    stereo: Option<Stereo>,
    /// Written into a scene's hash only where f64 cannot hold the position
    /// (`Camera::offset`), so frames of ordinary zooms keep their hashes.
    #[serde(skip_deserializing, skip_serializing_if = "Option::is_none")]
    offset: Option<DVec3>,
}

impl Default for CameraForm {
    fn default() -> Self {
        Camera::default().into()
    }
}

impl From<CameraForm> for Camera {
    fn from(form: CameraForm) -> Camera {
        Camera {
            position: form.position.value,
            target: form.target.value,
            position_digits: form.position.digits,
            target_digits: form.target.digits,
            up: form.up,
            roll_degrees: form.roll_degrees,
            fov_degrees: form.fov_degrees,
            aperture_radius: form.aperture_radius,
            focus_distance: form.focus_distance,
            projection: form.projection,
            stereo: form.stereo,
            offset: None,
        }
    }
}

impl From<Camera> for CameraForm {
    fn from(c: Camera) -> CameraForm {
        let offset = c.offset.filter(|o| c.unresolved(*o));
        CameraForm {
            position: Coordinates {
                value: c.position,
                digits: c.position_digits,
            },
            target: Coordinates {
                value: c.target,
                digits: c.target_digits,
            },
            up: c.up,
            roll_degrees: c.roll_degrees,
            fov_degrees: c.fov_degrees,
            aperture_radius: c.aperture_radius,
            focus_distance: c.focus_distance,
            projection: c.projection,
            stereo: c.stereo,
            offset,
        }
    }
}

/// An offset below this share of the target's size is written into the
/// scene's hash: f64's position keeps only a few of its bits.
const OFFSET_IN_HASH: Real = 1.0 / (1u64 << 30) as Real;

impl Camera {
    /// Whether `offset` from the target is below what f64 positions keep
    /// of it (`OFFSET_IN_HASH` of the target's size).
    fn unresolved(&self, offset: DVec3) -> bool {
        let scale = self.target.abs().max_element();
        offset.abs().max_element() < OFFSET_IN_HASH * scale
    }

    /// The position's digits where `camera.distance` placed it nearer the
    /// target than its f64 keeps apart: the target's digits (or its f64,
    /// exactly) moved by the offset.
    pub fn placed_position_digits(&self) -> Option<[String; 3]> {
        let offset = self.offset.filter(|o| self.unresolved(*o))?;
        let target = self.target.to_array();
        let anchor = |i: usize| match &self.target_digits {
            Some(d) => d[i].clone(),
            None => crate::exact::f64_digits(target[i]),
        };
        Some([0, 1, 2].map(|i| crate::exact::moved(&anchor(i), offset[i])))
    }

    /// The position relative to the target as exactly as the scene knows
    /// it: `offset`, or the difference of the digits (or of the f64 values,
    /// which is exact where they are close) computed in `bits`.
    pub fn relative_position(&self) -> DVec3 {
        if let Some(offset) = self.offset {
            return offset;
        }
        crate::exact::difference(
            (self.position, self.position_digits.as_ref()),
            (self.target, self.target_digits.as_ref()),
        )
    }

    /// How far the camera is from its target, as exactly as the scene
    /// knows it (`relative_position`), at any depth.
    pub fn distance(&self) -> Real {
        crate::math::length(self.relative_position())
    }

    /// The size of one eye's image in a `width`×`height` image (the image
    /// itself without stereo), at least 1×1.
    pub fn eye_size(&self, [width, height]: [u32; 2]) -> [u32; 2] {
        let (w, h) = match self.stereo.map(|s| s.layout) {
            Some(StereoLayout::SideBySide) => (width / 2, height),
            Some(StereoLayout::TopBottom) => (width, height / 2),
            None => (width, height),
        };
        [w.max(1), h.max(1)]
    }

    /// Why a `width`×`height` image cannot hold this camera's stereo pair,
    /// if it cannot: a side a pair splits must be even, or one eye would
    /// have a column (or row) more than the other.
    pub fn uneven_eyes(&self, [width, height]: [u32; 2]) -> Option<String> {
        let (side, length, layout) = match self.stereo.map(|s| s.layout) {
            Some(StereoLayout::SideBySide) => ("width", width, "SideBySide"),
            Some(StereoLayout::TopBottom) => ("height", height, "TopBottom"),
            None => return None,
        };
        (length % 2 == 1).then(|| {
            format!(
                "a {layout} stereo pair splits the {side} in two halves, so it must be \
                 even, got {width}x{height}"
            )
        })
    }

    /// `width`×`height` with the side a stereo pair splits rounded down to
    /// an even length (at least 2), for sizes derived from the one given.
    pub fn even_eyes(&self, [width, height]: [u32; 2]) -> [u32; 2] {
        let even = |n: u32| (n & !1).max(2);
        match self.stereo.map(|s| s.layout) {
            Some(StereoLayout::SideBySide) => [even(width), height],
            Some(StereoLayout::TopBottom) => [width, even(height)],
            None => [width, height],
        }
    }

    /// The angle a pixel spans on the view's axis in a `width`×`height`
    /// image (of one eye where the image holds two).
    pub fn axis_pixel_angle(&self, [width, height]: [u32; 2]) -> Real {
        let mono = Camera {
            stereo: None,
            ..self.clone()
        };
        let [w, h] = self.eye_size([width, height]);
        let centre = mono.frame().ray(0.5 * w as Real, 0.5 * h as Real, w, h);
        centre.pixel_angle
    }

    /// Builds the camera's orthonormal frame. Validation guarantees position ≠
    /// target and an up vector not parallel to the view; the fallbacks only keep
    /// the maths finite.
    pub fn frame(&self) -> CameraFrame {
        let forward = normalize_or(self.target - self.position, -DVec3::Z);
        let mut right = normalize_or(forward.cross(self.up), DVec3::X);
        let mut up = right.cross(forward);
        if self.roll_degrees != 0.0 {
            let (s, c) = self.roll_degrees.to_radians().sin_cos();
            (right, up) = (right * c + up * s, up * c - right * s);
        }
        // Only a pair's eyes need the distance, exactly where digits give it.
        let half = |s: Stereo| 0.5 * s.eye_separation * self.distance();
        CameraFrame {
            origin: self.position,
            projection: self.projection,
            stereo: self.stereo.map(|s| (half(s), s.layout)),
            forward,
            right,
            up,
            tan_half_fov: (self.fov_degrees.to_radians() * 0.5).tan(),
            aperture_radius: self.aperture_radius,
            focus_distance: self
                .focus_distance
                .unwrap_or_else(|| crate::math::length(self.target - self.position)),
        }
    }
}

/// Orthonormal camera frame with the image-plane half-height, the
/// projection, and each eye's distance from the centre.
#[derive(Clone, Copy, Debug)]
pub struct CameraFrame {
    pub origin: DVec3,
    pub forward: DVec3,
    pub right: DVec3,
    pub up: DVec3,
    pub tan_half_fov: Real,
    pub aperture_radius: Real,
    pub focus_distance: Real,
    pub projection: Projection,
    /// Half the eye separation in scene units, and where the eyes lie.
    pub stereo: Option<(Real, StereoLayout)>,
}

/// One eye's part of an image: the eye (−1 left, +1 right, 0 the only
/// one), the position in its part and the part's size.
struct Eye {
    side: Real,
    x: Real,
    y: Real,
    w: Real,
    h: Real,
}

impl CameraFrame {
    /// Which eye image position (`x`, `y`) of a `width`×`height` image
    /// belongs to, and where in that eye's image it is.
    fn eye(&self, x: Real, y: Real, width: u32, height: u32) -> Eye {
        let (w, h) = (width as Real, height as Real);
        let eye = |side, x, y, w, h| Eye { side, x, y, w, h };
        match self.stereo {
            None => eye(0.0, x, y, w, h),
            Some((_, StereoLayout::SideBySide)) => {
                let half = (0.5 * w).floor();
                match x < half {
                    true => eye(-1.0, x, y, half, h),
                    false => eye(1.0, x - half, y, w - half, h),
                }
            }
            Some((_, StereoLayout::TopBottom)) => {
                let half = (0.5 * h).floor();
                match y < half {
                    true => eye(-1.0, x, y, w, half),
                    false => eye(1.0, x, y - half, w, h - half),
                }
            }
        }
    }

    /// The ray through image position (`x`, `y`) in pixels from the top-left
    /// corner (pixel centres at +0.5) of a `width`×`height` image; its
    /// origin is the eye's where the image holds two.
    pub fn ray(&self, x: Real, y: Real, width: u32, height: u32) -> Ray {
        let eye = self.eye(x, y, width, height);
        let half = self.stereo.map_or(0.0, |(half, _)| half);
        let position = [eye.x, eye.y, eye.w, eye.h];
        let d = projection::direction(self.projection, self.tan_half_fov, position);
        // Forward first: a pinhole's is 1, so its sum is the plane's exactly.
        let dir = (self.forward * d.forward + self.right * d.right + self.up * d.up).normalize();
        let pixel_angle = d.pixel_angle;
        let offset = match self.projection {
            // Omni-directional stereo: each column's eyes.
            Projection::Equirectangular => {
                let (longitude, _) = projection::longitude_latitude(eye.x, eye.y, eye.w, eye.h);
                let (r, f) = (self.right, self.forward);
                projection::ods_offset(longitude, half, eye.side, r, f)
            }
            Projection::Perspective | Projection::Fisheye { .. } => self.right * (eye.side * half),
        };
        // One eye's rays leave from the centre itself, to the bit.
        let origin = match self.stereo {
            Some(_) => self.origin + offset,
            None => self.origin,
        };
        Ray {
            origin,
            dir,
            pixel_angle,
            start_footprint: 0.0,
        }
    }

    /// Whether the pixel at (`px`, `py`) of a `width`×`height` image sees
    /// anything through its centre (outside a fisheye's circle it does not).
    pub fn covers(&self, px: u32, py: u32, width: u32, height: u32) -> bool {
        self.sees(px as Real + 0.5, py as Real + 0.5, width, height)
    }

    /// Whether image position (`x`, `y`) of a `width`×`height` image is in
    /// the picture: a sample beyond a fisheye's circle is transparent black.
    pub fn sees(&self, x: Real, y: Real, width: u32, height: u32) -> bool {
        let eye = self.eye(x, y, width, height);
        projection::covers(self.projection, eye.x, eye.y, eye.w, eye.h)
    }

    /// Whether any of the pixel at (`px`, `py`) is in the picture: a pixel
    /// wholly outside a fisheye's circle takes no rays.
    pub fn touches(&self, px: u32, py: u32, width: u32, height: u32) -> bool {
        let eye = self.eye(px as Real + 0.5, py as Real + 0.5, width, height);
        let (x, y) = (eye.x - 0.5, eye.y - 0.5);
        projection::touches(self.projection, x, y, eye.w, eye.h)
    }

    /// Whether every pixel of a `width`×`height` image sees something.
    pub fn covers_all(&self) -> bool {
        !matches!(self.projection, Projection::Fisheye { .. })
    }
}

impl CameraFrame {
    /// Whether the camera has a lens (depth of field) rather than a pinhole.
    pub fn has_lens(&self) -> bool {
        self.aperture_radius > 0.0
    }

    /// The ray through image position (`x`, `y`) from lens position (`u`, `v`)
    /// in [0, 1)²: a thin lens focused at `focus_distance`. Every lens position
    /// of one image position meets the others on the plane of focus (for a
    /// perspective; on the sphere of that radius about the eye for the
    /// other projections, whose lens faces each ray).
    pub fn lens_ray(&self, x: Real, y: Real, width: u32, height: u32, u: Real, v: Real) -> Ray {
        let pinhole = self.ray(x, y, width, height);
        if !self.has_lens() {
            return pinhole;
        }
        let (across, above, along) = match self.projection {
            Projection::Perspective => (self.right, self.up, pinhole.dir.dot(self.forward)),
            Projection::Fisheye { .. } | Projection::Equirectangular => {
                let across = crate::math::normalize_or(pinhole.dir.cross(self.up), self.right);
                (across, across.cross(pinhole.dir), 1.0)
            }
        };
        let focus = pinhole.origin + pinhole.dir * (self.focus_distance / along);
        // Uniform point on the disc (polar mapping; the sampler is stratified
        // in u already, so the mapping's distortion matters little).
        let (radius, angle) = (u.sqrt() * self.aperture_radius, std::f64::consts::TAU * v);
        let origin = pinhole.origin + (across * angle.cos() + above * angle.sin()) * radius;
        Ray {
            origin,
            dir: crate::math::direction(focus - origin),
            ..pinhole
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera {
            position: DVec3::new(0.0, 0.0, 5.0),
            target: DVec3::ZERO,
            up: DVec3::Y,
            roll_degrees: 0.0,
            fov_degrees: 90.0,
            ..Camera::default()
        }
    }

    #[test]
    fn centre_pixel_looks_at_target() {
        let f = camera().frame();
        let r = f.ray(50.0, 25.0, 100, 50);
        assert!((r.dir - -DVec3::Z).length() < 1e-12);
        assert!((r.pixel_angle - 2.0 / 50.0).abs() < 1e-12);
    }

    #[test]
    fn corners_follow_fov_and_aspect() {
        let f = camera().frame();
        // fov 90°: the top edge is at 45° up; the right edge at atan(aspect).
        let top = f.ray(50.0, 0.0, 100, 50);
        assert!((top.dir.y - (0.5f64).sqrt()).abs() < 1e-12, "{}", top.dir);
        let right = f.ray(100.0, 25.0, 100, 50);
        assert!((right.dir.x / -right.dir.z - 2.0).abs() < 1e-12);
        let left = f.ray(0.0, 25.0, 100, 50);
        assert!(left.dir.x < 0.0);
    }

    #[test]
    fn lens_rays_meet_on_the_plane_of_focus() {
        let lens = Camera {
            aperture_radius: 0.2,
            focus_distance: Some(4.0),
            ..camera()
        }
        .frame();
        let pinhole = camera().frame();
        // Without a lens, lens rays are the pinhole's.
        let a = pinhole.lens_ray(30.0, 10.0, 100, 50, 0.7, 0.2);
        assert_eq!(a.dir, pinhole.ray(30.0, 10.0, 100, 50).dir);
        let through = |u: f64, v: f64| {
            let r = lens.lens_ray(30.0, 10.0, 100, 50, u, v);
            // Where the ray crosses the plane 4 in front of the camera (z = 1).
            let t = (r.origin.z - 1.0) / -r.dir.z;
            (r.origin, r.origin + r.dir * t)
        };
        let (o1, p1) = through(0.1, 0.3);
        let (o2, p2) = through(0.9, 0.8);
        assert!(o1 != o2, "different lens positions");
        assert!((o1 - camera().position).length() <= 0.2 + 1e-12);
        assert!((p1 - p2).length() < 1e-12, "{p1} vs {p2}");
    }

    #[test]
    fn roll_rotates_the_up_vector() {
        let rolled = Camera {
            roll_degrees: 90.0,
            ..camera()
        }
        .frame();
        // Rolling 90° counter-clockwise turns the image's up towards the world's −x.
        assert!((rolled.up - -DVec3::X).length() < 1e-12, "{}", rolled.up);
        let frame = camera().frame();
        assert!(frame.right.dot(frame.up).abs() < 1e-15);
        assert!(frame.forward.dot(frame.up).abs() < 1e-15);
    }
}

#[cfg(test)]
mod projection_tests;
