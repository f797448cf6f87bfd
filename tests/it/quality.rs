//! `mandelreel quality`: frames with speckles, pops and errors known by
//! construction, written as PNGs, and a real tiny render against a finer one.

use crate::util::Dir;
use image::{Rgb, RgbImage};

/// Grey 100, 10×8, with a white-ish dot (+100) at each of `dots`.
fn grey_with_dots(dots: &[(u32, u32)]) -> RgbImage {
    let mut img = RgbImage::from_pixel(10, 8, Rgb([100, 100, 100]));
    for &(x, y) in dots {
        img.put_pixel(x, y, Rgb([200, 200, 200]));
    }
    img
}

fn save(d: &Dir, folder: &str, frame: u32, img: &RgbImage) {
    std::fs::create_dir_all(d.path().join(folder)).unwrap();
    img.save(d.path().join(folder).join(format!("frame_{frame:05}.png")))
        .unwrap();
}

/// A: a dot in frame 0, none in 1, another in 2 (two speckles, and a pop
/// at each change); REF: flat grey, frame 1 a step brighter (MSE 1).
fn sequence_and_reference(d: &Dir) {
    save(d, "A", 0, &grey_with_dots(&[(3, 3)]));
    save(d, "A", 1, &grey_with_dots(&[]));
    save(d, "A", 2, &grey_with_dots(&[(6, 4)]));
    save(d, "REF", 0, &grey_with_dots(&[]));
    save(
        d,
        "REF",
        1,
        &RgbImage::from_pixel(10, 8, Rgb([101, 101, 101])),
    );
    save(d, "REF", 2, &grey_with_dots(&[]));
}

fn json(d: &Dir, args: &[&str]) -> serde_json::Value {
    let out = d.ok(args);
    serde_json::from_slice(&out.stdout).expect("quality --json prints JSON")
}

