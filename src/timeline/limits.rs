//! How large a timeline may be: frames, keys, and the instants and track
//! values checked before rendering, each limit with the message that names
//! the field to change.

use crate::scene::Scene;

/// The most frames a timeline may have: 11.6 hours at 24 fps, longer than
/// any film.
pub const MAX_FRAMES: u32 = 1_000_000;

/// What the frame limit's messages suggest.
pub(super) const FRAMES_HINT: &str = "split a longer film into timelines of its parts";

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
