//! A render's run: the job checked before the output folder is touched,
//! the folder made and recorded, the frames that need work, and the loop
//! that shares them out through claims. What is shown is the caller's.

use crate::error::Error;
use crate::job::plan::Plan;
use crate::job::request::{parse_shard, set_threads, Request};
use crate::job::waves::Said;
use crate::output::{self, Format};
use crate::render::FrameStats;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// A render checked and ready to start: its plan, its record, and the
/// frames of this worker's share.
pub struct Job {
    pub request: Request,
    pub plan: Plan,
    pub record: crate::job::record::JobRecord,
    /// `--shard I/N`, parsed.
    pub shard: Option<(u32, u32)>,
    /// The frames of this worker's share (every frame without a shard).
    pub mine: Vec<u32>,
}

/// The output folder while a render runs in it.
pub struct Folder {
    /// The render's announcement (`claim::announce_run`): until it is
    /// dropped, `status` lists the render as running. Dropped before
    /// `scaffold`, so that an empty folder can be removed.
    pub running: crate::job::claim::Claim,
    /// Removed again, when dropped, if the render ends having written nothing.
    pub scaffold: crate::job::record::Scaffold,
    /// Temporary files an interrupted render left, now removed.
    pub stale: usize,
}

impl Job {
    /// Checks everything before the output folder is touched; from its
    /// return on, Ctrl-C and SIGTERM clean up and say what is done (where
    /// they cannot be caught, they end the render as they always did).
    pub fn new(request: Request) -> anyhow::Result<Job> {
        // Before the timeline, whose frames are checked on the thread pool.
        set_threads(request.threads)?;
        let mut plan = Plan::new(&request.timeline, &request.sequence)?;
        plan.verify = request.verify;
        let shard = request
            .shard
            .as_deref()
            .map(|s| parse_shard(s, &|k| std::env::var(k).ok()))
            .transpose()?;
        let record = plan.record()?;
        plan.check_memory(request.sequence.size.is_some())?;
        let out_dir = &plan.out_dir;
        if out_dir.exists() && !out_dir.is_dir() {
            let message = format!("{} is a file, not a folder", out_dir.display());
            return Err(Error::usage("--out", message).into());
        }
        let _ = crate::interrupt::install();
        let mine: Vec<u32> = plan
            .range
            .clone()
            .filter(|f| shard.is_none_or(|(i, n)| f % n == i))
            .collect();
        Ok(Job {
            request,
            plan,
            record,
            shard,
            mine,
        })
    }

    /// Makes the output folder, records the job in it (refusing another
    /// sequence's folder unless told to replace it), removes what an
    /// interrupted render left, and announces this render.
    pub fn open(&self) -> anyhow::Result<Folder> {
        let out_dir = &self.plan.out_dir;
        let request = &self.request;
        let scaffold = crate::job::record::Scaffold::make(out_dir)?;
        // Checked under the record's lock, so two renders started at once
        // cannot both pass it.
        let replacing = request.force || request.replace;
        self.record.clone().record_in(out_dir, |old| {
            if replacing {
                return Ok(());
            }
            if old.same_sequence(&self.record) {
                return refuse_other_names(out_dir, old, &self.record);
            }
            let running = crate::job::claim::live_runs(out_dir, request.claim_timeout);
            refuse_other_sequence(out_dir, old, &self.record, running.len())
        })?;
        let stale = output::atomic::remove_stale_partials(out_dir)?;
        let running = crate::job::claim::announce_run(out_dir, request.claim_timeout)?;
        Ok(Folder {
            running,
            scaffold,
            stale,
        })
    }

    /// The frames of this share that need work, with their hashes, so the
    /// progress bar and ETA count only those; the others are counted
    /// complete in `tally`. Their scenes are built again as each renders:
    /// kept, a long film's (a scene per sample under motion blur) would
    /// fill the memory.
    pub fn todo(&self, tally: &Mutex<Tally>) -> Vec<(u32, String)> {
        let mut todo = Vec::new();
        for &frame in &self.mine {
            let (_, hash) = self.plan.frame(frame);
            if self.request.force || !self.plan.is_complete(frame, &hash) {
                todo.push((frame, hash));
            } else {
                lock(tally).complete += 1;
            }
        }
        lock(tally).checked = true;
        todo
    }