fn stderr(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

#[test]
fn quality_counts_known_speckles_and_pops_and_psnr() {
    let d = Dir::new();
    sequence_and_reference(&d);
    let q = json(&d, &["quality", "A", "--reference", "REF", "--json"]);
    let frames = q["frames"].as_array().unwrap();
    let speckles: Vec<u64> = frames
        .iter()
        .map(|f| f["speckles"].as_u64().unwrap())
        .collect();
    assert_eq!(speckles, [1, 0, 1]);
    let pops: Vec<Option<u64>> = frames.iter().map(|f| f["pops"].as_u64()).collect();
    assert_eq!(pops, [None, Some(1), Some(1)]);
    // A dot 100 off in all three channels of one of 80 pixels: 3·100²/240.
    let mse: Vec<f64> = frames.iter().map(|f| f["mse"].as_f64().unwrap()).collect();
    assert_eq!(mse, [125.0, 1.0, 125.0]);
    assert!((frames[1]["psnr_db"].as_f64().unwrap() - 48.1308).abs() < 1e-4);
    // 10·log10(255²/125) = 27.1617; the whole from the mean MSE, 251/3.
    let worst = q["worst_psnr_db"].as_f64().unwrap();
    assert!((worst - 27.1617).abs() < 1e-4, "{worst}");
    let whole = 10.0 * (255.0_f64.powi(2) / (251.0 / 3.0)).log10();
    assert!((q["psnr_db"].as_f64().unwrap() - whole).abs() < 1e-9);
    assert_eq!(
        (q["speckles"].as_u64(), q["pops"].as_u64()),
        (Some(2), Some(2))
    );
    assert_eq!(q["pixels"].as_u64(), Some(240));
}

#[test]
fn quality_prints_a_table_and_takes_a_range_of_frames() {
    let d = Dir::new();
    sequence_and_reference(&d);
    let out = d.ok(&["quality", "A", "--reference", "REF", "--frames", "1..3"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("| frame | PSNR dB | speckles | pops |"),
        "{text}"
    );
    // Frame 1 is the first measured: no pops to it.
    assert!(text.contains("| 1 | 48.13 | 0 | - |"), "{text}");
    assert!(text.contains("| 2 | 27.16 | 1 | 1 |"), "{text}");
    assert!(!text.lines().any(|l| l.starts_with("| 0 |")), "{text}");
    assert!(text.contains("2 frames: PSNR"), "{text}");
    // Without a reference there is no PSNR.
    let q = json(&d, &["quality", "A", "--json"]);
    assert!(q["psnr_db"].is_null() && q["frames"][0]["mse"].is_null());
}

#[test]
fn quality_reads_rgba_and_16_bit_frames_as_8_bit_rgb() {
    let d = Dir::new();
    std::fs::create_dir_all(d.path().join("A")).unwrap();
    std::fs::create_dir_all(d.path().join("REF")).unwrap();
    let rgba = image::RgbaImage::from_pixel(6, 5, image::Rgba([100, 100, 100, 7]));
    rgba.save(d.path().join("A/frame_00000.png")).unwrap();
    // 100·257 is 100 in 8 bits.
    let deep = image::ImageBuffer::<Rgb<u16>, _>::from_pixel(6, 5, Rgb([25700u16; 3]));
    deep.save(d.path().join("REF/frame_00000.png")).unwrap();
    let q = json(&d, &["quality", "A", "--reference", "REF", "--json"]);
    assert_eq!(q["psnr_db"], "inf");
    assert_eq!(q["frames"][0]["mse"].as_f64(), Some(0.0));
}

#[test]
fn quality_refuses_a_folder_without_frames() {
    let d = Dir::new();
    std::fs::create_dir_all(d.path().join("empty")).unwrap();
    let out = d.run(&["quality", "empty"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("no PNG frames named frame_#####"),
        "{}",
        stderr(&out)
    );
    let out = d.run(&["quality", "empty", "--frame-name", "shot_###"]);
    assert!(stderr(&out).contains("shot_###"), "{}", stderr(&out));
}

#[test]
fn quality_names_a_missing_reference_frame() {
    let d = Dir::new();
    sequence_and_reference(&d);
    std::fs::remove_file(d.path().join("REF/frame_00002.png")).unwrap();
    let out = d.run(&["quality", "A", "--reference", "REF"]);
    assert!(!out.status.success());
    let said = stderr(&out);
    assert!(
        said.contains("frame 2") && said.contains("frame_00002.png"),
        "{said}"
    );
}

#[test]
fn quality_names_the_frame_and_both_sizes_of_a_mismatch() {
    let d = Dir::new();
    sequence_and_reference(&d);
    save(&d, "REF", 1, &RgbImage::new(12, 8));
    let out = d.run(&["quality", "A", "--reference", "REF"]);
    assert!(!out.status.success());
    let said = stderr(&out);
    assert!(
        said.contains("frame 1: it is 10×8 but the reference is 12×8"),
        "{said}"
    );
    // Within the folder, too.
    save(&d, "A", 2, &RgbImage::new(4, 4));
    let out = d.run(&["quality", "A"]);
    assert!(!out.status.success());
    let said = stderr(&out);
    assert!(said.contains("frame 2: it is 4×4"), "{said}");
}

#[test]
fn quality_refuses_a_range_without_frames() {
    let d = Dir::new();
    sequence_and_reference(&d);
    let out = d.run(&["quality", "A", "--frames", "5..9"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("--frames: no frames of 5..9"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn quality_of_a_real_render_against_a_finer_one() {
    let d = Dir::new();
    let zoom = concat!(env!("CARGO_MANIFEST_DIR"), "/timelines/zoom.ron");
    for (samples, out) in [("1", "A"), ("4", "B")] {
        let args = ["render", zoom, "--frames", "0..3", "--size", "32x18"];
        d.ok(&[&args[..], &["--samples", samples, "--out", out, "-q"]].concat());
    }
    let q = json(&d, &["quality", "A", "--reference", "B", "--json"]);
    assert_eq!(q["frames"].as_array().unwrap().len(), 3);
    let psnr = q["psnr_db"].as_f64().expect("a finite PSNR");
    assert!(psnr.is_finite() && psnr > 0.0, "{psnr}");
    let out = d.ok(&["quality", "A", "--reference", "B"]);
    let rows = String::from_utf8_lossy(&out.stdout);
    // The heading, three frames and the whole.
    let is_row = |l: &&str| l.starts_with("| ") && !l.contains("---");
    assert_eq!(rows.lines().filter(is_row).count(), 5, "{rows}");
}
