//! The second formula through every path a formula takes: the quaternion
//! Julia example rendered, picked and measured from the command line, and
//! its surface checked against the oracle's Hamilton products
//! (`deep_oracle`), which share nothing with mandelreel's triplex form.

use crate::deep_oracle::{self, OracleFractal};
use crate::util::{stdout, Dir};
use mandelreel::fractal::Formula;

fn example() -> String {
    concat!(env!("CARGO_MANIFEST_DIR"), "/timelines/quaternion.ron").to_string()
}

/// The example's fractal at frame 0, as the oracle takes it.
fn oracle() -> OracleFractal {
    OracleFractal {
        formula: Formula::Quaternion,
        power: 2,
        iterations: 14,
        bailout: 4.0,
        julia: Some(["-0.123", "0.745", "0"].map(String::from)),
        bits: 128,
    }
}

#[test]
fn the_quaternion_julia_example_renders_with_the_set_in_view() {
    let d = Dir::new();
    let timeline = example();
    d.ok(&[
        "render",
        &timeline,
        "--frames",
        "0",
        "--size",
        "64x36",
        "--samples",
        "1",
        "--out",
        "o",
        "-q",
    ]);
    let image = image::load_from_memory(&d.bytes("o/frame_00000.png"))
        .unwrap()
        .to_luma8();
    let (centre, corner) = (image.get_pixel(32, 18)[0], image.get_pixel(0, 0)[0]);
    assert!(
        centre > corner + 40,
        "the set is not in the middle: {centre} against {corner}"
    );
    // Lit ridges and shadowed clefts, not one flat tone.
    let set: Vec<u8> = image
        .pixels()
        .map(|p| p[0])
        .filter(|&v| v > corner + 10)
        .collect();
    let (low, high) = (set.iter().min().unwrap(), set.iter().max().unwrap());
    assert!(
        set.len() > 300 && high - low > 80,
        "{} pixels, {low}..{high}",
        set.len()
    );
}

#[test]
fn a_pick_on_the_quaternion_lands_on_the_oracles_surface() {
    let d = Dir::new();
    let timeline = example();
    let f = oracle();
    for pixel in ["32,18", "20,14", "44,20"] {
        let out = d.ok(&[
            "pick", &timeline, "--pixel", pixel, "--size", "64x36", "--json",
        ]);
        let report: serde_json::Value = serde_json::from_str(&stdout(&out)).unwrap();
        assert_eq!(report["hit"], true, "{report}");
        let point: Vec<String> = (0..3).map(|k| report["point"][k].to_string()).collect();
        let point: [String; 3] = point.try_into().unwrap();
        let footprint = report["pixel_footprint"].as_f64().unwrap();
        // Outside the set, within a footprint of it by the oracle's bound,
        // and a footprint further along the ray, inside or nearer still.
        let (distance, _, escaped) = deep_oracle::estimate(&f, &point, [0.0; 3]);
        assert!(escaped, "{pixel}: the hit is inside the set: {report}");
        assert!(
            distance < footprint,
            "{pixel}: {distance} from the set, footprint {footprint}"
        );
        let ray: Vec<f64> = (0..3)
            .map(|k| report["ray_direction"][k].as_f64().unwrap())
            .collect();
        let on = [0, 1, 2].map(|k| ray[k] * footprint);
        let (further, _, escaped) = deep_oracle::estimate(&f, &point, on);
        assert!(
            !escaped || further < distance,
            "{pixel}: {further} against {distance}"
        );
    }
}

#[test]
fn accuracy_measures_the_quaternion() {
    let d = Dir::new();
    let out = d.ok(&[
        "accuracy",
        &example(),
        "--size",
        "32x18",
        "--out",
        "a",
        "-q",
    ]);
    let table = stdout(&out);
    assert!(table.contains("| scene | as in the timeline |"), "{table}");
    // The reference and the scene see the same set: most pixels agree.
    let scene = table.lines().find(|l| l.starts_with("| scene |")).unwrap();
    let differ: f64 = scene
        .split('|')
        .nth(8)
        .unwrap()
        .trim()
        .trim_end_matches('%')
        .parse()
        .unwrap();
    assert!(differ < 20.0, "{scene}");
    assert!(d.path().join("a/accuracy.png").exists());
}
