//! How much work a frame may still do: the [`Budget`] polled between bounded batches of
//! work (a wall-clock [`Deadline`], a counted [`VisitBudget`] for deterministic tests, or
//! [`Unlimited`]), and the [`Completeness`] of an answer it cut short.
//!
//! A budget is polled between batches, never inside a primitive test (DESIGN §5), so work
//! may end up to one batch past it; the caller reserves time for what follows.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// How much work may still be done, polled between bounded batches of visits.
pub trait Budget {
    /// Whether work may go on after `visits` visits (bounding-volume tests plus triangle
    /// tests) since the budgeted work started
    /// ([`FrontierWorkspace::start`](crate::narrow::mesh_mesh::frontier::FrontierWorkspace::start) for the frontier).
    fn allows(&mut self, visits: u64) -> bool;

    /// Whether work may go on after `visits` visits when stopping now would leave `pending`
    /// entries whose answers the caller then extracts: work that grows with them and that no
    /// poll interrupts (the frontier's answer pass, and the sort of the round they would
    /// start). A wall-clock budget that knows their cost reserves it; others ignore them.
    fn allows_pending(&mut self, visits: u64, pending: u64) -> bool {
        let _ = pending;
        self.allows(visits)
    }

    /// The wall-clock instant this budget ends at, when it is one (so a caller can reserve
    /// time for work after the traversal); `None` for counted and unlimited budgets.
    #[must_use]
    fn deadline(&self) -> Option<Instant> {
        None
    }

    /// Whether this budget never refuses (callers may then take their exact, unbudgeted
    /// paths, which give the same answers).
    #[must_use]
    fn is_unlimited(&self) -> bool {
        false
    }
}

/// A counted budget: allows work while fewer than `0` visits were made (so `VisitBudget(0)`
/// does nothing). A batch started below the limit is finished, so a run may end up to one
/// batch (`poll_every` visits plus one entry) beyond it. Deterministic: tests use only this.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct VisitBudget(pub u64);

impl Budget for VisitBudget {
    #[inline]
    fn allows(&mut self, visits: u64) -> bool {
        visits < self.0
    }
}

/// A wall-clock budget: allows work until the instant is reached (for the frame pipeline).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Deadline(pub Instant);

impl Budget for Deadline {
    #[inline]
    fn allows(&mut self, _visits: u64) -> bool {
        Instant::now() < self.0
    }

    fn deadline(&self) -> Option<Instant> {
        Some(self.0)
    }
}

/// No limit: the traversal runs to the exact answers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Unlimited;

impl Budget for Unlimited {
    #[inline]
    fn allows(&mut self, _visits: u64) -> bool {
        true
    }

    fn is_unlimited(&self) -> bool {
        true
    }
}

/// Whether an answer is final: one pair's, or a whole frame's (the shallowest of its
/// pairs').
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Completeness {
    /// The traversal finished: the answer is the exact one (every pair's, for a frame).
    #[default]
    Exact,
    /// The budget ran out with work left; `level` is the shallowest depth (descents from
    /// the root pair; 0 = the world boxes) of the waiting node pairs.
    Truncated {
        /// Shallowest depth of the waiting entries.
        level: u32,
    },
}

impl Completeness {
    /// `self` with one more answer truncated at `level`: truncated at the shallower of the
    /// two levels.
    #[must_use]
    pub fn truncated_at(self, level: u32) -> Self {
        match self {
            Self::Truncated { level: seen } if seen <= level => self,
            _ => Self::Truncated { level },
        }
    }
}

/// A flag another thread raises to abandon a frame's work: the daemon raises a scene's once
/// its owner is gone (DESIGN §10). Every [`WorkClock`] and frontier budget holding it stops
/// at its next poll, as if its deadline had come, so the frame ends with conservative
/// answers marked `Truncated` (and an unlimited frame is no longer exact). Clones share the
/// flag; the default one can never be raised. Once raised it stays raised.
#[derive(Debug, Clone, Default)]
pub struct Abandon(Option<Arc<AtomicBool>>);

