//! Hard cases through the binary: whole frames that must come out finite,
//! quickly, and with a clear message where the scene is odd.

use crate::util::{says, stderr, stdout, Dir};

/// Every channel of an EXR frame, checked finite; returns (alpha, depth).
fn finite_channels(d: &Dir, rel: &str) -> (Vec<f32>, Vec<f32>) {
    let exr = d.exr(rel);
    for (name, v) in &exr.channels {
        assert!(v.iter().all(|x| x.is_finite()), "{rel}: {name} not finite");
    }
    (exr.channel("A").to_vec(), exr.channel("depth.Z").to_vec())
}

/// A one-frame timeline of `body`, its background transparent so that an
/// EXR's alpha is the fractal's coverage.
fn scene(body: &str) -> String {
    let body = match body.strip_prefix("look: (") {
        Some(look) => format!("look: (transparent_background: true, {look}"),
        None => format!("{body}, look: (transparent_background: true)"),
    };
    format!("(fps: 24, frames: 1, size: (32, 18), scene: ({body}))")
}

#[test]
fn camera_inside_the_bulb_renders_with_a_warning() {
    let d = Dir::new();
    d.write(
        "t.ron",
        &scene("camera: (position: (0, 0.1, 0), target: (0, 0, 1))"),
    );
    let out = d.ok(&["render", "t.ron", "--format", "exr"]);
    says(&out, "camera is inside the fractal");
    let (alpha, depth) = finite_channels(&d, "out/t/frame_00000.exr");
    assert!(alpha.iter().all(|&a| a == 1.0));
    assert!(depth.iter().all(|&z| z == 0.0));
}

/// Renders a Julia set with constant `c` and returns (alpha, evaluations per sample).
fn julia_frame(c: &str) -> (Vec<f32>, f64) {
    let d = Dir::new();
    d.write("t.ron", &scene(&format!("fractal: (julia: {c})")));
    // --stats is printed even with --quiet: it was asked for.
    let out = d.ok(&["render", "t.ron", "--format", "exr", "--stats", "--quiet"]);
    let (alpha, _) = finite_channels(&d, "out/t/frame_00000.exr");
    let err = stderr(&out);
    let per_sample: f64 = err
        .split(" per sample")
        .next()
        .and_then(|s| s.rsplit('(').next())
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("no stats in {err}"));
    (alpha, per_sample)
}

#[test]
fn empty_and_dust_julia_sets_render_fast_without_hanging() {
    // |c| far beyond the bulb's reach: nothing stays bounded inside the
    // bounding sphere, so the frame is background, at a few estimates a ray.
    let (alpha, per_sample) = julia_frame("(100, 100, 100)");
    assert!(
        alpha.iter().all(|&a| a == 0.0),
        "an empty set shows no surface"
    );
    assert!(per_sample < 10.0, "{per_sample} evaluations per sample");
    // c = (2, 2, 2) leaves Cantor dust near radius 1.17: sparse specks at
    // most, still a handful of estimates per ray, not a crawl to the step limit.
    let (alpha, per_sample) = julia_frame("(2, 2, 2)");
    let covered = alpha.iter().filter(|&&a| a > 0.0).count();
    assert!(
        covered < alpha.len() / 2,
        "dust covers {covered} of {} pixels",
        alpha.len()
    );
    assert!(per_sample < 20.0, "{per_sample} evaluations per sample");
}

#[test]
fn extreme_but_valid_cameras_render_finite_frames() {
    for camera in [
        "camera: (fov_degrees: 1e-6)",
        "camera: (fov_degrees: 178.9)",
        "camera: (roll_degrees: 1e9)",
        "camera: (position: (0, 40, 0.001), target: (0, 0, 0))",
    ] {
        let d = Dir::new();
        d.write("t.ron", &scene(camera));
        d.ok(&["render", "t.ron", "--format", "exr"]);
        finite_channels(&d, "out/t/frame_00000.exr");
    }
}

