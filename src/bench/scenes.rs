//! The benchmark scenes (timelines and their Mandelbulber2 twins) and the work
//! a render of each does, counted in this process.

use super::peak::FLOPS_PER_POWER8_ITERATION;
use crate::error::Error;
use crate::error::Result;
use crate::render::render_frame_into;
use crate::render::Film;
use crate::render::FrameStats;
use crate::render::Layers;
use crate::timeline::Timeline;
use std::path::{Path, PathBuf};

/// One benchmark scene: a timeline and, where there is one, its Mandelbulber2 twin.
#[derive(Clone, Debug)]
pub(super) struct BenchScene {
    pub name: String,
    pub timeline: PathBuf,
    pub fract: Option<PathBuf>,
}

/// The timelines in `dir` (sorted by name) with their `.fract` twins in `fract_dir`.
pub(super) fn scenes(dir: &Path, fract_dir: &Path) -> Result<Vec<BenchScene>> {
    let mut found: Vec<BenchScene> = std::fs::read_dir(dir)
        .map_err(|e| Error::io(dir, e))?
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .map(|timeline| {
            let name = timeline
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default();
            let fract = fract_dir.join(format!("{name}.fract"));
            BenchScene {
                name,
                fract: fract.is_file().then_some(fract),
                timeline,
            }
        })
        .collect();
    found.sort_by(|a, b| a.name.cmp(&b.name));
    if found.is_empty() {
        return Err(Error::usage(
            "--scenes",
            format!("no .ron timelines in {}", dir.display()),
        ));
    }
    Ok(found)
}

/// Work one render does, counted by rendering it in this process (the
/// counts do not depend on threads or timing).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Work {
    pub frames: u32,
    pub pixels: u64,
    pub stats: FrameStats,
    /// Floating-point operations counted as they were done (the ceiling
    /// loop's); where `None`, the DE iterations' (`flops`).
    pub counted_flops: Option<u64>,
}

impl Work {
    /// The floating-point operations done: those counted, or else
    /// `FLOPS_PER_POWER8_ITERATION` for each DE iteration.
    pub(super) fn flops(&self) -> u64 {
        self.counted_flops
            .unwrap_or(self.stats.de_iterations * FLOPS_PER_POWER8_ITERATION)
    }
}

/// Renders every frame of `timeline` at `size` in this process, keeping only the counts.
fn count_work(timeline: &Timeline, size: (u32, u32)) -> Work {
    let mut stats = FrameStats::default();
    let mut film = Film::default();
    for frame in 0..timeline.frame_count {
        let scenes = timeline.scenes_for_frame(frame);
        let (w, h) = size;
        render_frame_into(&mut film, &scenes, frame, w, h, Layers::default(), &|| {});
        stats = stats + film.stats;
    }
    Work {
        frames: timeline.frame_count,
        pixels: size.0 as u64 * size.1 as u64 * timeline.frame_count as u64,
        stats,
        counted_flops: None,
    }
}

/// The timeline of `scene`, and the work of rendering it at its size.
pub(super) fn load_counted(scene: &BenchScene) -> Result<(Timeline, Work)> {
    let timeline = Timeline::load(&scene.timeline)?;
    let work = count_work(&timeline, (timeline.width, timeline.height));
    Ok((timeline, work))
}
