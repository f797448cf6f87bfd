//! Deep frames (past f64): against the high-precision oracle, pixel by
//! pixel, across threads, and from the command line.

use crate::deep_oracle::{self, OracleFractal};
use crate::util::{stdout, Dir};
use mandelreel::fractal::Formula;
use mandelreel::march::{march, MarchSettings};
use mandelreel::math::DVec3;
use mandelreel::scene::Scene;

/// A point on the 60-iteration power-8 bulb's surface, to 36 digits
/// (`pick --refine` at 1e-30).
const TARGET: [&str; 3] = [
    "0.503022307080229373071939037055122258",
    "0.443273582773394260215122339228275534",
    "0.397548797954846079557511169564137767",
];

/// Where the camera looks from, far off: its direction from the target.
const FROM: DVec3 = DVec3::new(2.4548, 3.5662, 1.9590);

fn digits() -> [String; 3] {
    TARGET.map(String::from)
}

/// The scene of a camera `distance` from `TARGET`, looking at it.
fn scene(distance: f64) -> Scene {
    let text = format!(
        "(camera: (position: (2.4548, 3.5662, 1.9590), target: (\"{}\", \"{}\", \"{}\"), fov_degrees: 40), fractal: (iterations: 60), quality: (over_relaxation: 1.0, max_steps: 1000))",
        TARGET[0], TARGET[1], TARGET[2]
    );
    let mut s: Scene = ron::from_str(&text).unwrap();
    let away = (FROM - s.camera.target).normalize();
    s.camera.offset = Some(away * distance);
    s.camera.position = s.camera.target + away * distance;
    s
}

fn oracle() -> OracleFractal {
    OracleFractal {
        formula: Formula::Quilez,
        power: 8,
        iterations: 60,
        bailout: 4.0,
        julia: None,
        bits: 192,
    }
}

const SIZE: [u32; 2] = [1920, 1080];

/// The analytic estimate overstates the distance many times where an orbit
/// escapes at the iteration limit, as it does just off a surface refined at
/// that limit: a march steps into the set and bisects back, which a plain
/// sphere tracer cannot. So each hit is checked against the oracle's
/// estimate and membership instead: outside at the hit, and either under
/// the hit threshold there or inside a pixel further, and outside at
/// `samples` points on the way from the camera.
fn check_against_the_oracle(
    s: &Scene,
    oracle: &OracleFractal,
    base: &[String; 3],
    pixels: [(u32, u32); 3],
    samples: u32,
) {
    let outside = |offset: DVec3| deep_oracle::estimate(oracle, base, offset.to_array()).2;
    let distance = s.camera.distance();
    let deep = mandelreel::deep::prepare(s, SIZE).expect("a deep frame");
    let camera = deep.camera.frame();
    for (x, y) in pixels {
        let ray = camera.ray(x as f64 + 0.5, y as f64 + 0.5, SIZE[0], SIZE[1]);
        let marched = march(&ray, &deep.fractal, &deep.quality);
        assert!(!marched.out_of_steps, "pixel ({x}, {y}) ran out of steps");
        let hit = marched.hit.expect("the surface is in view");
        let footprint = ray.footprint(hit.t);
        let at = |t: f64| ray.at(t);
        let place = format!("{distance:e}, pixel ({x}, {y}), hit at {:e}", hit.t);
        let (estimate, _, escaped) = deep_oracle::estimate(oracle, base, at(hit.t).to_array());
        assert!(escaped, "{place}: inside");
        // Stopped by the estimate (under half a footprint), or by
        // bisecting a crossing that is within a footprint.
        let stopped = estimate < 0.5 * footprint * (1.0 + 1e-9);
        assert!(
            stopped || !outside(at(hit.t + footprint)),
            "{place}: estimate {estimate:e}, outside a pixel on"
        );
        for k in 0..samples {
            let t = hit.t * k as f64 / samples as f64;
            assert!(outside(at(t)), "{place}: inside at {k}/{samples}");
        }
    }
}

