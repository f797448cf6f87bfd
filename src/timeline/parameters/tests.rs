use super::*;

#[test]
fn every_parameter_sets_its_field() {
    let all_effects = Scene {
        effects: crate::shade::Effects {
            shadows: Some(Default::default()),
            ambient_occlusion: Some(Default::default()),
            specular: Some(Default::default()),
            fog: Some(Default::default()),
            glow: Some(Default::default()),
            motion_blur: None,
            path_tracing: None,
        },
        camera: crate::camera::Camera {
            projection: Projection::Fisheye { degrees: 180.0 },
            stereo: Some(crate::camera::Stereo {
                eye_separation: 0.03,
                layout: crate::camera::StereoLayout::SideBySide,
            }),
            ..Default::default()
        },
        ..Scene::default()
    };
    let mut all_effects = all_effects;
    all_effects.look.palette = Some(crate::shade::Palette {
        stops: vec![crate::shade::Palette::default().stops[0]; MAX_STOPS],
        scale: 1.0,
        ..Default::default()
    });
    for p in all() {
        let mut scene = all_effects.clone();
        let before = scene.clone();
        let v = vec![0.25; p.shape.components()];
        (p.set)(&mut scene, &v);
        assert_ne!(scene, before, "{} changed nothing", p.name);
    }
}

#[test]
fn the_list_of_parameters_is_the_table() {
    let listed: Vec<(&str, usize)> = all().map(|p| (p.name, p.shape.components())).collect();
    assert_eq!(PARAMETERS, &listed[..]);
    for (i, (name, _)) in PARAMETERS.iter().enumerate() {
        assert!(
            !PARAMETERS[..i].iter().any(|(n, _)| n == name),
            "{name} twice"
        );
        assert_eq!(find(name).map(|p| p.name), Some(*name));
    }
}

#[test]
fn each_docs_value_starts_with_its_shape() {
    for p in all() {
        let word = match p.shape {
            Shape::Number => "number",
            Shape::Triple => "triple",
        };
        assert!(p.doc.starts_with(word), "{}: {}", p.name, p.doc);
    }
}

#[test]
fn the_default_scene_passes_every_check() {
    let scene = Scene::default();
    for p in all() {
        assert_eq!((p.check)(&scene), Ok(()), "{}", p.name);
    }
}

#[test]
fn the_docs_table_of_parameters_is_the_generated_one() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/timeline.md");
    let docs = std::fs::read_to_string(&path).unwrap_or_default();
    let table = docs
        .split_once("<!-- parameters:begin -->\n")
        .and_then(|(_, rest)| rest.split_once("<!-- parameters:end -->"))
        .map(|(table, _)| table.trim_matches('\n'));
    let expected = markdown_table();
    assert!(
        table == Some(expected.trim_end_matches('\n')),
        "{} should hold, between the lines `<!-- parameters:begin -->` and \
         `<!-- parameters:end -->`, the table of parameters \
         `timeline::parameters::markdown_table` gives:\n\n{expected}",
        path.display()
    );
}

#[test]
fn validation_orders_name_each_quality_and_look_parameter_once() {
    use crate::timeline::validate::{LOOK_CHECKS, QUALITY_CHECKS};
    for (group, order) in [(QUALITY, &QUALITY_CHECKS[..]), (LOOK, &LOOK_CHECKS[..])] {
        let mut names: Vec<&str> = group.iter().map(|p| p.name).collect();
        let mut ordered = order.to_vec();
        names.sort_unstable();
        ordered.sort_unstable();
        assert_eq!(names, ordered);
    }
}

#[test]
fn of_two_wrong_fields_validation_names_the_one_it_always_checked_first() {
    use crate::timeline::validate_scene;
    let mut s = Scene::default();
    s.quality.normal_step = 0.0;
    s.quality.fudge = 2.0;
    assert_eq!(validate_scene(&s).unwrap_err().0, "quality.normal_step");
    let mut s = Scene::default();
    s.look.exposure = -1.0;
    s.look.background_top = crate::math::Vec3::splat(-1.0);
    assert_eq!(validate_scene(&s).unwrap_err().0, "look.background_top");
}

/// The error parsing timeline `text` gives.
fn error_of(text: &str) -> String {
    crate::timeline::Timeline::parse(text, std::path::Path::new("test.ron"))
        .expect_err("timeline should be rejected")
        .to_string()
}