    /// Other renders running on this folder, where neither shares the
    /// frames out (--claim, --shard) and this one has frames to render:
    /// not an error, since the frames come out the same, but each frame
    /// neither has finished is rendered twice.
    pub fn others(&self, folder: &Folder, todo: &[(u32, String)]) -> Vec<String> {
        let request = &self.request;
        if request.claim || self.shard.is_some() || todo.is_empty() {
            return Vec::new();
        }
        crate::job::claim::live_runs(&self.plan.out_dir, request.claim_timeout)
            .iter()
            .filter(|run| run.token != folder.running.token())
            .map(crate::job::claim::ClaimRecord::who)
            .collect()
    }

    /// Renders `frame` from its `scenes` (`Plan::render_frame`), noting in
    /// `tally` the files it writes while it writes them and the frame once
    /// complete.
    #[allow(clippy::too_many_arguments)]
    pub fn render_one(
        &self,
        film: &mut crate::render::Film,
        frame: u32,
        scenes: &[crate::scene::Scene],
        hash: &str,
        tally: &Mutex<Tally>,
        on_row: &(dyn Fn() + Sync),
        say: &dyn Fn(Said),
    ) -> anyhow::Result<FrameStats> {
        let plan = &self.plan;
        lock(tally).writing = plan
            .formats
            .iter()
            .map(|&f| {
                (
                    plan.path(frame, f),
                    f,
                    output::frames::stored_key(f, hash, &plan.aovs, plan.exr_compression),
                )
            })
            .collect();
        let every = self.request.checkpoint_every;
        let stats = plan.render_frame(film, frame, scenes, hash, every, on_row, say)?;
        let mut tally = lock(tally);
        tally.complete += 1;
        tally.writing.clear();
        Ok(stats)
    }

    /// Renders `todo` shared with any number of other `--claim` workers:
    /// takes frames one at a time, and waits out frames other live workers
    /// hold, so a worker that dies has its frame taken over by one that did
    /// not. `waiting` hears of the frames held by others, and the workers
    /// holding them, each time that set changes.
    pub fn share_claimed(
        &self,
        todo: &[(u32, String)],
        tally: &Mutex<Tally>,
        render_one: &mut dyn FnMut(u32, &str) -> anyhow::Result<()>,
        waiting: &mut dyn FnMut(&[u32], &[String]),
    ) -> anyhow::Result<()> {
        let (plan, force) = (&self.plan, self.request.force);
        let timeout = self.request.claim_timeout;
        // At most a second: a worker whose last frames others are
        // finishing sees them done that soon.
        let poll = (timeout / 4).clamp(
            std::time::Duration::from_millis(100),
            std::time::Duration::from_secs(1),
        );
        // The frames last reported as held by others (said once per change).
        let mut waiting_for = Vec::new();
        // Frames seen finished, here or by others, are not read again: a
        // worker waiting on a farm's shared storage would otherwise check
        // them all every round (read whole, with --verify).
        let mut finished = vec![false; todo.len()];
        loop {
            let mut held = Vec::new();
            for (k, (frame, hash)) in todo.iter().enumerate() {
                if finished[k] {
                    continue;
                }
                if !force && plan.is_complete(*frame, hash) {
                    finished[k] = true;
                    lock(tally).complete += 1;
                    continue;
                }
                match crate::job::claim::try_claim(&plan.claim_path(*frame), timeout)? {
                    crate::job::claim::Attempt::Claimed(claim) => {
                        // It may have been finished between the check and the claim.
                        if force || !plan.is_complete(*frame, hash) {
                            render_one(*frame, hash)?;
                        } else {
                            lock(tally).complete += 1;
                        }
                        finished[k] = true;
                        drop(claim);
                    }
                    // Another live worker has it: look again next round.
                    crate::job::claim::Attempt::Held(other) => held.push((k, other)),
                }
            }
            // With --force a worker makes one pass: "complete" cannot tell its
            // own fresh frames from old ones, so waiting would re-render them.
            if force {
                break;
            }
            // Frames held when this pass came to them may be done by now.
            held.retain(|(k, _)| {
                let (frame, hash) = &todo[*k];
                finished[*k] = plan.is_complete(*frame, hash);
                lock(tally).complete += usize::from(finished[*k]);
                !finished[*k]
            });
            if held.is_empty() {
                break;
            }
            let frames: Vec<u32> = held.iter().map(|(k, _)| todo[*k].0).collect();
            if frames != waiting_for {
                let mut workers: Vec<String> = held.iter().map(|(_, c)| c.who()).collect();
                workers.sort();
                workers.dedup();
                waiting(&frames, &workers);
                waiting_for = frames;
            }
            std::thread::sleep(poll);
        }
        Ok(())
    }

