//! `info`: validates a timeline and prints its frames, fractal, quality,
//! tracks, effects, the work each sample does, a measured cost, and warnings.

use crate::job::probe::{cost_probe, worst_orbits_per_sample};
use crate::job::warnings::{out_of_steps_matters, out_of_steps_warning, warnings};
use crate::scene::Scene;
use crate::timeline::{Timeline, ZOOM_TRACK};
use std::path::Path;

/// Loads the timeline at `path` and prints what it holds.
pub fn info(path: &Path) -> anyhow::Result<()> {
    let t = Timeline::load(path)?;
    let first = t.scene_at(0);
    let base = &first;
    out!("timeline: {}", path.display());
    out!(
        "frames:   {} at {} fps ({:.3} s), {}x{} pixels, {}",
        t.frame_count,
        t.fps,
        t.duration_seconds(),
        t.width,
        t.height,
        base.sampling_summary()
    );
    if t.looping {
        out!(
            "loop:     seamless: every track repeats every {:.3} s, so frame {} would be frame 0 again",
            t.duration_seconds(),
            t.frame_count
        );
    }
    let f = &base.fractal;
    let animated_julia = t.tracks.iter().any(|tr| tr.name == "fractal.julia");
    let mode = match (f.julia, animated_julia) {
        (_, true) => "Julia mode (constant animated)".to_string(),
        (Some(k), false) => format!("Julia mode, c = ({}, {}, {})", k.x, k.y, k.z),
        (None, false) => "Mandelbrot mode".to_string(),
    };
    out!(
        "fractal:  {mode}, formula {}, power {}, {} iterations, bailout {} (at frame 0)",
        f.formula.name(),
        f.power,
        f.iterations,
        f.bailout
    );
    let walk = match base.quality.membership_step {
        0.0 => String::new(),
        step => format!(", membership walk in steps of {step} x footprint"),
    };
    out!(
        "quality:  DE {} in {}, hit threshold {} x footprint{walk}, fudge {}, {} max steps",
        f.de.name(),
        f.precision.name(),
        base.quality.hit_threshold,
        base.quality.fudge,
        base.quality.max_steps
    );
    print_auto(&t)?;
    print_deep(&t)?;
    print_tracks(&t)?;
    print_plan(base)?;
    print_cost(&t, base)
}

/// Each track: its interpolation, keys and span (a zoom's reach in decades).
fn print_tracks(t: &Timeline) -> anyhow::Result<()> {
    if t.tracks.is_empty() {
        out!("tracks:   none (a still)");
    } else {
        out!("tracks:");
        for tr in &t.tracks {
            let first = tr.key_times[0];
            let last = tr.key_times[tr.key_times.len() - 1];
            let mut line = format!(
                "  {:<24} {:<10} {} key(s), {first:.3} s .. {last:.3} s",
                tr.name,
                format!("{:?}", tr.interpolation),
                tr.key_times.len()
            );
            if tr.name == ZOOM_TRACK {
                let (mut a, mut b) = (tr.sample(first)[0], tr.sample(last)[0]);
                if t.looping {
                    // The last key may be the first again: the zoom's
                    // reach is between its farthest and nearest frames.
                    // (Every frame, or 10 000 spread over a longer film.)
                    let step = (t.frame_count / 10_000).max(1) as usize;
                    let frames = (0..t.frame_count).step_by(step);
                    let d: Vec<f64> = frames.map(|f| tr.sample(t.time_of(f))[0]).collect();
                    a = d.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                    b = d.iter().copied().fold(f64::INFINITY, f64::min);
                }
                line += &format!(
                    "  (log-space zoom {a:.3e} -> {b:.3e}, {:.1} decades)",
                    (a / b).log10().abs()
                );
            }
            out!("{line}");
        }
    }
    Ok(())
}

/// The effects enabled, and the render plan (`job::describe`).
fn print_plan(base: &Scene) -> anyhow::Result<()> {
    for line in crate::job::describe::plan_lines(base) {
        out!("{line}");
    }
    Ok(())
}

