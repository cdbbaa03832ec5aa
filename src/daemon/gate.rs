//! A test hook: a gate that work of one kind (every shape build, or every control request)
//! waits at while it is closed, so a test can hold that work in progress for as long as it
//! likes and watch what else the daemon does meanwhile (see
//! [`Daemon::set_build_gate`](super::Daemon::set_build_gate) and
//! [`Daemon::set_control_gate`](super::Daemon::set_control_gate)).

use std::sync::{Arc, Condvar, Mutex, PoisonError};
use std::time::{Duration, Instant};

/// A gate work waits at while it is closed (see the module docs); clones share one gate.
#[derive(Debug, Clone, Default)]
pub struct Gate {
    shared: Arc<(Mutex<GateState>, Condvar)>,
}

#[derive(Debug, Default)]
struct GateState {
    open: bool,
    /// Builds waiting at the gate now.
    held: usize,
}

impl Gate {
    /// A closed gate: work waits until [`open`](Self::open).
    #[must_use]
    pub fn closed() -> Self {
        Self::default()
    }

    /// An open gate: work passes until [`close`](Self::close).
    #[must_use]
    pub fn opened() -> Self {
        let gate = Self::default();
        gate.open();
        gate
    }

    /// Opens the gate: held work goes on, later work passes.
    pub fn open(&self) {
        self.set_open(true);
    }

    /// Closes the gate: work that comes to it from now on waits.
    pub fn close(&self) {
        self.set_open(false);
    }

    fn set_open(&self, open: bool) {
        let (state, changed) = &*self.shared;
        state.lock().unwrap_or_else(PoisonError::into_inner).open = open;
        changed.notify_all();
    }

    /// Waits until work is held at the gate, at most `timeout`; whether one is.
    #[must_use]
    pub fn wait_until_holding(&self, timeout: Duration) -> bool {
        let (state, changed) = &*self.shared;
        let deadline = Instant::now() + timeout;
        let mut guard = state.lock().unwrap_or_else(PoisonError::into_inner);
        while guard.held == 0 {
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return false;
            }
            guard = changed
                .wait_timeout(guard, left)
                .unwrap_or_else(PoisonError::into_inner)
                .0;
        }
        true
    }

    /// Whether work is held at the gate now.
    #[must_use]
    pub fn is_holding(&self) -> bool {
        let (state, _) = &*self.shared;
        state.lock().unwrap_or_else(PoisonError::into_inner).held > 0
    }

    /// Waits (counted as held) while the gate is closed.
    pub(super) fn pass(&self) {
        let (state, changed) = &*self.shared;
        let mut guard = state.lock().unwrap_or_else(PoisonError::into_inner);
        guard.held += 1;
        changed.notify_all();
        while !guard.open {
            guard = changed.wait(guard).unwrap_or_else(PoisonError::into_inner);
        }
        guard.held -= 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn work_is_held_while_the_gate_is_closed() {
        let gate = Gate::closed();
        assert!(!gate.wait_until_holding(Duration::from_millis(1)));
        let passed = std::sync::atomic::AtomicBool::new(false);
        std::thread::scope(|s| {
            s.spawn(|| {
                gate.pass();
                passed.store(true, std::sync::atomic::Ordering::SeqCst);
            });
            assert!(gate.wait_until_holding(Duration::from_secs(10)));
            assert!(gate.is_holding());
            assert!(!passed.load(std::sync::atomic::Ordering::SeqCst));
            gate.open();
        });
        assert!(passed.into_inner());
        assert!(!gate.is_holding());
        // An open gate lets work through at once; closed again, it holds again.
        gate.pass();
        gate.close();
        std::thread::scope(|s| {
            s.spawn(|| gate.pass());
            assert!(gate.wait_until_holding(Duration::from_secs(10)));
            gate.open();
        });
        Gate::opened().pass();
    }
}
