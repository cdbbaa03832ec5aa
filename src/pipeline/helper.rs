//! The frame's helper: a second thread that answers a contact-rich frame's convex pairs
//! from the back of the candidate list while the pair loop answers them from the front.
//!
//! # Design note
//! A frame whose bodies all move (a pile while it settles: no answer can be kept) costs
//! 3–3.5× a resting one, and while the daemon works its client waits for the answer: the
//! second core is idle. The helper takes it for the frame's direct convex pairs (closed
//! forms and GJK/EPA, [`answer::direct`] without a tree walk):
//! - **Never waited for.** Each pair the helper may answer has a claim, taken by a
//!   compare-and-swap: the pair loop from the front, the helper from the back. A pair the
//!   loop reaches while the helper holds it unfinished, the loop answers itself (the
//!   helper's answer is then dropped); one the helper finished, the loop takes. The helper
//!   stops at the first pair the loop claimed, or when the loop ends the frame. A helper
//!   that wakes late, or is preempted mid-pair for milliseconds (waking a parked thread
//!   takes 11–12 µs at the median on the 2-core VM, but 0.1–1 ms at p99), costs the frame
//!   nothing but the share it did not take.
//! - **Owns what it reads.** A frame's [`HelperFrame`] holds the scene's shape table (an
//!   `Arc`, copied on write when a shape is registered), a copy of its body slots and the
//!   pairs: the helper borrows nothing of the scene, and needs no `unsafe`. The copy of the
//!   bodies is why a frame with few pairs for many bodies is not helped
//!   ([`BODIES_PER_HELPED_PAIR`]).
//! - **No allocation once grown.** A frame reuses the last frame's buffers once the helper
//!   has let go of them; only a helper still busy on an old frame makes the loop take a
//!   new set.
//! - **The same answers.** The helper answers a pair as the loop does, with no clock: the
//!   exact answer, which the loop gives too unless its clock stopped it first (then the
//!   helper's answer is the better one, and still a true one). Unbudgeted frames get
//!   the same records, bit for bit, with or without a helper.
//! - **A panic** (a bug; client input is validated at ingest) leaves the pair unfinished,
//!   so the loop answers it; the helper starts its scratch afresh.

use super::Query;
use super::workers::{JobScratch, PairOutcome};
use crate::broad::CandidatePair;
use crate::budget::WorkClock;
use crate::narrow::Shape;
use crate::narrow::dispatch::PathCounts;
use crate::scene::{Body, Scene};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::atomic::{AtomicBool, AtomicU8, Ordering};
use std::sync::{Arc, Condvar, Mutex, OnceLock, PoisonError, TryLockError};
use std::thread::JoinHandle;

/// Fewest pairs the helper is woken for, answered afresh in the last frame and open to it
/// in this one: below, its wake, the frame's copy and the answers crossing between the
/// cores cost more than the share it takes (a direct pair costs 0.1–2 µs). The settling
/// pile answers about 500 a frame afresh, the resting pile 90–140 (which a threshold of
/// 64 made 4–6 % slower at the median).
pub const MIN_HELPED_PAIRS: usize = 192;

/// Most body slots copied for the helper per pair it may answer: a frame with fewer pairs
/// for its bodies is not helped (the copy, about 230 bytes a body, would outweigh them).
pub const BODIES_PER_HELPED_PAIR: usize = 4;

/// A pair's claim: nobody's yet.
const FREE: u8 = 0;
/// The pair loop's: it answers the pair itself.
const LOOP: u8 = 1;
/// The helper's, being answered.
const HELPER: u8 = 2;
/// The helper's, answered: its outcome is set.
const DONE: u8 = 3;

/// What the helper reads of one frame, and its answers.
#[derive(Debug, Default)]
struct HelperFrame {
    shapes: Arc<Vec<Shape>>,
    bodies: Vec<Option<Body>>,
    query: Query,
    /// The pairs it may answer, in candidate order, with their candidate slots.
    pairs: Vec<(u32, CandidatePair)>,
    /// One claim a pair (`FREE`, `LOOP`, `HELPER`, `DONE`).
    claims: Vec<AtomicU8>,
    /// One outcome a pair, set by the helper before its claim becomes `DONE`.
    outcomes: Vec<OnceLock<PairOutcome>>,
    /// Raised when the pair loop has ended the frame.
    closed: AtomicBool,
}

impl HelperFrame {
    /// The helper's part: the pairs from the back, until one is the loop's or the frame
    /// ends.
    fn help(&self, scratch: &mut JobScratch, shared: &Shared) {
        for (i, (slot, pair)) in self.pairs.iter().enumerate().rev() {
            if self.closed.load(Ordering::Relaxed)
                || self.claims[i]
                    .compare_exchange(FREE, HELPER, Ordering::Acquire, Ordering::Relaxed)
                    .is_err()
            {
                return;
            }
            shared.pause();
            let answered = catch_unwind(AssertUnwindSafe(|| self.answer(*slot, pair, scratch)));
            match answered {
                Ok(Some(outcome)) => {
                    // Only the helper sets it, once per frame (the claim was FREE).
                    let _ = self.outcomes[i].set(outcome);
                    self.claims[i].store(DONE, Ordering::Release);
                }
                // Left as the helper's, unfinished: the loop answers it.
                Ok(None) => {}
                Err(_) => *scratch = JobScratch::default(),
            }
        }
    }

