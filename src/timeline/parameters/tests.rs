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