    /// The frames of this render known complete once it has run: its
    /// share, but where a --force claim worker made its one pass (others
    /// may still hold some).
    pub fn known_complete(&self) -> &[u32] {
        if self.request.claim && self.request.force {
            &[]
        } else {
            &self.mine
        }
    }
}

/// Refuses a render (`record`) into a folder whose job record (`old`) is
/// another sequence's (`JobRecord::same_sequence`), if the folder has
/// frames: the render would replace them, or leave two sequences mixed
/// under one record.
fn refuse_other_sequence(
    out_dir: &Path,
    old: &crate::job::record::JobRecord,
    record: &crate::job::record::JobRecord,
    running: usize,
) -> crate::error::Result<()> {
    let frames: usize = old.outputs().iter().map(|o| frame_count(out_dir, o)).sum();
    if frames == 0 && running == 0 {
        return Ok(());
    }
    let what = |r: &crate::job::record::JobRecord| {
        let name = r.timeline_path.file_name().unwrap_or_default();
        format!("{} at {}x{}", name.to_string_lossy(), r.width, r.height)
    };
    Err(Error::usage(
        "--out",
        format!(
            "{} holds {frames} frame file(s) of {} (by its {}){}; rendering {} there would \
             replace them or mix two sequences in one folder: choose another folder with \
             --out, or pass --replace to replace them",
            out_dir.display(),
            what(old),
            crate::job::record::JOB_FILE,
            if running > 0 {
                format!(" and {running} render(s) of it still running")
            } else {
                String::new()
            },
            what(record),
        ),
    ))
}

/// How many frame files of `output` (its format, named its way) `out_dir` holds.
fn frame_count(out_dir: &Path, output: &crate::job::record::OutputRecord) -> usize {
    Format::named(&output.format).map_or(0, |f| {
        output::frames::frame_files(out_dir, f, &output.frame_name).map_or(0, |v| v.len())
    })
}

/// Refuses a render (`record`) of the sequence in `out_dir` that names a
/// format's frames otherwise than the frames there (`old`): it would
/// render them all again under the new names, and the folder's record
/// could count only one naming. `--replace` does that on purpose.
fn refuse_other_names(
    out_dir: &Path,
    old: &crate::job::record::JobRecord,
    record: &crate::job::record::JobRecord,
) -> crate::error::Result<()> {
    for new in record.outputs() {
        let renamed = old.outputs().into_iter().find(|o| {
            o.same_files(&new) && o.frame_name != new.frame_name && frame_count(out_dir, o) > 0
        });
        let Some(o) = renamed else { continue };
        let (was, now, format) = (&o.frame_name, &new.frame_name, &o.format);
        let message = format!(
            "{} holds {} {format} frame(s) named {was} (by its {}), not {now}: pass \
             --frame-name {was} to resume them, or --replace to render them again as {now} \
             (the {was} files stay, no longer counted)",
            out_dir.display(),
            frame_count(out_dir, &o),
            crate::job::record::JOB_FILE,
        );
        return Err(Error::usage("--frame-name", message));
    }
    Ok(())
}

/// How far a render has got, for what an interrupt says (`report_interrupt`).
#[derive(Default)]
pub struct Tally {
    /// Whether every frame of the render has been checked for being complete.
    pub checked: bool,
    /// Frames of this render's share complete: found so, or rendered.
    pub complete: usize,
    /// The files of the frame being rendered, and the key each will hold:
    /// they may be in place a moment before `complete` counts the frame.
    pub writing: Vec<(PathBuf, Format, String)>,
}

/// `tally`, locked (a panic elsewhere does not make its numbers wrong).
pub fn lock(tally: &Mutex<Tally>) -> std::sync::MutexGuard<'_, Tally> {
    tally.lock().unwrap_or_else(|e| e.into_inner())
}

impl Tally {
    /// Frames complete, counting the one being written if its files are
    /// all in place already.
    pub fn complete_now(&self) -> usize {
        let written = !self.writing.is_empty()
            && self.writing.iter().all(|(path, format, key)| {
                output::frames::file_state(path, *format, key, false) == output::FileState::Current
            });
        self.complete + usize::from(written)
    }
}
