//! The Preetham sky.

use super::*;

#[test]
fn preetham_sky_is_brightest_near_the_sun_and_one_at_the_zenith() {
    let sun = DVec3::new(0.0, 0.5, 0.866).normalize();
    let luminance = |c: Vec3| 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
    let zenith = preetham(DVec3::Y, sun, 3.0);
    assert!((luminance(zenith) - 1.0).abs() < 0.05, "{zenith}");
    let near_sun = preetham(DVec3::new(0.0, 0.45, 0.89).normalize(), sun, 3.0);
    let away = preetham(DVec3::new(0.0, 0.45, -0.89).normalize(), sun, 3.0);
    assert!(
        luminance(near_sun) > 2.0 * luminance(away),
        "{near_sun} vs {away}"
    );
    // Clear skies are blue away from the sun.
    assert!(away.z > away.x, "{away}");
    // Finite everywhere, the ground and a sun at the zenith or below the horizon too.
    for s in [DVec3::Y, DVec3::new(1.0, -0.2, 0.0).normalize(), sun] {
        for d in [
            DVec3::Y,
            -DVec3::Y,
            DVec3::X,
            DVec3::new(0.3, -0.9, 0.1).normalize(),
        ] {
            for t in [2.0, 10.0] {
                assert!(preetham(d, s, t).is_finite());
            }
        }
    }
}
