//! The pipeline's worker pool: persistent threads that answer a frame's expensive pairs
//! (mesh–mesh, and a convex shape or compound against a mesh or compound: the pairs that
//! walk a tree) alongside the calling thread.
//!
//! # Design note
//! A job owns everything it needs (the two bodies, their shapes, whose meshes, hulls and
//! compounds are `Arc`s, the query and a mesh pair's warm-start cache), so workers hold no
//! borrow of the scene and need no `unsafe`. Jobs travel over a bounded crossbeam channel
//! (a fixed ring: no allocation per message); the calling thread takes queued jobs itself
//! once it has handed them out, then collects the workers' outcomes and sorts them by
//! candidate slot, so the frame's results are the same, in the same order, whichever
//! thread answered which pair.
//!
//! Waking a parked worker costs 60–120 µs on a VM, so [`step`](super::step) hands out work
//! only when a frame has at least [`MIN_PARALLEL_MESH_PAIRS`] mesh pairs or
//! [`MIN_PARALLEL_WALKS`] tree walks (a mesh pair counting as
//! `MIN_PARALLEL_WALKS / MIN_PARALLEL_MESH_PAIRS` walks); the calling thread does not wait
//! for the wake, it starts on the queue at once. A pool serves one frame at a time (a lock
//! held for the frame), so scenes may share one.
//!
//! Budgeted frames refine their frontier on the calling thread only. Measured and not
//! kept (`examples/time_vs_error --workers 1`, mesh pile, 300 frames, two alternating runs
//! against no pool): the frontier split in four groups that the calling thread and a worker
//! took in turns of 20 µs, the worker joining when it woke. Waking a parked worker takes
//! 46–82 µs at the median and up to 1 ms at p99 on this 2-core VM, and at the deadline the
//! calling thread must wait for a group the worker holds, which a preempted worker makes
//! milliseconds: precision 0.993–0.996 against 0.991–0.993 at 1,000 µs (50 % more visits),
//! 0.974–0.980 against 0.970–0.978 at 500 µs, 0.952–0.957 against 0.963–0.964 at 350 µs,
//! 0.836–0.921 against 0.922–0.927 at 250 µs, with 26–90 of 300 frames past their deadline
//! against 0–13.
//!
//! A worker that panics on a job (a bug, never client input, which is validated at ingest)
//! answers that pair with the conservative box answer instead of leaving the frame waiting.
//!
//! The pool also holds the pair loop's helper thread (`helper.rs`), which answers convex
//! pairs beside the calling thread on frames the pool does not take, budgeted ones
//! included, and is never waited for.

use super::answer::{self, Answer, MeshScratch};
use super::helper::PairHelper;
use super::{ContactPoint, Query};
use crate::broad::CandidatePair;
use crate::budget::{Abandon, WorkClock};
use crate::math::DVec3;
use crate::narrow::contact::Manifold;
use crate::narrow::dispatch::{self, NarrowScratch, PathCounts, Route};
use crate::narrow::mesh_mesh::DistanceCache;
use crate::narrow::{MANIFOLD_POINTS, Shape};
use crate::scene::Body;
use crossbeam::channel::{self, Receiver, Sender, TrySendError};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::{Mutex, PoisonError};
use std::thread::JoinHandle;

/// Fewest mesh–mesh pairs in a frame for the pool to be used (below it, waking a worker
/// costs more than it saves).
pub const MIN_PARALLEL_MESH_PAIRS: usize = 2;
/// Fewest walks of a convex shape or compound over a tree (1–10 µs each in
/// `examples/falling_bodies.rs`) for the pool to be used, a mesh pair counting as
/// `MIN_PARALLEL_WALKS / MIN_PARALLEL_MESH_PAIRS` of them.
pub const MIN_PARALLEL_WALKS: usize = 32;
/// Jobs the channel holds; a frame with more answers the overflow on the calling thread.
const QUEUE_CAPACITY: usize = 4096;

/// One pair to answer: mesh–mesh, or a direct pair that walks a tree.
#[derive(Debug, Clone)]
pub(super) struct PairJob {
    /// Index of the pair among the frame's candidates.
    pub slot: u32,
    pub pair: CandidatePair,
    pub a: Body,
    pub b: Body,
    /// The bodies' shapes (clones share their meshes, hulls and compounds).
    pub shapes: (Shape, Shape),
    pub query: Query,
    /// A mesh pair's warm-start cache (unused by direct pairs).
    pub cache: DistanceCache,
    /// The frame's abandon flag.
    pub abandon: Abandon,
}