#[test]
fn a_camera_a_billion_units_away_sees_what_a_near_one_sees() {
    // The same view of the bulb from 1e3 and from 1e9 units (the field of
    // view narrowed to match): the bounding sphere's entry lost all
    // precision at 1e9 (747 of 5184 pixels off by more than 30 levels, with
    // false hits and streaks in the background).
    let d = Dir::new();
    for (name, far) in [("near", 1e3), ("far", 1e9)] {
        let fov = 0.103 * 1e3 / far;
        let camera = format!(
            "camera: (position: ({far:e}, {:e}, {far:e}), target: (0, 0, 0), fov_degrees: {fov:e})",
            0.3 * far
        );
        d.write(
            &format!("{name}.ron"),
            &scene(&camera).replace("(32, 18)", "(96, 54)"),
        );
        d.ok(&["render", &format!("{name}.ron")]);
    }
    let pixels = |name: &str| {
        let path = d.path().join(format!("out/{name}/frame_00000.png"));
        image::open(path).unwrap().to_rgb8().into_raw()
    };
    let (near, far) = (pixels("near"), pixels("far"));
    let differ = near
        .chunks(3)
        .zip(far.chunks(3))
        .filter(|(a, b)| a.iter().zip(*b).any(|(x, y)| x.abs_diff(*y) > 30))
        .count();
    // 4 pixels differ at this size, from the rounding of the two cameras' rays.
    assert!(differ <= 26, "{differ} of {} pixels differ", near.len() / 3);
    assert!(
        near.chunks(3).any(|p| p != [near[0], near[1], near[2]]),
        "the bulb is in view"
    );
}

#[test]
fn degenerate_cameras_are_rejected_before_rendering() {
    for (camera, field) in [
        (
            "camera: (position: (0, 3, 0), target: (0, 0, 0), up: (0, 1, 0))",
            "camera.up",
        ),
        (
            "camera: (position: (1, 1, 1), target: (1, 1, 1))",
            "camera.target",
        ),
        ("camera: (fov_degrees: 180)", "camera.fov_degrees"),
        // Narrower than f64 can march: a pixel under 1.4e-14 radians.
        ("camera: (fov_degrees: 1e-9)", "camera.fov_degrees"),
        ("camera: (up: (0, 0, 0))", "camera.up"),
    ] {
        let d = Dir::new();
        d.write("t.ron", &scene(camera));
        let out = d.run(&["render", "t.ron"]);
        assert_eq!(out.status.code(), Some(3), "{camera}");
        assert!(stderr(&out).contains(field), "{camera}: {}", stderr(&out));
        assert!(!d.path().join("out").exists());
    }
}

#[test]
fn zoom_to_1e_minus_12_renders_finite_distinct_depths() {
    // The example zoom's target, approached to 1e-12 with iterations raised.
    let d = Dir::new();
    d.write(
        "t.ron",
        "(fps: 24, frames: 1, size: (24, 16), scene: (
            camera: (position: (0.2372, 0.4442, 4.0), target: (0.237207564481, 0.444190855613, 0.882531801629), fov_degrees: 40),
            fractal: (iterations: 40),
        ), tracks: { \"camera.distance\": (keys: [(time: 0, value: 1e-12)]) })",
    );
    d.ok(&["render", "t.ron", "--format", "exr"]);
    let (alpha, depth) = finite_channels(&d, "out/t/frame_00000.exr");
    assert!(alpha.iter().all(|&a| a == 1.0), "all pixels see surface");
    let mut distinct: Vec<u32> = depth.iter().map(|z| z.to_bits()).collect();
    distinct.sort();
    distinct.dedup();
    assert!(
        distinct.len() > depth.len() / 2,
        "only {} distinct depths",
        distinct.len()
    );
}

