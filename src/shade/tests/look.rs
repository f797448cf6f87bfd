//! The filmic tone map and the look's serialised form.

use super::*;
use crate::color::ToneMap;

#[test]
fn the_filmic_curve_rolls_off_below_white_and_defaults_are_not_serialised() {
    let f = |x: f32| ToneMap::Filmic.apply(x);
    assert_eq!(f(0.0), 0.0);
    // Narkowicz's fit at a few points, by hand: 0.18·0.4818/0.32493 …
    for (x, y) in [(0.18, 0.2669), (1.0, 0.8038), (4.0, 0.9734)] {
        assert!((f(x) - y).abs() < 1e-3, "f({x}) = {}", f(x));
    }
    let mut last = 0.0;
    // Rising, and below white until about 7.2 (where the fit crosses 1).
    for k in 1..=720 {
        let y = f(k as f32 * 0.01);
        assert!(y > last && y < 1.0, "not rising below 1 at {k}");
        last = y;
    }
    assert!(f(1e6) < 1.04 && f(-1.0) == 0.0 && f(f32::NAN) == 0.0);
    for huge in [1e19, 1e30, f32::MAX, f32::INFINITY] {
        assert!(f(huge) > 1.0, "f({huge}) = {}: white, not black", f(huge));
    }
    assert_eq!(ToneMap::Clip.apply(3.0), 3.0);
    // Left at their defaults, exposure and tone map are not serialised:
    // frames rendered before they existed keep their hashes.
    let json = serde_json::to_string(&Look::default()).unwrap();
    assert!(
        !json.contains("tone_map") && !json.contains("exposure"),
        "{json}"
    );
    let filmic = Look {
        tone_map: ToneMap::Filmic,
        exposure: 2.0,
        ..Look::default()
    };
    let json = serde_json::to_string(&filmic).unwrap();
    assert!(
        json.contains("\"tone_map\":\"Filmic\"") && json.contains("\"exposure\":2.0"),
        "{json}"
    );
    let display = filmic.display_transform();
    assert!(display.apply(0.5) == f(1.0) && !display.is_plain());
}
