//! What is allowed but likely not what the author meant: keys outside the
//! film, a camera inside the fractal, effects short of samples, and camera
//! rays that ran out of steps. `render` and `info` print these.

use crate::job::frames::ranges;
use crate::render::FrameStats;
use crate::timeline::{Timeline, Track, ZOOM_TRACK};
use rayon::prelude::*;
use std::time::Instant;

/// Orbit iterations (`iteration_weight`) the camera-inside check of
/// `warnings` may spend, about a fifth of a second on two cores: beyond,
/// it checks frames evenly spread.
const INSIDE_CHECK_ITERATIONS: u64 = 10_000_000;

/// Seconds after which the camera-inside check stops where it is: where
/// orbits are slower than their weight says (a camera on a power's pole
/// axis, where whole powers take the trigonometric form too).
const INSIDE_CHECK_SECONDS: f64 = 0.4;

/// An equirectangular eye's image that is not twice as wide as high:
/// its pixels are not square, and 360° players stretch it.
fn equirectangular_shape(timeline: &Timeline) -> Option<String> {
    use crate::camera::Projection;
    let camera = &timeline.base.camera;
    if camera.projection != Projection::Equirectangular {
        return None;
    }
    let [w, h] = camera.eye_size([timeline.width, timeline.height]);
    (w != 2 * h).then(|| {
        format!(
            "an equirectangular image is twice as wide as high, and each eye's here is {w}×{h}: \
             its pixels are not square, and 360° players will stretch it"
        )
    })
}

/// What is allowed but likely not what the author meant, in `frames` of
/// `timeline`: `render` and `info` print these. `samples_matter` is false
/// for previews, which take one sample whatever the timeline says. Nothing
/// is kept per frame but its number where a warning names it.
pub fn warnings(timeline: &Timeline, frames: &[u32], samples_matter: bool) -> Vec<String> {
    let mut said = Vec::new();
    // Keys all on one side of the film: the track never changes a frame.
    let end = timeline.time_of(timeline.frame_count - 1);
    // (A looping film's keys all lie in its period, and repeat.)
    let animating = |t: &&Track| !timeline.looping && t.key_times.len() > 1;
    for track in timeline.tracks.iter().filter(animating) {
        let (first, last) = (
            track.key_times[0],
            track.key_times[track.key_times.len() - 1],
        );
        let (side, held) = if first > end {
            (format!("after the last frame (t = {end:.3} s)"), "first")
        } else if last < 0.0 {
            ("before the first frame (t = 0 s)".to_string(), "last")
        } else {
            continue;
        };
        said.push(format!(
            "every key of track \"{}\" ({first} s .. {last} s) is {side}: it does not animate, \
             every frame holds its {held} key's value",
            track.name
        ));
    }
    if let Some(message) = camera_inside(timeline, frames) {
        said.push(message);
    }
    said.extend(equirectangular_shape(timeline));
    // Effects that need several samples a pixel, declared with too few:
    // not an error (a test render may want it), but not what they look like.
    // No track animates the samples or the shutter; one may open the lens.
    if samples_matter {
        use crate::scene::{LENS_SAMPLES, MOTION_BLUR_SAMPLES};
        let base = &timeline.base;
        let lens = timeline.with_tracks(|name| name == "camera.aperture_radius");
        let short_for_lens: Vec<u32> = if base.samples_per_pixel < LENS_SAMPLES {
            frames
                .par_iter()
                .copied()
                .filter(|&f| lens.scene_at(f).camera.frame().has_lens())
                .collect()
        } else {
            Vec::new()
        };
        let short_for_blur =
            if base.effects.motion_blur.is_some() && base.samples_per_pixel < MOTION_BLUR_SAMPLES {
                frames.to_vec()
            } else {
                Vec::new()
            };
        let needs = [
            (
                short_for_lens,
                "depth of field",
                LENS_SAMPLES,
                "to be smooth",
            ),
            (
                short_for_blur,
                "motion blur",
                MOTION_BLUR_SAMPLES,
                "to blur rather than ghost",
            ),
        ];
        for (short, effect, n, why) in needs {
            if !short.is_empty() {
                said.push(format!(
                    "{effect} needs samples_per_pixel of {n} or more {why}; frame(s) {} have fewer",
                    ranges(&short)
                ));
            }
        }
    }
    said
}