/// A pair's answer, its contacts, its updated warm-start cache and the dispatcher's paths
/// it took (a direct pair's; a mesh pair's path is counted by the caller).
#[derive(Debug, Clone, Copy)]
pub(super) struct PairOutcome {
    pub slot: u32,
    pub answer: Answer,
    contacts: [ContactPoint; MANIFOLD_POINTS],
    contact_count: usize,
    pub cache: DistanceCache,
    pub paths: PathCounts,
}

impl PairOutcome {
    /// The outcome of pair `slot`: its answer, the first [`MANIFOLD_POINTS`] of
    /// `contacts`, its cache and its paths.
    pub(super) fn new(
        slot: u32,
        answer: Answer,
        contacts: &[ContactPoint],
        cache: DistanceCache,
        paths: PathCounts,
    ) -> Self {
        let mut outcome = Self {
            slot,
            answer,
            contacts: [NO_CONTACT; MANIFOLD_POINTS],
            contact_count: contacts.len().min(MANIFOLD_POINTS),
            cache,
            paths,
        };
        outcome.contacts[..outcome.contact_count]
            .copy_from_slice(&contacts[..outcome.contact_count]);
        outcome
    }

    /// The pair's contacts (their `pair` index not yet set).
    pub fn contacts(&self) -> &[ContactPoint] {
        &self.contacts[..self.contact_count]
    }
}

/// A placeholder for unused contact slots.
const NO_CONTACT: ContactPoint = ContactPoint {
    pair: 0,
    point_a: DVec3::ZERO,
    point_b: DVec3::ZERO,
    normal: DVec3::ZERO,
    distance: 0.0,
    error_bound: 0.0,
};

/// Scratch of one thread answering jobs, reused across jobs and frames.
#[derive(Debug, Default)]
pub(super) struct JobScratch {
    mesh: MeshScratch,
    narrow: NarrowScratch,
    manifold: Manifold,
    /// The contacts of the pair being answered.
    contacts: Vec<ContactPoint>,
}

impl JobScratch {
    /// The outcome of direct pair `slot` (bodies `a`, `b` with shapes `sa`, `sb`) under
    /// `query`, answered by [`answer::direct`] on `clock`: a pool job's, or the pair
    /// helper's ([`helper`](super::helper), whose clock never stops).
    pub(super) fn direct(
        &mut self,
        (slot, pair): (u32, &CandidatePair),
        ((a, sa), (b, sb)): ((&Body, &Shape), (&Body, &Shape)),
        query: Query,
        clock: WorkClock,
    ) -> PairOutcome {
        let Self {
            narrow,
            manifold,
            contacts,
            ..
        } = self;
        contacts.clear();
        narrow.clock = clock;
        narrow.paths = PathCounts::default();
        let answer = answer::direct(pair, (a, sa), (b, sb), query, narrow, manifold, contacts);
        PairOutcome::new(slot, answer, contacts, DistanceCache::new(), narrow.paths)
    }
}

/// Answers `job` with `scratch`.
fn run(job: &PairJob, scratch: &mut JobScratch) -> PairOutcome {
    // The pool answers only frames without a limited budget: an unlimited clock, which
    // stops only when the frame is abandoned.
    let mut clock = WorkClock::default().abandonable(job.abandon.clone());
    let (sa, sb) = &job.shapes;
    match dispatch::route(sa, sb) {
        Route::MeshMesh(mesh_a, mesh_b) => {
            let JobScratch { mesh, contacts, .. } = scratch;
            contacts.clear();
            let mut cache = job.cache;
            let answer = answer::mesh_mesh(
                &job.pair,
                (&job.a, mesh_a),
                (&job.b, mesh_b),
                job.query,
                &mut cache,
                (mesh, &mut clock),
                contacts,
            );
            PairOutcome::new(job.slot, answer, contacts, cache, PathCounts::default())
        }
        Route::Direct => scratch.direct(
            (job.slot, &job.pair),
            ((&job.a, sa), (&job.b, sb)),
            job.query,
            clock,
        ),
    }
}