/// Frame 0's cost as measured on a thumbnail, where one can be rendered
/// at once, and the warnings.
fn print_cost(t: &Timeline, base: &Scene) -> anyhow::Result<()> {
    // Measured, not guessed: frame 0 as a thumbnail, as declared and with
    // every effect off, counting the estimates.
    let probe = cost_probe(t);
    match &probe {
        Some(p) => out!(
            "cost:     frame 0 at {}x{}{}: {} estimates, {:.2}x the same frame without effects ({})",
            p.width,
            p.height,
            if p.samples < base.samples_per_pixel {
                format!(" with {} of its {} samples per pixel", p.samples, base.samples_per_pixel)
            } else {
                String::new()
            },
            p.with.de_evaluations,
            p.with.de_evaluations as f64 / p.without.de_evaluations.max(1) as f64,
            p.without.de_evaluations
        ),
        None => out!(
            "cost:     not measured: one sample of frame 0 could compute {} orbits of {} \
             iterations (every march to quality.max_steps); render it with --frames 0 --stats",
            worst_orbits_per_sample(&crate::job::probe::deep_steps(base, [t.width, t.height])),
            base.fractal.iterations
        ),
    }
    let probe_short = probe.is_some_and(|p| out_of_steps_matters(&p.with));
    out!("output:   out/{}/ by default", t.name);
    let all: Vec<u32> = (0..t.frame_count).collect();
    for warning in warnings(t, &all, true) {
        out!("warning:  {warning}");
    }
    if probe_short {
        out!(
            "warning:  {} (of the thumbnail)",
            out_of_steps_warning(&[0], t)
        );
    }
    Ok(())
}

/// `iterations: Auto`'s count for every frame, as runs of frames that
/// share a count and what decided it (the target, or the surface under the
/// centre ray); nothing where the timeline gives a number.
fn print_auto(t: &Timeline) -> anyhow::Result<()> {
    use rayon::prelude::*;
    let Some(auto) = t.base.fractal.auto else {
        return Ok(());
    };
    let counts: Vec<_> = (0..t.frame_count)
        .into_par_iter()
        .filter_map(|f| t.auto_count(f))
        .collect();
    let (Some(least), Some(most)) = (
        counts.iter().map(|r| r.count).min(),
        counts.iter().map(|r| r.count).max(),
    ) else {
        return Ok(());
    };
    out!(
        "iterations: Auto, margin {}: {least} to {most} at {}x{} (where the orbit's derivative passes one over a pixel, plus the margin)",
        auto.margin,
        t.width,
        t.height
    );
    let mut runs: Vec<(u32, u32, crate::timeline::auto::Resolved)> = Vec::new();
    for (f, r) in (0..).zip(&counts) {
        match runs.last_mut() {
            Some((_, end, last)) if last == r => *end = f,
            _ => runs.push((f, f, *r)),
        }
    }
    for (start, end, r) in runs {
        let frames = match start == end {
            true => format!("frame {start}"),
            false => format!("frames {start}..={end}"),
        };
        out!("          {frames}: {} ({})", r.count, r.decided.name());
    }
    Ok(())
}

/// The deep frames of `t` at its size, in order, each with its resolution
/// (`deep::resolution`): every frame's scene built and measured once.
fn deep_frames(t: &Timeline) -> Vec<(u32, f64)> {
    use rayon::prelude::*;
    let size = [t.width, t.height];
    let resolution = |f| (f, crate::deep::resolution(&t.scene_at(f), size));
    (0..t.frame_count)
        .into_par_iter()
        .map(resolution)
        .filter(|&(_, r)| r < crate::deep::DEEP_BELOW)
        .collect()
}

/// Which frames ask for f32 but render in f64, since f32 cannot resolve
/// their pixels (`deep::f32_too_coarse`); nothing where none does.
fn print_f32_in_f64(t: &Timeline) -> anyhow::Result<()> {
    use rayon::prelude::*;
    let size = [t.width, t.height];
    let coarse: Vec<u32> = (0..t.frame_count)
        .into_par_iter()
        .filter(|&f| crate::deep::f32_too_coarse(&t.scene_at(f), size))
        .collect();
    let (Some(first), Some(last)) = (coarse.first(), coarse.last()) else {
        return Ok(());
    };
    out!(
        "f32:      {} frame(s) ({first}..={last}) have pixels finer than f32 resolves at {}x{} (2^-16 of the target's coordinates): they render in f64",
        coarse.len(),
        t.width,
        t.height
    );
    Ok(())
}