/// A timeline of two frames whose look has the palette `palette`, with `tracks`.
fn palette_timeline(palette: &str, tracks: &str) -> String {
    format!(
        "(fps: 1, frames: 2, size: (8, 6),\n scene: (look: (palette: {palette})),\n tracks: {{ {tracks} }})"
    )
}

#[test]
fn palette_parts_animate_from_tracks() {
    let text = palette_timeline(
        "(stops: [(position: 0, colour: (1, 0, 0)), (position: 1, colour: (0, 0, 1))])",
        "\"look.palette.offset\": (interpolation: Linear, keys: [(time: 0, value: 0), (time: 1, value: 0.5)]),\n \
         \"look.palette.stops[1].colour\": (keys: [(time: 0, value: (0, 1, 0))])",
    );
    let t = crate::timeline::Timeline::parse(&text, std::path::Path::new("test.ron")).unwrap();
    let (a, b) = (t.scene_at(0), t.scene_at(1));
    let (pa, pb) = (a.look.palette.unwrap(), b.look.palette.unwrap());
    assert_eq!((pa.offset, pb.offset), (0.0, 0.5));
    assert_eq!(pb.stops[1].colour, crate::math::Vec3::new(0.0, 1.0, 0.0));
    assert_eq!(pb.by, crate::shade::OrbitQuantity::SmoothIterations);
}

#[test]
fn bad_palettes_are_refused_at_their_line_and_column() {
    let stops = |positions: &[&str]| {
        let stops: Vec<String> = positions
            .iter()
            .map(|p| format!("(position: {p}, colour: (1, 1, 1))"))
            .collect();
        format!("(stops: [{}])", stops.join(", "))
    };
    // Out of order: the later stop's position, where it is written.
    let e = error_of(&palette_timeline(&stops(&["0.5", "0.25"]), ""));
    assert!(
        e.starts_with("test.ron:2:82: scene.look.palette.stops[1].position: stops go in order"),
        "{e}"
    );
    let e = error_of(&palette_timeline(&stops(&["0", "1.5"]), ""));
    assert!(
        e.starts_with("test.ron:2:80: scene.look.palette.stops[1].position: must be in [0, 1]"),
        "{e}"
    );
    let e = error_of(&palette_timeline(&stops(&["0"; MAX_STOPS + 1]), ""));
    assert!(
        e.starts_with("test.ron:2:34: scene.look.palette.stops: a palette has 1 to 8 stops, got 9"),
        "{e}"
    );
    let e = error_of(&palette_timeline("(stops: [])", ""));
    assert!(e.contains("got 0"), "{e}");
    let e = error_of(&palette_timeline("(by: Hue)", ""));
    assert!(e.starts_with("test.ron:2:31:"), "{e}");
    assert!(e.contains("palette.by") && e.contains("Hue"), "{e}");
    let e = error_of(&palette_timeline("(mix: 2)", ""));
    assert!(
        e.contains("scene.look.palette.mix: must be in [0, 1]"),
        "{e}"
    );
}

#[test]
fn palette_tracks_need_the_palette_and_the_stop() {
    let track = |name: &str| format!("\"{name}\": (keys: [(time: 0, value: 0.5)])");
    let text = "(fps: 1, frames: 2, size: (8, 6), tracks: { \"look.palette.mix\": (keys: [(time: 0, value: 0.5)]) })";
    let e = error_of(text);
    assert!(e.contains("which the scene does not have"), "{e}");
    let e = error_of(&palette_timeline(
        "(stops: [(position: 0, colour: (1, 0, 0))])",
        &track("look.palette.stops[1].position"),
    ));
    assert!(e.contains("stop 1 of the palette, which has 1"), "{e}");
    // A key out of range is blamed on its own line.
    let e = error_of(&palette_timeline(
        "()",
        &track("look.palette.stops[0].position").replace("0.5", "-1"),
    ));
    assert!(e.starts_with("test.ron:3:"), "{e}");
    assert!(e.contains("must be in [0, 1]"), "{e}");
}

#[test]
fn a_scene_without_a_palette_serialises_as_before() {
    let scene = Scene::default();
    let json = serde_json::to_string(&scene).unwrap();
    assert!(!json.contains("palette"), "{json}");
}