/// Writes a small equirectangular EXR map: a dim blue sky with one bright texel.
fn write_sky(path: &std::path::Path, bright: f32) {
    use exr::prelude::*;
    let (w, h) = (32usize, 16usize);
    write_rgba_file(path, w, h, |x, y| {
        if (x, y) == (20, 5) {
            (bright, bright, bright * 0.9, 1.0)
        } else {
            (0.1, 0.15, 0.3, 1.0)
        }
    })
    .unwrap();
}

#[test]
fn environment_map_lights_a_path_traced_frame_deterministically() {
    let d = Dir::new();
    write_sky(&d.path().join("sky.exr"), 200.0);
    let text = scene(
        "effects: (path_tracing: (max_bounces: 3, sky: Environment(path: \"sky.exr\", rotation_degrees: 30))), samples_per_pixel: 4",
    );
    d.write("t.ron", &text);
    d.same_on_one_and_two_threads("t.ron", &["--format", "exr"], &["frame_00000.exr"]);
    finite_channels(&d, "one/frame_00000.exr");
    // A changed map changes what made the frame: it re-renders, to a new picture.
    write_sky(&d.path().join("sky.exr"), 50.0);
    let out = d.ok(&[
        "render",
        "t.ron",
        "--format",
        "exr",
        "--threads",
        "2",
        "--out",
        "two",
    ]);
    assert!(
        !stderr(&out).contains("already complete"),
        "{}",
        stderr(&out)
    );
    assert!(d.bytes("one/frame_00000.exr") != d.bytes("two/frame_00000.exr"));
    // A missing map is a clear timeline error, before anything is written.
    d.write("missing.ron", &text.replace("sky.exr", "nope.exr"));
    let out = d.run(&["render", "missing.ron", "--out", "never"]);
    assert_eq!(out.status.code(), Some(3));
    says(&out, "nope.exr");
    assert!(!d.path().join("never").exists());
    // A misspelt field of the map and a NaN turn are errors too, not ignored.
    for (bad, named) in [
        ("rotation_degrees: 30", "rotaton_degrees: 30"),
        ("rotation_degrees: 30", "rotation_degrees: NaN"),
    ] {
        d.write("bad.ron", &text.replace(bad, named));
        let out = d.run(&["render", "bad.ron", "--out", "never"]);
        assert_eq!(out.status.code(), Some(3), "{named}");
        says(&out, named.split(':').next().unwrap());
        assert!(!d.path().join("never").exists());
    }
}

#[test]
fn light_too_bright_for_the_file_is_white_and_finite() {
    // Light of 1e30 exposed by 1e30 is past f32: every pixel shows white (the
    // lit surface showed black, its infinite value taken for a bad one), and
    // the EXR's half floats hold 65504 rather than infinity.
    let d = Dir::new();
    d.write(
        "t.ron",
        &scene("look: (light_colour: (1e30, 1e30, 1e30), exposure: 1e30)"),
    );
    d.ok(&["render", "t.ron", "--format", "png,exr"]);
    let (alpha, _) = finite_channels(&d, "out/t/frame_00000.exr");
    assert!(alpha.contains(&1.0), "the bulb is in view");
    let exr = d.exr("out/t/frame_00000.exr");
    assert!(exr.channel("R").contains(&65504.0));
    // Every pixel the bulb covers whole (the background is transparent:
    // black in an RGB PNG).
    let png = image::open(d.path().join("out/t/frame_00000.png")).unwrap();
    let rgb = png.to_rgb8();
    let covered = rgb.pixels().zip(&alpha).filter(|(_, &a)| a == 1.0);
    let black = covered.filter(|(p, _)| p.0 != [255; 3]).count();
    assert_eq!(black, 0, "pixels not white");
}

