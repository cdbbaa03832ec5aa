//! What each client process holds, and the most it may: scenes, shapes, bodies and memory,
//! charged before the work is done and given back when it goes.
//!
//! Pure bookkeeping, no IPC. A quota belongs to a client *process*, not to a control port:
//! a process that opens many ports (up to the control service's client limit) still holds
//! one quota, so it cannot take every scene or all the memory from the others. The
//! process is the one iceoryx2 records as having created the port's node (its pid); the
//! daemon-wide limits ([`DaemonConfig::max_scenes`](super::DaemonConfig),
//! [`max_memory_bytes`](super::DaemonConfig)) hold besides.
//!
//! # Invariant
//! A process's [`Usage`] is the sum of the usages charged to its scenes ([`Quotas::charge`])
//! and not yet refunded ([`Quotas::refund`]); the control state refunds a scene's whole
//! usage when the scene goes, so a process that holds nothing has no entry.

use super::budget_memory::{BODY_BYTES, readable};
use super::convert::Rejection;
use proxima_ipc::wire::ErrorCode;
use std::collections::HashMap;

/// A client process, as iceoryx2 names the creator of a port's node: its process id.
pub type ProcessId = u32;

/// The most one client process may hold at once (`[limits]` `*_per_client` in the
/// configuration file).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ClientQuota {
    /// Scenes alive, quarantined ones included.
    pub scenes: u32,
    /// Shapes registered, over all its scenes (primitives, convex and mesh).
    pub shapes: u32,
    /// Bodies alive, over all its scenes.
    pub bodies: u32,
    /// Memory of its shapes and bodies, bytes, as estimated before anything is built or
    /// added (the daemon's `budget_memory` estimates).
    pub memory_bytes: u64,
}

impl ClientQuota {
    /// The defaults: a quarter of the daemon's 64 scenes and 8 GiB of memory, four scenes'
    /// worth of shapes (4,096 each) and 262,144 bodies (1 GiB of body charges).
    pub const STANDARD: Self = Self {
        scenes: 16,
        shapes: 16_384,
        bodies: 1 << 18,
        memory_bytes: 2 << 30,
    };
}

/// What is charged: to a scene (what it holds) and to its process (the sum over its scenes).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Usage {
    /// Scenes (1 for a scene's own usage).
    pub scenes: u32,
    /// Shapes registered.
    pub shapes: u32,
    /// Bodies alive.
    pub bodies: u32,
    /// Memory of shapes and bodies, bytes.
    pub memory_bytes: u64,
}

impl Usage {
    /// One scene.
    pub const SCENE: Self = Self {
        scenes: 1,
        shapes: 0,
        bodies: 0,
        memory_bytes: 0,
    };
    /// One shape, of `memory_bytes` estimated bytes (0 for a primitive).
    #[must_use]
    pub const fn shape(memory_bytes: u64) -> Self {
        Self {
            shapes: 1,
            memory_bytes,
            ..Self::NOTHING
        }
    }
    /// One body, of `BODY_BYTES` (4,096 B).
    pub const BODY: Self = Self {
        bodies: 1,
        memory_bytes: BODY_BYTES,
        ..Self::NOTHING
    };
    /// Nothing.
    pub const NOTHING: Self = Self {
        scenes: 0,
        shapes: 0,
        bodies: 0,
        memory_bytes: 0,
    };

    /// Adds `other`.
    pub fn add(&mut self, other: Self) {
        self.scenes += other.scenes;
        self.shapes += other.shapes;
        self.bodies += other.bodies;
        self.memory_bytes += other.memory_bytes;
    }

    /// Takes `other` off; `other` must have been added before (the invariant above).
    pub fn remove(&mut self, other: Self) {
        self.scenes -= other.scenes;
        self.shapes -= other.shapes;
        self.bodies -= other.bodies;
        self.memory_bytes -= other.memory_bytes;
    }

    fn is_nothing(&self) -> bool {
        *self == Self::NOTHING
    }
}

/// Every client process's usage against one [`ClientQuota`].
#[derive(Debug, Clone)]
pub struct Quotas {
    limit: ClientQuota,
    by_process: HashMap<ProcessId, Usage>,
}

impl Quotas {
    /// Nobody holds anything yet.
    #[must_use]
    pub fn new(limit: ClientQuota) -> Self {
        Self {
            limit,
            by_process: HashMap::new(),
        }
    }

