//! `mandelreel accuracy` on a tiny frame: the three files, one row per variant,
//! zero error for the reference against itself, the front's rule, the chart.

use crate::util::{stdout, tiny_timeline, Dir};

#[test]
fn accuracy_writes_csv_table_and_chart() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(2, 7.0));
    let out = d.ok(&[
        "accuracy", "t.ron", "--frame", "1", "--size", "24x14", "--quiet",
    ]);
    assert_eq!(
        d.files("out/t"),
        ["accuracy.csv", "accuracy.md", "accuracy.png"]
    );
    let csv = std::fs::read_to_string(d.path().join("out/t/accuracy.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(header[0], "knob");
    let rows: Vec<Vec<String>> = lines
        .map(|l| {
            // Settings are quoted and may hold spaces but no commas.
            l.split(',')
                .map(|f| f.trim_matches('"').to_string())
                .collect()
        })
        .collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    // The reference, the scene, and one row per variant of every knob.
    assert_eq!(rows[0][0], "reference");
    assert_eq!(rows[1][0], "scene");
    for knob in [
        "iterations",
        "bailout",
        "hit_threshold",
        "membership_step",
        "fudge",
        "max_steps",
        "normal_step",
        "samples_per_pixel",
        "adaptive",
        "de",
    ] {
        assert!(rows.iter().any(|r| r[0] == knob), "no {knob} rows");
    }
    assert_eq!(rows.iter().filter(|r| r[0] == "de").count(), 9);
    // Perturbation is a knob of deep frames only (tests/it/deep.rs).
    assert!(!rows.iter().any(|r| r[0] == "perturbation"));
    // Zero error for the reference against itself.
    for c in [
        "depth_error_mean_px",
        "depth_error_p99_px",
        "hit_mismatch",
        "overshoot",
        "image_rmse",
    ] {
        assert_eq!(rows[0][col(c)].parse::<f64>().unwrap(), 0.0, "{c}");
    }
    // Every measurement is a finite number; some variant differs from the reference.
    let mut differs = false;
    for r in &rows[1..] {
        for c in ["seconds", "depth_error_mean_px", "image_rmse"] {
            let v: f64 = r[col(c)].parse().unwrap();
            assert!(v.is_finite() && v >= 0.0, "{} {c} = {v}", r[0]);
        }
        assert!(r[col("de_evaluations")].parse::<u64>().unwrap() > 0);
        differs |= r[col("image_rmse")].parse::<f64>().unwrap() > 0.0;
    }
    assert!(differs);
    // The hits' 3D distance to the set, in footprints, on every row: the
    // reference's below a footprint, the coarsest hit threshold's farther.
    let surface = |r: &Vec<String>| r[col("surface_distance_px")].parse::<f64>().unwrap();
    assert!(surface(&rows[0]) < 1.0, "{}", surface(&rows[0]));
    let coarsest = rows
        .iter()
        .filter(|r| r[0] == "hit_threshold")
        .max_by(|a, b| {
            a[1].parse::<f64>()
                .unwrap()
                .total_cmp(&b[1].parse::<f64>().unwrap())
        })
        .unwrap();
    assert!(surface(coarsest) > surface(&rows[0]), "{coarsest:?}");
    let md = std::fs::read_to_string(d.path().join("out/t/accuracy.md")).unwrap();
    assert_eq!(
        md.lines().filter(|l| l.starts_with("| ")).count(),
        rows.len() + 1
    );
    assert!(stdout(&out).contains("| reference |"));
    // The table says how times were taken and the front computed.
    assert!(md.contains("median of 5 to 21 runs"), "{md}");
    assert!(md.contains("less error at no more than 1.03× its median time"));
    // Two panels side by side over a four-line key: the chart's fixed size.
    let chart = image::open(d.path().join("out/t/accuracy.png")).unwrap();
    assert_eq!((chart.width(), chart.height()), (1600, 900));
}