#[test]
fn rays_running_out_of_steps_are_counted_and_warned_of() {
    // A fudge of 0.01 takes a hundredth of each estimate: 300 steps cannot
    // cross the bounding sphere, so rays stop as hits in the background.
    // Counted per frame and said once, with the fix; at the default fudge
    // no ray runs out and nothing is said.
    let d = Dir::new();
    d.write("small.ron", &scene("quality: (fudge: 0.01)"));
    let out = d.ok(&["render", "small.ron", "--stats"]);
    says(
        &out,
        "in frame(s) 0, 1% or more of the camera rays ran out of quality.max_steps (300)",
    );
    says(&out, "or quality.fudge (0.01)");
    let err = stderr(&out);
    let counted = err
        .split(" out of steps)")
        .next()
        .and_then(|s| s.rsplit('(').next())
        .and_then(|n| n.parse::<u32>().ok())
        .unwrap();
    assert!(counted > 32 * 18 / 10, "{err}");
    assert!(stdout(&d.ok(&["info", "small.ron"])).contains("ran out of quality.max_steps"));
    // A farm's quiet workers say it too, as they do every warning.
    let quiet = d.ok(&["render", "small.ron", "--force", "-q"]);
    says(&quiet, "ran out of quality.max_steps");
    d.write("plain.ron", &scene("quality: (fudge: 1)"));
    let out = d.ok(&["render", "plain.ron", "--stats"]);
    says(&out, "(0 out of steps)");
    assert!(!stderr(&out).contains("warning"), "{}", stderr(&out));
}

// Hostile but legal scenes, measured against membership: the library's
// marcher against `march_by_membership` (orbits alone, no estimate), ray by
// ray over a small camera grid.

use mandelreel::camera::Camera;
use mandelreel::fractal::{DeMethod, Fractal, Precision};
use mandelreel::march::judge::past_the_set;
use mandelreel::march::{march, march_by_membership, MarchSettings, Ray};
use mandelreel::math::DVec3;

/// The bulb seen from 13 units, outside every bounding sphere below.
fn far_camera() -> Camera {
    Camera {
        position: DVec3::new(0.0, 3.0, 13.0),
        fov_degrees: 11.0,
        ..Camera::default()
    }
}

/// How far apart two hits on one ray may be, in footprints: in the halo
/// where the 12-iteration estimate lingers under the hit threshold, rays
/// that start elsewhere stop up to 5 footprints apart (0.7 units here).
const NEAR_FOOTPRINTS: f64 = 6.0;

/// The rays of a 32×18 grid of `camera`'s on which `fractal` marched
/// inside `radius` disagrees with `trusted` marched inside `reference` (a
/// hit against a miss, or hits `NEAR_FOOTPRINTS` apart), and those
/// on which membership alone (`march_by_membership`, no estimate) finds the
/// set inside `reference`.
fn disagreements(
    camera: &Camera,
    (fractal, radius): (&Fractal, f64),
    (trusted, reference): (&Fractal, f64),
) -> (usize, usize) {
    let frame = camera.frame();
    let (w, h) = (32, 18);
    let settings = |bounding_radius| MarchSettings {
        bounding_radius,
        ..MarchSettings::default()
    };
    let (mut wrong, mut members) = (0, 0);
    for y in 0..h {
        for x in 0..w {
            let ray = frame.ray(x as f64 + 0.5, y as f64 + 0.5, w, h);
            let got = march(&ray, fractal, &settings(radius)).hit;
            if let Some(hit) = &got {
                assert!(hit.t.is_finite() && hit.estimate.distance.is_finite());
            }
            let want = march(&ray, trusted, &settings(reference)).hit;
            let (member, _) =
                march_by_membership(&ray, fractal, &settings(reference), 0.25, 1e-4, 1_000_000);
            members += usize::from(member.is_some());
            let agree = match (got.map(|hit| hit.t), want.map(|hit| hit.t)) {
                (Some(t), Some(u)) => (t - u).abs() <= NEAR_FOOTPRINTS * ray.footprint(u),
                (None, None) => true,
                _ => false,
            };
            wrong += usize::from(!agree);
        }
    }
    (wrong, members)
}