/// Which frames are deep (`crate::deep`) at the timeline's size, the
/// precision their reference orbits take, and the iterations that resolve
/// the deepest; nothing where every frame is within f64's reach.
fn print_deep(t: &Timeline) -> anyhow::Result<()> {
    print_f32_in_f64(t)?;
    let deep = deep_frames(t);
    let (Some(&(first, _)), Some(&(last, _))) = (deep.first(), deep.last()) else {
        return Ok(());
    };
    // The deepest: the finest pixel against the target's size.
    let deepest = deep
        .iter()
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map_or(last, |&(f, _)| f);
    let scene = t.scene_at(deepest);
    let frames = format!("{} frame(s) ({first}..={last})", deep.len());
    let size = format!("{}x{}", t.width, t.height);
    if crate::fractal::whole_power(scene.fractal.power).is_none() {
        out!("deep:     {frames} are finer than f64 resolves at {size}, but power {} is not a whole number from 2 to 64: perturbation needs one, so they render in f64 and lose their detail", scene.fractal.power);
        return Ok(());
    }
    out!(
        "deep:     {frames} are finer than f64 resolves at {size}: rendered by perturbation, the deepest (frame {deepest}) from a {}-bit reference orbit with up to {} march steps (40 more per decade)",
        crate::deep::bits(&scene, [t.width, t.height]),
        crate::deep::max_steps(&scene, [t.width, t.height])
    );
    if t.base.fractal.auto.is_some() {
        // `print_auto` told each frame's count.
        return Ok(());
    }
    use crate::deep::Derivative;
    let (has, last) = (scene.fractal.iterations, deepest);
    match crate::deep::iterations_for(&scene, [t.width, t.height]) {
        Some(Derivative::Passes(n)) => out!(
            "          frame {last} has {has} iterations; {n} resolve its pixels (where the target's own orbit's derivative passes one over a pixel)"
        ),
        Some(Derivative::Escapes(n)) => out!(
            "          frame {last}: the target's orbit escapes after {n} iterations, before it resolves a pixel: the target is off the surface at this depth (pick --refine)"
        ),
        Some(Derivative::Stays) => out!(
            "          frame {last}: the target is inside the set (its orbit stays bounded): put it on the surface (pick --refine)"
        ),
        None => {}
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exact::tally;
    use std::collections::BTreeSet;

    /// A dive of `frames` frames at 64×36 from 2 units to 1e-30 onto the
    /// power-8 bulb's tip, written as `y` (`timelines/deep_zoom.ron`'s,
    /// turning as it falls), with `iterations: Auto`.
    fn dive(y: &str, frames: u32) -> Timeline {
        let end = (frames - 1) as f64 / 24.0;
        let text = format!(
            r#"(
    fps: 24, frames: {frames}, size: (64, 36),
    scene: (
        camera: (position: (0.575, -2.4, 0.482), target: ("0", "{y}", "0"), up: (0, 1, 0)),
        fractal: (power: 8, iterations: Auto, bailout: 4),
    ),
    tracks: {{
        "camera.distance": (interpolation: Linear,
            keys: [(time: 0, value: 2.0), (time: {end}, value: 1e-30)]),
        "camera.position": (interpolation: CatmullRom,
            keys: [(time: 0, value: (0.575, -2.4, 0.482)), (time: {end}, value: (0.482, -2.4, -0.575))]),
    }},
)"#
        );
        Timeline::parse(&text, Path::new("dive.ron")).unwrap()
    }

    #[test]
    fn planning_a_deep_film_does_each_frames_high_precision_work_once() {
        // Digits of this test's own: the tallies count by string.
        let y = "-1.1040895136738123376495053876233447213253266007801241655145";
        let (frames, size) = (48, [64, 36]);
        let t = dive(y, frames);
        let all: Vec<u32> = (0..frames).collect();
        // What validation, `info`, `render`'s plan and `status` ask of
        // every frame, several times over.
        for f in 0..frames {
            t.invalid_instant(f);
            t.auto_count(f);
            let scenes = t.scenes_for_frame(f);
            crate::output::frames::frame_hash(&scenes, f, size[0], size[1]);
        }
        let deep = deep_frames(&t);
        crate::job::warnings::warnings(&t, &all, true);
        let precisions: BTreeSet<usize> = deep
            .iter()
            .map(|&(f, _)| crate::deep::bits(&t.scene_at(f), size))
            .collect();
        assert!(deep.len() > 10 && deep.len() < frames as usize, "{deep:?}");
        // One difference of the position and the target a frame (and one
        // for the scene as written, checked before the tracks), and one
        // conversion of the target's digits for them all (at the precision
        // of differences) and for each precision a reference orbit takes.
        let differences = tally::differences(y);
        assert!(
            differences <= frames as usize + 1,
            "{differences} differences"
        );
        let conversions = tally::conversions(y);
        let most = precisions.len() + 1;
        assert!(
            conversions <= most,
            "{conversions} conversions, {most} precisions"
        );
    }
}
