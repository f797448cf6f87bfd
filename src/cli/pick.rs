//! `pick`: reads the frame and pixel asked for, and prints the point the
//! ray through that pixel hits (`crate::render::pick`), as text or JSON.

use super::PickArgs;
use crate::error::Error;
use crate::job::request::{check_eyes, check_frame, parse_size};
use crate::timeline::Timeline;

/// Checks the frame and pixel, picks, and prints.
pub fn pick(args: PickArgs) -> anyhow::Result<()> {
    let t = Timeline::load(&args.timeline)?;
    let (width, height) = match &args.size {
        Some(s) => parse_size("--size", s)?,
        None => (t.width, t.height),
    };
    check_eyes(&t, (width, height))?;
    check_frame(&t, args.frame)?;
    let Some(pixel) = &args.pixel else {
        return refine(&t, &args, [width, height]);
    };
    let bad = || {
        Error::usage(
            "--pixel",
            format!("expected X,Y inside {width}x{height}, got {pixel:?}"),
        )
    };
    let (x, y) = pixel.split_once(',').ok_or_else(bad)?;
    let (x, y): (u32, u32) = (
        x.trim().parse().map_err(|_| bad())?,
        y.trim().parse().map_err(|_| bad())?,
    );
    if x >= width || y >= height {
        return Err(bad().into());
    }
    let report =
        crate::render::pick::pick(&t.scene_at(args.frame), args.frame, [x, y], [width, height]);
    if args.json {
        out!("{}", serde_json::to_string(&report)?);
        return Ok(());
    }
    out!("frame {}, pixel ({x}, {y}) of {width}x{height}", args.frame);
    let hit = report
        .point
        .zip(report.distance)
        .zip(report.normal.zip(report.pixel_footprint));
    match hit {
        Some(((point, distance), (n, footprint))) => {
            match report.point_digits.as_ref().filter(|_| report.deep) {
                Some(d) => out!("hit:       ({}, {}, {})", d[0], d[1], d[2]),
                None => out!(
                    "hit:       ({:.12}, {:.12}, {:.12})",
                    point[0],
                    point[1],
                    point[2]
                ),
            }
            out!("distance:  {distance:.6e} along the ray from the camera");
            out!("normal:    ({:.4}, {:.4}, {:.4})", n[0], n[1], n[2]);
            out!("footprint: {footprint:.3e} (one pixel's width there)");
            let target = match report.point_digits.as_ref().filter(|_| report.deep) {
                Some(d) => as_ron(d),
                None => format!("({:.12}, {:.12}, {:.12})", point[0], point[1], point[2]),
            };
            out!("As a zoom target:  target: {target}");
            if args.aim {
                aim(&args.timeline, &target)?;
            }
        }
        None if args.aim => anyhow::bail!(
            "pixel ({x}, {y}) of frame {} misses the fractal: nothing to aim at",
            args.frame
        ),
        None => out!("miss: the ray leaves the bounding sphere without meeting the fractal"),
    }
    Ok(())
}

/// `--aim`: `target` written into the timeline as its `camera.target`.
fn aim(path: &std::path::Path, target: &str) -> anyhow::Result<()> {
    let text = crate::timeline::read_text(path)?;
    let edited = crate::timeline::edit::set_target(&text, target)
        .map_err(|problem| anyhow::anyhow!("{}: cannot aim: {problem}", path.display()))?;
    // Written only as a timeline render would read.
    Timeline::parse(&edited, path)?;
    crate::output::atomic::replace_text(path, &edited)?;
    out!("Aimed: {} now has target: {target}", path.display());
    Ok(())
}

/// A target as the timeline writes one with digits: `("…", "…", "…")`.
fn as_ron(d: &[String; 3]) -> String {
    format!("(\"{}\", \"{}\", \"{}\")", d[0], d[1], d[2])
}

/// Rounds of `--refine` at most: the first walks in from afar; each later
/// one from a step above frame F, until the target stays put there.
const MAX_ROUNDS: usize = 8;

/// A round that moves the target by less than this share of one of frame
/// F's pixels has settled it.
const SETTLED_PIXELS: f64 = 0.5;

/// `pick --refine`: re-centres the frame's target, in rounds until it stays
/// put (`refine_rounds`), and prints it.
fn refine(t: &Timeline, args: &PickArgs, size: [u32; 2]) -> anyhow::Result<()> {
    let Round {
        refined,
        round,
        moved,
        framed,
    } = refine_rounds(t, args, size)?;
    let check = framed.map(|scene| surface_check(&scene, size, args.frame));
    if args.json {
        #[derive(serde::Serialize)]
        struct Report<'a> {
            #[serde(flatten)]
            refined: &'a crate::render::pick::Refined,
            round: usize,
            move_pixels: Option<f64>,
            surface_check: Option<String>,
        }
        let report = Report {
            refined: &refined,
            round,
            move_pixels: moved,
            surface_check: check,
        };
        out!("{}", serde_json::to_string(&report)?);
        return Ok(());
    }
    if let Some(moved) = moved.filter(|&m| m >= SETTLED_PIXELS) {
        out!(
            "note: the target did not settle; this is round {round}'s, which moved it {moved:.1} \
             pixels: aim at another point, or approach from another side (camera.position)"
        );
    }
    out!(
        "Re-centred for frame {}:  target: {}",
        args.frame,
        as_ron(&refined.target)
    );
    if let Some(check) = check {
        out!("{check}");
    }
    if args.aim {
        aim(&args.timeline, &as_ron(&refined.target))?;
    }
    Ok(())
}