/// Asserts that `fractal` marched inside `radius` sees what the everyday
/// setting (bailout 4 inside a sphere of 1.5, the rest the same) sees on all but 2% of the rays, where membership sees the
/// set on at least 100 of them.
fn sees_the_bulb(fractal: &Fractal, radius: f64) {
    let trusted = Fractal {
        bailout: 4.0,
        ..fractal.clone()
    };
    let (wrong, members) = disagreements(&far_camera(), (fractal, radius), (&trusted, 1.5));
    assert!(
        members > 100,
        "{fractal:?}: membership sees the set ({members} rays)"
    );
    assert!(
        wrong <= 576 / 50,
        "{fractal:?} inside {radius}: {wrong} of 576 rays differ ({members} in the set)"
    );
}

#[test]
fn a_bounding_sphere_past_the_bailout_draws_no_bailout_ball() {
    // Bailout 4 in a sphere of 6: the estimate outside the bailout ball was
    // |p| − 4, so rays crept onto the ball and hit it (358 of 576 rays
    // wrong here). Other bailouts, estimators, precisions and a Julia set
    // alike; the power-8 bulb lies within 1.2.
    let julia = Some(DVec3::new(0.3, -0.5, 0.2));
    for (bailout, radius, de, precision, julia) in [
        (4.0, 6.0, DeMethod::Analytic, Precision::F64, None),
        (2.0, 3.0, DeMethod::Analytic, Precision::F64, None),
        (2.0, 3.0, DeMethod::Potential, Precision::F32, None),
        (4.0, 6.0, DeMethod::SinhPotential, Precision::F64, None),
        (3.0, 5.0, DeMethod::Analytic, Precision::F32, julia),
    ] {
        let f = bulb(bailout, de, precision, julia);
        sees_the_bulb(&f, radius);
    }
}

#[test]
fn large_bailouts_and_spheres_keep_the_bulb() {
    // Bailout 100 in a sphere of 10: from |p| = 10 the estimate ½·r·ln r/dr
    // is 11.5 where the bulb is 8.9 away, so rays stepped past it (412 of
    // 576 rays wrong; the potential estimator hit nothing). Bailout 1e30:
    // |z|² overflowed past 1e154 and the estimate read ∞/∞.
    for (bailout, radius, de) in [
        (100.0, 10.0, DeMethod::Analytic),
        (100.0, 10.0, DeMethod::Potential),
        (100.0, 10.0, DeMethod::SinhPotential),
        (1e30, 10.0, DeMethod::Analytic),
        (1e30, 1e6, DeMethod::Analytic),
        (1e30, 1e6, DeMethod::SinhPotential),
        (1e30, 1e6, DeMethod::Potential),
    ] {
        let f = Fractal {
            bailout,
            de,
            ..Fractal::default()
        };
        sees_the_bulb(&f, radius);
    }
}

/// The default bulb, or Julia set where `julia` is given, with the bailout,
/// estimator and precision given.
fn bulb(bailout: f64, de: DeMethod, precision: Precision, julia: Option<DVec3>) -> Fractal {
    Fractal {
        bailout,
        de,
        precision,
        julia,
        ..Fractal::default()
    }
}

/// The deepest point of the set, in footprints of the hit, that a ray of a
/// 24×14 grid of the far camera's passes before its hit (`past_the_set` at a
/// 64th of a footprint), and the number of hits.
fn deepest_pass_through(fractal: &Fractal, radius: f64) -> (f64, usize) {
    let (deepest, hits, _) = deepest_pass_through_with(fractal, radius, false);
    (deepest, hits)
}

