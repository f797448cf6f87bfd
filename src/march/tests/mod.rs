//! Unit tests of the marcher, by concern, and the helpers they share.

use super::cone::*;
use super::membership::*;
use super::normal::*;
use super::walk::*;
use super::*;

fn unit_ball() -> Fractal {
    Fractal::unit_ball()
}

/// Each ray's bounding-sphere interval, as `march_camera_rays` gives
/// them to a cone.
fn intervals(rays: &[Ray], settings: &MarchSettings) -> Vec<Option<(Real, Real)>> {
    rays.iter().map(|ray| settings.interval(ray)).collect()
}

fn ray(origin: DVec3, dir: DVec3) -> Ray {
    Ray {
        origin,
        dir: dir.normalize(),
        pixel_angle: 1e-3,
        start_footprint: 0.0,
    }
}

mod cone;
mod march;
mod membership;
mod normal;
