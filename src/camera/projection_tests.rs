//! Each projection against its defining geometry: the direction of a
//! pixel's ray, and where the eyes of a stereo pair stand.

use super::*;
use std::f64::consts::PI;

/// A camera at +z looking at the origin, up +y: right is +x, forward −z.
fn camera(projection: Projection, stereo: Option<Stereo>) -> CameraFrame {
    Camera {
        position: DVec3::new(0.0, 0.0, 5.0),
        target: DVec3::ZERO,
        projection,
        stereo,
        ..Camera::default()
    }
    .frame()
}

fn angle(a: DVec3, b: DVec3) -> f64 {
    a.normalize().dot(b.normalize()).clamp(-1.0, 1.0).acos()
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-9
}

#[test]
fn fisheye_angle_grows_with_the_radius_and_keeps_the_azimuth() {
    let f = camera(Projection::Fisheye { degrees: 180.0 }, None);
    // A 200×100 image: the circle is 100 across, centred at (100, 50).
    assert!((f.ray(100.0, 50.0, 200, 100).dir - -DVec3::Z).length() < 1e-12);
    // The circle's edge of a 180° dome looks at 90° from the axis.
    let edge = f.ray(150.0, 50.0, 200, 100).dir;
    assert!(close(angle(edge, -DVec3::Z), PI / 2.0), "{edge}");
    assert!((edge - DVec3::X).length() < 1e-9, "{edge}");
    // Halfway out, up and to the left (azimuth 135°): 45° from the axis.
    let r = 25.0 / 2f64.sqrt();
    let d = f.ray(100.0 - r, 50.0 - r, 200, 100).dir;
    assert!(close(angle(d, -DVec3::Z), PI / 4.0), "{d}");
    assert!(close(d.y.atan2(d.x), 0.75 * PI), "{d}");
    // A 240° fisheye: 0.3 of the radius out is 36° from the axis.
    let wide = camera(Projection::Fisheye { degrees: 240.0 }, None);
    let d = wide.ray(100.0, 50.0 + 15.0, 200, 100).dir;
    assert!(close(angle(d, -DVec3::Z), 36f64.to_radians()), "{d}");
    assert!(d.y < 0.0, "below the centre looks down: {d}");
}

#[test]
fn only_the_fisheye_circle_is_covered() {
    let f = camera(Projection::Fisheye { degrees: 180.0 }, None);
    assert!(f.covers(100, 50, 200, 100));
    assert!(f.covers(149, 50, 200, 100));
    assert!(!f.covers(151, 50, 200, 100));
    assert!(!f.covers(0, 0, 200, 100));
    let equirect = camera(Projection::Equirectangular, None);
    assert!(equirect.covers(0, 0, 200, 100));
}

#[test]
fn equirectangular_maps_columns_to_longitude_and_rows_to_latitude() {
    let f = camera(Projection::Equirectangular, None);
    let dir = |x: f64, y: f64| f.ray(x, y, 400, 200).dir;
    assert!(
        (dir(200.0, 100.0) - -DVec3::Z).length() < 1e-12,
        "centre looks forward"
    );
    assert!(
        (dir(0.0, 100.0) - DVec3::Z).length() < 1e-12,
        "left edge looks back"
    );
    assert!(
        (dir(400.0, 100.0) - DVec3::Z).length() < 1e-12,
        "right edge looks back"
    );
    assert!(
        (dir(300.0, 100.0) - DVec3::X).length() < 1e-12,
        "three quarters: right"
    );
    assert!(
        (dir(200.0, 0.0) - DVec3::Y).length() < 1e-12,
        "top row looks up"
    );
    assert!(
        (dir(50.0, 200.0) - -DVec3::Y).length() < 1e-12,
        "bottom row down"
    );
    // Longitude 45° right, latitude 30° up.
    let d = dir(250.0, 200.0 / 3.0);
    assert!(close(d.y.asin(), PI / 6.0), "{d}");
    assert!(close(d.x.atan2(-d.z), PI / 4.0), "{d}");
}

