use super::*;
use crate::render::{render_samples, Layers};
use crate::scene::Adaptive;

use crate::render::adaptive_scene as adaptive;

fn schedule(scene: &Scene) -> Vec<u32> {
    let mut done = 0;
    std::iter::from_fn(|| {
        (done < scene.samples_per_pixel).then(|| {
            done = next_wave(scene, done);
            done
        })
    })
    .collect()
}

#[test]
fn waves_double_from_the_first_up_to_the_cap() {
    assert_eq!(schedule(&adaptive(2, 16)), [2, 4, 8, 16]);
    assert_eq!(schedule(&adaptive(3, 16)), [3, 6, 12, 16]);
    assert_eq!(schedule(&adaptive(4, 1)), [1]);
    assert_eq!(schedule(&adaptive(32, 16)), [16]);
    assert_eq!(wave_count(&adaptive(2, 16)), 4);
    let uniform = Scene {
        samples_per_pixel: 40,
        ..Scene::default()
    };
    assert_eq!(
        schedule(&uniform),
        (1..=14).map(|k| (k * 3).min(40)).collect::<Vec<_>>()
    );
    assert_eq!(wave_count(&uniform), 14);
}

/// An accumulation of `w`×`h` whose pixels have the spreads `f` makes,
/// `done` samples in.
fn judged(w: u32, h: u32, done: u32, f: impl Fn(usize) -> Spread) -> Accumulation {
    let mut acc = Accumulation::new(w, h, Layers::default());
    acc.start_spreads();
    acc.samples_done = done;
    for (i, p) in acc.spread.iter_mut().enumerate() {
        *p = f(i);
    }
    acc
}

fn samples(values: &[f64]) -> Spread {
    Spread {
        taken: values.len() as u32,
        grazes: 0,
        sum: values.iter().sum(),
        squares: values.iter().map(|v| v * v).sum(),
    }
}

fn count(out: &[bool]) -> usize {
    out.iter().filter(|&&on| on).count()
}

#[test]
fn pixels_go_on_while_they_or_a_neighbour_are_noisy_grazed_or_stand_out() {
    let scene = adaptive(2, 16).adaptive.expect("adaptive"); // noise 0.02
    let flat = samples(&[0.5, 0.5]);
    let mut out = Vec::new();
    // A flat frame stops everywhere after the first wave.
    refining(&scene, &judged(5, 5, 2, |_| flat), &mut out);
    assert_eq!(count(&out), 0);
    // Two samples 0.1 apart: a standard error of 0.05, above 0.02. The
    // pixel and its eight neighbours go on.
    let noisy = samples(&[0.45, 0.55]);
    refining(
        &scene,
        &judged(5, 5, 2, |i| if i == 12 { noisy } else { flat }),
        &mut out,
    );
    assert_eq!(count(&out), 9);
    assert!(out[6] && out[12] && out[18] && !out[0] && !out[14 + 1]);
    // 0.01 apart: an error of 0.005, below.
    let quiet = samples(&[0.495, 0.505]);
    refining(
        &scene,
        &judged(5, 5, 2, |i| if i == 12 { quiet } else { flat }),
        &mut out,
    );
    assert_eq!(count(&out), 0);
    // A graze goes on though its samples agree; it alone.
    let grazed = Spread { grazes: 1, ..flat };
    refining(
        &scene,
        &judged(5, 5, 2, |i| if i == 0 { grazed } else { flat }),
        &mut out,
    );
    assert_eq!(count(&out), 1);
    assert!(out[0]);
    // A pixel brighter than its neighbours by more than 8 noises (0.2 >
    // 0.16): it and its eight neighbours go on, at any wave.
    for done in [2, 4, 8] {
        let frame = judged(5, 5, done, |i| {
            let v = if i == 12 { 0.7 } else { 0.5 };
            samples(&vec![v; done as usize])
        });
        refining(&scene, &frame, &mut out);
        assert_eq!(count(&out), 9, "after {done} samples");
    }
    // By 0.15, less than 8 noises: all stop.
    let dim = judged(5, 5, 2, |i| samples(&[if i == 12 { 0.65 } else { 0.5 }; 2]));
    refining(&scene, &dim, &mut out);
    assert_eq!(count(&out), 0);
    // A pixel stopped by an earlier wave stays stopped, however noisy,
    // and its noise moves no neighbour.
    let stopped = samples(&[0.0, 1.0, 0.0, 1.0]);
    let acc = judged(
        5,
        5,
        8,
        |i| if i == 3 { stopped } else { samples(&[0.5; 8]) },
    );
    refining(&scene, &acc, &mut out);
    assert_eq!(count(&out), 0);
}

#[test]
fn a_frame_stops_where_it_is_flat_and_refines_its_edges() {
    // The default bulb: the background stops after the first wave; the
    // silhouette's pixels take every sample.
    let scene = Scene {
        samples_per_pixel: 16,
        adaptive: Some(Adaptive::default()),
        ..Scene::default()
    };
    let scenes = std::slice::from_ref(&scene);
    let (w, h) = (48, 36);
    let mut acc = Accumulation::new(w, h, Layers::default());
    while acc.samples_done < 16 {
        let until = next_wave(&scene, acc.samples_done);
        render_samples(scenes, 0, &mut acc, until, &|| {});
    }
    let taken: Vec<u32> = acc.spread.iter().map(|p| p.taken).collect();
    assert_eq!(taken[0], 2, "a corner of background");
    let full = taken.iter().filter(|&&t| t == 16).count();
    let least = taken.iter().filter(|&&t| t == 2).count();
    assert!(
        full > 0 && least > taken.len() / 5,
        "{full} at 16, {least} at 2 of {}",
        taken.len()
    );
    assert_eq!(
        acc.stats.samples,
        taken.iter().map(|&t| t as u64).sum::<u64>()
    );
    // Every pixel with a mixed hit count took every sample.
    for (i, p) in acc.spread.iter().enumerate() {
        if acc.hits[i] > 0 && acc.hits[i] < p.taken {
            assert_eq!(p.taken, 16, "pixel {i}: mixed hits, {} samples", p.taken);
        }
    }
}