    /// Pair `slot`'s outcome, as the pair loop's `answer::direct` gives it, with a clock
    /// that never stops; `None` when a body or shape is missing (never, for a frame's
    /// candidates).
    fn answer(
        &self,
        slot: u32,
        pair: &CandidatePair,
        scratch: &mut JobScratch,
    ) -> Option<PairOutcome> {
        let body = |id: u32| self.bodies.get(id as usize)?.as_ref();
        let (a, b) = (body(pair.a)?, body(pair.b)?);
        let shape = |body: &Body| self.shapes.get(body.shape.0 as usize);
        let (sa, sb) = (shape(a)?, shape(b)?);
        let clock = WorkClock::default();
        Some(scratch.direct((slot, pair), ((a, sa), (b, sb)), self.query, clock))
    }
}

/// The frame handed to the helper thread, or its stop.
#[derive(Debug, Default)]
struct Posted {
    frame: Option<Arc<HelperFrame>>,
    stop: bool,
}

#[derive(Debug, Default)]
struct Shared {
    posted: Mutex<Posted>,
    wake: Condvar,
    /// A test's gate, at which the helper waits after each claim until it opens.
    #[cfg(test)]
    gate: Option<Gate>,
}

/// A gate for tests: closed while `false`.
#[cfg(test)]
pub(super) type Gate = Arc<(Mutex<bool>, Condvar)>;

impl Shared {
    /// Holds the helper at a test's gate, if any (nothing otherwise).
    fn pause(&self) {
        #[cfg(test)]
        if let Some(gate) = &self.gate {
            let (open, opened) = &**gate;
            let mut is_open = open.lock().unwrap_or_else(PoisonError::into_inner);
            while !*is_open {
                is_open = opened.wait(is_open).unwrap_or_else(PoisonError::into_inner);
            }
        }
    }
}

/// A helper thread and its frame buffers (module docs); dropping it stops and joins the
/// thread.
#[derive(Debug)]
pub struct PairHelper {
    /// Tests: each frame waits (at most a second) for the helper's first answer (a held
    /// helper's first claim), so the helper takes part however busy the machine (it runs
    /// only on an idle core).
    #[cfg(test)]
    eager: bool,
    shared: Arc<Shared>,
    /// The last frame's buffers, reused when the helper has let go of them.
    last: Option<Arc<HelperFrame>>,
    thread: Option<JoinHandle<()>>,
}

impl PairHelper {
    /// A helper with its thread started.
    ///
    /// # Panics
    /// When the operating system cannot start a thread.
    #[must_use]
    pub fn new() -> Self {
        Self::with_shared(Shared::default())
    }

    /// A helper that holds every pair it claims at `gate` until the gate opens (a helper
    /// preempted mid-pair, for tests); each frame waits for its first claim.
    #[cfg(test)]
    pub(super) fn held(gate: Gate) -> Self {
        let mut helper = Self::with_shared(Shared {
            gate: Some(gate),
            ..Shared::default()
        });
        helper.eager = true;
        helper
    }

    /// A helper whose every frame waits for its first answer (module tests).
    #[cfg(test)]
    pub(super) fn eager() -> Self {
        let mut helper = Self::new();
        helper.eager = true;
        helper
    }

    fn with_shared(shared: Shared) -> Self {
        let shared = Arc::new(shared);
        let theirs = Arc::clone(&shared);
        let thread = std::thread::Builder::new()
            .name("proxima-helper".into())
            .spawn(move || run(&theirs))
            .expect("the operating system starts a helper thread");
        Self {
            #[cfg(test)]
            eager: false,
            shared,
            last: None,
            thread: Some(thread),
        }
    }