#[test]
fn pixel_angles_span_a_pixel_of_each_projection() {
    let fish = camera(Projection::Fisheye { degrees: 180.0 }, None);
    let a = fish.ray(100.0, 50.0, 200, 100).pixel_angle;
    assert!(close(a, PI / 100.0), "180° over 100 pixels: {a}");
    let equirect = camera(Projection::Equirectangular, None);
    let a = equirect.ray(10.0, 100.0, 400, 200).pixel_angle;
    assert!(close(a, PI / 200.0), "{a}");
}

fn stereo(layout: StereoLayout) -> Option<Stereo> {
    Some(Stereo {
        eye_separation: 0.02,
        layout,
    })
}

#[test]
fn ods_eyes_stand_on_a_circle_across_each_column() {
    let f = camera(Projection::Equirectangular, stereo(StereoLayout::TopBottom));
    // The camera is 5 from its target: eyes 0.1 apart, 0.05 from the centre.
    let centre = DVec3::new(0.0, 0.0, 5.0);
    for x in [0.5, 37.0, 100.0, 163.5, 250.0, 399.5] {
        for y in [20.0, 50.0, 85.0] {
            let left = f.ray(x, y, 400, 400);
            let right = f.ray(x, y + 200.0, 400, 400);
            assert_eq!(left.dir, right.dir, "both eyes look the same way");
            let (l, r) = (left.origin - centre, right.origin - centre);
            assert!(
                close(l.length(), 0.05) && close(r.length(), 0.05),
                "{l} {r}"
            );
            assert!((l + r).length() < 1e-12, "opposite: {l} {r}");
            let horizontal = DVec3::new(left.dir.x, 0.0, left.dir.z);
            assert!(l.dot(horizontal).abs() < 1e-12 && l.y == 0.0, "{l}");
            // The left eye is to the left of the column's direction.
            assert!(horizontal.cross(l).y > 0.0, "{l} for {horizontal}");
        }
    }
}

#[test]
fn side_by_side_eyes_are_the_left_and_right_halves() {
    let f = camera(
        Projection::Fisheye { degrees: 180.0 },
        stereo(StereoLayout::SideBySide),
    );
    let (left, right) = (f.ray(50.0, 50.0, 200, 100), f.ray(150.0, 50.0, 200, 100));
    assert_eq!(left.dir, right.dir);
    assert!((left.origin - DVec3::new(-0.05, 0.0, 5.0)).length() < 1e-12);
    assert!((right.origin - DVec3::new(0.05, 0.0, 5.0)).length() < 1e-12);
    assert!(f.covers(50, 50, 200, 100) && !f.covers(99, 2, 200, 100));
    let p = camera(Projection::Perspective, stereo(StereoLayout::SideBySide));
    let (l, r) = (p.ray(50.0, 50.0, 200, 100), p.ray(150.0, 50.0, 200, 100));
    assert!(
        (l.dir - -DVec3::Z).length() < 1e-12 && l.dir == r.dir,
        "parallel axes"
    );
    assert!(close(r.origin.x - l.origin.x, 0.1));
}

#[test]
fn fisheye_lens_rays_meet_on_the_sphere_of_focus() {
    let lens = Camera {
        position: DVec3::new(0.0, 0.0, 5.0),
        target: DVec3::ZERO,
        projection: Projection::Fisheye { degrees: 200.0 },
        aperture_radius: 0.2,
        focus_distance: Some(4.0),
        ..Camera::default()
    }
    .frame();
    let pinhole = lens.ray(170.0, 20.0, 200, 100);
    let focus = pinhole.at(4.0);
    for (u, v) in [(0.1, 0.3), (0.9, 0.8), (0.5, 0.5)] {
        let r = lens.lens_ray(170.0, 20.0, 200, 100, u, v);
        let t = (focus - r.origin).length();
        assert!((r.at(t) - focus).length() < 1e-12, "{u} {v}");
        assert!((r.origin - pinhole.origin).dot(pinhole.dir).abs() < 1e-12);
    }
}
