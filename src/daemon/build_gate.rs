//! A test hook: a gate every shape build waits at until it is opened, so a test can hold a
//! registration in progress for as long as it likes and watch what else the daemon does
//! meanwhile (see [`Daemon::set_build_gate`](super::Daemon::set_build_gate)).

use std::sync::{Arc, Condvar, Mutex, PoisonError};
use std::time::{Duration, Instant};

/// A gate shape builds wait at (see the module docs); clones share one gate.
#[derive(Debug, Clone, Default)]
pub struct BuildGate {
    shared: Arc<(Mutex<GateState>, Condvar)>,
}

#[derive(Debug, Default)]
struct GateState {
    open: bool,
    /// Builds waiting at the gate now.
    held: usize,
}

impl BuildGate {
    /// A closed gate: every build waits until [`open`](Self::open).
    #[must_use]
    pub fn closed() -> Self {
        Self::default()
    }

    /// Opens the gate for good: held builds go on, later ones pass.
    pub fn open(&self) {
        let (state, changed) = &*self.shared;
        state.lock().unwrap_or_else(PoisonError::into_inner).open = true;
        changed.notify_all();
    }

    /// Waits until a build is held at the gate, at most `timeout`; whether one is.
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

    /// Whether a build is held at the gate now.
    #[must_use]
    pub fn is_holding(&self) -> bool {
        let (state, _) = &*self.shared;
        state.lock().unwrap_or_else(PoisonError::into_inner).held > 0
    }

    /// Waits (counted as held) until the gate is open.
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
    fn a_build_is_held_until_the_gate_opens() {
        let gate = BuildGate::closed();
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
        // An open gate lets builds through at once.
        gate.pass();
    }
}