impl Abandon {
    /// A flag not raised yet.
    #[must_use]
    pub fn new() -> Self {
        Self(Some(Arc::new(AtomicBool::new(false))))
    }

    /// Raises the flag: the work polling it stops at its next poll.
    pub fn raise(&self) {
        if let Some(flag) = &self.0 {
            // Relaxed: the flag guards no data; a poll that misses it sees it at the next.
            flag.store(true, Ordering::Relaxed);
        }
    }

    /// Whether the flag was raised.
    #[inline]
    #[must_use]
    pub fn is_raised(&self) -> bool {
        self.0.as_ref().is_some_and(|f| f.load(Ordering::Relaxed))
    }
}

/// When a [`WorkClock`] stops the work it is polled for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Stop {
    /// Never: the work runs to its exact answer.
    #[default]
    Never,
    /// At a wall-clock instant (a frame's deadline less what follows the work).
    At(Instant),
    /// Once this many units of work were counted (deterministic, for tests).
    AfterWork(u64),
}

/// The clock a frame's interruptible work polls between bounded steps (a leaf of a mesh
/// walk, an EPA expansion, a pair of the pair loop): it counts units of work and says
/// whether more may be done. Reading the wall clock costs about 25 ns, so an
/// [`Stop::At`] clock reads it only once [`WORK_PER_CLOCK_READ`] units have passed since
/// the last read; a unit is about the cost of a closed-form pair (tens of ns), and a step
/// that costs more counts more. Whatever its [`Stop`], a clock made
/// [`abandonable`](Self::abandonable) also looks at its [`Abandon`] flag at those reads.
/// Once stopped, it stays stopped.
#[derive(Debug, Clone, Default)]
pub struct WorkClock {
    stop: Stop,
    work: u64,
    /// `work` at which the clock next reads the time and the abandon flag.
    next_read: u64,
    stopped: bool,
    abandon: Abandon,
}

/// Units of work between two reads of the wall clock by a [`WorkClock`].
pub const WORK_PER_CLOCK_READ: u64 = 8;

impl WorkClock {
    /// A clock that stops as `stop` says.
    #[must_use]
    pub fn new(stop: Stop) -> Self {
        Self {
            stop,
            work: 0,
            next_read: 0,
            stopped: false,
            abandon: Abandon::default(),
        }
    }

    /// This clock, also stopped once `abandon` is raised.
    #[must_use]
    pub fn abandonable(mut self, abandon: Abandon) -> Self {
        self.abandon = abandon;
        self
    }

    /// The answer of interruptible `work` run under a clock that never stops (the plain
    /// form of a `_within` search, whose `None` means "stopped first").
    ///
    /// # Panics
    /// When `work` answers `None` under it: a bug of `work`, which may stop only when its
    /// clock does.
    pub fn run_to_end<T>(work: impl FnOnce(&mut WorkClock) -> Option<T>) -> T {
        work(&mut WorkClock::default()).expect("an unlimited clock never stops")
    }

    /// Counts `units` more units of work about to be done; whether they may be. The first
    /// call reads the clock, so work never starts past the instant.
    pub fn allows(&mut self, units: u64) -> bool {
        if self.stopped {
            return false;
        }
        let before = self.work;
        self.work = before.saturating_add(units);
        let reads = before >= self.next_read;
        if reads {
            self.next_read = before.saturating_add(WORK_PER_CLOCK_READ);
        }
        let abandoned = || reads && self.abandon.is_raised();
        self.stopped = match self.stop {
            Stop::Never => abandoned(),
            Stop::AfterWork(limit) => before >= limit || abandoned(),
            Stop::At(instant) => reads && (Instant::now() >= instant || abandoned()),
        };
        !self.stopped
    }