/// Whether the refined target is on the surface at `frame` (`scene`, the
/// frame with that target), by the test `info` applies: its orbit's
/// derivative passes one over a pixel before it escapes, and it escapes.
fn surface_check(scene: &crate::scene::Scene, size: [u32; 2], frame: u32) -> String {
    use crate::deep::Derivative;
    match crate::timeline::auto::target_derivative(scene, size) {
        Derivative::Passes(n) => format!(
            "check: on the surface: the target's orbit resolves frame {frame}'s pixels after {n} iterations"
        ),
        Derivative::Escapes(n) => format!(
            "warning: the target's orbit escapes after {n} iterations, before it resolves a pixel of frame {frame}: it is off the surface"
        ),
        Derivative::Stays => format!(
            "warning: the target is inside the set at frame {frame} (its orbit stays bounded)"
        ),
    }
}

/// One round of `--refine`: its target, its number, how far it moved the
/// target in frame F's pixels, and frame F with that target (both none
/// where a track sets the target).
struct Round {
    refined: crate::render::pick::Refined,
    round: usize,
    moved: Option<f64>,
    framed: Option<crate::scene::Scene>,
}

/// Refines the target in rounds, each from the target the last one found,
/// until a round moves it by less than `SETTLED_PIXELS` of frame F's
/// pixels, a round moves it further than the one before (the rounds
/// diverge), or `MAX_ROUNDS`; returns the round that moved it least.
fn refine_rounds(t: &Timeline, args: &PickArgs, size: [u32; 2]) -> anyhow::Result<Round> {
    let text = crate::timeline::read_text(&args.timeline)?;
    let mut scene = t.scene_at(args.frame);
    let pixel = scene.camera.axis_pixel_angle(size) * scene.camera.distance();
    let mut best: Option<Round> = None;
    let mut previous = f64::INFINITY;
    // The frame counts Auto's iterations at the whole image's size.
    let recount = |s: &crate::scene::Scene| auto_count(s, size);
    for round in 1..=MAX_ROUNDS {
        let refined = match crate::render::pick::refine(&scene, size, round == 1, &recount) {
            Ok(refined) => refined,
            // A later round's failure leaves the best round's target,
            // which is never worse than one round's; say why it stopped.
            Err(problem) => return stopped(best, round, &problem, args.json),
        };
        for step in refined.steps.iter().filter(|_| !args.json) {
            out!(
                "camera {:.3e} away: surface {:+.3e} beyond the target",
                step.camera_distance,
                step.beyond_target
            );
        }
        // A target a track sets cannot be tried again: one round.
        let Ok(moved) = crate::timeline::edit::set_target(&text, &as_ron(&refined.target)) else {
            let (moved, framed) = (None, None);
            return Ok(Round {
                refined,
                round,
                moved,
                framed,
            });
        };
        let next = Timeline::parse(&moved, &args.timeline)?.scene_at(args.frame);
        let shift = distance(&scene.camera, &next.camera) / pixel;
        if !args.json {
            out!(
                "round {round}: the target moved {shift:.3} pixels of frame {}",
                args.frame
            );
        }
        let done = shift < SETTLED_PIXELS || shift > previous;
        if best
            .as_ref()
            .is_none_or(|b| b.moved.is_some_and(|m| shift < m))
        {
            let (moved, framed) = (Some(shift), Some(next.clone()));
            best = Some(Round {
                refined,
                round,
                moved,
                framed,
            });
        }
        if done {
            break;
        }
        (previous, scene) = (shift, next);
    }
    best.ok_or_else(|| anyhow::anyhow!("--refine ran no round"))
}

/// The iterations `scene` takes at `size`: Auto's count for its target
/// and camera, or the fixed count.
fn auto_count(scene: &crate::scene::Scene, size: [u32; 2]) -> u32 {
    match scene.fractal.auto {
        Some(auto) => crate::timeline::auto::resolve(scene, auto, size).count,
        None => scene.fractal.iterations,
    }
}

/// Where round `round` of `--refine` failed with `problem`: the best
/// round's result, with a note, or the error where there is none.
fn stopped(best: Option<Round>, round: usize, problem: &str, json: bool) -> anyhow::Result<Round> {
    let Some(best) = best else {
        anyhow::bail!(
            "{problem}: pick a target on the surface first (pick --pixel), or approach it from outside (camera.position)"
        );
    };
    if !json {
        out!(
            "note: round {round} stopped: {problem}; the target below is round {}'s",
            best.round
        );
    }
    Ok(best)
}

/// How far apart two cameras' targets are, from their digits where a deep
/// target has them (f64 would lose the difference).
fn distance(a: &crate::camera::Camera, b: &crate::camera::Camera) -> f64 {
    crate::math::length(crate::exact::difference(
        (a.target, a.target_digits.as_ref()),
        (b.target, b.target_digits.as_ref()),
    ))
}
