//! Runs one fuzz case under a deadline and a memory budget, catching its
//! panic: the case runs on a thread of its own whose allocations a counting
//! global allocator charges to the case. A case past its deadline or its
//! budget is given up and its thread frozen at its next allocation, so a
//! hang or an endless read fails the test instead of holding CI or filling
//! the machine's memory.
//!
//! The allocator serves the whole test binary; threads that run no fuzz
//! case (the other tests, which mostly spawn the binary) are only passed
//! through to the system allocator.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicBool, AtomicIsize, Ordering};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// The most memory one case may hold at once: the budget for a
/// whole `mandelreel info`, so a parse alone has no reason to come near it.
pub const MAX_LIVE_BYTES: isize = 300_000_000;

/// How an input was answered.
pub enum Outcome<T> {
    /// It returned (an `Ok` or an error: both are answers).
    Returned(T),
    Panicked(String),
    /// Still running at the deadline.
    Hung(Duration),
    /// Asked for more than `MAX_LIVE_BYTES` at once.
    OverBudget(isize),
}

/// What one case's thread holds and whether it has been given up.
#[derive(Default)]
struct Budget {
    live: AtomicIsize,
    over: AtomicBool,
    abandoned: AtomicBool,
}

thread_local! {
    // Const-initialised and without a destructor: readable from inside the
    // allocator without allocating.
    static BUDGET: Cell<Option<&'static Budget>> = const { Cell::new(None) };
}

struct Counting;

#[global_allocator]
static ALLOCATOR: Counting = Counting;

// SAFETY: every call is forwarded unchanged to the system allocator; the
// bookkeeping around it only reads and writes atomics and a thread-local
// cell, and never allocates, unwinds or touches the memory handed out.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        charge(layout.size() as isize);
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        charge(layout.size() as isize);
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) };
        charge(-(layout.size() as isize));
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        charge(new_size as isize - layout.size() as isize);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

/// Counts `bytes` (negative when freed) against the calling thread's case,
/// if it runs one. A case over its budget, or given up, stops here for
/// good: before the allocation, so its memory stays below the budget, and
/// without unwinding, which an allocator must not do.
fn charge(bytes: isize) {
    // `try_with`: a thread being torn down has no budget.
    let Ok(Some(budget)) = BUDGET.try_with(Cell::get) else {
        return;
    };
    let live = budget.live.fetch_add(bytes, Ordering::Relaxed) + bytes;
    if bytes > 0 && live > MAX_LIVE_BYTES {
        budget.over.store(true, Ordering::Release);
        freeze();
    }
    // Never while unwinding: the panic hook holds the process's panic lock
    // while it allocates, and a thread frozen there would hang every later
    // panic in the test binary, the harness's own included.
    if budget.abandoned.load(Ordering::Acquire) && !std::thread::panicking() {
        freeze();
    }
}

/// Holds the calling thread until the process ends (sleeping allocates nothing).
fn freeze() -> ! {
    loop {
        std::thread::sleep(Duration::from_secs(3600));
    }
}

/// Stack of a case's thread: the binary parses on its main thread, which
/// has 8 MiB, so a stack overflow here is one the binary has too.
const STACK_BYTES: usize = 8 << 20;

/// Runs `case` on its own thread, answering what became of it by `deadline`.
pub fn run<T: Send + 'static>(
    deadline: Duration,
    case: impl FnOnce() -> T + Send + 'static,
) -> Outcome<T> {
    // Leaked, a few bytes a case: a thread given up may still use it.
    let budget: &'static Budget = Box::leak(Box::default());
    let (send, receive) = mpsc::channel();
    let spawned = std::thread::Builder::new()
        .name("fuzz case".into())
        .stack_size(STACK_BYTES)
        .spawn(move || {
            BUDGET.with(|b| b.set(Some(budget)));
            let answer = std::panic::catch_unwind(std::panic::AssertUnwindSafe(case));
            // Frees its result on the receiving side, outside the budget.
            BUDGET.with(|b| b.set(None));
            let _ = send.send(answer);
        });
    if let Err(e) = spawned {
        return Outcome::Panicked(format!("could not start the case's thread: {e}"));
    }
    wait(deadline, budget, &receive)
}

/// Waits for the case's answer, watching its budget meanwhile.
fn wait<T>(
    deadline: Duration,
    budget: &Budget,
    receive: &mpsc::Receiver<std::thread::Result<T>>,
) -> Outcome<T> {
    let start = Instant::now();
    loop {
        match receive.recv_timeout(Duration::from_millis(20)) {
            Ok(Ok(value)) => return Outcome::Returned(value),
            Ok(Err(payload)) => return Outcome::Panicked(panic_message(&*payload)),
            Err(mpsc::RecvTimeoutError::Disconnected) => {
                return Outcome::Panicked("the case's thread ended without an answer".into())
            }
            Err(mpsc::RecvTimeoutError::Timeout) => {}
        }
        let elapsed = start.elapsed();
        if budget.over.load(Ordering::Acquire) {
            budget.abandoned.store(true, Ordering::Release);
            return Outcome::OverBudget(budget.live.load(Ordering::Relaxed));
        }
        if elapsed > deadline {
            budget.abandoned.store(true, Ordering::Release);
            return Outcome::Hung(elapsed);
        }
    }
}

fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        s.to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "a panic without a message".into()
    }
}

#[test]
fn guard_reports_a_panic_a_hang_and_a_huge_allocation() {
    // Deadlines generous enough for a machine under load: an answer ends
    // the wait at once.
    let ample = Duration::from_secs(30);
    assert!(matches!(run(ample, || 7), Outcome::Returned(7)));
    let panicked = run(ample, || -> u8 { panic!("boom {}", 1) });
    assert!(matches!(panicked, Outcome::Panicked(m) if m == "boom 1"));
    let hung = run(Duration::from_millis(100), || loop {
        std::hint::black_box(vec![0u8; 16]);
    });
    assert!(matches!(hung, Outcome::Hung(_)));
    let huge = run(ample, || vec![1u8; 2 * MAX_LIVE_BYTES as usize].len());
    assert!(matches!(huge, Outcome::OverBudget(_)));
    // Freed memory is given back to the case's budget.
    let churn = run(Duration::from_secs(30), || {
        (0..5).map(|_| vec![1u8; 100_000_000].len()).sum::<usize>()
    });
    assert!(matches!(churn, Outcome::Returned(500_000_000)));
}
