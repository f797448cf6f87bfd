//! Stopping cleanly on Ctrl-C (SIGINT) and SIGTERM. A render registers what
//! it would otherwise leave behind (temporary files, its claims and run
//! record, a folder it made and wrote nothing into) and what to say; the
//! first signal runs all of that, then ends the process by the same signal,
//! so a shell reports 130 or 143 and a script's loop stops as it would for
//! any program killed by it. A second signal ends the process at once.
//!
//! Files an interrupt must clean up are created, and renamed into place,
//! under `hold()`. The signal's thread takes that lock and keeps it: no
//! writer can then start a file the cleanup would miss, or put one in place
//! after the cleanup looked (a writer that tries waits for the end).

use std::sync::{Mutex, MutexGuard};

type Action = Box<dyn FnOnce() + Send>;
type Report = Box<dyn FnOnce(&Stop) + Send>;

/// What runs on an interrupt: cleanups, newest first, then reports.
pub struct Actions {
    next_id: u64,
    cleanups: Vec<(u64, Action)>,
    reports: Vec<(u64, Report)>,
}

/// What a report is told of the interrupt.
pub struct Stop {
    /// A SIGINT, with standard error a terminal that echoes control
    /// characters: most likely Ctrl-C, whose `^C` the terminal has printed
    /// where the cursor was (after a full-width progress bar, on the next
    /// line).
    pub echoed: bool,
}

static ACTIONS: Mutex<Actions> = Mutex::new(Actions {
    next_id: 0,
    cleanups: Vec::new(),
    reports: Vec::new(),
});

/// The lock under which files an interrupt must find are created and
/// renamed, and actions registered (module doc). Held only for the
/// system call: never across a wait, nor while dropping a `Registered`.
pub fn hold() -> MutexGuard<'static, Actions> {
    // A thread that panicked holding it left the actions whole.
    ACTIONS.lock().unwrap_or_else(|e| e.into_inner())
}

/// An action registered to run on an interrupt; dropping this removes it
/// (without running it).
#[must_use = "the action is removed when this is dropped"]
pub struct Registered(u64);

impl Actions {
    /// Runs `cleanup` if the process is interrupted before the returned
    /// guard is dropped (under this lock, so nothing slips in between).
    pub fn on_interrupt(&mut self, cleanup: impl FnOnce() + Send + 'static) -> Registered {
        self.next_id += 1;
        self.cleanups.push((self.next_id, Box::new(cleanup)));
        Registered(self.next_id)
    }
}

/// `Actions::on_interrupt`, taking the lock for it.
#[cfg(test)]
pub fn on_interrupt(cleanup: impl FnOnce() + Send + 'static) -> Registered {
    hold().on_interrupt(cleanup)
}

/// Runs `report` on an interrupt after every cleanup, until the guard is
/// dropped: what the user is told.
pub fn report_on_interrupt(report: impl FnOnce(&Stop) + Send + 'static) -> Registered {
    let mut actions = hold();
    actions.next_id += 1;
    let id = actions.next_id;
    actions.reports.push((id, Box::new(report)));
    Registered(id)
}

impl Drop for Registered {
    fn drop(&mut self) {
        let mut actions = hold();
        actions.cleanups.retain(|(id, _)| *id != self.0);
        actions.reports.retain(|(id, _)| *id != self.0);
    }
}

/// A write past the file-size limit (`ulimit -f`) fails with EFBIG, which
/// the writer reports and cleans up after, instead of SIGXFSZ killing the
/// process with its temporary files, lock and run record left behind.
pub fn survive_file_size_limit() {
    #[cfg(unix)]
    {
        let seen = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
        let _ = signal_hook::flag::register(signal_hook::consts::SIGXFSZ, seen);
    }
}

/// From now on, SIGINT and SIGTERM run the registered actions and end the
/// process by that signal (module doc). Elsewhere than Unix, a no-op.
pub fn install() -> std::io::Result<()> {
    #[cfg(unix)]
    {
        use signal_hook::consts::{SIGINT, SIGTERM};
        use std::sync::atomic::{AtomicBool, Ordering};
        use std::sync::Arc;
        let stopping = Arc::new(AtomicBool::new(false));
        for signal in [SIGINT, SIGTERM] {
            // Checked before the flag is set: only a second signal ends it
            // at once (a cleanup stuck on a hung file system, say).
            signal_hook::flag::register_conditional_shutdown(
                signal,
                128 + signal,
                stopping.clone(),
            )?;
        }
        let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM])?;
        std::thread::spawn(move || {
            if let Some(signal) = signals.forever().next() {
                stopping.store(true, Ordering::SeqCst);
                stop(signal);
            }
        });
    }
    Ok(())
}

/// Runs every action, holding the lock to the end, and ends the process
/// as the default action of `signal` would.
#[cfg(unix)]
fn stop(signal: i32) -> ! {
    let mut actions = hold();
    let cleanups = std::mem::take(&mut actions.cleanups);
    let reports = std::mem::take(&mut actions.reports);
    for (_, cleanup) in cleanups.into_iter().rev() {
        cleanup();
    }
    let stop = Stop {
        echoed: signal == signal_hook::consts::SIGINT && echoes_control_characters(),
    };
    for (_, report) in reports.into_iter().rev() {
        report(&stop);
    }
    // Dying of the signal, not exiting 130: a shell running a loop stops
    // only then (it takes an exit status for a program that handled it).
    let _ = signal_hook::low_level::emulate_default_handler(signal);
    std::process::exit(128 + signal)
}

/// Whether standard error is a terminal that echoes `^C` (ECHO and ECHOCTL).
#[cfg(unix)]
fn echoes_control_characters() -> bool {
    use nix::sys::termios::{tcgetattr, LocalFlags};
    tcgetattr(std::io::stderr()).is_ok_and(|t| {
        t.local_flags
            .contains(LocalFlags::ECHO | LocalFlags::ECHOCTL)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_dropped_registration_is_forgotten_and_a_held_one_kept() {
        let kept = on_interrupt(|| {});
        let id = kept.0;
        let gone = report_on_interrupt(|_| {});
        let gone_id = gone.0;
        drop(gone);
        let actions = hold();
        assert!(actions.cleanups.iter().any(|(i, _)| *i == id));
        assert!(!actions.reports.iter().any(|(i, _)| *i == gone_id));
        drop(actions);
        drop(kept);
        assert!(!hold().cleanups.iter().any(|(i, _)| *i == id));
    }
}
