//! `render`: turns the arguments into a job (`job::run::Job`), shows its
//! progress as bars (or log lines), says what the job has to say, and
//! prints the ffmpeg command once the film's frames are complete.

use super::RenderArgs;
use crate::job::frames::{frame_summary, frames_text, ranges};
use crate::job::plan::{shell_quote, Plan};
use crate::job::run::{lock, Folder, Job, Tally};
use crate::job::warnings::{opaque_alpha, out_of_steps_matters, out_of_steps_warning, warnings};
use crate::job::waves::{waves, Said};
use crate::render::FrameStats;
use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// The progress bars of a render: frames done, and rows of the current frame.
struct Bars {
    /// Whether they are drawn (standard error is a terminal, and not --quiet).
    shown: bool,
    all: MultiProgress,
    overall: ProgressBar,
    current: ProgressBar,
}

impl Bars {
    /// Bars for `frames` frames of `height` rows, drawn only when `shown`.
    fn new(shown: bool, frames: usize, height: u32) -> Bars {
        let all = MultiProgress::with_draw_target(if shown {
            ProgressDrawTarget::stderr()
        } else {
            ProgressDrawTarget::hidden()
        });
        let overall = all.add(ProgressBar::new(frames as u64));
        overall.set_style(
            ProgressStyle::with_template(
                "{prefix:>8} [{bar:32}] {pos}/{len} frames  {elapsed_precise}  ETA {eta_precise}",
            )
            .expect("template is valid")
            .progress_chars("=> "),
        );
        overall.set_prefix("frames");
        let current = all.add(ProgressBar::new(height as u64));
        current.set_style(
            ProgressStyle::with_template("{prefix:>8} [{bar:32}] {pos}/{len} rows  {msg}")
                .expect("template is valid")
                .progress_chars("=> "),
        );
        Bars {
            shown,
            all,
            overall,
            current,
        }
    }

    /// Prints `line` above the bars when they show, plainly to stderr otherwise.
    fn say(&self, line: String) {
        if self.shown {
            let _ = self.all.println(line);
        } else {
            eprintln!("{line}");
        }
    }
}

/// What a render has done so far, for its summary.
#[derive(Default)]
struct Done {
    totals: FrameStats,
    /// Frames where many camera rays ran out of steps (said once, at the end).
    short_of_steps: Vec<u32>,
    rendered: usize,
}

/// Runs `render`: checks everything, renders the frames that need it, and
/// says what it did.
pub fn render(args: RenderArgs) -> anyhow::Result<()> {
    // Everything is checked before the output folder is touched.
    let job = Job::new(args.request())?;
    let total = job.mine.len();
    let tally = Arc::new(Mutex::new(Tally::default()));
    let bars_drawn = Arc::new(std::sync::OnceLock::new());
    let _reported = report_interrupt(&tally, &bars_drawn, total, job.shard);
    let folder = job.open()?;
    let todo = job.todo(&tally);
    let skipped = total - todo.len();

    let show_bars = !args.quiet && std::io::stderr().is_terminal();
    let bars = Bars::new(show_bars, todo.len(), job.plan.height);
    let _ = bars_drawn.set([bars.overall.clone(), bars.current.clone()]);
    say_before(&job, &folder, &todo, skipped, &args, &bars);

    let started = Instant::now();
    let mut done = Done::default();
    let mut film = crate::render::Film::default();
    let mut render_one = |frame: u32, hash: &str| -> anyhow::Result<()> {
        let stats = render_shown(&job, &mut film, frame, hash, &tally, &bars, &args)?;
        done.totals = done.totals + stats.0;
        if out_of_steps_matters(&stats.0) {
            done.short_of_steps.push(frame);
        }
        done.rendered += 1;
        bars.overall.inc(1);
        // Asked for, so printed even with --quiet.
        if args.stats {
            let pixels = job.plan.width as u64 * job.plan.height as u64;
            bars.say(stats_line(frame, stats.1, &stats.0, pixels));
        } else if !args.quiet && !show_bars {
            eprintln!(
                "frame {frame} ({}/{}) rendered in {:.2} s",
                done.rendered,
                todo.len(),
                stats.1
            );
        }
        Ok(())
    };
    if args.claim {
        let quiet = args.quiet;
        let timeout = args.claim_timeout;
        job.share_claimed(&todo, &tally, &mut render_one, &mut |frames, workers| {
            if !quiet {
                bars.say(format!(
                    "waiting for frame(s) {} claimed by {} (a claim without a heartbeat for {} s is taken over)",
                    ranges(frames),
                    workers.join(", "),
                    timeout.as_secs_f64()
                ));
            }
        })?;
    } else {
        for (frame, hash) in &todo {
            render_one(*frame, hash)?;
        }
    }
    bars.current.finish_and_clear();
    bars.overall.finish_and_clear();
    say_after(&job, &done, skipped, started, &args);
    print_video_command(&job.plan, job.known_complete(), args.quiet)?;
    folder.scaffold.keep();
    Ok(())
}

