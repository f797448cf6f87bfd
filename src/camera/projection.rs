//! How a camera maps image positions to view directions: a pinhole's
//! plane, an equidistant fisheye's disc, or the whole sphere in latitude
//! and longitude; and stereo pairs of any of them in one image.

use crate::math::{DVec3, Real};
use serde::{Deserialize, Serialize};
use std::f64::consts::{PI, TAU};

/// The mapping from an eye's image to directions around the camera.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Projection {
    /// A pinhole over `fov_degrees` vertically (the default).
    #[default]
    Perspective,
    /// An equidistant (angular) fisheye, the dome master's convention: a
    /// disc inscribed in the image, the angle from the view axis
    /// proportional to the radius, `degrees` across its diameter (up to 360).
    Fisheye { degrees: Real },
    /// The whole sphere: longitude across (the centre looks forward, the
    /// edges behind), latitude down (the top row looks up).
    Equirectangular,
}

impl Projection {
    /// Whether this is the default, which a scene's hash leaves out.
    pub fn is_perspective(&self) -> bool {
        *self == Projection::Perspective
    }

    /// The projection's name and its angle, for `info`.
    pub fn describe(&self, fov_degrees: Real) -> String {
        match self {
            Projection::Perspective => format!("perspective, {fov_degrees}° vertically"),
            Projection::Fisheye { degrees } => {
                format!("equidistant fisheye, {degrees}° across the inscribed circle")
            }
            Projection::Equirectangular => "equirectangular, 360°×180°".into(),
        }
    }
}

/// Two eyes in one image.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Stereo {
    /// The distance between the eyes as a share of the camera–target
    /// distance, so a zoom keeps its depth: 0.0325 is a viewer two metres
    /// from something with 6.5 cm between the eyes.
    pub eye_separation: Real,
    pub layout: StereoLayout,
}

/// Where each eye's image lies in the frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum StereoLayout {
    /// The left eye in the left half, the right eye in the right half.
    SideBySide,
    /// The left eye in the top half, the right eye in the bottom half.
    TopBottom,
}

/// A view direction in the camera's frame: along `right`, `up` and
/// `forward`, with the angle a pixel subtends there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Direction {
    pub right: Real,
    pub up: Real,
    pub forward: Real,
    pub pixel_angle: Real,
}

/// The direction through image position (`x`, `y`) of a `w`×`h` eye image
/// (pixels from the top-left corner), not normalised; `tan_half_fov` is
/// the pinhole's.
pub fn direction(projection: Projection, tan_half_fov: Real, [x, y, w, h]: [Real; 4]) -> Direction {
    match projection {
        Projection::Perspective => perspective(tan_half_fov, x, y, w, h),
        Projection::Fisheye { degrees } => fisheye(degrees, x, y, w, h),
        Projection::Equirectangular => equirectangular(x, y, w, h),
    }
}

/// The pinhole's direction: through the image plane one unit ahead, which
/// spans `tan_half_fov` above and below the axis.
fn perspective(tan_half_fov: Real, x: Real, y: Real, w: Real, h: Real) -> Direction {
    Direction {
        right: (2.0 * x / w - 1.0) * tan_half_fov * (w / h),
        up: (1.0 - 2.0 * y / h) * tan_half_fov,
        forward: 1.0,
        pixel_angle: 2.0 * tan_half_fov / h,
    }
}

/// The fisheye's direction: the angle from the axis is `degrees`/2 at the
/// inscribed circle's edge, growing with the radius; the azimuth is the
/// image's. Beyond the circle the mapping goes on (jittered samples of an
/// edge pixel), past 180° from the axis included.
fn fisheye(degrees: Real, x: Real, y: Real, w: Real, h: Real) -> Direction {
    let radius = 0.5 * w.min(h);
    let (dx, dy) = (x - 0.5 * w, 0.5 * h - y);
    let r = dx.hypot(dy);
    let per_pixel = degrees.to_radians() * 0.5 / radius;
    let theta = r * per_pixel;
    let (s, c) = theta.sin_cos();
    let (cos_a, sin_a) = if r > 0.0 {
        (dx / r, dy / r)
    } else {
        (1.0, 0.0)
    };
    // The radial angle a pixel spans is the larger one (the tangential is
    // smaller by sin θ / θ), so the footprint holds the whole pixel.
    Direction {
        right: s * cos_a,
        up: s * sin_a,
        forward: c,
        pixel_angle: per_pixel,
    }
}

/// The equirectangular direction: longitude −180° to 180° across, latitude
/// 90° to −90° down.
fn equirectangular(x: Real, y: Real, w: Real, h: Real) -> Direction {
    let (longitude, latitude) = longitude_latitude(x, y, w, h);
    let (sl, cl) = longitude.sin_cos();
    let (sp, cp) = latitude.sin_cos();
    // A pixel spans π/h in latitude and 2π/w·cos φ across: the larger.
    let pixel_angle = (PI / h).max(TAU / w * cp);
    Direction {
        right: cp * sl,
        up: sp,
        forward: cp * cl,
        pixel_angle,
    }
}

/// An equirectangular image position's longitude (0 at the centre,
/// increasing to the right) and latitude (up positive), in radians.
pub fn longitude_latitude(x: Real, y: Real, w: Real, h: Real) -> (Real, Real) {
    ((x / w - 0.5) * TAU, (0.5 - y / h) * PI)
}

/// Whether image position (`x`, `y`) of a `w`×`h` eye image is in the
/// picture: outside a fisheye's circle it is not.
pub fn covers(projection: Projection, x: Real, y: Real, w: Real, h: Real) -> bool {
    match projection {
        Projection::Fisheye { .. } => {
            let (dx, dy) = (x - 0.5 * w, y - 0.5 * h);
            dx.hypot(dy) <= 0.5 * w.min(h)
        }
        Projection::Perspective | Projection::Equirectangular => true,
    }
}

/// Whether any of the pixel whose top-left corner is (`x`, `y`) of a
/// `w`×`h` eye image is in the picture: the point of its square nearest
/// the fisheye circle's centre is.
pub fn touches(projection: Projection, x: Real, y: Real, w: Real, h: Real) -> bool {
    let nearest = |corner: Real, centre: Real| centre.clamp(corner, corner + 1.0);
    let (cx, cy) = (0.5 * w, 0.5 * h);
    covers(projection, nearest(x, cx), nearest(y, cy), w, h)
}

/// The omni-directional stereo offset of the eye on `side` (−1 left, +1
/// right) for a ray at `longitude`: on the circle of radius `half` about
/// the camera, perpendicular to the ray's horizontal direction, so each
/// column sees as a head turned towards it would.
pub fn ods_offset(longitude: Real, half: Real, side: Real, right: DVec3, forward: DVec3) -> DVec3 {
    let (s, c) = longitude.sin_cos();
    // The horizontal direction's own right: `right` turned by the longitude.
    let across = right * c - forward * s;
    across * (side * half)
}
