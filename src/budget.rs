//! How much work a frame may still do: the [`Budget`] polled between bounded batches of
//! work (a wall-clock [`Deadline`], a counted [`VisitBudget`] for deterministic tests, or
//! [`Unlimited`]), and the [`Completeness`] of an answer it cut short.
//!
//! A budget is polled between batches, never inside a primitive test (DESIGN §5), so work
//! may end up to one batch past it; the caller reserves time for what follows.

use std::time::Instant;

/// How much work may still be done, polled between bounded batches of visits.
pub trait Budget {
    /// Whether work may go on after `visits` visits (bounding-volume tests plus triangle
    /// tests) since the budgeted work started
    /// ([`FrontierWorkspace::start`](crate::narrow::mesh_mesh::frontier::FrontierWorkspace::start) for the frontier).
    fn allows(&mut self, visits: u64) -> bool;

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
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Completeness {
    /// The traversal finished: the answer is the exact one (every pair's, for a frame).
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