#[test]
fn deep_hits_agree_with_high_precision_membership() {
    for distance in [1e-20, 1e-30] {
        let pixels = [(960, 540), (700, 300), (1300, 800)];
        check_against_the_oracle(&scene(distance), &oracle(), &digits(), pixels, 64);
    }
}

/// A point on the surface of the rabbit's quaternion Julia set
/// (`timelines/quaternion.ron`'s frame 0), `pick --refine` at 1e-20.
const QUATERNION_TARGET: [&str; 3] = [
    "0.28187549051015906631152909",
    "0.19381999594507400873670005",
    "0.40343175306428212063223989",
];

#[test]
fn deep_quaternion_hits_agree_with_the_oracles_hamilton_products() {
    let [x, y, z] = QUATERNION_TARGET;
    let text = format!(
        "(camera: (position: (1.6, 1.4, 2.6), target: (\"{x}\", \"{y}\", \"{z}\"), fov_degrees: 40), fractal: (formula: Quaternion, power: 2, julia: Some((\"-0.123\", \"0.745\", \"0\")), iterations: 125), quality: (over_relaxation: 1.0, max_steps: 1000))"
    );
    let mut s: Scene = ron::from_str(&text).unwrap();
    let away = (DVec3::new(1.6, 1.4, 2.6) - s.camera.target).normalize();
    s.camera.offset = Some(away * 1e-20);
    let oracle = OracleFractal {
        formula: Formula::Quaternion,
        power: 2,
        iterations: 125,
        julia: Some(["-0.123", "0.745", "0"].map(String::from)),
        ..oracle()
    };
    let target = QUATERNION_TARGET.map(String::from);
    check_against_the_oracle(
        &s,
        &oracle,
        &target,
        [(960, 540), (700, 300), (1300, 800)],
        32,
    );
}

/// The bottom tip of the power-8 bulb (`deep_zoom.ron`'s target), c = −b
/// with b⁷ = 2, to 120 digits.
const TIP: &str = "-1.10408951367381233764950538762334472132532660078012416551453246414210632288038098071659828988630200514689715906557993125397";

/// The tip (`digits`) seen from the side, `distance` away, with
/// `iterations`, checked against the oracle at `bits` on the tip and the
/// crown above it (rays below it pass the tip by, a fixed share of their
/// distance a step, and run out of steps).
fn tip_from_the_side(digits: &str, distance: f64, iterations: u32, bits: usize) {
    let text = format!(
        "(camera: (position: (1.5, -1.3, 1.2), target: (\"0\", \"{digits}\", \"0\"), fov_degrees: 40), fractal: (iterations: {iterations}), quality: (over_relaxation: 1.0, max_steps: 1000))"
    );
    let mut s: Scene = ron::from_str(&text).unwrap();
    let away = (DVec3::new(1.5, -1.3, 1.2) - s.camera.target).normalize();
    s.camera.offset = Some(away * distance);
    let oracle = OracleFractal {
        iterations,
        bits,
        ..oracle()
    };
    let tip = ["0", digits, "0"].map(String::from);
    check_against_the_oracle(&s, &oracle, &tip, [(960, 540), (900, 420), (1040, 470)], 16);
}

#[test]
fn a_few_pixels_a_hundred_decades_down() {
    tip_from_the_side(TIP, 1e-100, 100, 480);
}

/// The same tip to 330 digits, for a camera 1e-300 from it.
const TIP_330: &str = "-1.1040895136738123376495053876233447213253266007801241655145324641421063228803809807165982898863020051468971590655799312539692146804308557965106480583880819616391986439221558381455123439747633950789066468590292118061394214405628351921950077401104391392922233895379037673207050320639038098849444570708452792524058273072548646796718";

#[test]
fn a_few_pixels_three_hundred_decades_down() {
    // Near the tip an orbit's offset grows 16 times an iteration: 250 of
    // them carry a point 1e-300 away out to the bailout.
    tip_from_the_side(TIP_330, 1e-300, 300, 1160);
}

