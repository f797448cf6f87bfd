//! Unit tests of shading, by concern, and the helpers they share.

use super::fog::*;
use super::look::*;
use super::palette::*;
use super::path::*;
use super::shadow::*;
use super::sky::*;
use super::*;
use crate::fractal::{Fractal, OrbitTraps};
use crate::march::MarchSettings;
use crate::math::{DVec3, Real, Vec3};

/// Where `ray` meets the surface, as shading takes it.
fn surface_at(
    ray: &crate::march::Ray,
    fractal: &Fractal,
    settings: &MarchSettings,
) -> Option<SurfacePoint> {
    let hit = crate::march::march(ray, fractal, settings).hit?;
    let (normal, _) = crate::march::normal(ray, &hit, fractal, settings);
    Some(SurfacePoint::from_hit(ray, &hit, normal))
}

/// Where `count` rays from around the bulb (`seed` picks them) meet it.
fn bulb_points(
    count: usize,
    seed: u64,
    fractal: &Fractal,
    settings: &MarchSettings,
) -> Vec<SurfacePoint> {
    crate::math::shell_points(count, 2.5..2.6, seed)
        .into_iter()
        .filter_map(|origin| {
            let ray = crate::march::Ray {
                origin,
                dir: (DVec3::new(0.1, -0.2, 0.15) - origin).normalize(),
                pixel_angle: 1e-3,
                start_footprint: 0.0,
            };
            surface_at(&ray, fractal, settings)
        })
        .collect()
}

fn unit_ball() -> Fractal {
    Fractal::unit_ball()
}

mod bundle;
mod fog;
mod lighting;
mod look;
mod palette;
mod path;
mod shadow;
mod sky;