/// The warning for `frames` of `timeline` whose camera is inside the
/// fractal, if any: not an error (a fly-through may pass through the
/// surface), but those frames show only the inside, since every ray starts
/// in the set. A point inside costs the full iterations to tell, so past
/// `INSIDE_CHECK_ITERATIONS` in all, frames evenly spread are checked.
fn camera_inside(timeline: &Timeline, frames: &[u32]) -> Option<String> {
    // Scenes with only the tracks that matter are quicker to build.
    let counting =
        timeline.with_tracks(|name| ["fractal.iterations", "fractal.power"].contains(&name));
    let cost: u64 = frames
        .par_iter()
        .map(|&f| {
            let fractal = counting.scene_at(f).fractal;
            fractal.iterations as u64 * iteration_weight(&fractal)
        })
        .sum();
    let moving = ["camera.position", "camera.target", ZOOM_TRACK];
    let timeline =
        &timeline.with_tracks(|name| moving.contains(&name) || name.starts_with("fractal."));
    let stride = cost.div_ceil(INSIDE_CHECK_ITERATIONS).max(1) as usize;
    let checked: Vec<u32> = frames.iter().step_by(stride).copied().collect();
    let (inside, done) = frames_inside(timeline, &checked);
    if inside.is_empty() {
        return None;
    }
    let which = if stride == 1 && done == checked.len() {
        let frames: Vec<u32> = inside.iter().map(|&k| checked[k]).collect();
        format!("{} frame(s) ({})", frames.len(), ranges(&frames))
    } else {
        // Runs of frames checked one after another, each from its first
        // frame to its last.
        let mut runs: Vec<(usize, usize)> = Vec::new();
        for &k in &inside {
            match runs.last_mut() {
                Some((_, last)) if *last + 1 == k => *last = k,
                _ => runs.push((k, k)),
            }
        }
        let shown: Vec<String> = runs
            .iter()
            .map(|&(a, b)| match (checked[a], checked[b]) {
                (a, b) if a == b => a.to_string(),
                (a, b) => format!("{a}-{b}"),
            })
            .collect();
        let spread = if stride > 1 {
            format!(", one in {stride} of {}", frames.len())
        } else {
            String::new()
        };
        let stopped = if done < checked.len() {
            format!(
                ", up to frame {}: slow to check for this fractal",
                checked[done - 1]
            )
        } else {
            String::new()
        };
        format!(
            "{} of the {done} frames checked{spread}{stopped} ({})",
            inside.len(),
            shown.join(", ")
        )
    };
    Some(format!(
        "the camera is inside the fractal in {which}; they render as a flat inside colour"
    ))
}

/// Which of `frames` (their indices) have the camera inside the fractal,
/// and how many were checked: all of them, unless `INSIDE_CHECK_SECONDS`
/// ran out first. A frame whose camera and fractal are those of the frame
/// before is not checked again.
fn frames_inside(timeline: &Timeline, frames: &[u32]) -> (Vec<usize>, usize) {
    let started = Instant::now();
    let (mut inside, mut done) = (Vec::new(), 0);
    for block in frames.chunks(256) {
        let found: Vec<bool> = block
            .par_chunks(16)
            .flat_map_iter(|run| {
                let mut last: Option<(crate::scene::Scene, bool)> = None;
                run.iter().map(move |&f| {
                    let s = timeline.scene_at(f);
                    let same = |(l, _): &&(crate::scene::Scene, bool)| {
                        l.camera.position == s.camera.position
                            && l.camera.offset == s.camera.offset
                            && l.fractal == s.fractal
                    };
                    if let Some((_, was)) = last.as_ref().filter(same) {
                        return *was;
                    }
                    // A deep frame's camera is placed from its target more
                    // finely than f64 holds its position.
                    let is = match timeline.prepare_deep(&s) {
                        Some(d) => d.fractal.contains(d.camera.position),
                        None => s.fractal.contains(s.camera.position),
                    };
                    last = Some((s, is));
                    is
                })
            })
            .collect();
        let found = found.iter().enumerate().filter(|(_, &is)| is);
        inside.extend(found.map(|(k, _)| done + k));
        done += block.len();
        if started.elapsed().as_secs_f64() > INSIDE_CHECK_SECONDS {
            break;
        }
    }
    (inside, done)
}

/// What an orbit iteration of `fractal` costs, in iterations of a whole
/// power (complex squaring): other powers take the trigonometric form,
/// about eight times as long.
pub fn iteration_weight(fractal: &crate::fractal::Fractal) -> u64 {
    if crate::fractal::whole_power(fractal.power).is_some() {
        1
    } else {
        8
    }
}

/// Whether enough of a frame's camera rays ran out of steps to say so: 1%.
pub fn out_of_steps_matters(stats: &FrameStats) -> bool {
    stats.out_of_steps * 100 >= stats.samples.max(1)
}

/// What to say of `frames`, in each of which 1% or more of the camera rays
/// ran out of `quality.max_steps`.
pub fn out_of_steps_warning(frames: &[u32], timeline: &Timeline) -> String {
    let scene = timeline.scene_at(frames[0]);
    let quality = &scene.quality;
    let steps = crate::deep::steps_of(&scene, [timeline.width, timeline.height]);
    let deeper = if steps > quality.max_steps {
        " with 40 more a decade of a deep frame's depth"
    } else {
        ""
    };
    format!(
        "in frame(s) {}, 1% or more of the camera rays ran out of quality.max_steps ({steps}{deeper}) and \
         count as hits where they stopped (a false surface in the background): raise max_steps{}",
        ranges(frames),
        if quality.fudge < 0.5 {
            format!(", or quality.fudge ({}): a step of a fudge of the estimate needs about 1/fudge times the steps", quality.fudge)
        } else {
            String::new()
        }
    )
}

/// An alpha channel asked of a scene that draws its background: every
/// pixel is opaque, which is seldom why a format with alpha was chosen.
pub fn opaque_alpha(timeline: &Timeline, formats: &[crate::output::Format]) -> Option<String> {
    let with_alpha = formats.contains(&crate::output::Format::Png16Alpha);
    (with_alpha && !timeline.base.look.transparent_background).then(|| {
        "png16alpha of a scene that draws its background: alpha is 1 in every pixel; \
         set look: (transparent_background: true) in the timeline for alpha that is the \
         fractal's coverage"
            .to_string()
    })
}
