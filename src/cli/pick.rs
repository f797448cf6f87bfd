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
    let bad = || {
        Error::usage(
            "--pixel",
            format!("expected X,Y inside {width}x{height}, got {:?}", args.pixel),
        )
    };
    let (x, y) = args.pixel.split_once(',').ok_or_else(bad)?;
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
            out!(
                "hit:       ({:.12}, {:.12}, {:.12})",
                point[0],
                point[1],
                point[2]
            );
            out!("distance:  {distance:.6e} along the ray from the camera");
            out!("normal:    ({:.4}, {:.4}, {:.4})", n[0], n[1], n[2]);
            out!("footprint: {footprint:.3e} (one pixel's width there)");
            out!(
                "As a zoom target:  target: ({:.12}, {:.12}, {:.12})",
                point[0],
                point[1],
                point[2]
            );
        }
        None => out!("miss: the ray leaves the bounding sphere without meeting the fractal"),
    }
    Ok(())
}
