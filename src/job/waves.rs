//! One frame rendered and written: in waves of samples, saving a checkpoint
//! between them so that a killed render resumes mid-frame.

use crate::error::Error;
use crate::job::plan::Plan;
use crate::output;
use crate::render::FrameStats;
use std::time::Instant;

impl Plan {
    /// Renders one frame and writes every format. A frame of one sample per
    /// pixel is rendered band by band (`render_frame_into`), without the
    /// whole frame's running sums. Others run in waves of samples, saving
    /// their accumulation every `checkpoint_every` and continuing from a
    /// saved one for the same inputs; the result is bit-identical either way.
    /// A one-sample frame renders into `film`, whose buffers the frames of a
    /// run share. `say` gets a line when the frame resumes from a checkpoint
    /// and a warning when one cannot be saved: the frame goes on without
    /// (a full disk should not end a night's render whose frames still fit),
    /// keeping any checkpoint saved before. Returns the stats.
    #[allow(clippy::too_many_arguments)]
    pub fn render_frame(
        &self,
        film: &mut crate::render::Film,
        frame: u32,
        scenes: &[crate::scene::Scene],
        hash: &str,
        checkpoint_every: std::time::Duration,
        on_row: &(dyn Fn() + Sync),
        say: &dyn Fn(Said),
    ) -> anyhow::Result<FrameStats> {
        let n = scenes[0].samples_per_pixel.max(1);
        let layers = self.layers();
        if n == 1 {
            // One sample is one wave: there is never a checkpoint to resume.
            crate::render::render_frame_into(
                film,
                scenes,
                frame,
                self.width,
                self.height,
                layers,
                on_row,
            );
            return self.write_film(frame, film, hash, &scenes[0].look);
        }
        let checkpoint = self.checkpoint_path(frame);
        // A checkpoint holds linear light: how a PNG shows it is not its key.
        let light = output::frames::light_hash(hash);
        let saved_acc = crate::job::checkpoint::read_checkpoint(
            &checkpoint,
            light,
            self.width,
            self.height,
            layers,
        )
        // Spreads are there exactly when the frame samples adaptively.
        .filter(|a| a.samples_done < n && a.spread.is_empty() == scenes[0].adaptive.is_none());
        let mut acc = saved_acc
            .unwrap_or_else(|| crate::render::Accumulation::new(self.width, self.height, layers));
        if acc.samples_done > 0 {
            say(Said::Resumed {
                frame,
                samples: acc.samples_done,
                of: n,
            });
        }
        let mut saved = Instant::now();
        let mut saving = true;
        while acc.samples_done < n {
            let until = crate::render::next_wave(&scenes[0], acc.samples_done);
            crate::render::render_samples(scenes, frame, &mut acc, until, on_row);
            if saving && until < n && saved.elapsed() >= checkpoint_every {
                if let Err(e) = crate::job::checkpoint::write_checkpoint(&checkpoint, &acc, light) {
                    say(Said::CheckpointFailed { frame, error: e });
                    saving = false;
                }
                saved = Instant::now();
            }
        }
        let film = acc.finish(n);
        self.write_film(frame, &film, hash, &scenes[0].look)
    }

    /// Writes every format of a finished frame and drops its checkpoint.
    pub fn write_film(
        &self,
        frame: u32,
        film: &crate::render::Film,
        hash: &str,
        look: &crate::shade::Look,
    ) -> anyhow::Result<FrameStats> {
        for &f in &self.formats {
            output::frames::write_frame(
                &self.path(frame, f),
                f,
                film,
                hash,
                &self.aovs,
                &output::Encoding {
                    display: look.display_transform(),
                    transparent: look.transparent_background,
                    exr_compression: self.exr_compression,
                },
            )?;
        }
        let _ = std::fs::remove_file(self.checkpoint_path(frame));
        Ok(film.stats)
    }
}

/// What `Plan::render_frame` has to say while a frame renders.
pub enum Said {
    /// It goes on from a checkpoint holding `samples` of its `of` samples a pixel.
    Resumed { frame: u32, samples: u32, of: u32 },
    /// A checkpoint could not be saved; the frame goes on without.
    CheckpointFailed { frame: u32, error: Error },
}

/// Passes over a frame's rows that rendering its `scenes` takes: one per
/// wave of samples.
pub fn waves(scenes: &[crate::scene::Scene]) -> u32 {
    crate::render::wave_count(&scenes[0])
}
