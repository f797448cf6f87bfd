//! Skies for the path tracer: a gradient, Preetham's daylight model, or
//! an environment map.

use super::look::Look;
use crate::math::{normalize_or, DVec3, Real, Vec3};
use serde::{Deserialize, Serialize};

/// The light arriving from directions that leave the scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Sky {
    /// The background gradient (`look.background_top` / `_bottom`).
    Gradient,
    /// The same radiance from every direction (a white furnace at (1, 1, 1)).
    Constant(Vec3),
    /// The Preetham daylight model for the sun at `look.light_direction`,
    /// +y up, with atmospheric turbidity (2 very clear … 10 hazy); zenith
    /// luminance 1, below the horizon the horizon's colour at half brightness.
    Preetham { turbidity: Real },
    /// An equirectangular HDR map (.exr or .hdr; a path relative to the
    /// timeline), +y up, turned about +y; sampled by importance.
    Environment {
        path: std::path::PathBuf,
        #[serde(default)]
        rotation_degrees: Real,
        /// SHA-256 of the file, filled in when the timeline is read: part of
        /// each frame's hash, so a changed map re-renders.
        #[serde(default, skip_deserializing)]
        digest: String,
    },
}

impl Sky {
    /// Radiance arriving along `dir` (the sun is separate).
    pub fn radiance(
        &self,
        look: &Look,
        dir: DVec3,
        up: DVec3,
        environment: Option<&crate::environment::EnvironmentMap>,
    ) -> Vec3 {
        match self {
            Sky::Gradient => look.background(dir, up),
            Sky::Constant(c) => *c,
            Sky::Preetham { turbidity } => preetham(
                dir,
                normalize_or(look.light_direction, DVec3::Y),
                *turbidity,
            ),
            // The map is fetched once per frame by the caller, never per ray.
            Sky::Environment { .. } => {
                environment.map_or(Vec3::ZERO, |map| map.radiance(dir, self.rotation()))
            }
        }
    }

    /// Turn of an environment map about +y, in radians (0 for other skies).
    pub fn rotation(&self) -> Real {
        match self {
            Sky::Environment {
                rotation_degrees, ..
            } => rotation_degrees.to_radians(),
            _ => 0.0,
        }
    }

    /// The loaded map of an `Environment` sky. A timeline loads and checks
    /// it when read, so it is in the cache; for a scene built otherwise a
    /// map that fails to load gives `None`, a black sky.
    pub fn environment(&self) -> Option<std::sync::Arc<crate::environment::EnvironmentMap>> {
        match self {
            Sky::Environment { path, digest, .. } => crate::environment::cached(path, digest).ok(),
            _ => None,
        }
    }
}

/// The Preetham, Shirley and Smits (1999) analytic daylight sky: the Perez
/// distribution of luminance and chromaticity over the sky, fitted to
/// turbidity. Linear sRGB, zenith luminance 1.
pub fn preetham(dir: DVec3, to_sun: DVec3, turbidity: Real) -> Vec3 {
    let t = turbidity;
    let perez = |theta: Real, gamma: Real, c: [Real; 5]| {
        (1.0 + c[0] * (c[1] / theta.cos().max(0.01)).exp())
            * (1.0 + c[2] * (c[3] * gamma).exp() + c[4] * gamma.cos().powi(2))
    };
    let lum = [
        0.1787 * t - 1.4630,
        -0.3554 * t + 0.4275,
        -0.0227 * t + 5.3251,
        0.1206 * t - 2.5771,
        -0.0670 * t + 0.3703,
    ];
    let cx = [
        -0.0193 * t - 0.2592,
        -0.0665 * t + 0.0008,
        -0.0004 * t + 0.2125,
        -0.0641 * t - 0.8989,
        -0.0033 * t + 0.0452,
    ];
    let cy = [
        -0.0167 * t - 0.2608,
        -0.0950 * t + 0.0092,
        -0.0079 * t + 0.2102,
        -0.0441 * t - 1.6537,
        -0.0109 * t + 0.0529,
    ];
    let theta_s = to_sun
        .y
        .clamp(-1.0, 1.0)
        .acos()
        .min(std::f64::consts::FRAC_PI_2);
    let (s1, s2, s3) = (theta_s, theta_s * theta_s, theta_s * theta_s * theta_s);
    let zenith_x = t * t * (0.00166 * s3 - 0.00375 * s2 + 0.00209 * s1)
        + t * (-0.02903 * s3 + 0.06377 * s2 - 0.03202 * s1 + 0.00394)
        + (0.11693 * s3 - 0.21196 * s2 + 0.06052 * s1 + 0.25886);
    let zenith_y = t * t * (0.00275 * s3 - 0.00610 * s2 + 0.00317 * s1)
        + t * (-0.04214 * s3 + 0.08970 * s2 - 0.04153 * s1 + 0.00516)
        + (0.15346 * s3 - 0.26756 * s2 + 0.06670 * s1 + 0.26688);
    // Below the horizon: the horizon's colour at half brightness.
    let (d, dim) = if dir.y < 0.0 {
        (normalize_or(DVec3::new(dir.x, 0.0, dir.z), DVec3::X), 0.5)
    } else {
        (dir, 1.0)
    };
    let theta = d.y.clamp(0.0, 1.0).acos().min(1.5608); // 89.4°: keeps 1/cos θ finite
    let gamma = d.dot(to_sun).clamp(-1.0, 1.0).acos();
    let relative = |c: [Real; 5]| perez(theta, gamma, c) / perez(0.0, theta_s, c);
    let luminance = relative(lum) * dim;
    let x = zenith_x * relative(cx);
    let y = (zenith_y * relative(cy)).max(1e-6);
    // xyY → XYZ → linear sRGB (D65).
    let (cap_x, cap_z) = (x / y * luminance, (1.0 - x - y) / y * luminance);
    let rgb = Vec3::new(
        (3.2406 * cap_x - 1.5372 * luminance - 0.4986 * cap_z) as f32,
        (-0.9689 * cap_x + 1.8758 * luminance + 0.0415 * cap_z) as f32,
        (0.0557 * cap_x - 0.2040 * luminance + 1.0570 * cap_z) as f32,
    );
    crate::math::finite_or_zero(rgb.max(Vec3::ZERO))
}
