//! Direct lighting, traps and the background.

use super::*;

#[test]
fn every_light_adds_its_light_and_casts_its_shadow() {
    let one = Look {
        light_direction: DVec3::Y,
        ..Look::default()
    };
    let two = Look {
        extra_lights: vec![Light {
            direction: DVec3::X,
            colour: Vec3::ONE,
            intensity: 0.5,
        }],
        ..one.clone()
    };
    // On top of the ball, facing up and out along x: both lights reach it.
    let at = SurfacePoint {
        point: DVec3::new(1.0, 1.0, 0.0).normalize(),
        normal: DVec3::new(1.0, 1.0, 0.0).normalize(),
        view_dir: -DVec3::Z,
        t: 2.0,
        footprint: 1e-3,
        traps: OrbitTraps {
            origin: 1.0,
            planes: DVec3::splat(1.0),
        },
        palette_colour: None,
    };
    let effects = Effects {
        shadows: Some(Shadows::default()),
        ..Effects::default()
    };
    let (mut c1, mut c2) = (StageCounts::default(), StageCounts::default());
    let a = one.shade(
        &effects,
        &unit_ball(),
        &MarchSettings::default(),
        &at,
        &mut c1,
    );
    let b = two.shade(
        &effects,
        &unit_ball(),
        &MarchSettings::default(),
        &at,
        &mut c2,
    );
    let albedo = one.albedo(&at.traps, None);
    let extra = albedo * Vec3::ONE * (0.5 * std::f32::consts::FRAC_1_SQRT_2);
    assert!((b - a - extra).length() < 1e-5, "{b} vs {a} + {extra}");
    // One shadow march per light that faces the surface.
    assert!(c2.shadows > c1.shadows && c1.shadows > 0);
}

fn traps_far() -> OrbitTraps {
    OrbitTraps {
        origin: 1.0,
        planes: DVec3::splat(1.0),
    }
}

#[test]
fn lambert_is_ambient_only_facing_away_and_brightest_facing_light() {
    let look = Look::default();
    let light = look.light_direction.normalize();
    // With no effects, shading needs no estimates: the fractal is never asked.
    let plain = |normal: DVec3| {
        let at = SurfacePoint {
            point: DVec3::new(0.0, 5.0, 0.0),
            normal,
            view_dir: -normal,
            t: 1.0,
            footprint: 1e-3,
            traps: traps_far(),
            palette_colour: None,
        };
        let mut counts = StageCounts::default();
        let c = look.shade(
            &Effects::default(),
            &Fractal::default(),
            &MarchSettings::default(),
            &at,
            &mut counts,
        );
        assert_eq!(counts, StageCounts::default());
        c
    };
    let lit = plain(light);
    let unlit = plain(-light);
    let albedo = look.albedo(&traps_far(), None);
    assert!((unlit - albedo * look.ambient).length() < 1e-6);
    assert!((lit - albedo * (look.ambient + look.light_colour)).length() < 1e-6);
}

#[test]
fn far_traps_give_base_colour_and_plane_traps_pull() {
    let look = Look::default();
    assert!((look.albedo(&traps_far(), None) - look.base_colour).length() < 1e-6);
    let on_x_plane = OrbitTraps {
        planes: DVec3::new(0.0, 1.0, 1.0),
        ..traps_far()
    };
    assert!((look.albedo(&on_x_plane, None) - look.trap_x_colour).length() < 1e-6);
    let crevice = OrbitTraps {
        origin: 0.0,
        ..traps_far()
    };
    assert!(look.albedo(&crevice, None).length() < look.albedo(&traps_far(), None).length());
}

#[test]
fn background_blends_bottom_to_top() {
    let look = Look::default();
    assert!((look.background(DVec3::Y, DVec3::Y) - look.background_top).length() < 1e-6);
    assert!((look.background(-DVec3::Y, DVec3::Y) - look.background_bottom).length() < 1e-6);
}
