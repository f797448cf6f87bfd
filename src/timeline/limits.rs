//! How large a timeline may be: frames, keys, and the instants and track
//! values checked before rendering, each limit with the message that names
//! the field to change.

use crate::scene::Scene;

/// The most frames a timeline may have: 11.6 hours at 24 fps, longer than
/// any film.
pub const MAX_FRAMES: u32 = 1_000_000;

/// What the frame limit's messages suggest.
pub(super) const FRAMES_HINT: &str = "split a longer film into timelines of its parts";

/// The widest and tallest frame, from the timeline or `--size`.
pub const MAX_SIDE: u32 = 32_768;

// The most each whole-number field of a scene may hold (the least is 1):
// past these a frame takes days, or an effect no longer changes the image.
/// Also the most `--samples` (and the explorer) take.
pub const MAX_SAMPLES: u32 = 4096;
pub(super) const MAX_CONE_RAYS: u32 = 4096;
pub(super) const MAX_ITERATIONS: u32 = crate::fractal::MAX_ITERATIONS;
pub(super) const MAX_MARCH_STEPS: u32 = 1_000_000;
pub(super) const MAX_SHADOW_STEPS: u32 = 100_000;
pub(super) const MAX_OCCLUSION_SAMPLES: u32 = 64;
pub(super) const MAX_BOUNCES: u32 = 1024;
/// Past a few, refining steps stop on their own (the estimate is under a
/// quarter of the threshold or rising).
pub(super) const MAX_REFINE_STEPS: u32 = 64;

/// Every whole-number field of a timeline with its limit, by its path in
/// the file: a number too large for the field's type, or negative, is
/// told the limit the field has rather than the type's. `scene.seed` may
/// be any u64: its 0 stands for no limit of its own.
const COUNTS: [(&str, u32); 13] = [
    ("frames", MAX_FRAMES),
    ("size[0]", MAX_SIDE),
    ("size[1]", MAX_SIDE),
    ("scene.samples_per_pixel", MAX_SAMPLES),
    ("scene.adaptive.first", MAX_SAMPLES),
    ("scene.fractal.iterations", MAX_ITERATIONS),
    ("scene.quality.max_steps", MAX_MARCH_STEPS),
    ("scene.quality.cone_rays", MAX_CONE_RAYS),
    ("scene.quality.refine_steps", MAX_REFINE_STEPS),
    ("scene.effects.shadows.max_steps", MAX_SHADOW_STEPS),
    (
        "scene.effects.ambient_occlusion.samples",
        MAX_OCCLUSION_SAMPLES,
    ),
    ("scene.effects.path_tracing.max_bounces", MAX_BOUNCES),
    ("scene.seed", 0),
];

/// What `quality.refine_steps` past its limit is told: it may be 0.
pub(super) fn refine_outside(got: impl std::fmt::Display) -> String {
    format!("must be 0..={MAX_REFINE_STEPS}, got {got}")
}

/// What a count outside 1..=`most` is told: `got` as written or held.
pub(super) fn count_outside(most: u32, got: impl std::fmt::Display) -> String {
    format!("must be 1..={most}, got {got}")
}

/// What whole-number field `field` given `written` (a number its type
/// cannot hold: negative, or too large) is told, where `field` is one of
/// the timeline's: the same as a number its type holds but its limit
/// does not.
pub(super) fn count_message(field: &str, written: &str) -> Option<String> {
    let (_, most) = COUNTS.iter().find(|(name, _)| *name == field)?;
    let negative = written.starts_with('-');
    Some(match field {
        "scene.seed" if negative => format!("must be 0 or more, got {written}"),
        "scene.seed" => format!("must be at most {}, got {written}", u64::MAX),
        "frames" if negative => format!("must be at least 1, got {written}"),
        "frames" => format!("at most {MAX_FRAMES}, got {written}: {FRAMES_HINT}"),
        "size[0]" | "size[1]" => format!("width and height must be 1..={MAX_SIDE}, got {written}"),
        "scene.quality.refine_steps" => refine_outside(written),
        _ => count_outside(*most, written),
    })
}

/// The most instants a timeline's frames may show: with motion blur each
/// sample of a frame sees the timeline at its own instant. Every one's scene
/// is checked before a frame renders (`Timeline::invalid_instant`), a
/// quarter of a second a million on two cores.
pub const MAX_INSTANTS: u64 = 2_000_000;

/// The most track values sampled in checking every instant (each animated
/// value, a component of a track's parameter, at every instant): from 0.2
/// to 1 s a ten million on two cores, as the tracks' keys grow.
pub const MAX_SAMPLED_VALUES: u64 = 10_000_000;

/// The most keys a timeline's tracks may have in all: a key a frame for
/// an hour at 24 fps, on one track or spread over several.
pub const MAX_KEYS: usize = 100_000;

/// Too many scenes to check: the field to blame (`scene.samples_per_pixel`
/// or `tracks`) and why.
pub type TooMany = (&'static str, String);

/// Whether the instants `frame_count` frames of `scene` show (one each, or
/// one per sample with motion blur), and the `values` a timeline's tracks
/// animate sampled at each, stay within `MAX_INSTANTS` and
/// `MAX_SAMPLED_VALUES`.
pub fn check_scene_count(
    scene: &Scene,
    frame_count: u32,
    values: usize,
) -> std::result::Result<(), TooMany> {
    let samples = scene.samples_per_pixel as u64;
    let (instants, shown) = match scene.effects.motion_blur {
        Some(_) => (
            frame_count as u64 * samples,
            format!("{frame_count} frames × {samples} motion-blurred samples"),
        ),
        None => (frame_count as u64, format!("{frame_count} frames")),
    };
    if instants > MAX_INSTANTS {
        return Err((
            "scene.samples_per_pixel",
            format!(
                "with motion blur each of a frame's samples sees the timeline at its own \
                 instant: {shown} = {instants} instants, more than the {MAX_INSTANTS} a \
                 timeline may have; take fewer frames or samples"
            ),
        ));
    }
    let sampled = instants * values as u64;
    if sampled > MAX_SAMPLED_VALUES {
        return Err((
            "tracks",
            format!(
                "every instant's scene is checked before rendering: {values} animated values \
                 (the tracks' components) × {shown} = {sampled} track samples, more than the \
                 {MAX_SAMPLED_VALUES} checked at most; take fewer frames, samples or tracks"
            ),
        ));
    }
    Ok(())
}
