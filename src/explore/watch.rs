//! Watching the timeline's file and the render's progress, for the page.
//! The file is read again every half second and compared: editors save by
//! writing a new file and renaming it, which a watch on the old file's
//! inode would miss, and a 1 MiB read at most costs nothing at this rate.

use super::{Event, State};
use std::sync::atomic::Ordering;
use std::sync::Arc;
use std::time::Duration;

const EVERY: Duration = Duration::from_millis(500);
const PROGRESS_EVERY: Duration = Duration::from_millis(200);

pub async fn watch(state: Arc<State>) {
    let mut file = tokio::time::interval(EVERY);
    let mut progress = tokio::time::interval(PROGRESS_EVERY);
    let mut shown = (0, 0, 0, 0);
    loop {
        tokio::select! {
            _ = file.tick() => {
                let looked = state.clone();
                let changed = tokio::task::spawn_blocking(move || {
                    looked.document.lock().expect("document").check_disk()
                });
                if let Ok(Some(event)) = changed.await {
                    super::routes::announce(&state, event);
                }
            }
            _ = progress.tick() => {
                let now = (
                    state.renders.rows_done.load(Ordering::Relaxed),
                    state.renders.rows_total.load(Ordering::Relaxed),
                    state.renders.rows_stage.load(Ordering::Relaxed),
                    state.renders.rows_renders.load(Ordering::Relaxed),
                );
                if now != shown {
                    shown = now;
                    let stage = if now.2 == 1 { "full" } else { "final" };
                    super::routes::announce(&state, Event::Progress { done: now.0, of: now.1, stage });
                }
            }
        }
    }
}