    /// Whether `process` may take `more` on top of what it holds.
    ///
    /// # Errors
    /// `LimitExceeded`, naming the limit it would pass, when it may not.
    pub fn check(&self, process: ProcessId, more: Usage) -> Result<(), Rejection> {
        let held = self.usage(process);
        let limit = &self.limit;
        let over = |held: u64, more: u64, limit: u64| more > 0 && held + more > limit;
        let refusal = if over(held.scenes.into(), more.scenes.into(), limit.scenes.into()) {
            format!(
                "this client process holds its limit of {} scenes",
                limit.scenes
            )
        } else if over(held.shapes.into(), more.shapes.into(), limit.shapes.into()) {
            format!(
                "this client process holds its limit of {} shapes",
                limit.shapes
            )
        } else if over(held.bodies.into(), more.bodies.into(), limit.bodies.into()) {
            format!(
                "this client process holds its limit of {} bodies",
                limit.bodies
            )
        } else if over(held.memory_bytes, more.memory_bytes, limit.memory_bytes) {
            format!(
                "it needs about {}; this client process's {} for shapes and bodies has {} left",
                readable(more.memory_bytes),
                readable(limit.memory_bytes),
                readable(limit.memory_bytes - held.memory_bytes)
            )
        } else {
            return Ok(());
        };
        Err(Rejection::new(ErrorCode::LimitExceeded, refusal))
    }

    /// Charges `more` to `process` (after a successful [`check`](Self::check)).
    pub fn charge(&mut self, process: ProcessId, more: Usage) {
        self.by_process.entry(process).or_default().add(more);
    }

    /// Gives `back` (charged before) back from `process`.
    pub fn refund(&mut self, process: ProcessId, back: Usage) {
        if let Some(held) = self.by_process.get_mut(&process) {
            held.remove(back);
            if held.is_nothing() {
                self.by_process.remove(&process);
            }
        }
    }

    /// What `process` holds.
    #[must_use]
    pub fn usage(&self, process: ProcessId) -> Usage {
        self.by_process.get(&process).copied().unwrap_or_default()
    }

    /// How many processes hold anything.
    #[must_use]
    pub fn processes(&self) -> usize {
        self.by_process.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const LIMIT: ClientQuota = ClientQuota {
        scenes: 2,
        shapes: 3,
        bodies: 4,
        memory_bytes: 4 * BODY_BYTES,
    };

    #[test]
    fn each_limit_refuses_the_charge_that_would_pass_it_and_names_it() {
        let mut quotas = Quotas::new(LIMIT);
        for (one, count, name) in [
            (Usage::SCENE, 2, "2 scenes"),
            (Usage::shape(0), 3, "3 shapes"),
            (Usage::BODY, 4, "4 bodies"),
        ] {
            for _ in 0..count {
                quotas.check(7, one).unwrap();
                quotas.charge(7, one);
            }
            let refused = quotas.check(7, one).unwrap_err();
            assert_eq!(refused.code, ErrorCode::LimitExceeded);
            assert!(refused.reason.contains(name), "{}", refused.reason);
            // Another process is not touched by this one's usage.
            quotas.check(8, one).unwrap();
        }
        quotas.check(7, Usage::NOTHING).unwrap();
    }

    #[test]
    fn shape_memory_is_refused_past_the_limit_and_given_back_with_its_scene() {
        let mut quotas = Quotas::new(LIMIT);
        let scene = Usage {
            memory_bytes: 4 * BODY_BYTES - 100,
            shapes: 1,
            ..Usage::SCENE
        };
        quotas.check(7, scene).unwrap();
        quotas.charge(7, scene);
        let refused = quotas.check(7, Usage::shape(101)).unwrap_err();
        assert!(
            refused
                .reason
                .contains("needs about 1 KiB; this client process's 16 KiB"),
            "{}",
            refused.reason
        );
        quotas.check(7, Usage::shape(100)).unwrap();
        quotas.refund(7, scene);
        assert_eq!(quotas.usage(7), Usage::NOTHING);
        assert_eq!(
            quotas.processes(),
            0,
            "a process holding nothing has no entry"
        );
        quotas.check(7, Usage::shape(4 * BODY_BYTES)).unwrap();
    }
}