#[test]
fn every_pixel_has_its_own_hit_thirty_decades_down() {
    let deep = mandelreel::deep::prepare(&scene(1e-30), SIZE).unwrap();
    let camera = deep.camera.frame();
    let settings = MarchSettings {
        cone_rays: 1,
        ..deep.quality.clone()
    };
    let mut hits = Vec::new();
    for y in 536..544 {
        for x in 956..964 {
            let ray = camera.ray(x as f64 + 0.5, y as f64 + 0.5, SIZE[0], SIZE[1]);
            let hit = march(&ray, &deep.fractal, &settings).hit.unwrap();
            hits.push((x as f64, y as f64, hit.t, hit.point, ray.footprint(hit.t)));
        }
    }
    for (i, a) in hits.iter().enumerate() {
        for b in &hits[i + 1..] {
            assert_ne!(a.3, b.3, "two pixels share a hit point");
        }
    }
    // No terraces: depth follows a plane (least squares) to a fraction of
    // a footprint, where f64 would step by many.
    let rms = plane_residual(&hits.iter().map(|h| (h.0, h.1, h.2)).collect::<Vec<_>>());
    let footprint = hits[0].4;
    assert!(
        rms < 0.3 * footprint,
        "rms {rms:e} against a footprint of {footprint:e}"
    );
}

/// The rms distance of `z` from the least-squares plane z = a + b·x + c·y.
fn plane_residual(points: &[(f64, f64, f64)]) -> f64 {
    let n = points.len() as f64;
    let mean = |f: &dyn Fn(&(f64, f64, f64)) -> f64| points.iter().map(f).sum::<f64>() / n;
    let (mx, my, mz) = (mean(&|p| p.0), mean(&|p| p.1), mean(&|p| p.2));
    let (mut sxx, mut sxy, mut syy, mut sxz, mut syz) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for &(x, y, z) in points {
        let (x, y, z) = (x - mx, y - my, z - mz);
        (sxx, sxy, syy, sxz, syz) = (
            sxx + x * x,
            sxy + x * y,
            syy + y * y,
            sxz + x * z,
            syz + y * z,
        );
    }
    let det = sxx * syy - sxy * sxy;
    let b = (sxz * syy - syz * sxy) / det;
    let c = (syz * sxx - sxz * sxy) / det;
    let sum: f64 = points
        .iter()
        .map(|&(x, y, z)| (z - mz - b * (x - mx) - c * (y - my)).powi(2))
        .sum();
    (sum / n).sqrt()
}

/// A timeline zooming onto `TARGET` from 1e-12 to 1e-24 over `frames`.
fn deep_timeline(frames: u32) -> String {
    format!(
        "(fps: 1, frames: {frames}, size: (48, 27), scene: (camera: (position: (2.4548, 3.5662, 1.9590), target: (\"{}\", \"{}\", \"{}\"), fov_degrees: 40), fractal: (iterations: 60)), tracks: {{ \"camera.distance\": (interpolation: Linear, keys: [(time: 0, value: 1e-12), (time: {}, value: 1e-24)]) }})",
        TARGET[0],
        TARGET[1],
        TARGET[2],
        frames - 1
    )
}

#[test]
fn deep_frames_are_the_same_on_any_thread_count_and_after_a_resume() {
    let dir = Dir::new();
    dir.write("deep.ron", &deep_timeline(2));
    dir.ok(&[
        "render",
        "deep.ron",
        "--out",
        "one",
        "--threads",
        "1",
        "--quiet",
    ]);
    dir.ok(&[
        "render",
        "deep.ron",
        "--out",
        "two",
        "--threads",
        "2",
        "--quiet",
    ]);
    let read = |folder: &str, frame: u32| {
        std::fs::read(
            dir.path()
                .join(folder)
                .join(format!("frame_{frame:05}.png")),
        )
        .unwrap()
    };
    for frame in 0..2 {
        assert_eq!(read("one", frame), read("two", frame), "frame {frame}");
    }
    std::fs::remove_file(dir.path().join("two/frame_00001.png")).unwrap();
    dir.ok(&["render", "deep.ron", "--out", "two", "--quiet"]);
    assert_eq!(read("one", 1), read("two", 1));
    // And the frames are not blank: a deep frame shows the surface.
    let image = image::load_from_memory(&read("one", 1)).unwrap().to_rgb8();
    let distinct: std::collections::HashSet<_> = image.pixels().map(|p| p.0).collect();
    assert!(distinct.len() > 3, "{} colours", distinct.len());
}

