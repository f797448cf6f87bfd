//! `accuracy`: measures what each quality knob, estimator and precision
//! costs on one frame, and writes the tables and chart.

use super::AccuracyArgs;
use crate::error::Error;
use crate::job::request::{check_eyes, check_frame, parse_size, set_threads};
use crate::timeline::Timeline;
use std::path::Path;

/// Runs `accuracy` and prints its table.
pub fn accuracy(args: AccuracyArgs) -> anyhow::Result<()> {
    // Before the timeline, whose frames are checked on the thread pool.
    set_threads(args.threads)?;
    let t = Timeline::load(&args.timeline)?.with_samples(args.samples);
    let (width, height) = match &args.size {
        Some(s) => parse_size("--size", s)?,
        None => {
            let w = t.width.min(160);
            let h = ((w as u64 * t.height as u64) / t.width as u64).max(1) as u32;
            let [w, h] = t.base.camera.even_eyes([w, h]);
            (w, h)
        }
    };
    check_eyes(&t, (width, height))?;
    check_frame(&t, args.frame)?;
    let out_dir = args
        .out
        .clone()
        .unwrap_or_else(|| Path::new("out").join(&t.name));
    std::fs::create_dir_all(&out_dir).map_err(|e| Error::io(&out_dir, e))?;
    let scene = t.scene_at(args.frame);
    let quiet = args.quiet;
    let report = crate::accuracy::measure(&scene, args.frame, width, height, &|i, n, v| {
        if !quiet {
            eprintln!("[{}/{}] {} = {}", i + 1, n, v.knob, v.setting);
        }
    });
    let title = format!(
        "What accuracy costs: {} frame {} at {width}x{height}, {} threads",
        t.name,
        args.frame,
        rayon::current_num_threads()
    );
    let csv = out_dir.join("accuracy.csv");
    let md = out_dir.join("accuracy.md");
    let png = out_dir.join("accuracy.png");
    let table = crate::accuracy::to_markdown(&report, &format!("## {title}"));
    std::fs::write(&csv, crate::accuracy::to_csv(&report.rows)).map_err(|e| Error::io(&csv, e))?;
    std::fs::write(&md, &table).map_err(|e| Error::io(&md, e))?;
    crate::accuracy::write_chart(&report.rows, &title, &png)?;
    out!("{table}");
    eprintln!(
        "wrote {}, {} and {}",
        csv.display(),
        md.display(),
        png.display()
    );
    Ok(())
}