/// `deepest_pass_through`, with hits checked by the potential estimate
/// where `confirm_hits` says, and the orbits the marches took.
fn deepest_pass_through_with(
    fractal: &Fractal,
    radius: f64,
    confirm_hits: bool,
) -> (f64, usize, u64) {
    let settings = MarchSettings {
        bounding_radius: radius,
        confirm_hits,
        ..MarchSettings::default()
    };
    let frame = far_camera().frame();
    let (w, h) = (24, 14);
    let (mut deepest, mut hits, mut orbits) = (0.0f64, 0, 0);
    for y in 0..h {
        for x in 0..w {
            let ray = frame.ray(x as f64 + 0.5, y as f64 + 0.5, w, h);
            let m = march(&ray, fractal, &settings);
            orbits += u64::from(m.evaluations);
            if let Some(hit) = m.hit {
                hits += 1;
                let past = past_the_set(fractal, &settings, &ray, hit.t, 1.0 / 64.0);
                deepest = deepest.max(past);
            }
        }
    }
    (deepest, hits, orbits)
}

#[test]
fn no_ray_passes_through_the_set_in_a_wide_sphere_or_at_a_large_bailout() {
    // An over-relaxed step from the sphere's edge landed inside the bulb,
    // and bisecting the whole step found a crossing past the first: 222 of
    // 750 hits lay up to 7.9 footprints inside at bailout 4 in a sphere
    // of 6, and 94 up to 6.0 at bailout 100 in a sphere of 10.
    for (bailout, radius, de, precision) in [
        (4.0, 6.0, DeMethod::Analytic, Precision::F64),
        (2.0, 3.0, DeMethod::Analytic, Precision::F64),
        (100.0, 10.0, DeMethod::Analytic, Precision::F64),
        (4.0, 6.0, DeMethod::Analytic, Precision::F32),
        (1e30, 1e6, DeMethod::Potential, Precision::F64),
        (4.0, 6.0, DeMethod::SinhPotential, Precision::F32),
        (2.0, 3.0, DeMethod::EscapeLength, Precision::F64),
        (4.0, 6.0, DeMethod::EscapeLength, Precision::F32),
        (4.0, 1.5, DeMethod::EscapeLength, Precision::F64),
    ] {
        let f = Fractal {
            bailout,
            de,
            precision,
            ..Fractal::default()
        };
        let (deepest, hits) = deepest_pass_through(&f, radius);
        assert!(hits > 50, "{f:?} inside {radius}: {hits} hits");
        assert!(
            deepest == 0.0,
            "{f:?} inside {radius}: a hit {deepest:.2} footprints past the set"
        );
    }
}

#[test]
fn no_ray_passes_through_the_set_by_jacobian_in_julia_mode_or_confirming_hits() {
    // The rest of the class of the test above: the Jacobian estimator,
    // Julia mode by each estimator, and the potential check of hits,
    // which marches grazing rays on.
    let julia = Some(DVec3::new(-0.2, 0.6, 0.3));
    let cases = [
        (4.0, 6.0, DeMethod::Jacobian, Precision::F64, None, false),
        (100.0, 10.0, DeMethod::Jacobian, Precision::F64, None, false),
        (4.0, 6.0, DeMethod::Jacobian, Precision::F32, None, false),
        (4.0, 6.0, DeMethod::Analytic, Precision::F64, julia, false),
        (
            100.0,
            10.0,
            DeMethod::Potential,
            Precision::F64,
            julia,
            false,
        ),
        (
            2.0,
            3.0,
            DeMethod::EscapeLength,
            Precision::F32,
            julia,
            false,
        ),
        (4.0, 6.0, DeMethod::Jacobian, Precision::F64, julia, false),
        (4.0, 6.0, DeMethod::Analytic, Precision::F64, None, true),
        (100.0, 10.0, DeMethod::Analytic, Precision::F64, None, true),
        (4.0, 6.0, DeMethod::Analytic, Precision::F64, julia, true),
    ];
    for (bailout, radius, de, precision, julia, confirm_hits) in cases {
        let f = bulb(bailout, de, precision, julia);
        let (deepest, hits, orbits) = deepest_pass_through_with(&f, radius, confirm_hits);
        let case = format!("{f:?} inside {radius}, confirming hits: {confirm_hits}");
        assert!(hits > 50, "{case}: {hits} hits");
        if confirm_hits {
            // The check ran: it takes four orbits a checked hit.
            let (_, _, unchecked) = deepest_pass_through_with(&f, radius, false);
            assert!(orbits > unchecked, "{case}: no hit checked");
        }
        assert!(
            deepest == 0.0,
            "{case}: a hit {deepest:.2} footprints past the set"
        );
    }
}