/// [`run`], with a panic turned into the pair's conservative box answer.
fn run_guarded(job: &PairJob, scratch: &mut JobScratch) -> PairOutcome {
    catch_unwind(AssertUnwindSafe(|| run(job, scratch))).unwrap_or_else(|_| {
        // The scratch may be half-updated: start afresh.
        *scratch = JobScratch::default();
        let contacts = &mut scratch.contacts;
        let answer = answer::boxes(
            &job.pair,
            &job.a.world_bounds,
            &job.b.world_bounds,
            job.query,
            contacts,
        );
        let paths = PathCounts::default();
        PairOutcome::new(job.slot, answer, contacts, DistanceCache::new(), paths)
    })
}

/// Persistent worker threads; dropping the pool stops and joins them.
#[derive(Debug)]
pub struct WorkerPool {
    /// `None` only while dropping (closing it stops the workers).
    jobs: Option<Sender<PairJob>>,
    /// The same queue, for the calling thread to take jobs from.
    queue: Receiver<PairJob>,
    outcomes: Receiver<PairOutcome>,
    /// Held for the length of a frame: one frame at a time.
    frame: Mutex<()>,
    threads: Vec<JoinHandle<()>>,
    /// The pair loop's helper ([`helper`](super::helper)), when the
    /// pool has workers: one for the pool, taken by one frame at a time.
    helper: Option<Mutex<PairHelper>>,
}

impl WorkerPool {
    /// A pool of `workers` threads (besides the calling thread, which works too).
    ///
    /// # Panics
    /// When the operating system cannot start a thread.
    #[must_use]
    pub fn new(workers: usize) -> Self {
        Self::with_helper(workers, (workers > 0).then(PairHelper::new))
    }

    /// A pool of `workers` threads whose pair helper is `helper` (tests give a held one).
    pub(super) fn with_helper(workers: usize, helper: Option<PairHelper>) -> Self {
        let (jobs, queue) = channel::bounded::<PairJob>(QUEUE_CAPACITY);
        let (outcome_tx, outcomes) = channel::bounded(QUEUE_CAPACITY);
        let threads = (0..workers)
            .map(|i| {
                let (queue, outcome_tx) = (queue.clone(), outcome_tx.clone());
                std::thread::Builder::new()
                    .name(format!("proxima-worker-{i}"))
                    .spawn(move || {
                        let mut scratch = JobScratch::default();
                        for job in queue {
                            let outcome = run_guarded(&job, &mut scratch);
                            if outcome_tx.send(outcome).is_err() {
                                break;
                            }
                        }
                    })
                    .expect("the operating system starts a worker thread")
            })
            .collect();
        Self {
            jobs: Some(jobs),
            queue,
            outcomes,
            frame: Mutex::new(()),
            threads,
            helper: helper.map(Mutex::new),
        }
    }

    /// The pool's pair helper, unless the pool has no workers or another frame holds it.
    pub(super) fn helper(&self) -> Option<std::sync::MutexGuard<'_, PairHelper>> {
        self.helper.as_ref()?.try_lock().ok()
    }

    /// Number of worker threads.
    #[must_use]
    pub fn workers(&self) -> usize {
        self.threads.len()
    }

    /// Answers every job, on the workers and the calling thread (with `scratch` as its
    /// scratch); `outcomes` receives one outcome per job, sorted by slot.
    pub(super) fn answer_all(
        &self,
        jobs: impl Iterator<Item = PairJob>,
        outcomes: &mut Vec<PairOutcome>,
        scratch: &mut JobScratch,
    ) {
        let _frame = self.frame.lock().unwrap_or_else(PoisonError::into_inner);
        let sender = self.jobs.as_ref().expect("open until the pool drops");
        let mut pending = 0usize;
        for job in jobs {
            match sender.try_send(job) {
                Ok(()) => pending += 1,
                Err(TrySendError::Full(job) | TrySendError::Disconnected(job)) => {
                    outcomes.push(run_guarded(&job, scratch));
                }
            }
        }
        while let Ok(job) = self.queue.try_recv() {
            outcomes.push(run_guarded(&job, scratch));
            pending -= 1;
        }
        for _ in 0..pending {
            // Every worker answers every job it takes (`run_guarded` catches panics) and lives
            // until the pool drops, so the channel stays open and `pending` outcomes arrive.
            let outcome = self
                .outcomes
                .recv()
                .expect("workers live as long as the pool");
            outcomes.push(outcome);
        }
        outcomes.sort_unstable_by_key(|o| o.slot);
    }
}

impl Drop for WorkerPool {
    fn drop(&mut self) {
        self.jobs = None;
        for thread in self.threads.drain(..) {
            let _ = thread.join();
        }
    }
}