    /// Hands the helper `pairs` (candidate slot and pair, in candidate order) of `scene`
    /// under `query`, and returns the pair loop's side of the frame. `None`, the frame going
    /// unhelped: fewer than [`MIN_HELPED_PAIRS`] pairs, more than
    /// [`BODIES_PER_HELPED_PAIR`] body slots to copy for each, or the helper taking the
    /// last frame just then.
    pub(super) fn begin(
        &mut self,
        scene: &Scene,
        query: Query,
        pairs: impl Iterator<Item = (u32, CandidatePair)>,
    ) -> Option<Helping> {
        let mut frame = match self.last.take() {
            Some(frame) if Arc::strong_count(&frame) == 1 => frame,
            _ => Arc::new(HelperFrame::default()),
        };
        let f = Arc::get_mut(&mut frame).expect("a frame no other thread holds");
        f.pairs.clear();
        f.pairs.extend(pairs);
        let n = f.pairs.len();
        if n < MIN_HELPED_PAIRS || scene.body_slots().len() > BODIES_PER_HELPED_PAIR * n {
            self.last = Some(frame);
            return None;
        }
        f.shapes = scene.shape_table();
        f.bodies.clear();
        f.bodies.extend_from_slice(scene.body_slots());
        f.query = query;
        f.claims.clear();
        f.claims.resize_with(n, || AtomicU8::new(FREE));
        f.outcomes.truncate(n);
        for outcome in &mut f.outcomes {
            outcome.take();
        }
        f.outcomes.resize_with(n, OnceLock::new);
        *f.closed.get_mut() = false;
        // Never waited for, not even for the hand-over: a helper preempted (it runs only
        // on an idle core) while it takes a frame holds this lock, and then the frame goes
        // without it.
        let mut posted = match self.shared.posted.try_lock() {
            Ok(posted) => posted,
            Err(TryLockError::Poisoned(poisoned)) => poisoned.into_inner(),
            Err(TryLockError::WouldBlock) => {
                self.last = Some(frame);
                return None;
            }
        };
        posted.frame = Some(Arc::clone(&frame));
        drop(posted);
        self.shared.wake.notify_one();
        #[cfg(test)]
        if self.eager && n > 0 {
            let waited = std::time::Instant::now();
            // Answered, or claimed and held at a test's gate.
            let reached =
                |claim: u8| claim == DONE || (claim == HELPER && self.shared.gate.is_some());
            while !reached(frame.claims[n - 1].load(Ordering::Acquire))
                && waited.elapsed() < std::time::Duration::from_secs(1)
            {
                std::thread::yield_now();
            }
        }
        self.last = Some(Arc::clone(&frame));
        Some(Helping {
            frame,
            next: 0,
            taken: PathCounts::default(),
        })
    }

    fn posted(&self) -> std::sync::MutexGuard<'_, Posted> {
        self.shared
            .posted
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
    }
}

impl Default for PairHelper {
    fn default() -> Self {
        Self::new()
    }
}

impl Drop for PairHelper {
    fn drop(&mut self) {
        self.posted().stop = true;
        self.shared.wake.notify_one();
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

/// The helper thread: each frame posted, helped until its end or the loop's claims.
fn run(shared: &Shared) {
    run_when_idle();
    let mut scratch = JobScratch::default();
    loop {
        let frame = {
            let mut posted = shared.posted.lock().unwrap_or_else(PoisonError::into_inner);
            loop {
                if posted.stop {
                    return;
                }
                if let Some(frame) = posted.frame.take() {
                    break frame;
                }
                posted = shared
                    .wake
                    .wait(posted)
                    .unwrap_or_else(PoisonError::into_inner);
            }
        };
        frame.help(&mut scratch, shared);
    }
}

/// The pair loop's side of a helped frame.
#[derive(Debug)]
pub(super) struct Helping {
    frame: Arc<HelperFrame>,
    /// The first of the frame's pairs the loop has not passed.
    next: usize,
    /// The dispatcher's paths of the helper's answers the loop took.
    taken: PathCounts,
}

impl Helping {
    /// The helper's outcome for candidate `slot` when it answered that pair; otherwise the
    /// pair is the loop's (claimed now, so the helper stops there). Slots come in
    /// increasing order; the pairs before `slot` the loop answered otherwise (a kept
    /// answer, ...) are claimed too.
    pub(super) fn take(&mut self, slot: u32) -> Option<&PairOutcome> {
        while let Some(&(at, _)) = self.frame.pairs.get(self.next) {
            if at > slot {
                return None;
            }
            let i = self.next;
            self.next += 1;
            let claim = self.frame.claims[i].compare_exchange(
                FREE,
                LOOP,
                Ordering::Acquire,
                Ordering::Acquire,
            );
            if at == slot && claim == Err(DONE) {
                let outcome = self.frame.outcomes[i].get()?;
                self.taken.add(&outcome.paths);
                return Some(outcome);
            }
        }
        None
    }

    /// Ends the frame for the helper (it stops before its next pair) and gives the
    /// dispatcher's paths of the answers the loop took from it.
    pub(super) fn end(self) -> PathCounts {
        self.frame.closed.store(true, Ordering::Relaxed);
        self.taken
    }
}

/// Moves the calling thread (the helper) to `SCHED_IDLE`: it runs only on a core nothing
/// else wants, and never takes the frame thread's core from it. Waking it from the frame
/// thread would otherwise put it on that core ahead of the frame thread (the fair
/// scheduler's wake-up preemption) whenever the other core is busy, and the pair loop
/// would then run after the helper rather than beside it. Ignored where unavailable.
fn run_when_idle() {
    #[cfg(target_os = "linux")]
    {
        let param = libc::sched_param { sched_priority: 0 };
        // SAFETY: `sched_setscheduler` with pid 0 changes only the calling thread's policy
        // (Linux schedules threads); it reads `param`, a live local, and writes nothing.
        let _ = unsafe { libc::sched_setscheduler(0, libc::SCHED_IDLE, &raw const param) };
    }
}
