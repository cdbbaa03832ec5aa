//! Stopping the daemon's threads together.
//!
//! One flag for the daemon: set by a termination signal (whichever thread sees it first),
//! by a [`StopHandle`] from another thread of the process, or by a thread that ends (with an
//! error, or a panic: [`StopOnDrop`]). Every thread checks it at least once per sweep
//! interval, so all of them end soon after any one of them does.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// Stops a running daemon from another thread of the same process (SIGINT and SIGTERM stop
/// the process's daemon the same way); clones stop the same daemon.
#[derive(Debug, Clone, Default)]
pub struct StopHandle(Arc<AtomicBool>);

impl StopHandle {
    /// Asks the daemon to stop; it does within about one sweep interval.
    pub fn stop(&self) {
        self.0.store(true, Ordering::Relaxed);
    }

    /// Whether [`stop`](Self::stop) was called.
    #[must_use]
    pub fn is_stopped(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }
}

/// Stops the daemon when dropped: held by each thread for its whole run, so a thread that
/// ends for any reason, a panic included, takes the others with it.
#[derive(Debug)]
pub struct StopOnDrop<'a>(pub &'a StopHandle);

impl Drop for StopOnDrop<'_> {
    fn drop(&mut self) {
        self.0.stop();
    }
}