#[test]
fn single_precision_takes_huge_bailouts() {
    // f32 holds 3.4e38: at bailout 1e30 the last step overflowed and every
    // ray hit the bounding sphere itself.
    for (bailout, radius, de) in [
        (1e30, 1.5, DeMethod::Analytic),
        (1e30, 10.0, DeMethod::Analytic),
        (1e6, 1.5, DeMethod::Potential),
        (1e30, 1.5, DeMethod::SinhPotential),
    ] {
        let f = Fractal {
            bailout,
            de,
            precision: Precision::F32,
            ..Fractal::default()
        };
        sees_the_bulb(&f, radius);
    }
}

#[test]
fn a_julia_camera_on_the_critical_point_sees_the_set() {
    // In Julia mode the derivative of z ↦ zⁿ + c is 0 at z = 0: the
    // naive estimate there is 0 (every ray would hit at once) and, nearby,
    // far too large. c = (0.8, 0.3, 0.2) leaves 0 outside the set, which is first
    // met 0.59 along the view: each ray must find what it finds when
    // started 0.3 along, past the critical point, where membership finds
    // nothing before.
    for de in DeMethod::ALL {
        for precision in [Precision::F64, Precision::F32] {
            let f = Fractal {
                julia: Some(DVec3::new(0.8, 0.3, 0.2)),
                de,
                precision,
                ..Fractal::default()
            };
            assert!(!f.contains(DVec3::ZERO));
            for position in [DVec3::ZERO, DVec3::new(1e-3, 0.0, 0.0), DVec3::splat(-1e-7)] {
                let camera = Camera {
                    position,
                    target: position + DVec3::new(0.2, -0.1, 1.0),
                    fov_degrees: 30.0,
                    ..Camera::default()
                };
                let frame = camera.frame();
                let settings = MarchSettings::default();
                let (mut same, mut hits) = (0, 0);
                for y in 0..18 {
                    for x in 0..32 {
                        let ray = frame.ray(x as f64 + 0.5, y as f64 + 0.5, 32, 18);
                        let (member, _) =
                            march_by_membership(&ray, &f, &settings, 0.25, 1e-4, 1_000_000);
                        assert!(member.is_none_or(|t| t > 0.3));
                        let later = Ray {
                            origin: ray.at(0.3),
                            start_footprint: ray.footprint(0.3),
                            ..ray
                        };
                        let want = march(&later, &f, &settings).hit.map(|hit| 0.3 + hit.t);
                        let got = march(&ray, &f, &settings).hit.map(|hit| hit.t);
                        hits += usize::from(got.is_some());
                        same += usize::from(match (got, want) {
                            (Some(t), Some(u)) => {
                                (t - u).abs() <= NEAR_FOOTPRINTS * ray.footprint(u)
                            }
                            (None, None) => true,
                            _ => false,
                        });
                    }
                }
                assert!(
                    hits > 200,
                    "{de:?} {precision:?} from {position}: {hits} hits"
                );
                assert!(
                    same >= 576 - 576 / 10,
                    "{de:?} {precision:?} from {position}: {same} of 576 rays as from 0.3 along"
                );
            }
        }
    }
}

