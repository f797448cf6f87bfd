//! `pick`: reads the frame and pixel asked for, and prints the point the
//! ray through that pixel hits (`crate::render::pick`), as text or JSON.

use super::PickArgs;
use crate::error::Error;
use crate::job::request::{check_frame, parse_size};
use crate::timeline::Timeline;

/// Checks the frame and pixel, picks, and prints.
pub fn pick(args: PickArgs) -> anyhow::Result<()> {
    let t = Timeline::load(&args.timeline)?;
    let (width, height) = match &args.size {
        Some(s) => parse_size("--size", s)?,
        None => (t.width, t.height),
    };
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

/// `pick --refine`: re-centres the frame's target and prints it.
fn refine(t: &Timeline, args: &PickArgs, size: [u32; 2]) -> anyhow::Result<()> {
    let scene = t.scene_at(args.frame);
    let refined = crate::render::pick::refine(&scene, size).map_err(|problem| {
        anyhow::anyhow!(
            "{problem}: pick a target on the surface first (pick --pixel), or approach it from outside (camera.position)"
        )
    })?;
    if args.json {
        out!("{}", serde_json::to_string(&refined)?);
        return Ok(());
    }
    for step in &refined.steps {
        out!(
            "camera {:.3e} away: surface {:+.3e} beyond the target",
            step.camera_distance,
            step.beyond_target
        );
    }
    out!(
        "Re-centred for frame {}:  target: {}",
        args.frame,
        as_ron(&refined.target)
    );
    if args.aim {
        aim(&args.timeline, &as_ron(&refined.target))?;
    }
    Ok(())
}