/// Renders `frame` with its row bar, saying what the frame has to say;
/// returns its stats and the seconds it took.
fn render_shown(
    job: &Job,
    film: &mut crate::render::Film,
    frame: u32,
    hash: &str,
    tally: &Mutex<Tally>,
    bars: &Bars,
    args: &RenderArgs,
) -> anyhow::Result<(FrameStats, f64)> {
    let (scenes, _) = job.plan.frame(frame);
    let current = &bars.current;
    current.reset();
    current.set_prefix(format!("#{frame}"));
    current.set_message(format!("{}x{}", job.plan.width, job.plan.height));
    let t0 = Instant::now();
    current.set_length(job.plan.height as u64 * waves(&scenes) as u64);
    let stats = job.render_one(
        film,
        frame,
        &scenes,
        hash,
        tally,
        &|| current.inc(1),
        &|said| match said {
            Said::Resumed { frame, samples, of } if !args.quiet => bars.say(format!(
                "frame {frame}: resuming from a checkpoint at {samples} of {of} samples per pixel"
            )),
            Said::Resumed { .. } => {}
            Said::CheckpointFailed { frame, error } => bars.say(format!(
                "warning: frame {frame}: could not save a checkpoint ({error}); \
                 going on without one for this frame"
            )),
        },
    )?;
    Ok((stats, t0.elapsed().as_secs_f64()))
}

/// What `--stats` says of a frame.
fn stats_line(frame: u32, seconds: f64, stats: &FrameStats, pixels: u64) -> String {
    format!(
        "frame {frame}: {seconds:.2} s, {} DE evaluations ({:.1} per sample, at most {} in one pixel; primary {}, normals {}, shadows {}, occlusion {}, bounces {}, sun {}), {} of {} samples hit ({} out of steps), {:.2} samples a pixel, {} repaired",
        stats.de_evaluations,
        stats.de_evaluations as f64 / stats.samples.max(1) as f64,
        stats.max_pixel_evaluations,
        stats.primary_evaluations,
        stats.normal_evaluations,
        stats.shadow_evaluations,
        stats.occlusion_evaluations,
        stats.bounce_evaluations,
        stats.sun_evaluations,
        stats.hits,
        stats.samples,
        stats.out_of_steps,
        stats.samples as f64 / pixels.max(1) as f64,
        stats.repaired_samples
    )
}

/// What is said before the first frame renders: warnings, another render
/// on the folder, files cleaned up, frames skipped.
fn say_before(
    job: &Job,
    folder: &Folder,
    todo: &[(u32, String)],
    skipped: usize,
    args: &RenderArgs,
    bars: &Bars,
) {
    let plan = &job.plan;
    let planned: Vec<u32> = todo.iter().map(|(frame, _)| *frame).collect();
    let alpha = opaque_alpha(&plan.timeline, &plan.formats);
    for warning in warnings(&plan.timeline, &planned, !plan.preview)
        .into_iter()
        .chain(alpha)
    {
        bars.say(format!("warning: {warning}"));
    }
    let others = job.others(folder, todo);
    if !others.is_empty() {
        bars.say(format!(
            "warning: another render is running on {} ({}): both will render the frames \
             neither has finished; give every worker --claim to share them",
            plan.out_dir.display(),
            others.join(", ")
        ));
    }
    if !args.quiet && folder.stale > 0 {
        bars.say(format!(
            "removed {} temporary file(s) left by an interrupted render",
            folder.stale
        ));
    }
    if !args.quiet && skipped > 0 {
        bars.say(format!(
            "{skipped} of {} frames already complete and current in {}; rendering {}",
            job.mine.len(),
            plan.out_dir.display(),
            todo.len()
        ));
    }
}