    /// Whether the clock has stopped the work.
    #[must_use]
    pub fn stopped(&self) -> bool {
        self.stopped
    }

    /// Moves the instant of a [`Stop::At`] clock (others are left as they are): the frame
    /// moves it as the work left after the clock stops shrinks or grows. Takes effect at
    /// the clock's next read of the time; a stopped clock stays stopped.
    pub fn move_stop(&mut self, instant: Instant) {
        if let Stop::At(at) = &mut self.stop {
            *at = instant;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    #[test]
    fn a_counted_clock_allows_exactly_its_work_and_stays_stopped() {
        let mut clock = WorkClock::new(Stop::AfterWork(3));
        assert!(clock.allows(1) && clock.allows(1) && clock.allows(1));
        assert!(!clock.allows(1));
        assert!(clock.stopped());
        assert!(!clock.allows(0), "a stopped clock never restarts");
        // A step started below the limit is allowed whatever it costs.
        let mut clock = WorkClock::new(Stop::AfterWork(2));
        assert!(clock.allows(1) && clock.allows(100));
        assert!(!clock.allows(1));
    }

    #[test]
    fn a_deadline_clock_reads_the_time_at_once_then_every_few_units() {
        let past = Instant::now().checked_sub(Duration::from_millis(1));
        let mut late = WorkClock::new(Stop::At(past.unwrap_or_else(Instant::now)));
        assert!(!late.allows(1), "the first poll reads the clock");
        let mut early = WorkClock::new(Stop::At(Instant::now() + Duration::from_secs(3600)));
        assert!((0..1000).all(|_| early.allows(3)));
        // Counting is the same whatever stops the clock: 1,000 steps of 3 units are 3,000.
        let mut counted = WorkClock::new(Stop::AfterWork(3000));
        assert!((0..1000).all(|_| counted.allows(3)) && !counted.allows(3));
        let mut never = WorkClock::default();
        assert!((0..1000).all(|_| never.allows(u64::MAX / 2)));
    }

    #[test]
    fn an_abandoned_clock_stops_at_its_next_read_whatever_its_stop() {
        let far = Instant::now() + Duration::from_secs(3600);
        for stop in [Stop::Never, Stop::At(far), Stop::AfterWork(u64::MAX)] {
            let abandon = Abandon::new();
            let mut clock = WorkClock::new(stop).abandonable(abandon.clone());
            assert!(
                (0..100).all(|_| clock.allows(1)),
                "{stop:?} before the flag"
            );
            abandon.raise();
            let allowed = (0..2 * WORK_PER_CLOCK_READ)
                .take_while(|_| clock.allows(1))
                .count() as u64;
            assert!(
                allowed < WORK_PER_CLOCK_READ,
                "{stop:?}: {allowed} units after"
            );
            assert!(
                clock.stopped() && !clock.allows(0),
                "{stop:?} stays stopped"
            );
        }
        // A clock without the flag, or with one never raised, is not stopped by it.
        let mut plain = WorkClock::default();
        Abandon::new().raise();
        assert!((0..1000).all(|_| plain.allows(1)));
        assert!(!Abandon::default().is_raised());
        Abandon::default().raise();
    }

    #[test]
    fn a_moved_stop_takes_effect_at_the_next_read() {
        let now = Instant::now();
        let mut clock = WorkClock::new(Stop::At(now + Duration::from_secs(3600)));
        assert!(clock.allows(1), "the first read: an hour left");
        clock.move_stop(now);
        let allowed = (0..WORK_PER_CLOCK_READ)
            .take_while(|_| clock.allows(1))
            .count();
        assert_eq!(
            allowed as u64,
            WORK_PER_CLOCK_READ - 1,
            "the units before the next read"
        );
        assert!(clock.stopped());
        let mut counted = WorkClock::new(Stop::AfterWork(2));
        counted.move_stop(now);
        assert!(counted.allows(1) && counted.allows(1) && !counted.allows(1));
    }
}