#[test]
fn info_names_the_deep_frames_and_pick_refine_recentres_the_target() {
    let dir = Dir::new();
    dir.write("deep.ron", &deep_timeline(3));
    let info = stdout(&dir.ok(&["info", "deep.ron"]));
    assert!(info.contains("deep:     3 frame(s) (0..=2)"), "{info}");
    // From a target off the surface, refine finds one on it.
    let off = deep_timeline(3).replace(TARGET[0], "0.5030223070");
    dir.write("off.ron", &off);
    let out = stdout(&dir.ok(&["pick", "off.ron", "--frame", "2", "--refine"]));
    let line = out.lines().find(|l| l.starts_with("Re-centred")).unwrap();
    let target = line.split("target: ").nth(1).expect(line);
    let refined = deep_timeline(3).replace(
        &format!("(\"{}\", \"{}\", \"{}\")", TARGET[0], TARGET[1], TARGET[2]),
        target,
    );
    assert!(target.len() > 3 * 28, "too few digits: {target}");
    dir.write("refined.ron", &refined);
    let pick = stdout(&dir.ok(&[
        "pick",
        "refined.ron",
        "--frame",
        "2",
        "--pixel",
        "24,13",
        "--size",
        "49x27",
        "--json",
    ]));
    let report: serde_json::Value = serde_json::from_str(&pick).unwrap();
    assert_eq!(report["deep"], true);
    // The camera is 1e-24 from the refined target, and the surface is there,
    // on the ray through the middle of the view (a pixel's centre at 49×27):
    // within a few footprints, as the last round's move (under half a
    // pixel) shifts that ray across the surface's sheets.
    let distance = report["distance"].as_f64().unwrap();
    let footprint = report["pixel_footprint"].as_f64().unwrap();
    assert!(
        (distance - 1e-24).abs() < 5.0 * footprint,
        "{distance:e}, footprint {footprint:e}"
    );
}

#[test]
fn digits_that_are_not_a_number_are_refused_at_their_line() {
    let dir = Dir::new();
    let bad = deep_timeline(2).replace(TARGET[1], "0.44x3");
    dir.write("bad.ron", &bad);
    let out = dir.run(&["info", "bad.ron"]);
    assert_eq!(out.status.code(), Some(3));
    let said = crate::util::stderr(&out);
    assert!(
        said.contains("bad.ron:1:")
            && said.contains("scene.camera.target[1]")
            && said.contains("\"0.44x3\" is not a decimal number"),
        "{said}"
    );
}

/// Rays passing the tip step a fixed share of their distance from it, so
/// crossing 60 decades takes far more than the 300 steps a scene gets: a
/// deep frame's rays get 40 more a decade, and none runs out.
#[test]
fn deep_frames_take_the_steps_their_depth_needs() {
    let dir = Dir::new();
    dir.write(
        "tip.ron",
        &format!(
            "(fps: 1, frames: 1, size: (64, 36), scene: (camera: (position: (1.5, -1.3, 1.2), target: (\"0\", \"{TIP}\", \"0\"), fov_degrees: 40), fractal: (iterations: 80)), tracks: {{ \"camera.distance\": (keys: [(time: 0, value: 1e-60)]) }})"
        ),
    );
    let out = dir.ok(&["render", "tip.ron", "--quiet", "--stats"]);
    let said = crate::util::stderr(&out);
    assert!(said.contains("(0 out of steps)"), "{said}");
    let info = stdout(&dir.ok(&["info", "tip.ron"]));
    assert!(info.contains("with up to 2770 march steps"), "{info}");
}