/// What is said once the frames are rendered: frames short of steps, the
/// summary, and the total estimates with --stats.
fn say_after(job: &Job, done: &Done, skipped: usize, started: Instant, args: &RenderArgs) {
    if !done.short_of_steps.is_empty() {
        eprintln!(
            "warning: {}",
            out_of_steps_warning(&done.short_of_steps, &job.plan.timeline)
        );
    }
    let rendered = done.rendered;
    if !args.quiet {
        let elapsed = started.elapsed().as_secs_f64();
        eprintln!(
            "{rendered} frame{} rendered in {elapsed:.1} s ({:.2} s/frame), {skipped} skipped; frames in {}",
            if rendered == 1 { "" } else { "s" },
            elapsed / rendered.max(1) as f64,
            job.plan.out_dir.display()
        );
    }
    if args.stats {
        eprintln!(
            "total DE evaluations: {}, repaired (NaN/inf) samples: {}",
            done.totals.de_evaluations, done.totals.repaired_samples
        );
    }
}

/// After a render: on stdout (scripts run it, so also with `--quiet`) the
/// ffmpeg command for the whole film once every frame of it is complete;
/// else for this render's range alone, under a name of its own so that no
/// complete video is replaced, if that range is complete; and on stderr
/// what is still missing. `known` frames are complete; the others are
/// looked for on disk.
fn print_video_command(plan: &Plan, known: &[u32], quiet: bool) -> anyhow::Result<()> {
    let format = plan.video_format();
    let known: std::collections::HashSet<u32> = known.iter().copied().collect();
    let listed = plan.listing();
    let current = |f: u32| plan.is_current_in(f, format, listed.as_ref());
    let missing: Vec<u32> = (0..plan.timeline.frame_count)
        .filter(|&f| !known.contains(&f) && !current(f))
        .collect();
    let say = |line: String| {
        if !quiet {
            eprintln!("{line}");
        }
    };
    if missing.is_empty() {
        say("encode the video with:".into());
        out!(
            "{}",
            plan.video_command(&(0..plan.timeline.frame_count), format)
        );
        return Ok(());
    }
    let status = format!(
        "mandelreel status {}",
        shell_quote(&plan.out_dir.to_string_lossy())
    );
    let lacking = format!(
        "frame(s) {} of the film are not complete yet",
        frame_summary(&missing)
    );
    // Another worker's frames in this range: nothing to encode on its own.
    if missing.iter().any(|f| plan.range.contains(f)) {
        say(format!(
            "{lacking}; once they are, {status} prints the command that encodes the video"
        ));
        return Ok(());
    }
    say(format!(
        "{lacking} ({status} tells when, and prints the command for the whole video); \
         to encode {} alone, leaving {}.mp4 as it is:",
        frames_text(&plan.range),
        plan.timeline.name
    ));
    out!("{}", plan.video_command(&plan.range, format));
    Ok(())
}

/// On Ctrl-C or SIGTERM, once the render's files are cleaned up (see
/// `interrupt`): clears the progress bars and says how many of the `total`
/// frames of this render (of its `shard`) are complete.
fn report_interrupt(
    tally: &Arc<Mutex<Tally>>,
    bars: &Arc<std::sync::OnceLock<[ProgressBar; 2]>>,
    total: usize,
    shard: Option<(u32, u32)>,
) -> crate::interrupt::Registered {
    let (tally, bars) = (tally.clone(), bars.clone());
    crate::interrupt::report_on_interrupt(move |stop| {
        use std::io::Write as _;
        if let Some(bars) = bars.get() {
            if stop.echoed && !bars[0].is_hidden() {
                // The `^C` went past the bars' last column, onto a line of
                // its own: wipe it, and go back up to where they end.
                let _ = write!(std::io::stderr(), "\r\x1b[2K\x1b[1A");
            }
            // As at the end of a render; rows still finishing draw nothing.
            for bar in bars {
                bar.finish_and_clear();
            }
        }
        let tally = lock(&tally);
        let share = match shard {
            Some((i, n)) if n > 1 => format!(" (shard {i}/{n})"),
            _ => String::new(),
        };
        let done = if tally.checked {
            let complete = tally.complete_now();
            format!(": {complete} of {total} frames complete{share}")
        } else {
            format!(" while checking which of {total} frames are complete{share}")
        };
        // Not `eprintln!`, which panics if standard error is gone.
        let _ = writeln!(
            std::io::stderr(),
            "interrupted{done}; the same command resumes"
        );
    })
}
