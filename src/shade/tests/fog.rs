//! Fog and glow.

use super::*;

#[test]
fn fog_and_glow_fall_off_as_declared() {
    let fog = Fog {
        density: 1.0,
        colour: Vec3::ONE,
    };
    let c = Vec3::ZERO;
    assert_eq!(fogged(c, &fog, 0.0, 1.0), c);
    // One camera–target distance away at density 1: e^-1 of the surface is left.
    let f = fogged(c, &fog, 2.0, 2.0);
    assert!((f.x - (1.0 - (-1.0f32).exp())).abs() < 1e-6);
    let g = Glow {
        colour: Vec3::ONE,
        strength: 1.0,
        width: 2.0,
    };
    assert_eq!(glow(&g, 0.0), Vec3::ONE);
    assert!((glow(&g, 2.0).x - (-1.0f32).exp()).abs() < 1e-6);
    assert_eq!(glow(&g, Real::INFINITY), Vec3::ZERO);
}