/// `accuracy` on a deep frame has a row for f64 alone: on the tip at 1e-9
/// (about 2⁻³³ of its size a pixel at 12×7, where f64's rounding is amplified into
/// noise) it is further from the reference than the frame as rendered.
#[test]
fn accuracy_shows_what_f64_alone_gets_in_a_deep_frame() {
    let dir = Dir::new();
    dir.write(
        "tip.ron",
        &format!(
            "(fps: 1, frames: 1, size: (12, 7), scene: (camera: (position: (1.5, -1.3, 1.2), target: (\"0\", \"{TIP}\", \"0\"), fov_degrees: 40), fractal: (iterations: 40)), tracks: {{ \"camera.distance\": (keys: [(time: 0, value: 1e-9)]) }})"
        ),
    );
    dir.ok(&["accuracy", "tip.ron", "--quiet"]);
    let csv = std::fs::read_to_string(dir.path().join("out/tip/accuracy.csv")).unwrap();
    let rmse = |knob: &str| -> f64 {
        let line = csv.lines().find(|l| l.starts_with(knob)).expect(knob);
        line.split(',').nth(8).unwrap().parse().unwrap()
    };
    let (scene, alone) = (rmse("scene,"), rmse("perturbation,off: f64 alone"));
    assert!(alone > scene, "f64 alone {alone} against {scene}");
}

/// A deep frame whose rays run out of steps is warned of with the steps it
/// took, the scene's and those its depth added, not the scene's alone.
#[test]
fn the_out_of_steps_warning_names_a_deep_frames_steps() {
    let dir = Dir::new();
    dir.write(
        "tip.ron",
        &format!(
            "(fps: 1, frames: 1, size: (48, 27), scene: (camera: (position: (1.5, -1.3, 1.2), target: (\"0\", \"{TIP}\", \"0\"), fov_degrees: 40), fractal: (iterations: 40), quality: (max_steps: 1, fudge: 0.05)), tracks: {{ \"camera.distance\": (keys: [(time: 0, value: 1e-9)]) }})"
        ),
    );
    let out = dir.ok(&["render", "tip.ron", "--quiet"]);
    let said = crate::util::stderr(&out);
    let steps = stdout(&dir.ok(&["info", "tip.ron"]))
        .split("with up to ")
        .nth(1)
        .and_then(|rest| rest.split(' ').next())
        .expect("info names the steps")
        .to_string();
    assert!(
        said.contains(&format!("quality.max_steps ({steps} with 40 more a decade")),
        "{said}"
    );
}

/// A dome master 1e-20 from the target: `info` counts it deep, and it
/// renders from its reference orbit with every channel finite and the
/// surface in view.
#[test]
fn a_fisheye_deep_frame_renders_without_nan() {
    let dir = Dir::new();
    let t = deep_timeline(2)
        .replace("frames: 2", "frames: 1")
        .replace("size: (48, 27)", "size: (24, 24)")
        .replace("fov_degrees: 40", "projection: Fisheye(degrees: 180)")
        .replace("value: 1e-12", "value: 1e-20");
    dir.write("dome.ron", &t);
    let info = stdout(&dir.ok(&["info", "dome.ron"]));
    assert!(info.contains("deep:     1 frame(s)"), "{info}");
    dir.ok(&["render", "dome.ron", "--format", "exr", "--quiet"]);
    let frame = dir.exr("out/dome/frame_00000.exr");
    for (name, values) in &frame.channels {
        assert!(values.iter().all(|v| v.is_finite()), "{name} not finite");
    }
    let hits = frame
        .channel("depth.Z")
        .iter()
        .filter(|&&z| z < 1e9)
        .count();
    assert!(hits > 50, "{hits} pixels see the surface");
}