#[test]
fn escape_length_in_f32_steps_from_just_outside_the_surface() {
    // The escape-length stencil is 3.4e-4·|p| wide in f32: from 1e-3 … 1e-7
    // outside the surface it straddled it, its samples overflowed, and the
    // ray stopped where it started.
    for precision in [Precision::F32, Precision::F64] {
        let f = Fractal {
            de: DeMethod::EscapeLength,
            precision,
            ..Fractal::default()
        };
        let reference = MarchSettings::default();
        for dir in [DVec3::new(0.1, -0.2, -1.0), DVec3::new(-0.3, 0.1, -1.0)] {
            let fine = Ray {
                origin: DVec3::new(0.0, 0.3, 3.0),
                dir: dir.normalize(),
                pixel_angle: 1e-12,
                start_footprint: 0.0,
            };
            let (crossing, _) = march_by_membership(&fine, &f, &reference, 0.25, 1e-3, 1_000_000);
            let crossing = crossing.expect("the ray meets the bulb");
            for offset in [1e-3, 1e-4, 1e-5, 1e-6, 1e-7] {
                let ray = Ray {
                    origin: fine.at(crossing - offset),
                    pixel_angle: 1e-3,
                    ..fine
                };
                let t = march(&ray, &f, &reference).hit.map(|hit| hit.t);
                let t = t.unwrap_or_else(|| panic!("{precision:?} {offset}: no hit"));
                if f.contains(ray.origin) {
                    // A speck of the set the membership steps passed over.
                    assert_eq!(t, 0.0);
                    continue;
                }
                assert!(
                    t > 0.25 * offset && t < offset + 1e-4,
                    "{precision:?} from {offset:e} outside: hit at {t:e}"
                );
            }
        }
    }
}

/// A zoom onto the surface in f32 and in f64, one frame a decade from 1e-3
/// to 1e-7 from the target: pixels of 8e-6 down to 8e-10.
fn zoom_in(precision: &str) -> String {
    format!(
        "(fps: 1, frames: 5, size: (48, 27), scene: (camera: (position: (2.4548, 3.5662, 1.9590), target: (0.503044367725, 0.443308880733, 0.397566446799), fov_degrees: 40), fractal: (iterations: 20, precision: {precision})), tracks: {{ \"camera.distance\": (interpolation: Linear, keys: [(time: 0, value: 1e-3), (time: 4, value: 1e-7)]) }})"
    )
}

#[test]
fn frames_finer_than_f32_resolves_render_in_f64() {
    let d = Dir::new();
    d.write("f32.ron", &zoom_in("F32"));
    d.write("f64.ron", &zoom_in("F64"));
    for (name, out) in [("f32.ron", "a"), ("f64.ron", "b")] {
        d.ok(&["render", name, "--out", out, "--quiet"]);
    }
    let pixels = |rel: &str| {
        image::open(d.path().join(rel))
            .unwrap()
            .to_rgb8()
            .into_raw()
    };
    // Frame 0's pixels (1.6e-5 of the target) are f32's own; below 2^-16
    // of the target f32 speckled, and each frame is now f64's.
    let frame = |out: &str, f: u32| pixels(&format!("{out}/frame_{f:05}.png"));
    assert_ne!(frame("a", 0), frame("b", 0), "frame 0 is rendered in f32");
    for f in 1..5 {
        assert_eq!(frame("a", f), frame("b", f), "frame {f}");
    }
    let info = stdout(&d.ok(&["info", "f32.ron"]));
    assert!(
        info.contains("f32:      4 frame(s) (1..=4) have pixels finer than f32 resolves"),
        "{info}"
    );
    assert!(!stdout(&d.ok(&["info", "f64.ron"])).contains("f32:"));
    // `pick` marches such a frame as it renders, in world coordinates.
    let point = |name: &str| {
        let pick = ["pick", name, "--frame", "2", "--pixel", "24,13", "--json"];
        let json: serde_json::Value = serde_json::from_str(&stdout(&d.ok(&pick))).unwrap();
        (json["point_digits"].clone(), json["deep"].clone())
    };
    assert_eq!(point("f32.ron"), point("f64.ron"));
}
