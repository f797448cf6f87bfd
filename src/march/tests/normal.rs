//! Normals on a shape with a known answer.

use super::*;

#[test]
fn oblique_normal_on_the_ball_points_outward() {
    let r = ray(DVec3::new(0.5, 0.3, 3.0), DVec3::new(-0.1, 0.0, -1.0));
    let m = march(&r, &unit_ball(), &MarchSettings::default());
    let hit = m.hit.unwrap();
    let (n, _) = normal(&r, &hit, &unit_ball(), &MarchSettings::default());
    let expected = hit.point.normalize();
    assert!(n.dot(expected) > 0.995, "{n} vs {expected}");
}