/// A camera 1e-30 from the tip whose target drifts `shift` along x, keyed
/// as digits, over 1 s of 5 frames; or held at `still` with no track.
fn drift_timeline(track: bool, still: &str) -> String {
    let (tip, from) = (&TIP[..62], "(1.5, -2.4, 1.2)");
    let target = format!("(\"{still}\", \"{tip}\", \"0\")");
    let drift = format!(
        "\"camera.target\": (interpolation: Linear, keys: [(time: 0, value: (\"0\", \"{tip}\", \"0\")), (time: 1, value: (\"0.000000000000000000000000000002\", \"{tip}\", \"0\"))]),"
    );
    format!(
        "(fps: 4, frames: 5, size: (32, 18), scene: (camera: (position: {from}, target: {target}, fov_degrees: 40), fractal: (iterations: 40)), tracks: {{ \"camera.distance\": (keys: [(time: 0, value: 1e-30)]), {} }})",
        if track { drift.as_str() } else { "" }
    )
}

#[test]
fn a_target_keyed_with_digits_pans_thirty_decades_down() {
    let d = Dir::new();
    d.write("drift.ron", &drift_timeline(true, "0"));
    // Frame 2 is halfway: the still whose target is written there.
    d.write(
        "still.ron",
        &drift_timeline(false, "0.000000000000000000000000000001"),
    );
    d.ok(&["render", "drift.ron", "--out", "drift", "--quiet"]);
    d.ok(&[
        "render",
        "still.ron",
        "--out",
        "still",
        "--frames",
        "2",
        "--quiet",
    ]);
    let pixels = |path: &str| {
        image::open(d.path().join(path))
            .unwrap()
            .to_rgb8()
            .into_raw()
    };
    let frames: Vec<Vec<u8>> = (0..5)
        .map(|f| pixels(&format!("drift/frame_{f:05}.png")))
        .collect();
    assert_eq!(frames[2], pixels("still/frame_00002.png"));
    // The view moves at every frame: 2e-30 is about three views across.
    for pair in frames.windows(2) {
        assert_ne!(pair[0], pair[1]);
    }
    let info = stdout(&d.ok(&["info", "drift.ron"]));
    assert!(
        info.contains("5 frame(s) (0..=4) are finer than f64"),
        "{info}"
    );
}

/// One frame of the tip from below, `distance` away, at 32×18.
fn tip_frame(distance: &str) -> String {
    format!(
        "(fps: 1, frames: 1, size: (32, 18), scene: (camera: (position: (0.575, -2.4, 0.482), target: (\"0\", \"{TIP_330}\", \"0\"), fov_degrees: 40), fractal: (iterations: Auto), samples_per_pixel: 1), tracks: {{ \"camera.distance\": (keys: [(time: 0, value: {distance})]) }})"
    )
}

#[test]
fn a_frame_three_hundred_decades_down_renders_and_deeper_is_refused() {
    let dir = Dir::new();
    dir.write("tip.ron", &tip_frame("1e-300"));
    let out = dir.ok(&["render", "tip.ron", "--out", "tip", "--stats"]);
    // The tunnel of terraces fills the frame: every sample hits, and no
    // estimate overflows into a hit at the camera.
    let said = stdout(&out) + &crate::util::stderr(&out);
    assert!(said.contains("576 of 576 samples hit"), "{said}");
    let image = image::open(dir.path().join("tip/frame_00000.png"))
        .unwrap()
        .to_luma8();
    let (lo, hi) = image
        .pixels()
        .fold((255, 0), |(lo, hi), p| (lo.min(p[0]), hi.max(p[0])));
    assert!(hi - lo > 100, "a flat frame: {lo}..{hi}");
    dir.write("deeper.ron", &tip_frame("1e-303"));
    let refused = dir.run(&["info", "deeper.ron"]);
    assert!(!refused.status.success());
    let said = crate::util::stderr(&refused);
    assert!(said.contains("1e-302") && said.contains("camera"), "{said}");
}
